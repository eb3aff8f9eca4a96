"""Pictures of a run: an SVG top view as in the paper's Fig. 9 (the floor and what is on
it, the path, the vehicle's outline at intervals, the events), and a self-contained HTML
page that replays the run offline (play, pause, scrub)."""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from html import escape

from .geometry import Point, rectangle
from .motion import Pose
from .simulator import Event
from .world import World

OUTLINE_EVERY = 40.0  # cm of travel (or, turning, its equivalent) between two outlines
REPLAY_CALLS = 10_000
"""The calls a replay page lists, at most: the first and the last half of them, and how
many were left out between (a loop of calls can make millions, 16 bytes each)."""
_COLOURS = {"lost": "#e67e00", "handler": "#8e24aa", "found": "#2a9d2a", "fault": "#d11",
            "end": "#1565c0"}


def _points(points: Sequence[Point]) -> str:
    return " ".join(f"{x:.1f},{y:.1f}" for x, y in points)


def _scene(world: World) -> list[str]:
    """The floor and its features, in world coordinates (the caller flips y)."""
    width, depth = world.floor
    parts = [f'<rect x="0" y="0" width="{width:g}" height="{depth:g}" fill="#f7f5ef" '
             'stroke="#888" stroke-width="2"/>']
    for line in world.lines:
        parts.append(f'<polyline points="{_points(line.points)}" fill="none" stroke="#222" '
                     f'stroke-width="{line.width:g}"><title>{escape(line.name)}</title></polyline>')
    for mark in world.marks:
        parts.append(f'<polygon points="{_points(mark.points)}" fill="#444">'
                     f'<title>{escape(mark.name)}</title></polygon>')
    for block in world.blocks:
        parts.append(f'<polygon points="{_points(block.points)}" fill="#9aa" stroke="#566">'
                     f'<title>{escape(block.name)}</title></polygon>')
    for stand in world.stands:
        mx, my = stand.marker()
        parts.append(f'<polygon points="{_points(stand.corners())}" fill="#c9b38a" '
                     f'stroke="#7a6236"><title>{escape(stand.name)}</title></polygon>'
                     f'<circle cx="{mx:.1f}" cy="{my:.1f}" r="3" fill="#f33"/>')
    return parts


def _outline(world: World, pose: Pose) -> str:
    vehicle = world.vehicle
    corners = rectangle(pose.x, pose.y, vehicle.length, vehicle.width, pose.heading)
    nose = (pose.x + vehicle.length / 2 * math.cos(pose.heading),
            pose.y + vehicle.length / 2 * math.sin(pose.heading))
    return _points([*corners, nose, corners[3]])


def svg(world: World, track: Sequence[tuple[float, Pose]], events: Sequence[Event],
        title: str = "") -> str:
    """The top view of a run."""
    width, depth = world.floor
    margin = 20.0
    body = _scene(world)
    body.append(f'<polyline points="{_points([(p.x, p.y) for _, p in track])}" fill="none" '
                'stroke="#1565c0" stroke-width="1.5" stroke-dasharray="4 3"/>')
    drawn: Pose | None = None
    for _, pose in track:
        # The outline is drawn again once the vehicle has moved on: a halt draws none.
        if drawn is None or math.hypot(pose.x - drawn.x, pose.y - drawn.y) + abs(
                pose.heading - drawn.heading) * world.vehicle.length / 2 >= OUTLINE_EVERY:
            body.append(f'<polygon points="{_outline(world, pose)}" fill="none" '
                        'stroke="#1565c0" stroke-opacity="0.45"/>')
            drawn = pose
    if track:
        body.append(f'<polygon points="{_outline(world, track[-1][1])}" fill="#1565c0" '
                    'fill-opacity="0.25" stroke="#1565c0" stroke-width="2"/>')
    for event in events:
        colour = _COLOURS.get(event.kind, "#555")
        body.append(f'<circle cx="{event.pose.x:.1f}" cy="{event.pose.y:.1f}" r="7" '
                    f'fill="{colour}" fill-opacity="0.8"><title>{event.time:.2f} s: '
                    f'{escape(event.text)}</title></circle>')
    legend = [f'<text x="{margin}" y="16" font-size="14" font-family="sans-serif">'
              f'{escape(title)}</text>']
    for i, event in enumerate(events[:12]):
        legend.append(f'<text x="{margin}" y="{depth + 2 * margin + 16 * (i + 1):.0f}" '
                      f'font-size="12" font-family="sans-serif" '
                      f'fill="{_COLOURS.get(event.kind, "#555")}">{event.time:7.2f} s  '
                      f'{escape(event.text)}</text>')
    total_height = depth + 2 * margin + 16 * (min(len(events), 12) + 1)
    # World y grows up the plan; SVG's grows down: flip the scene, not the text.
    return (f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {width + 2 * margin:g} '
            f'{total_height:g}" width="{width + 2 * margin:g}" height="{total_height:g}">'
            + "".join(legend)
            + f'<g transform="translate({margin},{depth + margin + 10}) scale(1,-1)">'
            + "".join(body) + "</g></svg>\n")


def html(world: World, track: Sequence[tuple[float, Pose]], events: Sequence[Event],
         calls: Sequence[tuple[float, str]], title: str = "") -> str:
    """A page that replays the run: the top view, the vehicle moving along its track,
    the calls as they are made. Everything is inline: it opens offline."""
    if len(calls) > REPLAY_CALLS:
        half = REPLAY_CALLS // 2
        left_out = len(calls) - 2 * half
        calls = [*calls[:half], (calls[half][0], f"... {left_out:,} calls left out ..."),
                 *calls[len(calls) - half:]]
    data = json.dumps({
        "track": [[round(t, 3), round(p.x, 2), round(p.y, 2), round(p.heading, 4)]
                  for t, p in track],
        "calls": [[round(t, 3), text] for t, text in calls],
        "size": [world.vehicle.length, world.vehicle.width],
    })
    picture = svg(world, track, events, title).replace(
        "</g></svg>", '<polygon id="vehicle" fill="#1565c0" fill-opacity="0.6"/></g></svg>')
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{escape(title)}</title>
<style>body{{font-family:sans-serif;margin:1em}} svg{{max-width:100%;height:auto}}
#log{{font-family:monospace;white-space:pre;height:8em;overflow:auto;background:#eee}}</style>
</head><body><h1>{escape(title)}</h1>
<p><button id="play">Play</button> <input id="scrub" type="range" min="0" max="1000" value="0"
style="width:60%"> <span id="clock">0.00 s</span></p>
{picture}<div id="log"></div>
<script>
const run = {data};
const track = run.track, end = track.length ? track[track.length - 1][0] : 0;
const vehicle = document.getElementById("vehicle"), scrub = document.getElementById("scrub");
const clock = document.getElementById("clock"), log = document.getElementById("log");
const play = document.getElementById("play");
let time = 0, playing = false, last = null;
function pose(t) {{
  let lo = 0, hi = track.length - 1;
  while (lo < hi) {{
    const mid = (lo + hi + 1) >> 1;
    if (track[mid][0] <= t) lo = mid; else hi = mid - 1;
  }}
  return track[lo];
}}
function draw() {{
  const [t, x, y, h] = pose(time), [l, w] = run.size, c = Math.cos(h), s = Math.sin(h);
  const corners = [[l/2, w/2], [-l/2, w/2], [-l/2, -w/2], [l/2, -w/2], [l/2 + 10, 0]];
  vehicle.setAttribute("points", corners.map(([a, b]) => {{
    return (x + a * c - b * s).toFixed(1) + "," + (y + a * s + b * c).toFixed(1); }}).join(" "));
  clock.textContent = time.toFixed(2) + " s";
  scrub.value = end ? Math.round(1000 * time / end) : 0;
  log.textContent = run.calls.filter(c => c[0] <= time).slice(-8)
    .map(c => c[0].toFixed(2).padStart(8) + "  " + c[1]).join("\\n");
}}
function frame(now) {{
  if (!playing) return;
  if (last !== null) time = Math.min(end, time + (now - last) / 1000 * 5);
  last = now; draw();
  if (time >= end) {{ playing = false; play.textContent = "Play"; return; }}
  requestAnimationFrame(frame);
}}
play.onclick = () => {{ playing = !playing; play.textContent = playing ? "Pause" : "Play";
  if (playing) {{ if (time >= end) time = 0; last = null; requestAnimationFrame(frame); }} }};
scrub.oninput = () => {{ time = end * scrub.value / 1000; draw(); }};
// A link can open the page at a moment: page.html#t=30 shows the run at 30 s.
const at = /t=([0-9.]+)/.exec(location.hash);
if (at) time = Math.min(end, parseFloat(at[1]));
draw();
</script></body></html>
"""
