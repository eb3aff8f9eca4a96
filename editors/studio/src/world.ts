// The world's top view: the floor and what is on it, from the geometry the server sends,
// and the vehicle drawn at each frame the server sends while the program runs. Frames
// can come faster than the screen shows them: the latest is drawn at the next
// animation frame, and the others only extend the path.

import type { Frame, Geometry, Point } from "./protocol";

const SVG = "http://www.w3.org/2000/svg";
const PATH_POINTS = 4000;  // past this, the path keeps every other point

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

const points = (list: readonly Point[]): string => list.map(([x, y]) => `${x},${y}`).join(" ");

export class WorldView {
  private readonly layer: SVGGElement;
  private readonly vehicle: SVGPolygonElement;
  private readonly heading: SVGLineElement;
  private readonly path: SVGPolylineElement;
  private pathPoints: Point[] = [];
  private latest: Frame | null = null;
  private scheduled = false;
  private geometry: Geometry | null = null;
  /** Frames drawn, and the time of the last (for the benchmark and the tests). */
  framesDrawn = 0;

  constructor(readonly svg: SVGSVGElement, private readonly clock: HTMLElement) {
    this.layer = element("g", {});
    this.path = element("polyline", { class: "path", points: "" });
    this.vehicle = element("polygon", { class: "vehicle", id: "vehicle", points: "" });
    this.heading = element("line", { class: "heading" });
    svg.replaceChildren(this.layer, this.path, this.vehicle, this.heading);
  }

  /** Draws a world; the vehicle at its start. */
  show(geometry: Geometry): void {
    this.geometry = geometry;
    const [width, depth] = geometry.floor;
    const margin = 10;
    this.svg.setAttribute("viewBox", `${-margin} ${-depth - margin} ${width + 2 * margin} ${depth + 2 * margin}`);
    // World y goes up, the screen's down: everything is drawn with y negated.
    const flip = (list: readonly Point[]): Point[] => list.map(([x, y]) => [x, -y]);
    const parts: SVGElement[] = [
      element("rect", { x: "0", y: String(-depth), width: String(width), height: String(depth),
                        fill: "#f7f5ef", stroke: "#888", "stroke-width": "2" }),
    ];
    for (const line of geometry.lines) {
      parts.push(element("polyline", { points: points(flip(line.points)), fill: "none", stroke: "#222",
                                       "stroke-width": String(line.width) }, `line ${line.name}`));
    }
    for (const mark of geometry.marks) {
      parts.push(element("polygon", { points: points(flip(mark.points)), fill: "#444" }, `mark ${mark.name}`));
    }
    for (const block of geometry.blocks) {
      parts.push(element("polygon", { points: points(flip(block.points)), fill: "#9aa", stroke: "#566" },
                         block.name));
    }
    for (const stand of geometry.stands) {
      parts.push(element("polygon", { points: points(flip(stand.corners)), fill: "#c9b38a", stroke: "#7a6236" },
                         `stand ${stand.name}`));
      const [mx, my] = stand.marker;
      parts.push(element("circle", { cx: String(mx), cy: String(-my), r: "3", fill: "#f33" },
                         `marker of ${stand.name}`));
    }
    this.layer.replaceChildren(...parts);
    this.reset();
  }

  /** The vehicle back at its start, the path cleared. */
  reset(): void {
    this.pathPoints = [];
    this.latest = null;
    if (this.geometry) this.draw(this.geometry.start);
    this.path.setAttribute("points", "");
  }

  /** A frame from the server: drawn at the next animation frame, unless a newer one comes first. */
  frame(frame: Frame): void {
    this.pathPoints.push([frame.x, -frame.y]);
    if (this.pathPoints.length > PATH_POINTS) this.pathPoints = this.pathPoints.filter((_, i) => i % 2 === 0);
    this.latest = frame;
    if (!this.scheduled) {
      this.scheduled = true;
      requestAnimationFrame(() => {
        this.scheduled = false;
        if (this.latest) this.draw(this.latest);
        this.path.setAttribute("points", points(this.pathPoints));
      });
    }
  }

  private draw(frame: Frame): void {
    const outline = this.geometry?.vehicle.outline ?? [];
    const cos = Math.cos(frame.heading), sin = Math.sin(frame.heading);
    const placed = outline.map(([x, y]): Point => [frame.x + x * cos - y * sin, -(frame.y + x * sin + y * cos)]);
    this.vehicle.setAttribute("points", points(placed));
    const nose = Math.max(0, ...outline.map(([x]) => x));
    this.heading.setAttribute("x1", String(frame.x));
    this.heading.setAttribute("y1", String(-frame.y));
    this.heading.setAttribute("x2", String(frame.x + nose * cos));
    this.heading.setAttribute("y2", String(-(frame.y + nose * sin)));
    this.clock.textContent = `${frame.time.toFixed(2)} s`;
    this.framesDrawn += 1;
    this.svg.dataset.framesDrawn = String(this.framesDrawn);
  }
}
