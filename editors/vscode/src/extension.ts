// The VS Code side of RL/I: highlighting comes from the TextMate grammar alone; this
// starts the `rl1-lsp` language server for diagnostics, hover and completion, and runs
// `rl1c` for the commands Check, Compile, Run, Show disassembly and Simulate and the `rl1`
// tasks, and `rl1-dap` for the debugger of type `rl1`.

import * as fs from 'node:fs';
import * as path from 'node:path';
import * as vscode from 'vscode';
import { LanguageClient, LanguageClientOptions, ServerOptions } from 'vscode-languageclient/node';
import {
  CommandId,
  COMMANDS,
  disassemble,
  Rl1cError,
  TASK_TYPE,
  Tool,
  TOOL_SETTINGS,
  toolPath,
  TaskCommand,
  taskCommandLine,
  TaskError,
  taskRequest,
} from './rl1cCommand';
import { DEFAULT_SERVER, serverCommand, SettingError } from './serverCommand';
import {
  DEBUG_TYPE,
  launchForFile,
  replayFor,
  WORLD_SETTING,
  worldFor,
  wroteReplay,
} from './debugging';

const DISASSEMBLY_SCHEME = 'rl1-dis';

let client: LanguageClient | undefined;
let output: vscode.LogOutputChannel | undefined;

// Typed by CommandId, so that tsc refuses a command of package.json without a handler.
const HANDLERS: Record<CommandId, () => Promise<void>> = {
  'rl1.restartServer': restart,
  'rl1.check': () => runTask('check'),
  'rl1.compile': () => runTask('compile'),
  'rl1.run': runWithSensors,
  'rl1.showDisassembly': showDisassembly,
  'rl1.simulate': simulate,
};

// A disassembly view's URI is its source's path with `.ils` added, in this scheme.
const DISASSEMBLY_SUFFIX = '.ils';
const disassemblyChanged = new vscode.EventEmitter<vscode.Uri>();

export async function activate(context: vscode.ExtensionContext): Promise<void> {
  output = vscode.window.createOutputChannel('RL/I', { log: true });
  context.subscriptions.push(
    output,
    ...COMMANDS.map((id) => vscode.commands.registerCommand(id, HANDLERS[id])),
    vscode.workspace.registerTextDocumentContentProvider(DISASSEMBLY_SCHEME, {
      onDidChange: disassemblyChanged.event,
      provideTextDocumentContent: disassembly,
    }),
    // An open disassembly follows its source from save to save.
    vscode.workspace.onDidSaveTextDocument((saved) => {
      const view = disassemblyUri(saved.fileName);
      if (vscode.workspace.textDocuments.some((document) => document.uri.toString() === view.toString())) {
        disassemblyChanged.fire(view);
      }
    }),
    vscode.tasks.registerTaskProvider(TASK_TYPE, {
      provideTasks: () => providedTasks(),
      resolveTask: (task) => resolvedTask(task),
    }),
    vscode.debug.registerDebugAdapterDescriptorFactory(DEBUG_TYPE, {
      createDebugAdapterDescriptor: () => new vscode.DebugAdapterExecutable(tool('rl1-dap'), []),
    }),
    vscode.debug.registerDebugConfigurationProvider(DEBUG_TYPE, {
      resolveDebugConfiguration: (_folder, configuration) => resolvedLaunch(configuration),
    }),
    vscode.workspace.onDidChangeConfiguration((change) => {
      if (change.affectsConfiguration('rl1.server')) {
        void restart();
      }
    }),
  );
  await start();
}

export async function deactivate(): Promise<void> {
  await stop();
}

async function restart(): Promise<void> {
  await stop();
  await start();
}

async function stop(): Promise<void> {
  const running = client;
  client = undefined;
  if (running !== undefined) {
    await running.stop();
  }
}

async function start(): Promise<void> {
  const settings = vscode.workspace.getConfiguration('rl1.server');
  const folder = vscode.workspace.workspaceFolders?.[0]?.uri.fsPath;
  let server;
  try {
    server = serverCommand(settings.get('path'), settings.get('args'), folder);
  } catch (error) {
    if (error instanceof SettingError) {
      void offerSettings(`RL/I: ${error.message}.`);
      return;
    }
    throw error;
  }
  const serverOptions: ServerOptions = { command: server.command, args: server.args };
  const clientOptions: LanguageClientOptions = {
    documentSelector: [
      { scheme: 'file', language: 'rl1' },
      { scheme: 'untitled', language: 'rl1' },
      // rl1c test's files: the server shows what rl1c test would refuse in them.
      { scheme: 'file', pattern: '**/*.tests.toml' },
    ],
    outputChannel: output,
  };
  // The id 'rl1' makes the client follow the `rl1.trace.server` setting.
  const starting = new LanguageClient('rl1', 'RL/I language server', serverOptions, clientOptions);
  try {
    await starting.start();
    client = starting;
  } catch (error) {
    const reason = error instanceof Error ? error.message : String(error);
    const where =
      server.command === DEFAULT_SERVER
        ? `install the rl1 Python package (\`pipx install /path/to/rl1\`) so that ` +
          `${DEFAULT_SERVER} is on PATH, or set rl1.server.path to its full path`
        : 'check rl1.server.path';
    void offerSettings(
      `RL/I: the language server "${server.command}" did not start (${reason}). ` +
        `Highlighting still works; for diagnostics ${where}.`,
    );
  }
}

/** Tells the user what is wrong with a task or a setting; a setting's message offers the settings. */
function report(error: unknown): void {
  if (error instanceof SettingError) {
    void offerSettings(`RL/I: ${error.message}.`);
  } else if (error instanceof TaskError) {
    void vscode.window.showErrorMessage(`RL/I: ${error.message}.`);
  } else {
    throw error;
  }
}

async function offerSettings(message: string): Promise<void> {
  const choice = await vscode.window.showErrorMessage(message, 'Open Settings');
  if (choice === 'Open Settings') {
    await vscode.commands.executeCommand('workbench.action.openSettings', 'rl1.');
  }
}

/** Where a tool of the rl1 package is, by its setting or beside the language server. */
function tool(name: Tool): string {
  const folder = vscode.workspace.workspaceFolders?.[0]?.uri.fsPath;
  const server = vscode.workspace.getConfiguration('rl1.server');
  return toolPath(
    name,
    vscode.workspace.getConfiguration().get(TOOL_SETTINGS[name]),
    serverCommand(server.get('path'), server.get('args'), folder).command,
    folder,
  );
}

function rl1c(): string {
  return tool('rl1c');
}

/** The RL/I file in the active editor, saved so that rl1c reads what the user sees. */
async function currentFile(): Promise<string | undefined> {
  const document = vscode.window.activeTextEditor?.document;
  if (document === undefined || document.languageId !== 'rl1' || document.uri.scheme !== 'file') {
    void vscode.window.showErrorMessage('RL/I: open an RL/I file (.rob) saved on disk first.');
    return undefined;
  }
  if (document.isDirty && !(await document.save())) {
    void vscode.window.showErrorMessage(`RL/I: ${path.basename(document.fileName)} could not be saved.`);
    return undefined;
  }
  return document.fileName;
}

/** A task for a definition, or undefined after telling the user what is wrong with it. */
function buildTask(definition: vscode.TaskDefinition, scope: vscode.TaskScope | vscode.WorkspaceFolder): vscode.Task | undefined {
  try {
    const request = taskRequest(definition, vscode.window.activeTextEditor?.document.fileName);
    const line = taskCommandLine(rl1c(), request);
    return new vscode.Task(
      definition,
      scope,
      `${request.command} ${path.basename(request.file)}`,
      'rl1c',
      new vscode.ProcessExecution(line.command, line.args),
      request.command === 'check' ? ['$rl1c'] : [],
    );
  } catch (error) {
    report(error);
    return undefined;
  }
}

function providedTasks(): vscode.Task[] {
  const document = vscode.window.activeTextEditor?.document;
  if (document?.languageId !== 'rl1' || document.uri.scheme !== 'file') {
    return [];
  }
  const scope = vscode.workspace.getWorkspaceFolder(document.uri) ?? vscode.TaskScope.Workspace;
  return (['check', 'compile'] as const)
    .map((command) => buildTask({ type: TASK_TYPE, command, file: document.fileName }, scope))
    .filter((task): task is vscode.Task => task !== undefined);
}

function resolvedTask(task: vscode.Task): vscode.Task | undefined {
  return buildTask(task.definition, task.scope ?? vscode.TaskScope.Workspace);
}

async function runTask(command: TaskCommand): Promise<void> {
  const file = await currentFile();
  if (file !== undefined) {
    await startTask({ type: TASK_TYPE, command, file });
  }
}

async function runWithSensors(): Promise<void> {
  const file = await currentFile();
  if (file === undefined) {
    return;
  }
  const picked = await vscode.window.showOpenDialog({
    title: 'RL/I: the sensor script to run with',
    openLabel: 'Run with this script',
    defaultUri: vscode.Uri.file(path.dirname(file)),
    filters: { 'Sensor scripts': ['json', 'toml'] },
  });
  if (picked?.[0] !== undefined) {
    await startTask({ type: TASK_TYPE, command: 'run', file, sensors: picked[0].fsPath });
  }
}

async function startTask(definition: vscode.TaskDefinition & { file: string }): Promise<vscode.TaskExecution | undefined> {
  const scope = vscode.workspace.getWorkspaceFolder(vscode.Uri.file(definition.file)) ?? vscode.TaskScope.Workspace;
  const task = buildTask(definition, scope);
  return task === undefined ? undefined : await vscode.tasks.executeTask(task);
}

async function showDisassembly(): Promise<void> {
  const file = await currentFile();
  if (file === undefined) {
    return;
  }
  const view = disassemblyUri(file);
  disassemblyChanged.fire(view); // an open view is brought up to date
  await vscode.window.showTextDocument(view, { preview: false, viewColumn: vscode.ViewColumn.Beside });
}

function disassemblyUri(source: string): vscode.Uri {
  return vscode.Uri.file(source + DISASSEMBLY_SUFFIX).with({ scheme: DISASSEMBLY_SCHEME });
}

/** The view's text: what `rl1c dis` shows, or, as an .ils comment, why there is none. */
async function disassembly(view: vscode.Uri): Promise<string> {
  const source = view.with({ scheme: 'file' }).fsPath.slice(0, -DISASSEMBLY_SUFFIX.length);
  try {
    return await disassemble(rl1c(), source);
  } catch (error) {
    if (error instanceof Rl1cError || error instanceof SettingError) {
      return `; RL/I: ${error.message}.\n`;
    }
    throw error;
  }
}

/**
 * A launch configuration to start: launch.json's as written, or, when there is none
 * (F5 on an RL/I file), the file in the world or with the sensor script beside it.
 */
function resolvedLaunch(configuration: vscode.DebugConfiguration): vscode.DebugConfiguration | undefined {
  if (configuration.type !== undefined || configuration.request !== undefined) {
    return configuration;
  }
  const document = vscode.window.activeTextEditor?.document;
  if (document?.languageId !== 'rl1' || document.uri.scheme !== 'file') {
    void vscode.window.showErrorMessage('RL/I: open an RL/I file (.rob) saved on disk to debug it, or add a launch.json.');
    return undefined;
  }
  const launch = launchForFile(document.fileName, fs.existsSync);
  if (launch === undefined) {
    void vscode.window.showErrorMessage(
      `RL/I: ${path.basename(document.fileName)} has no world or sensor script beside it ` +
        '(NAME.world.toml, NAME.sensors.toml): add one, or a launch.json (Add Configuration… offers both).',
    );
  }
  return launch;
}

/** RL/I: Simulate: `rl1c sim` on the current file in a world, in a terminal; then offers the replay. */
async function simulate(): Promise<void> {
  const file = await currentFile();
  if (file === undefined) {
    return;
  }
  const folder = vscode.workspace.workspaceFolders?.[0]?.uri.fsPath;
  let world;
  try {
    world = worldFor(file, vscode.workspace.getConfiguration().get(WORLD_SETTING), folder, fs.existsSync);
  } catch (error) {
    report(error);
    return;
  }
  if (world === undefined) {
    const picked = await vscode.window.showOpenDialog({
      title: `RL/I: the world to simulate ${path.basename(file)} in (set ${WORLD_SETTING}, or put NAME.world.toml beside it)`,
      openLabel: 'Simulate in this world',
      defaultUri: vscode.Uri.file(path.dirname(file)),
      filters: { 'World files': ['toml'] },
    });
    world = picked?.[0]?.fsPath;
    if (world === undefined) {
      return;
    }
  }
  // Listening before the task starts: a short run can end before executeTask returns.
  const ended = vscode.tasks.onDidEndTaskProcess(async (end) => {
    const { definition } = end.execution.task;
    if (definition.type !== TASK_TYPE || definition.command !== 'sim' || definition.file !== file) {
      return;
    }
    ended.dispose();
    if (wroteReplay(end.exitCode)) {
      const replay = replayFor(file);
      const choice = await vscode.window.showInformationMessage(
        `RL/I: the run's replay is in ${path.basename(replay)}.`,
        'Open Replay',
      );
      if (choice === 'Open Replay') {
        await vscode.env.openExternal(vscode.Uri.file(replay));
      }
    }
  });
  if ((await startTask({ type: TASK_TYPE, command: 'sim', file, world })) === undefined) {
    ended.dispose();
  }
}
