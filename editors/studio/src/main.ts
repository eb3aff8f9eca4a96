// The studio's page: the program's editor on the language server, the palette of
// built-ins, the world with the vehicle moving and its file, and the debugger. All it
// knows comes from the server over two WebSockets (spec/studio.md): the language
// server's session at /lsp, and the studio's protocol at /studio.

import "./studio.css";
import { EditorState } from "@codemirror/state";
import { EditorView, drawSelection, highlightActiveLine, keymap, lineNumbers } from "@codemirror/view";
import { defaultKeymap, history, historyKeymap, indentWithTab } from "@codemirror/commands";
import { bracketMatching, syntaxHighlighting } from "@codemirror/language";
import { lintGutter } from "@codemirror/lint";
import { autocompletion, closeBrackets } from "@codemirror/autocomplete";
import { formatDocument } from "@codemirror/lsp-client";
import { rl1Highlight, rl1Language } from "./language";
import { openSocket, studioClient, webSocketTransport } from "./lsp";
import { LineBreakpoint, debuggerMarks, showCurrentLine } from "./breakpoints";
import { showPalette } from "./palette";
import { WorldView } from "./world";
import { DebugPane } from "./debugPane";
import { CameraPane } from "./camera";
import { SensorPlots } from "./sensors";
import { WorldFile } from "./worldFile";
import {
  Binding, Builtin, CheckDiagnostic, Ended, FileEntry, FileText, Frame, Hello, INVALID_CONFIGURATION,
  Launched, PROGRAM_HAS_ERRORS, Progress, Stopped, StudioConnection, StudioError, WorldCheck,
} from "./protocol";

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

/** A file: URI of a path relative to the served folder. */
const fileUri = (rootUri: string, path: string): string =>
  `${rootUri.replace(/\/$/, "")}/${path.split("/").map(encodeURIComponent).join("/")}`;

/** The page's address names the files it shows after `#`: `#program=a.rob&world=a.world.toml`. */
const chosen = new URLSearchParams(location.hash.slice(1));

function fillSelect(select: HTMLSelectElement, paths: string[], current: string | null, none?: string): void {
  const options = [...(none === undefined ? [] : [[none, ""]]), ...paths.map((path) => [path, path])];
  if (current !== null && !paths.includes(current)) options.push([current, current]);
  select.replaceChildren(...options.map(([label, value]) => new Option(label, value, false, value === (current ?? ""))));
}

type RunState = "none" | "running" | "stopped" | "ended";

async function start(): Promise<void> {
  const token = new URLSearchParams(location.search).get("token") ?? "";
  const base = `${location.protocol === "https:" ? "wss" : "ws"}://${location.host}`;
  const query = `?token=${encodeURIComponent(token)}`;
  const [studioSocket, lspSocket] = await Promise.all([
    openSocket(`${base}/studio${query}`), openSocket(`${base}/lsp${query}`).catch(() => null)]);
  const studio = new StudioConnection(studioSocket, (why) => say(`disconnected: ${why}`, true));
  const hello = await studio.request<Hello>("initialize");
  const [{ files }, { builtins }] = await Promise.all([
    studio.request<{ files: FileEntry[] }>("files/list"), studio.request<{ builtins: Builtin[] }>("palette")]);
  const paths = (kind: FileEntry["kind"]) => files.filter((file) => file.kind === kind).map((file) => file.path);
  const programPath = chosen.get("program") ?? hello.program ?? paths("program")[0] ?? "program.rob";
  const worldPath = chosen.has("world") ? chosen.get("world") || null : hello.world;
  const program = files.some((file) => file.path === programPath)
    ? await studio.request<FileText>("files/read", { path: programPath })
    : { path: programPath, text: "", encoding: "utf-8" as const };

  // Without the language server the page still edits, saves and runs the program.
  const client = studioClient(
    hello.rootUri,
    (count) => { byId("editor").dataset.diagnostics = String(count); },
    (message) => say(message, true));
  const lspLost = "the language server's connection closed: reload the page";
  const withLsp = lspSocket?.readyState === WebSocket.OPEN;
  if (withLsp) {
    client.connect(webSocketTransport(lspSocket));
    lspSocket.addEventListener("close", () => {
      if (studioSocket.readyState === WebSocket.OPEN) say(lspLost, true);  // else the studio's own word
    });
  }

  // Which names are built-ins, which take a selector, which variables calls set: the palette's.
  const facts = {
    selectors: new Map(builtins.map((builtin) => [
      builtin.mnemonic, new Set(builtin.forms.flatMap((form) => form.selector ? [form.selector] : []))])),
    reserved: new Set(builtins.flatMap((builtin) => builtin.forms.flatMap((form) => form.writes))),
  };

  // The program.
  const programSelect = byId<HTMLSelectElement>("program-file");
  fillSelect(programSelect, paths("program"), programPath);
  let savedText = program.text;
  const markUnsaved = (text: string) => programSelect.classList.toggle("unsaved", text !== savedText);
  const save = async (): Promise<void> => {
    const text = editor.state.doc.toString();
    try {
      await studio.request("files/save", { path: programPath, text, encoding: program.encoding });
      savedText = text;
      markUnsaved(text);
      say(`saved ${programPath}`);
    } catch (error) {
      say((error as Error).message, true);
    }
  };
  let breakpoints: LineBreakpoint[] = [];
  const stopOnLost = byId<HTMLInputElement>("stop-on-lost");
  const sendBreakpoints = async (): Promise<void> => {
    const answer = await studio.request<{ breakpoints: Binding[] | null }>("debug/setBreakpoints", {
      lines: breakpoints.map(({ line, condition }) => condition === null ? { line } : { line, condition }),
      lostLines: stopOnLost.checked });
    reportBindings(answer.breakpoints ?? []);
  };
  stopOnLost.addEventListener("change", () => sendBreakpoints().catch((error: Error) => say(error.message, true)));
  const reportBindings = (bindings: Binding[]): void => {
    const refused = bindings.filter((binding) => !binding.verified);
    if (refused.length) say(refused.map((binding) => `breakpoint on line ${binding.line}: ${binding.message}`).join("; "), true);
  };
  const editor = new EditorView({
    parent: byId("editor"),
    state: EditorState.create({
      doc: program.text,
      extensions: [
        lineNumbers(),
        debuggerMarks((now) => {
          breakpoints = now;
          sendBreakpoints().catch((error: Error) => say(error.message, true));
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
        withLsp ? client.plugin(fileUri(hello.rootUri, programPath), "rl1") : [],
        EditorView.updateListener.of((update) => {
          if (update.docChanged) markUnsaved(update.state.doc.toString());
        }),
      ],
    }),
  });
  byId("save").addEventListener("click", () => void save());
  byId("format").addEventListener("click", () => formatDocument(editor));
  programSelect.addEventListener("change", () => {
    if (editor.state.doc.toString() !== savedText && !confirm(`${programPath} has unsaved changes: leave them?`)) {
      programSelect.value = programPath;
      return;
    }
    chosen.set("program", programSelect.value);
    location.hash = chosen.toString();
    location.reload();
  });
  showPalette(byId("palette"), builtins, editor);

  // The world, and its file.
  const world = new WorldView(byId("world") as unknown as SVGSVGElement, byId("world-clock"));
  const worldFile = new WorldFile(studio, world, byId("world-editor"), byId("world-errors"), byId("world-file"),
                                  (error) => say(error.message, true));
  const openWorld = async (path: string | null): Promise<void> => {
    byId("world-pane").classList.toggle("no-world", path === null);
    await worldFile.open(path);
  };
  const worldSelect = byId<HTMLSelectElement>("world-name");
  fillSelect(worldSelect, paths("world"), worldPath, "no world (the scripted device)");
  await openWorld(worldPath);
  worldSelect.addEventListener("change", () => {
    chosen.set("world", worldSelect.value);
    window.history.replaceState(null, "", `#${chosen.toString()}`);
    openWorld(worldSelect.value || null).catch((error: Error) => say(error.message, true));
  });
  byId("world-save").addEventListener("click", () => {
    worldFile.save().then(() => say(`saved ${worldFile.path}`), (error: Error) => say(error.message, true));
  });

  // The debugger.
  const pane = new DebugPane(byId("stop"), byId("variables"), byId("device"),
                             byId<HTMLOListElement>("trace"), facts.reserved);
  const camera = new CameraPane(byId("camera-pane"), byId<HTMLCanvasElement>("camera"), byId("camera-caption"));
  const plots = new SensorPlots(byId("plots-pane"), byId("plots"),
                                new Map(builtins.map((builtin) => [builtin.mnemonic, builtin.readings])));
  let state: RunState = "none";
  const controls: Record<string, RunState[]> = {
    run: ["none", "stopped", "ended"], pause: ["running"], "step-line": ["none", "stopped", "ended"],
    "step-instruction": ["none", "stopped", "ended"], continue: ["none", "stopped", "ended"],
    restart: ["running", "stopped", "ended"],
  };
  const setState = (now: RunState): void => {
    state = now;
    for (const [name, enabled] of Object.entries(controls)) byId<HTMLButtonElement>(name).disabled = !enabled.includes(now);
    document.body.dataset.run = now;
  };
  setState("none");
  let shownLine: number | null = null;
  const progress = (notice: Progress): void => {
    if (notice.frame) world.frame(notice.frame);
    world.events(notice.events);
    camera.show(notice.image, notice.frame);
    plots.add(notice.trace, notice.frame);
  };
  studio.on("run/frame", (frame: Progress) => {
    progress(frame);
    pane.progress(frame);
    const line = (frame.frame as Frame | null)?.line ?? null;
    if (line !== shownLine) {
      shownLine = line;
      showCurrentLine(editor, line, false);
    }
  });
  studio.on("run/stopped", (stopped: Stopped) => {
    progress(stopped);
    pane.stopped(stopped);
    shownLine = stopped.line;
    showCurrentLine(editor, stopped.line, true);
    setState("stopped");
  });
  studio.on("run/ended", (ended: Ended) => {
    progress(ended);
    pane.ended(ended);
    shownLine = ended.status?.line ?? null;  // a fault's
    showCurrentLine(editor, shownLine, true, true);
    setState("ended");
  });
  const speedSelect = byId<HTMLSelectElement>("speed");
  const speed = (): number | null => speedSelect.value === "" ? null : Number(speedSelect.value);
  speedSelect.addEventListener("change", () => {
    if (state !== "none") studio.request("debug/setSpeed", { speed: speed() }).catch((error: Error) => say(error.message, true));
  });

  const launch = async (stopOnEntry: boolean): Promise<void> => {
    world.reset();
    pane.clear();
    camera.clear();
    plots.clear();
    showCurrentLine(editor, null, false);
    const launched = await studio.request<Launched>("run/launch", {
      program: { text: editor.state.doc.toString(), name: programPath },
      ...(worldFile.path === null ? {} : { world: { text: worldFile.text, name: worldFile.path } }),
      speed: speed(),
      stopOnEntry,
    });
    reportBindings(launched.breakpoints);
  };
  // Each command, given the state the run was in when it was asked.
  const commands: Record<string, (from: RunState) => Promise<unknown>> = {
    run: () => launch(false),
    pause: () => studio.request("debug/pause"),
    "step-line": (from) => from === "stopped" ? studio.request("debug/stepLine") : launch(true),
    "step-instruction": (from) => from === "stopped" ? studio.request("debug/stepInstruction") : launch(true),
    continue: (from) => from === "stopped" ? studio.request("debug/continue", { speed: speed() }) : launch(false),
    restart: () => studio.request("debug/restart"),
  };
  const command = (name: string): void => {
    if (!controls[name].includes(state)) return;
    const before = state;
    if (name !== "pause") setState("running");  // before the answer, which a stop may precede
    say("");
    commands[name](before).catch((error: Error) => {
      if (state === "running") setState(before);
      explain(error);
    });
  };
  const explain = (error: Error): void => {
    if (error instanceof StudioError && error.code === PROGRAM_HAS_ERRORS) {
      const { diagnostics } = error.data as { diagnostics: CheckDiagnostic[] };
      const first = diagnostics.find((diagnostic) => diagnostic.severity === "error") ?? diagnostics[0];
      say(first ? `the program cannot run: line ${first.line}: ${first.message} [${first.code}]` : error.message, true);
    } else if (error instanceof StudioError && error.code === INVALID_CONFIGURATION) {
      const { errors } = error.data as WorldCheck;
      worldFile.showErrors(errors);
      say(`the world cannot be used: ${errors[0]?.message ?? error.message}`, true);
    } else {
      say(error.message, true);
    }
  };
  for (const name of Object.keys(controls)) byId(name).addEventListener("click", () => command(name));
  const keys: Record<string, string> = { F5: "run", F6: "pause", F10: "step-line", F11: "step-instruction" };
  document.addEventListener("keydown", (event) => {
    if (keys[event.key]) {
      event.preventDefault();
      command(keys[event.key]);
    }
  });
  document.body.dataset.ready = "true";
  say(withLsp ? `serving ${hello.folder}` : lspLost, !withLsp);
}

start().catch((error: Error) => say(`the studio cannot start: ${error.message}. Is \`rl1c studio\` still `
                                    + "running? Start it again and open the address it prints.", true));
