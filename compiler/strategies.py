"""Hypothesis strategies that generate RL/I source text, for fuzzing the toolchain.

For us and for anyone testing a tool that reads RL/I (an interpreter, a device
simulator, an editor plug-in):

- `lines()`: one line of source, syntactically valid (it parses without a diagnostic),
  covering every construct: labels, every statement, every operator, every built-in form
  with constant and variable arguments, decimal, negative and hex constants, comments in
  any script, empty statements, and odd spacing (tabs, no spaces, spaces everywhere).
  It need not pass the checker (a jump may name no label, an argument may be out of
  range, a call without a result may be an operand).
- `programs()`: whole sources of such lines, with LF, CR LF or CR line ends.
- `checked_programs()`: programs the checker accepts without errors and that always end:
  loops are counted (a counter set to a small constant, stepped, tested), other jumps go
  forward, handlers `:96`-`:99` end with `(END)`, every argument is in range (a variable
  argument is set just before its call). Their expressions use every operator with
  constants chosen to hit the edges: wrap-around at both ends, shift counts below 0 and
  of 16 or more. Mixed in are the shapes each optimizer pass rewrites, so that every
  pass has work in some of them (spec/optimization.md): if-else ways that end alike (or
  nearly), and loops whose body ends as the code before them does; equal operands
  (`A=P-P`), steps written as additions (`A=A+1`), copies then their uses, stores
  overwritten before they are read, and branches on a variable inside the way a branch
  on it fell through, mostly on a sensor's reading (a value no pass knows). Use them to
  run two engines side by side:

      from hypothesis import given
      from rl1.compiler.strategies import checked_programs

      @given(checked_programs())
      def test_engines_agree(source: str) -> None:
          assert interpreter_run(source) == vm_run(source)

- `runs()`: a `Run`, a program the checker accepts and the sensor script to run it on
  (a dict as a JSON script file holds it). Beyond counted loops, its programs wait in
  loops that a sensor reading ends (the script's last readings end every such loop),
  lose the guidance line in tracing modes 2 and 3 (the script's `line_lost` entries) and
  enter handlers that end, or jump back into the program and so are entered again, or
  are missing (and, when asked, lose the line between calls, after an instruction
  count); and some pass a variable argument out of its range or ask the device for
  a move it refuses, so that runs fault. Most runs end within a small budget; a few
  meet the watchdog.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass, field

try:
    from hypothesis import strategies as st
except ModuleNotFoundError as missing:  # an optional part of rl1: pyproject.toml's `fuzz`
    raise ModuleNotFoundError("rl1.compiler.strategies generates programs with Hypothesis, "
                              "which is not installed here: pip install 'rl1[fuzz]'",
                              name="hypothesis") from missing

from rl1.vm.language import BUILTINS, HANDLER_LABELS, RESERVED_VARIABLES, VARIABLES, Form

Tokens = tuple[str, ...]

OPERATORS = ("+", "-", "&", "|", "^", "<", ">")
RELATIONS = ("=", ">", "<")

# Values where 16-bit arithmetic and shifts change behaviour.
EDGE_VALUES = (0, 1, -1, 2, -2, 7, 15, 16, 17, 31, -15, -16, -17, 255, 256, 1000,
               16383, 16384, 32766, 32767, -32767, -32768)

# Comment text: any printable text, and Japanese as the paper's authors wrote it.
JAPANESE = ("誘導ラインを追尾", "分岐マークで停止", "作業台に接近", "カメラを原点へ",
            "全角　スペース", "ﾊﾝｶｸ", "①②③", "異常時ジャンプ先")

_WORD_CHARACTERS = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                             "0123456789@$")
_FORMS: tuple[tuple[str, Form], ...] = tuple(
    (builtin.mnemonic, form) for builtin in BUILTINS.values() for form in builtin.forms
)
_VALUE_FORMS = tuple((mnemonic, form) for mnemonic, form in _FORMS if form.returns_value)
_ORDINARY_VARIABLES = tuple(v for v in VARIABLES if v not in RESERVED_VARIABLES)
_EQUAL_OPERAND_OPERATORS = ("-", "^", "&", "|")  # `P-P` is 0, `P&P` is P
_NEAR_OPERANDS = ("0", "1", "2", "7", "A", "B", "P")  # what `nearly` changes an end to


# Text -----------------------------------------------------------------------------------

_gaps = st.sampled_from(("", "", "", " ", " ", "  ", "\t", " \t ", "\f", "\v"))
_indents = st.sampled_from(("", "", "", " ", "      ", "\t", "\t\t"))
_separators = st.sampled_from(("; ", "; ", ";", " ; ", ";;", "; ;", "\t;\t", ";  "))

comment_texts = st.one_of(
    st.sampled_from(JAPANESE),
    st.text(st.characters(blacklist_categories=("Cs", "Cc"), blacklist_characters="\r\n")
            | st.just("\t"), max_size=30),
)
"""The text after `'`: anything but a line end."""


def _needs_space(left: str, right: str) -> bool:
    """Would `left` and `right` written together scan as one token (`A` `B` as `AB`)?"""
    return left[-1] in _WORD_CHARACTERS and right[0] in _WORD_CHARACTERS


def _spaced(draw: st.DrawFn, tokens: Sequence[str], odd: bool) -> str:
    """Tokens with random white space between them where it is allowed."""
    text = tokens[0]
    for left, right in itertools.pairwise(tokens):
        gap = draw(_gaps) if odd else ""
        if not gap and _needs_space(left, right):
            gap = " "
        text += gap + right
    return text


def _line_text(draw: st.DrawFn, label: str | None, statements: Sequence[Tokens],
               comment: str | None, odd: bool) -> str:
    parts = [draw(_indents)] if odd else []
    code = ""
    for index, statement in enumerate(statements):
        if index:
            code += draw(_separators) if odd else "; "
        code += _spaced(draw, statement, odd)
    if odd and draw(st.integers(0, 5)) == 0:  # an empty statement, before or after
        code = ";" + draw(_gaps) + code if draw(st.booleans()) else code + draw(_gaps) + ";"
    if label:
        parts.append(label)
        if code:
            parts.append(draw(_gaps) if odd else " ")
    parts.append(code)
    if comment is not None:
        if label or code:
            parts.append(draw(_gaps) if odd else " ")
        parts.append("'" + comment)
    return "".join(parts)


def _joined(draw: st.DrawFn, lines: Sequence[str]) -> str:
    """Lines with one line-end style, or (rarely) a mix, and maybe a final line end."""
    style = draw(st.sampled_from(("\n", "\n", "\r\n", "\r", "mixed")))
    ends = [draw(st.sampled_from(("\n", "\r\n", "\r"))) if style == "mixed" else style
            for _ in lines]
    for index in range(len(lines) - 1):  # CR, empty line, LF would read as one CR LF
        if ends[index] == "\r" and not lines[index + 1] and ends[index + 1] == "\n":
            ends[index] = "\r\n"
    text = "".join(line + end for line, end in zip(lines, ends, strict=True))
    return text if draw(st.booleans()) else text[: len(text) - len(ends[-1])]


# Constants and arguments ----------------------------------------------------------------


def _constant_text(draw: st.DrawFn, value: int) -> str:
    """A 16-bit value as decimal, or as a `$` bit pattern in either case, maybe with
    leading zeros."""
    if draw(st.integers(0, 3)):
        return str(value)
    digits = f"{value & 0xFFFF:X}"
    digits = digits.rjust(draw(st.integers(len(digits), 4)), "0")
    return "$" + (digits.lower() if draw(st.booleans()) else digits)


def _value(draw: st.DrawFn, low: int = -32768, high: int = 32767) -> int:
    edges = [v for v in EDGE_VALUES if low <= v <= high] + [low, high]
    return draw(st.sampled_from(edges) | st.integers(low, high))


def _label_number(draw: st.DrawFn) -> str:
    return f"{draw(st.integers(0, 99)):02d}"


# lines() and programs() -------------------------------------------------------------------


def _any_call(draw: st.DrawFn) -> Tokens:
    """Any built-in form, its arguments constants or variables of any value."""
    mnemonic, form = draw(st.sampled_from(_FORMS))
    args = [draw(st.sampled_from(VARIABLES)) if draw(st.booleans())
            else _constant_text(draw, _value(draw)) for _ in form.params]
    return _call_tokens(draw, mnemonic, form.selector, args)


def _call_tokens(draw: st.DrawFn, mnemonic: str, selector: str | None,
                 args: Sequence[str]) -> Tokens:
    """`( MNEMONIC [selector] args )`; commas are optional except before a negative
    number (after an operand, `-5` would read as minus 5)."""
    tokens = ["(", mnemonic]
    if selector:
        tokens.append(selector)
    for index, arg in enumerate(args):
        first = index == 0 and not selector
        if not first and (arg.startswith("-") or draw(st.booleans())):
            tokens.append(",")
        tokens.append(arg)
    return (*tokens, ")")


def _any_operand(draw: st.DrawFn) -> Tokens:
    kind = draw(st.sampled_from(("variable", "constant", "constant", "call")))
    if kind == "variable":
        return (draw(st.sampled_from(VARIABLES)),)
    if kind == "constant":
        return (_constant_text(draw, _value(draw)),)
    return _any_call(draw)


def _any_statement(draw: st.DrawFn) -> Tokens:
    kind = draw(st.sampled_from(("assign", "assign", "step", "goto", "jump", "call")))
    variable = draw(st.sampled_from(VARIABLES))
    if kind == "assign":
        tokens = [variable, "=", *_any_operand(draw)]
        for _ in range(draw(st.integers(0, 4))):
            tokens += [draw(st.sampled_from(OPERATORS)), *_any_operand(draw)]
        return tuple(tokens)
    if kind == "step":
        return (variable, draw(st.sampled_from(("++", "--"))))
    if kind == "goto":
        return ("#" + _label_number(draw),)
    if kind == "jump":
        return ("?", variable, draw(st.sampled_from(RELATIONS)), "#" + _label_number(draw))
    return _any_call(draw)


@st.composite
def lines(draw: st.DrawFn) -> str:
    """One syntactically valid line of RL/I, without a line end."""
    label = ":" + _label_number(draw) if draw(st.integers(0, 3)) == 0 else None
    statements = [_any_statement(draw) for _ in range(draw(st.integers(0, 4)))]
    comment = draw(comment_texts) if draw(st.integers(0, 3)) == 0 else None
    return _line_text(draw, label, statements, comment, odd=draw(st.booleans()))


@st.composite
def programs(draw: st.DrawFn, max_lines: int = 30) -> str:
    """A whole syntactically valid source text."""
    return _joined(draw, draw(st.lists(lines(), min_size=1, max_size=max_lines)))


# checked_programs() -----------------------------------------------------------------------


@dataclass
class _Line:
    label: str | None = None
    statements: list[Tokens] = field(default_factory=list)


@dataclass
class _Wild:
    """What `runs()` adds to the always-ending programs: sensor loops, faults, and the
    labels at the program's top level (safe places for a handler to jump back to)."""

    top_labels: list[int] = field(default_factory=list)


@dataclass
class _Builder:
    """Builds a program that passes the checker and ends: counted loops, forward jumps,
    arguments in range. The variables `held` are never written while they are held: the
    counter of a loop in progress, and what a shape relies on keeping its value."""

    draw: st.DrawFn
    free_labels: list[int]
    lines: list[_Line] = field(default_factory=lambda: [_Line()])
    held: set[str] = field(default_factory=set)
    traces: bool = False  # some (TRC 2) or (TRC 3) may run
    wild: _Wild | None = None  # runs(): sensor loops, re-entered handlers, faults

    # Layout

    def label(self, number: int) -> None:
        self.lines.append(_Line(f":{number:02d}"))

    def emit(self, statement: Tokens) -> None:
        line = self.lines[-1]
        if len(line.statements) >= self.draw(st.integers(1, 4)):
            self.lines.append(line := _Line())
        line.statements.append(statement)

    def new_label(self) -> int | None:
        return self.free_labels.pop() if self.free_labels else None

    # Variables and values

    def writable(self) -> str:
        """A variable the program may assign now: not one held; rarely a reserved one
        (the checker only warns)."""
        pool = [v for v in _ORDINARY_VARIABLES if v not in self.held]
        if self.draw(st.integers(0, 15)) == 0:
            pool += RESERVED_VARIABLES
        return self.draw(st.sampled_from(pool))

    def unheld(self) -> str:
        """An ordinary variable not held, to hold or to set to a reading."""
        return self.draw(st.sampled_from(
            [v for v in _ORDINARY_VARIABLES if v not in self.held]))

    def operand(self) -> Tokens:
        kind = self.draw(st.sampled_from(("variable", "constant", "constant", "call")))
        if kind == "variable":
            return (self.draw(st.sampled_from(VARIABLES)),)
        if kind == "constant":
            return (_constant_text(self.draw, _value(self.draw)),)
        mnemonic, form = self.draw(st.sampled_from(_VALUE_FORMS))
        return self.call(mnemonic, form)

    def call(self, mnemonic: str, form: Form) -> Tokens:
        """A call whose arguments are in range: constants, or variables set just before
        (to distinct variables, so one setting cannot undo another)."""
        args: list[str] = []
        values = self.arguments(mnemonic, form)
        spare = [v for v in _ORDINARY_VARIABLES if v not in self.held]
        for value, param in zip(values, form.params, strict=True):
            if self.draw(st.integers(0, 2)) == 0:
                variable = self.draw(st.sampled_from(spare))
                spare.remove(variable)
                if self.wild and self.draw(st.integers(0, 11)) == 0:
                    value = self.draw(st.sampled_from(  # out of range: a fault at run time
                        [v for v in (param.low - 1, param.high + 1) if -32768 <= v <= 32767]
                        or [value]))
                self.emit((variable, "=", str(value)))
                args.append(variable)
            else:
                args.append(_constant_text(self.draw, value))
        return _call_tokens(self.draw, mnemonic, form.selector, args)

    def arguments(self, mnemonic: str, form: Form) -> list[int]:
        values = [_value(self.draw, param.low, param.high) for param in form.params]
        if mnemonic == "MVI" and values[0] + values[1] == 0:
            values[2] = 0  # a distance the centre never covers would be a device error
        if mnemonic == "TRC" and values[0] >= 2:
            self.traces = True
        return values

    # The shapes the optimizer's passes look for (issue 25): each pass has work in some
    # share of the programs, which tests/backend/test_generator_shapes.py holds.

    def reading(self) -> str:
        """A variable set to a sensor's reading (one the script has, and repeats): a
        value no pass knows, where a constant would be folded before the passes that
        need a variable (equal operands, steps, branches decided by signs) see it."""
        variable = self.unheld()
        sensor, _ = self.draw(st.sampled_from(_SENSED))
        self.emit((variable, "=", *sensor))
        return variable

    def plain(self, pool: Sequence[str]) -> list[Tokens]:
        """A statement or two without a call, reading mostly the variables of `pool`,
        of a shape one of the passes rewrites: equal operands (`A=P-P`, `A=P&P`); a
        step written as an addition (`A=A+1`; `+3` is left as it is); a copy, then its
        use (`A=P+1; B=A`, `A=A`, `D=D+A`); a store overwritten before it is read
        (`A=P+1; A=Q`); or an assignment."""
        draw = self.draw
        target, other = self.writable(), self.writable()
        source = draw(st.sampled_from(pool))
        computed = (target, "=", source, draw(st.sampled_from(OPERATORS)), self.small())
        kind = draw(st.sampled_from(("equal", "step", "copy", "overwritten", "assign")))
        if kind == "equal":
            return [(target, "=", source, draw(st.sampled_from(_EQUAL_OPERAND_OPERATORS)),
                     source, *draw(st.sampled_from(((), ("+", self.small())))))]
        if kind == "step":
            return [(target, "=", target, draw(st.sampled_from("+-")),
                     draw(st.sampled_from(("1", "2", "1", "2", "3", "0", "-1"))))]
        if kind == "copy":
            use = draw(st.sampled_from(((other, "=", target), (target, "=", target),
                                        (other, "=", other, draw(st.sampled_from("+&|^")),
                                         target))))
            return [computed, use]
        if kind == "overwritten":
            return [computed, (target, "=", draw(st.sampled_from(pool)), "-", self.small())]
        return [computed]

    def small(self) -> str:
        return _constant_text(self.draw, self.draw(st.integers(-2, 300)))

    def nearly(self, statement: Tokens) -> Tokens:
        """The statement with its last operand changed: alike but for its end, where
        tail merging must stop."""
        last = statement[-1]
        other = self.draw(st.sampled_from([operand for operand in _NEAR_OPERANDS
                                           if operand != last]))
        return (*statement[:-1], other)

    def arm(self, depth: int) -> None:
        """What an if-else's way, or the code between branches, holds: now and then a
        block (not too deep), else a statement or none; kept small, as a way runs only
        when it is taken."""
        if depth < 2 and self.draw(st.integers(0, 3)) == 0:
            self.block(depth + 1)
        else:
            for _ in range(self.draw(st.integers(0, 1))):
                self.statement()

    def if_else(self, depth: int) -> None:
        """`?V=#20; <then>; <tail>; #30; :20 <else>; <tail>; :30`: two ways that end
        alike and join, whose tail merge_tails writes once; or, now and then, the else
        way's tail with its first statement's last operand changed, where the merge
        must stop."""
        otherwise, join = self.new_label(), self.new_label()
        assert otherwise is not None and join is not None
        variable = self.reading() if self.draw(st.integers(0, 2)) \
            else self.draw(st.sampled_from(VARIABLES))
        pool = (variable, self.draw(st.sampled_from(VARIABLES)))
        tail = self.plain(pool)
        self.emit(("?", variable, self.draw(st.sampled_from(RELATIONS)),
                   f"#{otherwise:02d}"))
        self.arm(depth)
        for statement in tail:
            self.emit(statement)
        self.emit((f"#{join:02d}",))
        self.label(otherwise)
        self.arm(depth)
        if self.draw(st.integers(0, 3)) == 0:
            tail[0] = self.nearly(tail[0])
        for statement in tail:
            self.emit(statement)
        self.label(join)

    def branches(self, depth: int) -> None:
        """Two or three branches on one variable, each inside the way the one before
        falls through, nothing writing the variable in between: `?V=#20; ...; ?V=#30`,
        where the second never jumps (decide_branches); the same relation again, or
        another (`?V<#20; ?V>#30; ?V=#40` always jumps)."""
        variable = self.reading() if self.draw(st.integers(0, 2)) else self.unheld()
        self.held.add(variable)  # not written until the last branch's target
        relation = self.draw(st.sampled_from(RELATIONS))
        targets: list[int] = []
        for _ in range(self.draw(st.integers(2, 3))):
            if (target := self.new_label()) is None:
                break
            if self.draw(st.booleans()):
                relation = self.draw(st.sampled_from(RELATIONS))
            self.emit(("?", variable, relation, f"#{target:02d}"))
            targets.append(target)
            self.arm(depth)
        self.held.discard(variable)
        for target in reversed(targets):
            self.label(target)

    # Statements and blocks

    def statement(self, tracing: bool = True) -> None:
        """One statement (or a few of the shapes in `plain`); with `tracing` False, no
        (TRC ...) (handlers must not set a mode whose handlers might not exist)."""
        kind = self.draw(st.sampled_from(("assign", "assign", "plain", "step", "call",
                                          "call")))
        if self.wild and self.draw(st.integers(0, 199)) == 100:  # not 0: Hypothesis favours 0
            self.emit(("(", "MVI", "3", ",", "-3", ",", "10", ")"))  # a device error
        elif kind == "plain":
            for statement in self.plain([self.draw(st.sampled_from(VARIABLES))]):
                self.emit(statement)
        elif kind == "assign":
            target = self.writable()
            tokens = [target, "=", *self.operand()]
            for _ in range(self.draw(st.integers(0, 5))):
                tokens += [self.draw(st.sampled_from(OPERATORS)), *self.operand()]
            self.emit(tuple(tokens))
        elif kind == "step":
            self.emit((self.writable(), self.draw(st.sampled_from(("++", "--")))))
        else:
            mnemonic, form = self.draw(st.sampled_from(_FORMS))
            if mnemonic != "END" and (tracing or mnemonic != "TRC"):
                self.emit(self.call(mnemonic, form))

    def block(self, depth: int) -> None:
        """A block of the kinds the generator made before the shapes (straight code, a
        counted loop, a block skipped, a sensor loop, in their shares), then, now and
        then, a shape the passes rewrite (an if-else, nested branches). The shapes come
        beside those blocks, not in their place: in place of straight code and loops
        (whose body runs up to four times), their ways (one of which runs) left fewer
        statements run, and runs reached fewer faults and lost lines (issue 25)."""
        kinds = ("straight", "straight", "loop", "skip", *(("sensed",) if self.wild else ()))
        kind = self.draw(st.sampled_from(kinds))
        if self.wild and depth == 0 and self.free_labels and self.draw(st.booleans()):
            self.wild.top_labels.append(number := self.free_labels.pop())
            self.label(number)
        if kind == "sensed" and self.free_labels:
            self.sensed_loop()
        elif kind == "loop" and depth < 2 and len(self.free_labels) >= 2:
            self.loop(depth)
        elif kind == "skip" and depth < 3 and self.free_labels:
            self.skip(depth)
        else:
            for _ in range(self.draw(st.integers(1, 4))):
                self.statement()
        shape = self.draw(st.sampled_from((None, None, None, None, "if-else", "branches")))
        if shape == "if-else" and depth < 3 and len(self.free_labels) >= 2:
            self.if_else(depth)
        elif shape == "branches" and depth < 3 and self.free_labels:
            self.branches(depth)

    def body(self, depth: int) -> None:
        for _ in range(self.draw(st.integers(1, 3))):
            self.block(depth + 1)

    def loop(self, depth: int) -> None:
        """A counted loop in one of four shapes; `count` passes (0 for the third shape
        means the body never runs). In the fourth, the code before the loop ends as its
        body does (`C=3; A=P+1; :10 ?C=#20; C--; ...; A=P+1; #10`), which merge_tails
        writes once."""
        counter = self.unheld()
        count = self.draw(st.integers(1, 4))
        top, exit_label = self.new_label(), self.new_label()
        assert top is not None and exit_label is not None
        self.held.add(counter)
        shape = self.draw(st.sampled_from(("down", "up", "while", "tail")))
        if shape == "down":
            self.emit((counter, "=", str(count)))
            self.label(top)
            self.body(depth)
            self.emit((counter, "--"))
            self.emit(("?", counter, ">", f"#{top:02d}"))
        elif shape == "up":
            self.emit((counter, "=", str(-count)))
            self.label(top)
            self.body(depth)
            self.emit((counter, "++"))
            self.emit(("?", counter, "<", f"#{top:02d}"))
        elif shape == "while":
            self.emit((counter, "=", str(count - 1)))
            self.label(top)
            self.emit(("?", counter, "=", f"#{exit_label:02d}"))
            self.body(depth)
            self.emit((counter, "--"))
            self.emit((f"#{top:02d}",))
        else:
            self.emit((counter, "=", str(count)))
            read = self.reading()
            self.held.add(read)  # its value alike in both tails
            tail = self.plain((read, self.draw(st.sampled_from(VARIABLES))))
            for statement in tail:
                self.emit(statement)
            self.label(top)
            self.emit(("?", counter, "=", f"#{exit_label:02d}"))
            self.emit((counter, "--"))
            self.body(depth)
            for statement in tail:
                self.emit(statement)
            self.emit((f"#{top:02d}",))
            self.held.discard(read)
        if shape in ("while", "tail"):
            self.label(exit_label)
        else:
            self.free_labels.append(exit_label)
        self.held.discard(counter)

    def sensed_loop(self) -> None:
        """A loop that waits for a sensor, as Listing 1's `:10 A=(IMG)-180; ?A<#10`: the
        script's last readings (`_ENDING_READINGS`) end it."""
        top = self.new_label()
        assert top is not None
        self.label(top)
        if self.draw(st.booleans()):
            self.statement()
        variable = self.writable()
        sensor, relation = self.draw(st.sampled_from(_SENSED))
        threshold = self.draw(st.integers(0, 1000))
        self.emit((variable, "=", *sensor, "-", str(threshold)))
        self.emit(("?", variable, relation, f"#{top:02d}"))

    def skip(self, depth: int) -> None:
        """A forward jump over a block: conditional, or rarely an early `(END)`."""
        target = self.new_label()
        assert target is not None
        variable = self.draw(st.sampled_from(VARIABLES))
        self.emit(("?", variable, self.draw(st.sampled_from(RELATIONS)), f"#{target:02d}"))
        if self.draw(st.integers(0, 7)) == 0:
            self.emit(("(", "END", ")"))
        else:
            self.body(depth)
        self.label(target)

    def end(self) -> None:
        if self.draw(st.booleans()):
            self.emit(self.draw(st.sampled_from((("(", "MOV", "0", ",", "0", ")"),
                                                 ("(", "FRE", ")"), ("(", "HLD", ")")))))
        self.emit(("(", "END", ")"))

    def handlers(self) -> None:
        """:96-:99, each ending the program; all four when a mode 2 or 3 may be set. In
        runs(), a handler may be missing (a fault when it is needed) or jump back to a
        label of the top level (the script's losses are finite, so it ends)."""
        for number in HANDLER_LABELS:
            if (self.traces and not self.wild) or self.draw(st.booleans()):
                self.label(number)
                for _ in range(self.draw(st.integers(0, 2))):
                    self.statement(tracing=False)
                if self.wild and self.wild.top_labels and self.draw(st.booleans()):
                    back = self.draw(st.sampled_from(self.wild.top_labels))
                    self.emit((f"#{back:02d}",))
                else:
                    self.end()

    def text(self) -> str:
        draw = self.draw
        odd = draw(st.integers(0, 3)) == 0
        rendered = [
            _line_text(draw, line.label, line.statements,
                       draw(comment_texts) if draw(st.integers(0, 7)) == 0 else None, odd)
            for line in self.lines if line.label or line.statements
        ]
        return _joined(draw, rendered)


def _build(draw: st.DrawFn, max_blocks: int, wild: _Wild | None) -> str:
    labels = list(draw(st.permutations(range(96))))
    builder = _Builder(draw, labels, wild=wild)
    if wild or draw(st.booleans()):
        # runs() mostly trace in modes 2 and 3, so that its scripts' losses matter.
        mode = draw(st.sampled_from((0, 1, 2, 3, 2, 3) if wild else (0, 1, 2, 3)))
        builder.emit(("(", "TRC", str(mode), ")"))
        builder.traces = mode >= 2
        if wild and draw(st.booleans()):
            # Under a label a handler may jump back to: driving again, it may lose the
            # line again, and enter its handler again.
            wild.top_labels.append(number := labels.pop())
            builder.label(number)
            builder.emit(("(", "MOV", "3", ",", "3", ")"))
    for _ in range(draw(st.integers(1, max_blocks))):
        builder.block(0)
    builder.end()
    builder.handlers()
    return builder.text()


@st.composite
def checked_programs(draw: st.DrawFn, max_blocks: int = 6) -> str:
    """A program with no checker errors that always ends (see the module's notes)."""
    return _build(draw, max_blocks, None)


# runs() ---------------------------------------------------------------------------------

# What a sensor loop reads and how it tests it; the script's last readings (large areas,
# ultrasonic distances and odometry of 0) end every such loop.
_SENSED: tuple[tuple[Tokens, str], ...] = (
    (("(", "IMG", ")"), "<"), (("(", "ULT", "A", ")"), ">"), (("(", "ULT", "C", ")"), ">"),
    (("(", "KYO", ")"), ">"),
)
_ENDING_AREA = 1000  # at least every threshold: `A=(IMG)-K; ?A<#NN` goes on

JsonScript = dict[str, object]


@dataclass(frozen=True)
class Run:
    """A program and the sensor script (as JSON data) to run it on."""

    source: str
    script: JsonScript


def _readings(draw: st.DrawFn, make: st.SearchStrategy[object], ending: object) -> list[object]:
    return [*draw(st.lists(make, max_size=4)), ending]


@st.composite
def sensor_scripts(draw: st.DrawFn, instruction_losses: bool = False) -> JsonScript:
    """A sensor script (JSON data, spec of vm/scripted.py) whose last readings end the
    sensor loops of `runs()`, with up to four losses of the guidance line: at a device
    time, during a motion and, with `instruction_losses`, after an instruction count
    (which only engines running the same compiled file can compare, and the interpreter
    does not run)."""
    small = st.integers(-300, 1200)
    image = st.builds(lambda area, x, y, z: {"area": area, "x": x, "y": y, "z": z},
                      small, small, small, st.integers(-180, 180))
    odometry = st.builds(lambda c, r, left: {"centre": c, "right": r, "left": left},
                         small, small, small)
    script: JsonScript = {
        "IMG": _readings(draw, image, {"area": _ENDING_AREA, "x": 128, "y": 100, "z": 0}),
        "KYO": _readings(draw, odometry, {"centre": 0, "right": 0, "left": 0}),
        "ULT A": _readings(draw, small, 0),
        "ULT C": _readings(draw, small, 0),
        "CAM R": draw(st.lists(st.integers(0, 784), min_size=1, max_size=3)),
        "FZI": draw(st.lists(st.builds(lambda a, b: {"s": a, "t": b}, small, small),
                             min_size=1, max_size=2)),
    }
    kinds = [
        st.builds(lambda time: {"time": time}, st.integers(1, 2000)),
        st.builds(lambda command, nth, after: {"during": command, "nth": nth, "after": after},
                  st.sampled_from(("MOV", "MVI")), st.integers(1, 2), st.integers(1, 300)),
    ]
    if instruction_losses and draw(st.booleans()):
        # Between calls, where a loss is taken at a jump (or at the next call).
        kinds.append(st.builds(lambda count: {"instruction": count}, st.integers(1, 400)))
    losses = draw(st.lists(st.one_of(kinds), max_size=4))
    if losses:
        script["line_lost"] = losses
    script["after_last"] = "repeat"  # the last readings end the loops: they must repeat
    return script


@st.composite
def runs(draw: st.DrawFn, max_blocks: int = 6, instruction_losses: bool = False) -> Run:
    """A program the checker accepts, with a sensor script (see the module's notes and
    `sensor_scripts`)."""
    return Run(_build(draw, max_blocks, _Wild()), draw(sensor_scripts(instruction_losses)))
