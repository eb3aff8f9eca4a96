"""Hostile inputs for every `rl1c` command, and what each must still do.

Shared by tests/cli/test_hostile_inputs.py (a bounded run in the test command) and
bench/hostile_fuzz.py (a campaign as long as asked). `source_attack`, `ilc_attack` and
`world_attack` run the commands in-process on one input and return the problems found:
an internal error, an exit status the command does not document, output written by a
command that failed, a traceback on any stream; and for world files, a bad world not
refused with status 2 and a message naming the file. `cache_attack` damages the C
engine's build cache and runs `rl1c run --engine c` from it, in a process of its own.
"""

from __future__ import annotations

import atexit
import functools
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from hypothesis import strategies as st

from rl1.compiler.backend.driver import compile_text
from rl1.compiler.strategies import programs
from rl1.vm import native
from rl1.vm.sim.world import WorldError, decode_world

from . import EXAMPLES, ROOT, SAMPLE, SAMPLE_SENSORS
from .cli import Result, rl1c
from .ilc import with_crc

# The exit statuses each command documents (docs/commands.md).
STATUSES = {
    "check": {0, 1, 2},
    "fmt": {0, 1, 2},
    "compile": {0, 1, 2},
    "run": {0, 1, 2, 10, 11, 12, 13},
    "dis": {0, 1, 2},
    "asm": {0, 1, 2},
    "sim": {0, 1, 2, 10, 11, 12, 13},
}
BUDGET = "20000"  # instructions: a runaway input ends quickly


def _mutated(text: bytes, draw: st.DrawFn) -> bytes:
    data = bytearray(text)
    for _ in range(draw(st.integers(1, 8))):
        if not data:
            data += draw(st.binary(min_size=1, max_size=8))
            continue
        at = draw(st.integers(0, len(data) - 1))
        action = draw(st.sampled_from(["flip", "insert", "delete", "replace", "cut"]))
        if action == "flip":
            data[at] ^= 1 << draw(st.integers(0, 7))
        elif action == "insert":
            data[at:at] = draw(st.binary(min_size=1, max_size=16))
        elif action == "delete":
            del data[at:at + draw(st.integers(1, 16))]
        elif action == "replace":
            data[at] = draw(st.integers(0, 255))
        else:
            del data[at:]
    return bytes(data)


@st.composite
def hostile_sources(draw: st.DrawFn) -> bytes:
    """Arbitrary bytes, generated programs, and programs mutated byte by byte."""
    kind = draw(st.sampled_from(["bytes", "program", "mutated"]))
    if kind == "bytes":
        return draw(st.binary(max_size=400))
    program = draw(programs(max_lines=12)).encode("utf-8")
    return program if kind == "program" else _mutated(program, draw)


def _seed_ilc_files() -> list[bytes]:
    sample = (EXAMPLES / "sample.rob").read_text(encoding="utf-8")
    compiled = [compile_text(sample, "sample.rob", strip_debug=strip).output
                for strip in (False, True)]
    documents = [json.loads(group.read_text(encoding="utf-8"))
                 for group in sorted((ROOT / "spec" / "vectors").glob("*.json"))]
    vectors = [bytes.fromhex(vector[key]) for document in documents
               for vector in document.get("vectors", []) for key in ("ilc", "ilc_stripped")]
    verifier_files = [bytes.fromhex(file["ilc"]) for document in documents
                      for file in document.get("files", [])]
    return [data for data in compiled if data is not None] + vectors + verifier_files


SEED_ILC_FILES = _seed_ilc_files()


@st.composite
def hostile_ilc_files(draw: st.DrawFn) -> bytes:
    """Valid .ilc files (the sample's, the vectors') mutated, mostly with the CRC fixed
    so that the mutation reaches the verifier rather than stopping at the checksum."""
    data = _mutated(draw(st.sampled_from(SEED_ILC_FILES)), draw)
    return with_crc(data) if len(data) >= 12 and draw(st.integers(0, 4)) else data


def _problems(command: str, result: Result, written: Path | None) -> list[str]:
    found = []
    if result.exit_code not in STATUSES[command]:
        found.append(f"{command}: exit status {result.exit_code}")
    if b"internal error" in result.output_bytes or b"Traceback" in result.output_bytes:
        found.append(f"{command}: {result.output_bytes[-300:]!r}")
    if written is not None and result.exit_code != 0 and written.exists():
        found.append(f"{command}: failed with status {result.exit_code} but wrote {written}")
    return found


def source_attack(data: bytes, folder: Path) -> list[str]:
    """Every command that reads RL/I source, on `data`."""
    source, output = folder / "hostile.rob", folder / "hostile.ilc"
    source.write_bytes(data)
    output.unlink(missing_ok=True)
    found = _problems("check", rl1c("check", source), None)
    found += _problems("check", rl1c("check", "--format", "sarif", "-", stdin=data), None)
    found += _problems("fmt", rl1c("fmt", "--diff", source), None)
    found += _problems("fmt", rl1c("fmt", "-", stdin=data), None)
    found += _problems("check", rl1c("check", "--diff", "--format", "concise", "-",
                                     stdin=data), None)
    found += _problems("compile", rl1c(source, "-o", output), output)
    c_output = folder / "hostile.c"
    c_output.unlink(missing_ok=True)
    found += _problems("compile", rl1c(source, "--emit", "c", "-o", c_output), c_output)
    for engine in ("vm", "ast"):
        found += _problems("run", rl1c("run", source, "--engine", engine, "--budget", BUDGET),
                           None)
    # Last, as it rewrites the source.
    found += _problems("check", rl1c("check", "--fix", source), None)
    return found


def ilc_attack(data: bytes, folder: Path) -> list[str]:
    """The commands that read .ilc files, on `data`; `asm` on what `dis` printed must
    give the same bytes back."""
    binary, text, again = folder / "hostile.ilc", folder / "hostile.ils", folder / "again.ilc"
    binary.write_bytes(data)
    again.unlink(missing_ok=True)
    found = _problems("run", rl1c("run", binary, "--budget", BUDGET), None)
    shown = rl1c("dis", binary)
    found += _problems("dis", shown, None)
    if shown.exit_code == 0 and data[4:6] == bytes([1, 0]):  # the round trip is for 1.0
        text.write_text(shown.stdout, encoding="utf-8")
        built = rl1c("asm", text, "-o", again)
        found += _problems("asm", built, again)
        if built.exit_code != 0 or again.read_bytes() != data:
            found.append(f"asm(dis(x)) != x: {built.output_bytes[-300:]!r}")
    return found


# A short program that uses every part of the world: the floor and its lines (tracing,
# the camera looking down), the markers (looking level), the ultrasonic sensors, the
# motion and the odometry.
SIM_PROGRAM = b"""(CAM D); (SCN 0); (TRC 1); (MOV 12,12); (TIM 10); A=(IMG)
(CAM U); (SCN 2); B=(IMG); C=(ULT A); D=(ULT B); (INP 3); (FZI)
(TRC 0); (ROT 90); (STX 450); (MVI 3,3,40); E=(KYO); (MOV 2,2)
(END)
"""
SEED_WORLDS = [path.read_bytes() for path in sorted(EXAMPLES.glob("*.world.toml"))]
# Values that break naive code: not finite, huge, tiny, of the wrong type, degenerate
# polygons, deep nesting.
HOSTILE_VALUES = [
    "nan", "inf", "-inf", "1e308", "-1e308", "1e6", "-1e6", "0", "-0.0", "5e-324",
    "9" * 400, '"x"', "true", "[]", "{}", "[[0, 0], [0, 0], [0, 0]]",
    "[[0, 0], [1e6, 1e6]]", "[[0, 0], [1e6, 0], [1e6, 1e6], [0, 1e6]]", "[1e6, 1e6]",
    "[0, 0, 0, 0]", "[0, 0, 1024, 1024]", "[" * 600 + "]" * 600,
]


@st.composite
def hostile_worlds(draw: st.DrawFn) -> bytes:
    """Arbitrary bytes, the example worlds mutated byte by byte, and the example worlds
    with one value replaced by a hostile one."""
    kind = draw(st.sampled_from(["bytes", "mutated", "value"]))
    if kind == "bytes":
        return draw(st.binary(max_size=400))
    world = draw(st.sampled_from(SEED_WORLDS))
    if kind == "mutated":
        return _mutated(world, draw)
    assignments = list(re.finditer(rb"(?m)^(\s*[\w\"]+\s*=\s*)(.*?)(\s*(#.*)?)$", world))
    chosen = draw(st.sampled_from(assignments))
    value = draw(st.sampled_from(HOSTILE_VALUES)).encode()
    return world[:chosen.start(2)] + value + world[chosen.end(2):]


def world_attack(data: bytes, folder: Path) -> list[str]:
    """`rl1c sim` on the world file `data`, with pictures and JSON: a world the loader
    refuses must end with status 2 and a message naming the file, and write nothing."""
    world, program, picture = folder / "hostile.world.toml", folder / "run.rob", folder / "run.svg"
    world.write_bytes(data)
    program.write_bytes(SIM_PROGRAM)
    picture.unlink(missing_ok=True)
    result = rl1c("sim", program, "--world", world, "--svg", picture, "--format", "json",
                  "--budget", BUDGET)
    # A run that faulted still draws its picture (the fault is in it); a refused input
    # draws none.
    found = _problems("sim", result, picture if result.exit_code in (1, 2) else None)
    try:
        decode_world(data, str(world))
    except WorldError:
        said = f"error[E0100]: the world file `{world}` is not valid: {world}"
        if result.exit_code != 2 or not result.stderr.startswith(said):
            found.append(f"sim: a bad world gave status {result.exit_code}: "
                         f"{result.output_bytes[-300:]!r}")
    return found


# The C engine's build cache --------------------------------------------------------------


@functools.cache
def _built_cache() -> tuple[Path, bytes, str]:
    """A cache folder with the C VM built in it, the library's bytes, and what
    `rl1c run --engine c` prints from it (the first call builds: seconds)."""
    cache = Path(tempfile.mkdtemp(prefix="rl1-hostile-cache-"))
    atexit.register(shutil.rmtree, cache, ignore_errors=True)
    library = native.library(cache / "rl1")
    done = _run_engine_c(cache)
    assert done.returncode == 0 and "rl1: warning" not in done.stderr, done.stderr
    return cache, library.read_bytes(), done.stdout


def _run_engine_c(cache: Path) -> subprocess.CompletedProcess[str]:
    rl1c_path = Path(sys.executable).with_name("rl1c")
    return subprocess.run([str(rl1c_path), "run", str(SAMPLE), "--sensors",
                           str(SAMPLE_SENSORS), "--engine", "c", "--format", "json"],
                          capture_output=True, text=True, check=False, timeout=600,
                          env={**os.environ, "XDG_CACHE_HOME": str(cache)})


@st.composite
def hostile_libraries(draw: st.DrawFn) -> bytes:
    """Bytes for the cached library in place of the one built: the built one mutated
    (truncated, flipped, cut), arbitrary bytes, nothing."""
    kind = draw(st.sampled_from(["mutated", "mutated", "bytes", "empty"]))
    if kind == "bytes":
        return draw(st.binary(max_size=4096))
    return b"" if kind == "empty" else _mutated(_built_cache()[1], draw)


def cache_attack(data: bytes, folder: Path) -> list[str]:
    """`rl1c run --engine c` (in a process of its own: a bad library could kill it) from
    a copy of a built cache whose library now holds `data`: it must print what it
    printed from the intact cache, with a warning when the library was damaged, and
    leave an intact library behind."""
    cache, library_bytes, expected = _built_cache()
    copy = Path(tempfile.mkdtemp(dir=folder)) / "cache"  # a folder may serve many inputs
    shutil.copytree(cache, copy)
    library = next((copy / "rl1").glob("librl1vm-*.so"))
    library.write_bytes(data)
    done = _run_engine_c(copy)
    found = []
    if done.returncode != 0 or done.stdout != expected:
        found.append(f"run --engine c from a damaged cache: exit status {done.returncode}: "
                     f"{done.stderr[-300:]!r}")
    if "Traceback" in done.stderr or "internal error" in done.stderr:
        found.append(f"run --engine c: {done.stderr[-300:]!r}")
    if data != library_bytes and "is damaged or was not built there" not in done.stderr:
        found.append("run --engine c: no warning of the damaged library")
    recorded = library.with_name(library.name + native.DIGEST_SUFFIX)
    if recorded.read_text("ascii").strip() != hashlib.sha256(library.read_bytes()).hexdigest():
        found.append("run --engine c: the library left in the cache is not intact")
    return found
