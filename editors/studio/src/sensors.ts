// The sensor plots over the run's time, as the replay page of `rl1c sim --html` draws
// them: for each call that reads something, a series for each value it returns (named as
// the palette names them, IMG's area, x, y and angle; a reading of one value by its call),
// from the trace the server sends; and, on a world, the wheels' speeds from the frames.
// The plots share one time axis, from 0 to the latest time told.

import type { Frame, TraceEntry } from "./protocol";

const SVG = "http://www.w3.org/2000/svg";
const POINTS = 2000;  // a series keeps every other point past this
const WIDTH = 300, HEIGHT = 70;
export const WHEELS = "wheel speeds";

interface Series { name: string; points: [number, number][]; line: SVGPolylineElement }
/** `steps`: a reading holds its value until the next; the wheels' speeds change between frames. */
interface Plot { series: Series[]; steps: boolean; label: HTMLElement }

export class SensorPlots {
  private readonly plots = new Map<string, Plot>();
  private end = 0;
  private scheduled = false;

  /** `readings`: the names of the values of each call that reads several (the palette's). */
  constructor(private readonly pane: HTMLElement, private readonly holder: HTMLElement,
              private readonly readings: ReadonlyMap<string, readonly string[]>) {}

  clear(): void {
    this.plots.clear();
    this.end = 0;
    this.holder.replaceChildren();
    this.pane.hidden = true;
  }

  add(entries: readonly TraceEntry[], frame: Frame | null): void {
    for (const entry of entries) {
      if (!entry.result?.length) continue;
      const names = this.readings.get(entry.call.split(" ")[0]);
      const plot = this.plot(entry.call, names?.length ? names : [entry.call], true);
      plot.series.forEach((series, i) => add(series, entry.time, entry.result![i]));
      this.end = Math.max(this.end, entry.time);
    }
    if (frame) {
      const plot = this.plot(WHEELS, ["left", "right"], false);
      plot.series.forEach((series, i) => add(series, frame.time, frame.wheels[i]));
      this.end = Math.max(this.end, frame.time);
    }
    if (!this.scheduled && (entries.length || frame)) {
      this.scheduled = true;
      requestAnimationFrame(() => { this.scheduled = false; this.draw(); });
    }
  }

  private plot(name: string, values: readonly string[], steps: boolean): Plot {
    const known = this.plots.get(name);
    if (known) return known;
    const svg = document.createElementNS(SVG, "svg");
    svg.setAttribute("class", "plot");
    svg.setAttribute("viewBox", `0 0 ${WIDTH} ${HEIGHT}`);
    svg.setAttribute("preserveAspectRatio", "none");
    svg.dataset.name = name;
    const series = values.map((value, i) => {
      const line = document.createElementNS(SVG, "polyline");
      line.setAttribute("class", `series series-${i}`);
      line.setAttribute("vector-effect", "non-scaling-stroke");
      line.dataset.name = value;
      svg.append(line);
      return { name: value, points: [], line };
    });
    const label = document.createElement("div");
    label.className = "plot-label";
    this.holder.append(label, svg);
    const plot = { series, steps, label };
    this.plots.set(name, plot);
    return plot;
  }

  private draw(): void {
    this.pane.hidden = this.plots.size === 0;
    const span = this.end || 1;
    for (const [name, { series, steps, label }] of this.plots) {
      const values = series.flatMap(({ points }) => points.map(([, value]) => value));
      const low = Math.min(...values), high = Math.max(...values, low + 1);
      const at = (time: number, value: number): string =>
        `${(time / span * WIDTH).toFixed(1)},${(HEIGHT - 4 - (value - low) / (high - low) * (HEIGHT - 16)).toFixed(1)}`;
      for (const { points, line } of series) {
        const drawn = points.flatMap(([time, value], i) =>
          steps && i ? [at(time, points[i - 1][1]), at(time, value)] : [at(time, value)]);
        if (steps && points.length) drawn.push(at(this.end, points[points.length - 1][1]));
        line.setAttribute("points", drawn.join(" "));
      }
      label.replaceChildren(`${name}: `, ...series.flatMap(({ name: value, points }, i) => {
        const shown = document.createElement("span");
        shown.className = `series-${i}`;
        shown.textContent = `${series.length > 1 ? `${value} ` : ""}${points[points.length - 1]?.[1] ?? ""}`;
        return i ? [", ", shown] : [shown];
      }), ` (${low}..${high})`);
    }
  }
}

/** A point of a series; a value that holds as it was adds nothing (the stops' frames). */
function add(series: Series, time: number, value: number): void {
  const last = series.points[series.points.length - 1];
  if (last && last[0] === time && last[1] === value) return;
  series.points.push([time, value]);
  if (series.points.length > POINTS) series.points = series.points.filter((_, i) => i % 2 === 0);
}
