"""spec/language.md agrees with the code it describes: the built-in table with
vm/language.py, the EBNF with grammar.lark, and the token examples with the scanner."""

import re

import pytest
from support import ROOT

from rl1.compiler.backend.codegen import generate
from rl1.compiler.backend.lower import lower
from rl1.compiler.frontend import ast
from rl1.compiler.frontend.make_tables import GRAMMAR
from rl1.compiler.frontend.parser import parse_line, parse_program
from rl1.compiler.frontend.scanner import scan
from rl1.compiler.interpreter import interpret
from rl1.compiler.reporting.catalogue import CODES
from rl1.vm import ilc, machine
from rl1.vm.language import BUILTINS, Feature
from rl1.vm.scripted import ScriptedDevice
from rl1.vm.verifier import verify

SPEC = (ROOT / "spec" / "language.md").read_text(encoding="utf-8")
NONE = "—"


# The built-in table ------------------------------------------------------------------


def _spec_table_rows() -> list[list[str]]:
    header = "| call | arguments | result | writes | waits | feature | what it does |"
    start = SPEC.index(header)
    rows = []
    for line in SPEC[start:].splitlines()[2:]:
        if not line.startswith("|"):
            break
        rows.append([cell.strip() for cell in line.strip("|").split("|")])
    return rows


def _number(text: str) -> int:
    return int(text[1:], 16) if text.startswith("$") else int(text)


def _row_of_form(mnemonic: str, selector: str | None) -> list[str]:
    """How vm/language.py says a form's row should read, in the spec's notation."""
    builtin = BUILTINS[mnemonic]
    form = builtin.form(selector)
    assert form is not None
    names = ",".join(param.name for param in form.params)
    call = "(" + " ".join(part for part in (mnemonic, selector, names) if part) + ")"
    return [
        f"`{call}`",
        "; ".join(f"{p.name}: {p.low}..{p.high}" for p in form.params) or NONE,
        form.result or NONE,
        ", ".join(form.writes) or NONE,
        "yes" if builtin.waits else "no",
        builtin.feature.name.lower() if builtin.feature else NONE,
        form.summary,
    ]


def _normalise(row: list[str]) -> list[str]:
    """The spec may write a range in hex (`$0..$7D`); compare numbers, not spellings."""
    ranges = re.sub(r"(-?\$?[0-9A-Fa-f]+)\.\.(-?\$?[0-9A-Fa-f]+)",
                    lambda m: f"{_number(m[1])}..{_number(m[2])}", row[1])
    return [row[0], ranges, *row[2:]]


def test_builtin_table_lists_every_form_of_builtins_py_in_order() -> None:
    forms = [(b.mnemonic, form.selector) for b in BUILTINS.values() for form in b.forms]
    rows = _spec_table_rows()
    assert len(rows) == len(forms)
    for row, (mnemonic, selector) in zip(rows, forms, strict=True):
        assert _normalise(row) == _row_of_form(mnemonic, selector), mnemonic


def test_every_feature_in_the_table_is_a_feature() -> None:
    named = {row[5] for row in _spec_table_rows()} - {NONE}
    assert named <= {feature.name.lower() for feature in Feature}


# Diagnostic codes ---------------------------------------------------------------------


def test_every_diagnostic_code_has_a_row_in_section_5_or_10() -> None:
    static = SPEC.split("## 5. Static rules", 1)[1].split("## 6.", 1)[0]
    faults = SPEC.split("## 10. Faults", 1)[1].split("## 11.", 1)[0]
    rows = set(re.findall(r"^\| ([EW]\d{4}) \|", static + faults, re.MULTILINE))
    assert set(CODES) <= rows


# The EBNF and grammar.lark ------------------------------------------------------------

# The EBNF quotes the punctuation tokens that grammar.lark names.
_QUOTED = {"<": "LESS", ">": "MORE", "=": "EQUAL", "?": "QMARK", "(": "LPAR", ")": "RPAR",
           ",": "_COMMA", ";": "_SEMI"}


def _rules(text: str, assign: str) -> dict[str, list[str]]:
    """Rule name to the body's tokens; `assign` is `::=` (EBNF) or `:` (lark)."""
    rules: dict[str, list[str]] = {}
    name = ""
    for line in text.splitlines():
        line = line.split("//")[0].rstrip()
        if not line or line.startswith("%"):
            continue
        head = re.match(rf"^([?_]?[a-z_]+)\s*{re.escape(assign)}\s*(.*)$", line)
        if head:
            name, body = head[1].lstrip("?_"), head[2]
            rules[name] = []
        else:
            body = line
        rules[name] += re.findall(r'"[^"]+"|[A-Za-z_]+|[()|*+?]', body)
    return rules


def _ebnf_block() -> str:
    return SPEC.split("```ebnf\n", 1)[1].split("```", 1)[0]


def test_ebnf_rules_are_grammar_lark_rules() -> None:
    def lark_token(token: str) -> str:
        return token.lstrip("_") if token.islower() else token

    def ebnf_token(token: str) -> str:
        return _QUOTED[token.strip('"')] if token.startswith('"') else token

    lark = {name: [lark_token(token) for token in body]
            for name, body in _rules(GRAMMAR.read_text(encoding="utf-8"), ":").items()}
    ebnf = {name: [ebnf_token(token) for token in body]
            for name, body in _rules(_ebnf_block(), "::=").items()}
    assert ebnf == lark


# Token examples of section 3 ----------------------------------------------------------


@pytest.mark.parametrize(("code", "tokens"), [
    ("B-5", ["VAR B", "OPERATOR -", "NUMBER 5"]),
    ("(IMG)-180", ["LPAR (", "MNEMONIC IMG", "RPAR )", "OPERATOR -", "NUMBER 180"]),
    ("d=-450", ["VAR d", "EQUAL =", "NUMBER -450"]),
    ("A=B+-5", ["VAR A", "EQUAL =", "VAR B", "OPERATOR +", "NUMBER -5"]),
    ("A=B--5", ["VAR A", "EQUAL =", "VAR B", "OPERATOR -", "NUMBER -5"]),
    ("A=B- -5", ["VAR A", "EQUAL =", "VAR B", "OPERATOR -", "NUMBER -5"]),
    ("@--", ["VAR @", "INCDEC --"]),
    ("(mov", ["LPAR (", "MNEMONIC mov"]),
    ("(X", ["LPAR (", "MNEMONIC X"]),
    ("AB", ["WORD AB"]),
    (":1 #123", ["LABEL :1", "LABELREF #123"]),
])
def test_tokens_are_as_section_3_says(code: str, tokens: list[str]) -> None:
    kinds, lexemes = scan(code)
    assert [f"{kind} {text}" for kind, (text, _) in zip(kinds, lexemes, strict=True)] == tokens


@pytest.mark.parametrize(("text", "code"), [
    ("A=-B", "E0101"), ("(MOV 3 -3)", "E0101"), ("A=-$10", "E0101"), ("AB=3", "E0103"),
    ("A=1; :10", "E0104"), ("A=$G1", "E0105"), ("A=$10000", "E0105"), ("A=1 B=2", "E0101"),
    ("A=1．", "E0102"),
])
def test_lines_the_spec_calls_errors_are_errors(text: str, code: str) -> None:
    _, diagnostics = parse_line(text, 1)
    assert [d.code for d in diagnostics] == [code]


@pytest.mark.parametrize("text", [
    ":13", ";", ":12 c=579; d=450;", "(CAM A 90)", "(MVI 1,1,50)", "(MOV 3 3)", "(CAM A,-5)",
    "A=$FFFF", "A=$00FF", ":10A=1", "\t ' 空白だけ",
])
def test_lines_the_spec_accepts_parse(text: str) -> None:
    line, diagnostics = parse_line(text, 1)
    assert diagnostics == [] and line.ok


def test_hex_is_a_bit_pattern_and_selectors_are_letters() -> None:
    line, _ = parse_line("A=$8000; (CAM P c); (ULT A)", 1)
    assign, cam, ult = line.statements
    assert isinstance(assign, ast.Assign) and isinstance(assign.first, ast.Const)
    assert assign.first.value == -32768
    assert isinstance(cam, ast.CallStmt) and isinstance(ult, ast.CallStmt)
    assert [type(arg) for arg in cam.call.args] == [ast.Selector, ast.Var]
    assert [type(arg) for arg in ult.call.args] == [ast.Selector]


# The arithmetic examples of section 7.2, on both engines -------------------------------


def _expression_examples() -> list[tuple[str, int]]:
    section = SPEC.split("### 7.2 Expressions", 1)[1].split("### 7.3", 1)[0]
    rows = re.findall(r"^\| `(A=[^`]+)` \| (-?\d+)", section, re.MULTILINE)
    return [(code, int(value)) for code, value in rows]


def test_section_7_2_has_its_examples() -> None:
    assert len(_expression_examples()) >= 10


@pytest.mark.parametrize(("code", "value"), _expression_examples())
def test_arithmetic_examples_hold_in_the_interpreter_and_the_vm(code: str, value: int) -> None:
    program, diagnostics = parse_program(code)
    assert diagnostics == []
    interpreted = interpret(program, ScriptedDevice())
    compiled = machine.run(verify(ilc.encode(generate(lower(program), "spec.rob"))),
                           ScriptedDevice())
    assert interpreted.named()["A"] == compiled.named()["A"] == value
