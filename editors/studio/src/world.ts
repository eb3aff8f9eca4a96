// The world's top view: the floor and what is on it, from the geometry the server sends
// (spec/studio.md, "Geometry"), the vehicle at each frame of a run and the events marked
// where they happened. Frames can come faster than the screen shows them: the latest is
// drawn at the next animation frame, and the others only extend the path.

import type { Frame, Geometry, Point, Pose, RunEvent } from "./protocol";

const SVG = "http://www.w3.org/2000/svg";
const PATH_POINTS = 4000;  // past this, the path keeps every other point
const EVENTS_SHOWN = 500;  // the newest events marked, at most

function element<K extends keyof SVGElementTagNameMap>(name: K, attributes: Record<string, string>,
                                                       title?: string): SVGElementTagNameMap[K] {
  const made = document.createElementNS(SVG, name);
  for (const [key, value] of Object.entries(attributes)) made.setAttribute(key, value);
  if (title) {
    const tip = document.createElementNS(SVG, "title");
    tip.textContent = title;
    made.append(tip);
  }
  return made;
}

// World y goes up, the screen's down: every point is drawn with y negated.
const screen = (list: readonly Point[]): string => list.map(([x, y]) => `${x},${-y}`).join(" ");

export class WorldView {
  private readonly layer: SVGGElement;
  private readonly marks: SVGGElement;
  private readonly vehicle: SVGPolygonElement;
  private readonly heading: SVGLineElement;
  private readonly path: SVGPolylineElement;
  private pathPoints: Point[] = [];
  private latest: Frame | null = null;
  private scheduled = false;
  private geometry: Geometry | null = null;
  private framesDrawn = 0;

  constructor(readonly svg: SVGSVGElement, private readonly clock: HTMLElement) {
    this.layer = element("g", {});
    this.marks = element("g", {});
    this.path = element("polyline", { class: "path", points: "" });
    this.vehicle = element("polygon", { class: "vehicle", id: "vehicle", points: "" });
    this.heading = element("line", { class: "heading" });
    svg.replaceChildren(this.layer, this.path, this.marks, this.vehicle, this.heading);
  }

  /** Draws a world, and the vehicle at its start. */
  show(geometry: Geometry): void {
    this.geometry = geometry;
    const [width, depth] = geometry.floor;
    const margin = 10;
    this.svg.setAttribute("viewBox", `${-margin} ${-depth - margin} ${width + 2 * margin} ${depth + 2 * margin}`);
    const parts: SVGElement[] = [
      element("rect", { x: "0", y: String(-depth), width: String(width), height: String(depth),
                        class: "floor" }),
    ];
    const polygon = (kind: string, points: Point[], title: string) =>
      parts.push(element("polygon", { points: screen(points), class: kind }, title));
    for (const area of geometry.goal?.reach ?? []) polygon("goal", area.points, `reach ${area.name}`);
    for (const area of geometry.goal?.avoid ?? []) polygon("avoid", area.points, `avoid ${area.name}`);
    if (geometry.goal?.end) polygon("goal", geometry.goal.end.points, `end in ${geometry.goal.end.name}`);
    for (const line of geometry.lines) {
      parts.push(element("polyline", { points: screen(line.points), class: "guide",
                                       "stroke-width": String(line.width) }, `line ${line.name}`));
    }
    for (const mark of geometry.marks) polygon("mark", mark.points, `mark ${mark.name}`);
    for (const wall of geometry.walls) polygon("wall", wall.points, `wall ${wall.name}`);
    for (const obstacle of geometry.obstacles) polygon("obstacle", obstacle.points, `obstacle ${obstacle.name}`);
    for (const stand of geometry.stands) {
      polygon("stand", stand.corners, `stand ${stand.name}`);
      const [mx, my] = stand.marker;
      parts.push(element("circle", { cx: String(mx), cy: String(-my), r: "3", class: "marker" },
                         `marker of ${stand.name}`));
    }
    this.layer.replaceChildren(...parts);
    this.reset();
  }

  /** The vehicle back at its start; the path and the events cleared. */
  reset(): void {
    this.pathPoints = [];
    this.latest = null;
    this.marks.replaceChildren();
    this.path.setAttribute("points", "");
    if (this.geometry) this.draw(this.geometry.start, null);
  }

  /** A frame of the run: drawn at the next animation frame, unless a newer one comes first. */
  frame(frame: Frame): void {
    const [x, y] = frame.pose;
    this.pathPoints.push([x, y]);
    if (this.pathPoints.length > PATH_POINTS) this.pathPoints = this.pathPoints.filter((_, i) => i % 2 === 0);
    this.latest = frame;
    if (this.scheduled) return;
    this.scheduled = true;
    requestAnimationFrame(() => {
      this.scheduled = false;
      if (this.latest) this.draw(this.latest.pose, this.latest.time);
      this.path.setAttribute("points", screen(this.pathPoints));
    });
  }

  /** Marks where lost lines, handler jumps, faults and the end happened. */
  events(events: readonly RunEvent[]): void {
    for (const event of events) {
      const [x, y] = event.pose;
      this.marks.append(element("circle", { cx: String(x), cy: String(-y), r: "5", class: `event ${event.kind}` },
                                `${event.time.toFixed(2)} s: ${event.text}`));
    }
    while (this.marks.childElementCount > EVENTS_SHOWN) this.marks.firstElementChild?.remove();
  }

  private draw([x, y, degrees]: Pose, time: number | null): void {
    const { length, width } = this.geometry?.vehicle ?? { length: 0, width: 0 };
    const heading = degrees * Math.PI / 180;
    const cos = Math.cos(heading), sin = Math.sin(heading);
    const corners = [[1, 1], [1, -1], [-1, -1], [-1, 1]].map(([along, across]): Point => {
      const a = along * length / 2, b = across * width / 2;
      return [x + a * cos - b * sin, y + a * sin + b * cos];
    });
    this.vehicle.setAttribute("points", screen(corners));
    const nose = length / 2 + 12;
    this.heading.setAttribute("x1", String(x));
    this.heading.setAttribute("y1", String(-y));
    this.heading.setAttribute("x2", String(x + nose * cos));
    this.heading.setAttribute("y2", String(-(y + nose * sin)));
    this.clock.textContent = time === null ? "" : `${time.toFixed(2)} s`;
    if (time !== null) {
      this.framesDrawn += 1;
      this.svg.dataset.framesDrawn = String(this.framesDrawn);
    }
  }
}
