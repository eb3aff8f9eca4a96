"""The test vectors, as cases: a program, its sensor script, and what the spec says the run
must give.

Each case carries its expectations, written from spec/language.md and the scripted
device's motion model (vm/scripted.py), not copied from a run: the final variables (all
53: a variable the case does not name must end at 0), optionally the status and source
line of the fault, and optionally the trace. For the arithmetic, shift and comparison
vectors the expected variables come from oracle.py. generate.py runs every case on the
VM and on the interpreter and refuses to write a vector whose run disagrees with them.
"""

from __future__ import annotations

import json
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from oracle import (
    RESERVED,
    VARIABLES,
    Assign,
    Hex,
    Operand,
    Port,
    Step,
    Straight,
    render,
)

from rl1.vm import isa
from rl1.vm.language import BUILTINS, Param

EXAMPLES = Path(__file__).resolve().parent.parent.parent / "examples"
DEFAULT_BUDGET = 100_000
REPEAT = {"after_last": "repeat"}  # a used-up list repeats its last reading, none reads 0

TraceItem = tuple[int | None, str, tuple[int, ...]]  # (time, or None: not checked; call; args)


@dataclass(frozen=True)
class Case:
    group: str  # the file the vector goes to: spec/vectors/<group>.json
    name: str
    covers: str
    source: str
    variables: Mapping[str, int]  # expected final values; unnamed variables end at 0
    sensors: Mapping[str, Any] = field(default_factory=dict)
    budget: int = DEFAULT_BUDGET
    status: str = "ok"  # "ok" or a fault code (vm/faults.py)
    fault_line: int = 0
    trace: tuple[TraceItem, ...] | None = None  # the expected trace, when the case fixes it
    executed: int | None = None  # the VM's instruction count, when the case fixes it
    language: str = "rl1"  # "ils": `source` is intermediate code written by hand (.ils)
    level: int = 0  # the optimization level it is compiled at (2: format 1.2's fused code)


def all_cases() -> list[Case]:
    return [*arithmetic(), *shifts(), *control(), *calls(), *tracing(), *events(), *faults(),
            *sample(), *intermediate(),
            *fused(), *compact()]


def _straight(group: str, name: str, covers: str, program: Straight) -> Case:
    return Case(group, name, covers, program.source(), program.evaluate(),
                program.sensors())


# Results go to the variables that are not reserved, so no sensing call can disturb them.
FREE = [name for name in VARIABLES if name not in RESERVED]


# --- arithmetic --------------------------------------------------------------------------

EDGES: list[Operand] = [-32768, -1, 0, 1, 32767, Hex("5555"), Hex("AAAA")]
ALU_NAMES = {"+": "add", "-": "sub", "&": "and", "|": "or", "^": "xor"}


def arithmetic() -> Iterator[Case]:
    group = "arithmetic"
    yield _straight(group, "wrap-and-constants",
                    "wrap-around of + and - at both ends, $hex as 16-bit patterns, "
                    "the examples of spec/language.md 7.2", Straight([
                        Assign("A", 32767, (("+", 1),)),
                        Assign("B", -32768, (("-", 1),)),
                        Assign("C", Hex("FFFF")),
                        Assign("D", Hex("8000")),
                        Assign("E", Hex("7FFF")),
                        Assign("F", Hex("0")),
                        Assign("G", Hex("ffff")),
                        Assign("H", 32767, (("+", 32767),)),
                        Assign("I", -32768, (("+", -32768),)),
                        Assign("J", -32768, (("-", 32767),)),
                        Assign("K", 0, (("-", -32768),)),
                        Assign("L", Hex("F0F0"), (("&", Hex("0FF0")), ("^", Hex("00FF")))),
                        Assign("M", 1, (("<", 15),)),
                        Assign("N", 1, (("<", 16),)),
                        Assign("O", -1, ((">", 20),)),
                        Assign("P", -8, ((">", 1),)),
                        Assign("Q", -7, ((">", 1),)),
                        Assign("R", 5, (("<", -1),)),
                        Assign("S", 3, ((">", -2),)),
                        Assign("T", Hex("00"), (("-", Hex("0001")),)),
                        Assign("U", Hex("7FFF"), (("+", Hex("0001")),)),
                    ]))
    yield _straight(group, "increment-decrement-limits",
                    "V++ and V-- wrap at both ends (INC, DEC)", Straight([
                        Assign("A", 32767), Step("A", "++"),
                        Assign("B", -32768), Step("B", "--"),
                        Assign("C", -1), Step("C", "++"),
                        Step("D", "--"),
                        Assign("E", 32766), Step("E", "++"), Step("E", "++"),
                        Assign("F", -32767), Step("F", "--"), Step("F", "--"),
                        Step("G", "++"),
                        Assign("H", 100), Step("H", "++"), Step("H", "--"), Step("H", "--"),
                    ]))
    yield _straight(group, "left-to-right",
                    "expressions are evaluated strictly left to right, no precedence; "
                    "the target is written last", Straight([
                        Assign("A", 2, (("+", 3), ("<", 2))),
                        Assign("B", 1, (("-", 2), ("-", 3))),
                        Assign("a", 100), Assign("b", -3), Assign("C", 7),
                        Assign("C", "a", (("<", 3), ("+", "b"), (">", 6), ("+", "C"))),
                        Assign("F", Hex("4321")),
                        Assign("H", "C", (("+", Hex("12")), ("+", "F"), ("&", Hex("AA55")))),
                        Assign("D", -1, ((">", 1), ("<", 1))),
                        Assign("E", 1, (("<", 15), (">", 15))),
                        Assign("G", "G", (("+", 1), ("+", "G"), ("-", "G"))),
                    ]))
    for op, word in ALU_NAMES.items():
        pairs = [(a, b) for a in EDGES for b in EDGES]
        half = (len(pairs) + 1) // 2
        for part, chunk in enumerate((pairs[:half], pairs[half:]), start=1):
            yield _straight(group, f"{word}-immediates-{part}",
                            f"`{op}` on every pair of edge values (-32768, -1, 0, 1, 32767, "
                            f"$5555, $AAAA), both constants (LDI, {word.upper()}I), "
                            f"part {part} of 2", Straight([
                                Assign(target, a, ((op, b),))
                                for target, (a, b) in zip(FREE, chunk, strict=False)
                            ]))
            bank = dict(zip("jklmnop", EDGES, strict=True))
            of_value = {value: name for name, value in bank.items()}
            targets = [name for name in FREE if name not in bank]
            yield _straight(group, f"{word}-variables-{part}",
                            f"`{op}` on every pair of edge values held in variables "
                            f"(LDV, {word.upper()}V), part {part} of 2", Straight([
                                *(Assign(name, value) for name, value in bank.items()),
                                *(Assign(target, of_value[a], ((op, of_value[b]),))
                                  for target, (a, b) in zip(targets, chunk, strict=False)),
                            ]))
    yield _straight(group, "result-operands",
                    "a call's result as the first operand (LDR) and as the operand of "
                    "every operator (ADDR ... SHRR), evaluated where it stands",
                    Straight([
                        Assign("A", Port(1)),
                        Assign("B", 32767, (("+", Port(1)),)),
                        Assign("C", -32768, (("-", Port(1)),)),
                        Assign("D", Hex("AAAA"), (("&", Port(2)),)),
                        Assign("E", Hex("5500"), (("|", Port(2)),)),
                        Assign("F", Hex("00FF"), (("^", Port(2)),)),
                        Assign("G", 1, (("<", Port(3)),)),
                        Assign("H", -1, ((">", Port(3)),)),
                        Assign("I", 3, (("<", Port(4)),)),
                        Assign("J", -32768, ((">", Port(4)),)),
                        Assign("K", Port(4), (("+", Port(3)), ("-", Port(1)))),
                    ], ports={1: [255], 2: [170, 85], 3: [17], 4: [15]}))


# --- shifts ------------------------------------------------------------------------------

SHIFT_COUNTS = [-32768, -32767, -256, *range(-17, 18), 256, 32767]
SHIFT_VALUES: list[Operand] = [1, -1, 32767, -32768, Hex("1234"), Hex("EDCB")]


def _value_label(value: Operand) -> str:
    if isinstance(value, Hex):
        return "x" + value.digits.lower()
    return str(value).replace("-", "minus")


def shifts() -> Iterator[Case]:
    for op, word in (("<", "left"), (">", "right")):
        for value in SHIFT_VALUES:
            label = _value_label(value)
            yield _straight("shifts", f"shift-{word}-{label}-by-constants",
                            f"`{render(value)}{op}n` for every count n in -17..17 and -32768, "
                            "-32767, -256, 256, 32767, the count an immediate "
                            f"(SH{word[0].upper()}I)",
                            Straight([Assign(target, value, ((op, count),))
                                      for target, count in zip(FREE, SHIFT_COUNTS,
                                                               strict=False)]))
            targets = [name for name in FREE if name != "n"]
            statements: list[Assign | Step] = []
            for target, count in zip(targets, SHIFT_COUNTS, strict=False):
                statements += [Assign("n", count), Assign(target, value, ((op, "n"),))]
            yield _straight("shifts", f"shift-{word}-{label}-by-variables",
                            f"the same counts held in a variable (SH{word[0].upper()}V)",
                            Straight(statements))
    yield _shifts_by_results()


def _shifts_by_results() -> Case:
    """Counts a C VM reads from R, not from V or an immediate: negative, 16 and more, and
    -32768 (spec/language.md 7.2: a negative count shifts the other way)."""
    return Case("shifts", "shift-counts-from-results",
                "`<` and `>` by a call's result (SHLR, SHRR): (IMG) areas -1, -2, 16, 16, "
                "-32768, -32768 and (KYO) centres -3, 16 as counts",
                "A=1<(IMG)\nB=$100<(IMG)\nC=3<(IMG)\nD=$4000>(IMG)\nE=1>(IMG)\nF=-8<(IMG)\n"
                "G=$80>(KYO)\nH=-2<(KYO)\n",
                {"A": 0, "B": 64, "C": 0, "D": 0, "E": 0, "F": -1, "G": 1024, "H": 0,
                 "w": -32768},
                sensors={"IMG": [{"area": area, "x": 0, "y": 0, "z": 0}
                                 for area in (-1, -2, 16, 16, -32768, -32768)],
                         "KYO": [{"centre": -3, "right": 0, "left": 0},
                                 {"centre": 16, "right": 0, "left": 0}]})


# --- control -----------------------------------------------------------------------------

RELATIONS = {"=": lambda v: v == 0, ">": lambda v: v > 0, "<": lambda v: v < 0}


def _compare_with_zero() -> Case:
    """Each relation on -32768, -1, 0, 1, 32767: a result variable ends at 2 when the
    jump is taken and 1 when it is not."""
    lines: list[str] = []
    expected: dict[str, int] = {}
    checks = [(relation, value) for relation in RELATIONS
              for value in (-32768, -1, 0, 1, 32767)]
    for index, ((relation, value), result) in enumerate(zip(checks, FREE, strict=False)):
        taken, after = f"{2 * index:02d}", f"{2 * index + 1:02d}"
        lines += [f"n={value}", f"?n{relation}#{taken}", f"{result}=1", f"#{after}",
                  f":{taken} {result}=2", f":{after}"]
        expected[result] = 2 if RELATIONS[relation](value) else 1
        expected["n"] = value
    return Case("control", "compare-with-zero",
                "?V=#NN, ?V>#NN and ?V<#NN (JZ, JGT, JLT) on -32768, -1, 0, 1 and 32767, "
                "taken and not taken; JMP; labels with no statement after them",
                "".join(line + "\n" for line in lines), expected)


def control() -> Iterator[Case]:
    yield _compare_with_zero()
    yield Case("control", "counted-loop", "a backward conditional jump counting @ down",
               "@=5; A=0\n:10 A=A+3; @--; ?@>#10\n(END)\n", {"A": 15})
    yield Case("control", "goto-order", "unconditional jumps forward and backward",
               "#20\n:10 A=1; #30\n:20 B=2; A=B; #10\n:30 C=A+B\n", {"A": 1, "B": 2, "C": 3})
    yield Case("control", "end-stops-the-program", "(END) ends the run; nothing after runs",
               "A=1\n(END)\nA=2\n", {"A": 1})
    yield Case("control", "jump-to-the-end",
               "a label with no statement after it names the end of the program",
               "A=1; #50\nA=2\n:50\n", {"A": 1})
    yield Case("control", "end-keeps-moving", "(END) does not stop a MOV in effect: the "
               "device gets no stop", "(MOV 3,3)\n(END)\n", {}, trace=((0, "MOV", (3, 3)),))
    yield Case("control", "fall-off-the-end", "running past the last statement is (END)",
               "A=1\nB=A+1\n", {"A": 1, "B": 2})
    yield Case("control", "layout",
               "comments, blank lines, empty statements, a label alone on its line, "
               "reserved variables assigned by the program",
               "'a comment line\n\n;;A=1;;B=2;\n:10 ; C=3 ' a comment\n;\n:11\n"
               "D=A+B+C; x=5; x++\n", {"A": 1, "B": 2, "C": 3, "D": 6, "x": 6})


# --- calls -------------------------------------------------------------------------------


def _call(form: tuple[str, str | None], args: list[str]) -> str:
    mnemonic, selector = form
    words = mnemonic + (f" {selector}" if selector else "")
    return f"({words} {','.join(args)})" if args else f"({words})"


def _safe(params: tuple[Param, ...], values: list[int]) -> bool:
    """False for an MVI that the scripted device refuses (the centre would not move)."""
    return not (len(params) == 3 and values[0] + values[1] == 0 and values[2] != 0)


def _form_with_arguments(form: tuple[str, str | None], compact: bool = False) -> Case:
    """Both ends of every parameter's range, as constants, as variables, and mixed;
    `compact`: of the range's part that fits a byte, at -O2 (the compact calls)."""
    spec = BUILTINS[form[0]].form(form[1])
    assert spec is not None
    params = spec.params
    names = "abc"[:len(params)]
    lows = [max(param.low, -0x80) if compact else param.low for param in params]
    highs = [min(param.high, 0x7F) if compact else param.high for param in params]
    assert _safe(params, lows) and _safe(params, highs)
    variables: dict[str, int] = {}
    lines: list[str] = []
    calls: list[TraceItem] = []

    def call(values: list[int], as_variable: list[bool]) -> None:
        for name, value, is_var in zip(names, values, as_variable, strict=True):
            if is_var:
                lines.append(f"{name}={value}")
                variables[name] = value
        lines.append(_call(form, [name if is_var else str(value) for name, value, is_var
                                  in zip(names, values, as_variable, strict=True)]))
        calls.append((None, " ".join(filter(None, form)), tuple(values)))

    for values in (lows, highs):
        call(values, [False] * len(params))
    for values in (lows, highs):
        call(values, [True] * len(params))
    if len(params) > 1:
        call(highs, [True] + [False] * (len(params) - 1))
        call(lows, [False] + [True] * (len(params) - 1))
    label = "-".join(filter(None, form)).lower()
    if compact:
        return Case("compact", f"compact-call-{label}",
                    f"{_call(form, list(names))} as a compact call (-O2, format 1.3): both "
                    "ends of each range within -128..127, as constants, as variables and "
                    "mixed", "".join(line + "\n" for line in lines),
                    {name: value for name, value in variables.items() if value},
                    trace=tuple(calls), sensors=REPEAT if form == ("INP", None) else {},
                    level=2)
    return Case("calls", f"call-{label}", f"{_call(form, list(names))} with both ends of each "
                "range, as constants, as variables and mixed",
                "".join(line + "\n" for line in lines),
                {name: value for name, value in variables.items() if value}, trace=tuple(calls),
                sensors=REPEAT if form == ("INP", None) else {})


def calls() -> Iterator[Case]:
    group = "calls"
    for info in sorted(isa.OPCODES.values(), key=lambda info: info.opcode):
        if info.builtin is not None and info.arity and not info.compact:
            yield _form_with_arguments(info.builtin)
    yield Case(group, "calls-without-arguments",
               "FRE, HLD, ORG, KYC, CAM Z, CAM U, CAM D; the built-ins that wait take "
               "100 ms of device time, the others none",
               "(FRE); (HLD); (ORG); (KYC)\n(CAM Z); (CAM U); (CAM D)\n", {},
               trace=((0, "FRE", ()), (0, "HLD", ()), (0, "ORG", ()), (100, "KYC", ()),
                      (100, "CAM Z", ()), (200, "CAM U", ()), (300, "CAM D", ())))
    yield Case(group, "timing",
               "device time: TIM t waits t x 100 ms, ROT |a| x 10 ms, MVI |cm| x 400 / "
               "|l+r| ms rounded up, MOV none, other waiting calls 100 ms",
               "(TIM 1); (ROT -45); (STR 10)\n(MVI 3,4,-70); (MOV 2,2); (TIM 100); (ORG)\n"
               "(MOV 0,0)\n", {},
               trace=((0, "TIM", (1,)), (100, "ROT", (-45,)), (550, "STR", (10,)),
                      (650, "MVI", (3, 4, -70)), (4650, "MOV", (2, 2)),
                      (4650, "TIM", (100,)), (14650, "ORG", ()), (14750, "MOV", (0, 0))))
    yield Case(group, "kyo-results", "(KYO) as an operand and as a statement: the result is the "
               "centre's movement, u the right wheel's, v the left wheel's; operands are "
               "read when the evaluation reaches them",
               "(KYC)\nA=(KYO)\n(KYO)\nB=u+(KYO)\nC=(KYO)+u\n",
               {"A": 50, "B": 91, "C": 201, "u": 101, "v": 99},
               sensors={"KYO": [{"centre": 50, "right": 52, "left": 48},
                                {"centre": -7, "right": -9, "left": -5},
                                {"centre": 100, "right": 101, "left": 99}], **REPEAT})
    yield Case(group, "img-results", "(IMG) writes w, x, y, z and returns the area; x read before "
               "an (IMG) in the same expression is the old x; the target is written last",
               "(SCN 5)\n(IMG)\nA=(IMG)\nB=x+(IMG)\nx=(IMG)+1\n",
               {"A": 120, "B": 129, "w": -1, "x": 0, "y": 32767, "z": 359},
               sensors={"IMG": [{"area": 7, "x": 8, "y": 9, "z": 10},
                                {"area": 120, "x": 130, "y": 100, "z": -5},
                                {"area": -1, "x": -32768, "y": 32767, "z": 359}],
                        **REPEAT},
               trace=((0, "SCN", (5,)), (0, "IMG", ()), (100, "IMG", ()), (200, "IMG", ()),
                      (300, "IMG", ())))
    yield Case(group, "cam-r-results", "(CAM R) returns the pan position and writes no variable",
               "(CAM P 100)\nA=(CAM R)\nB=(CAM R)+1\n(CAM R)\nC=0-(CAM R)\n",
               {"A": 392, "B": 785, "C": -784}, sensors={"CAM R": [392, 784], **REPEAT})
    yield Case(group, "ult-results", "(ULT A) .. (ULT D): each sensor its own readings; a list "
               "that runs out repeats its last reading; a sensor with none reads 0",
               "A=(ULT A)\nB=(ULT B)\nC=(ULT B)\nD=(ULT C)\nE=(ULT D)\n(ULT A)\nF=(ULT B)\n",
               {"A": 150, "B": 1, "C": 2, "D": -5, "F": 2},
               sensors={"ULT A": [150], "ULT B": [1, 2], "ULT C": [-5], **REPEAT})
    yield Case(group, "inp-results", "(INP p) with a constant and a variable port, both "
               "ends of the port range; each port its own readings",
               "A=(INP 0)\np=0; B=(INP p)\np=125; C=(INP p)\nD=(INP 125)\nE=(INP 3)\n",
               {"A": 9, "B": 255, "p": 125, "C": 7, "D": 7},
               sensors={"INP": {"0": [9, 255], "125": [7]}, **REPEAT})
    yield Case(group, "fzi-results", "(FZI) writes s and t and returns nothing",
               "(FZI)\nA=s; B=t\n(FZI)\n(FZI)\n",
               {"A": 1, "B": -2, "s": 32767, "t": -32768},
               sensors={"FZI": [{"s": 1, "t": -2}, {"s": 32767, "t": -32768}], **REPEAT})


# --- tracing -----------------------------------------------------------------------------

HANDLERS = "".join(f":{label} G++; H={label}; (TIM 50); (END)\n" for label in (96, 97, 98, 99))
TRACING_MODES = {0: "ignored", 1: "goes straight, no jump", 2: "stops, jumps",
                 3: "keeps moving, jumps"}


def _mov_case(mode: int) -> Case:
    """A line lost at 500 ms and at 800 ms while (MOV 3,3) is in effect during (TIM 10)."""
    start: tuple[TraceItem, ...] = ((0, "TRC", (mode,)), (0, "MOV", (3, 3)),
                                    (0, "TIM", (10,)))
    if mode == 0:
        trace, variables = (*start, (1000, "MOV", (0, 0))), {"H": 1}
    elif mode == 1:
        trace = (*start, (500, "LINE LOST", (1,)), (800, "LINE LOST", (1,)),
                 (1000, "MOV", (0, 0)))
        variables = {"H": 1}
    elif mode == 2:  # stopped at 500, so the loss at 800 finds no motion
        trace, variables = (*start, (500, "LINE LOST", (2,)), (500, "TIM", (50,))), \
            {"G": 1, "H": 98}
    else:  # still moving, so the loss at 800 ends the handler's wait and jumps again
        trace = (*start, (500, "LINE LOST", (3,)), (500, "TIM", (50,)),
                 (800, "LINE LOST", (3,)), (800, "TIM", (50,)))
        variables = {"G": 2, "H": 96}
    return Case("tracing", f"mode-{mode}-lost-during-mov",
                f"tracing mode {mode}, line lost during MOV: {TRACING_MODES[mode]}"
                + (" (:98)" if mode == 2 else " (:96)" if mode == 3 else ""),
                f"(TRC {mode})\n(MOV 3,3)\n(TIM 10)\nH=1\n(MOV 0,0)\n(END)\n" + HANDLERS,
                variables, sensors={"line_lost": [{"time": 500}, {"time": 800}]},
                trace=trace)


def _mvi_case(mode: int) -> Case:
    """Lines lost 3000 ms and 6000 ms into (MVI 2,2,100), which takes 10000 ms."""
    start: tuple[TraceItem, ...] = ((0, "TRC", (mode,)), (0, "MVI", (2, 2, 100)))
    if mode == 0:
        trace, variables = start, {"H": 1}
    elif mode == 1:
        trace = (*start, (3000, "LINE LOST", (1,)), (6000, "LINE LOST", (1,)))
        variables = {"H": 1}
    elif mode == 2:  # the MVI is aborted at 3000: the loss at 6000 finds no motion
        trace = (*start, (3000, "LINE LOST", (2,)), (3000, "TIM", (50,)))
        variables = {"G": 1, "H": 99}
    else:  # the MVI runs on in the background until 10000
        trace = (*start, (3000, "LINE LOST", (3,)), (3000, "TIM", (50,)),
                 (6000, "LINE LOST", (3,)), (6000, "TIM", (50,)))
        variables = {"G": 2, "H": 97}
    return Case("tracing", f"mode-{mode}-lost-during-mvi",
                f"tracing mode {mode}, line lost during MVI: {TRACING_MODES[mode]}"
                + (" (:99)" if mode == 2 else " (:97)" if mode == 3 else ""),
                f"(TRC {mode})\n(MVI 2,2,100)\nH=1\n(END)\n" + HANDLERS, variables,
                sensors={"line_lost": [{"during": "MVI", "nth": 1, "after": 3000},
                                       {"during": "MVI", "nth": 1, "after": 6000}]},
                trace=trace)


def tracing() -> Iterator[Case]:
    group = "tracing"
    for mode in range(4):
        yield _mov_case(mode)
        yield _mvi_case(mode)
    yield Case(group, "lost-without-motion",
               "a lost line with no motion in effect is ignored in every mode: none yet, "
               "after MOV 0,0, after FRE, after HLD",
               "(TRC 2)\n(TIM 10)\n(MOV 0,0)\n(TIM 10)\n(TRC 3)\n(MOV 3,3); (FRE)\n(TIM 10)\n"
               "(MOV 2,2); (HLD)\n(TIM 10)\nH=1\n(END)\n" + HANDLERS, {"H": 1},
               sensors={"line_lost": [{"time": 500}, {"time": 1500}, {"time": 2500},
                                      {"time": 3500}]},
               trace=((0, "TRC", (2,)), (0, "TIM", (10,)), (1000, "MOV", (0, 0)),
                      (1000, "TIM", (10,)), (2000, "TRC", (3,)), (2000, "MOV", (3, 3)),
                      (2000, "FRE", ()), (2000, "TIM", (10,)), (3000, "MOV", (2, 2)),
                      (3000, "HLD", ()), (3000, "TIM", (10,))))
    yield Case(group, "mvi-zero-distance", "(MVI l,r,0) returns at once and leaves no "
               "motion in effect: a lost line after it is ignored",
               "(TRC 3)\n(MVI 2,2,0)\n(TIM 10)\nH=1\n(END)\n" + HANDLERS, {"H": 1},
               sensors={"line_lost": [{"time": 500}]},
               trace=((0, "TRC", (3,)), (0, "MVI", (2, 2, 0)), (0, "TIM", (10,))))
    yield Case(group, "lost-during-an-operand",
               "a line lost during (IMG) in `A=(IMG)-180` jumps right after the call: "
               "IMG's variables are written, A is not",
               "(TRC 3)\n(MOV 3,3)\nA=(IMG)-180; B=1\n(END)\n" + HANDLERS,
               {"G": 1, "H": 96, "w": 200, "x": 10, "y": 20, "z": 30},
               sensors={"IMG": [{"area": 200, "x": 10, "y": 20, "z": 30}],
                        "line_lost": [{"during": "MOV", "nth": 1, "after": 50}]},
               trace=((0, "TRC", (3,)), (0, "MOV", (3, 3)), (0, "IMG", ()),
                      (50, "LINE LOST", (3,)), (100, "TIM", (50,))))
    yield Case(group, "one-event-pending",
               "two losses during one call that does not end early (ROT): both are "
               "recorded, the program jumps once",
               "(TRC 3)\n(MOV 3,3)\n(ROT 90)\n(END)\n" + HANDLERS, {"G": 1, "H": 96},
               sensors={"line_lost": [{"time": 200}, {"time": 400}]},
               trace=((0, "TRC", (3,)), (0, "MOV", (3, 3)), (0, "ROT", (90,)),
                      (200, "LINE LOST", (3,)), (400, "LINE LOST", (3,)),
                      (900, "TIM", (50,))))
    yield Case(group, "mode-persists-after-the-jump",
               "the tracing mode stays set across a handler jump: a new MOV in the "
               ":98 handler loses the line and jumps to :98 again",
               "(TRC 2)\n(MOV 3,3)\n(TIM 10)\n(END)\n"
               ":98 G++; (MOV 1,1); (TIM 10); (MOV 0,0); (END)\n", {"G": 2},
               sensors={"line_lost": [{"time": 500}, {"time": 800}]},
               trace=((0, "TRC", (2,)), (0, "MOV", (3, 3)), (0, "TIM", (10,)),
                      (500, "LINE LOST", (2,)), (500, "MOV", (1, 1)), (500, "TIM", (10,)),
                      (800, "LINE LOST", (2,)), (800, "MOV", (1, 1)), (800, "TIM", (10,)),
                      (1800, "MOV", (0, 0))))


# --- events: losses between instructions, and what a wait does with them ----------------

EVENT_HANDLERS = "(END)\n:96 H=96; (END)\n:98 H=98; (END)\n"


def events() -> Iterator[Case]:
    group = "events"
    for name, jump, mode, covers in (
            ("event-at-a-jump", "#20", 3, "a loss posted between instructions is taken at "
             "the next jump taken (#NN), before its target runs"),
            ("event-at-a-conditional-jump", "?A>#20", 2, "the same at a conditional jump "
             "whose condition holds; mode 2 stops the MOV")):
        yield Case(group, name, covers,
                   f"(TRC {mode})\n(MOV 1,1)\nA++\n{jump}\nB++\n:20 C++\n" + EVENT_HANDLERS,
                   {"A": 1, "H": 102 - 2 * mode}, sensors={"line_lost": [{"instruction": 3}]},
                   trace=((0, "TRC", (mode,)), (0, "MOV", (1, 1)),
                          (0, "LINE LOST", (mode,))),
                   executed=7)
    yield Case(group, "event-waits-for-an-event-point",
               "straight code and a conditional jump not taken take no event; a call that "
               "takes no device time (KYC) does, right after it",
               "(TRC 3)\n(MOV 1,1)\nA++\n?B>#20\nB++\n(KYC)\n:20 C++\n" + EVENT_HANDLERS,
               {"A": 1, "B": 1, "H": 96}, sensors={"line_lost": [{"instruction": 2}]},
               trace=((0, "TRC", (3,)), (0, "MOV", (1, 1)), (0, "LINE LOST", (3,)),
                      (0, "KYC", ())),
               executed=9)
    yield Case(group, "event-pending-at-the-end",
               "(END) is no event point: an event still pending when the program ends is "
               "never taken, and the MOV keeps going",
               "(TRC 3)\n(MOV 1,1)\nA++\n" + EVENT_HANDLERS,
               {"A": 1}, sensors={"line_lost": [{"instruction": 3}]},
               trace=((0, "TRC", (3,)), (0, "MOV", (1, 1)), (0, "LINE LOST", (3,))),
               executed=4)
    yield Case(group, "event-at-the-end-of-a-wait",
               "a loss at the very millisecond a TIM ends: the TIM ends, the event is taken "
               "right after it",
               "(TRC 3)\n(MOV 1,1)\n(TIM 10)\nA++\n" + EVENT_HANDLERS,
               {"H": 96}, sensors={"line_lost": [{"time": 1000}]},
               trace=((0, "TRC", (3,)), (0, "MOV", (1, 1)), (0, "TIM", (10,)),
                      (1000, "LINE LOST", (3,))))
    yield Case(group, "two-losses-in-one-millisecond",
               "two losses at the same millisecond are one loss: one LINE LOST, one event, "
               "which ends the TIM early",
               "(TRC 3)\n(MOV 1,1)\n(TIM 10)\nA++\n" + EVENT_HANDLERS,
               {"H": 96}, sensors={"line_lost": [{"time": 500}, {"time": 500}]},
               trace=((0, "TRC", (3,)), (0, "MOV", (1, 1)), (0, "TIM", (10,)),
                      (500, "LINE LOST", (3,))))
    yield Case(group, "mode-2-during-a-background-mvi",
               "an MVI running in the background after a mode-3 loss (:97) is stopped by a "
               "mode-2 loss, which jumps to :99 and ends the TIM early",
               "(TRC 3)\n(MVI 2,2,100)\n(END)\n:97 (TRC 2); (TIM 50); (END)\n"
               ":99 H=99; (TIM 10); (END)\n",
               {"H": 99}, sensors={"line_lost": [{"during": "MVI", "nth": 1, "after": 1000},
                                                 {"during": "MVI", "nth": 1, "after": 3000}]},
               trace=((0, "TRC", (3,)), (0, "MVI", (2, 2, 100)), (1000, "LINE LOST", (3,)),
                      (1000, "TRC", (2,)), (1000, "TIM", (50,)), (3000, "LINE LOST", (2,)),
                      (3000, "TIM", (10,))))
    for command in ("MOV 1,1", "FRE"):
        yield Case(group, f"{command.split()[0].lower()}-replaces-a-background-mvi",
                   f"({command}) in the :97 handler replaces the MVI running in the "
                   "background: a later loss timed during that MVI is nothing",
                   f"(TRC 3)\n(MVI 2,2,100)\n(END)\n:97 G++; ({command}); (TIM 50); (END)\n"
                   ":96 H=96; (END)\n",
                   {"G": 1}, sensors={"line_lost": [
                       {"during": "MVI", "nth": 1, "after": 1000},
                       {"during": "MVI", "nth": 1, "after": 3000}]},
                   trace=((0, "TRC", (3,)), (0, "MVI", (2, 2, 100)),
                          (1000, "LINE LOST", (3,)),
                          (1000, "FRE", ()) if command == "FRE" else (1000, "MOV", (1, 1)),
                          (1000, "TIM", (50,))))


# --- faults ------------------------------------------------------------------------------

FAULT_PREFIX = "' the fault's line is counted from the top\n(MOV 2,2)\n"


def _in_range(param: Param) -> int:
    return max(param.low, min(param.high, 1))


def _range_faults() -> Iterator[Case]:
    for info in sorted(isa.OPCODES.values(), key=lambda info: info.opcode):
        spec = info.form
        if info.builtin is None or spec is None or info.compact:
            continue
        for index, param in enumerate(spec.params):
            if (param.low, param.high) == (-32768, 32767):
                continue  # no 16-bit value is out of this range
            for side, bad in (("below", param.low - 1), ("above", param.high + 1)):
                args = [str(_in_range(other)) for other in spec.params]
                args[index] = "a"
                label = "-".join(filter(None, info.builtin)).lower()
                yield Case("faults", f"range-{label}-{param.name}-{side}",
                           f"argument {param.name} of {_call(info.builtin, ['...'])} "
                           f"{side} {param.low}..{param.high} (the value {bad} in a "
                           "variable): fault after the vehicle is stopped",
                           FAULT_PREFIX + f"a={bad}\n{_call(info.builtin, args)}\n",
                           {"a": bad}, status="argument-range", fault_line=4,
                           trace=((0, "MOV", (2, 2)), (0, "STOP", ())))


def _missing_handler(mode: int, command: str, label: int) -> Case:
    others = "".join(f":{other} (END)\n" for other in (96, 97, 98, 99) if other != label)
    loss: dict[str, object]
    if command == "MOV":
        body, line, loss = "(MOV 3,3)\n(TIM 10)\n", 4, {"time": 500}
        trace: tuple[TraceItem, ...] = ((0, "TRC", (mode,)), (0, "MOV", (3, 3)),
                                        (0, "TIM", (10,)), (500, "LINE LOST", (mode,)),
                                        (500, "STOP", ()))
    else:
        body, line, loss = "(MVI 2,2,100)\n", 3, {"during": "MVI", "nth": 1, "after": 3000}
        trace = ((0, "TRC", (mode,)), (0, "MVI", (2, 2, 100)), (3000, "LINE LOST", (mode,)),
                 (3000, "STOP", ()))
    return Case("faults", f"missing-handler-{label}",
                f"tracing mode {mode}, line lost during {command}: the program has no "
                f":{label}", f"'\n(TRC {mode})\n{body}(MOV 0,0)\n(END)\n{others}", {},
                sensors={"line_lost": [loss]}, status="missing-handler", fault_line=line,
                trace=trace)


def faults() -> Iterator[Case]:
    group = "faults"
    yield from _range_faults()
    yield Case(group, "range-in-an-operand",
               "a variable argument out of range in a call used as an operand: the "
               "target is not written",
               "A=5\np=126\nA=(INP p)+1\n", {"A": 5, "p": 126}, status="argument-range",
               fault_line=3, trace=((0, "STOP", ()),))
    yield Case(group, "range-second-argument",
               "the arguments are checked in order; the device gets nothing",
               "a=12; b=13\n(MVI a,b,10)\n", {"a": 12, "b": 13}, status="argument-range",
               fault_line=2, trace=((0, "STOP", ()),))
    for mode, command, label in ((2, "MOV", 98), (2, "MVI", 99), (3, "MOV", 96),
                                 (3, "MVI", 97)):
        yield _missing_handler(mode, command, label)
    yield Case(group, "budget-loop",
               "the budget runs out in an endless loop; it is looked at when a jump is "
               "taken: the 501st #10 brings the count to 1 + 2 x 501 = 1003 > 1001",
               "(MOV 1,1)\n:10 A++; #10\n", {"A": 501}, budget=1001, status="budget",
               fault_line=2, trace=((0, "MOV", (1, 1)), (0, "STOP", ())))
    yield Case(group, "budget-waiting-loop", "the budget runs out in a loop that waits",
               "(MOV 2,2)\n:10 (TIM 1)\n#10\n", {}, budget=11, status="budget",
               fault_line=2,
               trace=((0, "MOV", (2, 2)), *((100 * n, "TIM", (1,)) for n in range(5)),
                      (500, "STOP", ())))
    yield Case(group, "budget-straight-code", "the budget is looked at only at jumps "
               "taken and calls: straight code and (END) run on past it",
               "A++\nB++\nC++\n(END)\n", {"A": 1, "B": 1, "C": 1}, budget=1)
    yield Case(group, "budget-before-a-call", "the budget is checked before a call runs: "
               "the call does not reach the device", "A++\nB++\n(MOV 1,1)\n(END)\n",
               {"A": 1, "B": 1}, budget=2, status="budget", fault_line=3,
               trace=((0, "STOP", ()),))
    yield Case(group, "budget-at-a-conditional-jump",
               "a loop closed by a conditional jump meets the watchdog there: the 501st "
               "?A<#10 brings the count to 2 x 501 = 1002 > 1001",
               ":10 A--; ?A<#10\n", {"A": -501}, budget=1001, status="budget",
               fault_line=1, trace=((0, "STOP", ()),), executed=1002)
    yield Case(group, "budget-not-counting-a-handler-jump",
               "a handler jump is no instruction: TRC, MOV, TIM, then at :96 A++ and the "
               "#10 taken make 5 instructions, within a budget of 5",
               "(TRC 3)\n(MOV 1,1)\n(TIM 10)\n(END)\n:10 B=1; (END)\n:96 A++; #10\n",
               {"A": 1, "B": 1}, budget=5, sensors={"line_lost": [{"time": 500}]},
               trace=((0, "TRC", (3,)), (0, "MOV", (1, 1)), (0, "TIM", (10,)),
                      (500, "LINE LOST", (3,))),
               executed=8)
    yield Case(group, "budget-before-the-range-check",
               "the watchdog is checked before a call's arguments: a call both over budget "
               "and out of range is a budget fault",
               "a++\n" * 13 + "(MOV a,0)\n", {"a": 13}, budget=13, status="budget",
               fault_line=14, trace=((0, "STOP", ()),), executed=14)
    yield Case(group, "failing-poll", "the device fails the 2nd (ULT A), a built-in that "
               "takes device time, at the end of that time (its poll answers an error): a "
               "device error at that call, after the vehicle is stopped; the first reading "
               "was written",
               "(MOV 1,1)\nA=(ULT A)\nB=(ULT A)\n", {"A": 7}, status="device-error",
               fault_line=3, sensors={"ULT A": [7], "fail": {"ULT A": 2}, **REPEAT},
               trace=((0, "MOV", (1, 1)), (0, "ULT A", ()), (100, "ULT A", ()),
                      (200, "STOP", ())),
               executed=5)
    yield Case(group, "readings-run-out", "a sensing call past the last reading of its list "
               "ends the run: the device records the call, then a device error",
               "A=(ULT A)\nB=(ULT A)\nC=1\n", {"A": 150}, status="device-error",
               fault_line=2, sensors={"ULT A": [150]},
               trace=((0, "ULT A", ()), (100, "ULT A", ()), (100, "STOP", ())))
    yield Case(group, "no-readings", "a sensing call that the script gives no list ends the "
               "run likewise, at its first call",
               "(SCN 1)\n(IMG)\n", {}, status="device-error", fault_line=2,
               trace=((0, "SCN", (1,)), (0, "IMG", ()), (0, "STOP", ())))
    yield Case(group, "failing-stop", "the stop after a fault fails: the fault reported is "
               "still the one that caused the stop (argument-range), not a device error",
               "a=13\n(MOV a,0)\n", {"a": 13}, status="argument-range", fault_line=2,
               sensors={"stop_fails": True}, trace=((0, "STOP", ()),), executed=3)
    yield Case(group, "device-error", "the device refuses an MVI whose centre would not "
               "move: a device error, after the vehicle is stopped",
               "(MOV 2,2)\n(MVI 3,-3,10)\n", {}, status="device-error", fault_line=2,
               trace=((0, "MOV", (2, 2)), (0, "MVI", (3, -3, 10)), (0, "STOP", ())))
    yield Case(group, "device-error-variables", "the same refusal, the arguments in "
               "variables", "a=-5; b=5; c=-1900\n\n(MVI a,b,c)\n",
               {"a": -5, "b": 5, "c": -1900}, status="device-error", fault_line=3,
               trace=((0, "MVI", (-5, 5, -1900)), (0, "STOP", ())))


# --- intermediate code written by hand ------------------------------------------------------


def intermediate() -> Iterator[Case]:
    """What the compiler never writes, but a VM must run as section 9 of spec/ilc.md says."""
    group = "ils"
    yield Case(group, "ils-off-the-end", "code with no final END: running past the last "
               "instruction ends the program", "  LDI 5\n  STV A\n", {"A": 5},
               language="ils", executed=2)
    yield Case(group, "ils-empty-code", "an empty code section: the program begins and "
               "ends having run no instruction", "", {}, language="ils", executed=0)
    yield Case(group, "ils-ldr-before-any-call", "R is 0 before any call returns a value",
               "  LDR\n  STV A\n  LDI 7\n  ADDR\n  STV B\n", {"B": 7}, language="ils",
               executed=5)
    yield Case(group, "ils-r-kept-by-calls-without-result",
               "FZI, TIM and MOV return nothing: R still holds IMG's area for SHLR",
               "  IMG\n  FZI\n  TIM 1\n  MOV 0, 0\n  LDI 1\n  SHLR\n  STV A\n",
               {"A": 8, "w": 3, "s": -1, "t": 20},
               sensors={"IMG": [{"area": 3, "x": 0, "y": 0, "z": 0}],
                        "FZI": [{"s": -1, "t": 20}]},
               language="ils", executed=7)
    yield Case(group, "ils-jump-into-a-statement", "a jump into the middle of a "
               "load-operate-store run continues with the accumulator as it is",
               "  LDI 100\n  JMP L1\n  LDI 10\nL1:\n  ADDI 5\n  STV A\n  END\n", {"A": 105},
               language="ils", executed=5)
    yield Case(group, "ils-budget-at-a-conditional-jump-to-a-handler",
               "the budget fault comes at a conditional jump taken even with an event "
               "pending there: the watchdog is checked before the event point",
               ".handler 96 H\n  TRC 3\n  MOV 1, 1\n  INC A\nL:\n  JGT A, L\nH:\n  END\n",
               {"A": 1}, budget=3, status="budget", fault_line=1,
               sensors={"line_lost": [{"instruction": 3}]},
               trace=((0, "TRC", (3,)), (0, "MOV", (1, 1)), (0, "LINE LOST", (3,)),
                      (0, "STOP", ())),
               language="ils", executed=4)


# --- Listing 1 ---------------------------------------------------------------------------


def sample() -> Iterator[Case]:
    source = (EXAMPLES / "sample.rob").read_text(encoding="utf-8")
    sensors = json.loads((EXAMPLES / "sample.sensors.json").read_text(encoding="utf-8"))
    budget = 1_000_000
    # By hand from the listing and the script: the stand is on the right (c=579, d=450);
    # the :14 loop pans to 585, 589 and stays; the approach steers to D=450.
    ending = {"C": 589, "D": 450}
    yield Case("sample", "listing-1", "Listing 1 (examples/sample.rob) with its sensor "
               "script (examples/sample.sensors.json): the paper's program, end to end",
               source, _sample_variables(ending), sensors, budget)
    lost_in_mov = {**sensors, "line_lost": [{"during": "MOV", "nth": 1, "after": 150}]}
    yield Case("sample", "listing-1-lost-line", "Listing 1 losing the line while it traces "
               "in mode 3 at the start: the handler :96 stops, then :99 frees the axes",
               source, {"A": -60, "w": 150, "x": 128, "y": 90}, lost_in_mov, budget,
               trace=((0, "CAM Z", ()), (100, "CAM A", (90,)), (200, "CAM D", ()),
                      (300, "SCN", (0,)), (300, "TRC", (3,)), (300, "MOV", (3, 3)),
                      (300, "IMG", ()), (400, "IMG", ()), (450, "LINE LOST", (3,)),
                      (500, "MOV", (0, 0)), (500, "FRE", ())))
    lost_in_mvi = {**sensors, "line_lost": [{"during": "MVI", "nth": 1, "after": 1000}]}
    yield Case("sample", "listing-1-no-97", "Listing 1 losing the line during its "
               "(MVI 1,1,50) in mode 3: it defines no :97, so the run faults",
               source, _sample_variables(ending), lost_in_mvi, budget,
               status="missing-handler", fault_line=40)


def _sample_variables(ending: dict[str, int]) -> dict[str, int]:
    """The variables at the end of Listing 1's main path with its sensor script, worked
    out by hand (reading the listing against the script's readings)."""
    return {
        # A=(IMG)-100 with the last reading's area 105
        "A": 5,
        # L, U: the x of the scene 4 and scene 3 readings
        "L": 100, "U": 160,
        # X=x-200, Y=y-160 from the :20 loop's last reading (x 129, y 165); the X tests
        # do not run after ?Y>#29 jumps, so X holds 128-200 from the reading before
        "X": 128 - 200, "Y": 5,
        # a=x-128 and the formulas of the :14 loop on its last reading (x 128)
        "a": 0, "b": 0, "c": 0, "d": 0,
        "w": 105, "x": 128, "y": 100,
        **ending,
    }


# --- fused: the superinstructions of format 1.2, as -O2 compiles them ----------------------


def fused() -> Iterator[Case]:
    yield Case("fused", "fused-moves", "MOVV, MOVB, MOVI and MOVR: a variable copied, a "
               "small and a large constant stored, a call's result stored (-O2)",
               "A=(KYO); D=A+1; B=A; C=5; E=-1000; (FZO B,C); G=(ULT A)\n",
               {"A": 42, "u": 40, "v": 44, "B": 42, "C": 5, "D": 43, "E": -1000, "G": 7},
               {"KYO": [{"centre": 42, "right": 40, "left": 44}], "ULT A": [7]}, level=2)
    yield Case("fused", "fused-counted-loop", "DJGT: a counted loop's decrement and jump "
               "(-O2)", "@=3\n:10 A=A+7; (TIM 1); @--; ?@>#10\n(END)\n", {"A": 21},
               level=2)
    yield Case("fused", "fused-store-and-jump", "SJLT, SJZ, SJGT: an expression stored and "
               "tested in one instruction, each jump taken (-O2)",
               "A=(ULT A)-100; ?A<#10\nB=1\n:10 C=(ULT B); ?C=#20\nD=1\n"
               ":20 E=(ULT C)-5; ?E>#30\nF=1\n:30 (END)\n",
               {"A": -50, "B": 0, "C": 0, "D": 0, "E": 5, "F": 0},
               {"ULT A": [50], "ULT B": [0], "ULT C": [10]}, level=2)
    yield Case("fused", "fused-load-and-operate", "ADDVV ... SHRRI: every operator of the "
               "load-and-operate blocks, on two variables, a variable and a constant, a call's "
               "result and a variable, a call's result and a constant (-O2)",
               "A=(ULT A); B=(ULT B)\n"
               "D=A-B; C=A+B; E=A&B; F=A|B; G=A^B; H=A<B; I=A>B\n"
               "J=A+5; K=A-5; L=A&6; M=A|6; N=A^6; O=A<2; P=A>2\n"
               "Q=(ULT C)+B; R=(ULT C)-B; S=(ULT C)&B; T=(ULT C)|B; U=(ULT C)^B; "
               "V=(ULT C)<B; W=(ULT C)>B\n"
               "X=(ULT C)+5; Y=(ULT C)-5; Z=(ULT C)&6; a=(ULT C)|6; b=(ULT C)^6; "
               "c=(ULT C)<2; d=(ULT C)>2\n",
               {"A": 300, "B": 3, "C": 303, "D": 297, "E": 0, "F": 303, "G": 303,
                "H": 2400, "I": 37, "J": 305, "K": 295, "L": 4, "M": 302, "N": 298,
                "O": 1200, "P": 75, "Q": 103, "R": 97, "S": 0, "T": 103, "U": 103, "V": 800,
                "W": 12, "X": 105, "Y": 95, "Z": 4, "a": 102, "b": 98, "c": 400, "d": 25},
               {"ULT A": [300], "ULT B": [3], "ULT C": [100] * 14}, level=2)


# --- compact: the compact calls of format 1.3, as -O2 compiles them ------------------------


def compact() -> Iterator[Case]:
    for info in sorted(isa.OPCODES.values(), key=lambda info: info.opcode):
        if info.compact:
            assert info.builtin is not None
            yield _form_with_arguments(info.builtin, compact=True)
            yield _compact_with_variables(info)
            yield from _compact_range_faults(info)


def _compact_range_faults(info: isa.OpInfo) -> Iterator[Case]:
    """A compact call's variable argument just out of its range, each side (intermediate
    code, the others in range)."""
    form = info.form
    assert form is not None and info.builtin is not None
    names = "abc"[:info.arity]
    label = "-".join(filter(None, info.builtin)).lower()
    for index, param in enumerate(form.params):
        if (param.low, param.high) == (-32768, 32767):
            continue  # no 16-bit value is out of this range
        for side, bad in (("below", param.low - 1), ("above", param.high + 1)):
            values = [_in_range(other) for other in form.params]
            values[index] = bad
            stores = "".join(f"  LDI {value}\n  STV {name}\n"
                             for name, value in zip(names, values, strict=True))
            yield Case("compact", f"compact-range-{label}-{param.name}-{side}",
                       f"{info.name}'s argument {param.name} {side} {param.low}..{param.high} "
                       f"(the value {bad} in a variable; intermediate code)",
                       stores + f"  {info.name} {', '.join(names)}\n",
                       {name: value for name, value in zip(names, values, strict=True)
                        if value},
                       status="argument-range", fault_line=1, language="ils")


def _compact_with_variables(info: isa.OpInfo) -> Case:
    """A compact call on variables only, then mixed, written as intermediate code: -O2
    knows the constants that RL/I assigns, and compiles them into the call."""
    form = info.form
    assert form is not None and info.builtin is not None
    names = "abc"[:info.arity]
    ends = ([max(param.low, -0x80) for param in form.params],
            [min(param.high, 0x7F) for param in form.params])
    lines: list[str] = []
    calls: list[TraceItem] = []
    for values in ends:
        lines += [f"  MOVB {name}, {value}" for name, value in zip(names, values, strict=True)]
        lines.append(f"  {info.name} {', '.join(names)}")
        calls.append((None, " ".join(filter(None, info.builtin)), tuple(values)))
    mixed = [ends[0][0], *ends[1][1:]]  # the first a constant, the others variables
    if _safe(form.params, mixed):
        lines.append(f"  {info.name} {', '.join([str(mixed[0]), *names[1:]])}")
        calls.append((None, calls[-1][1], tuple(mixed)))
    label = "-".join(filter(None, info.builtin)).lower()
    return Case("compact", f"compact-variables-{label}",
                f"{info.name} on variables at both ends of each range within -128..127, "
                "then a constant and variables (intermediate code)",
                "".join(line + "\n" for line in lines),
                {name: value for name, value in zip(names, ends[1], strict=True) if value},
                trace=tuple(calls), sensors=REPEAT if info.builtin == ("INP", None) else {},
                language="ils")
