"""Line breakpoints by the thousand: each bound by a search of the lines with code, each
condition parsed once (and not again when a client sends the same one with the next
list), looked up only on the line a step enters; and what a continue stops at, for any
set of breakpoints, is every entry of a line where one bound there holds."""

from __future__ import annotations

import json
from typing import Any

from hypothesis import given
from hypothesis import strategies as st
from support import SAMPLE, SAMPLE_SENSORS

from rl1.compiler import debugger
from rl1.compiler.debugger import Session, Stop, compile_program, parse_condition
from rl1.compiler.runner import load_script
from rl1.lsp.dap import Adapter
from rl1.vm.scripted import ScriptedDevice

LISTING_1 = SAMPLE.read_text(encoding="utf-8")
SCRIPT = load_script(SAMPLE_SENSORS)
CONDITIONS = [None, "A>0", "A<0", "y-150>0", "@=0", "@-3=0", "x-128=0", "C-589=0", "U-L>0"]
REFUSED = "A<5"  # compared with 5: refused, saying to write A-5<0


def _session(text: str = LISTING_1, level: int | None = None) -> Session:
    image = compile_program(text, "program.rob", level)
    assert isinstance(image, bytes), image
    return Session(image, lambda: ScriptedDevice(SCRIPT), 100_000)


def _entries() -> list[tuple[int, list[int]]]:
    """Each line the run of Listing 1 enters, in order, with the variables there: where
    it starts, then each step_line's stop, on a session without breakpoints."""
    session = _session()
    assert session.line is not None
    entries = [(session.line, list(session.machine.variables))]
    while (stop := session.step_line()).reason == "step":
        assert stop.line is not None
        entries.append((stop.line, list(session.machine.variables)))
    assert stop.reason == "end"
    return entries


ENTRIES = _entries()
WITH_CODE = sorted({line for line in _session().lines if line is not None})


@given(st.lists(st.tuples(st.integers(0, WITH_CODE[-1] + 2),
                          st.sampled_from([*CONDITIONS, REFUSED])), max_size=30))
def test_a_continue_stops_at_each_entry_where_a_breakpoint_bound_there_holds(
        wanted: list[tuple[int, str | None]]) -> None:
    session = _session()
    bindings = session.set_line_breakpoints(wanted)
    bound: dict[int, list[str | None]] = {}
    for (requested, text), binding in zip(wanted, bindings, strict=True):
        line = next((line for line in WITH_CODE if line >= requested), None)
        assert binding.requested == requested
        if line is None or text == REFUSED:
            assert (binding.line, binding.verified) == (None, False)
            assert binding.message == ("no code runs on this line or after it"
                                       if line is None else
                                       "the condition `A<5` compares with 5, and a condition "
                                       "compares with 0 (`<` after a value is a shift): "
                                       "write `A-5<0`")
            continue
        assert (binding.line, binding.verified) == (line, True)
        bound.setdefault(line, []).append(text)
    expected = []
    for line, variables in ENTRIES:
        met = [text or "" for text in bound.get(line, [])
               if text is None or parse_condition(text).met(variables)]
        if met:  # one without a condition says nothing; else the first condition met
            expected.append(Stop("breakpoint", line, "" if "" in met else met[0]))
    stops = []
    while (stop := session.continue_()).reason == "breakpoint":
        stops.append(stop)
    assert stop.reason == "end"
    assert stops == expected


LOOP = "@=5\n:10 @--\n' between\nB=@\n?@>#10\n"  # at -O0, code on each line but 3


def _loop() -> Session:
    return _session(LOOP, level=0)


def test_two_conditions_bound_to_one_line_each_stop_there() -> None:
    # Lines 3 (a comment) and 4 both bind to 4; the first condition was lost, the line
    # keeping one breakpoint.
    session = _loop()
    bindings = session.set_line_breakpoints([(3, "@-3=0"), (4, "@-1=0")])
    assert [binding.line for binding in bindings] == [4, 4]
    assert session.continue_() == Stop("breakpoint", 4, "@-3=0")
    assert session.continue_() == Stop("breakpoint", 4, "@-1=0")
    assert session.continue_().reason == "end"


def test_a_breakpoint_without_a_condition_on_a_line_stops_whatever_the_others_say() -> None:
    session = _loop()
    session.set_line_breakpoints([(4, "@-3=0"), (3, None)])
    stops = []
    while (stop := session.continue_()).reason == "breakpoint":
        stops.append((stop, session.variables["@"]))
    assert stops == [(Stop("breakpoint", 4), left) for left in (4, 3, 2, 1, 0)]


def test_a_condition_sent_again_is_parsed_once(monkeypatch: Any) -> None:
    parsed: list[str] = []
    parse = debugger.parse_condition

    def counted(text: str) -> debugger.Condition:
        parsed.append(text)
        return parse(text)

    monkeypatch.setattr(debugger, "parse_condition", counted)
    session = _loop()
    wanted = [(4, "@-3=0"), (2, "@-3=0"), (4, REFUSED)]
    first = session.set_line_breakpoints(wanted)
    again = session.set_line_breakpoints([*wanted, (5, "@=0")])
    assert parsed == ["@-3=0", REFUSED, "@=0"]
    assert again[:3] == first
    assert not again[2].verified and "write `A-5<0`" in again[2].message
    # A condition changed on a line is the new one.
    session.set_line_breakpoints([(4, "@-2=0")])
    assert session.continue_() == Stop("breakpoint", 4, "@-2=0")


def test_rl1_dap_binds_ten_thousand_conditional_breakpoints_each_as_asked(tmp_path: Any
                                                                          ) -> None:
    program = tmp_path / "long.rob"
    program.write_text("A=B\n" * 10_000, encoding="utf-8")
    answers: list[dict[str, Any]] = []
    adapter = Adapter(answers.append)

    def request(command: str, arguments: dict[str, Any]) -> dict[str, Any]:
        adapter.receive(json.dumps({"seq": 1, "type": "request", "command": command,
                                    "arguments": arguments}).encode())
        response = answers[-1] if command != "launch" else answers[-2]
        assert response["type"] == "response" and response["success"], response
        return response

    request("launch", {"program": str(program), "level": 0})
    wanted = [{"line": line, "condition": REFUSED if line % 1000 == 0 else f"B-A-{line}>0"}
              for line in range(1, 10_003)]
    response = request("setBreakpoints", {"source": {"path": str(program)},
                                          "breakpoints": wanted})
    answered = response["body"]["breakpoints"]
    assert len(answered) == len(wanted)
    for line, answer in enumerate(answered, 1):
        if line > 10_000:
            assert answer == {"verified": False, "line": line,
                              "message": "no code runs on this line or after it"}
        elif line % 1000 == 0:
            assert not answer["verified"] and "write `A-5<0`" in answer["message"]
        else:
            assert answer == {"verified": True, "line": line}
