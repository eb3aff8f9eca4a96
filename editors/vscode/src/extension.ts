// The VS Code side of RL/I: highlighting comes from the TextMate grammar alone; this
// starts the `rl1-lsp` language server for diagnostics, hover and completion.

import * as vscode from 'vscode';
import { LanguageClient, LanguageClientOptions, ServerOptions } from 'vscode-languageclient/node';
import { DEFAULT_SERVER, serverCommand, SettingError } from './serverCommand';

let client: LanguageClient | undefined;
let output: vscode.LogOutputChannel | undefined;

export async function activate(context: vscode.ExtensionContext): Promise<void> {
  output = vscode.window.createOutputChannel('RL/I', { log: true });
  context.subscriptions.push(
    output,
    vscode.commands.registerCommand('rl1.restartServer', restart),
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
        ? `install the rl1 Python package (\`pip install -e .\` in the rl1 project) so that ` +
          `${DEFAULT_SERVER} is on PATH, or set rl1.server.path to its full path`
        : 'check rl1.server.path';
    void offerSettings(
      `RL/I: the language server "${server.command}" did not start (${reason}). ` +
        `Highlighting still works; for diagnostics ${where}.`,
    );
  }
}

async function offerSettings(message: string): Promise<void> {
  const choice = await vscode.window.showErrorMessage(message, 'Open Settings');
  if (choice === 'Open Settings') {
    await vscode.commands.executeCommand('workbench.action.openSettings', 'rl1.server');
  }
}
