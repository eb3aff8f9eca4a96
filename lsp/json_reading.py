"""Reading JSON as RFC 8259 writes it, for every protocol of `rl1.lsp` (LSP, the studio's,
DAP): Python's json also reads NaN, Infinity and -Infinity, and reads a number beyond a
double (`1e400`) as infinity, none of which is JSON. Read, an id of NaN was answered as
`"id": NaN`, which no client's JSON reader reads, so that the client waited for ever."""

from __future__ import annotations

import json
import math
from typing import Any


def read_json(data: str | bytes) -> Any:
    """The value of the JSON text `data`; ValueError (or RecursionError, nested too
    deeply) when it is none, saying why."""
    return json.loads(data, parse_float=_finite, parse_constant=_no_constant)


def _finite(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"{text} is beyond the numbers JSON carries")
    return value


def _no_constant(name: str) -> float:
    raise ValueError(f"{name} is no JSON")
