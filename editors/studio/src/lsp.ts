// The editor's language server: rl1-lsp's session, which the studio serves at
// /lsp?token=T, one JSON-RPC message a WebSocket text frame, through CodeMirror's own
// LSP client. The client's diagnostics are replaced by ours, which carry the server's
// quick fixes and are asked for at once after each change (the client's own wait half a
// second after the last keystroke).

import { Text } from "@codemirror/state";
import { EditorView, ViewPlugin, keymap } from "@codemirror/view";
import { Action, Diagnostic, setDiagnostics } from "@codemirror/lint";
import {
  LSPClient, LSPClientExtension, LSPPlugin, Transport, findReferencesKeymap, formatKeymap,
  hoverTooltips, jumpToDefinitionKeymap, renameKeymap, serverCompletion, signatureHelp,
} from "@codemirror/lsp-client";
import type * as lsp from "vscode-languageserver-protocol";

/** A WebSocket as the LSP client's transport, once open. */
export function webSocketTransport(socket: WebSocket): Transport {
  const handlers = new Set<(message: string) => void>();
  socket.addEventListener("message", (event) => {
    if (typeof event.data === "string") for (const handler of handlers) handler(event.data);
  });
  return {
    send(message) {
      if (socket.readyState !== WebSocket.OPEN) throw new Error("the language server is gone");
      socket.send(message);
    },
    subscribe: (handler) => handlers.add(handler),
    unsubscribe: (handler) => handlers.delete(handler),
  };
}

/** Opens a WebSocket, resolving once it is open and rejecting if it cannot be. */
export function openSocket(url: string): Promise<WebSocket> {
  return new Promise((resolve, reject) => {
    const socket = new WebSocket(url);
    socket.addEventListener("open", () => resolve(socket), { once: true });
    socket.addEventListener("error", () => reject(new Error(`cannot connect to ${url}`)),
                            { once: true });
  });
}

const SEVERITIES = ["error", "error", "warning", "info", "hint"] as const;

/** What identifies a diagnostic in a code action's `diagnostics`. */
function key(diagnostic: lsp.Diagnostic): string {
  const { start, end } = diagnostic.range;
  return [start.line, start.character, end.line, end.character, diagnostic.code,
          diagnostic.message].join("\u0000");
}

/** A quick fix's edits of this document, made if the document is still the one they
 * were offered for (a newer one gets its own fixes with its diagnostics). */
function applyEdit(uri: string, offeredFor: Text, edit: lsp.WorkspaceEdit | undefined): Action["apply"] {
  return (view) => {
    const plugin = LSPPlugin.get(view);
    if (!plugin || view.state.doc !== offeredFor || !edit) return;
    const edits = edit.changes?.[uri] ?? [];
    view.dispatch({
      changes: edits.map((one) => ({
        from: plugin.fromPosition(one.range.start), to: plugin.fromPosition(one.range.end),
        insert: one.newText,
      })),
      userEvent: "input.fix",
    });
  };
}

/** The diagnostics the server publishes, shown at once, then again with their quick
 * fixes when the server has answered for them (textDocument/codeAction). */
function diagnostics(onPublished: (count: number) => void): LSPClientExtension {
  return {
    clientCapabilities: { textDocument: { publishDiagnostics: { versionSupport: true } } },
    notificationHandlers: {
      "textDocument/publishDiagnostics": (client, params: lsp.PublishDiagnosticsParams) => {
        const file = client.workspace.getFile(params.uri);
        if (!file || (params.version != null && params.version !== file.version)) return false;
        const view = file.getView();
        const plugin = view && LSPPlugin.get(view);
        if (!view || !plugin) return false;
        const shown = (fixes: Map<string, Action[]>): Diagnostic[] => params.diagnostics.map((item) => ({
          from: plugin.unsyncedChanges.mapPos(plugin.fromPosition(item.range.start, plugin.syncedDoc)),
          to: plugin.unsyncedChanges.mapPos(plugin.fromPosition(item.range.end, plugin.syncedDoc)),
          severity: SEVERITIES[item.severity ?? 1],
          source: item.code == null ? undefined : String(item.code),
          message: item.message,
          actions: fixes.get(key(item)) ?? [],
        }));
        view.dispatch(setDiagnostics(view.state, shown(new Map())));
        onPublished(params.diagnostics.length);
        if (params.diagnostics.length === 0) return true;
        const doc = view.state.doc;
        client.request<lsp.CodeActionParams, (lsp.CodeAction | lsp.Command)[] | null>(
          "textDocument/codeAction", {
            textDocument: { uri: params.uri },
            range: { start: { line: 0, character: 0 }, end: plugin.toPosition(doc.length, doc) },
            context: { diagnostics: params.diagnostics, only: ["quickfix"] },
          }).then((actions) => {
            if (view.state.doc !== doc) return;  // edited since: newer diagnostics follow
            const fixes = new Map<string, Action[]>();
            for (const action of actions ?? []) {
              if (!("edit" in action) || !action.diagnostics?.length) continue;
              const forKey = key(action.diagnostics[0]);
              fixes.set(forKey, [...(fixes.get(forKey) ?? []),
                                 { name: action.title, apply: applyEdit(params.uri, doc, action.edit) }]);
            }
            view.dispatch(setDiagnostics(view.state, shown(fixes)));
          }, () => undefined);  // the server went away: the diagnostics stay, without fixes
        return true;
      },
    },
  };
}

/** Sends each change to the server as soon as it is made (after the transaction, once
 * the client's own plugin has recorded it). */
const syncAtOnce = ViewPlugin.fromClass(class {
  private pending = false;
  constructor(readonly view: EditorView) {}
  update(update: { docChanged: boolean }) {
    if (!update.docChanged || this.pending) return;
    this.pending = true;
    queueMicrotask(() => {
      this.pending = false;
      LSPPlugin.get(this.view)?.client.sync();
    });
  }
});

/** A client with every feature the studio offers: completion, hover, signature help,
 * formatting, rename, go to definition, references, and diagnostics with quick fixes;
 * `rootUri` is the served folder's. */
export function studioClient(rootUri: string, onPublished: (count: number) => void,
                             onMessage: (message: string) => void): LSPClient {
  return new LSPClient({
    rootUri,
    timeout: 10_000,
    notificationHandlers: {
      "window/showMessage": (_client, params: lsp.ShowMessageParams) => {
        onMessage(params.message);
        return true;
      },
    },
    extensions: [
      serverCompletion(),
      hoverTooltips(),
      signatureHelp(),
      keymap.of([...formatKeymap, ...renameKeymap, ...jumpToDefinitionKeymap, ...findReferencesKeymap]),
      diagnostics(onPublished),
      syncAtOnce,
    ],
  });
}
