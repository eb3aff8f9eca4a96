"""Reducing a test case: a program, and its sensor script, made as small as they can be
while they stay interesting (a predicate says so: a shell command's exit status for
`rl1c reduce`, the engines' disagreement for `rl1c fuzz`), in creduce's manner.

Passes, each deterministic, run in turn until a round of them changes nothing, or until
the predicate has run a given number of times (a bound in tests rather than seconds, so
that a case gives the same result on a loaded machine as on an idle one):
- lines, then the label, statements and comment of each line, deleted in halves,
  quarters... down to one at a time;
- the terms of each assignment (`A=B+C-D` to `A=B-D`);
- each operand made smaller: 0 or 1 for a variable or a call, and a constant towards 0
  (0, 1, its sign made positive, halved);
- the sensor script's keys, readings and losses deleted, and its numbers made smaller
  as a constant's are;
and, at the end, the program in the canonical layout of the formatter and the script
written one key a line, each only if the case stays interesting.

A candidate is tested only once (the results are remembered by the candidate's digest),
and only when it is no larger than the original (so the result never is, whatever the
layouts) and as well-formed: a program the checker accepts stays one (engines compare
only such programs, and a bug found in one is seldom a bug of another), and a valid
sensor script stays valid (vm/sensor_script.py).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from typing import Any, TypeVar

from rl1.compiler.analysis import analyze
from rl1.compiler.formatter import format_text
from rl1.compiler.frontend import ast
from rl1.compiler.frontend.parser import parse_line
from rl1.compiler.frontend.source import LINE_BREAK, split_lines
from rl1.vm.sensor_script import ScriptError, decode_script


@dataclass(frozen=True)
class Case:
    """A program and the text of its sensor script (JSON), None without one."""

    source: str
    script: str | None = None

    @property
    def size(self) -> int:
        """Its bytes in UTF-8, the program's and the script's."""
        return len(self.source.encode()) + len((self.script or "").encode())


Interesting = Callable[[Case], bool]


@dataclass(frozen=True)
class Reduction:
    case: Case  # the smallest interesting case found
    tests: int  # how many times the predicate ran
    finished: bool  # the passes reached a fixpoint (False: the tests ran out first)


class NotInteresting(Exception):
    """The case to reduce is not interesting to begin with."""


class _Spent(Exception):
    """The tests allowed have all run."""


Progress = Callable[[str, Case, int], None]  # a pass's name, the case after it, tests


def reduce(case: Case, interesting: Interesting, *, max_tests: int,
           progress: Progress | None = None) -> Reduction:
    """The smallest case the passes find that `interesting` holds for, testing at most
    `max_tests` candidates (the original among them); NotInteresting when the original
    is not. `progress(pass, case, tests)` after each pass that made it smaller."""
    test = _Test(case, interesting, max(max_tests, 1))
    if not test(case):
        raise NotInteresting
    try:
        while True:
            before = case
            for name, run in PASSES:
                after = run(case, test)
                if after != case and progress is not None:
                    progress(name, after, test.tests)
                case = after
            if case == before:
                break
        after = _laid_out(case, test)
        if after != case and progress is not None:
            progress("layout", after, test.tests)
        return Reduction(after, test.tests, True)
    except _Spent:
        return Reduction(test.smallest, test.tests, False)


class _Test:
    """The predicate behind its memory of every candidate tried, the bound on its runs,
    and the original's well-formedness kept."""

    def __init__(self, original: Case, interesting: Interesting, max_tests: int) -> None:
        self.interesting = interesting
        self.max_tests = max_tests
        self.tests = 0
        self.seen: dict[bytes, bool] = {}  # a candidate's digest: whether it was interesting
        self.checked = _accepted(original.source)
        self.valid_script = original.script is not None and _valid_script(original.script)
        self.original = original
        self.smallest = original  # the last interesting candidate: the smallest so far

    def __call__(self, case: Case) -> bool:
        digest = hashlib.sha256(json.dumps([case.source, case.script]).encode()).digest()
        known = self.seen.get(digest)
        if known is not None:
            return known
        if case.size > self.original.size or (self.checked and not _accepted(case.source)) \
                or (self.valid_script and not _valid_script(case.script or "")):
            result = False
        else:
            if self.tests >= self.max_tests:
                raise _Spent
            self.tests += 1
            result = self.interesting(case)
        self.seen[digest] = result
        if result:
            self.smallest = case
        return result


def _accepted(source: str) -> bool:
    """Whether the checker accepts `source` (a checker that fails on it does not)."""
    try:
        return not analyze(source).has_errors
    except Exception:  # a bug of the checker may be what is being reduced
        return False


def _valid_script(text: str) -> bool:
    try:
        decode_script(text.encode(), "sensors.json")
    except ScriptError:
        return False
    return True


# Deleting ----------------------------------------------------------------------------

T = TypeVar("T")


def deleted(items: list[T], keeps: Callable[[list[T]], bool], *, empty: bool = False
            ) -> list[T]:
    """`items` without the runs of them that `keeps` does not need, trying none of them
    first when `empty`, then runs of half their number, of a quarter, down to single
    items; never empty unless `empty`."""
    if empty and items and keeps([]):
        return []
    size = len(items) // 2
    while size >= 1:
        start = 0
        while start < len(items):
            shorter = items[:start] + items[start + size:]
            if shorter and keeps(shorter):
                items = shorter
            else:
                start += size
        size //= 2
    return items


def _joined(lines: list[str], like: str) -> str:
    """`lines` as a text, each ended as the first line of `like` is."""
    end = LINE_BREAK.search(like)
    line_end = end.group() if end else "\n"
    return "".join(line + line_end for line in lines)


def _lines(case: Case, test: Interesting) -> Case:
    lines = split_lines(case.source)
    kept = deleted(lines, lambda shorter: test(replace(case, source=_joined(shorter,
                                                                           case.source))))
    return case if kept == lines else replace(case, source=_joined(kept, case.source))


def _line_edits(case: Case, test: Interesting,
                edit: Callable[[str, Callable[[str], bool]], str]) -> Case:
    """`edit(line, keeps)` on each line in turn, `keeps(new line)` testing the case with
    that line replaced."""
    lines, like, script = split_lines(case.source), case.source, case.script
    edited = False
    for row in range(len(lines)):
        def keeps(text: str, row: int = row) -> bool:
            return test(Case(_joined([*lines[:row], text, *lines[row + 1:]], like), script))

        changed = edit(lines[row], keeps)
        edited = edited or changed != lines[row]
        lines[row] = changed
    return Case(_joined(lines, like), script) if edited else case


def _parsed(text: str) -> ast.Line | None:
    line, _ = parse_line(text, 1)
    return line if line.ok else None


def _slice(text: str, span: ast.Span) -> str:
    return text[span.column - 1:span.end_column - 1]


def _items(case: Case, test: Interesting) -> Case:
    """The label, statements and comment of each line that the case does not need."""
    def edit(text: str, keeps: Callable[[str], bool]) -> str:
        line = _parsed(text)
        if line is None:
            return text
        items = ([("label", _slice(text, line.label.span))] if line.label else []) + [
            ("statement", _slice(text, statement.span)) for statement in line.statements] + (
            [("comment", _slice(text, line.comment.span))] if line.comment else [])

        def written(kept: list[tuple[str, str]]) -> str:
            label = [item for kind, item in kept if kind == "label"]
            code = ";".join(item for kind, item in kept if kind == "statement")
            comment = [item for kind, item in kept if kind == "comment"]
            return " ".join([*label, *([code] if code else []), *comment])

        kept = deleted(items, lambda shorter: keeps(written(shorter)))
        return text if kept == items else written(kept)

    return _line_edits(case, test, edit)


def _terms(case: Case, test: Interesting) -> Case:
    """The terms of each assignment that the case does not need: `A=B+C` to `A=B` or
    `A=C`."""
    def edit(text: str, keeps: Callable[[str], bool]) -> str:
        index = 0
        while (line := _parsed(text)) is not None and index < len(line.statements):
            statement = line.statements[index]
            if isinstance(statement, ast.Assign) and statement.rest:
                text = _assignment_terms(text, statement, keeps)
            index += 1
        return text

    return _line_edits(case, test, edit)


def _assignment_terms(text: str, statement: ast.Assign, keeps: Callable[[str], bool]
                      ) -> str:
    """The line `text` with the terms of its assignment `statement` that `keeps` does
    not need deleted (a first term left is written without its operator)."""
    terms = [_slice(text, statement.first.span)] + [
        step.op + _slice(text, step.operand.span) for step in statement.rest]
    start, end = statement.span.column - 1, statement.span.end_column - 1

    def written(kept: list[int]) -> str:
        first = terms[kept[0]] if kept[0] == 0 else terms[kept[0]][1:]
        rest = "".join(terms[index] for index in kept[1:])
        return f"{text[:start]}{statement.target.name}={first}{rest}{text[end:]}"

    everything = list(range(len(terms)))
    kept = deleted(everything, lambda shorter: keeps(written(shorter)))
    return text if kept == everything else written(kept)


def smaller_numbers(value: int) -> list[int]:
    """What a number is tried as, smallest first: 0, 1, itself made positive, half of
    it (towards 0); only those smaller than it (by size, then a positive before a
    negative of the same size)."""
    def order(number: int) -> tuple[int, bool]:
        return abs(number), number < 0

    tried = [0, 1, -value, int(value / 2)]
    return [number for number in dict.fromkeys(tried) if order(number) < order(value)]


def _operand_sites(line: ast.Line) -> Iterator[tuple[ast.Span, list[str]]]:
    """Each operand of the line that can be made smaller, and what it may become."""
    def arguments(call: ast.Call) -> Iterator[tuple[ast.Span, list[str]]]:
        for arg in call.args:
            yield from operand(arg)

    def operand(node: ast.Node) -> Iterator[tuple[ast.Span, list[str]]]:
        match node:
            case ast.Const(value=value, hex=hexadecimal):
                smaller = [str(number) for number in smaller_numbers(value)]
                # In hex, also the same value in decimal (`$FFFF` is -1), shorter.
                yield node.span, list(dict.fromkeys(["0", "1", str(value), *smaller])
                                      ) if hexadecimal else smaller
            case ast.Var():
                yield node.span, ["0", "1"]
            case ast.Call():
                yield node.span, ["0"]
                yield from arguments(node)

    for statement in line.statements:
        match statement:
            case ast.Assign(first=first, rest=rest):
                yield from operand(first)
                for step in rest:
                    yield from operand(step.operand)
            case ast.CallStmt(call=call):
                yield from arguments(call)


def _operands(case: Case, test: Interesting) -> Case:
    """Each operand made smaller while the case stays interesting: one site after
    another, a site tried again after each change (a constant halves again)."""
    def edit(text: str, keeps: Callable[[str], bool]) -> str:
        index = 0
        while (line := _parsed(text)) is not None:
            sites = list(_operand_sites(line))
            if index >= len(sites):
                break
            span, candidates = sites[index]
            smaller = next((changed for candidate in candidates if keeps(
                changed := text[:span.column - 1] + candidate + text[span.end_column - 1:])),
                None)
            if smaller is None:
                index += 1
            else:
                text = smaller
        return text

    return _line_edits(case, test, edit)


# The sensor script ------------------------------------------------------------------


def script_text(data: dict[str, Any]) -> str:
    """A sensor script as JSON, one key a line."""
    if not data:
        return "{}\n"
    return "{\n" + ",\n".join(f"  {json.dumps(key)}: {json.dumps(value)}"
                              for key, value in data.items()) + "\n}\n"


def _script(case: Case) -> dict[str, Any] | None:
    """The case's sensor script as JSON data; None when it has none, or one that is not
    a valid script in JSON (a TOML script, or anything nested deeper than a script's
    schema allows, is left as it is)."""
    if case.script is None or not _valid_script(case.script):
        return None
    data = json.loads(case.script)
    return data if isinstance(data, dict) else None


Path = tuple[str | int, ...]


def _containers(data: Any, path: Path = ()) -> Iterator[Path]:
    """The paths of the objects and lists in `data`, each before what it holds."""
    if isinstance(data, dict):
        yield path
        for key, value in data.items():
            yield from _containers(value, (*path, key))
    elif isinstance(data, list):
        yield path
        for index, value in enumerate(data):
            yield from _containers(value, (*path, index))


def _numbers(data: Any, path: Path = ()) -> Iterator[Path]:
    if isinstance(data, int) and not isinstance(data, bool):
        yield path
    elif isinstance(data, dict | list):
        for key, value in data.items() if isinstance(data, dict) else enumerate(data):
            yield from _numbers(value, (*path, key))


def _at(data: Any, path: Path) -> Any:
    for key in path:
        data = data[key]
    return data


def _with(data: Any, path: Path, value: Any) -> Any:
    """A copy of `data` with what is at `path` replaced by `value`."""
    if not path:
        return value
    key, *rest = path
    if isinstance(data, dict):
        return {**data, key: _with(data[key], tuple(rest), value)}
    copy = list(data)
    copy[key] = _with(copy[key], tuple(rest), value)  # type: ignore[index]
    return copy


def _script_items(case: Case, test: Interesting) -> Case:
    """The keys, readings and losses of the sensor script that the case does not need:
    of every object and list in it, the outermost first."""
    data = _script(case)
    if data is None:
        return case
    source, before, index = case.source, data, 0
    while index < len(paths := list(_containers(data))):
        data = _container_items(data, paths[index], lambda changed: test(Case(
            source, script_text(changed))))
        index += 1
    return case if data == before else Case(source, script_text(data))


def _container_items(data: Any, path: Path, keeps: Callable[[Any], bool]) -> Any:
    """`data` without the items of the object or list at `path` that `keeps` (given
    the script changed) does not need."""
    held = _at(data, path)
    items = list(held.items()) if isinstance(held, dict) else list(held)

    def rebuilt(kept: list[Any]) -> Any:
        return _with(data, path, dict(kept) if isinstance(held, dict) else kept)

    # An empty object or list is tried too: a script of none is valid, and an empty
    # list of readings is not (the script's validity, kept, refuses it with no test).
    kept = deleted(items, lambda shorter: keeps(rebuilt(shorter)), empty=True)
    return data if kept == items else rebuilt(kept)


def _script_numbers(case: Case, test: Interesting) -> Case:
    """Each number of the sensor script made smaller as a constant of the program is."""
    data = _script(case)
    if data is None:
        return case
    for path in list(_numbers(data)):
        while True:
            value = _at(data, path)
            smaller = next((changed for number in smaller_numbers(value) if test(replace(
                case, script=script_text(changed := _with(data, path, number))))), None)
            if smaller is None:
                break
            data = smaller
            case = replace(case, script=script_text(data))
    return case


def _laid_out(case: Case, test: Interesting) -> Case:
    """The program in the formatter's canonical layout, and the script one key a line,
    each when the case stays interesting so."""
    formatted = replace(case, source=format_text(case.source))
    if formatted != case and test(formatted):
        case = formatted
    data = _script(case)
    if data is not None:
        written = replace(case, script=script_text(data))
        if written != case and test(written):
            case = written
    return case


PASSES: tuple[tuple[str, Callable[[Case, Interesting], Case]], ...] = (
    ("lines", _lines),
    ("statements", _items),
    ("terms", _terms),
    ("operands", _operands),
    ("sensor readings", _script_items),
    ("sensor numbers", _script_numbers),
)
