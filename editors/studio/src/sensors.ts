// The sensors as the run reads them: a plot over time of each call that reads a value
// (its first result: an ultrasonic distance, an image's area, the distance counters),
// from the trace the server sends, and the camera's pane: where it looks (the frame's
// pan, tilt and scene) and what the last (IMG) reported, its centroid and area drawn on
// the image's 256 x 240 pixels. The protocol carries the numbers, not the image.

import type { Frame, TraceEntry } from "./protocol";

const SVG = "http://www.w3.org/2000/svg";
const POINTS = 2000;  // a series keeps every other point past this
const WIDTH = 300, HEIGHT = 70;

interface Series { points: [number, number][]; line: SVGPolylineElement; label: HTMLElement }

export class Sensors {
  private readonly series = new Map<string, Series>();
  private scheduled = false;
  private lastImage: TraceEntry | null = null;
  private lastFrame: Frame | null = null;

  constructor(private readonly plots: HTMLElement, private readonly camera: HTMLCanvasElement,
              private readonly caption: HTMLElement) {}

  clear(): void {
    this.series.clear();
    this.plots.replaceChildren();
    this.lastImage = null;
    this.lastFrame = null;
    this.hidePanes();
  }

  add(entries: readonly TraceEntry[], frame: Frame | null): void {
    if (frame) this.lastFrame = frame;
    for (const entry of entries) {
      if (!entry.result?.length) continue;
      const name = entry.text.split(" = ")[0];
      if (entry.call === "IMG") this.lastImage = entry;
      const series = this.series.get(name) ?? this.newSeries(name);
      series.points.push([entry.time, entry.result[0]]);
      if (series.points.length > POINTS) series.points = series.points.filter((_, i) => i % 2 === 0);
    }
    if (!this.scheduled && (entries.length || frame)) {
      this.scheduled = true;
      requestAnimationFrame(() => { this.scheduled = false; this.draw(); });
    }
  }

  private newSeries(name: string): Series {
    const svg = document.createElementNS(SVG, "svg");
    svg.setAttribute("class", "plot");
    svg.setAttribute("viewBox", `0 0 ${WIDTH} ${HEIGHT}`);
    svg.setAttribute("preserveAspectRatio", "none");
    svg.dataset.name = name;
    const line = document.createElementNS(SVG, "polyline");
    line.setAttribute("class", "series");
    line.setAttribute("vector-effect", "non-scaling-stroke");
    svg.append(line);
    const label = document.createElement("div");
    label.className = "plot-label";
    this.plots.append(label, svg);
    const series = { points: [], line, label };
    this.series.set(name, series);
    return series;
  }

  private hidePanes(): void {
    this.plots.closest<HTMLElement>(".pane")!.hidden = this.series.size === 0;
    this.camera.closest<HTMLElement>(".pane")!.hidden = this.lastFrame === null && this.lastImage === null;
  }

  private draw(): void {
    this.hidePanes();
    for (const [name, { points, line, label }] of this.series) {
      const times = points.map(([time]) => time), values = points.map(([, value]) => value);
      const t0 = Math.min(...times), t1 = Math.max(...times, t0 + 1e-9);
      const low = Math.min(...values), high = Math.max(...values, low + 1);
      line.setAttribute("points", points.map(([time, value]) =>
        `${((time - t0) / (t1 - t0) * WIDTH).toFixed(1)},${(HEIGHT - 4 - (value - low) / (high - low) * (HEIGHT - 16)).toFixed(1)}`).join(" "));
      label.textContent = `${name}: ${values[values.length - 1]} (${low}..${high})`;
    }
    this.drawCamera();
  }

  private drawCamera(): void {
    const context = this.camera.getContext("2d");
    if (!context) return;
    const { width, height } = this.camera;
    context.fillStyle = "#000";
    context.fillRect(0, 0, width, height);
    const looks = this.lastFrame
      ? `pan ${this.lastFrame.pan}, tilted ${this.lastFrame.tilt}, scene ${this.lastFrame.scene}` : "";
    const image = this.lastImage?.result;
    if (this.lastImage && image) {
      const [area, x, y] = image;
      if (area > 0) {
        context.fillStyle = "rgba(255, 255, 255, 0.35)";
        context.beginPath();
        context.arc(x, y, Math.sqrt(area / Math.PI), 0, 2 * Math.PI);
        context.fill();
        context.strokeStyle = "#f33";
        context.beginPath();
        context.moveTo(x - 8, y); context.lineTo(x + 8, y);
        context.moveTo(x, y - 8); context.lineTo(x, y + 8);
        context.stroke();
      }
      this.caption.textContent = `${looks}; (IMG) at ${this.lastImage.time.toFixed(2)} s: area ${area}, `
        + `x ${x}, y ${y} (the circle has its area)`;
    } else {
      this.caption.textContent = looks ? `${looks}; no (IMG) yet` : "";
    }
  }
}
