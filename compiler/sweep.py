"""A sweep (`rl1c sim --runs N --sweep KEY=A:B:N`, spec/simulator.md "Sweeps"): a campaign
at each point of a grid over one or two parameters of the world, each moved by the
point's offset from the value the world writes (the keys are [vary]'s, vm/sim/vary.py),
every point with the same seeds; and the success rate of each point, as a table and, for
two parameters, a heat map.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import product

from rl1.compiler.campaign import Tally, wilson
from rl1.vm.sim.vary import check_bounds
from rl1.vm.sim.world import World

MAX_AXES = 2
MAX_POINTS = 10_000  # of a grid: each is a campaign of its own
_AXIS = re.compile(r"(?P<key>[^=]+)=(?P<first>[^:]+):(?P<last>[^:]+):(?P<count>[0-9]+)")

Point = tuple[tuple[str, float], ...]  # (key, offset) per axis


@dataclass(frozen=True, slots=True)
class Axis:
    """A parameter swept: its key and its offsets, from `first` to `last` in `count`
    evenly spaced steps (one: `first` alone)."""

    key: str
    first: float
    last: float
    count: int

    def offsets(self) -> list[float]:
        if self.count == 1:
            return [self.first]
        step = (self.last - self.first) / (self.count - 1)
        return [self.first + step * i for i in range(self.count - 1)] + [self.last]

    def words(self, offset: float | None = None) -> str:
        """The `--sweep` argument of this axis, or of its one point `offset`."""
        if offset is None:
            return f"{self.key}={self.first:g}:{self.last:g}:{self.count}"
        exact = f"{offset:g}" if float(f"{offset:g}") == offset else repr(offset)
        return f"{self.key}={exact}:{exact}:1"


def parse_axis(text: str) -> Axis:
    """`KEY=A:B:N` as an Axis; ValueError saying what to write."""
    match = _AXIS.fullmatch(text.strip())
    if match is None:
        raise ValueError(f"`{text[:80]}` is not KEY=A:B:N; write e.g. "
                         "stands.stand.x=-50:50:5 (offsets -50 to 50 cm in 5 points)")
    try:
        first, last = float(match["first"]), float(match["last"])
    except ValueError:
        raise ValueError(f"`{text[:80]}`: A and B are numbers, the first and the last "
                         "offset from the world's value") from None
    digits = match["count"].lstrip("0")  # no more digits than MAX_POINTS has are read
    count = int(digits or "0") if len(digits) <= len(str(MAX_POINTS)) else MAX_POINTS + 1
    if not (math.isfinite(first) and math.isfinite(last)):
        raise ValueError(f"`{text[:80]}`: A and B are finite numbers")
    if not 1 <= count <= MAX_POINTS or (count == 1 and first != last):
        raise ValueError(f"`{text[:80]}`: N is the number of points, 1 (with A equal to "
                         f"B) to {MAX_POINTS}")
    return Axis(match["key"].strip(), first, last, count)


def grid(axes: Sequence[Axis]) -> list[Point]:
    """Every point of the grid over `axes`, the first axis slowest."""
    return [tuple(zip((axis.key for axis in axes), offsets, strict=True))
            for offsets in product(*(axis.offsets() for axis in axes))]


def check(world: World, axes: Sequence[Axis]) -> None:
    """ValueError, saying which, when a point of the grid moves a parameter out of its
    range or leaves a [vary] draw no room; the axes are distinct known parameters."""
    if len(axes) > MAX_AXES:
        raise ValueError(f"at most {MAX_AXES} parameters are swept at once")
    keys = [axis.key for axis in axes]
    if len(set(keys)) < len(keys):
        raise ValueError(f"{keys[0]} is swept twice; sweep two parameters, or one")
    if math.prod(axis.count for axis in axes) > MAX_POINTS:
        raise ValueError(f"the grid has more than {MAX_POINTS:,} points")
    for axis in axes:
        try:
            world.parameter(axis.key)
        except ValueError as error:
            raise ValueError(f"{axis.key}: {error}") from None
    for axis in axes:  # the ends of each axis suffice: the ranges are intervals
        for offset in {axis.first, axis.last}:
            moved = world.moved({axis.key: offset})
            for varied in moved.varied:
                parameter = moved.parameter(varied.key)
                problem = check_bounds(varied.distribution, parameter.low - parameter.value,
                                       parameter.high - parameter.value)
                if problem is not None:
                    raise ValueError(f"{axis.key} moved by {offset:+g}: [vary] "
                                     f"{varied.key}: {problem}")


def table(axes: Sequence[Axis], points: Sequence[Point], tallies: Sequence[Tally]) -> str:
    """The success rate at each point with its 95 % Wilson interval, a line a point."""
    head = "".join(f"{axis.key:>{max(12, len(axis.key))}}  " for axis in axes)
    lines = [f"{head}{'successes':>12}  {'rate':>6}  95% Wilson interval"]
    for point, tally in zip(points, tallies, strict=False):
        cells = "".join(f"{offset:>+{max(12, len(key))}g}  " for key, offset in point)
        if tally.runs == 0:
            lines.append(f"{cells}{'no runs':>12}")
            continue
        low, high = wilson(tally.successes, tally.runs)
        lines.append(f"{cells}{f'{tally.successes}/{tally.runs}':>12}  "
                     f"{tally.successes / tally.runs:>6.1%}  {low:.1%}..{high:.1%}")
    return "\n".join(lines) + "\n"


def heat_map(axes: Sequence[Axis], tallies: Sequence[Tally]) -> str:
    """For two axes, the success rate (%) of each point: a row for each offset of the
    first, a column for each of the second ("-" where no run was made)."""
    rows, columns = axes
    width = max(6, *(len(f"{offset:+g}") + 1 for offset in columns.offsets()))
    lines = [f"success rate (%): a row for each offset of {rows.key}, a column for "
             f"each of {columns.key}",
             f"{'':>10}" + "".join(f"{offset:>+{width}g}" for offset in columns.offsets())]
    for i, offset in enumerate(rows.offsets()):
        cells = [tallies[at] if at < len(tallies) else Tally()
                 for at in range(i * columns.count, (i + 1) * columns.count)]
        lines.append(f"{offset:>+10g}" + "".join(
            f"{100 * tally.successes / tally.runs:>{width}.0f}" if tally.runs else
            f"{'-':>{width}}" for tally in cells))
    return "\n".join(lines) + "\n"
