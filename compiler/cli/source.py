"""The commands on RL/I source: `rl1c check`, `rl1c fmt` and `rl1c explain`.

Each command imports the stage it runs when it runs, so that no command loads what only
another one needs (`rl1c explain` no checker, `rl1c check` no formatter).
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING

import click

from rl1.compiler.frontend.source import Source
from rl1.compiler.reporting.catalogue import CODES
from rl1.compiler.reporting.render import (
    EXIT_ERRORS,
    EXIT_USAGE,
    ColorChoice,
    FileDiagnostics,
    Format,
    fixes_not_made,
    summary,
)

from .command import PATH, Command, CommandError, color_option, force_option, format_option
from .streams import (
    cannot,
    cannot_write,
    emit,
    encode_like,
    file_failure,
    file_problem,
    invalid_config,
    problem_text,
    read_input,
    source_files,
    unified_diff,
    write_back,
    write_stdout_bytes,
)

if TYPE_CHECKING:  # click's completion module loads only when a shell asks
    from click.shell_completion import CompletionItem

    from rl1.compiler.reporting.selection import Selection

SECTION = "RL/I programs"


@click.command(cls=Command)
@click.argument("files", nargs=-1, required=True, metavar="PATH...", type=PATH)
@format_option
@color_option
@click.option("--select", metavar="CODES", multiple=True,
              help="report only these warnings: codes or their starts, separated by commas "
                   "(W0601,W06; W is every warning). Errors are always reported")
@click.option("--ignore", metavar="CODES", multiple=True,
              help="never report these warnings (over --select)")
@click.option("--warnings-as-errors/--no-warnings-as-errors", default=None,
              help="report warnings as errors, so that any warning fails the check (exit "
                   "status 1), as CI wants")
@click.option("--fix", is_flag=True,
              help="make the checker's safe fixes in the files (those that keep what the "
                   "program means and everything written), then report what is left")
@click.option("--unsafe-fixes", is_flag=True,
              help="with --fix or --diff, make the unsafe fixes too: guesses at a misspelt "
                   "name, removals, changes to what the vehicle does (`rl1c explain CODE` "
                   "says which a code's fix is)")
@click.option("--diff", is_flag=True,
              help="change nothing; print what --fix would change as a unified diff (exit "
                   "status 1 when it would change a file)")
@click.option("--isolated", is_flag=True, help="read no rl1.toml: only the options given here")
@force_option
def check(files: tuple[str, ...], output_format: Format, color: ColorChoice,
          select: tuple[str, ...], ignore: tuple[str, ...], warnings_as_errors: bool | None,
          fix: bool, unsafe_fixes: bool, diff: bool, isolated: bool, force: bool) -> int:
    """Check RL/I programs and report every problem found.

    PATH is an RL/I program, or a folder: every .rob file below it is checked; `-` reads
    standard input. The nearest rl1.toml in the file's folder or above it may set
    --select, --ignore and --warnings-as-errors for its project (a `[check]` table);
    the options given here win. A comment `' rl1: allow W0601` allows a warning on its
    line, `' rl1: allow-file W0601` in its file. Exit status: 0 no errors (warnings
    allowed), 1 errors (--diff: a file would change), 2 an unreadable file or rl1.toml."""
    from rl1.compiler import analysis
    from rl1.compiler.reporting.project import ProjectFileError, project_selection
    from rl1.compiler.reporting.selection import Selection

    if unsafe_fixes and not (fix or diff):
        raise click.UsageError("--unsafe-fixes says which fixes --fix or --diff make: give "
                               "it with one of them")
    if fix and not diff and "-" in files:
        raise click.UsageError("--fix rewrites files, and standard input is none: give the "
                               "file, or --diff to see the fixes")
    given = Selection(_codes("--select", select), _codes("--ignore", ignore),
                      warnings_as_errors)
    project = project_selection()
    inputs: list[tuple[str | FileDiagnostics, Selection]] = []
    try:  # every rl1.toml is read before any file is checked: a bad one stops it all
        for item in source_files(files, "check"):
            selection = given
            if isinstance(item, str) and not isolated:
                selection = given.over(project(item))
            inputs.append((item, selection))
    except ProjectFileError as error:
        role = "project file"
        if error.unreadable:
            raise file_failure(file_problem(error.path, cannot("read", role, error.path,
                                                               error.detail),
                                            error.help)) from None
        raise invalid_config(role, error.path, error,
                             "correct the file (`rl1c docs commands`, \"Controlling `rl1c "
                             "check`\", shows its form), or move it aside") from None
    if diff:
        return _fix_diff(inputs, unsafe_fixes)
    checked: list[FileDiagnostics] = []
    fixed = left = 0
    status = 0
    for item, selection in inputs:
        source = read_input(item) if isinstance(item, str) else item
        if not isinstance(source, Source):
            checked.append(source)
            continue
        text, diagnostics = source.text, None
        if fix:
            fixing = analysis.fix(source.text, keep=selection.reports, unsafe=unsafe_fixes)
            text, diagnostics = fixing.text, fixing.diagnostics
            try:
                if fixing.fixes:
                    write_back(source, fixing.text, force=force)
                    fixed += fixing.fixes
                left += fixing.left
            except OSError as error:
                print(problem_text(cannot_write(source.name, "source file", error,
                                                "to make its fixes")), file=sys.stderr)
                status = EXIT_USAGE
                text, diagnostics = source.text, None  # the file is as it was
        if diagnostics is None:
            diagnostics = analysis.diagnose_compactly(text)
        checked.append(FileDiagnostics(source.name, text, selection.apply_compact(diagnostics)))
    status = max(status, emit(checked, output_format, color, None))
    if output_format in ("human", "concise"):
        sys.stdout.write(summary(checked, fixed, left, unsafe_fixes))
    return status


def _codes(option: str, words: tuple[str, ...]) -> tuple[str, ...] | None:
    from rl1.compiler.reporting.selection import SelectionError, parse_codes

    if not words:
        return None
    try:
        return parse_codes(words)
    except SelectionError as error:
        raise click.UsageError(f"argument {option}: {error}") from None


def _fix_diff(inputs: Sequence[tuple[str | FileDiagnostics, Selection]], unsafe: bool) -> int:
    """`rl1c check --diff`: what --fix would change, as diffs; exit status 1 when it
    would change a file, 2 when a file cannot be read."""
    from rl1.compiler import analysis

    changed = fixes = left = 0
    unreadable = False
    for item, selection in inputs:
        source = read_input(item) if isinstance(item, str) else item
        if not isinstance(source, Source):
            emit([source], "human", "auto", None, err=True)
            unreadable = True
            continue
        fixing = analysis.fix(source.text, keep=selection.reports, unsafe=unsafe)
        left += fixing.left
        if fixing.fixes:
            sys.stdout.write(unified_diff(source.name, source.text, fixing.text, "fixed"))
            changed += 1
            fixes += fixing.fixes
    flags = "--fix --unsafe-fixes" if unsafe else "--fix"
    not_made = f"; {fixes_not_made(left, unsafe)}" if left else ""
    print(f"{flags} would make {_plural(fixes, 'fix', 'fixes')} in "
          f"{_plural(changed, 'file')}{not_made}", file=sys.stderr)
    return EXIT_USAGE if unreadable else EXIT_ERRORS if changed else 0


@click.command(cls=Command)
@click.argument("files", nargs=-1, required=True, metavar="PATH...", type=PATH)
@click.option("--check", is_flag=True,
              help="change nothing; list the files formatting would change (exit status 1)")
@click.option("--diff", is_flag=True,
              help="change nothing; print what formatting would change as a unified diff "
                   "(exit status 1 when it would change a file)")
@force_option
def fmt(files: tuple[str, ...], check: bool, diff: bool, force: bool) -> int:
    """Put RL/I programs in the canonical layout (spec/language.md, section 11).

    PATH is an RL/I program, or a folder: every .rob file below it is formatted. Each
    file is rewritten in place in its own encoding; `-` formats standard input to
    standard output. A summary of what changed goes to standard error. Exit status: 0
    done, 1 (--check, --diff) a file would change, 2 a file cannot be read or
    written."""
    from rl1.compiler import formatter

    changed = unchanged = failed = 0
    for item in source_files(files, "fmt"):
        source = read_input(item) if isinstance(item, str) else item
        if not isinstance(source, Source):
            emit([source], "human", "auto", None, err=True)
            failed += 1
            continue
        formatted = formatter.format_text(source.text)
        if formatted == source.text:
            unchanged += 1
        else:
            changed += 1
        if diff and formatted != source.text:
            sys.stdout.write(unified_diff(source.name, source.text, formatted, "formatted"))
        if check and formatted != source.text:
            print(source.name)
        if check or diff:
            continue
        if item == "-":
            write_stdout_bytes(encode_like(source, formatted, bom=False))
        elif formatted != source.text:
            try:
                write_back(source, formatted, force=force)
            except OSError as error:
                print(problem_text(cannot_write(source.name, "source file", error,
                                                "in the canonical layout")),
                      file=sys.stderr)
                changed -= 1
                failed += 1
    would = check or diff
    counts = [_plural(changed, "file") + (" would be reformatted" if would else " reformatted"),
              _plural(unchanged, "file") + (" already formatted" if would else
                                            " left unchanged")]
    if failed:
        counts.append(_plural(failed, "file") + " could not be formatted")
    print(", ".join(counts), file=sys.stderr)
    if failed:
        return EXIT_USAGE
    return EXIT_ERRORS if would and changed else 0


def _plural(count: int, noun: str, nouns: str | None = None) -> str:
    return f"{count} {noun if count == 1 else nouns or noun + 's'}"


def _complete_code(ctx: click.Context, param: click.Parameter,
                   incomplete: str) -> list[CompletionItem]:
    """The diagnostic codes starting with what is typed, each with its title."""
    from click.shell_completion import CompletionItem

    prefix = incomplete.strip().upper()
    return [CompletionItem(code, help=info.title) for code, info in CODES.items()
            if code.startswith(prefix)]


@click.command(cls=Command)
@click.argument("code", required=False, metavar="[CODE]", shell_complete=_complete_code)
@click.option("--list", "list_codes", is_flag=True, help="list every code with its title")
def explain(code: str | None, list_codes: bool) -> int:
    """Explain a diagnostic code in depth, with examples: `rl1c explain E0101`."""
    if list_codes == (code is not None):
        raise click.UsageError("give a code, as in `rl1c explain E0101`, or --list")
    if code is None:
        for entry in CODES.values():
            print(f"{entry.code}  {entry.title}")
        return 0
    info = CODES.get(code.strip().upper())
    if info is None:
        raise CommandError(f"`{code}` is not a diagnostic code of rl1c\n"
                           "  = help: `rl1c explain --list` lists every code with its title")
    sys.stdout.write(info.explanation())
    return 0


COMMANDS = (check, fmt, explain)
