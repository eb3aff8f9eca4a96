import * as assert from 'node:assert/strict';
import * as fs from 'node:fs';
import * as path from 'node:path';
import { test } from 'node:test';
import { disassemble, Finished, Rl1cError, taskCommandLine, TaskError, taskRequest, toolPath } from '../rl1cCommand';
import { CommandLine, SettingError } from '../serverCommand';

test('rl1c is found beside a server given as a path, else on PATH', () => {
  assert.equal(toolPath('rl1c', undefined, 'rl1-lsp', undefined), 'rl1c');
  assert.equal(toolPath('rl1c', '', '/work/robot/.venv/bin/rl1-lsp', undefined), path.join('/work/robot/.venv/bin', 'rl1c'));
  assert.equal(toolPath('rl1c', null, '/venv/Scripts/rl1-lsp.exe', undefined), path.join('/venv/Scripts', 'rl1c.exe'));
});

test('rl1.rl1c.path wins, expanded as rl1.server.path is', () => {
  assert.equal(toolPath('rl1c', '${workspaceFolder}/bin/rl1c', '/elsewhere/rl1-lsp', '/work/robot'), '/work/robot/bin/rl1c');
  assert.throws(() => toolPath('rl1c', 7, 'rl1-lsp', undefined), /rl1\.rl1c\.path must be a string/);
  assert.throws(() => toolPath('rl1c', '${workspaceFolder}/rl1c', 'rl1-lsp', undefined), SettingError);
});

test('each task runs the rl1c command line for its file', () => {
  assert.deepEqual(taskCommandLine('rl1c', taskRequest({ command: 'check' }, '/r/a.rob')), {
    command: 'rl1c',
    args: ['check', '--format', 'concise', '/r/a.rob'],
  });
  assert.deepEqual(taskCommandLine('/v/rl1c', taskRequest({ command: 'compile', file: '/r/b.rob' }, '/r/a.rob')), {
    command: '/v/rl1c',
    args: ['/r/b.rob'],
  });
  assert.deepEqual(taskCommandLine('rl1c', taskRequest({ command: 'run', sensors: '/r/s.toml' }, '/r/a.rob')), {
    command: 'rl1c',
    args: ['run', '/r/a.rob', '--sensors', '/r/s.toml'],
  });
  assert.deepEqual(taskCommandLine('rl1c', taskRequest({ command: 'sim', world: '/r/w.toml' }, '/r/a.rob')), {
    command: 'rl1c',
    args: ['sim', '/r/a.rob', '--world', '/r/w.toml', '--html', path.join('/r', 'a.replay.html')],
  });
});

test('task definitions that cannot run are refused with what to write', () => {
  assert.throws(() => taskRequest({ command: 'fmt' }, '/r/a.rob'), /"command" must be one of "check", "compile", "run", "sim", not "fmt"/);
  assert.throws(() => taskRequest({ command: 'check', file: 3 }, '/r/a.rob'), /"file" must be a path/);
  assert.throws(() => taskRequest({ command: 'check' }, undefined), /open an RL\/I file, or give "file"/);
  assert.throws(() => taskRequest({ command: 'run' }, '/r/a.rob'), TaskError);
  assert.throws(() => taskRequest({ command: 'sim' }, '/r/a.rob'), /the rl1 "sim" task needs "world"/);
});

/** A stand-in for rl1c that records its command lines and answers with `answers` in turn. */
function fakeRl1c(answers: Finished[]): { calls: CommandLine[]; run: (line: CommandLine) => Promise<Finished> } {
  const calls: CommandLine[] = [];
  return {
    calls,
    run: async (line) => {
      calls.push(line);
      return answers[calls.length - 1];
    },
  };
}

test('the disassembly compiles to a temporary .ilc, disassembles it with the source, then removes it', async () => {
  const rl1c = fakeRl1c([
    { status: 0, stdout: '', stderr: 'warning[W0301]: ...' },
    { status: 0, stdout: '; sample.ilc\n.features MOTION\n', stderr: '' },
  ]);
  const text = await disassemble('/v/rl1c', '/r/sample.rob', rl1c.run);
  assert.equal(text, '; sample.ilc\n.features MOTION\n');
  const [compile, dis] = rl1c.calls;
  const ilc = compile.args[2];
  assert.deepEqual(compile, { command: '/v/rl1c', args: ['/r/sample.rob', '-o', ilc] });
  assert.equal(path.basename(ilc), 'sample.ilc');
  assert.deepEqual(dis, { command: '/v/rl1c', args: ['dis', ilc, '--source', '/r/sample.rob'] });
  assert.equal(fs.existsSync(path.dirname(ilc)), false);
});

test('a program that does not compile is not disassembled, and the message says why', async () => {
  const rl1c = fakeRl1c([{ status: 1, stdout: '', stderr: 'error[E0100]: unexpected `*`\n  --> a.rob:1:3\n' }]);
  await assert.rejects(
    disassemble('rl1c', '/r/a.rob', rl1c.run),
    (error: Error) =>
      error instanceof Rl1cError &&
      error.message === 'a.rob did not compile (rl1c exit 1): error[E0100]: unexpected `*`; RL/I: Check lists its problems',
  );
  assert.equal(rl1c.calls.length, 1);
  assert.equal(fs.existsSync(path.dirname(rl1c.calls[0].args[2])), false);
});

test('an rl1c that is not there is named, with what to do', async () => {
  await assert.rejects(disassemble('/nonexistent/rl1c', '/r/a.rob'), /"\/nonexistent\/rl1c" was not found: install the rl1 package/);
});
