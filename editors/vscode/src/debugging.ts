// The debugger of type `rl1` (the `rl1-dap` adapter) and the Simulate command: the
// launch configuration for a file, the world a simulation runs in, and `rl1c sim`'s
// command line. Kept free of the `vscode` module so node can test it.

import * as path from 'node:path';
import { expand, CommandLine, SettingError } from './serverCommand';

export const DEBUG_TYPE = 'rl1';

/** The setting naming the world that RL/I: Simulate runs in. */
export const WORLD_SETTING = 'rl1.simulate.world';

/** A launch configuration of `rl1-dap` (lsp/dap.py's launch arguments). */
export interface LaunchConfiguration {
  type: string;
  request: string;
  name: string;
  program: string;
  sensors?: string;
  world?: string;
  level?: number;
  [other: string]: unknown;
}

/** The file beside `file` of the same name with `suffix` in place of its extension. */
export function beside(file: string, suffix: string): string {
  return path.join(path.dirname(file), path.basename(file, path.extname(file)) + suffix);
}

/**
 * The configuration F5 starts when launch.json has none: the file at level 0 (at -O1
 * the dead-store pass leaves variables stale in a debugger), in the world beside it
 * (`NAME.world.toml`), else with the sensor script beside it (`NAME.sensors.toml` or
 * `.json`), else undefined: there is nothing to run it on.
 */
export function launchForFile(file: string, exists: (file: string) => boolean): LaunchConfiguration | undefined {
  const name = path.basename(file);
  const world = beside(file, '.world.toml');
  if (exists(world)) {
    return { type: DEBUG_TYPE, request: 'launch', name: `Debug ${name} in its world`, program: file, world, level: 0 };
  }
  const sensors = ['.sensors.toml', '.sensors.json'].map((suffix) => beside(file, suffix)).find(exists);
  if (sensors !== undefined) {
    return { type: DEBUG_TYPE, request: 'launch', name: `Debug ${name} with its sensor script`, program: file, sensors, level: 0 };
  }
  return undefined;
}

/**
 * The world RL/I: Simulate runs `file` in: the setting `rl1.simulate.world` when given
 * (expanded as the other path settings), else `NAME.world.toml` beside the file when it
 * exists, else undefined (the user picks one).
 */
export function worldFor(
  file: string,
  setting: unknown,
  workspaceFolder: string | undefined,
  exists: (file: string) => boolean,
): string | undefined {
  if (setting !== undefined && setting !== null && typeof setting !== 'string') {
    throw new SettingError(
      `${WORLD_SETTING} must be the path of a world file such as "\${workspaceFolder}/examples/sample.world.toml", ` +
        `not ${JSON.stringify(setting)}`,
    );
  }
  const written = (setting ?? '').trim();
  if (written !== '') {
    return expand(WORLD_SETTING, written, workspaceFolder);
  }
  const next = beside(file, '.world.toml');
  return exists(next) ? next : undefined;
}

/** Where a simulation of `file` writes its replay: `NAME.replay.html` beside it. */
export function replayFor(file: string): string {
  return beside(file, '.replay.html');
}

/** `rl1c sim FILE --world WORLD --html REPLAY`: the run, printed, and its replay page. */
export function simulateCommandLine(rl1c: string, file: string, world: string): CommandLine {
  return { command: rl1c, args: ['sim', file, '--world', world, '--html', replayFor(file)] };
}

/**
 * Whether `rl1c sim` wrote its replay, by its exit status: 0 the program ended, 20 it
 * ended but missed the world's goal, 10 to 13 a fault (the run up to it is replayed);
 * 1 (errors in the program) and 2 (an unusable file) write nothing.
 */
export function wroteReplay(status: number | undefined): boolean {
  return status === 0 || status === 20 || (status !== undefined && status >= 10 && status <= 13);
}
