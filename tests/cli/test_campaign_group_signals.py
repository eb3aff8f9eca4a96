"""SIGTERM to a campaign's whole process group, as a CI job's timeout sends it, or to its
workers first, as `pkill -f` may, stops `rl1c fuzz` and `rl1c sim --runs` as SIGTERM to
their process alone does: the workers, which ignore it, hear the stop from the campaign;
no worker is said to have ended abruptly; the summary, the seed and status 143; and no
process of the group left. Workers whose parent does not take the signal end with it."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from support import EXAMPLES

pytestmark = pytest.mark.slow  # campaigns on pools of processes, seconds each

TIMEOUT = 120  # s: to start on a loaded machine, and to stop

# rl1c with a progress line twice a second, so that a campaign is seen under way soon.
RL1C = [sys.executable, "-c",
        "from rl1.compiler.cli import fuzz, sim_campaign\n"
        "fuzz.PROGRESS_EVERY = sim_campaign.PROGRESS_EVERY = 0.5\n"
        "from rl1.compiler.cli.main import rl1c\n"
        "rl1c()"]


class Campaign:
    """`rl1c ARGS` in a session (and process group) of its own, its standard error read
    as it comes and its standard output written to a file."""

    def __init__(self, folder: Path, *args: str) -> None:
        self.out = folder / "stdout"
        with open(self.out, "w") as stdout:
            self.process = subprocess.Popen([*RL1C, *args], cwd=folder, stdout=stdout,
                                            stderr=subprocess.PIPE, text=True,
                                            start_new_session=True)
        self.lines: list[str] = []
        self.changed = threading.Condition()
        self.reader = threading.Thread(target=self._read)
        self.reader.start()

    def _read(self) -> None:
        assert self.process.stderr is not None
        for line in self.process.stderr:
            with self.changed:
                self.lines.append(line)
                self.changed.notify_all()
        with self.changed:
            self.lines.append("")  # the end
            self.changed.notify_all()

    def wait_for(self, pattern: str, after: int = 0) -> int:
        """Until a line of standard error past the first `after` matches `pattern`: the
        lines then."""
        def seen() -> bool:
            return "" in self.lines or any(re.search(pattern, line)
                                           for line in self.lines[after:])

        with self.changed:
            assert self.changed.wait_for(seen, TIMEOUT), self.lines
            assert "" not in self.lines, f"ended before {pattern!r} was said: {self.lines}"
            return len(self.lines)

    def stop(self, under_way: str, workers_first: bool) -> tuple[int, str, str]:
        """SIGTERM to the whole group once a line says the campaign is `under_way`
        (given `workers_first`, to each of its workers first, and on once it is seen to
        go on): the status, standard output and error."""
        group = self.process.pid  # a session's leader leads its group
        try:
            said = self.wait_for(under_way)
            if workers_first:
                children = _children(self.process.pid)
                assert children
                for child in children:
                    os.kill(child, signal.SIGTERM)
                self.wait_for(under_way, after=said)
            os.killpg(group, signal.SIGTERM)
            status = self.process.wait(TIMEOUT)
            self.reader.join(TIMEOUT)
            left = _alive(group)
        finally:
            _kill(group)
            self.process.wait(TIMEOUT)
        assert not left, "processes of the campaign's group outlived it"
        return status, self.out.read_text(), "".join(self.lines)


def _children(parent: int) -> list[int]:
    children = []
    for entry in os.listdir("/proc"):
        try:
            with open(f"/proc/{entry}/stat") as stat:
                # pid (comm) state ppid ...: comm may hold spaces and parentheses.
                if int(stat.read().rpartition(")")[2].split()[1]) == parent:
                    children.append(int(entry))
        except (OSError, ValueError, IndexError):  # no process, or gone since
            continue
    return children


def _alive(group: int) -> bool:
    try:
        os.killpg(group, 0)
    except ProcessLookupError:
        return False
    return True


def _kill(group: int) -> None:
    if _alive(group):
        os.killpg(group, signal.SIGKILL)


@pytest.mark.parametrize("workers_first", [False, True])
def test_rl1c_fuzz_stops_with_its_summary_when_its_group_is_sent_sigterm(
        tmp_path: Path, workers_first: bool) -> None:
    campaign = Campaign(tmp_path, "fuzz", "--time", "600", "--jobs", "2", "--seed", "7",
                        "--out", str(tmp_path / "out"))
    status, stdout, stderr = campaign.stop(r"^fuzz: [1-9][0-9]* programs", workers_first)
    assert status == 143, stderr
    assert "abruptly" not in stderr and "Traceback" not in stderr
    assert re.search(r"^fuzz: [1-9][0-9]* programs in [0-9.]+ s .*; seed 7, stopped by a "
                     r"signal before its end: all agreed so far$", stdout, re.MULTILINE), stdout
    assert not (tmp_path / "out").exists()  # no finding


@pytest.mark.parametrize("workers_first", [False, True])
def test_rl1c_sim_runs_stops_with_its_summary_when_its_group_is_sent_sigterm(
        tmp_path: Path, workers_first: bool) -> None:
    campaign = Campaign(tmp_path, "sim", str(EXAMPLES / "sample.rob"), "--world",
                        str(EXAMPLES / "sample.world.toml"), "--runs", "100000",
                        "--jobs", "2", "--seed", "3")
    status, stdout, stderr = campaign.stop(r"^[1-9][0-9]*/100000 runs", workers_first)
    assert status == 143, stderr
    assert "abruptly" not in stderr and "Traceback" not in stderr
    summary = re.search(r"^([0-9]+) runs? of \S+ on \S+, seeds 3\.\.100002 \(stopped after "
                        r"([0-9]+) of 100000\)$", stdout, re.MULTILINE)
    assert summary is not None, stdout
    runs = int(summary[1])
    assert runs == int(summary[2]) > 0
    assert f"success: {runs} of {runs}" in stdout
    assert (f"rl1c: interrupted: the runs finished are kept; to go on, run the seeds "
            f"left: rl1c sim {EXAMPLES / 'sample.rob'}") in stderr
    assert f"--runs {100000 - runs} --seed {3 + runs}" in stderr


# Workers that nap, on a pool of rl1's, in a parent that does not take SIGTERM.
NAPPING = """
import os
import time

from rl1.compiler.executors import workers


def nap() -> None:
    os.write(1, b"napping\\n")  # one write: the two workers' lines never interleave
    time.sleep(600)


with workers(2, isolated=True) as held:
    assert held.executor is not None
    for napped in [held.executor.submit(nap) for _ in range(2)]:
        napped.result()
"""


def test_workers_end_with_a_parent_that_sigterm_ends(tmp_path: Path) -> None:
    errors = tmp_path / "stderr"
    with open(errors, "w") as stderr, subprocess.Popen(
            [sys.executable, "-c", NAPPING], stdout=subprocess.PIPE, stderr=stderr,
            text=True, start_new_session=True) as parent:
        group = parent.pid
        try:
            assert parent.stdout is not None
            napping = [parent.stdout.readline() for _ in range(2)]
            assert napping == ["napping\n"] * 2, errors.read_text()
            os.killpg(group, signal.SIGTERM)
            assert parent.wait(TIMEOUT) == -signal.SIGTERM
            deadline = time.monotonic() + TIMEOUT
            while _alive(group) and time.monotonic() < deadline:
                time.sleep(0.1)
            assert not _alive(group), "the workers outlived their parent"
        finally:
            _kill(group)
