"""Code generation: the bytes of each construct, jump layout, handler table, features,
the line map and the code size limit; every valid program compiles to a verified file."""


import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import SAMPLE

from rl1.compiler.analysis import analyze
from rl1.compiler.backend import driver, ir
from rl1.compiler.backend.codegen import CodegenError, generate
from rl1.compiler.backend.lower import lower
from rl1.compiler.frontend.parser import parse_program
from rl1.compiler.interpreter import interpret
from rl1.compiler.strategies import checked_programs
from rl1.vm import ilc, isa, machine
from rl1.vm.device import FuzzyReading, ImageReading, Odometry
from rl1.vm.faults import FaultKind, RunResult
from rl1.vm.language import BUILTINS, VARIABLES, Feature
from rl1.vm.scripted import Script, ScriptedDevice, TraceEntry
from rl1.vm.verifier import verify


def compile_text(text: str) -> ilc.Image:
    program, diagnostics = parse_program(text)
    assert diagnostics == []
    return generate(lower(program), "test.rob")


def var(name: str) -> int:
    return VARIABLES.index(name)


def names(image: ilc.Image) -> list[str]:
    return [instruction.info.name for instruction in verify(ilc.encode(image)).instructions]


def test_expression_encodes_as_load_operate_store() -> None:
    # C=a<3+b>6+C: LDV a; SHLI 3; ADDV b; SHRI 6; ADDV C; STV C; then END.
    image = compile_text("C=a<3+b>6+C")
    assert image.code == bytes([
        0x01, var("a"), 0x1D, 3, 0, 0x10, var("b"), 0x1E, 6, 0, 0x10, var("C"),
        0x04, var("C"), 0x00,
    ])


def test_call_operand_reads_r_with_the_r_form_of_the_operator() -> None:
    image = compile_text("A=x+(IMG); B=(KYO)")
    assert names(image) == ["LDV", "IMG", "ADDR", "STV", "KYO", "LDR", "STV", "END"]


def test_call_arguments_mask_marks_the_variables() -> None:
    # MVI is the fourth call form; mask 0b010: only the middle argument is a variable.
    image = compile_text("(MVI 3,c,-50)")
    assert image.code == bytes([isa.CALL_BASE + 3, 0b010, 3, 0, var("c"), 0,
                                0xCE, 0xFF, 0x00])


def test_jump_to_the_next_block_is_left_out_and_others_resolve_to_offsets() -> None:
    # B0 falls into :10 (no JMP); the branch falls into B1 (no JMP); #10 goes back.
    image = compile_text("A=1\n:10 A--; ?A=#20; #10\n:20 (END)")
    instructions = verify(ilc.encode(image)).instructions
    assert [i.info.name for i in instructions] == ["LDI", "STV", "DEC", "JZ", "JMP", "END"]
    label_10, label_20 = instructions[2].offset, instructions[5].offset
    assert instructions[3].operands == (var("A"), label_20)
    assert instructions[4].operands == (label_10,)


def test_branch_whose_fall_through_is_not_next_gets_a_jump() -> None:
    program = ir.Program({
        "B0": ir.Block("B0", [], ir.Branch(ir.Var("A"), ">", "B1", "B2", 1)),
        "B1": ir.Block("B1", [], ir.End(2)),
        "B2": ir.Block("B2", [], ir.End(3)),
    }, "B0")
    instructions = verify(ilc.encode(generate(program, "x.rob"))).instructions
    assert [(i.info.name, i.operands) for i in instructions] == [
        ("JGT", (var("A"), 7)), ("JMP", (8,)), ("END", ()), ("END", ()),
    ]


def test_sample_compiles_decodes_and_verifies() -> None:
    image = generate(lower(parse_program(SAMPLE.read_text(encoding="utf-8"))[0]), "sample.rob")
    data = ilc.encode(image)
    assert ilc.decode(data) == image
    verified = verify(data)
    by_offset = {i.offset: i for i in verified.instructions}
    # :96 starts with (MOV 0,0), :99 with (FRE).
    assert set(image.handlers) == {96, 99}
    assert by_offset[image.handlers[96]].info.name == "MOV"
    assert by_offset[image.handlers[99]].info.name == "FRE"
    assert image.features == {Feature.MOTION, Feature.STEERING, Feature.CAMERA,
                              Feature.VISION}
    assert image.debug is not None
    assert image.debug.source_name == "sample.rob"
    assert image.debug.line_at(image.handlers[96]) == 41
    assert image.debug.line_at(len(image.code) - 1) == 43


def test_line_map_has_one_entry_per_instruction() -> None:
    image = compile_text("A=1\n\n(MOV 1,1); B++\n#00\n:00 (END)")
    assert image.debug is not None
    # LDI, STV on line 1; MOV, INC on line 3; #00 jumps to the next block: no code.
    assert image.debug.lines == ((0, 1), (3, 1), (5, 3), (11, 3), (13, 5))


def test_features_are_those_of_the_calls_made() -> None:
    assert compile_text("A=(ULT C); (FZI); (TIM 5)").features == {
        Feature.ULTRASONIC, Feature.FUZZY,  # TIM needs no device feature
    }
    assert compile_text("(OUT 1,2)").features == {Feature.IO}


def test_code_of_exactly_65535_bytes_fits() -> None:
    # 32767 two-byte INCs and a one-byte END.
    image = generate(_incs(32767), "big.rob")
    assert len(image.code) == 65535
    verify(ilc.encode(ilc.strip_debug(image)))


def test_code_past_65535_bytes_is_refused_at_the_line_where_it_passes() -> None:
    with pytest.raises(CodegenError) as refused:
        generate(_incs(32768), "big.rob")
    diagnostic = refused.value.diagnostic
    assert diagnostic.code == "E0190" and diagnostic.is_error
    # INC number 32768 (line 32768) would end at byte 65536.
    assert diagnostic.span.line == 32768
    assert "65535 bytes" in diagnostic.message


def test_lines_past_65535_are_refused_in_the_line_map_only() -> None:
    program = ir.Program({"B0": ir.Block("B0", [ir.StepVar(ir.Var("A"), "++", 65535)],
                                         ir.End(65536))}, "B0")
    with pytest.raises(CodegenError) as refused:
        generate(program, "long.rob")
    assert refused.value.diagnostic.code == "E0191"
    assert refused.value.diagnostic.span.line == 65536
    image = generate(program, "long.rob", debug=False)
    assert image.debug is None and names(image) == ["INC", "END"]


def _incs(count: int) -> ir.Program:
    block = ir.Block("B0", [ir.StepVar(ir.Var("A"), "++", line)
                           for line in range(1, count + 1)], ir.End(count))
    return ir.Program({"B0": block}, "B0")


# Every valid program compiles to a file the verifier accepts ----------------------------

VALUE_CALLS = ["(KYO)", "(IMG)", "(CAM R)", "(ULT A)", "(ULT D)", "(INP 3)", "(INP q)"]
OPERATORS = "+-&|^<>"
LABELS = st.integers(0, 99).map(lambda n: f"{n:02d}")


@st.composite
def operands(draw: st.DrawFn) -> str:
    return draw(st.one_of(
        st.sampled_from(VARIABLES),
        st.integers(-32768, 32767).map(str),
        st.integers(0, 0xFFFF).map(lambda n: f"${n:X}"),
        st.sampled_from(VALUE_CALLS),
    ))


@st.composite
def calls(draw: st.DrawFn) -> str:
    builtin = draw(st.sampled_from(sorted(BUILTINS.values(), key=lambda b: b.mnemonic)))
    form = draw(st.sampled_from(builtin.forms))
    args = [draw(st.one_of(st.sampled_from(VARIABLES), st.integers(p.low, p.high).map(str)))
            for p in form.params]
    words = [builtin.mnemonic, *([form.selector] if form.selector else [])]
    return "(" + " ".join(words) + (" " + ",".join(args) if args else "") + ")"


@st.composite
def valid_programs(draw: st.DrawFn) -> str:
    """Source texts without errors whose jumps go anywhere: backwards, into loops, past
    code that nothing then reaches. (strategies.checked_programs jumps only in ways that
    make a program end.)"""
    defined = draw(st.lists(LABELS, min_size=1, max_size=6, unique=True))
    lines: list[str] = []
    for index in range(draw(st.integers(1, 12))):
        statements = []
        for _ in range(draw(st.integers(0, 4))):
            kind = draw(st.integers(0, 4))
            variable = draw(st.sampled_from(VARIABLES))
            if kind == 0:
                rest = draw(st.lists(st.tuples(st.sampled_from(OPERATORS), operands()),
                                     max_size=4))
                statements.append(variable + "=" + draw(operands())
                                  + "".join(op + operand for op, operand in rest))
            elif kind == 1:
                statements.append(variable + draw(st.sampled_from(["++", "--"])))
            elif kind == 2:
                statements.append("#" + draw(st.sampled_from(defined)))
            elif kind == 3:
                relation = draw(st.sampled_from("=<>"))
                statements.append(f"?{variable}{relation}#{draw(st.sampled_from(defined))}")
            else:
                statements.append(draw(calls()))
        label = f":{defined[index]} " if index < len(defined) else ""
        lines.append(label + "; ".join(statements))
    lines += [f":{label}" for label in defined[len(lines):]]
    return "\n".join(lines) + "\n"


@settings(max_examples=100, deadline=None)
@given(st.one_of(valid_programs(), checked_programs()))
def test_every_valid_program_compiles_to_valid_ir_and_verified_bytes(text: str) -> None:
    analysis = analyze(text)
    assert not analysis.has_errors
    lowered = lower(analysis.program)
    assert ir.validate(lowered) == []
    image = generate(lowered, "generated.rob")
    data = ilc.encode(image)
    assert ilc.decode(data) == image
    verified = verify(data)
    assert image.debug is not None
    assert [offset for offset, _ in image.debug.lines] == [
        instruction.offset for instruction in verified.instructions
    ]
    assert verify(ilc.encode(ilc.strip_debug(image))).instructions == verified.instructions


INT16 = st.integers(-32768, 32767)


@st.composite
def scripts(draw: st.DrawFn) -> Script:
    """Sensor readings without line losses (the two engines take a loss at different
    points, by design), so that a run is a function of the program's code alone."""
    return Script(
        images=tuple(draw(st.lists(st.builds(ImageReading, INT16, INT16, INT16, INT16),
                                   max_size=3))),
        odometry=tuple(draw(st.lists(st.builds(Odometry, INT16, INT16, INT16), max_size=3))),
        camera=tuple(draw(st.lists(st.integers(0, 784), max_size=3))),
        ultrasonic={letter: (draw(INT16),) for letter in "ABCD"},
        ports={3: tuple(draw(st.lists(st.integers(0, 255), min_size=1, max_size=3)))},
        fuzzy=tuple(draw(st.lists(st.builds(FuzzyReading, INT16, INT16), max_size=3))),
    )


STATEMENT_BUDGET = 300
INSTRUCTION_BUDGET = 3000


def ran_away(result: RunResult) -> bool:
    return result.fault is not None and result.fault.kind is FaultKind.BUDGET


def commands(device: ScriptedDevice, result: RunResult) -> list[TraceEntry]:
    """The commands of a run, without the stop that ends a runaway."""
    if not ran_away(result):
        return device.trace
    *before, stop = device.trace
    assert stop.call == "STOP"
    return before


@settings(max_examples=100, deadline=None)
@given(valid_programs(), scripts())
def test_compiled_code_runs_as_the_interpreter_runs_the_source(
    text: str, script: Script,
) -> None:
    program, _ = parse_program(text)
    interpreted_device, vm_device = ScriptedDevice(script), ScriptedDevice(script)
    interpreted = interpret(program, interpreted_device, STATEMENT_BUDGET)
    compiled = verify(ilc.encode(generate(lower(program), "generated.rob")))
    ran = machine.run(compiled, vm_device, INSTRUCTION_BUDGET)
    # The engines count steps differently (statements, instructions), so a runaway is
    # stopped at different points: up to the stop, both traces follow the same one.
    vm_trace, interpreted_trace = commands(vm_device, ran), commands(interpreted_device,
                                                                     interpreted)
    shorter = min(len(vm_trace), len(interpreted_trace))
    assert vm_trace[:shorter] == interpreted_trace[:shorter]
    if not (ran_away(interpreted) or ran_away(ran)):
        assert vm_device.trace == interpreted_device.trace
        assert ran.named() == interpreted.named()
        assert (ran.fault and (ran.fault.kind, ran.fault.line)) == (
            interpreted.fault and (interpreted.fault.kind, interpreted.fault.line))


@settings(max_examples=100, deadline=None)
@given(checked_programs(), scripts())
def test_programs_that_end_end_the_same_compiled_and_interpreted(
    text: str, script: Script,
) -> None:
    program = analyze(text).program
    interpreted_device, vm_device = ScriptedDevice(script), ScriptedDevice(script)
    interpreted = interpret(program, interpreted_device)
    ran = machine.run(verify(ilc.encode(generate(lower(program), "checked.rob"))), vm_device)
    assert not ran_away(interpreted)
    assert ran.named() == interpreted.named()
    assert vm_device.trace == interpreted_device.trace
    assert (ran.fault and (ran.fault.kind, ran.fault.line)) == (
        interpreted.fault and (interpreted.fault.kind, interpreted.fault.line))


def test_a_move_of_a_constant_that_fits_a_byte_is_movb() -> None:
    moves = [ir.Move(ir.Var("A"), ir.Imm(value), 1) for value in (127, 128, -128, -129)]
    program = ir.Program({"B0": ir.Block("B0", list[ir.Instruction](moves), ir.End(1))}, "B0")
    image = generate(program, "test.rob", debug=False)
    assert names(image) == ["MOVB", "MOVI", "MOVB", "MOVI", "END"]
    assert image.code[:3] == bytes([0x0A, var("A"), 127])
    assert image.code[7:10] == bytes([0x0A, var("A"), 0x80])  # -128, signed
    cells = machine.run(verify(ilc.encode(image)), ScriptedDevice(Script())).variables
    assert cells[var("A")] == -129



def test_a_call_whose_constants_fit_a_byte_is_compact_at_o2_only() -> None:
    source = "(MOV 4,-4); (ROT 127); (ROT 128); A=(ULT A); (OUT 3,A); (FRE); (END)\n"
    files = {level: ilc.read(driver.compile_text(source, "t.rob", level=level,
                                                 strip_debug=True).output or b"")
             for level in (1, 2)}
    calls = {level: [name for name in names(file.image) if name not in ("LDR", "STV", "MOVR")]
             for level, file in files.items()}
    # (-O2 leaves the final END out: running past the code ends the run)
    assert calls[1] == ["MOV", "ROT", "ROT", "ULTA", "OUT", "FRE", "END"]
    assert calls[2] == ["MOVS", "ROTS", "ROT", "ULTA", "OUTS", "FRE"]
    code = files[2].image.code
    assert code[:4] == bytes([0xC4, 0, 4, 0xFC])  # a byte an argument, -4 signed
    assert code[-5:-1] == bytes([0xDB, 0b10, 3, var("A")])  # OUTS 3, A
    assert (files[1].header.minor, files[2].header.minor) == (0, isa.COMPACT_MINOR)
