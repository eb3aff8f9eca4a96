"""The world file's [vary] table (spec/simulator.md, "Varying the world"): distributions
over the start's and the stands' poses, the vehicle's calibration and the noise levels,
each drawn once a run from the run's seed.

Every entry is an offset added to the value the world writes, so the world stays the
one place its nominal values are written, and a sweep's offset and a draw add up. This
module knows the table's schema, the keys' grammar and the distributions; which values a
key names, and their ranges, are the world's (vm/sim/world.py, `World.parameter`).

Each key draws from a generator of its own, seeded by the run's seed and the key's text
and apart from the noise's generators, so that adding a key, or noise, leaves every
other draw alone, and the same seed gives the same world.
"""

from __future__ import annotations

import zlib
from collections.abc import Iterator
from dataclasses import dataclass
from statistics import NormalDist
from typing import Annotated

import numpy as np
from msgspec import UNSET, Meta, Struct, UnsetType

VARY_STREAM = 0x76617279  # "vary": the first word of every draw's seed; noise's are 0..5
LEAST_MASS = 1e-6
"""The least probability a normal must have within its bounds: below it the bounds are
a typo (a draw there would be one in a million), and their inverse is not exact."""

Offset = Annotated[float, Meta(ge=-1e6, le=1e6)]
Spread = Annotated[float, Meta(gt=0, le=1e6, description="the standard deviation")]
Interval = Annotated[tuple[Offset, Offset], Meta(extra={"expected": "[low, high]"})]


class Entry(Struct, frozen=True, forbid_unknown_fields=True, kw_only=True):
    """One [vary] entry, an offset from the value the world writes: `uniform = [low,
    high]`, or `normal = [mean, sd]` with `within = [low, high]` bounding it."""

    uniform: Interval | UnsetType = UNSET
    normal: Annotated[tuple[Offset, Spread], Meta(extra={
        "expected": "[mean, sd], sd more than 0"})] | UnsetType = UNSET
    within: Interval | UnsetType = UNSET


class StartEntries(Struct, frozen=True, forbid_unknown_fields=True, kw_only=True):
    """[vary.start]: the start's position (cm) and heading (degrees)."""

    x: Entry | UnsetType = UNSET
    y: Entry | UnsetType = UNSET
    heading: Entry | UnsetType = UNSET


class StandEntries(Struct, frozen=True, forbid_unknown_fields=True, kw_only=True):
    """[vary.stands.NAME]: a stand's centre (cm) and facing (degrees)."""

    x: Entry | UnsetType = UNSET
    y: Entry | UnsetType = UNSET
    facing: Entry | UnsetType = UNSET


class VaryTable(Struct, frozen=True, forbid_unknown_fields=True, kw_only=True):
    """[vary]: what each run draws, by the key of what it moves."""

    start: StartEntries = StartEntries()
    stands: dict[Annotated[str, Meta(min_length=1, max_length=64)], StandEntries] = {}
    vehicle: dict[Annotated[str, Meta(max_length=64)], Entry] = {}
    noise: dict[Annotated[str, Meta(max_length=64)], Entry] = {}


def entries(table: VaryTable) -> Iterator[tuple[tuple[str, ...], Entry]]:
    """Each entry of `table` with its path under [vary] (("stands", "s", "x")), in
    the order written within each table."""
    poses: list[tuple[tuple[str, ...], StartEntries | StandEntries]] = [
        (("start",), table.start),
        *((("stands", name), stand) for name, stand in table.stands.items())]
    for prefix, pose in poses:
        for field in pose.__struct_fields__:
            entry = getattr(pose, field)
            if isinstance(entry, Entry):
                yield (*prefix, field), entry
    for kind, flat in (("vehicle", table.vehicle), ("noise", table.noise)):
        for field, entry in flat.items():
            yield (kind, field), entry


def key_of(path: tuple[str, ...]) -> str:
    """A parameter's key, as `--sweep` and the records write it: `stands.NAME.x`."""
    return ".".join(path)


def split_key(key: str) -> tuple[str, str | None, str]:
    """A key's table, stand name (or None) and field; ValueError saying what a key is."""
    table, _, rest = key.partition(".")
    name, _, field = rest.rpartition(".") if table == "stands" else ("", "", rest)
    if table not in ("start", "stands", "vehicle", "noise") or not field or (
            table == "stands") != bool(name):
        raise ValueError(f"`{key[:80]}` names no parameter; a key is start.x, start.y, "
                         "start.heading, stands.NAME.x (.y, .facing), vehicle.FIELD or "
                         "noise.FIELD (spec/simulator.md, \"Varying the world\")")
    return table, name or None, field


@dataclass(frozen=True, slots=True)
class Uniform:
    """Every offset from `low` to `high` equally likely."""

    low: float
    high: float

    def bounds(self, low: float, high: float) -> tuple[float, float]:
        return self.low, self.high

    def draw(self, u: float, low: float, high: float) -> float:
        """The offset at `u` (0 <= u < 1) of the distribution's quantiles."""
        return self.low + (self.high - self.low) * u


@dataclass(frozen=True, slots=True)
class Normal:
    """A normal distribution of `mean` and `sd`, truncated to `within` when given, and
    always to the range its parameter may take (the bounds of `draw`)."""

    mean: float
    sd: float
    within: tuple[float, float] | None = None

    def bounds(self, low: float, high: float) -> tuple[float, float]:
        """Where the draws lie when the parameter's offsets may be `low`..`high`."""
        if self.within is None:
            return low, high
        return max(low, self.within[0]), min(high, self.within[1])

    def mass(self, low: float, high: float) -> float:
        """The probability of the untruncated normal within the bounds."""
        low, high = self.bounds(low, high)
        dist = NormalDist(self.mean, self.sd)
        return max(0.0, dist.cdf(high) - dist.cdf(low)) if low <= high else 0.0

    def draw(self, u: float, low: float, high: float) -> float:
        """The offset at `u` (0 <= u < 1) of the truncated distribution's quantiles: the
        inverse of the normal's distribution function, so one draw is one offset,
        whatever the bounds."""
        low, high = self.bounds(low, high)
        mean = self.mean
        # Past the mean, the upper tail's probabilities lose their digits near 1: draw
        # the mirror image in the lower tail.
        mirrored = (low + high) / 2 > mean
        first, last = (2 * mean - high, 2 * mean - low) if mirrored else (low, high)
        dist = NormalDist(mean, self.sd)
        a, b = dist.cdf(first), dist.cdf(last)
        p = a + (b - a) * (1 - u if mirrored else u)
        offset = dist.inv_cdf(p) if 0 < p < 1 else (first if p <= 0 else last)
        return min(high, max(low, 2 * mean - offset if mirrored else offset))


Distribution = Uniform | Normal


@dataclass(frozen=True, slots=True)
class Parameter:
    """A value of the world that [vary] and `--sweep` move, and the range it may take."""

    value: float
    low: float
    high: float


@dataclass(frozen=True, slots=True)
class Varied:
    """A parameter a run draws: its key (`start.x`) and the distribution of its offset."""

    key: str
    distribution: Distribution


def distribution(entry: Entry) -> Distribution:
    """The distribution an entry writes; ValueError with the entry's key at fault and
    what to write."""
    match entry:
        case Entry(uniform=(low, high), normal=UnsetType(), within=UnsetType()):
            if low > high:
                raise _Wrong("uniform", f"[{low:g}, {high:g}] runs backwards; write "
                             "[low, high] with low <= high")
            return Uniform(low, high)
        case Entry(uniform=UnsetType(), normal=(mean, sd), within=within):
            if isinstance(within, UnsetType):
                return Normal(mean, sd)
            if within[0] > within[1]:
                raise _Wrong("within", f"[{within[0]:g}, {within[1]:g}] runs backwards; "
                             "write [low, high] with low <= high")
            return Normal(mean, sd, within)
        case Entry(uniform=UnsetType(), normal=UnsetType()):
            raise _Wrong("", "gives no distribution; write `{ uniform = [low, high] }` or "
                         "`{ normal = [mean, sd], within = [low, high] }`")
        case Entry(uniform=tuple(), normal=tuple()):
            raise _Wrong("normal", "and uniform both given; give one distribution")
    raise _Wrong("within", "bounds a normal; a uniform's [low, high] are its bounds")


class _Wrong(ValueError):
    """An entry's fault: the key of the entry at fault ("" for the entry itself)."""

    def __init__(self, key: str, detail: str) -> None:
        super().__init__(detail)
        self.key = key


def wrong_key(error: ValueError) -> str:
    """The key within an entry that `distribution` found at fault ("" for the entry)."""
    return error.key if isinstance(error, _Wrong) else ""


def uniform_draw(seed: int, key: str) -> float:
    """The run's uniform number in [0, 1) for `key`, from a generator of its own."""
    return float(np.random.default_rng(
        [VARY_STREAM, seed, zlib.crc32(key.encode())]).random())


def check_bounds(dist: Distribution, low: float, high: float) -> str | None:
    """What is wrong with `dist` as offsets of a parameter that may move by `low`..`high`
    (its range less its value), or None."""
    first, last = dist.bounds(low, high)
    if first < low - 1e-9 or last > high + 1e-9:
        return (f"offsets {first:g}..{last:g} would leave the value's range; offsets "
                f"within {low:g}..{high:g} keep it")
    if isinstance(dist, Normal) and dist.mass(low, high) < LEAST_MASS:
        return (f"the normal [{dist.mean:g}, {dist.sd:g}] has less than one draw in a "
                f"million within {first:g}..{last:g}; move its mean or widen its bounds")
    return None
