"""The editors' highlighting agrees with the compiler.

editors/vscode/test/expected/*.tokens record what VS Code's own TextMate engine makes of
Listing 1 and the edge cases (the extension's `npm test` keeps them true to the grammar).
Here every token the compiler's scanner finds must appear there at the same column,
with the same text and a scope of the matching class, so that highlighting splits every
line as the compiler does (`A=B--5` is B minus -5, `C--` a decrement). The editors'
lists of built-in functions must be the compiler's, and Neovim's syntax file (run in
Neovim or Vim when one is installed) colours each class.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest
from support import ROOT

from rl1.compiler.frontend.scanner import scan
from rl1.vm.language import BUILTINS, HANDLER_LABELS, RESERVED_VARIABLES

EDITORS = ROOT / "editors"
EXPECTED = sorted((EDITORS / "vscode" / "test" / "expected").glob("*.tokens"))

_LINE_HEADER = re.compile(r"(\d+): (.*)")
_TOKEN = re.compile(r' +(\d+)  ("(?:[^"\\]|\\.)*") +(.*)')

# The scope class each of the scanner's token kinds is highlighted as, when the kind
# alone decides it.
_SCOPE_OF_KIND = {
    "NUMBER": "constant.numeric.decimal",
    "QMARK": "keyword.control.conditional",
    "LPAR": "punctuation.section.parens.begin",
    "RPAR": "punctuation.section.parens.end",
    "_SEMI": "punctuation.separator.statement",
    "_COMMA": "punctuation.separator.arguments",
    "WORD": "invalid.illegal",
    "BADHEX": "invalid.illegal.hex",
    "BAD": "invalid.illegal.character.rl1",
}
_OPERATOR_SCOPES = {"+": "keyword.operator.arithmetic", "-": "keyword.operator.arithmetic",
                    "&": "keyword.operator.bitwise", "|": "keyword.operator.bitwise",
                    "^": "keyword.operator.bitwise"}
_SELECTORS = {
    builtin.mnemonic: "".join(form.selector or "" for form in builtin.forms)
    for builtin in BUILTINS.values() if builtin.has_selector
}


@dataclass(frozen=True)
class Highlight:
    column: int  # 1-based
    text: str
    scopes: tuple[str, ...]


def read_tokens(path: Path) -> list[tuple[str, dict[int, Highlight]]]:
    """Each source line of an expectation file with its tokens by column."""
    lines: list[tuple[str, dict[int, Highlight]]] = []
    for row in path.read_text(encoding="utf-8").splitlines():
        if row.startswith("#"):
            continue
        if header := _LINE_HEADER.fullmatch(row):
            assert int(header[1]) == len(lines) + 1, f"{path.name}: line {header[1]} out of order"
            lines.append((header[2], {}))
        elif token := _TOKEN.fullmatch(row):
            column = int(token[1])
            scopes = () if token[3] == "-" else tuple(token[3].split())
            lines[-1][1][column] = Highlight(column, json.loads(token[2]), scopes)
        else:
            raise AssertionError(f"{path.name}: unreadable line {row!r}")
    return lines


def expected_class(kind: str, text: str, before: list[tuple[str, str]]) -> str:
    """The scope class the compiler's reading of a token calls for; `before` holds the
    kinds and texts of the tokens before it on its line."""
    previous = before[-1] if before else ("", "")
    if kind == "LABEL":
        if before or len(text) != 3:
            return "invalid.illegal.label"
        return ("entity.name.label.handler" if int(text[1:]) in HANDLER_LABELS
                else "entity.name.label")
    if kind == "LABELREF":
        return "keyword.control.goto" if len(text) == 3 else "invalid.illegal.jump-target"
    if kind == "MNEMONIC":
        return ("support.function.builtin" if text.upper() in BUILTINS
                else "invalid.illegal.unknown-function")
    if kind == "VAR":
        if previous[0] == "MNEMONIC" and previous[1].upper() in _SELECTORS:
            valid = text.upper() in _SELECTORS[previous[1].upper()]
            return "constant.language.selector" if valid else "invalid.illegal.selector"
        return "variable.language.reserved" if text in RESERVED_VARIABLES else "variable.other"
    if kind == "HEX":
        return "constant.numeric.hex"
    if kind == "OPERATOR":
        return _OPERATOR_SCOPES[text]
    if kind == "INCDEC":
        return "keyword.operator.increment" if text == "++" else "keyword.operator.decrement"
    if kind in ("EQUAL", "LESS", "MORE"):
        if len(before) >= 2 and before[-2][0] == "QMARK" and previous[0] == "VAR":
            return "keyword.operator.comparison"
        if kind == "EQUAL":
            return "keyword.operator.assignment"
        return "keyword.operator.bitwise.shift"
    return _SCOPE_OF_KIND[kind]


def test_there_are_expectation_files_for_the_sample_and_the_edge_cases() -> None:
    names = {path.stem for path in EXPECTED}
    assert {"sample", "expressions", "calls", "labels", "comments"} <= names


@pytest.mark.parametrize("path", EXPECTED, ids=lambda path: path.name)
def test_textmate_tokens_are_the_scanners_tokens(path: Path) -> None:
    for number, (line, highlights) in enumerate(read_tokens(path), start=1):
        code = line.partition("'")[0]
        where = f"{path.name} line {number} {line!r}"
        before: list[tuple[str, str]] = []
        kinds, lexemes = scan(code)
        for kind, (text, start) in zip(kinds, lexemes, strict=True):
            column = start + 1
            highlight = highlights.get(column)
            assert highlight is not None and highlight.text == text, (
                f"{where}: the scanner reads {text!r} at column {column}, "
                f"the grammar {highlight}"
            )
            wanted = expected_class(kind, text, before)
            assert any(scope.startswith(wanted) for scope in highlight.scopes), (
                f"{where}: {text!r} at column {column} should be {wanted}, "
                f"is {highlight.scopes}"
            )
            before.append((kind, text))


def test_comments_are_highlighted_to_the_end_of_the_line() -> None:
    for path in EXPECTED:
        for line, highlights in read_tokens(path):
            quote = line.find("'")
            if quote < 0:
                continue
            rest = [h for column, h in highlights.items() if column > quote]
            assert rest and all("comment.line.quote.rl1" in h.scopes for h in rest), line


def _textmate_mnemonics() -> set[str]:
    grammar = json.loads((EDITORS / "vscode" / "syntaxes" / "rl1.tmLanguage.json")
                         .read_text(encoding="utf-8"))
    calls = grammar["repository"]["call"]["patterns"]
    names: set[str] = set()
    for rule in calls:
        if rule["beginCaptures"]["2"]["name"] == "support.function.builtin.rl1":
            found = re.search(r"\(\?i:([A-Z|]+)\)", rule["begin"])
            assert found is not None, rule["begin"]
            names.update(found[1].split("|"))
    return names


def test_the_textmate_grammar_knows_exactly_the_builtins() -> None:
    assert _textmate_mnemonics() == set(BUILTINS)


def test_the_emacs_mode_knows_exactly_the_builtins() -> None:
    source = (EDITORS / "emacs" / "rl1-mode.el").read_text(encoding="utf-8")
    found = re.search(r"\(defconst rl1-mnemonics\s+'\(([^)]*)\)", source)
    assert found is not None
    assert set(re.findall(r'"([A-Z]+)"', found[1])) == set(BUILTINS)


def _neovim_mnemonics() -> set[str]:
    source = (EDITORS / "nvim" / "syntax" / "rl1.vim").read_text(encoding="utf-8")
    found = re.search(r"^let s:builtins = '([A-Z ]*)'$", source, re.MULTILINE)
    assert found is not None, "syntax/rl1.vim: no `let s:builtins = '...'` line"
    return set(found[1].split())


def test_the_neovim_syntax_knows_exactly_the_builtins() -> None:
    assert _neovim_mnemonics() == set(BUILTINS)


# Each token of these lines, by its first column, with the syntax group that should
# colour it.
_VIM_CASES = {
    ":10 (mov 3,3); A=$FF+#20 ' (MOV) 日本": {
        1: "rl1Label", 6: "rl1Builtin", 10: "rl1Number", 11: "rl1Delimiter", 16: "rl1Variable",
        17: "rl1Operator", 18: "rl1Number", 22: "rl1Jump", 26: "rl1Comment", 29: "rl1Comment"},
    "?x=#96; B=C++": {1: "rl1Conditional", 2: "rl1Reserved", 3: "rl1Operator", 4: "rl1Jump",
                      9: "rl1Variable", 12: "rl1Operator"},
    ":97 (CAM P 5); (ult Q); (ULT a)": {
        1: "rl1Handler", 6: "rl1Builtin", 10: "rl1Selector", 12: "rl1Number",
        17: "rl1Builtin", 21: "rl1Error", 30: "rl1Selector"},
    "(FOO 1); ABC=:5; E=$12345; #1 日": {2: "rl1Error", 10: "rl1Error", 14: "rl1Error",
                                          20: "rl1Error", 28: "rl1Error", 31: "rl1Error"},
    " :96 A=1": {2: "rl1Handler", 6: "rl1Variable"},
}
_VIM = shutil.which("nvim") or shutil.which("vim")
# Writes the file type, then for each line the syntax group of each character (by byte),
# space-separated.
_DUMP_GROUPS = """
let rows = [&filetype]
for l in range(1, line('$'))
  call add(rows, join(map(range(1, col([l, '$']) - 1), 'synIDattr(synID(l, v:val, 1), "name")')))
endfor
call writefile(rows, 'groups.txt')
"""


def _run_vim(folder: Path, *commands: str, path: str | None = None) -> None:
    """Run `commands` in Neovim (or Vim) in `folder`, with no user configuration and
    editors/nvim on the runtime path."""
    assert _VIM is not None
    arguments = [argument for command in (*commands, "qa!") for argument in ("-c", command)]
    environment = {**os.environ, "PATH": path or os.environ["PATH"]}
    subprocess.run([_VIM, "-N", "-u", "NONE", "-i", "NONE", "-es",
                    "--cmd", f"set runtimepath^={EDITORS / 'nvim'}", *arguments],
                   cwd=folder, env=environment, check=True, timeout=60)


def _vim_groups(lines: list[str], folder: Path) -> list[list[str]]:
    """The syntax group of each character of `lines` as Neovim (or Vim) colours them in a
    `.rob` file, found by the file type detection of editors/nvim."""
    (folder / "case.rob").write_text("\n".join(lines) + "\n", encoding="utf-8")
    (folder / "dump.vim").write_text(_DUMP_GROUPS, encoding="utf-8")
    _run_vim(folder, "filetype on", "syntax on", "edit case.rob", "source dump.vim")
    filetype, *rows = (folder / "groups.txt").read_text(encoding="utf-8").splitlines()
    assert filetype == "rl1", f"{_VIM} took case.rob for {filetype!r}, not rl1"
    groups = []
    for line, row in zip(lines, rows, strict=True):
        by_byte = row.split(" ")
        # Columns count characters; Vim counts bytes.
        starts = [len(line[:i].encode()) for i in range(len(line))]
        groups.append([by_byte[start] for start in starts])
    return groups


@pytest.mark.skipif(_VIM is None, reason="neither nvim nor vim is installed")
def test_the_neovim_syntax_colours_each_class(tmp_path: Path) -> None:
    lines = list(_VIM_CASES)
    for line, groups in zip(lines, _vim_groups(lines, tmp_path), strict=True):
        for column, wanted in _VIM_CASES[line].items():
            assert groups[column - 1] == wanted, (
                f"{line!r} column {column} ({line[column - 1]!r}): {groups[column - 1]!r}, "
                f"not {wanted}")


@pytest.mark.skipif(_VIM is None, reason="neither nvim nor vim is installed")
def test_the_neovim_syntax_colours_every_builtin_in_any_case(tmp_path: Path) -> None:
    lines = [f"({name} 1); ({name.lower()} 1)" for name in sorted(BUILTINS)] + ["(XYZ 1)"]
    groups = _vim_groups(lines, tmp_path)
    for line, row in zip(lines[:-1], groups, strict=False):
        second = line.index("(", 1) + 1
        assert row[1] == row[second] == "rl1Builtin", line
    assert groups[-1][1] == "rl1Error"


# A stand-in for rl1c: records its arguments, prints concise lines and a summary.
_FAKE_RL1C = """#!/bin/sh
echo "$@" > arguments.txt
echo 'case.rob:12:5: warning[W0301]: a lost line can jump to `:97`: add it'
echo 'case.rob:3:17: error[E0100]: unexpected `*`'
echo '2 files checked: 1 error, 1 warning'
exit 1
"""
# Writes makeprg, then each quickfix entry as valid|line|column|type|text: an entry that
# is not valid (a line no pattern matched) still shows in the list, as `|| text`.
_DUMP_QUICKFIX = """
compiler rl1c
let rows = [&makeprg]
silent make
for item in getqflist()
  call add(rows, join([item.valid, item.lnum, item.col, item.type, item.text], '|'))
endfor
call writefile(rows, 'quickfix.txt')
"""


@pytest.mark.skipif(_VIM is None or shutil.which("sh") is None,
                    reason="neither nvim nor vim is installed, or no sh")
def test_the_neovim_compiler_file_fills_the_quickfix_list_from_concise_lines(
        tmp_path: Path) -> None:
    fake = tmp_path / "bin" / "rl1c"
    fake.parent.mkdir()
    fake.write_text(_FAKE_RL1C, encoding="utf-8")
    fake.chmod(0o755)
    (tmp_path / "case.rob").write_text("A=1\n", encoding="utf-8")
    (tmp_path / "dump.vim").write_text(_DUMP_QUICKFIX, encoding="utf-8")
    _run_vim(tmp_path, "edit case.rob", "source dump.vim",
             path=f"{fake.parent}{os.pathsep}{os.environ['PATH']}")
    makeprg, *entries = (tmp_path / "quickfix.txt").read_text(encoding="utf-8").splitlines()
    assert makeprg == "rl1c check --format concise %:S"
    assert (tmp_path / "arguments.txt").read_text(encoding="utf-8").split() == [
        "check", "--format", "concise", "case.rob"]
    # The summary line is no entry.
    assert entries == ["1|12|5|w|[W0301]: a lost line can jump to `:97`: add it",
                       "1|3|17|e|[E0100]: unexpected `*`"]


def test_the_neovim_workspace_root_is_the_folder_of_rl1_toml_first() -> None:
    """The server reads rl1.toml from the workspace (as `rl1c check` does from the file's
    folder up), so a folder with rl1.toml is a root even inside a bigger repository."""
    plugin = (EDITORS / "nvim" / "lua" / "rl1" / "init.lua").read_text(encoding="utf-8")
    found = re.search(r"root_markers = \{([^}]*)\}", plugin)
    assert found is not None, "init.lua sets no root_markers"
    assert re.findall(r"'([^']+)'", found[1])[0] == "rl1.toml"
