"""Where a key path is written in a TOML or JSON file: the line a message names.

tomllib and json give no positions, and msgspec's errors give a key path. `entries`
walks a document's text once (it is linear in the text, however long a key or string
is), yielding each key and array element with its path and line, in the order written;
`line_of` takes the line of the path, or of the nearest enclosing entry written.

The scanners read documents that their parser has accepted, up to the point where it
stopped (`first_long_number` looks for the integer that stopped it), so they need not
diagnose anything: on text they do not expect they just stop yielding.
"""

from __future__ import annotations

import json
import re
import tomllib
from collections.abc import Callable, Iterator
from typing import Literal

KeyPath = tuple[str | int, ...]
Entry = tuple[KeyPath, int, str]  # a path, its line (1-based), a scalar's text or ""

BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")
"""A TOML key written without quotes; any other is written in them."""
_QUOTE_OR_ESCAPE = re.compile(r'["\\]')
_SCALAR = re.compile(r"[^,\]}#\r\n]*")
_SPACE = " \t"


def line_of(text: str, path: KeyPath, syntax: Literal["toml", "json"]) -> int | None:
    """The line where `path` is written, or the line of its longest prefix that is
    (a missing key: its table); None when not even its first key is written."""
    best: tuple[int, int] | None = None  # (length of the prefix, line)
    for found, line, _ in entries(text, syntax):
        if found == path:
            return line
        if len(found) < len(path) and path[:len(found)] == found and (
                best is None or len(found) > best[0]):
            best = (len(found), line)
    return best[1] if best is not None else None


def first_long_number(text: str, syntax: Literal["toml", "json"],
                      digits: int) -> tuple[int, KeyPath] | None:
    """The line and path of the first integer of more than `digits` digits (of any base:
    TOML's 0x, 0o and 0b integers too)."""
    for path, line, scalar in entries(text, syntax):
        if sum(c.isalnum() for c in scalar) > digits and not scalar.startswith(('"', "'")):
            return line, path
    return None


def entries(text: str, syntax: Literal["toml", "json"]) -> Iterator[Entry]:
    """Each key and array element of `text` with its path and line, in order."""
    scanner = _Scanner(text)
    return scanner.toml() if syntax == "toml" else scanner.json_value(())


class _Scanner:
    def __init__(self, text: str) -> None:
        self.text = text
        self.at = 0
        self.line = 1

    # Characters

    def peek(self, count: int = 1) -> str:
        return self.text[self.at:self.at + count]

    def skip_space(self, newlines: bool) -> None:
        """Skip blanks and, when `newlines`, line ends and comments too."""
        text = self.text
        while self.at < len(text):
            char = text[self.at]
            if char in _SPACE:
                self.at += 1
            elif newlines and char == "\n":
                self.at += 1
                self.line += 1
            elif newlines and char == "\r":
                self.at += 1
            elif newlines and char == "#":
                end = text.find("\n", self.at)
                self.at = len(text) if end < 0 else end
            else:
                return

    def advance_to(self, end: int) -> None:
        """Move to `end`, counting the line ends passed."""
        self.line += self.text.count("\n", self.at, end)
        self.at = end

    def string(self) -> str:
        """A quoted string's text, quotes included, moving past it."""
        text, start = self.text, self.at
        quote = text[start]
        triple = text.startswith(quote * 3, start)
        at = start + (3 if triple else 1)
        if quote == "'":  # a literal string has no escapes
            end = text.find("'''" if triple else "'", at)
            at = len(text) if end < 0 else end
        else:
            while (stop := _QUOTE_OR_ESCAPE.search(text, at)) is not None:
                at = stop.start()
                if text[at] == "\\":
                    at += 2
                elif triple and not text.startswith('"""', at):
                    at += 1
                else:
                    break
            else:
                at = len(text)
        at += 3 if triple else 1
        while triple and at < len(text) and text[at] == quote:  # up to two more quotes
            at += 1
        self.advance_to(min(at, len(text)))
        return text[start:self.at]

    # TOML

    def toml(self) -> Iterator[Entry]:
        table: KeyPath = ()
        arrays: dict[KeyPath, int] = {}  # each array of tables, by its path: its length
        text = self.text
        while True:
            self.skip_space(newlines=True)
            if self.at >= len(text):
                return
            line = self.line
            if text.startswith("[[", self.at):
                self.at += 2
                keys = self.toml_keys()
                parent = self._resolve(keys[:-1], arrays)
                array = (*parent, keys[-1])
                arrays[array] = arrays.get(array, 0) + 1
                table = (*array, arrays[array] - 1)
                yield array, line, ""
                yield table, line, ""
                self._to_line_end()
            elif text.startswith("[", self.at):
                self.at += 1
                table = self._resolve(self.toml_keys(), arrays)
                yield table, line, ""
                self._to_line_end()
            else:
                keys = self.toml_keys()
                if not keys or self.peek() != "=":
                    return
                self.at += 1
                yield from self.toml_value((*table, *keys), line)

    @staticmethod
    def _resolve(keys: KeyPath, arrays: dict[KeyPath, int]) -> KeyPath:
        """A header's dotted keys as a path: a key naming an array of tables stands for
        its last table."""
        path: KeyPath = ()
        for key in keys:
            path = (*path, key)
            if path in arrays:
                path = (*path, arrays[path] - 1)
        return path

    def _to_line_end(self) -> None:
        end = self.text.find("\n", self.at)
        self.at = len(self.text) if end < 0 else end

    def toml_keys(self) -> KeyPath:
        """Dotted keys up to `=` or `]`, past the `]`s of a header."""
        keys: list[str | int] = []
        text = self.text
        while True:
            self.skip_space(newlines=False)
            char = self.peek()
            if char in ('"', "'"):
                token = self.string()
                keys.append(tomllib.loads(f"k = {token}")["k"] if "\\" in token else token[1:-1])
            elif (bare := BARE_KEY.match(text, self.at)) is not None:
                keys.append(bare.group())
                self.at = bare.end()
            else:
                return tuple(keys)
            self.skip_space(newlines=False)
            if self.peek() != ".":
                while self.peek() == "]":
                    self.at += 1
                self.skip_space(newlines=False)
                return tuple(keys)
            self.at += 1

    def toml_value(self, path: KeyPath, line: int) -> Iterator[Entry]:
        self.skip_space(newlines=False)
        char = self.peek()
        if char == "[":
            yield from self.array(path, line, lambda item: self.toml_value(item, self.line),
                                  lambda: self.skip_space(newlines=True))
        elif char == "{":
            yield path, line, ""
            self.at += 1
            while True:
                self.skip_space(newlines=True)
                if self.peek() in ("}", ""):
                    self.at += 1
                    return
                key_line = self.line
                keys = self.toml_keys()
                if not keys or self.peek() != "=":
                    return
                self.at += 1
                yield from self.toml_value((*path, *keys), key_line)
                self.skip_space(newlines=True)
                if self.peek() == ",":
                    self.at += 1
        elif char in ('"', "'"):
            yield path, line, self.string()
        else:
            yield path, line, self._scalar()

    def array(self, path: KeyPath, line: int, item: Callable[[KeyPath], Iterator[Entry]],
              skip: Callable[[], None]) -> Iterator[Entry]:
        """An array at its `[`, in either syntax: its own entry, then each item's, read by
        `item` at the item's path; `skip` passes what the syntax allows between them."""
        yield path, line, ""
        self.at += 1
        index = 0
        while True:
            skip()
            if self.peek() in ("]", ""):
                self.at += 1
                return
            yield from item((*path, index))
            index += 1
            skip()
            if self.peek() == ",":
                self.at += 1

    def _scalar(self) -> str:
        """A number, boolean or date: up to the next separator."""
        scalar = _SCALAR.match(self.text, self.at)
        assert scalar is not None  # it matches the empty string
        self.at = scalar.end()
        return scalar.group().rstrip()

    # JSON

    def json_value(self, path: KeyPath) -> Iterator[Entry]:
        self.skip_json_space()
        line, char = self.line, self.peek()
        if char == "[":
            yield from self.array(path, line, self.json_value, self.skip_json_space)
        elif char == "{":
            yield path, line, ""
            self.at += 1
            while True:
                self.skip_json_space()
                if self.peek() != '"':
                    self.at += 1
                    return
                key = json.loads(self.string())
                self.skip_json_space()
                if self.peek() != ":":
                    return
                self.at += 1
                yield from self.json_value((*path, key))
                self.skip_json_space()
                if self.peek() == ",":
                    self.at += 1
        elif char == '"':
            yield path, line, self.string()
        else:
            yield path, line, self._scalar()

    def skip_json_space(self) -> None:
        text = self.text
        while self.at < len(text) and text[self.at] in " \t\r\n":
            if text[self.at] == "\n":
                self.line += 1
            self.at += 1
