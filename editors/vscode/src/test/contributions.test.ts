// What package.json declares is what the extension does: each command has a handler,
// the task type and the problem matcher read what rl1c prints.

import * as assert from 'node:assert/strict';
import * as fs from 'node:fs';
import * as path from 'node:path';
import { test } from 'node:test';
import { DebugAdapterExecutable, ProcessExecution, registered, Task } from './fakeVscode';
import { activate } from '../extension';
import { DEBUG_TYPE } from '../debugging';
import { COMMANDS, TASK_COMMANDS, TASK_TYPE } from '../rl1cCommand';
import { PACKAGE_ROOT } from './textmate';

const contributes = JSON.parse(fs.readFileSync(path.join(PACKAGE_ROOT, 'package.json'), 'utf8')).contributes;
const activated = activate({ subscriptions: [] } as never);

test('activating registers a handler for every command package.json declares, and no other', async () => {
  await activated;
  const declared = contributes.commands.map((command: { command: string }) => command.command);
  assert.deepEqual([...registered.commands.keys()].sort(), [...declared].sort());
  assert.deepEqual([...COMMANDS].sort(), [...declared].sort());
  assert.deepEqual([...registered.taskProviders.keys()], [TASK_TYPE]);
});

test('the commands that act on a file say so when no RL/I file is open', async () => {
  await activated;
  for (const id of ['rl1.check', 'rl1.compile', 'rl1.run', 'rl1.showDisassembly', 'rl1.simulate']) {
    registered.errors.length = 0;
    await registered.commands.get(id)?.();
    assert.deepEqual(registered.errors, ['RL/I: open an RL/I file (.rob) saved on disk first.'], id);
  }
});

test('a check task from tasks.json runs rl1c check --format concise under the $rl1c matcher', async () => {
  await activated;
  const provider = registered.taskProviders.get(TASK_TYPE);
  const task = provider?.resolveTask({ definition: { type: TASK_TYPE, command: 'check', file: '/r/a.rob' } });
  assert.ok(task instanceof Task);
  assert.deepEqual(task.execution, new ProcessExecution('rl1c', ['check', '--format', 'concise', '/r/a.rob']));
  assert.deepEqual(task.problemMatchers, ['$rl1c']);
  assert.equal(task.name, 'check a.rob');
});

test('a run task without a sensor script is refused with what to write', async () => {
  await activated;
  registered.errors.length = 0;
  const provider = registered.taskProviders.get(TASK_TYPE);
  assert.equal(provider?.resolveTask({ definition: { type: TASK_TYPE, command: 'run', file: '/r/a.rob' } }), undefined);
  assert.match(registered.errors.join('\n'), /the rl1 "run" task needs "sensors"/);
});

test('the debugger of type rl1 runs rl1-dap, found as rl1c is', async () => {
  await activated;
  assert.deepEqual([...registered.debugAdapters.keys()], [DEBUG_TYPE]);
  const descriptor = registered.debugAdapters.get(DEBUG_TYPE)?.createDebugAdapterDescriptor({});
  assert.deepEqual(descriptor, new DebugAdapterExecutable('rl1-dap', []));
});

test('a launch.json configuration is started as written; none without an RL/I file says what to do', async () => {
  await activated;
  const provider = registered.debugConfigurations.get(DEBUG_TYPE);
  const written = { type: DEBUG_TYPE, request: 'launch', name: 'x', program: '/r/a.rob', sensors: '/r/s.toml' };
  assert.equal(provider?.resolveDebugConfiguration(undefined, written), written);
  registered.errors.length = 0;
  assert.equal(provider?.resolveDebugConfiguration(undefined, {}), undefined);
  assert.match(registered.errors.join('\n'), /open an RL\/I file \(\.rob\) saved on disk to debug it, or add a launch\.json/);
});

test('the task type declares the commands the task provider runs', () => {
  const [definition] = contributes.taskDefinitions;
  assert.equal(definition.type, TASK_TYPE);
  assert.deepEqual(definition.properties.command.enum, [...TASK_COMMANDS]);
});

interface Pattern {
  regexp: string;
  file: number;
  line: number;
  column: number;
  severity: number;
  code: number;
  message: number;
}

function matched(line: string): Record<string, string> | undefined {
  const [matcher] = contributes.problemMatchers;
  const pattern: Pattern = matcher.pattern;
  const found = new RegExp(pattern.regexp).exec(line);
  if (found === null) {
    return undefined;
  }
  const fields = ['file', 'line', 'column', 'severity', 'code', 'message'] as const;
  return Object.fromEntries(fields.map((field) => [field, found[pattern[field]]]));
}

test('the $rl1c problem matcher reads each part of a concise line', () => {
  assert.deepEqual(matched('examples/sample.rob:12:5: warning[W0301]: a lost line can jump to `:97`: add it'), {
    file: 'examples/sample.rob',
    line: '12',
    column: '5',
    severity: 'warning',
    code: 'W0301',
    message: 'a lost line can jump to `:97`: add it',
  });
  assert.deepEqual(matched('C:\\robots\\line 2.rob:3:17: error[E0100]: unexpected `*`'), {
    file: 'C:\\robots\\line 2.rob',
    line: '3',
    column: '17',
    severity: 'error',
    code: 'E0100',
    message: 'unexpected `*`',
  });
  assert.equal(matched('a.rob:1:1: info[I0001]: note')?.severity, 'info');
});

test('the $rl1c problem matcher skips what is no concise diagnostic', () => {
  for (const line of [
    '3 files checked: 0 errors, 1 warning',
    'warning[W0301]: a lost guidance line can jump to `:97` here',
    '  --> examples/sample.rob:40:1',
    'a.rob:1:1: note[W0301]: not a severity',
  ]) {
    assert.equal(matched(line), undefined, line);
  }
});
