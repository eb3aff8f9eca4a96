// The command lines of `rl1c` behind the extension's commands and its `rl1` task type,
// and the two-step disassembly. Kept free of the `vscode` module so node can test it.

import { execFile } from 'node:child_process';
import * as fs from 'node:fs/promises';
import * as os from 'node:os';
import * as path from 'node:path';
import { simulateCommandLine } from './debugging';
import { CommandLine, expand, SettingError } from './serverCommand';

/** Every command the extension contributes; package.json declares the same list. */
export const COMMANDS = [
  'rl1.restartServer',
  'rl1.check',
  'rl1.compile',
  'rl1.run',
  'rl1.showDisassembly',
  'rl1.simulate',
] as const;
export type CommandId = (typeof COMMANDS)[number];

export const TASK_TYPE = 'rl1';
export const TASK_COMMANDS = ['check', 'compile', 'run', 'sim'] as const;
export type TaskCommand = (typeof TASK_COMMANDS)[number];

/** The commands of the rl1 package the extension runs besides the language server. */
export type Tool = 'rl1c' | 'rl1-dap';

/** The setting that names each tool's path. */
export const TOOL_SETTINGS: Record<Tool, string> = { rl1c: 'rl1.rl1c.path', 'rl1-dap': 'rl1.dap.path' };

/**
 * Where a tool of the rl1 package is: its setting (`rl1.rl1c.path`, `rl1.dap.path`)
 * when given, else beside the language server when that is given as a path (all come
 * from the same Python environment), else the tool on PATH.
 */
export function toolPath(tool: Tool, setting: unknown, serverCommand: string, workspaceFolder: string | undefined): string {
  const name = TOOL_SETTINGS[tool];
  if (setting !== undefined && setting !== null && typeof setting !== 'string') {
    throw new SettingError(
      `${name} must be a string such as "/path/to/rl1/.venv/bin/${tool}", not ${JSON.stringify(setting)}`,
    );
  }
  const written = (setting ?? '').trim();
  if (written !== '') {
    return expand(name, written, workspaceFolder);
  }
  if (path.basename(serverCommand) === serverCommand) {
    return tool;
  }
  // `rl1-lsp.exe` in a Windows virtual environment sits beside `rl1c.exe`.
  return path.join(path.dirname(serverCommand), tool + path.extname(serverCommand));
}

/** What a task of type `rl1` in tasks.json asks for; settings.json may hold any JSON. */
export interface TaskRequest {
  command: TaskCommand;
  file: string;
  sensors?: string;
  world?: string;
}

/** A task definition that cannot be run; the message says which property and what to write. */
export class TaskError extends Error {}

/** The task request for a definition's raw values; `file` defaults to the current file. */
export function taskRequest(definition: Record<string, unknown>, currentFile: string | undefined): TaskRequest {
  const { command, file, sensors, world } = definition;
  if (typeof command !== 'string' || !(TASK_COMMANDS as readonly string[]).includes(command)) {
    throw new TaskError(
      `an rl1 task's "command" must be one of ${TASK_COMMANDS.map((name) => `"${name}"`).join(', ')}, ` +
        `not ${JSON.stringify(command)}`,
    );
  }
  if (file !== undefined && typeof file !== 'string') {
    throw new TaskError(`an rl1 task's "file" must be a path such as "\${file}", not ${JSON.stringify(file)}`);
  }
  const target = file ?? currentFile;
  if (target === undefined) {
    throw new TaskError(`the rl1 "${command}" task needs a file: open an RL/I file, or give "file" in tasks.json`);
  }
  if (command === 'sim') {
    if (typeof world !== 'string' || world === '') {
      throw new TaskError(
        'the rl1 "sim" task needs "world", the world file (TOML), ' +
          'e.g. "${workspaceFolder}/examples/sample.world.toml"',
      );
    }
    return { command: 'sim', file: target, world };
  }
  if (command !== 'run') {
    return { command: command as TaskCommand, file: target };
  }
  if (typeof sensors !== 'string' || sensors === '') {
    throw new TaskError(
      'the rl1 "run" task needs "sensors", the sensor script (JSON or TOML), ' +
        'e.g. "${workspaceFolder}/examples/sample.sensors.json"',
    );
  }
  return { command: 'run', file: target, sensors };
}

/** The `rl1c` command line of a task; check's concise lines are what the `$rl1c` problem matcher reads. */
export function taskCommandLine(rl1c: string, request: TaskRequest): CommandLine {
  switch (request.command) {
    case 'check':
      return { command: rl1c, args: ['check', '--format', 'concise', request.file] };
    case 'compile':
      return { command: rl1c, args: [request.file] };
    case 'run':
      return { command: rl1c, args: ['run', request.file, '--sensors', request.sensors ?? ''] };
    case 'sim':
      return simulateCommandLine(rl1c, request.file, request.world ?? '');
  }
}

export interface Finished {
  status: number;
  stdout: string;
  stderr: string;
}

/** Runs a command line to its end; `status` is its exit status. */
export type Runner = (line: CommandLine) => Promise<Finished>;

/** Something `rl1c` refused or could not do; the message says what and what to do. */
export class Rl1cError extends Error {}

/**
 * The `.ils` text of a source file: `rl1c FILE -o TMP.ilc`, then `rl1c dis TMP.ilc
 * --source FILE`, in a temporary folder that is removed afterwards.
 */
export async function disassemble(rl1c: string, source: string, run: Runner = runProcess): Promise<string> {
  const folder = await fs.mkdtemp(path.join(os.tmpdir(), 'rl1-dis-'));
  try {
    const ilc = path.join(folder, path.basename(source, path.extname(source)) + '.ilc');
    const compiled = await run({ command: rl1c, args: [source, '-o', ilc] });
    if (compiled.status !== 0) {
      throw new Rl1cError(
        `${path.basename(source)} did not compile (rl1c exit ${compiled.status}): ` +
          `${firstLine(compiled.stderr)}; RL/I: Check lists its problems`,
      );
    }
    const shown = await run({ command: rl1c, args: ['dis', ilc, '--source', source] });
    if (shown.status !== 0) {
      throw new Rl1cError(`rl1c dis failed (exit ${shown.status}): ${firstLine(shown.stderr)}`);
    }
    return shown.stdout;
  } finally {
    await fs.rm(folder, { recursive: true, force: true });
  }
}

function firstLine(text: string): string {
  return text.trim().split('\n', 1)[0] || 'no message';
}

function runProcess(line: CommandLine): Promise<Finished> {
  return new Promise((resolve, reject) => {
    execFile(line.command, line.args, { maxBuffer: 64 * 1024 * 1024 }, (error, stdout, stderr) => {
      if (error !== null && typeof error.code !== 'number') {
        const reason = error.code === 'ENOENT' ? 'was not found' : `did not start (${error.message})`;
        reject(
          new Rl1cError(
            `"${line.command}" ${reason}: install the rl1 package (pipx install /path/to/rl1), ` +
              'or set rl1.rl1c.path to its full path',
          ),
        );
        return;
      }
      resolve({ status: error === null ? 0 : Number(error.code), stdout, stderr });
    });
  });
}
