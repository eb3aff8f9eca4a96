"""The program generator's speed, in one run: programs per second that
compiler/strategies.py's `runs()` (what `rl1c fuzz` generates) and `checked_programs()`
make, generation alone (Hypothesis' own work included, no engine run; in this
process's CPU time, which other work on the machine leaves alone), as a ratio to
`programs()`, the syntax-only generator, in the same run. With `--strategies PATH`,
the generators of another copy of strategies.py (an older one, to compare before and
after a change) beside this tree's.

    .venv/bin/python bench/generator_speed.py [--count 2000] [--strategies PATH]
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
import time
from types import ModuleType

from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from rl1.compiler import strategies


def rate(strategy: st.SearchStrategy[object], count: int) -> float:
    """Programs per second that `strategy` generates, `count` of them, derandomized."""
    @settings(max_examples=count, database=None, derandomize=True, deadline=None,
              suppress_health_check=list(HealthCheck), phases=(Phase.generate,))
    @given(strategy)
    def generate(_: object) -> None:
        pass

    started = time.process_time()  # this process's CPU: the machine may be shared
    generate()
    return count / (time.process_time() - started)


def loaded(path: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location("strategies_compared", path)
    if spec is None or spec.loader is None:
        sys.exit(f"{path}: not a Python module")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=2000, help="programs per figure")
    parser.add_argument("--strategies", metavar="PATH",
                        help="another strategies.py to measure beside this tree's")
    arguments = parser.parse_args()
    modules = {"this tree": strategies}
    if arguments.strategies:
        modules[arguments.strategies] = loaded(arguments.strategies)
    count = arguments.count
    reference = rate(strategies.programs(), count)
    print(f"generated programs per second, {count} each (Hypothesis derandomized), "
          f"against programs(): {reference:.1f}/s")
    for name, module in modules.items():
        for label, strategy in (("runs()", module.runs()),
                                ("checked_programs()", module.checked_programs())):
            figure = rate(strategy, count)
            print(f"  {name}: {label:<20} {figure:7.1f}/s  ({figure / reference:5.2f}x)")


if __name__ == "__main__":
    main()
