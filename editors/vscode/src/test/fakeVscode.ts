// Just enough of the `vscode` and `vscode-languageclient/node` modules for node to load
// out/extension.js and call its activate(): it records what the extension registers.

import Module = require('node:module');

type Handler = (...args: unknown[]) => unknown;

export const registered = {
  commands: new Map<string, Handler>(),
  taskTypes: [] as string[],
  schemes: [] as string[],
  errors: [] as string[],
};

const disposable = { dispose: () => undefined };

class EventEmitter {
  event = () => disposable;
  fire(): void {}
}

const vscode = {
  EventEmitter,
  window: {
    activeTextEditor: undefined,
    createOutputChannel: () => disposable,
    showErrorMessage: async (message: string) => {
      registered.errors.push(message);
      return undefined;
    },
  },
  commands: {
    registerCommand: (id: string, handler: Handler) => {
      registered.commands.set(id, handler);
      return disposable;
    },
  },
  workspace: {
    workspaceFolders: undefined,
    getConfiguration: () => ({ get: () => undefined }),
    onDidChangeConfiguration: () => disposable,
    onDidCloseTextDocument: () => disposable,
    registerTextDocumentContentProvider: (scheme: string) => {
      registered.schemes.push(scheme);
      return disposable;
    },
  },
  tasks: {
    registerTaskProvider: (type: string) => {
      registered.taskTypes.push(type);
      return disposable;
    },
  },
};

class LanguageClient {
  async start(): Promise<void> {}
  async stop(): Promise<void> {}
}

const fakes: Record<string, unknown> = { vscode, 'vscode-languageclient/node': { LanguageClient } };
const loader = Module as unknown as { _load: (request: string, ...rest: unknown[]) => unknown };
const load = loader._load;
loader._load = function (request: string, ...rest: unknown[]) {
  return fakes[request] ?? load.call(this, request, ...rest);
};
