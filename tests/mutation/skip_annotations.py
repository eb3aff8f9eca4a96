"""A cosmic-ray filter: marks as skipped the mutants of type annotations that Python
never evaluates, so that the figures count only mutants a test could kill.

Every module of rl1 begins with `from __future__ import annotations`, so a function's
parameter and return annotations, and the annotations of its local variables, stay
strings nobody reads at run time: `int | None` made `int & None` there runs the same
(a class body's annotations are left in, since msgspec and dataclasses read them).

Usage: python tests/mutation/skip_annotations.py SESSION.sqlite (after `cosmic-ray
init`, before `cosmic-ray exec`); tests/mutation/README.md has the whole sequence.
"""

from __future__ import annotations

import ast
import importlib
import sys
from collections.abc import Iterator
from functools import cache
from pathlib import Path
from typing import Any

# (line, column) as cosmic-ray counts them: lines from 1, columns in characters from 0.
Position = tuple[int, int]
Span = tuple[Position, Position]


def _annotations(function: ast.FunctionDef | ast.AsyncFunctionDef) -> Iterator[ast.expr]:
    arguments = function.args
    for argument in (*arguments.posonlyargs, *arguments.args, arguments.vararg,
                     *arguments.kwonlyargs, arguments.kwarg):
        if argument is not None and argument.annotation is not None:
            yield argument.annotation
    if function.returns is not None:
        yield function.returns
    for node in ast.walk(function):
        if isinstance(node, ast.AnnAssign):
            yield node.annotation


@cache
def unevaluated_annotations(path: Path) -> tuple[Span, ...]:
    """The spans of the annotations of `path` that are never evaluated: none unless the
    module postpones them."""
    source = path.read_text(encoding="utf-8")
    tree = ast.parse(source)
    postponed = any(isinstance(node, ast.ImportFrom) and node.module == "__future__"
                    and any(alias.name == "annotations" for alias in node.names)
                    for node in tree.body)
    if not postponed:
        return ()
    lines = source.splitlines()

    def position(line: int, byte_column: int) -> Position:
        # ast counts columns in UTF-8 bytes, cosmic-ray (parso) in characters.
        return line, len(lines[line - 1].encode()[:byte_column].decode())

    return tuple(
        (position(node.lineno, node.col_offset),
         position(node.end_lineno or node.lineno, node.end_col_offset or 0))
        for function in ast.walk(tree)
        if isinstance(function, ast.FunctionDef | ast.AsyncFunctionDef)
        for node in _annotations(function))


def within(inner: Span, spans: tuple[Span, ...]) -> bool:
    start, end = inner
    return any(low <= start and end <= high for low, high in spans)


def main(session: str) -> int:
    # cosmic-ray is the optional tool of this folder, not a dependency of the suite (or
    # of mypy's view of tests/): it is imported by name when the filter runs.
    work_db = importlib.import_module("cosmic_ray.work_db")
    work_item = importlib.import_module("cosmic_ray.work_item")
    skipped = work_item.WorkResult(output=None, test_outcome=None, diff=None,
                                   worker_outcome=work_item.WorkerOutcome.SKIPPED)
    count = 0
    with work_db.use_db(session, work_db.WorkDB.Mode.open) as db:
        item: Any
        for item in db.work_items:
            if all(within((tuple(m.start_pos), tuple(m.end_pos)),
                          unevaluated_annotations(Path(m.module_path)))
                   for m in item.mutations):
                db.set_result(item.job_id, skipped)
                count += 1
    print(f"{count} mutants of unevaluated annotations skipped")
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python tests/mutation/skip_annotations.py SESSION.sqlite")
    sys.exit(main(sys.argv[1]))
