"""The CLI loads only what a command needs, and its option choices match the stages'."""

import subprocess
import sys
from pathlib import Path

from rl1.compiler import cli, driver
from rl1.vm import runner

SAMPLE = Path(__file__).parent.parent / "examples" / "sample.rob"


def test_option_choices_are_the_stages_own() -> None:
    assert cli.EMIT_CHOICES == driver.EMITS
    assert cli.ENGINE_CHOICES == runner.ENGINES


def test_check_loads_neither_the_back_end_nor_the_vm_nor_lark() -> None:
    program = (
        "import sys\n"
        "from rl1.compiler.cli import main\n"
        "try:\n"
        f"    main(['check', {str(SAMPLE)!r}])\n"
        "except SystemExit as done:\n"
        "    assert done.code == 0, done.code\n"
        "print(' '.join(name for name in sys.modules if name.startswith(('rl1.', 'lark'))))\n"
    )
    result = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True,
                            check=True)
    loaded = set(result.stdout.split("\n")[-2].split())
    assert "rl1.compiler.checker" in loaded
    back_end = {"rl1.compiler.codegen", "rl1.compiler.lower", "rl1.compiler.asm",
                "rl1.compiler.formatter", "rl1.vm.machine", "rl1.vm.scripted",
                "rl1.vm.verifier", "rl1.vm.interpreter"}
    assert loaded & back_end == set()
    # The parser runs the tables make_tables.py wrote; lark itself costs 40 ms to import.
    assert "rl1.compiler.lalr_tables" in loaded and "lark" not in loaded
