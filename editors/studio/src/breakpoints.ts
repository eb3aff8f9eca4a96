// The debugger's marks in the editor: breakpoints in a gutter of their own (a click on
// a line's gutter, or F9 on the line, sets or clears one, and they move with the text as
// it is edited), and the line the run is on, highlighted.

import { RangeSet, StateEffect, StateField, EditorState } from "@codemirror/state";
import { Decoration, DecorationSet, EditorView, GutterMarker, gutter, keymap } from "@codemirror/view";

const toggleBreakpoint = StateEffect.define<number>();  // at a line's start
// A 1-based line, or none, and whether the run faulted there.
const setCurrentLine = StateEffect.define<{ line: number | null; fault: boolean }>();

class BreakpointMarker extends GutterMarker {
  override elementClass = "cm-breakpoint";
  override toDOM() {
    const dot = document.createElement("span");
    dot.className = "cm-breakpoint-dot";
    dot.textContent = "●";
    return dot;
  }
}
const BREAKPOINT = new BreakpointMarker();

const breakpointField = StateField.define<RangeSet<GutterMarker>>({
  create: () => RangeSet.empty,
  update(set, transaction) {
    set = set.map(transaction.changes);
    for (const effect of transaction.effects) {
      if (!effect.is(toggleBreakpoint)) continue;
      let present = false;
      set.between(effect.value, effect.value, () => { present = true; });
      set = present
        ? set.update({ filter: (from) => from !== effect.value })
        : set.update({ add: [BREAKPOINT.range(effect.value)] });
    }
    return set;
  },
});

/** The 1-based lines that have a breakpoint, in order. */
function breakpointLines(state: EditorState): number[] {
  const lines = new Set<number>();
  for (let cursor = state.field(breakpointField).iter(); cursor.value; cursor.next()) {
    lines.add(state.doc.lineAt(cursor.from).number);
  }
  return [...lines].sort((a, b) => a - b);
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

/** The gutter and the highlight; `changed` hears every change of the breakpoints' lines. */
export function debuggerMarks(changed: (lines: number[]) => void) {
  let last = "";
  return [
    breakpointField,
    currentLineField,
    gutter({
      class: "cm-breakpoint-gutter",
      markers: (view) => view.state.field(breakpointField),
      domEventHandlers: {
        mousedown(view, line) {
          view.dispatch({ effects: toggleBreakpoint.of(line.from) });
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
      const lines = breakpointLines(update.state);
      const now = lines.join(",");
      if (now !== last) {
        last = now;
        changed(lines);
      }
    }),
  ];
}
