// The debugger's marks in the editor: breakpoints in a gutter of their own (a click on
// a line's gutter, or F9 on the line, sets or clears one; a right click gives it a
// condition; they move with the text as it is edited), and the line the run is on,
// highlighted.

import { RangeSet, StateEffect, StateField, EditorState } from "@codemirror/state";
import { Decoration, DecorationSet, EditorView, GutterMarker, gutter, keymap } from "@codemirror/view";

/** A line's breakpoint: its 1-based line, and its condition (`A<0`) if any. */
export interface LineBreakpoint { line: number; condition: string | null }

const toggleBreakpoint = StateEffect.define<number>();  // at a line's start
const setCondition = StateEffect.define<{ at: number; condition: string | null }>();
// A 1-based line, or none, and whether the run faulted there.
const setCurrentLine = StateEffect.define<{ line: number | null; fault: boolean }>();

class BreakpointMarker extends GutterMarker {
  override elementClass = "cm-breakpoint";
  constructor(readonly condition: string | null) {
    super();
  }
  override eq(other: BreakpointMarker) {
    return other.condition === this.condition;
  }
  override toDOM() {
    const dot = document.createElement("span");
    dot.className = this.condition === null ? "cm-breakpoint-dot" : "cm-breakpoint-dot conditional";
    dot.textContent = this.condition === null ? "●" : "◆";
    dot.title = this.condition === null ? "breakpoint (right click: a condition)" : `stops when ${this.condition}`;
    return dot;
  }
}

const breakpointField = StateField.define<RangeSet<BreakpointMarker>>({
  create: () => RangeSet.empty,
  update(set, transaction) {
    set = set.map(transaction.changes);
    for (const effect of transaction.effects) {
      if (effect.is(toggleBreakpoint)) {
        let present = false;
        set.between(effect.value, effect.value, () => { present = true; });
        set = present
          ? set.update({ filter: (from) => from !== effect.value })
          : set.update({ add: [new BreakpointMarker(null).range(effect.value)] });
      } else if (effect.is(setCondition)) {
        const { at, condition } = effect.value;
        set = set.update({ filter: (from) => from !== at, add: [new BreakpointMarker(condition).range(at)] });
      }
    }
    return set;
  },
});

/** The breakpoints, by line. */
function breakpoints(state: EditorState): LineBreakpoint[] {
  const byLine = new Map<number, string | null>();
  for (let cursor = state.field(breakpointField).iter(); cursor.value; cursor.next()) {
    byLine.set(state.doc.lineAt(cursor.from).number, cursor.value.condition);
  }
  return [...byLine].sort(([a], [b]) => a - b).map(([line, condition]) => ({ line, condition }));
}

/** Asks for the condition of the breakpoint on the line starting at `at` (setting one). */
function askCondition(view: EditorView, at: number): void {
  let now: string | null = null;
  view.state.field(breakpointField).between(at, at, (_from, _to, marker) => { now = marker.condition; });
  const line = view.state.doc.lineAt(at).number;
  const answer = prompt(`Stop at line ${line} when (a value compared with 0, as ?V< compares: A<0, `
                        + "U-L>0, d=0; empty: always):", now ?? "");
  if (answer !== null) view.dispatch({ effects: setCondition.of({ at, condition: answer.trim() || null }) });
}

/** Highlights the line the run is on (1-based), or none, or the line it faulted on;
 * `scroll` brings it into view. */
export function showCurrentLine(view: EditorView, line: number | null, scroll: boolean, fault = false): void {
  const valid = line !== null && line >= 1 && line <= view.state.doc.lines ? line : null;
  view.dispatch({
    effects: [setCurrentLine.of({ line: valid, fault }),
              ...(scroll && valid !== null
                ? [EditorView.scrollIntoView(view.state.doc.line(valid).from, { y: "nearest" })] : [])],
  });
}

const currentLineMark = Decoration.line({ class: "cm-run-line" });
const faultLineMark = Decoration.line({ class: "cm-fault-line" });

const currentLineField = StateField.define<DecorationSet>({
  create: () => Decoration.none,
  update(marks, transaction) {
    marks = marks.map(transaction.changes);
    for (const effect of transaction.effects) {
      if (effect.is(setCurrentLine)) {
        const { line, fault } = effect.value;
        marks = line === null ? Decoration.none : Decoration.set([
          (fault ? faultLineMark : currentLineMark).range(transaction.state.doc.line(line).from)]);
      }
    }
    return marks;
  },
  provide: (field) => EditorView.decorations.from(field),
});

/** The gutter and the highlight; `changed` hears every change of the breakpoints. */
export function debuggerMarks(changed: (breakpoints: LineBreakpoint[]) => void) {
  let last = "";
  return [
    breakpointField,
    currentLineField,
    gutter({
      class: "cm-breakpoint-gutter",
      markers: (view) => view.state.field(breakpointField),
      domEventHandlers: {
        mousedown(view, line, event) {
          if ((event as MouseEvent).button !== 0) return false;
          view.dispatch({ effects: toggleBreakpoint.of(line.from) });
          return true;
        },
        contextmenu(view, line, event) {
          event.preventDefault();
          askCondition(view, line.from);
          return true;
        },
      },
    }),
    keymap.of([{
      key: "F9",
      run: (view) => {
        view.dispatch({ effects: toggleBreakpoint.of(view.state.doc.lineAt(view.state.selection.main.head).from) });
        return true;
      },
    }]),
    EditorView.updateListener.of((update) => {
      const now = breakpoints(update.state);
      const key = JSON.stringify(now);
      if (key !== last) {
        last = key;
        changed(now);
      }
    }),
  ];
}
