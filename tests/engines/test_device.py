"""The scripted device: sensor scripts (loading, validation), readings in order, the motion
model's clock, line losses per tracing mode, and the device binding of each built-in."""

import json
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import SAMPLE_SENSORS

from rl1.compiler.files import SourceError
from rl1.compiler.runner import load_script
from rl1.vm.device import (
    BINDINGS,
    DeviceError,
    FuzzyReading,
    ImageReading,
    LineLost,
    Odometry,
    perform,
)
from rl1.vm.hardware import Blocking
from rl1.vm.language import BUILTINS
from rl1.vm.scripted import (
    LOST,
    LossAt,
    LossDuring,
    Script,
    ScriptedDevice,
    ScriptError,
    TraceEntry,
    parse_script,
)


def calls(device: ScriptedDevice) -> list[tuple[int, str, tuple[int, ...]]]:
    return [(entry.time, entry.call, entry.args) for entry in device.trace]


# Scripts ------------------------------------------------------------------------------


def test_json_and_toml_scripts_load_to_the_same_script(tmp_path: Path) -> None:
    (tmp_path / "s.json").write_text(json.dumps({
        "IMG": [{"area": 120, "x": 130, "y": 100, "z": -5}],
        "KYO": [{"centre": 50, "right": 52, "left": 48}],
        "CAM R": [392], "ULT B": [150, 140], "INP": {"3": [1, 0]},
        "FZI": [{"s": 1, "t": -2}],
        "line_lost": [{"time": 2500}, {"during": "MVI", "nth": 2, "after": 300}],
    }))
    (tmp_path / "s.toml").write_text(
        '"CAM R" = [392]\n"ULT B" = [150, 140]\nline_lost = [{time = 2500}, '
        '{during = "MVI", nth = 2, after = 300}]\n'
        "[[IMG]]\narea = 120\nx = 130\ny = 100\nz = -5\n"
        "[[KYO]]\ncentre = 50\nright = 52\nleft = 48\n"
        '[INP]\n"3" = [1, 0]\n[[FZI]]\ns = 1\nt = -2\n')
    script = load_script(tmp_path / "s.json")
    assert script == load_script(tmp_path / "s.toml")
    assert script.images == (ImageReading(120, 130, 100, -5),)
    assert script.odometry == (Odometry(50, 52, 48),)
    assert script.ultrasonic == {"B": (150, 140)}
    assert script.ports == {3: (1, 0)}
    assert script.fuzzy == (FuzzyReading(1, -2),)
    assert script.losses == (LossAt(2500), LossDuring("MVI", 2, 300))


def test_the_sample_sensor_script_is_valid() -> None:
    assert len(load_script(SAMPLE_SENSORS).images) == 18


@pytest.mark.parametrize(("document", "message"), [
    ([1, 2], "s.json: the script must be an object"),
    ({"IMAGE": []}, 's.json:1: IMAGE: unknown key; did you mean "IMG"? (expected one of "IMG"'),
    ({"IMG": {}}, "s.json:1: IMG: expected a list of at least one reading (leave the key out for "
     "none), found an object"),
    ({"IMG": []}, "s.json:1: IMG: expected a list of at least one reading (leave the key out for "
     "none), found an empty array"),
    ({"IMG": [{"area": 1, "x": 2, "y": 3}]}, 's.json:1: IMG[0]: missing "z"'),
    ({"IMG": [{"area": 1, "x": 2, "y": 3, "z": 4, "w": 5}]},
     's.json:1: IMG[0].w: unknown key; expected one of "area", "x", "y", "z"'),
    ({"IMG": [{"area": "1", "x": 2, "y": 3, "z": 4}]},
     's.json:1: IMG[0].area: expected an integer in -32768..32767, found the string "1"'),
    ({"KYO": [{"centre": 40000, "right": 0, "left": 0}]},
     "s.json:1: KYO[0].centre: 40000 is outside -32768..32767"),
    ({"ULT A": [True]}, "s.json:1: ULT A[0]: expected an integer in -32768..32767, found true"),
    ({"CAM R": [785]}, "s.json:1: CAM R[0]: 785 is outside 0..784"),
    ({"INP": {"x": [1]}}, 's.json:1: INP.x: expected a port number 0..125 in quotes, such as "3"'),
    ({"INP": {"126": [1]}}, "s.json:1: INP.126: 126 is outside 0..125"),
    ({"INP": {"3": [256]}}, "s.json:1: INP.3[0]: 256 is outside 0..255"),
    ({"INP": [1]}, "s.json:1: INP: expected an object from port number"),
    ({"line_lost": [{"time": 0}]}, "s.json:1: line_lost[0].time: 0 is outside 1.."),
    ({"line_lost": [{"during": "TIM", "nth": 1}]},
     's.json:1: line_lost[0].during: expected "MOV" or "MVI"'),
    ({"line_lost": [{"at": 5}]}, 's.json:1: line_lost[0].at: unknown key; expected one of "time"'),
    ({"line_lost": [{"time": 5, "nth": 1}]},
     's.json:1: line_lost[0]: expected {"time": MS}, {"instruction": N} or'),
    ({"comment": 5}, "s.json:1: comment: expected a string"),
    ({"fail": ["TIM"]}, "s.json:1: fail: expected an object from a call"),
    ({"fail": {"CAM X": 1}}, "s.json:1: fail.CAM X: not a built-in form"),
    ({"fail": {"TIM": 0}}, "s.json:1: fail.TIM: 0 is outside 1.."),
    ({"stop_fails": 1}, "s.json:1: stop_fails: expected true or false"),
])
def test_bad_scripts_are_refused_with_file_key_and_reason(
    tmp_path: Path, document: object, message: str,
) -> None:
    path = tmp_path / "s.json"
    path.write_text(json.dumps(document))
    with pytest.raises(ScriptError) as refused:
        load_script(path)
    assert str(refused.value).startswith(str(tmp_path) + "/" + message)


def test_malformed_files_are_script_errors_and_unreadable_ones_source_errors(
        tmp_path: Path) -> None:
    (tmp_path / "bad.json").write_text('{"IMG": [\n')
    (tmp_path / "bad.toml").write_text("IMG = [\n")
    (tmp_path / "bin.json").write_bytes(b"\xff\xfe")
    (tmp_path / "deep.json").write_text("[" * 100_000)
    malformed = {
        "bad.json": "bad.json:2: invalid JSON", "bad.toml": "bad.toml: invalid TOML",
        "bin.json": "bin.json: not UTF-8 text",
        "deep.json": "deep.json(:1:100001)?: invalid JSON",
    }
    for name, message in malformed.items():
        with pytest.raises(ScriptError, match=message):
            load_script(tmp_path / name)
    for name, reason in {"none.json": "no such file", ".": "it is a directory"}.items():
        with pytest.raises(SourceError) as raised:
            load_script(tmp_path / name)
        assert raised.value.reason.startswith(reason)


json_values = st.recursive(
    st.none() | st.booleans() | st.integers(-70000, 70000) | st.text(max_size=5),
    lambda children: st.lists(children, max_size=4)
    | st.dictionaries(st.sampled_from(["IMG", "KYO", "CAM R", "ULT A", "INP", "FZI",
                                        "line_lost", "area", "x", "y", "z", "3", "time",
                                        "during", "nth", "after", "MOV", "other"]),
                      children, max_size=5),
    max_leaves=20,
)


@settings(max_examples=300, deadline=None)
@given(json_values)
def test_any_document_is_a_script_or_a_script_error(document: object) -> None:
    try:
        parse_script(document, "s.json")
    except ScriptError as error:
        assert str(error).startswith("s.json")


# Readings -----------------------------------------------------------------------------


def test_with_after_last_repeat_the_last_reading_repeats_and_absent_ones_read_zero() -> None:
    device = ScriptedDevice(Script(images=(ImageReading(1, 2, 3, 4), ImageReading(5, 6, 7, 8)),
                                   ultrasonic={"A": (100,)}, ports={3: (9, 8)},
                                   after_last="repeat"))
    assert [device.measure_image().area for _ in range(4)] == [1, 5, 5, 5]
    ranges = [device.ultrasonic("A"), device.ultrasonic("A"), device.ultrasonic("B")]
    assert ranges == [100, 100, 0]
    assert [device.read_port(3), device.read_port(4), device.read_port(3)] == [9, 0, 8]
    assert device.read_distance() == Odometry(0, 0, 0)
    assert device.fuzzy_read() == FuzzyReading(0, 0)
    assert device.camera_position() == 0
    assert device.trace[0] == TraceEntry(0, "IMG", (), (1, 2, 3, 4))
    # 4 IMG and 3 ULT of 100 ms each; INP, KYO and FZI take no time.
    assert device.trace[-1].to_json() == {"time": 700, "call": "CAM R", "args": [],
                                          "result": [0]}


def test_a_reading_past_the_end_of_its_list_stops_at_once_naming_the_call_and_time() -> None:
    script = parse_script({"IMG": [{"area": 1, "x": 2, "y": 3, "z": 4}], "INP": {"3": [9]}},
                          "s.json")
    device = ScriptedDevice(script)
    assert device.measure_image().area == 1
    with pytest.raises(DeviceError, match=r"^\(IMG\) at 100 ms has no reading: it is call 2, "
                       r"and the sensor script s.json gives 1 IMG reading$"):
        device.measure_image()
    assert device.trace[-1] == TraceEntry(100, "IMG")  # recorded, no time taken, nothing read
    assert device.time == 100
    with pytest.raises(DeviceError, match=r"^\(ULT B\) at 100 ms has no reading: the sensor "
                       "script s.json gives no ULT B readings$"):
        device.ultrasonic("B")
    assert device.read_port(3) == 9
    with pytest.raises(DeviceError, match=r"^\(INP 3\) at 100 ms .* gives 1 INP 3 reading$"):
        device.read_port(3)
    assert device.trace[-1] == TraceEntry(100, "INP", (3,))


def test_without_a_script_a_sensing_call_says_that_none_was_given() -> None:
    with pytest.raises(DeviceError, match=r"^\(KYO\) at 0 ms has no reading: no sensor script "
                       "was given$"):
        ScriptedDevice().read_distance()


@settings(max_examples=30, deadline=None)
@given(st.lists(st.integers(-32768, 32767), min_size=1, max_size=20), st.integers(1, 40))
def test_any_list_gives_exactly_its_readings_then_stops(readings: list[int], calls: int) -> None:
    device = ScriptedDevice(parse_script({"ULT A": readings}, "s.json"))
    got = []
    try:
        for _ in range(calls):
            got.append(device.ultrasonic("A"))
    except DeviceError:
        assert calls > len(readings)
    assert got == readings[:calls]


# The clock ----------------------------------------------------------------------------


def test_waiting_calls_take_their_time_and_the_others_none() -> None:
    device = ScriptedDevice()
    device.wait(15)  # 1.5 s
    device.move(3, 3)
    device.set_tracing(1)
    device.rotate(-90)  # 10 ms a degree
    device.steer_left(75)  # a fixed step
    device.write_port(1, 2)
    device.move_distance(1, 1, 50)  # 5 cm/s a unit: the centre covers 50 cm at 5 cm/s
    device.move_distance(12, 12, -1900)  # ceil(1900 * 400 / 24) ms
    device.move_distance(3, -3, 0)  # no distance: no time
    assert calls(device) == [
        (0, "TIM", (15,)), (1500, "MOV", (3, 3)), (1500, "TRC", (1,)),
        (1500, "ROT", (-90,)), (2400, "STL", (75,)), (2500, "OUT", (1, 2)),
        (2500, "MVI", (1, 1, 50)), (12500, "MVI", (12, 12, -1900)),
        (44167, "MVI", (3, -3, 0)),
    ]
    assert device.time == 44167


def test_an_mvi_whose_centre_never_moves_is_a_device_error() -> None:
    with pytest.raises(DeviceError, match=r"\(MVI 4,-4,10\) would never end"):
        ScriptedDevice().move_distance(4, -4, 10)


# Line losses ----------------------------------------------------------------------------


def lost_at(time: int, mode: int) -> ScriptedDevice:
    device = ScriptedDevice(Script(losses=(LossAt(time),)))
    device.set_tracing(mode)
    return device


@pytest.mark.parametrize("mode", [2, 3])
def test_a_loss_during_a_mov_ends_a_wait_early_and_is_delivered_once(mode: int) -> None:
    device = lost_at(700, mode)
    device.move(3, 3)
    device.wait(20)
    assert device.time == 700
    assert device.poll_event() == LineLost("MOV", mode)
    assert device.poll_event() is None
    assert calls(device)[-1] == (700, "LINE LOST", (mode,))


def test_mode_2_stops_a_mov_and_mode_3_keeps_it() -> None:
    for mode, moving in ((2, False), (3, True)):
        device = ScriptedDevice(Script(losses=(LossAt(100), LossAt(300))))
        device.set_tracing(mode)
        device.move(2, 2)
        device.wait(2)
        assert device.poll_event() == LineLost("MOV", mode)
        device.wait(5)
        assert (device.poll_event() is not None) == moving


@pytest.mark.parametrize("mode", [0, 1])
def test_modes_0_and_1_never_tell_the_program(mode: int) -> None:
    device = lost_at(100, mode)
    device.move(3, 3)
    device.wait(5)
    assert device.time == 500
    assert device.poll_event() is None
    assert [entry.call for entry in device.trace].count("LINE LOST") == (mode == 1)


def test_a_loss_without_motion_is_ignored() -> None:
    for moving in ((0, 0), None):
        device = lost_at(100, 3)
        if moving:
            device.move(*moving)
        device.wait(5)
        assert device.poll_event() is None
        assert device.time == 500


def test_mode_2_aborts_an_mvi() -> None:
    device = lost_at(4000, 2)
    device.move_distance(1, 1, 50)  # would take 10 s
    assert device.time == 4000
    assert device.poll_event() == LineLost("MVI", 2)
    device.wait(100)  # the vehicle is stopped: nothing more is lost
    assert device.poll_event() is None


def test_mode_3_lets_an_mvi_go_on_in_the_background_until_its_distance_is_covered() -> None:
    device = ScriptedDevice(Script(losses=(LossAt(4000), LossAt(6000), LossAt(11000))))
    device.set_tracing(3)
    device.move_distance(1, 1, 50)  # ends at 10000 ms
    assert (device.time, device.poll_event()) == (4000, LineLost("MVI", 3))
    device.wait(30)  # the background MVI is still motion in effect
    assert (device.time, device.poll_event()) == (6000, LineLost("MVI", 3))
    device.wait(60)  # it ends at 10000; the loss at 11000 meets no motion
    assert (device.time, device.poll_event()) == (12000, None)


def test_losses_during_the_nth_command() -> None:
    device = ScriptedDevice(Script(losses=(LossDuring("MOV", 2, 250),
                                           LossDuring("MVI", 1, 1))))
    device.set_tracing(3)
    device.move(1, 1)
    device.wait(5)
    assert device.poll_event() is None  # the first MOV
    device.move(2, 2)  # the second, from 500 ms
    device.wait(5)
    assert (device.time, device.poll_event()) == (750, LineLost("MOV", 3))
    device.move_distance(2, 2, 10)
    assert (device.time, device.poll_event()) == (751, LineLost("MVI", 3))


def test_a_replaced_mov_loses_nothing_and_stop_free_hold_end_motion() -> None:
    for end_motion in ("move", "stop", "free", "hold"):
        device = ScriptedDevice(Script(losses=(LossDuring("MOV", 1, 200),)))
        device.set_tracing(2)
        device.move(3, 3)
        if end_motion == "move":
            device.move(0, 0)
        else:
            getattr(device, end_motion)()
        device.wait(5)
        assert device.poll_event() is None, end_motion


# The binding of built-ins to device methods ----------------------------------------------


def test_every_builtin_form_but_end_is_bound() -> None:
    forms = {(b.mnemonic, form.selector) for b in BUILTINS.values() for form in b.forms}
    assert set(BINDINGS) == forms - {("END", None)}


def test_perform_returns_results_and_reserved_values_in_form_order() -> None:
    device = ScriptedDevice(Script(images=(ImageReading(180, 1, 2, 3),),
                                   odometry=(Odometry(10, 11, 9),),
                                   fuzzy=(FuzzyReading(-1, 1),)))
    image = perform(device, ("IMG", None), ())
    assert (image.result, image.writes) == (180, (180, 1, 2, 3))
    assert BUILTINS["IMG"].forms[0].writes == ("w", "x", "y", "z")
    odometry = perform(device, ("KYO", None), ())
    assert (odometry.result, odometry.writes) == (10, (11, 9))  # u right, v left
    fuzzy = perform(device, ("FZI", None), ())
    assert (fuzzy.result, fuzzy.writes) == (None, (-1, 1))
    assert perform(device, ("CAM", "P"), (392,)).result is None
    assert device.trace[-1].call == "CAM P"


class _Faulty(ScriptedDevice):
    def ultrasonic(self, sensor: str) -> int:
        return 40000


def test_a_value_outside_16_bits_from_a_device_is_its_error() -> None:
    with pytest.raises(DeviceError, match=r"\(ULT C\) returned 40000"):
        perform(_Faulty(), ("ULT", "C"), ())


@given(at=st.lists(st.integers(1, 30_000), max_size=60),
       during=st.lists(st.tuples(st.integers(1, 3), st.integers(1, 12_000)), max_size=60))
@settings(deadline=None)
def test_in_mode_1_every_scheduled_loss_under_motion_is_traced_once_in_time_order(
        at: list[int], during: list[tuple[int, int]]) -> None:
    """Three MOVs of 10 s each, in mode 1: each loss scheduled while one drives appears in
    the trace once, at its time, whatever the order and overlap of the script's entries."""
    losses: tuple[LossAt | LossDuring, ...] = (*[LossAt(time) for time in at],
                                                *[LossDuring("MOV", nth, after)
                                                  for nth, after in during])
    device = ScriptedDevice(Script(losses=losses))
    device.set_tracing(1)
    starts = []
    for _ in range(3):
        starts.append(device.time)
        device.move(3, 3)
        device.wait(100)
    expected = {time for time in at if time <= 30_000}
    expected |= {starts[nth - 1] + after for nth, after in during
                 if after <= 10_000 and starts[nth - 1] + after <= 30_000}
    traced = [entry.time for entry in device.trace if entry.call == "LINE LOST"]
    assert traced == sorted(expected)


def test_a_scripted_failure_refuses_the_nth_call_and_a_failing_stop_records_first() -> None:
    device = ScriptedDevice(parse_script({"fail": {"ULT A": 2}, "stop_fails": True,
                                          "after_last": "repeat"}))
    device.ultrasonic("A")
    with pytest.raises(DeviceError, match=r"\(ULT A\) failed: the sensor script says its "
                       "call 2 fails"):
        device.ultrasonic("A")
    device.ultrasonic("A")  # only the 2nd
    with pytest.raises(DeviceError, match="stopping fails"):
        device.stop()
    assert [entry.call for entry in device.trace] == ["ULT A"] * 3 + ["STOP"]
    assert device.time == 300  # the failing call took its time, then failed


# The log: every loss with what it did ---------------------------------------------------


def test_the_log_holds_every_loss_with_its_effect_and_the_trace_only_those_that_mattered(
        ) -> None:
    device = ScriptedDevice(parse_script({"line_lost": [
        {"time": 100}, {"time": 300}, {"time": 500}, {"time": 700}, {"time": 710}]}))
    device.wait(2)  # 100: no motion in effect
    device.move(3, 3)
    device.wait(2)  # 300: tracing off (mode 0)
    device.set_tracing(1)
    device.wait(2)  # 500: mode 1 drives on
    device.set_tracing(3)
    device.rotate(20)  # 700 and 710 during a ROT, which no loss interrupts: the second waits
    losses = [(entry.time, entry.during, entry.effect, entry.describe())
              for entry in device.log if entry.call == "LINE LOST"]
    assert losses == [
        (100, None, "no-motion", "LINE LOST (mode 0): ignored, no motion in effect"),
        (300, "MOV", "tracing-off", "LINE LOST (mode 0, MOV): ignored, tracing is off"),
        (500, "MOV", "drive-on", "LINE LOST (mode 1, MOV): mode 1 drives straight on, no jump"),
        (700, "MOV", "jump", "LINE LOST (mode 3, MOV) -> :96"),
        (710, "MOV", "already-waiting",
         "LINE LOST (mode 3, MOV): a loss already waits for the program"),
    ]
    assert [entry.time for entry in device.trace if entry.call == "LINE LOST"] == [500, 700, 710]
    assert device.log[-1].handler is None and device.log[-2].handler == 96


def test_entries_carry_the_line_the_adapter_gives() -> None:
    device = ScriptedDevice(Script(losses=(LossAt(50),)))
    perform(device, ("TRC", None), (3,), line=4)
    perform(device, ("MOV", None), (1, 1), line=7)
    perform(device, ("TIM", None), (1,), line=9)  # the line is lost during it
    device.lose_line_after(12, 11)
    hardware = Blocking(device, lambda: 13)
    hardware.call(("OUT", None), (1, 2))
    hardware.stop()
    assert [(entry.call, entry.line) for entry in device.log] == [
        ("TRC", 4), ("MOV", 7), ("TIM", 9), (LOST, 9), (LOST, 11), ("OUT", 13), ("STOP", 13)]
    assert device.trace[1] == TraceEntry(0, "MOV", (1, 1))  # the line is no part of equality


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(1, 3000), min_size=1, max_size=8),
       st.lists(st.integers(0, 10), max_size=8),
       st.integers(0, 3))
def test_every_scripted_loss_is_logged_or_said_not_to_have_happened(
        times: list[int], waits: list[int], mode: int) -> None:
    device = ScriptedDevice(parse_script({"line_lost": [{"time": t} for t in times]}))
    device.set_tracing(mode)
    device.move(2, 2)
    for tenths in waits:
        device.wait(tenths)
        device.poll_event()
    logged = {entry.time for entry in device.log if entry.call == "LINE LOST"}
    missed = {loss.time for _, loss, _ in device.losses_not_met() if isinstance(loss, LossAt)}
    assert logged | missed == set(times) and not logged & missed
    assert all(time > device.time for time in missed)
