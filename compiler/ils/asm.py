"""`rl1c asm`: .ils text to .ilc bytes, so that intermediate code can be written by hand.

The text is what `rl1c dis` prints (spec/ilc.md, "Text form"): one instruction or
directive a line, `;` comments, `name:` labels, an optional leading code offset that must
match. Operands are separated by commas: variables by name, constants in decimal or
`$hex`, jump targets by label or raw code offset. Without a `.features` directive the
features are those the code's calls need.

The assembler checks syntax and encodings; `assemble` then runs the verifier over the
result, so a file it writes is one the VM accepts, and a refusal is reported at the line
that caused it.
"""

from __future__ import annotations

import bisect
import json
import re
from dataclasses import dataclass, field

from rl1.compiler.frontend.source import split_lines
from rl1.vm import ilc, isa
from rl1.vm.language import BUILTINS, HANDLER_LABELS, VARIABLES, Feature, decimal_value
from rl1.vm.verifier import VerifyError, verify


@dataclass(frozen=True, slots=True)
class Problem:
    line: int
    column: int
    message: str


class AsmError(Exception):
    """The text does not assemble; `problems` says where and why, in text order."""

    def __init__(self, problems: list[Problem]) -> None:
        super().__init__("; ".join(f"{p.line}:{p.column}: {p.message}" for p in problems))
        self.problems = tuple(problems)


class _LineError(Exception):
    def __init__(self, column: int, message: str) -> None:
        super().__init__(message)
        self.column, self.message = column, message


_TOKEN = re.compile(r"""
    (?P<space>\s+)
  | (?P<comment>;.*)
  | (?P<string>"(?:[^"\\]|\\.)*")
  | (?P<number>[-+]?[0-9]+|\$[0-9A-Fa-f]+)
  | (?P<name>[A-Za-z_.@][A-Za-z0-9_.]*)
  | (?P<punct>[:,])
""", re.VERBOSE)


@dataclass(frozen=True, slots=True)
class _Token:
    kind: str  # "string", "number", "name", "punct" or "end"
    text: str
    column: int


def _tokenize(text: str) -> list[_Token]:
    tokens: list[_Token] = []
    position = 0
    while position < len(text):
        match = _TOKEN.match(text, position)
        if match is None:
            problem = ("a string without its closing quote" if text[position] == '"'
                       else f"unexpected character {text[position]!r}")
            raise _LineError(position + 1, problem)
        kind = match.lastgroup
        assert kind is not None
        if kind not in ("space", "comment"):
            tokens.append(_Token(kind, match.group(), position + 1))
        position = match.end()
    tokens.append(_Token("end", "", len(text) + 1))
    return tokens


class _Cursor:
    """The tokens of one line, consumed left to right."""

    def __init__(self, tokens: list[_Token]) -> None:
        self.tokens, self.index = tokens, 0

    @property
    def peek(self) -> _Token:
        return self.tokens[self.index]

    def next(self) -> _Token:
        token = self.tokens[self.index]
        if token.kind != "end":
            self.index += 1
        return token

    def accept(self, kind: str, text: str | None = None) -> bool:
        if self.peek.kind == kind and (text is None or self.peek.text == text):
            self.next()
            return True
        return False

    def expect(self, kind: str, what: str) -> _Token:
        token = self.peek
        if token.kind != kind:
            found = token.text or "the end of the line"
            raise _LineError(token.column, f"expected {what}, found {found!r}")
        return self.next()

    def finish(self) -> None:
        token = self.peek
        if token.kind != "end":
            raise _LineError(token.column, f"unexpected {token.text!r} at the end of the line")


def _number(token: _Token, low: int, high: int, what: str) -> int:
    """A decimal or `$hex` number in low..high; a hex pattern of 16 bits is signed when
    `low` is negative, as in RL/I (`$FFFF` = -1)."""
    if token.kind != "number":
        raise _LineError(token.column, f"expected {what}, found {token.text or 'nothing'!r}")
    if token.text.startswith("$"):
        value = int(token.text[1:], 16)  # linear in its length, unlike a decimal
        if value <= 0xFFFF and low < 0 and value >= 0x8000:
            value -= 0x10000
    else:
        value = decimal_value(token.text)
    if not low <= value <= high:
        raise _LineError(token.column, f"{what} {token.text} is out of range {low}..{high}")
    return value


_VARIABLE_INDEX = {name: index for index, name in enumerate(VARIABLES)}


def _variable(token: _Token) -> int:
    if token.kind != "name" or token.text not in _VARIABLE_INDEX:
        raise _LineError(token.column, f"expected a variable (A-Z, a-z or @), "
                                       f"found {token.text or 'nothing'!r}")
    return _VARIABLE_INDEX[token.text]


@dataclass
class _Assembler:
    code: bytearray = field(default_factory=bytearray)
    labels: dict[str, int] = field(default_factory=dict)
    fixups: list[tuple[int, _Token, int]] = field(default_factory=list)  # (pos, label, line)
    handler_targets: dict[int, tuple[_Token, int]] = field(default_factory=dict)
    features: frozenset[Feature] | None = None
    flags: int | None = None
    source_name: str | None = None
    source_digest: bytes | None = None
    source_origin: tuple[int, int] = (0, 0)  # (line, column) of .source
    current_line: int | None = None
    entries: list[tuple[int, int]] = field(default_factory=list)
    problems: list[Problem] = field(default_factory=list)
    # Where each part of the image came from, to report a verifier refusal at its line.
    instruction_starts: list[int] = field(default_factory=list)
    origins: list[tuple[int, int, int]] = field(default_factory=list)  # (code pos, line, col)
    handler_origins: dict[int, tuple[int, int]] = field(default_factory=dict)
    entry_origins: list[tuple[int, int]] = field(default_factory=list)
    features_origin: tuple[int, int] = (1, 1)
    flags_origin: tuple[int, int] = (1, 1)
    line_origin: tuple[int, int] = (1, 1)

    def line(self, number: int, text: str) -> None:
        try:
            cursor = _Cursor(_tokenize(text))
            self.statement(number, cursor)
            cursor.finish()
        except _LineError as error:
            self.problems.append(Problem(number, error.column, error.message))

    def statement(self, number: int, cursor: _Cursor) -> None:
        if (cursor.peek.kind == "name" and not cursor.peek.text.startswith(".")
                and cursor.tokens[cursor.index + 1].text == ":"):
            label = cursor.next()
            cursor.next()
            if label.text in self.labels:
                raise _LineError(label.column, f"label {label.text} is defined twice")
            self.labels[label.text] = len(self.code)
        if cursor.peek.kind == "number":
            self.check_offset(cursor.next())
        token = cursor.peek
        if token.kind == "end":
            return
        name = cursor.expect("name", "an instruction or a directive").text
        if name.startswith("."):
            self.directive(number, token, cursor)
        else:
            self.instruction(number, token, cursor)

    def check_offset(self, token: _Token) -> None:
        written = _number(token, 0, 0xFFFF, "code offset")
        # After an error the offsets of later lines are unknown; do not pile up errors.
        if not self.problems and written != len(self.code):
            raise _LineError(token.column, f"this line says code offset {written}, but its "
                                           f"instruction assembles at {len(self.code)}; fix "
                                           "the offset or delete it (offsets are optional)")

    def directive(self, number: int, token: _Token, cursor: _Cursor) -> None:
        position = (number, token.column)
        if token.text == ".features":
            if self.features is not None:
                raise _LineError(token.column, ".features is given twice")
            names = []
            while cursor.peek.kind == "name":
                names.append(cursor.next())
            self.features = frozenset(self.feature(name) for name in names)
            self.features_origin = position
        elif token.text == ".flags":
            if self.flags is not None:
                raise _LineError(token.column, ".flags is given twice")
            self.flags = _number(cursor.next(), 0, 0xFFFF, "flags")
            self.flags_origin = position
        elif token.text == ".handler":
            label = _number(cursor.next(), HANDLER_LABELS.start, HANDLER_LABELS.stop - 1,
                            "handler label")
            if label in self.handler_origins:
                raise _LineError(token.column, f"handler :{label} is given twice")
            self.handler_origins[label] = position
            if not cursor.accept("name", "none"):
                self.handler_targets[label] = (cursor.next(), number)
        elif token.text == ".source":
            if self.source_name is not None:
                raise _LineError(token.column, ".source is given twice")
            self.source_origin = position
            name = cursor.expect("string", "a quoted file name")
            try:
                self.source_name = json.loads(name.text)
            except json.JSONDecodeError as error:
                raise _LineError(name.column + error.pos, f"bad string: {error.msg} "
                                                          "(strings use JSON escapes)") from None
        elif token.text == ".digest":
            self.digest_directive(token, cursor)
        elif token.text == ".line":
            self.line_directive(token, cursor, position)
        else:
            raise _LineError(token.column, f"unknown directive {token.text}: the directives "
                                           "are .features, .flags, .handler, .source, .digest "
                                           "and .line")

    def digest_directive(self, token: _Token, cursor: _Cursor) -> None:
        if self.source_name is None:
            raise _LineError(token.column, '.digest needs a .source "FILE.rob" directive '
                                           "before it: it is the digest of that source")
        if self.source_digest is not None:
            raise _LineError(token.column, ".digest is given twice")
        text = cursor.expect("string", "the digest in quotes, as `rl1c dis` prints it")
        try:
            digest = bytes.fromhex(json.loads(text.text))
        except (ValueError, TypeError):
            digest = b""
        if len(digest) != ilc.DIGEST_SIZE:
            raise _LineError(text.column, f"a source digest is {ilc.DIGEST_SIZE} bytes: "
                                          f"{2 * ilc.DIGEST_SIZE} hexadecimal digits in quotes")
        self.source_digest = digest

    @staticmethod
    def feature(token: _Token) -> Feature:
        try:
            return Feature[token.text.upper()]
        except KeyError:
            names = ", ".join(feature.name for feature in Feature)
            raise _LineError(token.column, f"unknown feature {token.text}: "
                                           f"the features are {names}") from None

    def line_directive(self, token: _Token, cursor: _Cursor, position: tuple[int, int]) -> None:
        if self.source_name is None:
            raise _LineError(token.column, '.line needs a .source "FILE.rob" directive '
                                           "before it: the line map belongs to a source file")
        if cursor.accept("name", "none"):
            self.current_line = None
            return
        line = _number(cursor.next(), 1, ilc.MAX_LINE, "line number")
        if self.entries and line < self.entries[-1][1]:
            raise _LineError(token.column, f"line {line} comes after line "
                                           f"{self.entries[-1][1]}: the line map is in code "
                                           "order and its lines must not decrease")
        self.current_line = line
        self.line_origin = position

    def instruction(self, number: int, token: _Token, cursor: _Cursor) -> None:
        info = isa.BY_NAME.get(token.text.upper())
        if info is None:
            raise _LineError(token.column, f"unknown instruction {token.text}; spec/ilc.md "
                                           "lists the instruction set")
        if len(self.code) + info.length > ilc.MAX_CODE_SIZE:
            raise _LineError(token.column, f"the code passes {ilc.MAX_CODE_SIZE} bytes here, "
                                           "the most an .ilc file can hold")
        operand_tokens = iter(self.operand_tokens(info, token, cursor))
        start = len(self.code)
        position = start + 1  # of the operand being read
        operands: list[int] = []
        args: tuple[isa.Arg, ...] = ()
        self.origins.append((start, number, token.column))
        for operand in info.operands:
            if operand is isa.Operand.ARGS:
                arg_tokens = [next(operand_tokens) for _ in range(info.arity)]
                args = tuple(self.argument(arg_token, info) for arg_token in arg_tokens)
                self.origins += [(position + 1 + info.arg_size * index, number,
                                  arg_token.column)
                                 for index, arg_token in enumerate(arg_tokens)]
                continue
            operand_token = next(operand_tokens)
            self.origins.append((position, number, operand_token.column))
            if operand is isa.Operand.VAR:
                operands.append(_variable(operand_token))
                position += 1
                continue
            if operand is isa.Operand.BYTE:
                operands.append(_number(operand_token, -0x80, 0x7F, "byte constant"))
                position += 1
                continue
            if operand is isa.Operand.IMM:
                operands.append(_number(operand_token, -0x8000, 0x7FFF, "constant"))
            elif operand_token.kind == "name":
                operands.append(0)  # patched once every label is known
                self.fixups.append((position, operand_token, number))
            else:
                operands.append(_number(operand_token, 0, 0xFFFF, "code offset"))
            position += 2
        self.code += isa.encode(info, tuple(operands), args)
        self.instruction_starts.append(start)
        if self.current_line is not None:
            self.entries.append((start, self.current_line))
            self.entry_origins.append(self.line_origin)

    @staticmethod
    def operand_tokens(info: isa.OpInfo, token: _Token, cursor: _Cursor) -> list[_Token]:
        tokens: list[_Token] = []
        if cursor.peek.kind != "end":
            tokens.append(cursor.next())
            while cursor.accept("punct", ","):
                if cursor.peek.kind not in ("name", "number"):
                    raise _LineError(cursor.peek.column, "expected an operand after ','")
                tokens.append(cursor.next())
        expected = sum(info.arity if operand is isa.Operand.ARGS else 1
                       for operand in info.operands)
        if len(tokens) != expected:
            # Too many: point at the first one too many; too few: at the instruction.
            column = tokens[expected].column if len(tokens) > expected else token.column
            raise _LineError(column, f"{info.name} takes {expected} operand"
                                           f"{'' if expected == 1 else 's'}, found {len(tokens)}")
        return tokens

    @staticmethod
    def argument(token: _Token, call: isa.OpInfo) -> isa.Arg:
        if token.kind == "name":
            return isa.Arg(True, _variable(token))
        if call.compact:
            return isa.Arg(False, _number(token, -0x80, 0x7F, "byte constant"))
        return isa.Arg(False, _number(token, -0x8000, 0x7FFF, "constant"))

    def resolve(self, token: _Token) -> int:
        """A jump or handler target: a label, or a raw code offset."""
        if token.kind == "name":
            if token.text not in self.labels:
                raise _LineError(token.column, f"unknown label {token.text}")
            return self.labels[token.text]
        return _number(token, 0, 0xFFFF, "code offset")

    def image(self) -> ilc.Image:
        for position, token, number in self.fixups:
            try:
                self.code[position:position + 2] = self.resolve(token).to_bytes(2, "little")
            except _LineError as error:
                self.problems.append(Problem(number, error.column, error.message))
        handlers: dict[int, int] = {}
        for label, (token, number) in sorted(self.handler_targets.items()):
            try:
                handlers[label] = self.resolve(token)
            except _LineError as error:
                self.problems.append(Problem(number, error.column, error.message))
                continue
            if handlers[label] >= len(self.code):
                self.problems.append(Problem(number, token.column, f"handler :{label} at "
                                             f"{handlers[label]} is outside the "
                                             f"{len(self.code)}-byte code"))
        minor = isa.code_minor(bytes(self.code))
        if minor >= ilc.DIGEST_MINOR and self.source_name is not None \
                and self.source_digest is None:
            line, column = self.source_origin
            self.problems.append(Problem(line, column, f"the code uses instructions of format "
                                         f"1.{minor}, whose debug section carries the "
                                         "source's digest: add `.digest \"HEX\"` after "
                                         "`.source` (`rl1c dis` prints it) or leave out "
                                         "`.source`"))
        if self.problems:
            raise AsmError(self.problems)
        debug = None if self.source_name is None else ilc.DebugInfo(
            self.source_name, tuple(self.entries), self.source_digest)
        features = self.features if self.features is not None else self.needed_features()
        return ilc.Image(bytes(self.code), handlers, features, debug, self.flags or 0)

    def needed_features(self) -> frozenset[Feature]:
        needed = set()
        for start in self.instruction_starts:
            builtin = isa.OPCODES[self.code[start]].builtin
            feature = None if builtin is None else BUILTINS[builtin[0]].feature
            if feature is not None:
                needed.add(feature)
        return frozenset(needed)

    def origin_of(self, data: bytes, offset: int) -> tuple[int, int]:
        """The text position of what put file byte `offset` in the assembled file."""
        if offset == ilc.FLAGS_OFFSET:
            return self.flags_origin
        container = ilc.read(data)
        header = container.header
        if header.code_start <= offset < header.handler_start:
            positions = [position for position, _, _ in self.origins]
            _, line, column = self.origins[
                bisect.bisect_right(positions, offset - header.code_start) - 1]
            return line, column
        if header.handler_start <= offset < header.feature_start:
            label = HANDLER_LABELS[(offset - header.handler_start) // 2]
            return self.handler_origins.get(label, (1, 1))
        if header.feature_start <= offset < header.debug_start:
            return self.features_origin
        if offset >= header.debug_start and container.line_entry_offsets:
            index = bisect.bisect_right(container.line_entry_offsets, offset) - 1
            return self.entry_origins[max(index, 0)]
        return 1, 1


def assemble(text: str, *, check: bool = True) -> bytes:
    """The .ilc bytes of .ils `text`; AsmError with every problem found. With `check`
    (the default) the result must also verify; tests that need a refused file for the
    verifier pass check=False."""
    assembler = _Assembler()
    for number, line_text in enumerate(split_lines(text), start=1):
        assembler.line(number, line_text)
    data = ilc.encode(assembler.image())
    if check:
        try:
            verify(data)
        except VerifyError as error:
            line, column = assembler.origin_of(data, error.offset)
            raise AsmError([Problem(line, column, error.message)]) from None
    return data
