// The debugger's pane: why the run stopped, the variables (those the last command
// changed marked), the device's state and the trace (lost lines and handler jumps
// marked).

import type { Stopped, TraceLine } from "./protocol";

function cell(tag: string, className: string, text: string): HTMLElement {
  const made = document.createElement(tag);
  if (className) made.className = className;
  made.textContent = text;
  return made;
}

export class DebugPane {
  constructor(private readonly stop: HTMLElement, private readonly variables: HTMLElement,
              private readonly device: HTMLElement, private readonly trace: HTMLOListElement,
              private readonly reserved: ReadonlySet<string>) {}

  show(stopped: Stopped): void {
    this.stop.textContent = stopped.line === null ? stopped.text || stopped.reason
      : `line ${stopped.line}: ${stopped.text || stopped.reason}`;
    this.stop.className = stopped.reason === "fault" ? "fault" : "";
    this.stop.dataset.reason = stopped.reason;
    const changed = new Set(stopped.changed);
    this.variables.replaceChildren(...Object.entries(stopped.variables).map(([name, value]) => {
      const row = cell("div", "variable", "");
      row.classList.toggle("changed", changed.has(name));
      row.classList.toggle("reserved", this.reserved.has(name));
      row.dataset.name = name;
      row.append(cell("span", "name", name), cell("span", "value", String(value)));
      return row;
    }));
    const list = document.createElement("dl");
    for (const [key, value] of Object.entries(stopped.device)) {
      list.append(cell("dt", "", key), cell("dd", "", typeof value === "string" ? value : JSON.stringify(value)));
    }
    this.device.replaceChildren(list);
    this.showTrace(stopped.trace);
  }

  showTrace(lines: readonly TraceLine[]): void {
    this.trace.replaceChildren(...lines.map((line) => cell("li", line.kind, line.text)));
    this.trace.scrollTop = this.trace.scrollHeight;
  }

  clear(): void {
    this.stop.textContent = "";
    this.variables.replaceChildren();
    this.device.replaceChildren();
    this.trace.replaceChildren();
  }
}
