"""executors.in_own_process, how a Dask worker runs each search of `rl1c fuzz`, and
judge_apart: what cannot cross between the processes (a task the child cannot read, an
error the parent cannot rebuild) is said as such, and the child does not outlive its
parent."""

from __future__ import annotations

import contextlib
import importlib.util
import os
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from support.cli import rl1c
from support.processes import ends_within

from rl1.compiler import differential, fuzz
from rl1.compiler.differential import EngineUnavailable, Observation, VmEngine, judge_apart
from rl1.compiler.executors import TaskUnreadable, in_own_process
from rl1.compiler.strategies import Run


class _Refused(EngineUnavailable):
    """An error whose `__init__` takes other arguments than it keeps (`args`): it
    pickles, and unpickling it calls `_Refused("refused at 3")`, a TypeError."""

    def __init__(self, what: str, where: int) -> None:
        super().__init__(f"{what} at {where}")


def _refuses() -> None:
    raise _Refused("refused", 3)


@pytest.fixture
def loaded_here(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Callable[[], int]:
    """A function of a module this process loaded from a file that is not on the path
    (as Dask loads a preload file): it pickles here, and a child cannot import it."""
    (tmp_path / "rl1_loaded_here.py").write_text("def answer() -> int:\n    return 42\n")
    spec = importlib.util.spec_from_file_location("rl1_loaded_here",
                                                  tmp_path / "rl1_loaded_here.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    monkeypatch.setitem(sys.modules, "rl1_loaded_here", module)
    answer: Callable[[], int] = module.answer
    return answer


UNREADABLE = ("the process spawned for a task could not read it (ModuleNotFoundError: No "
              "module named 'rl1_loaded_here')\n  = help: the task's code must import there "
              "as it does here: install the same rl1")


def test_a_task_its_process_cannot_read_is_said_so_and_the_process_lives_on(
        loaded_here: Callable[[], int]) -> None:
    child = in_own_process((), os.getpid)
    with pytest.raises(TaskUnreadable) as raised:
        in_own_process((), loaded_here)
    assert str(raised.value).startswith(UNREADABLE)
    assert in_own_process((), os.getpid) == child  # the next task, in the same process


def test_a_preloaded_module_its_process_cannot_import_makes_each_task_unreadable() -> None:
    with pytest.raises(TaskUnreadable, match=r"^the process spawned for a task could not "
                       r"read it \(the module `rl1_nowhere` the worker preloaded: "
                       r"ModuleNotFoundError: No module named 'rl1_nowhere'\)\n"):
        in_own_process(("rl1_nowhere",), pow, 2, 10)


def test_rl1c_fuzz_says_a_search_its_process_cannot_read_with_status_2(
        loaded_here: Callable[[], int], monkeypatch: pytest.MonkeyPatch) -> None:
    # As a campaign's search on a cluster's worker whose rl1 imports other code (a
    # worker's own search raises it in the same way, named by its worker's address).
    def campaign(*args: object, **kwargs: object) -> None:
        in_own_process((), loaded_here)

    monkeypatch.setattr(fuzz, "campaign", campaign)
    result = rl1c("fuzz", "--count", "1")
    assert result.exit_code == 2
    assert result.stderr.startswith(f"rl1c fuzz: error: {UNREADABLE}")
    assert "Traceback" not in result.stderr


def test_an_error_the_parent_cannot_rebuild_is_named_with_its_message() -> None:
    with pytest.raises(RuntimeError) as raised:
        in_own_process((), _refuses)
    assert str(raised.value).startswith("_Refused: refused at 3 (raised in a child process, "
                                        "and not rebuilt here: TypeError: ")
    assert in_own_process((), pow, 2, 10) == 1024


def test_a_result_the_parent_cannot_rebuild_is_named_by_its_type() -> None:
    with pytest.raises(RuntimeError, match=r"^the task's result, a _Refused, cannot be rebuilt "
                       r"in this process \(TypeError: "):
        in_own_process((), _Refused, "refused", 3)


class _RefusingEngine:
    name = "refusing"
    level = 0

    def run(self, case: Run, budget: int) -> Observation:
        _refuses()
        raise AssertionError("unreachable")


def test_judged_apart_an_error_the_parent_cannot_rebuild_is_named_with_its_message() -> None:
    with pytest.raises(RuntimeError, match=r"^_Refused: refused at 3 \(raised in a child "
                       r"process, and not rebuilt here: TypeError: "):
        judge_apart(Run("A=1\n", {}), [VmEngine(0), _RefusingEngine()], 100)


def test_a_process_of_its_own_runs_one_thread_so_it_judges_apart_by_forking() -> None:
    # A thread of its own (one watching its parent, say) would have it spawn a process
    # for each case judged apart, some ten times as slow (bench/own_process.py).
    assert in_own_process((), differential.forks_safely)


def test_a_process_of_its_own_ends_amid_a_task_when_its_parent_is_killed() -> None:
    # As a Dask worker killed amid a search: the search's process must not finish it, an
    # orphan holding a core.
    task = "import os, time; print(os.getpid(), flush=True); time.sleep(600)"
    with subprocess.Popen(
            [sys.executable, "-c", "from rl1.compiler.executors import in_own_process; "
             f"in_own_process((), exec, {task!r})"],
            stdout=subprocess.PIPE, text=True) as parent:
        assert parent.stdout is not None
        child = int(parent.stdout.readline())
        parent.kill()
        parent.wait()
        try:
            assert ends_within(child, 30), f"process {child} outlived its parent"
        finally:
            with contextlib.suppress(ProcessLookupError):  # as it should be
                os.kill(child, signal.SIGKILL)
