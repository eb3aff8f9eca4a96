"""The configuration files' one validation layer (rl1.vm.config) and its locator of
lines (rl1.vm.config_lines): the line of every key path, the bounded reader of numbers,
short excerpts, and a byte order mark."""

from __future__ import annotations

import json
import tomllib
import tracemalloc
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rl1.vm.config import MAX_DIGITS, ConfigError, describe_path, read_document
from rl1.vm.config_lines import KeyPath, entries, first_long_number, line_of
from rl1.vm.sensor_script import ScriptError, decode_script

# Documents, and a writer that records the line of each key it writes -----------------

keys = st.text(alphabet="ab_-. \"'#[]=\\é", min_size=1, max_size=4)
scalars = (st.integers(-10**30, 10**30) | st.booleans() | st.floats(allow_nan=False)
           | st.text(alphabet=st.characters(max_codepoint=0xFFFF, codec="utf-8",
                                               exclude_characters="\x7f"),
                     max_size=6))


def _documents(depth: int) -> st.SearchStrategy[dict[str, Any]]:
    values: st.SearchStrategy[Any] = scalars | st.lists(scalars, max_size=3)
    if depth > 0:
        inner = _documents(depth - 1)
        values = values | inner | st.lists(inner, min_size=1, max_size=2)
    return st.dictionaries(keys, values, max_size=4)


documents = _documents(2)


def _key(key: str) -> str:
    bare = key and all(c.isascii() and (c.isalnum() or c in "_-") for c in key)
    return key if bare else json.dumps(key)


def _scalar(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(value) if isinstance(value, float) else json.dumps(value)


class TomlWriter:
    """A document as TOML: scalars and arrays (one element a line) first, then tables
    under headers and arrays of tables under [[headers]]; `lines` records each path."""

    def __init__(self) -> None:
        self.out: list[str] = []
        self.lines: dict[KeyPath, int] = {}

    def note(self, path: KeyPath) -> None:
        self.lines.setdefault(path, len(self.out) + 1)

    def table(self, document: dict[str, Any], path: KeyPath) -> None:
        def is_table(value: object) -> bool:
            return isinstance(value, dict)

        def is_tables(value: object) -> bool:
            return isinstance(value, list) and bool(value) and all(map(is_table, value))

        for key, value in document.items():
            if is_table(value) or is_tables(value):
                continue
            self.note((*path, key))
            if isinstance(value, list):
                self.out.append(f"{_key(key)} = [")
                for i, item in enumerate(value):
                    self.note((*path, key, i))
                    self.out.append(f"  {_scalar(item)},  # [x]")
                self.out.append("]")
            else:
                self.out.append(f"{_key(key)} = {_scalar(value)}")
        for key, value in document.items():
            header = ".".join(_key(k) for k in (*path, key) if isinstance(k, str))
            if is_table(value):
                self.note((*path, key))
                self.out.append(f"[{header}]")
                self.table(value, (*path, key))
            elif is_tables(value):
                for i, item in enumerate(value):
                    self.note((*path, key))
                    self.note((*path, key, i))
                    self.out.append(f"[[{header}]]")
                    self.table(item, (*path, key, i))


@settings(max_examples=300, deadline=None)
@given(documents)
def test_the_locator_finds_the_line_of_every_key_the_writer_wrote(
        document: dict[str, Any]) -> None:
    writer = TomlWriter()
    writer.table(document, ())
    text = "\n".join(writer.out) + "\n"
    assert tomllib.loads(text) == document  # the writer wrote the document
    for path, line in writer.lines.items():
        assert line_of(text, path, "toml") == line, (path, text)


@settings(max_examples=300, deadline=None)
@given(documents)
def test_in_json_every_key_on_its_own_line_is_found_there(document: dict[str, Any]) -> None:
    text = json.dumps(document, indent=1)
    rows = text.splitlines()
    for path, line, _ in entries(text, "json"):
        if path and isinstance(path[-1], str):
            assert rows[line - 1].lstrip().startswith(json.dumps(path[-1]) + ":")
        assert line_of(text, path, "json") == line


def test_a_missing_key_is_placed_at_its_table() -> None:
    text = "a = 1\n[t]\nb = 2\n\n[[s]]\nx = 1\n[[s]]\ny = 2\n"
    assert line_of(text, ("t", "nothing"), "toml") == 2
    assert line_of(text, ("s", 1, "x"), "toml") == 7
    assert line_of(text, ("nothing",), "toml") is None


# The bounded reader ------------------------------------------------------------------


@pytest.mark.parametrize(("syntax", "text", "line", "where"), [
    ("toml", 'a = 1\ns = "' + "9" * 5000 + '"\n[ports]\n"3" = ' + "9" * 5000 + "\n", 4,
     "ports.3"),
    ("json", '{"a": "' + "9" * 5000 + '",\n "INP": {"3": [1,\n ' + "9" * 5000 + "]}}", 3,
     "INP.3[1]"),
])
def test_a_number_too_long_to_read_is_an_error_at_its_line(
        syntax: str, text: str, line: int, where: str) -> None:
    with pytest.raises(ConfigError) as refused:
        read_document(text.encode(), "f", syntax)  # type: ignore[arg-type]
    assert (refused.value.line, refused.value.where) == (line, where)
    assert f"more than {MAX_DIGITS} digits" in str(refused.value)
    assert len(str(refused.value)) < 200  # no digits quoted


def test_first_long_number_skips_strings_and_comments() -> None:
    text = '# 9999999999\nk = "99999999999"\nn = 123\nm = 99_999_999_999\n'
    assert first_long_number(text, "toml", 10) == (4, ("m",))


@pytest.mark.parametrize("syntax", ["toml", "json"])
def test_a_byte_order_mark_is_accepted(syntax: str) -> None:
    text = "a = 1\n" if syntax == "toml" else '{"a": 1}'
    document, _ = read_document(b"\xef\xbb\xbf" + text.encode(), "f", syntax)  # type: ignore[arg-type]
    assert document == {"a": 1}


def test_json_has_no_nan() -> None:
    with pytest.raises(ConfigError, match="NaN is not a JSON number"):
        read_document(b'{"a": NaN}', "f", "json")


@pytest.mark.parametrize(("text", "where"), [
    ('{"comment": "",\n"\\ud800": 1}', "s.json:2: \ud800"),  # a key
    ('{\n"line_lost": [{"during": "\\udc00", "nth": 1, "after": 1}]}',
     "s.json:2: line_lost[0].during"),
    ('{"line_lost": [{"during": "MOV\\ud83d", "nth": 1, "after": 1}]}',
     "s.json:1: line_lost[0].during"),
])
def test_a_json_string_with_half_a_utf16_pair_is_an_error_at_its_key(
        text: str, where: str) -> None:
    # JSON's reader takes the escape; msgspec failed on it with UnicodeEncodeError.
    with pytest.raises(ScriptError) as refused:
        decode_script(text.encode(), "s.json")
    assert str(refused.value).startswith(f"{where}: a string holds half of a UTF-16 pair")


def test_a_json_string_with_a_whole_utf16_pair_is_its_character() -> None:
    document, _ = read_document(b'{"a": "\\ud83d\\ude00 \\\\ud800"}', "f", "json")
    assert document == {"a": "\U0001f600 \\ud800"}


# Messages quote excerpts, and a huge key costs time linear in it ---------------------


def test_a_key_path_is_quoted_in_short() -> None:
    assert describe_path(("ports", "k" * 3_000_000, 2)) == "ports." + "k" * 40 + "...[2]"


def test_locating_a_3_mb_key_is_linear_and_small() -> None:
    key = "k" * 3_000_000
    text = f'[floor]\nsize = [1, 2]\n[ports]\n"{key}" = 1\n'
    tracemalloc.start()
    line = line_of(text, ("ports", key), "toml")
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert line == 4
    # The regex locator took 375 MB (and 6 s) here; linear work keeps a few copies.
    assert peak < 10 * len(key)
