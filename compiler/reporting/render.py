"""Renderers: diagnostics to text for people (rustc/Elm style), one line each
(`file:line:col: warning[W0301]: message`, for editors' problem matchers and grep), JSON,
or SARIF 2.1.0.

`report` renders the diagnostics of several files in one of the four formats, `summary`
counts them in one line, and `exit_status` says how a command should end after reporting
them. Diagnostics stay data until here; nothing else turns them into text.
"""

from __future__ import annotations

import io
import os
import unicodedata
from collections.abc import Iterable, Iterator, Sequence
from typing import IO, Any, Literal, NamedTuple, Protocol, runtime_checkable

from rl1.compiler.frontend.ast import Span
from rl1.compiler.frontend.characters import code_point, shows_nothing
from rl1.compiler.frontend.diagnostics import Diagnostic, Fix, Severity, sort_by_place
from rl1.compiler.frontend.source import LineIndex, split_lines

from .catalogue import CODES

Format = Literal["human", "concise", "json", "sarif"]
ColorChoice = Literal["auto", "always", "never"]

FORMATS: tuple[Format, ...] = ("human", "concise", "json", "sarif")
COLOR_CHOICES: tuple[ColorChoice, ...] = ("auto", "always", "never")

# Exit statuses of a command that reports diagnostics.
EXIT_OK, EXIT_ERRORS, EXIT_USAGE = 0, 1, 2

TAB_STOP = 4
# Snippet lines wider than this (in terminal cells) are cut to a window around the span.
SNIPPET_WIDTH = 120
_CONTEXT = 40  # code points kept before the span in a cut line
MESSAGE_LENGTH = 400  # code points of a message shown to people
_ELLIPSIS = "..."

SARIF_SCHEMA = "https://json.schemastore.org/sarif-2.1.0.json"
_SARIF_LEVELS = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.INFO: "note"}


@runtime_checkable
class Ordered(Protocol):
    """Diagnostics in sort_key's order already, which say their severities without being
    built: checker/compact.py's, a source's million syntax errors held as a few bytes
    each. A report writes them as they come, built one at a time, and counts them
    without building them (the module imports no checker: `rl1c explain` loads none)."""

    def __iter__(self) -> Iterator[Diagnostic]: ...

    def severities(self) -> Iterator[Severity]: ...


class FileDiagnostics(NamedTuple):
    """The diagnostics of one source file. `text` is None when the file could not be
    read or used (a configuration file); its diagnostics then say why (E0100) and have
    no place in the text, but a line whose column is 0: the line of a key."""

    name: str
    text: str | None
    diagnostics: Sequence[Diagnostic]


def _tool_version() -> str:
    # importlib.metadata costs milliseconds at start-up; only SARIF needs the version.
    from importlib.metadata import version

    return version("rl1")


def report(
    files: Sequence[FileDiagnostics],
    output_format: Format = "human",
    *,
    color: bool = False,
    action: str | None = "check",
) -> str:
    """The diagnostics of `files`, in the order given, as one text ending in a newline
    (empty for people when there is nothing to say): what `write_report` writes."""
    text = io.StringIO()
    write_report(text, files, output_format, color=color, action=action)
    return text.getvalue()


def write_report(
    stream: IO[str],
    files: Sequence[FileDiagnostics],
    output_format: Format = "human",
    *,
    color: bool = False,
    action: str | None = "check",
) -> None:
    """Writes the diagnostics of `files` on `stream`, in the order given, each as soon as
    it is rendered, so that a report of a million diagnostics never lies whole in memory
    (issue 23, item 10). `action` names what failed in the human closing line of each
    file: "could not check `x.rob`"; None leaves those lines out, for a command that
    ends with one `summary` of every file."""
    match output_format:
        case "json":
            _write_json(stream, files)
        case "sarif":
            _write_sarif(stream, files)
        case "concise":
            for file in files:
                for diagnostic in _ordered(file.diagnostics):
                    stream.write(concise_line(file, diagnostic))
        case "human":
            _write_human(stream, files, color, action)


def diagnostic_blocks(file: FileDiagnostics, *, color: bool = False) -> str:
    """The human text of `file`'s diagnostics with no closing summary, ending in one
    newline: what a command prints about a file other than the one it acts on (a sensor
    script that cannot be read), or of a fault at run time."""
    renderer = _HumanRenderer(file, color)
    return "".join(renderer.diagnostic(d) for d in _ordered(file.diagnostics)).rstrip("\n") + "\n"


def summary(files: Sequence[FileDiagnostics], fixed: int = 0, left: int = 0,
            unsafe: bool = False) -> str:
    """One line that counts the files and what was found in them: "3 files checked:
    0 errors, 1 warning", the files that could not be read (their E0100 is said above
    it), the problems `fixed` before, if any, and the `left` ones whose fix was not
    made: an unsafe one (without `unsafe`: --unsafe-fixes makes it), or one that
    follows from another fix (a second run makes it)."""
    read = [file for file in files if file.text is not None]
    unread = len(files) - len(read)
    if unread and not read:
        return f"no file checked: {_plural(unread, 'file')} could not be read\n"
    counts = _counts(file.diagnostics for file in read)
    errors, warnings = counts[Severity.ERROR], counts[Severity.WARNING]
    notes = [f"{_plural(fixed, 'problem')} fixed"] if fixed else []
    if left:
        notes.append(fixes_not_made(left, unsafe))
    return (f"{_plural(len(read), 'file')} checked: {_plural(errors, 'error')}, "
            f"{_plural(warnings, 'warning')}"
            + (f"; {_plural(unread, 'file')} could not be read" if unread else "")
            + (f" ({'; '.join(notes)})" if notes else "") + "\n")


def fixes_not_made(left: int, unsafe: bool) -> str:
    """Why `left` fixes were not made: unsafe (without `unsafe`), or, being unsafe or
    coming after an unsafe fix, they wait for another run (analysis.fix)."""
    if unsafe:
        return f"{_plural(left, 'fix', 'fixes')} left for another run to make"
    them = "it" if left == 1 else "them"
    return f"{_plural(left, 'unsafe fix', 'unsafe fixes')} not made: --unsafe-fixes makes {them}"


def exit_status(files: Sequence[FileDiagnostics]) -> int:
    """2 when a file could not be read, else 1 when any diagnostic is an error, else 0."""
    if any(file.text is None for file in files):
        return EXIT_USAGE
    if any(severity is Severity.ERROR for file in files
           for severity in _severities(file.diagnostics)):
        return EXIT_ERRORS
    return EXIT_OK


def use_color(choice: ColorChoice, stream: IO[Any]) -> bool:
    """`auto` colours only a terminal, and never when NO_COLOR is set (no-color.org) or
    the terminal is a dumb one (TERM=dumb: an editor's output pane, which shows escapes
    as text)."""
    if choice == "auto":
        return (stream.isatty() and not os.environ.get("NO_COLOR")
                and os.environ.get("TERM") != "dumb")
    return choice == "always"


def _ordered(diagnostics: Sequence[Diagnostic]) -> Iterable[Diagnostic]:
    if isinstance(diagnostics, Ordered):
        return diagnostics
    ordered = list(diagnostics)
    sort_by_place(ordered)
    return ordered


def _severities(diagnostics: Sequence[Diagnostic]) -> Iterator[Severity]:
    if isinstance(diagnostics, Ordered):
        return diagnostics.severities()
    return (diagnostic.severity for diagnostic in diagnostics)


def _counts(files: Iterable[Sequence[Diagnostic]]) -> dict[Severity, int]:
    """How many diagnostics of each severity the files have."""
    counts = dict.fromkeys(Severity, 0)
    for diagnostics in files:
        for severity in _severities(diagnostics):
            counts[severity] += 1
    return counts


# Human ------------------------------------------------------------------------------

# ANSI SGR escapes: a colour, then bold; _RESET ends both.
_RED, _GREEN, _YELLOW, _BLUE, _CYAN = (f"\x1b[{code}m" for code in (31, 32, 33, 34, 36))
_BOLD, _RESET = "\x1b[1m", "\x1b[0m"
_STYLES = {
    "error": _RED + _BOLD,
    "warning": _YELLOW + _BOLD,
    "info": _CYAN + _BOLD,
    "note": _GREEN + _BOLD,
    "help": _CYAN + _BOLD,
    "gutter": _BLUE + _BOLD,
    "message": _BOLD,
}


def _glyph(character: str, cell: int) -> str:
    """How `character` is shown at display cell `cell`: tabs become spaces, and
    characters that would act on the terminal instead of printing are made visible."""
    if character == "\t":
        return " " * (TAB_STOP - cell % TAB_STOP)
    code = ord(character)
    if code < 0x20:
        return chr(0x2400 + code)  # the Control Pictures block: ␀ to ␟
    if code == 0x7F:
        return "\u2421"  # ␡
    if shows_nothing(character):  # C1 controls, bidi overrides, private use...
        return f"<{code_point(character)}>"
    return character


def _cells(text: str) -> int:
    """Terminal cells taken by `text`: wide East Asian characters take two, combining
    marks none."""
    width = 0
    for character in text:
        if unicodedata.category(character) in ("Mn", "Me"):
            continue
        width += 2 if unicodedata.east_asian_width(character) in ("W", "F") else 1
    return width


def _visible(text: str) -> str:
    """`text` with the characters that would act on a terminal made visible, and cut
    to MESSAGE_LENGTH (a message may quote a whole line of a hostile input)."""
    if len(text) > MESSAGE_LENGTH:
        text = text[: MESSAGE_LENGTH - len(_ELLIPSIS)] + _ELLIPSIS
    if text.isascii() and text.isprintable():
        return text
    return "".join(_glyph(c, 0) if c != "\t" else " " for c in text)


def excerpt(line: str, first: int, last: int) -> tuple[str, int, int]:
    """How to show `line` with code points [first, last) underlined: the text shown, and
    the cell where the underline starts and its width (at least one cell). A line wider
    than SNIPPET_WIDTH is cut to a window around `first`, marked with `...`."""
    start = max(0, first - _CONTEXT) if len(line) > SNIPPET_WIDTH else 0
    pieces = [_ELLIPSIS] if start > 0 else []
    cell = len(pieces[0]) if pieces else 0
    limit = cell + SNIPPET_WIDTH
    starts: list[int] = []
    index = start
    while index < len(line) and cell < limit:
        glyph = _glyph(line[index], cell)
        starts.append(cell)
        pieces.append(glyph)
        cell += _cells(glyph)
        index += 1
    end_cell = cell
    cut_right = index < len(line)
    if cut_right:
        pieces.append(_ELLIPSIS)

    def cell_of(position: int) -> int:
        if position < index:
            return starts[position - start]
        # Past the shown text: hidden by the cut, or one cell per position past the end.
        return end_cell if cut_right else end_cell + position - len(line)

    caret = cell_of(first)
    return "".join(pieces), caret, max(1, cell_of(max(first, last)) - caret)


def _write_human(stream: IO[str], files: Sequence[FileDiagnostics], color: bool,
                 action: str | None) -> None:
    """Each file's diagnostics, then its closing line (with an `action`), the files
    apart by a blank line (with an `action`: each diagnostic ends in one, a file's
    closing line needs one after it). A file with nothing to say writes nothing."""
    separator = ""
    for file in files:
        if not file.diagnostics:
            continue
        stream.write(separator)
        renderer = _HumanRenderer(file, color)
        for diagnostic in _ordered(file.diagnostics):
            stream.write(renderer.diagnostic(diagnostic))
        if action is not None:
            stream.write(renderer.summary(action))
            separator = "\n"


class _HumanRenderer:
    """The rustc-like text of one file's diagnostics and its closing summary."""

    def __init__(self, file: FileDiagnostics, color: bool) -> None:
        self.file = file
        self.color = color
        self.lines = LineIndex(file.text if file.text is not None else "")

    def paint(self, text: str, role: str) -> str:
        return f"{_STYLES[role]}{text}{_RESET}" if self.color else text

    def diagnostic(self, diagnostic: Diagnostic) -> str:
        level = diagnostic.severity.value
        spans = [diagnostic.span, *(related.span for related in diagnostic.related)]
        gutter = max(len(str(max(span.line, span.end_line))) for span in spans)
        out = [
            self.paint(f"{level}[{diagnostic.code}]", level)
            + self.paint(f": {_visible(diagnostic.message)}", "message")
        ]
        out += self.snippet(diagnostic.span, gutter, level)
        if diagnostic.help:
            pad = " " * gutter
            help_lines = _visible_lines(diagnostic.help)
            out.append(self.paint(f"{pad} |", "gutter"))
            out.append(
                self.paint(f"{pad} = ", "gutter") + self.paint("help", "help") + ": "
                + ("\n" + " " * (gutter + 9)).join(help_lines)
            )
        for related in diagnostic.related:
            out.append(self.paint("note", "note") + self.paint(
                f": {_visible(related.message)}", "message"))
            out += self.snippet(related.span, gutter, "note")
        return "\n".join(out) + "\n\n"

    def snippet(self, span: Span, gutter: int, role: str) -> list[str]:
        """The ` --> file:line:col` line and the underlined source lines of `span`."""
        pad = " " * gutter
        if self.file.text is None:
            line = f":{span.line}" if span.column == 0 else ""
            return [self.paint(f"{pad}--> ", "gutter") + _visible(self.file.name) + line]
        where = f"{_visible(self.file.name)}:{span.line}:{max(span.column, 1)}"
        out = [self.paint(f"{pad}--> ", "gutter") + where]
        if not 1 <= span.line <= len(self.lines):
            return out  # a place past the end of the text: nothing to show
        out.append(self.paint(f"{pad} |", "gutter"))
        last_line = min(span.end_line, len(self.lines))
        for number in dict.fromkeys((span.line, last_line)):  # the first and last lines
            if number == last_line and last_line > span.line + 1:
                out.append(self.paint("...", "gutter"))
            line = self.lines[number - 1]
            first = span.column - 1 if number == span.line else 0
            last = span.end_column - 1 if number == span.end_line else len(line)
            shown, caret, width = excerpt(line, max(first, 0), last)
            # Only ASCII spaces are trimmed: a trailing U+3000 may be what is underlined.
            out.append(self.paint(f"{number:>{gutter}} |", "gutter") + f" {shown}".rstrip(" "))
            out.append(self.paint(f"{pad} |", "gutter") + " " * (caret + 1)
                       + self.paint("^" * width, role))
        return out

    def summary(self, action: str) -> str:
        counts = _counts([self.file.diagnostics])
        errors, warnings = counts[Severity.ERROR], counts[Severity.WARNING]
        emitted = ", ".join(
            _plural(count, noun) for count, noun in ((errors, "error"), (warnings, "warning"))
            if count
        )
        name = _visible(self.file.name)
        if errors:
            return (self.paint("error", "error")
                    + self.paint(f": could not {action} `{name}`: {emitted} emitted", "message")
                    + "\n")
        if warnings:
            return (self.paint("warning", "warning")
                    + self.paint(f": `{name}`: {emitted} emitted", "message") + "\n")
        return ""


def _visible_lines(text: str) -> list[str]:
    return [_visible(line) for line in split_lines(text)] or [""]


def _plural(count: int, noun: str, nouns: str | None = None) -> str:
    return f"{count} {noun}" if count == 1 else f"{count} {nouns or noun + 's'}"


# Concise ----------------------------------------------------------------------------


def concise_line(file: FileDiagnostics, diagnostic: Diagnostic) -> str:
    """`file:line:col: warning[W0301]: message`, the help left out: the form of gcc and
    ruff that problem matchers read. A file that could not be read is placed at 1:1."""
    span = diagnostic.span
    return (f"{_visible(file.name)}:{span.line}:{max(span.column, 1)}: "
            f"{diagnostic.severity.value}[{diagnostic.code}]: {_visible(diagnostic.message)}\n")


# JSON -------------------------------------------------------------------------------


def _write_json(stream: IO[str], files: Sequence[FileDiagnostics]) -> None:
    """One JSON array of the diagnostics, each written as it is rendered."""
    _write_array(stream, (_json_item(file, d) for file in files
                          for d in _ordered(file.diagnostics)), 0)
    stream.write("\n")


def _json_item(file: FileDiagnostics, d: Diagnostic) -> dict[str, Any]:
    return {
        "file": file.name,
        **_json_span(d.span),
        "severity": d.severity.value,
        "code": d.code,
        "message": d.message,
        "help": d.help,
        "fixes": [_json_fix(fix) for fix in d.fixes],
        "related": [{**_json_span(r.span), "message": r.message} for r in d.related],
    }


def _write_array(stream: IO[str], items: Iterator[object], depth: int) -> None:
    """The array of `items` as `_json_text` lays it out at nesting `depth` (the array's
    own), written an item at a time: its text is the same as of the whole list."""
    inner = "\n" + "  " * (depth + 1)
    separator = "[" + inner
    for item in items:
        stream.write(separator)
        stream.write(_json_text(item)[:-1].replace("\n", inner))
        separator = "," + inner
    stream.write("[]" if separator.startswith("[") else "\n" + "  " * depth + "]")


def _json_text(value: object) -> str:
    # Imported here, as the human format needs no JSON: `json` costs 2 ms of every start.
    import json

    # ASCII only: valid JSON whatever the encoding of the stream it is written to.
    return json.dumps(value, indent=2, ensure_ascii=True) + "\n"


def _json_span(span: Span) -> dict[str, int]:
    return {"line": span.line, "column": span.column,
            "end_line": span.end_line, "end_column": span.end_column}


def _json_fix(fix: Fix) -> dict[str, Any]:
    return {"title": fix.title, "applicability": "safe" if fix.safe else "unsafe",
            "edits": [{**_json_span(edit.span), "text": edit.text} for edit in fix.edits]}


# SARIF ------------------------------------------------------------------------------


# Where the results array lies in the SARIF log: its text is cut there, to write the
# results one at a time between the two halves.
_RESULTS_HOLE = '"results": []\n'
_RESULTS_DEPTH = 3  # the log, its runs, the run: the results array is at this nesting


def _write_sarif(stream: IO[str], files: Sequence[FileDiagnostics]) -> None:
    rule_index = {code: index for index, code in enumerate(CODES)}
    log = {
        "$schema": SARIF_SCHEMA,
        "version": "2.1.0",
        "runs": [{
            "tool": {"driver": {
                "name": "rl1c",
                "version": _tool_version(),
                "rules": [_sarif_rule(code) for code in CODES],
            }},
            "columnKind": "unicodeCodePoints",  # as our Span columns count
            "results": [],
        }],
    }
    head, hole, tail = _json_text(log).rpartition(_RESULTS_HOLE)
    assert hole, "the results are the last member of the run"
    stream.write(head + '"results": ')
    _write_array(stream, (_sarif_result(file, d, rule_index) for file in files
                          for d in _ordered(file.diagnostics)), _RESULTS_DEPTH)
    stream.write("\n" + tail)


def _sarif_rule(code: str) -> dict[str, Any]:
    info = CODES[code]
    explanation = info.explanation()
    return {
        "id": code,
        "shortDescription": {"text": info.title},
        "fullDescription": {"text": first_paragraph(explanation)},
        "help": {"text": explanation, "markdown": explanation},
        "defaultConfiguration": {"level": _SARIF_LEVELS[info.severity]},
    }


def first_paragraph(markdown: str) -> str:
    """The first paragraph of prose of an explanation, on one line (headings skipped)."""
    for paragraph in markdown.split("\n\n"):
        text = " ".join(line.strip() for line in paragraph.strip().splitlines())
        if text and not text.startswith("#"):
            return text
    return ""


def _sarif_result(
    file: FileDiagnostics, diagnostic: Diagnostic, rule_index: dict[str, int]
) -> dict[str, Any]:
    uri = artifact_uri(file.name)
    result: dict[str, Any] = {"ruleId": diagnostic.code}
    if diagnostic.code in rule_index:
        result["ruleIndex"] = rule_index[diagnostic.code]
    text = diagnostic.message + (f"\nhelp: {diagnostic.help}" if diagnostic.help else "")
    result["level"] = _SARIF_LEVELS[diagnostic.severity]
    result["message"] = {"text": text}
    # An unreadable file has no text, so its diagnostic has no region in it.
    has_text = file.text is not None
    result["locations"] = [_sarif_location(uri, diagnostic.span if has_text else None)]
    if diagnostic.related:
        result["relatedLocations"] = [
            {**_sarif_location(uri, related.span), "id": index,
             "message": {"text": related.message}}
            for index, related in enumerate(diagnostic.related)
        ]
    if diagnostic.fixes:
        result["fixes"] = [
            {
                "description": {"text": fix.title},
                "artifactChanges": [{
                    "artifactLocation": {"uri": uri},
                    "replacements": [
                        {"deletedRegion": _sarif_region(edit.span),
                         "insertedContent": {"text": edit.text}}
                        for edit in fix.edits
                    ],
                }],
            }
            for fix in diagnostic.fixes
        ]
    return result


def _sarif_location(uri: str, span: Span | None) -> dict[str, Any]:
    physical: dict[str, Any] = {"artifactLocation": {"uri": uri}}
    if span is not None:
        physical["region"] = _sarif_region(span)
    return {"physicalLocation": physical}


def _sarif_region(span: Span) -> dict[str, int]:
    return {"startLine": span.line, "startColumn": span.column,
            "endLine": span.end_line, "endColumn": span.end_column}


def artifact_uri(name: str) -> str:
    """The SARIF URI of a file named on the command line: the relative path as given,
    percent-encoded where a URI needs it; an absolute path becomes a file: URI. The
    path's bytes are encoded, so that a name that is not UTF-8 keeps its bytes."""
    from pathlib import Path  # only for SARIF: with urllib, 3 ms of every start
    from urllib.parse import quote

    path = Path(name)
    if path.is_absolute():
        return path.as_uri()
    return quote(os.fsencode(path.as_posix()))
