// Just enough of the `vscode` and `vscode-languageclient/node` modules for node to load
// out/extension.js and call its activate(): it records what the extension registers.

import Module = require('node:module');

type Handler = (...args: unknown[]) => unknown;

export interface TaskProvider {
  resolveTask(task: { definition: Record<string, unknown>; scope?: unknown }): unknown;
}

export interface DebugAdapterFactory {
  createDebugAdapterDescriptor(session: unknown): unknown;
}

export interface DebugConfigurationProvider {
  resolveDebugConfiguration(folder: unknown, configuration: Record<string, unknown>): unknown;
}

export const registered = {
  commands: new Map<string, Handler>(),
  taskProviders: new Map<string, TaskProvider>(),
  debugAdapters: new Map<string, DebugAdapterFactory>(),
  debugConfigurations: new Map<string, DebugConfigurationProvider>(),
  schemes: [] as string[],
  errors: [] as string[],
};

const disposable = { dispose: () => undefined };

class EventEmitter {
  event = () => disposable;
  fire(): void {}
}

/** vscode.Task and vscode.ProcessExecution keep their constructor's arguments. */
export class Task {
  constructor(
    readonly definition: unknown,
    readonly scope: unknown,
    readonly name: string,
    readonly source: string,
    readonly execution: ProcessExecution,
    readonly problemMatchers: string[],
  ) {}
}

export class ProcessExecution {
  constructor(
    readonly process: string,
    readonly args: string[],
  ) {}
}

/** vscode.DebugAdapterExecutable keeps its constructor's arguments. */
export class DebugAdapterExecutable {
  constructor(
    readonly command: string,
    readonly args: string[],
  ) {}
}

const vscode = {
  EventEmitter,
  Task,
  ProcessExecution,
  DebugAdapterExecutable,
  TaskScope: { Workspace: 2 },
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
    onDidSaveTextDocument: () => disposable,
    registerTextDocumentContentProvider: (scheme: string) => {
      registered.schemes.push(scheme);
      return disposable;
    },
  },
  tasks: {
    registerTaskProvider: (type: string, provider: TaskProvider) => {
      registered.taskProviders.set(type, provider);
      return disposable;
    },
    onDidEndTaskProcess: () => disposable,
  },
  debug: {
    registerDebugAdapterDescriptorFactory: (type: string, factory: DebugAdapterFactory) => {
      registered.debugAdapters.set(type, factory);
      return disposable;
    },
    registerDebugConfigurationProvider: (type: string, provider: DebugConfigurationProvider) => {
      registered.debugConfigurations.set(type, provider);
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
