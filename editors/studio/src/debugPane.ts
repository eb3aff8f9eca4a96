// The debugger's pane: why the run stopped (or how it ended), the variables (those the
// last command changed marked), the device's state, and the trace of calls with the
// run's events (lost lines and handler jumps marked).

import type { Ended, Progress, Stopped } from "./protocol";

const TRACE_SHOWN = 2000;  // the newest lines of the trace kept on the page

function cell(tag: string, className: string, text: string): HTMLElement {
  const made = document.createElement(tag);
  if (className) made.className = className;
  made.textContent = text;
  return made;
}

const at = (time: number, line: number | null): string =>
  `${time.toFixed(2).padStart(7)} s ${line === null ? "   " : `:${line}`.padEnd(4)}`;

export class DebugPane {
  private shown: Record<string, number> = {};

  constructor(private readonly stop: HTMLElement, private readonly variables: HTMLElement,
              private readonly device: HTMLElement, private readonly trace: HTMLOListElement,
              private readonly reserved: ReadonlySet<string>) {}

  stopped(stopped: Stopped): void {
    this.progress(stopped);
    this.say(stopped.line === null ? stopped.text || stopped.reason
      : `${stopped.reason} at line ${stopped.line}${stopped.text ? `: ${stopped.text}` : ""}`, stopped.reason);
    this.showVariables(stopped.variables, new Set(stopped.changed));
    const list = document.createElement("dl");
    for (const [key, value] of Object.entries(stopped.device)) {
      list.append(cell("dt", "", key), cell("dd", "", typeof value === "string" ? value : JSON.stringify(value)));
    }
    this.device.replaceChildren(list);
  }

  ended(ended: Ended): void {
    this.progress(ended);
    const status = ended.status;
    const goal = ended.goal?.met ? "; goal met" : "";  // a missed goal is in the message
    this.say(status === null ? "stopped"
      : `ended: ${status.message}${status.line === null ? "" : ` (line ${status.line})`}${goal}; `
        + `${ended.instructions} instructions, ${(ended.deviceTime / 1000).toFixed(2)} s`,
             status === null ? "stopped" : status.code === "ok" ? "end"
               : status.code === "goal-missed" ? "goal-missed" : "fault");
    // Changed since the last stop shown, or since the start, where every variable is 0.
    const changed = new Set(Object.keys(ended.variables).filter(
      (name) => ended.variables[name] !== (this.shown[name] ?? 0)));
    this.showVariables(ended.variables, changed);
  }

  /** The trace entries and events of a notification, added to the trace. */
  progress(progress: Progress): void {
    const items = [
      ...progress.trace.map((entry) => ({
        time: entry.time,
        item: cell("li", entry.call === "LINE LOST" ? "lost" : "call", `${at(entry.time, entry.line)} ${entry.text}`),
      })),
      ...progress.events.map((event) => ({
        time: event.time, item: cell("li", event.kind, `${at(event.time, null)} ${event.text}`),
      })),
    ].sort((a, b) => a.time - b.time);
    if (items.length === 0) return;
    this.trace.append(...items.map(({ item }) => item));
    while (this.trace.childElementCount > TRACE_SHOWN) this.trace.firstElementChild?.remove();
    this.trace.scrollTop = this.trace.scrollHeight;
  }

  clear(): void {
    this.say("", "");
    this.shown = {};
    this.variables.replaceChildren();
    this.device.replaceChildren();
    this.trace.replaceChildren();
  }

  private say(text: string, reason: string): void {
    this.stop.textContent = text;
    this.stop.className = reason === "fault" ? "fault" : "";
    this.stop.dataset.reason = reason;
  }

  private showVariables(variables: Record<string, number>, changed: ReadonlySet<string>): void {
    this.shown = variables;
    this.variables.replaceChildren(...Object.entries(variables).map(([name, value]) => {
      const row = cell("div", "variable", "");
      row.classList.toggle("changed", changed.has(name));
      row.classList.toggle("reserved", this.reserved.has(name));
      row.dataset.name = name;
      row.title = changed.has(name) ? `${name}: changed by the last command` : name;
      row.append(cell("span", "name", name), cell("span", "value", String(value)));
      return row;
    }));
  }
}
