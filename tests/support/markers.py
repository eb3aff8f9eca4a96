"""A pytest plugin every run loads (pyproject.toml's addopts): marks tests by what they
need beyond Python and by how long they take, so that `make quick` can leave out the
tests marked `slow`, `needs_cc`, `needs_node` or `needs_browser` (pyproject.toml
registers them) and run the rest in under a minute.

Every Hypothesis property is slow; any other test is marked here by where it is (a
folder, a module, or one test of a module), so that the test files stay about what they
test, or in its own module (`pytestmark`, or a mark on the test).
tests/project/test_markers.py checks that every place named here exists. (A plugin
rather than tests/conftest.py, which mypy would take for tests/lsp/conftest.py.)
"""

from __future__ import annotations

import pytest

# Where a test is, as pytest names it from the project's folder, to its marks. A key
# ending in `/` is a folder, one with `::` a test (every parameter of it), any other a
# module.
MARKS: dict[str, tuple[str, ...]] = {
    # The C VM through ctypes, built with UBSan: every vector, loader refusals, the cache.
    "tests/c/": ("needs_cc", "slow"),
    "tests/backend/test_firmware.py::test_the_c_array_compiles_and_holds_the_ilc_bytes":
        ("needs_cc",),
    # The replay page in Debian's chromium, through Playwright.
    "tests/browser/": ("needs_browser", "slow"),
    # Emacs on a terminal and Neovim headless, each with rl1-lsp, as a user sets them up.
    "tests/editors/": ("slow",),
    # Slow, besides every Hypothesis property (below): fuzzing campaigns, hostile inputs
    # in subprocesses, compilations under many hash seeds, searches through generated
    # programs for each form of the syntax.
    "tests/cli/test_fuzz_cli.py": ("slow",),
    "tests/cli/test_reduce.py::test_a_fuzz_finding_of_a_planted_bug_is_reduced_with_its_engines":
        ("slow",),
    "tests/cli/test_reduce.py::test_ctrl_c_keeps_the_smallest_so_far": ("slow",),
    "tests/cli/test_reduce.py::test_rl1c_reduce_gives_the_same_bytes_every_time": ("slow",),
    "tests/cli/test_reduce.py::test_rl1c_fuzz_reduces_its_finding_with_these_passes": ("slow",),
    "tests/frontend/test_strategies.py": ("slow",),
    # A seeded search of 1,000 generated programs on two engines, and its statistics.
    "tests/backend/test_generator_shapes.py": ("slow",),
    # A language server process of its own for each test (its command line, its raw
    # protocol over standard input and output).
    "tests/lsp/test_command.py": ("slow",),
    "tests/lsp/test_protocol.py": ("slow",),
    "tests/cli/test_hostile_inputs.py": ("slow",),
    "tests/lsp/test_hostile_transports.py": ("slow",),
    # rl1c studio in a process of its own, stopped by Ctrl-C.
    "tests/studio/test_studio_command.py::test_it_prints_its_address_serves_there_and_stops_on_ctrl_c":
        ("slow",),
    "tests/backend/test_reproducible.py": ("slow",),
    # Each benchmark script in a process of its own, asked for --help.
    "tests/project/test_bench_help.py": ("slow",),
    # rl1c check's memory per source byte, under tracemalloc in a process of its own.
    "tests/checker/test_streaming.py::test_checking_takes_at_most_64_bytes_a_source_byte":
        ("slow",),
    "tests/checker/test_fixing.py::test_fixing_takes_at_most_64_bytes_a_source_byte": ("slow",),
    "tests/backend/test_compile_memory.py": ("slow",),
    # Campaigns of simulated runs on pools of processes, and on Dask clusters of a
    # scheduler and workers, each process started apart.
    "tests/sim/test_campaign.py": ("slow",),
    "tests/sim/test_cluster.py": ("slow",),
    # Forty seeded simulations of the robust Fig. 4 example.
    "tests/sim/test_sim_fig4.py::test_with_noise_it_succeeds_in_at_least_nine_runs_of_ten":
        ("slow",),
}


def marks_of(nodeid: str) -> tuple[str, ...]:
    """The marks MARKS gives the test `nodeid` (tests/c/test_c_vm.py::test_x[case])."""
    test = nodeid.split("[", 1)[0]
    return tuple(mark for where, marks in MARKS.items()
                 if test == where or test.startswith(where if where.endswith("/")
                                                     else where + "::")
                 for mark in marks)


def is_property(item: object) -> bool:
    """Whether the test is a Hypothesis property, which runs its examples by the hundred
    (about a tenth of the tests, and most of the time of the fast ones)."""
    return getattr(getattr(item, "obj", None), "is_hypothesis_test", False) is True


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        for mark in (*marks_of(item.nodeid), *(("slow",) if is_property(item) else ())):
            item.add_marker(mark)
