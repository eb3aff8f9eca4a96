"""What `rl1c run` prints: the device's trace, how the run ended, the final variables."""

from __future__ import annotations

import json
from collections.abc import Sequence

from rl1.vm.faults import RunResult
from rl1.vm.scripted import TraceEntry, run_document


def render_json(result: RunResult, trace: Sequence[TraceEntry]) -> str:
    """One JSON object: status ("ok" or the fault), all 53 variables, the trace."""
    return json.dumps(run_document(result, trace), indent=2) + "\n"


def render_text(result: RunResult, trace: Sequence[TraceEntry]) -> str:
    lines = ["trace (device time in ms):"]
    for entry in trace:
        call = entry.call + (" " + ",".join(map(str, entry.args)) if entry.args else "")
        if entry.result is not None:
            call += " -> " + " ".join(map(str, entry.result))
        lines.append(f"  {entry.time:>8}  {call}")
    if not trace:
        lines.append("  (no device command)")
    fault = result.fault
    if fault is None:
        lines.append("the program ended normally")
    else:
        where = f" at line {fault.line}" if fault.line is not None else ""
        lines.append(f"fault[{fault.kind.code}]{where}: {fault.message}")
    set_variables = [f"{name}={value}" for name, value in result.named().items() if value]
    lines.append("variables: " + (" ".join(set_variables) + " (all others 0)"
                                  if set_variables else "all 0"))
    return "\n".join(lines) + "\n"
