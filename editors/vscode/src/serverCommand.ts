// How the settings `rl1.server.path` and `rl1.server.args` become the command that
// starts the language server. Kept free of the `vscode` module so node can test it.

import * as os from 'node:os';
import * as path from 'node:path';

export const DEFAULT_SERVER = 'rl1-lsp';

/** A program and its arguments, run without a shell. */
export interface CommandLine {
  command: string;
  args: string[];
}

/** A setting that cannot be used; the message says which one and what to write. */
export class SettingError extends Error {}

/**
 * The command for the settings' raw values (settings.json may hold any JSON).
 * An empty path means the default `rl1-lsp` on PATH; `~/` and `${workspaceFolder}`
 * are expanded because a project's own `.venv/bin/rl1-lsp` is the usual choice.
 */
export function serverCommand(
  pathSetting: unknown,
  argsSetting: unknown,
  workspaceFolder: string | undefined,
): CommandLine {
  if (pathSetting !== undefined && pathSetting !== null && typeof pathSetting !== 'string') {
    throw new SettingError(
      `rl1.server.path must be a string such as "${DEFAULT_SERVER}", not ${JSON.stringify(pathSetting)}`,
    );
  }
  if (argsSetting !== undefined && argsSetting !== null && !isStringArray(argsSetting)) {
    throw new SettingError(
      `rl1.server.args must be a list of strings such as ["--log-level", "debug"], ` +
        `not ${JSON.stringify(argsSetting)}`,
    );
  }
  const written = (pathSetting ?? '').trim();
  return {
    command: written === '' ? DEFAULT_SERVER : expand('rl1.server.path', written, workspaceFolder),
    args: argsSetting ?? [],
  };
}

function isStringArray(value: unknown): value is string[] {
  return Array.isArray(value) && value.every((item) => typeof item === 'string');
}

/** A path setting with `~/` and `${workspaceFolder}` expanded; `setting` names it in errors. */
export function expand(setting: string, written: string, workspaceFolder: string | undefined): string {
  let expanded = written;
  if (expanded.includes('${workspaceFolder}')) {
    if (workspaceFolder === undefined) {
      throw new SettingError(
        `${setting} "${written}" uses \${workspaceFolder}, but no folder is open: ` +
          'open the project folder, or write the full path',
      );
    }
    expanded = expanded.split('${workspaceFolder}').join(workspaceFolder);
  }
  if (expanded === '~' || expanded.startsWith('~/')) {
    expanded = path.join(os.homedir(), expanded.slice(1));
  }
  return expanded;
}
