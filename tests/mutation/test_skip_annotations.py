"""The cosmic-ray filter of tests/mutation: which mutants it takes for mutants of
annotations that are never evaluated (it needs no cosmic-ray to be tested)."""

from __future__ import annotations

from pathlib import Path

from skip_annotations import unevaluated_annotations, within

MODULE = '''from __future__ import annotations

class Reading:
    value: int | None = None

def scaled(reading: Reading | None, *, by: int = 2 | 1) -> int | None:
    total: int | None = by - 1
    return total
'''


def spans_of(tmp_path: Path, text: str) -> tuple[tuple[tuple[int, int], tuple[int, int]], ...]:
    module = tmp_path / "module.py"
    module.write_text(text, encoding="utf-8")
    return unevaluated_annotations(module)


def test_a_functions_annotations_are_taken_and_nothing_else(tmp_path: Path) -> None:
    spans = spans_of(tmp_path, MODULE)
    lines = MODULE.splitlines()
    texts = sorted(lines[start[0] - 1][start[1]:end[1]] for start, end in spans)
    assert texts == ["Reading | None", "int", "int | None", "int | None"]
    # The `|` of `Reading | None` is in one; that of the default `2 | 1` and of the
    # class's annotation (which dataclasses and msgspec read) are not.
    def bar(line: int, after: str) -> tuple[tuple[int, int], tuple[int, int]]:
        column = lines[line - 1].index("|", lines[line - 1].index(after))
        return (line, column), (line, column + 1)

    assert within(bar(6, "Reading"), spans)
    assert not within(bar(6, "2"), spans)
    assert not within(bar(4, "int"), spans)


def test_a_module_that_evaluates_its_annotations_has_none_taken(tmp_path: Path) -> None:
    assert spans_of(tmp_path, MODULE.replace("from __future__ import annotations\n", "")) == ()


def test_columns_are_counted_in_characters(tmp_path: Path) -> None:
    text = 'from __future__ import annotations\ndef f(é: int) -> int: return é\n'
    ((start, end), (return_start, _)) = spans_of(tmp_path, text)
    assert (start, end) == ((2, 9), (2, 12))
    assert return_start == (2, 17)
