"""`rl1c test`: run the tests of test files (spec/tests.md; compiler/test_file.py reads
them, compiler/program_tests.py runs them, test_report.py reports them)."""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING

import click

from rl1.compiler.executors import workers
from rl1.compiler.files import SourceError, read_bounded
from rl1.compiler.reporting.render import EXIT_ERRORS, EXIT_USAGE, ColorChoice, use_color

from .command import (
    PATH,
    Command,
    CommandError,
    Failure,
    at_least_one,
    color_option,
    force_option,
    or_none,
)
from .streams import (
    cannot,
    config_problem,
    file_problem,
    problem_text,
    same_file,
    unreadable,
    write_file,
)

if TYPE_CHECKING:  # the test file's schema loads when the command runs
    from rl1.compiler.program_tests import Case
    from rl1.compiler.test_file import Test

SECTION = "Testing"
MAX_TEST_FILE_BYTES = 2**20
TEST_FILE_ROLE = "test file"


@click.command(cls=Command)
@click.argument("paths", nargs=-1, metavar="[PATH]...", type=PATH)
@click.option("--jobs", type=str, default=None, callback=or_none(at_least_one), metavar="J",
              help="the processes that make a success rate's runs (default: every core); "
                   "the results are the same for any J")
@click.option("--junit", "junit_file", metavar="FILE", type=PATH,
              help="also write the results as JUnit XML to FILE, for CI")
@force_option
@color_option
def test(paths: tuple[str, ...], jobs: int | None, junit_file: str | None, force: bool,
         color: ColorChoice) -> int:
    """Run the tests of test files: each a program on a world or a sensor script, and
    what must hold (spec/tests.md).

    PATH is a test file, or a folder searched for files named *.tests.toml (hidden
    folders left out); the default is the current folder. Prints a character per test
    (. passed, F failed, E an error: a file missing or invalid, a program with errors),
    then each failure with the run's story and the command that replays it, and a
    summary. Exit status: 0 every test passed; 1 a test failed or had an error; 2 a
    usage problem, or a test file that cannot be read or is not valid."""
    from rl1.compiler.program_tests import Case, run_test
    from rl1.compiler.test_file import Success

    from .test_report import MARKS, Result, finished, junit_xml, summary_line

    cases = [Case(file, test) for file, tests in _load(paths or (".",)) for test in tests]
    if junit_file is not None:
        _refuse_junit_target(junit_file, cases)
    jobs = jobs or os.cpu_count() or 1
    color_on = use_color(color, sys.stdout)
    started = time.perf_counter()
    results: list[Result] = []
    campaigns = any(isinstance(case.test.expect.success, Success) for case in cases)
    with workers(jobs if campaigns else 1) as pool:
        file = None
        for case in cases:
            if case.file != file:
                sys.stdout.write(("\n" if file is not None else "") + f"{case.file} ")
                file = case.file
            results.append(finished(case, run_test(case, pool.executor, jobs), jobs,
                                    color=color_on))
            sys.stdout.write(MARKS[results[-1].outcome.status])
            sys.stdout.flush()
    seconds = time.perf_counter() - started
    sys.stdout.write("\n")
    unpassed = [result for result in results if result.outcome.status != "passed"]
    if unpassed:
        sys.stdout.write(f"\n{' FAILURES ':=^60}\n")
        for result in unpassed:
            sys.stdout.write(result.printed)
    sys.stdout.write(f"{' ' + summary_line(results, seconds) + ' ':=^60}\n")
    if junit_file is not None:
        write_file(junit_file, junit_xml(results, seconds), force=force,
                   role="JUnit file")
    return EXIT_ERRORS if unpassed else 0


def _load(paths: Sequence[str]) -> list[tuple[str, list[Test]]]:
    """The tests of each test file `paths` name (each file, or the test files in each
    folder); a Failure (exit status 2) naming every file that cannot be read or used."""
    from rl1.compiler.test_file import load_test_file
    from rl1.vm.config import ConfigError

    loaded = []
    problems = []
    for file in _test_files(paths):
        try:
            loaded.append((file, load_test_file(read_bounded(
                file, MAX_TEST_FILE_BYTES, "a test file"), file).test))
        except SourceError as error:
            problems.append(unreadable(file, error, TEST_FILE_ROLE))
        except ConfigError as error:
            problems.append(config_problem(TEST_FILE_ROLE, file, error,
                                           "correct it as spec/tests.md describes"))
    if problems:
        raise Failure("\n".join(problem_text(problem) for problem in problems), EXIT_USAGE)
    return loaded


def _refuse_junit_target(target: str, cases: Sequence[Case]) -> None:
    """A usage error, before any test runs, when the JUnit file could not be written
    (the tests' time would be lost) or would replace a file the tests read."""
    if target in ("", "-"):
        raise click.UsageError("--junit writes a file, and standard output carries the "
                               "report: give --junit FILE")
    if os.path.isdir(target):
        raise click.UsageError(f"--junit `{target}` is a folder: give the path of a file")
    inputs = {case.file: "test file" for case in cases}
    for case in cases:
        inputs |= {name: role for name, role in ((case.program, "program"),
                                                 (case.world, "world file"),
                                                 (case.sensors, "sensor script"))
                   if name is not None}
    for name, role in inputs.items():
        if same_file(name, target):
            raise click.UsageError(f"--junit `{target}` is the {role} `{name}` itself: "
                                   "give another path for the JUnit XML")


def _test_files(paths: Sequence[str]) -> list[str]:
    """Each file of `paths` as given, and for each folder its test files, in sorted
    order (hidden files and folders left out)."""
    from rl1.compiler.test_file import TEST_FILE_SUFFIX, is_test_file

    files: list[str] = []
    for path in paths:
        if not os.path.isdir(path):
            files.append(path)
            continue
        found = []
        unlisted: list[OSError] = []
        for folder, folders, names in os.walk(path, onerror=unlisted.append):
            folders[:] = sorted(name for name in folders if not name.startswith("."))
            found += [os.path.normpath(os.path.join(folder, name)) for name in sorted(names)
                      if is_test_file(name) and not name.startswith(".")
                      and os.path.isfile(os.path.join(folder, name))]
        if unlisted:
            error = unlisted[0]
            folder = str(error.filename or path)
            raise Failure(problem_text(file_problem(folder, cannot(
                "list", "folder", folder, str(error.strerror or error)),
                "check its permissions")), EXIT_USAGE)
        if not found:
            raise CommandError(f"no test file (*{TEST_FILE_SUFFIX}) in "
                               f"`{path}` or below it; write one as spec/tests.md describes, "
                               "or start a project with one: `rl1c new DIR`", EXIT_USAGE)
        files += found
    return files


COMMANDS = (test,)
