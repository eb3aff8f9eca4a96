// The palette of built-ins (the paper's Tables 2 and 3, as the server sends them): a
// button for each form of each call, which inserts the call's snippet at the cursor, a
// field for each argument named after its parameter (Tab goes to the next).

import { snippet } from "@codemirror/autocomplete";
import { EditorView } from "@codemirror/view";
import type { Builtin, Form } from "./protocol";

/** The call as a button shows it: the snippet with its tab stops' names, `(MOV l,r)`. */
export function callLabel(form: Form): string {
  return form.snippet.replace(/\$\{\d+:([^}]*)\}/g, "$1").replace(/\$\{?\d+\}?/g, "");
}

function tooltip(builtin: Builtin, form: Form): string {
  const params = form.params.map((param) => `${param.name}: ${param.meaning}, ${param.low}..${param.high}`);
  return [`${builtin.name}: ${form.summary}`, ...params,
          ...(form.result ? [`returns ${form.result}`] : [])].join("\n");
}

const TABLES: Record<string, string> = {
  motion: "Table 2: motion",
  sensing: "Table 3: sensing",
};

/** Fills `parent` with the buttons; each inserts its call into `editor`. */
export function showPalette(parent: HTMLElement, builtins: readonly Builtin[],
                            editor: EditorView): void {
  parent.replaceChildren();
  for (const [group, title] of Object.entries(TABLES)) {
    const heading = document.createElement("div");
    heading.className = "table";
    heading.textContent = title;
    parent.append(heading);
    for (const builtin of builtins.filter((one) => one.group === group)) {
      for (const form of builtin.forms) {
        const button = document.createElement("button");
        button.type = "button";
        button.textContent = callLabel(form);
        button.title = tooltip(builtin, form);
        button.addEventListener("click", () => insertCall(editor, form.snippet));
        parent.append(button);
      }
    }
  }
}

/** What goes between the code before the cursor on its line and a new statement: a
 * `; ` after a statement, a space after a label or a `;`, nothing at the line's start. */
function separator(before: string): string {
  const code = before.trimEnd();
  if (code === "") return "";
  const spaced = code.length < before.length ? "" : " ";
  return /^:[0-9]*$/.test(code.trimStart()) || code.endsWith(";") ? spaced : "; ";
}

/** Inserts a call at the cursor as a statement, its first argument selected (Tab goes
 * to the next). */
export function insertCall(editor: EditorView, template: string): void {
  const { from, to } = editor.state.selection.main;
  const line = editor.state.doc.lineAt(from);
  snippet(separator(editor.state.sliceDoc(line.from, from)) + template)(editor, null, from, to);
  editor.focus();
}
