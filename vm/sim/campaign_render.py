"""Pictures of a campaign (`rl1c sim --runs N --svg FILE`, `--html FILE`; spec/simulator.md
"Pictures of a campaign"): every run's path overlaid on the world as written, thin and
translucent, each failure marked where it happened and coloured by its kind, the goal;
and, for a sweep, the heat map of the success rate over its grid.

The picture is drawn with the top view's helpers (render.py). What it keeps of the runs
is bounded whatever their number (`Overlay`): the paths of at most MAX_PATHS runs, spread
evenly over the campaign, and the first MAX_MARKS failures; the picture says so.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from html import escape

from .geometry import Point
from .render import _TEXT, MARGIN, TOP, _Plane, _scale, _scene, _svg_start
from .world import World

MAX_PATHS = 500
"""Paths a picture overlays, at most (64 points each): a larger campaign's every n-th."""
MAX_MARKS = 2_000
"""Failures a picture marks, at most: the first of a campaign that has more."""
SUCCESS = "#1565c0"
KIND_COLOURS = ("#d11", "#e67e00", "#8e24aa", "#2a9d2a", "#c2185b", "#6d4c41", "#00838f",
                "#9e9d24")
"""Colours of the kinds of failure, in the order they first appear (then again)."""


@dataclass(frozen=True, slots=True)
class Run:
    """A run as its picture draws it: its seed, its path, where it ended, and, when it
    failed, its kind (a fault's or a safety stop's, or goal-missed) and source line."""

    seed: int
    path: tuple[Point, ...]
    end: Point
    kind: str | None = None
    line: int | None = None


@dataclass(slots=True)
class Overlay:
    """What a picture keeps of a campaign's runs, given in order: the paths of every
    `every`-th run, and the first MAX_MARKS failures; and the counts of all.

    `every` doubles (and every other path kept goes) each time the paths would pass
    MAX_PATHS, so that however many runs were planned, a campaign stopped at any point
    shows from MAX_PATHS / 2 to MAX_PATHS paths spread evenly over the runs it made."""

    runs: int = 0
    every: int = 1
    paths: list[Run] = field(default_factory=list)
    marks: list[Run] = field(default_factory=list)
    kinds: dict[str, int] = field(default_factory=dict)  # failures of each kind, in order

    def add(self, run: Run) -> None:
        if self.runs % self.every == 0:
            if len(self.paths) == MAX_PATHS:
                self.every *= 2
                self.paths = self.paths[::2]
            if self.runs % self.every == 0:
                self.paths.append(run)
        self.runs += 1
        if run.kind is not None:
            self.kinds[run.kind] = self.kinds.get(run.kind, 0) + 1
            if len(self.marks) < MAX_MARKS:
                self.marks.append(run)

    def colour(self, kind: str) -> str:
        return KIND_COLOURS[list(self.kinds).index(kind) % len(KIND_COLOURS)]


def svg(world: World, overlay: Overlay, title: str, moved: Sequence[str] = ()) -> str:
    """The campaign's runs on the world as written, whose parameters `moved` (by [vary]
    or a sweep: their keys) each run moves; the paths show where."""
    width, depth = world.floor
    plane = _Plane(world)
    body = _scene(world, plane, None)
    for run in overlay.paths:
        colour = SUCCESS if run.kind is None else overlay.colour(run.kind)
        body.append(f'<polyline class="run" data-seed="{run.seed}" points="'
                    f'{plane.points(run.path)}" fill="none" stroke="{colour}" '
                    f'stroke-width="1" stroke-opacity="0.3"><title>seed {run.seed}'
                    f'{"" if run.kind is None else ": " + escape(run.kind)}</title>'
                    "</polyline>")
    for run in overlay.marks:
        assert run.kind is not None
        x, y = plane.at(*run.end)
        at = "" if run.line is None else f" at line {run.line}"
        body.append(f'<circle class="failure" data-seed="{run.seed}" data-kind="'
                    f'{escape(run.kind)}" cx="{x:.1f}" cy="{y:.1f}" r="4" fill="'
                    f'{overlay.colour(run.kind)}" fill-opacity="0.8"><title>seed {run.seed}: '
                    f"{escape(run.kind)}{at}</title></circle>")
    below = TOP + depth + MARGIN
    legend, height = _legend(overlay, MARGIN, below + 24, moved)
    total_width = max(width + 2 * MARGIN, 560)
    total_height = below + 34 + height
    return (_svg_start(total_width, total_height)
            + f'<text x="{MARGIN}" y="18" font-size="14" {_TEXT}>{escape(title)}</text>'
            + "".join(body) + _scale(MARGIN, below + 6, width) + legend + "</svg>\n")


def _legend(overlay: Overlay, x: float, y: float, moved: Sequence[str]
            ) -> tuple[str, float]:
    """The legend, a line an item: what the paths are (and which were left out), each
    kind of failure with its count (and the marks left out); its markup and height."""
    shown = len(overlay.paths)
    items = [(f'<line x1="0" y1="0" x2="22" y2="0" stroke="{SUCCESS}" stroke-width="2"/>',
              f"a run's path, ended well ({shown:,} paths of {overlay.runs:,} runs"
              + (f": every {overlay.every}th run)" if shown < overlay.runs else ")"))]
    for kind, count in overlay.kinds.items():
        items.append((f'<circle cx="11" cy="0" r="5" fill="{overlay.colour(kind)}"/>',
                      f"{kind}: {count:,} run{'s' if count != 1 else ''}, marked where "
                      "it ended, its path in the same colour"))
    marked = len(overlay.marks)
    failures = sum(overlay.kinds.values())
    if marked < failures:
        items.append(("", f"the first {marked:,} failures of {failures:,} are marked"))
    if moved:
        items.append(("", "the world as written; each run moves " + ", ".join(moved)))
    row = 18
    parts = ['<g id="legend">']
    for i, (swatch, text) in enumerate(items):
        parts.append(f'<g class="item" transform="translate({x:.0f},{y + row * i:.0f})">'
                     f'{swatch}<text x="28" y="4" font-size="11" {_TEXT}>{escape(text)}'
                     "</text></g>")
    return "".join(parts) + "</g>", row * len(items)


CELL = 48  # px, a heat map's cell


def heat_map_svg(title: str, rows: tuple[str, Sequence[float]],
                 columns: tuple[str, Sequence[float]],
                 rates: Sequence[tuple[int, int]]) -> str:
    """The success rate of each point of a sweep's grid: a row for each offset of the
    first parameter, a column for each of the second (one column when one is swept),
    each cell shaded from red (0 %) to green (100 %) and labelled with its rate and
    runs; `rates` gives (successes, runs) point by point, rows first."""
    (row_key, row_offsets), (column_key, column_offsets) = rows, columns
    left, top = 150.0, 60.0
    parts = [f'<text x="{MARGIN}" y="18" font-size="14" {_TEXT}>{escape(title)}</text>',
             f'<text x="{left}" y="{top - 26}" font-size="12" {_TEXT}>'
             f"{escape(column_key)} (offset)</text>",
             f'<text x="{MARGIN}" y="{top - 8}" font-size="12" {_TEXT}>'
             f"{escape(row_key)} (offset)</text>"]
    for j, offset in enumerate(column_offsets):
        parts.append(f'<text x="{left + CELL * (j + 0.5):.1f}" y="{top - 8}" font-size="11" '
                     f'text-anchor="middle" {_TEXT}>{offset:+g}</text>')
    for i, offset in enumerate(row_offsets):
        cy = top + CELL * i
        parts.append(f'<text x="{left - 8}" y="{cy + CELL / 2 + 4:.1f}" font-size="11" '
                     f'text-anchor="end" {_TEXT}>{offset:+g}</text>')
        for j in range(len(column_offsets)):
            at = i * len(column_offsets) + j
            successes, runs = rates[at] if at < len(rates) else (0, 0)
            cx = left + CELL * j
            if runs == 0:
                fill, label = "#eee", "-"
            else:
                rate = successes / runs
                fill, label = _shade(rate), f"{rate:.0%}"
            parts.append(f'<g class="cell" data-successes="{successes}" data-runs="{runs}">'
                         f'<rect x="{cx:.1f}" y="{cy:.1f}" width="{CELL}" height="{CELL}" '
                         f'fill="{fill}" stroke="#fff"/><text x="{cx + CELL / 2:.1f}" '
                         f'y="{cy + CELL / 2 + 4:.1f}" font-size="11" text-anchor="middle" '
                         f'{_TEXT}>{label}</text><title>{row_key} {offset:+g}'
                         + (f", {column_key} {column_offsets[j]:+g}" if column_key else "")
                         + f": {successes} of {runs}</title></g>")
    total_width = max(left + CELL * len(column_offsets) + MARGIN, 8.0 * len(title))
    total_height = top + CELL * len(row_offsets) + MARGIN
    return (_svg_start(total_width, total_height)
            + "".join(parts) + "</svg>\n")


def _shade(rate: float) -> str:
    """Red at 0, amber at a half, green at 1."""
    red, green = (1.0, rate * 2) if rate < 0.5 else (2 - rate * 2, 1.0)
    return f"#{round(40 + 180 * red):02x}{round(40 + 160 * green):02x}50"


def html(title: str, pictures: Sequence[str], summary: str) -> str:
    """One page, offline: the pictures (SVG markup) and the campaign's summary."""
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{escape(title)}</title><style>body{{font-family:sans-serif;"
            "margin:1em}pre{background:#f6f6f6;padding:.5em}</style></head><body>"
            f"<h1>{escape(title)}</h1>" + "".join(f"<figure>{picture}</figure>"
                                                  for picture in pictures)
            + f"<pre>{escape(summary)}</pre></body></html>\n")
