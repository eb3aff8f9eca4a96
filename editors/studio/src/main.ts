// The studio's page: the program's editor on the language server, the palette of
// built-ins, the world with the vehicle moving, the world file, and the debugger. All
// it knows comes from the server over two WebSockets (spec/studio.md): the language
// server's session at /lsp, and the studio's protocol.

import "./studio.css";
import { EditorState } from "@codemirror/state";
import { EditorView, keymap, lineNumbers, highlightActiveLine, drawSelection } from "@codemirror/view";
import { defaultKeymap, history, historyKeymap, indentWithTab } from "@codemirror/commands";
import { syntaxHighlighting, bracketMatching } from "@codemirror/language";
import { lintGutter, setDiagnostics } from "@codemirror/lint";
import { closeBrackets, autocompletion } from "@codemirror/autocomplete";
import { rl1Highlight, rl1Language } from "./language";
import { openSocket, studioClient, webSocketTransport } from "./lsp";
import { debuggerMarks, showCurrentLine } from "./breakpoints";
import { showPalette } from "./palette";
import { WorldView } from "./world";
import { DebugPane } from "./debugPane";
import { StudioConnection } from "./protocol";
import type { Builtin, Frame, Geometry, Stopped } from "./protocol";

interface Opened {
  file: string;
  uri: string;
  text: string;
  builtins: Builtin[];
  reserved: string[];
  world: { file: string; text: string; geometry: Geometry | null; errors: string[] };
}

const byId = <T extends HTMLElement = HTMLElement>(id: string): T => {
  const found = document.getElementById(id);
  if (!found) throw new Error(`the page has no #${id}`);
  return found as T;
};

function say(text: string, problem = false): void {
  const status = byId("status");
  status.textContent = text;
  status.classList.toggle("problem", problem);
}

async function start(): Promise<void> {
  const token = new URLSearchParams(location.search).get("token") ?? "";
  const base = `${location.protocol === "https:" ? "wss" : "ws"}://${location.host}`;
  const query = `?token=${encodeURIComponent(token)}`;
  const [studioSocket, lspSocket] = await Promise.all([
    openSocket(`${base}/studio${query}`), openSocket(`${base}/lsp${query}`)]);
  const studio = new StudioConnection(studioSocket, (why) => say(`disconnected: ${why}`, true));
  const opened = await studio.request<Opened>("open");

  const client = studioClient(
    (count) => { byId("editor").dataset.diagnostics = String(count); },
    (message) => say(message, true));
  client.connect(webSocketTransport(lspSocket));
  lspSocket.addEventListener("close", () => say("the language server's connection closed", true));

  const facts = {
    selectors: new Map(opened.builtins.map((builtin) => [
      builtin.mnemonic, new Set(builtin.forms.flatMap((form) => form.selector ? [form.selector] : []))])),
    reserved: new Set(opened.reserved),
  };
  let breakpoints: number[] = [];
  const fileName = byId("file");
  fileName.textContent = opened.file;
  let savedText = opened.text;

  const save = async (): Promise<void> => {
    const text = editor.state.doc.toString();
    try {
      await studio.request("save", { text });
      savedText = text;
      fileName.classList.toggle("unsaved", false);
      say(`saved ${opened.file}`);
    } catch (error) {
      say(String((error as Error).message), true);
    }
  };

  const editor = new EditorView({
    parent: byId("editor"),
    state: EditorState.create({
      doc: opened.text,
      extensions: [
        lineNumbers(),
        debuggerMarks((lines) => {
          breakpoints = lines;
          void studio.request("breakpoints", { lines });
        }),
        lintGutter(),
        history(),
        drawSelection(),
        highlightActiveLine(),
        bracketMatching(),
        closeBrackets(),
        autocompletion(),
        rl1Language(facts),
        syntaxHighlighting(rl1Highlight),
        keymap.of([{ key: "Mod-s", run: () => { void save(); return true; } },
                   ...defaultKeymap, ...historyKeymap, indentWithTab]),
        client.plugin(opened.uri, "rl1"),
        EditorView.updateListener.of((update) => {
          if (update.docChanged) fileName.classList.toggle("unsaved", update.state.doc.toString() !== savedText);
        }),
      ],
    }),
  });
  byId("save").addEventListener("click", () => void save());
  showPalette(byId("palette"), opened.builtins, editor);

  // The world, and its file.
  const world = new WorldView(byId("world") as unknown as SVGSVGElement, byId("world-clock"));
  if (opened.world.geometry) world.show(opened.world.geometry);
  byId("world-name").textContent = opened.world.file;
  const worldErrors = byId("world-errors");
  const showWorldErrors = (errors: string[]): void => {
    worldErrors.replaceChildren(...errors.map((text) => {
      const item = document.createElement("li");
      item.textContent = text;
      return item;
    }));
    byId("world-file").toggleAttribute("open", errors.length > 0 || byId("world-file").hasAttribute("open"));
  };
  showWorldErrors(opened.world.errors);
  const worldEditor = new EditorView({
    parent: byId("world-editor"),
    state: EditorState.create({
      doc: opened.world.text,
      extensions: [lineNumbers(), history(), drawSelection(), lintGutter(),
                   keymap.of([...defaultKeymap, ...historyKeymap])],
    }),
  });
  byId("world-apply").addEventListener("click", async () => {
    const result = await studio.request<{ geometry: Geometry | null; errors: { line: number; message: string }[] }>(
      "world", { text: worldEditor.state.doc.toString() });
    showWorldErrors(result.errors.map((error) => error.message));
    worldEditor.dispatch(setDiagnostics(worldEditor.state, result.errors.map((error) => {
      const line = worldEditor.state.doc.line(Math.min(Math.max(error.line, 1), worldEditor.state.doc.lines));
      return { from: line.from, to: line.to, severity: "error", message: error.message };
    })));
    if (result.geometry) world.show(result.geometry);
  });

  // The debugger.
  const pane = new DebugPane(byId("stop"), byId("variables"), byId("device"),
                             byId<HTMLOListElement>("trace"), facts.reserved);
  studio.on("frame", (frame: Frame) => world.frame(frame));
  studio.on("stopped", (stopped: Stopped) => {
    pane.show(stopped);
    showCurrentLine(editor, stopped.reason === "end" ? null : stopped.line);
    setRunning(false);
  });
  const controls = ["run", "pause", "step-line", "step-instruction", "continue", "restart"];
  const setRunning = (running: boolean): void => {
    for (const name of controls) {
      (byId(name) as HTMLButtonElement).disabled = name === "pause" ? !running : running;
    }
    document.body.dataset.running = String(running);
  };
  setRunning(false);
  const speed = byId<HTMLSelectElement>("speed");
  const command = (name: string): void => {
    if (name !== "pause") setRunning(true);
    if (name === "run" || name === "restart") world.reset();
    studio.request(name, { text: editor.state.doc.toString(), breakpoints, speed: Number(speed.value) })
      .catch((error: Error) => { say(error.message, true); setRunning(false); });
  };
  for (const name of controls) byId(name).addEventListener("click", () => command(name));
  speed.addEventListener("change", () => void studio.request("speed", { speed: Number(speed.value) }));
  document.addEventListener("keydown", (event) => {
    const key = { F5: "run", F6: "pause", F10: "step-line", F11: "step-instruction" }[event.key];
    if (key) {
      event.preventDefault();
      command(key);
    }
  });
  document.body.dataset.ready = "true";
  say("ready");
}

start().catch((error: Error) => say(`the studio cannot start: ${error.message}`, true));
