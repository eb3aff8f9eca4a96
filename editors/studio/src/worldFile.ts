// The world file beside the top view: read from the served folder, edited, checked by
// the server as it is edited (world/check) with its error shown in the list and the
// editor's gutter, drawn while it is valid, and saved on request.

import { EditorState } from "@codemirror/state";
import { EditorView, drawSelection, keymap, lineNumbers } from "@codemirror/view";
import { defaultKeymap, history, historyKeymap } from "@codemirror/commands";
import { lintGutter, setDiagnostics } from "@codemirror/lint";
import type { ConfigProblem, FileText, StudioConnection, WorldCheck } from "./protocol";
import type { WorldView } from "./world";

const CHECK_AFTER = 250;  // ms without an edit before the world is checked

export class WorldFile {
  /** The world's path in the served folder; null: no world, the scripted device. */
  path: string | null = null;
  private readonly editor: EditorView;
  private asked = 0;  // the last check asked, so that an older answer is dropped
  private timer = -1;

  constructor(private readonly studio: StudioConnection, private readonly world: WorldView,
              parent: HTMLElement, private readonly errors: HTMLElement,
              private readonly details: HTMLElement, private readonly failed: (error: Error) => void) {
    this.editor = new EditorView({
      parent,
      state: EditorState.create({
        extensions: [lineNumbers(), history(), drawSelection(), lintGutter(),
                     keymap.of([...defaultKeymap, ...historyKeymap]),
                     EditorView.updateListener.of((update) => { if (update.docChanged) this.schedule(); })],
      }),
    });
  }

  get text(): string {
    return this.editor.state.doc.toString();
  }

  async open(path: string | null): Promise<void> {
    this.path = path;
    const text = path === null ? "" : (await this.studio.request<FileText>("files/read", { path })).text;
    this.editor.dispatch({ changes: { from: 0, to: this.editor.state.doc.length, insert: text } });
    clearTimeout(this.timer);
    await this.check();
  }

  async save(): Promise<void> {
    if (this.path !== null) await this.studio.request("files/save", { path: this.path, text: this.text });
  }

  /** The problems of the world as checked, in the list and on their lines. */
  showErrors(problems: readonly ConfigProblem[]): void {
    this.errors.replaceChildren(...problems.map((problem) => {
      const item = document.createElement("li");
      item.textContent = problem.message;
      return item;
    }));
    const doc = this.editor.state.doc;
    this.editor.dispatch(setDiagnostics(this.editor.state, problems.map((problem) => {
      const line = doc.line(Math.min(Math.max(problem.line ?? 1, 1), doc.lines));
      return { from: line.from, to: line.to, severity: "error", message: problem.message };
    })));
    if (problems.length) this.details.setAttribute("open", "");
  }

  private schedule(): void {
    clearTimeout(this.timer);
    this.timer = window.setTimeout(() => this.check().catch(this.failed), CHECK_AFTER);
  }

  private async check(): Promise<void> {
    if (this.path === null) return;
    const asked = ++this.asked;
    const check = await this.studio.request<WorldCheck>("world/check", { text: this.text, path: this.path });
    if (asked !== this.asked) return;  // edited since
    this.showErrors(check.errors);
    if (check.geometry) this.world.show(check.geometry);
  }
}
