"""`rl1c run --batch`: runs one program after another, as a batch engine of `rl1c fuzz`
does (spec/optimization.md, section 5, "Batch engines"): a job a line on standard input,
`{"ilc": BASE64, "sensors": SCRIPT, "budget": N}`, and for each the run on a line of
standard output, as `rl1c run --format json` gives its status, variables and trace. A
job it cannot run is answered all the same, with the status code `bad-job` or
`invalid-ilc` and a message, so that the fuzzer never waits for an answer that does not
come; it ends at the end of its input."""

from __future__ import annotations

import base64
import binascii
import json
from typing import IO, Any

from rl1.compiler.runner import MAX_SCRIPT_BYTES, run
from rl1.vm.defaults import Engine
from rl1.vm.faults import MAX_BUDGET
from rl1.vm.scripted import ScriptedDevice, ScriptError, parse_script, run_document
from rl1.vm.verifier import VerifyError

from .command import CommandError
from .streams import MAX_ILC_BYTES, stdin_problem

# A job's line: the .ilc file in base64 (4 bytes for 3) and the script, with room to spare.
MAX_JOB_BYTES = MAX_ILC_BYTES * 4 // 3 + MAX_SCRIPT_BYTES + 4096
JOB_SHAPE = '{"ilc": BASE64, "sensors": {...}, "budget": N}'


def serve(jobs: IO[bytes], answers: IO[str], engine: Engine, time_limit: int) -> int:
    """Answer each job line of `jobs` on `answers` until the end of `jobs`; exit status 0."""
    while line := _read_line(jobs, MAX_JOB_BYTES + 1):
        if len(line) > MAX_JOB_BYTES:
            while line and not line.endswith(b"\n"):  # the rest of the line, unread
                line = _read_line(jobs, 1 << 20)
            answer = _refused("bad-job", f"the job is longer than {MAX_JOB_BYTES} bytes")
        else:
            answer = _answer(line, engine, time_limit)
        answers.write(json.dumps(answer, separators=(",", ":")) + "\n")
        answers.flush()
    return 0


def _read_line(jobs: IO[bytes], limit: int) -> bytes:
    try:
        return jobs.readline(limit)
    except OSError as error:
        raise CommandError(f"cannot read the jobs: {stdin_problem(error)}; "
                           "send them through a pipe") from None


def _answer(line: bytes, engine: Engine, time_limit: int) -> dict[str, Any]:
    try:
        job = json.loads(line)
    except (ValueError, RecursionError):
        return _refused("bad-job", f"the job is no JSON line; expected {JOB_SHAPE}")
    match job:
        case {"ilc": str(encoded), "sensors": dict(document), "budget": int(budget)} \
                if 1 <= budget <= MAX_BUDGET and not isinstance(budget, bool):
            pass
        case _:
            return _refused("bad-job", f"expected {JOB_SHAPE} with N from 1 to {MAX_BUDGET}")
    try:
        data = base64.b64decode(encoded, validate=True)
        device = ScriptedDevice(parse_script(document, "the job's sensors"), time_limit)
    except binascii.Error:
        return _refused("bad-job", "the job's ilc is not base64")
    except ScriptError as error:
        return _refused("bad-job", str(error))
    try:
        finished = run(data, device, engine=engine, budget=budget)
    except VerifyError as error:
        return _refused("invalid-ilc", f"the job's ilc is not valid intermediate code: {error}")
    return run_document(finished.result, device.trace)


def _refused(code: str, message: str) -> dict[str, Any]:
    return {"status": {"code": code, "line": None, "message": message}, "variables": {},
            "trace": []}
