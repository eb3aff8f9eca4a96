"""The text form of the vectors (spec/vectors/GROUP.txt, README.md "The text form") holds
exactly what the JSON form holds, read by a reader as small as a C runner's: split each
line at spaces, dispatch on the first word."""

from __future__ import annotations

import json
from typing import Any

import pytest
from test_vectors import FILES, VECTOR_DIR

from rl1.vm.device import FuzzyReading, ImageReading, Odometry
from rl1.vm.scripted import LossAfter, LossAt, LossDuring, Script, parse_script


def _call(word: str) -> str:
    return word.replace("_", " ")


def read_text(text: str) -> tuple[str, list[dict[str, Any]]]:
    """The group and the vectors of a text file: each vector's fields as the JSON names
    them, its sensor script as a Script."""
    header, *lines = text.splitlines()
    magic, _, group = header.split(" ")
    assert magic == "rl1-vectors"
    vectors: list[dict[str, Any]] = []
    script: dict[str, Any] = {}
    vector: dict[str, Any] = {}
    for line in lines:
        word, *rest = line.split(" ")
        numbers = [int(item) for item in rest if item.lstrip("-").isdigit()]
        if word == "vector":
            vector, script = {"name": rest[0], "trace": []}, {
                "images": [], "odometry": [], "camera": [], "ultrasonic": {}, "ports": {},
                "fuzzy": [], "losses": [], "failures": {}, "stop_fails": False,
                "after_last": "stop"}
        elif word in ("budget", "executed"):
            vector[word] = numbers[0]
        elif word in ("ilc", "ilc_stripped"):
            vector[word] = rest[0]
        elif word == "sensor":
            kind = _call(rest[0])
            values = [int(item) for item in rest[1:]]
            if kind == "IMG":
                script["images"].append(ImageReading(*values))
            elif kind == "KYO":
                script["odometry"].append(Odometry(*values))
            elif kind == "FZI":
                script["fuzzy"].append(FuzzyReading(*values))
            elif kind == "CAM R":
                script["camera"].append(values[0])
            elif kind == "INP":
                script["ports"].setdefault(values[0], []).append(values[1])
            else:
                script["ultrasonic"].setdefault(kind[-1], []).append(values[0])
        elif word == "loss":
            script["losses"].append(
                LossAt(numbers[0]) if rest[0] == "time" else LossAfter(numbers[0])
                if rest[0] == "instruction" else LossDuring(rest[1], *numbers))  # type: ignore[arg-type]
        elif word == "fail":
            script["failures"][_call(rest[0])] = numbers[0]
        elif word == "stop_fails":
            script["stop_fails"] = True
        elif word == "after_last":
            script["after_last"] = rest[0]
        elif word == "status":
            vector["status"], vector["exit_status"], vector["fault_line"] = (
                rest[0], numbers[0], numbers[1])
        elif word == "variables":
            vector["variables"] = numbers
        elif word == "trace":
            time, arity = numbers[0], numbers[1]
            args = numbers[2:2 + arity]
            result = numbers[3 + arity:]
            vector["trace"].append({"time": time, "call": _call(rest[1]), "args": args,
                                    "result": result})
        else:
            assert word == "end", line
            vector["sensors"] = Script(
                images=tuple(script["images"]), odometry=tuple(script["odometry"]),
                camera=tuple(script["camera"]),
                ultrasonic={k: tuple(v) for k, v in script["ultrasonic"].items()},
                ports={k: tuple(v) for k, v in script["ports"].items()},
                fuzzy=tuple(script["fuzzy"]), losses=tuple(script["losses"]),
                failures=script["failures"], stop_fails=script["stop_fails"],
                after_last=script["after_last"])
            vectors.append(vector)
    return group, vectors


GROUPS = sorted(path.stem for path in VECTOR_DIR.glob("*.json") if path.stem != "verifier")


@pytest.mark.parametrize("group", GROUPS)
def test_the_text_form_holds_what_the_json_holds(group: str) -> None:
    document = json.loads((VECTOR_DIR / f"{group}.json").read_text(encoding="ascii"))
    name, vectors = read_text((VECTOR_DIR / f"{group}.txt").read_text(encoding="ascii"))
    assert name == group
    assert len(vectors) == len(document["vectors"])
    for got, want in zip(vectors, document["vectors"], strict=True):
        assert got["sensors"] == parse_script(want["sensors"]), want["name"]
        for key in ("name", "budget", "ilc", "ilc_stripped", "status", "exit_status",
                    "fault_line", "executed", "variables", "trace"):
            assert got[key] == want[key], (want["name"], key)


def test_the_verifier_text_form_holds_what_the_json_holds() -> None:
    lines = (VECTOR_DIR / "verifier.txt").read_text(encoding="ascii").splitlines()
    assert lines[0].split(" ")[::2] == ["rl1-vectors", "verifier"]
    read = []
    for line in lines[1:]:
        word, name, data, verdict, *where = line.split(" ")
        assert word == "file"
        read.append((name, data, verdict == "accepted",
                     *(map(int, where) if where else (0, -1))))
    assert read == [(f["name"], f["ilc"], f["accepted"], f["rule"], f["offset"])
                    for f in FILES]
