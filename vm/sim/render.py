"""Pictures of a run: an SVG top view as in the paper's Fig. 9, and a self-contained HTML
page that replays the run offline.

The top view shows the floor and what is on it (each labelled as the world file names
it), the path, the vehicle's outline at intervals with its heading, the start, turns in
place as arcs, the camera's footprint at each (IMG) and the ultrasonic cone and echo at
each (ULT), the events, a scale and a legend. The replay page adds the vehicle moving,
a log of calls and events with their source lines, the camera's binary image at each
(IMG) with its window and centroid, and plots of the readings and wheel speeds over time.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterable, Sequence
from html import escape
from itertools import pairwise
from typing import Any

from .camera import View, focal
from .device import SimEntry
from .geometry import Point, rectangle
from .goal import Goal, Verdict
from .motion import Pose
from .sightings import Sighting, SightingImages
from .simulator import Event
from .ultrasonic import SENSORS
from .world import World

OUTLINE_EVERY = 40.0  # cm of travel (or, turning, its equivalent) between two outlines
REPLAY_CALLS = 10_000
"""The calls a replay page lists, at most: the first and the last half of them, and how
many were left out between (a loop of calls can make millions, 16 bytes each)."""
MAX_DRAWN = 200
"""Camera footprints and ultrasonic cones the top view draws, at most, each: a run with
more draws every n-th, and the legend says so."""
MAX_FRAMES = 120
"""Camera images a replay page holds, at most (up to 8 KB each), spread over the run."""
MAX_PLOTTED = 2_000
"""Points of each series a plot draws, at most (a polling loop can read millions)."""
MAX_SIGHTS = 2_000
"""Camera footprints a replay page holds, at most (60 bytes each), spread over the run."""
VIEW_MOVED = 25.0  # cm
VIEW_TURNED = math.radians(5)
FAR = 300.0  # cm: a footprint that reaches the horizon is cut here
TURN_MIN = math.radians(2)  # a turn in place smaller than this is not drawn
MARGIN = 20.0  # px around the floor (1 px = 1 cm)
TOP = 30.0  # px above the floor, for the title
LEGEND_COLUMNS, LEGEND_WIDTH = 3, 270  # px a column

COLOURS = {"lost": "#e67e00", "handler": "#8e24aa", "found": "#2a9d2a", "fault": "#d11",
           "end": "#1565c0", "call": "#333"}
_PATH = "#1565c0"
_CAMERA = "#0a8"
_ULTRASONIC = "#c2185b"
_TEXT = 'font-family="sans-serif"'


class _Plane:
    """World coordinates (cm, y up) to the picture's (px, y down)."""

    def __init__(self, world: World) -> None:
        self.depth = world.floor[1]

    def at(self, x: float, y: float) -> tuple[float, float]:
        return MARGIN + x, TOP + self.depth - y

    def points(self, points: Iterable[Point]) -> str:
        return " ".join(f"{sx:.1f},{sy:.1f}" for sx, sy in (self.at(x, y) for x, y in points))

    def label(self, x: float, y: float, text: str, anchor: str = "middle") -> str:
        sx, sy = self.at(x, y)
        return (f'<text class="label" x="{sx:.1f}" y="{sy:.1f}" text-anchor="{anchor}" '
                f'font-size="11" {_TEXT} fill="#222" stroke="#fff" stroke-width="3" '
                f'paint-order="stroke">{escape(text)}</text>')


def _centroid(points: Sequence[Point]) -> Point:
    return sum(p[0] for p in points) / len(points), sum(p[1] for p in points) / len(points)


def _scene(world: World, plane: _Plane, verdict: Verdict | None) -> list[str]:
    """The floor and its features, each labelled with its name, and the world's goal
    (as `verdict` judged it, when given)."""
    width, depth = world.floor
    x0, y0 = plane.at(0, depth)
    parts = [f'<rect x="{x0:g}" y="{y0:g}" width="{width:g}" height="{depth:g}" '
             'fill="#f7f5ef" stroke="#888" stroke-width="2"/>']
    labels = []
    for line in world.lines:
        parts.append(f'<polyline points="{plane.points(line.points)}" fill="none" '
                     f'stroke="#222" stroke-width="{line.width:g}">'
                     f'<title>line {escape(line.name)}</title></polyline>')
        # The label sits beside the middle of the line's longest piece.
        a, b = max(pairwise(line.points),
                   key=lambda ab: math.dist(ab[0], ab[1]), default=(line.points[0],) * 2)
        labels.append(plane.label((a[0] + b[0]) / 2, (a[1] + b[1]) / 2 + 6, line.name))
    for mark in world.marks:
        parts.append(f'<polygon points="{plane.points(mark.points)}" fill="#444">'
                     f'<title>mark {escape(mark.name)}</title></polygon>')
        mx, my = _centroid(mark.points)
        labels.append(plane.label(mx + 8, my, mark.name, "start"))
    for block in world.blocks:
        parts.append(f'<polygon points="{plane.points(block.points)}" fill="#9aa" '
                     f'stroke="#566"><title>{escape(block.name)}</title></polygon>')
        labels.append(plane.label(*_centroid(block.points), block.name))
    for stand in world.stands:
        mx, my = plane.at(*stand.marker())
        parts.append(f'<polygon points="{plane.points(stand.corners())}" fill="#c9b38a" '
                     f'stroke="#7a6236"><title>stand {escape(stand.name)}</title></polygon>'
                     f'<circle cx="{mx:.1f}" cy="{my:.1f}" r="3" fill="#f33">'
                     f'<title>marker of {escape(stand.name)}</title></circle>')
        labels.append(plane.label(*_centroid(stand.corners()), stand.name))
    goal = goal_marks(world.goal, verdict, plane) if world.goal is not None else []
    return parts + labels + goal


def _outline(world: World, plane: _Plane, pose: Pose, style: str) -> str:
    """The vehicle's body at `pose`, with its heading as an arrow from the centre."""
    vehicle = world.vehicle
    corners = rectangle(pose.x, pose.y, vehicle.length, vehicle.width, pose.heading)
    nose = (pose.x + (vehicle.length / 2 + 12) * math.cos(pose.heading),
            pose.y + (vehicle.length / 2 + 12) * math.sin(pose.heading))
    return (f'<g class="pose"><polygon points="{plane.points(corners)}" {style}/>'
            f'<polyline class="heading" points="{plane.points([(pose.x, pose.y), nose])}" '
            f'stroke="{_PATH}" stroke-width="1.5" marker-end="url(#arrow)"/></g>')


def turns_in_place(track: Sequence[tuple[float, Pose]], trace: Sequence[SimEntry] = ()
                   ) -> list[tuple[Pose, float]]:
    """The turns the vehicle made without moving, in the order of time: where each began
    and the angle turned (radians, + left), each turn one way (a scan left then right is
    two). A (ROT)'s is its own, exact; any other (wheels turning opposite ways) is read
    from the track, to within what its decimation keeps."""
    rotations = [(entry.time, following.time if following else math.inf, entry)
                 for entry, following in pairwise([*trace, None])
                 if entry is not None and entry.call == "ROT" and entry.args]
    turns = [(entry.time, Pose(entry.pose.x, entry.pose.y,
                               entry.pose.heading - math.radians(entry.args[0])),
              math.radians(entry.args[0])) for _, _, entry in rotations]
    start: tuple[float, Pose] | None = None
    turned = 0.0
    for (t0, before), (t1, after) in pairwise(track):
        step = after.heading - before.heading
        still = (math.hypot(after.x - before.x, after.y - before.y) < 0.5
                 and not any(low < t1 and t0 < high for low, high, _ in rotations))
        if start is not None and (not still or step * turned < 0 or math.hypot(
                after.x - start[1].x, after.y - start[1].y) > 2.0):
            if abs(turned) >= TURN_MIN:
                turns.append((*start, turned))
            start, turned = None, 0.0
        if still and abs(step) > 1e-6:
            if start is None:
                start = (t0, before)
            turned += step
    if start is not None and abs(turned) >= TURN_MIN:
        turns.append((*start, turned))
    return [(pose, angle) for _, pose, angle in sorted(turns, key=lambda turn: turn[0])]


def _turn(world: World, plane: _Plane, start: Pose, turned: float) -> str:
    radius = world.vehicle.width * 0.8
    steps = max(2, int(abs(turned) / math.radians(5)))
    arc = [(start.x + radius * math.cos(start.heading + turned * i / steps),
            start.y + radius * math.sin(start.heading + turned * i / steps))
           for i in range(steps + 1)]
    end = start.heading + turned
    label_at = (start.x + (radius + 12) * math.cos(end), start.y + (radius + 12) * math.sin(end))
    return (f'<g class="turn"><polyline points="{plane.points(arc)}" fill="none" '
            f'stroke="#6a1b9a" stroke-width="2" marker-end="url(#arrow)"/>'
            + plane.label(*label_at, f"{math.degrees(turned):+.0f}°") + "</g>")


def footprint(view: View, world: World) -> list[Point]:
    """The floor the camera at `view` sees: where the rays through the image's corners
    meet it, cut at FAR cm from the camera (a ray at or above the horizon is cut there)."""
    vehicle = world.vehicle
    f = focal(vehicle)
    width, height = vehicle.image_width, vehicle.image_height
    corners = []
    for column, row in ((0, height), (width, height), (width, 0), (0, 0)):
        left, up = column - width / 2, height / 2 - row  # image x grows to the left
        ahead = f * math.cos(view.pitch) - up * math.sin(view.pitch)
        rise = f * math.sin(view.pitch) + up * math.cos(view.pitch)
        dx = ahead * math.cos(view.yaw) - left * math.sin(view.yaw)
        dy = ahead * math.sin(view.yaw) + left * math.cos(view.yaw)
        reach = FAR / math.hypot(dx, dy)
        if rise < 0:
            reach = min(reach, view.z / -rise)
        corners.append((view.x + reach * dx, view.y + reach * dy))
    return corners


def _cone(world: World, plane: _Plane, entry: SimEntry) -> str:
    """The ultrasonic sensor's cone at a reading, to the distance it reported: solid
    with a dot where an echo came back, dashed when nothing was in range."""
    vehicle = world.vehicle
    along, across, facing = SENSORS[entry.call[-1]]
    pose = entry.pose
    c, s = math.cos(pose.heading), math.sin(pose.heading)
    bx, by = along * vehicle.length / 2, across * vehicle.width / 2
    ox, oy = pose.x + bx * c - by * s, pose.y + bx * s + by * c
    distance = float(entry.result[0]) if entry.result else 0.0
    towards = pose.heading + facing
    cone = math.radians(vehicle.ultrasonic_cone)
    edge = [(ox + distance * math.cos(towards + cone * k / 4),
             oy + distance * math.sin(towards + cone * k / 4)) for k in range(-4, 5)]
    tip = (ox + distance * math.cos(towards), oy + distance * math.sin(towards))
    echo = distance < vehicle.ultrasonic_range
    dashed = ' stroke-dasharray="3 3"'
    ex, ey = plane.at(*tip)
    return (f'<g class="ultrasonic"><polygon points="{plane.points([(ox, oy), *edge])}" '
            f'fill="{_ULTRASONIC}" fill-opacity="0.08" stroke="none"/>'
            f'<polyline points="{plane.points([(ox, oy), tip])}" stroke="{_ULTRASONIC}" '
            f'stroke-width="1.2"{"" if echo else dashed}/>'
            + (f'<circle cx="{ex:.1f}" cy="{ey:.1f}" r="2.5" fill="{_ULTRASONIC}"/>'
               if echo else "")
            + f'<title>{entry.time:.2f} s: ULT {entry.call[-1]} = {distance:g} cm</title></g>')


def _distinct(sightings: Sequence[Sighting]) -> list[Sighting]:
    """The sightings whose view differs from the one kept before: another scene or
    pitch, or moved VIEW_MOVED cm or turned VIEW_TURNED (a loop polling (IMG) while the
    vehicle stands or creeps draws one footprint, not thousands on top of each other)."""
    kept: list[Sighting] = []
    for sighting in sightings:
        view = sighting.view
        if kept:
            last = kept[-1].view
            if (kept[-1].scene == sighting.scene and last.pitch == view.pitch
                    and math.hypot(view.x - last.x, view.y - last.y) < VIEW_MOVED
                    and abs(view.yaw - last.yaw) < VIEW_TURNED):
                continue
        kept.append(sighting)
    return kept


def _every(items: Sequence[object], most: int = MAX_DRAWN) -> int:
    """Take every n-th of `items` so that at most `most` are taken."""
    return max(1, math.ceil(len(items) / most))


def _legend(x: float, y: float, notes: dict[str, str]) -> tuple[str, float]:
    """The legend, four items a row, from (x, y) down; its markup and its height."""
    swatches = [
        ("path", f'<line x1="0" y1="0" x2="22" y2="0" stroke="{_PATH}" stroke-width="1.5" '
                 'stroke-dasharray="4 3"/>'),
        (f"outline every {OUTLINE_EVERY:g} cm, heading",
         f'<rect x="0" y="-5" width="16" height="10" fill="none" stroke="{_PATH}"/>'
         f'<line x1="8" y1="0" x2="22" y2="0" stroke="{_PATH}" marker-end="url(#arrow)"/>'),
        ("start", '<rect x="0" y="-5" width="16" height="10" fill="#2a9d2a" '
                  'fill-opacity="0.35" stroke="#2a9d2a"/>'),
        ("end pose", f'<rect x="0" y="-5" width="16" height="10" fill="{_PATH}" '
                f'fill-opacity="0.25" stroke="{_PATH}" stroke-width="2"/>'),
        ("turn in place", '<path d="M0,4 A9,9 0 0 1 18,4" fill="none" stroke="#6a1b9a" '
                          'stroke-width="2"/>'),
        ("camera at each IMG" + notes.get("camera", ""),
         f'<polygon points="0,6 22,6 16,-6 6,-6" fill="{_CAMERA}" fill-opacity="0.2" '
         f'stroke="{_CAMERA}"/>'),
        ("ultrasonic echo" + notes.get("ultrasonic", ""),
         f'<polygon points="0,0 22,-6 22,6" fill="{_ULTRASONIC}" fill-opacity="0.15"/>'
         f'<line x1="0" y1="0" x2="22" y2="0" stroke="{_ULTRASONIC}"/>'),
        ("line, mark", '<line x1="0" y1="0" x2="12" y2="0" stroke="#222" stroke-width="2"/>'
                       '<rect x="14" y="-4" width="8" height="8" fill="#444"/>'),
        ("stand, marker", '<rect x="0" y="-6" width="16" height="12" fill="#c9b38a" '
                          'stroke="#7a6236"/><circle cx="8" cy="0" r="3" fill="#f33"/>'),
        ("wall, obstacle", '<rect x="0" y="-6" width="22" height="12" fill="#9aa" stroke="#566"/>'),
        *[(f"line {kind}" if kind in ("lost", "found") else
           {"handler": "handler taken", "fault": "fault", "end": "run ended"}[kind],
           f'<circle cx="8" cy="0" r="6" fill="{COLOURS[kind]}" fill-opacity="0.8"/>')
          for kind in ("lost", "found", "handler", "fault", "end")],
    ]
    columns, column_width, row_height = LEGEND_COLUMNS, LEGEND_WIDTH, 18
    parts = ['<g id="legend">']
    for i, (text, swatch) in enumerate(swatches):
        cx, cy = x + column_width * (i % columns), y + row_height * (i // columns) + 9
        parts.append(f'<g class="item" transform="translate({cx:.0f},{cy:.0f})">{swatch}'
                     f'<text x="28" y="4" font-size="11" {_TEXT}>{escape(text)}</text></g>')
    parts.append("</g>")
    return "".join(parts), row_height * math.ceil(len(swatches) / columns)


def _svg_start(width: float, height: float) -> str:
    """The opening tag of a picture `width` by `height` pixels."""
    return (f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {width:g} {height:g}" '
            f'width="{width:g}" height="{height:g}">')


def _scale(x: float, y: float, width: float) -> str:
    """A scale bar of a round length, about a quarter of the floor's width."""
    length = max((n for n in (10, 20, 50, 100, 200, 500, 1000, 2000) if n <= width / 4),
                 default=10)
    ticks = "".join(f'<line x1="{x + length * k / 2:g}" y1="{y - 4:g}" '
                    f'x2="{x + length * k / 2:g}" y2="{y + 4:g}" stroke="#222"/>'
                    for k in range(3))
    return (f'<g id="scale"><line x1="{x:g}" y1="{y:g}" x2="{x + length:g}" y2="{y:g}" '
            f'stroke="#222" stroke-width="2"/>{ticks}<text x="{x + length + 6:g}" '
            f'y="{y + 4:g}" font-size="11" {_TEXT}>{length} cm</text></g>')


def goal_marks(goal: Goal, verdict: Verdict | None, plane: _Plane) -> list[str]:
    """The goal's regions, each labelled (reach and end dashed, avoid filled, a hold as
    the circle of its distance round the stand's marker): grey before a verdict, green
    where it was met, red where missed, with a cross where a missed part went wrong."""
    outcomes = iter(verdict.outcomes if verdict is not None else ())  # in the goal's order
    marks, labels = [], []

    def draw(shape: str, label: str, where: Point) -> None:
        outcome = next(outcomes, None)
        colour = "#777" if outcome is None else "#2a9d2a" if outcome.met else "#d11"
        said = label if outcome is None else f"{outcome.title()}: {outcome.text}"
        marks.append(f'<g class="goal" stroke="{colour}" fill="{colour}" stroke-width="1.5">'
                     f'{shape}<title>{escape(said)}</title></g>')
        labels.append(plane.label(*where, label))
        if outcome is not None and not outcome.met and outcome.pose is not None:
            x, y = plane.at(outcome.pose.x, outcome.pose.y)
            marks.append(f'<path class="goal-miss" d="M{x - 6:.1f},{y - 6:.1f} l12,12 '
                         f'm0,-12 l-12,12" stroke="#d11" stroke-width="3"><title>'
                         f'{escape(said)}</title></path>')

    def region(points: Sequence[Point], style: str) -> str:
        return f'<polygon points="{plane.points(points)}" {style}/>'

    def above(points: Sequence[Point]) -> Point:  # the label clear of the path through it
        return _centroid(points)[0], max(y for _, y in points) + 6

    dashed = 'fill-opacity="0.08" stroke-dasharray="6 4"'
    for reach in goal.reach:
        draw(region(reach.points, dashed), f"reach {reach.name}", above(reach.points))
    for hold in goal.holds:
        (x, y), radius = plane.at(*hold.marker), hold.within
        draw(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="{radius:g}" {dashed}/>',
             f"hold {hold.stand}", (hold.marker[0], hold.marker[1] + radius + 4))
    if goal.end is not None:
        draw(region(goal.end.points, dashed), f"end {goal.end.name}", above(goal.end.points))
    for avoid in goal.avoid:
        draw(region(avoid.points, 'fill-opacity="0.25"'), f"avoid {avoid.name}",
             above(avoid.points))
    return marks + labels


def svg(world: World, track: Sequence[tuple[float, Pose]], events: Sequence[Event],
        title: str = "", trace: Sequence[SimEntry] = (),
        sightings: Iterable[Sighting] = (), verdict: Verdict | None = None) -> str:
    """The top view of a run (and of its goal's `verdict`, when the world has a goal)."""
    return _svg(world, track, events, title, trace, list(sightings), vehicle_mark=False,
                verdict=verdict)


def _svg(world: World, track: Sequence[tuple[float, Pose]], events: Sequence[Event],
         title: str, trace: Sequence[SimEntry], sightings: Sequence[Sighting],
         vehicle_mark: bool, verdict: Verdict | None = None) -> str:
    width, depth = world.floor
    plane = _Plane(world)
    body = _scene(world, plane, verdict)
    notes: dict[str, str] = {}
    views = _distinct(sightings)
    views = views[::_every(views)]
    if len(views) < len(sightings):
        notes["camera"] = f" ({len(views):,} views of {len(sightings):,})"
    for sighting in views:
        body.append(f'<polygon class="footprint" points="'
                    f'{plane.points(footprint(sighting.view, world))}" fill="{_CAMERA}" '
                    f'fill-opacity="0.05" stroke="{_CAMERA}" stroke-opacity="0.5">'
                    f'<title>{sighting.time:.2f} s: IMG in scene {sighting.scene} = '
                    f'{", ".join(map(str, sighting.reading))}</title></polygon>')
    readings = [entry for entry in trace if entry.call.startswith("ULT ")]
    every = _every(readings)
    if every > 1:
        notes["ultrasonic"] = f" ({len(readings[::every]):,} of {len(readings):,})"
    body.extend(_cone(world, plane, entry) for entry in readings[::every])
    body.append(f'<polyline points="{plane.points((p.x, p.y) for _, p in track)}" '
                f'fill="none" stroke="{_PATH}" stroke-width="1.5" stroke-dasharray="4 3"/>')
    drawn: Pose | None = None
    for _, pose in track[1:-1]:
        # The outline is drawn again once the vehicle has moved on: a halt draws none.
        if drawn is None or math.hypot(pose.x - drawn.x, pose.y - drawn.y) + abs(
                pose.heading - drawn.heading) * world.vehicle.length / 2 >= OUTLINE_EVERY:
            body.append(_outline(world, plane, pose, f'fill="none" stroke="{_PATH}" '
                                                     'stroke-opacity="0.45"'))
            drawn = pose
    body.extend(_turn(world, plane, start, turned)
                for start, turned in turns_in_place(track, trace))
    if track:
        start = track[0][1]
        body.append(_outline(world, plane, start, 'fill="#2a9d2a" fill-opacity="0.35" '
                                                  'stroke="#2a9d2a" stroke-width="2"'))
        body.append(plane.label(start.x, start.y - world.vehicle.width / 2 - 12, "start"))
        body.append(_outline(world, plane, track[-1][1], f'fill="{_PATH}" fill-opacity="0.25" '
                                                         f'stroke="{_PATH}" stroke-width="2"'))
    for event in events:
        ex, ey = plane.at(event.pose.x, event.pose.y)
        body.append(f'<circle class="event {event.kind}" cx="{ex:.1f}" cy="{ey:.1f}" r="7" '
                    f'fill="{COLOURS.get(event.kind, "#555")}" fill-opacity="0.8"><title>'
                    f'{event.time:.2f} s: {escape(event.text)}</title></circle>')
    if vehicle_mark:
        body.append('<g id="now"><polygon id="vehicle" fill="#1565c0" fill-opacity="0.6"/>'
                    f'<polygon id="sight" fill="{_CAMERA}" fill-opacity="0.25" '
                    f'stroke="{_CAMERA}"/></g>')
    below = TOP + depth + MARGIN
    scale = _scale(MARGIN, below + 6, width)
    legend, legend_height = _legend(MARGIN, below + 20, notes)
    listed = [f'<text x="{MARGIN}" y="{below + 36 + legend_height + 16 * i:.0f}" '
              f'font-size="12" {_TEXT} fill="{COLOURS.get(event.kind, "#555")}">'
              f'{event.time:7.2f} s  {escape(event.text)}</text>'
              for i, event in enumerate(events[:12])]
    total_width = max(width + 2 * MARGIN, LEGEND_COLUMNS * LEGEND_WIDTH + MARGIN)
    total_height = below + 30 + legend_height + 16 * len(listed)
    return (_svg_start(total_width, total_height)
            + '<defs><marker id="arrow" viewBox="0 0 10 10" refX="8" refY="5" markerWidth="6" '
            'markerHeight="6" orient="auto-start-reverse"><path d="M0,0 L10,5 L0,10 z" '
            'fill="context-stroke"/></marker></defs>'
            f'<text x="{MARGIN}" y="18" font-size="14" {_TEXT}>{escape(title)}</text>'
            + "".join(body) + scale + legend + "".join(listed) + "</svg>\n")


# The replay page -----------------------------------------------------------------------

def _frames(world: World, sightings: Sequence[Sighting]) -> list[dict[str, Any]]:
    """The camera's binary image at each of at most MAX_FRAMES sightings, spread over the
    run (SightingImages.encoded)."""
    images = SightingImages(world)
    return [images.encoded(sighting)
            for sighting in sightings[::_every(sightings, MAX_FRAMES)]]


def wheel_speeds(world: World, track: Sequence[tuple[float, Pose]]
                 ) -> list[tuple[float, float, float]]:
    """The wheels' speeds (units) between two points of the track, as the kinematics of
    motion.py give them from the distance and the turn: (time, left, right)."""
    vehicle = world.vehicle
    speeds = []
    for (t0, p0), (t1, p1) in pairwise(track):
        if t1 <= t0:
            continue
        dx, dy = p1.x - p0.x, p1.y - p0.y
        ahead = dx * math.cos(p0.heading) + dy * math.sin(p0.heading)
        half = (p1.heading - p0.heading) / 2  # between two points the path is an arc
        arc = math.hypot(dx, dy) * (half / math.sin(half) if abs(half) > 1e-9 else 1.0)
        speed = arc / (t1 - t0) * (-1 if ahead < -1e-9 else 1)
        turn = (p1.heading - p0.heading) / (t1 - t0) * vehicle.tread / 2
        speeds.append((t1, (speed - turn) / vehicle.wheel_unit,
                       (speed + turn) / vehicle.wheel_unit))
    return speeds


_SERIES_COLOURS = ("#1565c0", "#d11", "#2a9d2a", "#8e24aa")


def _plot(name: str, unit: str, end: float, series: dict[str, list[tuple[float, float]]],
          steps: bool) -> str:
    """One plot over time, 0 to `end` s, a polyline per series (a staircase when the
    value holds between readings) of at most MAX_PLOTTED points."""
    series = {label: points[::_every(points, MAX_PLOTTED)] for label, points in series.items()
              if points}
    width, height, left, right, top, bottom = 640, 110, 44, 10, 16, 18
    values = [v for points in series.values() for _, v in points]
    low, high = (min(values), max(values)) if values else (0.0, 1.0)
    if high - low < 1e-9:
        low, high = low - 1, high + 1
    span = end or 1.0

    def at(t: float, v: float) -> str:
        return (f"{left + (width - left - right) * t / span:.1f},"
                f"{top + (height - top - bottom) * (high - v) / (high - low):.1f}")

    parts = [f'<svg class="plot" data-name="{escape(name)}" viewBox="0 0 {width} {height}" '
             f'width="{width}" height="{height}" xmlns="http://www.w3.org/2000/svg">',
             f'<text x="{left}" y="11" font-size="11" {_TEXT}>{escape(name)} ({unit})</text>',
             f'<text x="{left - 4}" y="{top + 8}" font-size="10" text-anchor="end" {_TEXT}>'
             f'{high:g}</text><text x="{left - 4}" y="{height - bottom}" font-size="10" '
             f'text-anchor="end" {_TEXT}>{low:g}</text>',
             f'<line x1="{left}" y1="{height - bottom}" x2="{width - right}" '
             f'y2="{height - bottom}" stroke="#999"/>',
             f'<text x="{width - right}" y="{height - 4}" font-size="10" text-anchor="end" '
             f'{_TEXT}>{end:.1f} s</text>']
    if not values:
        parts.append(f'<text x="{width / 2}" y="{height / 2}" font-size="11" '
                     f'text-anchor="middle" fill="#777" {_TEXT}>no readings</text>')
    for i, (label, points) in enumerate(series.items()):
        colour = _SERIES_COLOURS[i % len(_SERIES_COLOURS)]
        drawn = []
        for j, (t, v) in enumerate(points):
            if steps and j:
                drawn.append(at(t, points[j - 1][1]))
            drawn.append(at(t, v))
        if steps and points:
            drawn.append(at(end, points[-1][1]))
        parts.append(f'<polyline class="series" points="{" ".join(drawn)}" fill="none" '
                     f'stroke="{colour}" stroke-width="1.2"><title>{escape(label)}</title>'
                     f'</polyline><text x="{left + 250 + 90 * i}" y="11" font-size="11" '
                     f'fill="{colour}" {_TEXT}>{escape(label)}</text>')
    parts.append(f'<line class="cursor" x1="{left}" y1="{top}" x2="{left}" '
                 f'y2="{height - bottom}" stroke="#000" stroke-opacity="0.5" '
                 f'data-left="{left}" data-width="{width - left - right}"/></svg>')
    return "".join(parts)


def _plots(world: World, track: Sequence[tuple[float, Pose]], trace: Sequence[SimEntry],
           end: float) -> str:
    def readings(call: str, index: int) -> list[tuple[float, float]]:
        return [(entry.time, float(entry.result[index])) for entry in trace
                if entry.call == call and entry.result]

    ultrasonic = {f"ULT {sensor}": readings(f"ULT {sensor}", 0) for sensor in SENSORS}
    speeds = wheel_speeds(world, track)
    return "".join([
        _plot("ultrasonic", "cm", end,
              {name: points for name, points in ultrasonic.items() if points}, steps=True),
        _plot("odometry KYO", "cm", end, {"centre": readings("KYO", 0),
                                          "right": readings("KYO", 1),
                                          "left": readings("KYO", 2)}, steps=True),
        _plot("image IMG", "pixels", end, {"area": readings("IMG", 0), "x": readings("IMG", 1),
                                           "y": readings("IMG", 2)}, steps=True),
        _plot("wheel speeds, from the track", "units", end,
              {"left": [(t, left) for t, left, _ in speeds],
               "right": [(t, right) for t, _, right in speeds]}, steps=False),
    ])


def _log(events: Sequence[Event], trace: Sequence[SimEntry],
         describe: Callable[[SimEntry], str]) -> list[list[object]]:
    """The calls (at most REPLAY_CALLS: the first and the last half, and how many were
    left out) and the events, in the order of time: [time, kind, source line, text]."""
    calls: list[list[object]] = [[round(e.time, 3), "call", e.line, describe(e)] for e in trace]
    if len(calls) > REPLAY_CALLS:
        half = REPLAY_CALLS // 2
        left_out = len(calls) - 2 * half
        calls = [*calls[:half], [calls[half][0], "call", None,
                                 f"... {left_out:,} calls left out ..."],
                 *calls[len(calls) - half:]]
    noted: list[list[object]] = [[round(event.time, 3), event.kind, None, event.text]
                                 for event in events]
    # At one time, a line lost or found and a handler taken came before the call that
    # starts then (it happened while the time passed up to it), the end and a fault after.
    order = {"lost": 0, "found": 0, "handler": 0, "call": 1}
    return sorted([*calls, *noted], key=lambda item: (item[0], order.get(str(item[1]), 2)))


def describe_call(entry: SimEntry) -> str:
    """A call as the log shows it without the report's wording: (NAME args) = result."""
    args = " " + ",".join(map(str, entry.args)) if entry.args else ""
    result = f" = {', '.join(map(str, entry.result))}" if entry.result else ""
    return f"({entry.call}{args}){result}"


def html(world: World, track: Sequence[tuple[float, Pose]], events: Sequence[Event],
         trace: Sequence[SimEntry], title: str = "", sightings: Iterable[Sighting] = (),
         describe: Callable[[SimEntry], str] = describe_call,
         verdict: Verdict | None = None) -> str:
    """A page that replays the run: the top view with the vehicle moving and the camera's
    footprint, the log of calls and events with their source lines, the camera's image
    and the plots over time. Everything is inline: it opens offline."""
    seen = list(sightings)
    log = _log(events, trace, describe)
    # The run ends with its last record: calls and events may follow the last motion.
    end = max(track[-1][0] if track else 0.0, float(log[-1][0]) if log else 0.0)  # type: ignore[arg-type]
    data = json.dumps({
        "end": end,
        "track": [[round(t, 3), round(p.x, 2), round(p.y, 2), round(p.heading, 4)]
                  for t, p in track],
        "log": log,
        "frames": _frames(world, seen),
        "sights": [[round(s.time, 3), [[round(x, 1), round(y, 1)] for x, y in
                                       footprint(s.view, world)]]
                   for s in seen[::_every(seen, MAX_SIGHTS)]],
        "size": [world.vehicle.length, world.vehicle.width],
        "image": [world.vehicle.image_width, world.vehicle.image_height],
        "floor": [MARGIN, TOP + world.floor[1]],
    })
    picture = _svg(world, track, events, title, trace, seen, vehicle_mark=True,
                   verdict=verdict)
    plots = _plots(world, track, trace, end)
    return _PAGE.format(title=escape(title), picture=picture, plots=plots,
                        data=data.replace("</", "<\\/"))


_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>
body{{font-family:sans-serif;margin:1em}} svg{{max-width:100%;height:auto}}
#controls{{position:sticky;top:0;background:#fff;padding:.3em 0;z-index:1}}
#panes{{display:flex;flex-wrap:wrap;gap:1em;align-items:flex-start}}
#log{{font-family:monospace;white-space:pre;height:18em;width:46em;overflow:auto;
background:#f3f3f3;border:1px solid #ccc;padding:.3em}}
#log .lost{{color:#e67e00}} #log .found{{color:#2a9d2a}} #log .handler{{color:#8e24aa;
font-weight:bold}} #log .fault{{color:#d11;font-weight:bold}} #log .end{{color:#1565c0}}
#camera{{background:#000;image-rendering:pixelated;width:384px;border:1px solid #ccc}}
.caption{{font-size:small;color:#555}}
</style>
</head><body><h1>{title}</h1>
<p id="controls"><button id="play" title="Space plays and pauses">Play</button>
<label>speed <select id="speed"><option>1</option><option>2</option>
<option selected>5</option><option>10</option><option>20</option><option>50</option>
</select>x</label>
<input id="scrub" type="range" min="0" max="1000" value="0" style="width:40%">
<span id="clock">0.00 s</span> <span id="line"></span></p>
{picture}
<div id="panes">
<div><div class="caption">calls, lost and found lines, handlers (newest last)</div>
<div id="log"></div></div>
<div><div class="caption">camera: the scene's image at the last IMG (noise acts on what
IMG returns, not on this), its window (box) and the centroid IMG returned (cross);
image x counts columns left to right here</div>
<canvas id="camera"></canvas><div id="frame" class="caption">no IMG yet</div></div>
</div>
<div id="plots">{plots}</div>
<script>
"use strict";
const run = {data};
const track = run.track, end = run.end;
const $ = id => document.getElementById(id);
const vehicle = $("vehicle"), sight = $("sight"), scrub = $("scrub"), clock = $("clock");
const log = $("log"), play = $("play"), speed = $("speed"), lineShown = $("line");
const camera = $("camera"), frameText = $("frame"), context = camera.getContext("2d");
camera.width = run.image[0]; camera.height = run.image[1];
const cursors = Array.from(document.querySelectorAll(".plot .cursor"));
let time = 0, playing = false, last = null, shownLog = -1, shownFrame = -2;
// The index of the last item whose time is at or before t (-1: none).
function upTo(items, t, timeOf = item => item[0]) {{
  let lo = -1, hi = items.length - 1;
  while (lo < hi) {{
    const mid = (lo + hi + 1) >> 1;
    if (timeOf(items[mid]) <= t) lo = mid; else hi = mid - 1;
  }}
  return lo;
}}
function screen(x, y) {{
  return (run.floor[0] + x).toFixed(1) + "," + (run.floor[1] - y).toFixed(1);
}}
function drawVehicle() {{
  const i = Math.max(0, upTo(track, time));
  if (!track.length) return;
  const [, x, y, h] = track[i], [l, w] = run.size, c = Math.cos(h), s = Math.sin(h);
  const corners = [[l/2, w/2], [-l/2, w/2], [-l/2, -w/2], [l/2, -w/2], [l/2 + 12, 0]];
  vehicle.setAttribute("points", corners.map(([a, b]) =>
    screen(x + a * c - b * s, y + a * s + b * c)).join(" "));
}}
function drawLog() {{
  const n = upTo(run.log, time);
  if (n === shownLog) return;
  shownLog = n;
  const lines = [];
  for (let i = Math.max(0, n - 199); i <= n; i++) {{
    const [t, kind, line, text] = run.log[i];
    const where = line === null ? "" : "line " + line;
    lines.push('<span class="' + kind + '">' + t.toFixed(2).padStart(8) + "  " +
      where.padEnd(9) + " " + text.replace(/&/g, "&amp;").replace(/</g, "&lt;") + "</span>");
  }}
  log.innerHTML = lines.join("\\n");
  log.scrollTop = log.scrollHeight;
  const call = (() => {{ for (let i = n; i >= 0; i--) if (run.log[i][1] === "call" &&
    run.log[i][2] !== null) return run.log[i]; return null; }})();
  lineShown.textContent = call ? "line " + call[2] + ": " + call[3] : "";
}}
function drawCamera() {{
  const i = upTo(run.frames, time, frame => frame.time), j = upTo(run.sights, time);
  sight.setAttribute("points", j < 0 ? "" : run.sights[j][1].map(([x, y]) =>
    screen(x, y)).join(" "));
  if (i === shownFrame) return;
  shownFrame = i;
  context.fillStyle = "#000"; context.fillRect(0, 0, camera.width, camera.height);
  if (i < 0) {{ frameText.textContent = "no IMG yet"; return; }}
  const {{time: t, left, top, columns, rows, bits, window: win, reading}} = run.frames[i];
  const bytes = atob(bits), pixels = context.createImageData(camera.width, camera.height);
  for (let r = 0; r < rows; r++) for (let c = 0; c < columns; c++) {{
    const k = r * columns + c;
    if (bytes.charCodeAt(k >> 3) & (128 >> (k & 7))) {{
      const p = 4 * ((top + r) * camera.width + left + c);
      pixels.data[p] = pixels.data[p + 1] = pixels.data[p + 2] = 255;
    }}
  }}
  for (let p = 3; p < pixels.data.length; p += 4) pixels.data[p] = 255;
  context.putImageData(pixels, 0, 0);
  context.strokeStyle = "#0c8"; context.lineWidth = 1;
  // Round the window, not on it: its edge pixels are measured too.
  context.strokeRect(win[0] - 0.5, win[1] - 0.5, win[2] - win[0] + 1, win[3] - win[1] + 1);
  const [area, cx, cy] = reading;
  if (area) {{
    context.strokeStyle = "#f33"; context.beginPath();
    context.moveTo(cx - 6, cy + 0.5); context.lineTo(cx + 7, cy + 0.5);
    context.moveTo(cx + 0.5, cy - 6); context.lineTo(cx + 0.5, cy + 7); context.stroke();
  }}
  frameText.textContent = "IMG at " + t.toFixed(2) + " s: area " + area + ", x " + cx +
    ", y " + cy;
}}
function draw() {{
  drawVehicle(); drawLog(); drawCamera();
  clock.textContent = time.toFixed(2) + " s";
  scrub.value = end ? Math.round(1000 * time / end) : 0;
  for (const cursor of cursors) {{
    const x = +cursor.dataset.left + (end ? cursor.dataset.width * time / end : 0);
    cursor.setAttribute("x1", x.toFixed(1)); cursor.setAttribute("x2", x.toFixed(1));
  }}
}}
function frame(now) {{
  if (!playing) return;
  if (last !== null) time = Math.min(end, time + (now - last) / 1000 * speed.value);
  last = now; draw();
  if (time >= end) {{ setPlaying(false); return; }}
  requestAnimationFrame(frame);
}}
function setPlaying(on) {{
  playing = on; play.textContent = on ? "Pause" : "Play";
  if (on) {{ if (time >= end) time = 0; last = null; requestAnimationFrame(frame); }}
}}
play.onclick = () => {{ setPlaying(!playing); play.blur(); }};
document.addEventListener("keydown", event => {{
  const target = event.target;
  if (event.code !== "Space" || target.tagName === "SELECT" ||
      target.tagName === "INPUT" && target.type !== "range") return;
  event.preventDefault(); setPlaying(!playing);
}});
scrub.oninput = () => {{ time = end * scrub.value / 1000; draw(); }};
// A link can open the page at a moment: page.html#t=30 shows the run at 30 s.
const at = /t=([0-9.]+)/.exec(location.hash);
if (at) time = Math.min(end, parseFloat(at[1]));
draw();
</script></body></html>
"""
