import * as assert from 'node:assert/strict';
import * as os from 'node:os';
import * as path from 'node:path';
import { test } from 'node:test';
import { serverCommand, SettingError } from '../serverCommand';

test('unset or blank settings start rl1-lsp from PATH with no arguments', () => {
  for (const unset of [undefined, null, '', '   ']) {
    assert.deepEqual(serverCommand(unset, undefined, undefined), { command: 'rl1-lsp', args: [] });
  }
});

test('a path and arguments are used as written', () => {
  assert.deepEqual(serverCommand('/opt/rl1/bin/rl1-lsp', ['--stdio'], undefined), {
    command: '/opt/rl1/bin/rl1-lsp',
    args: ['--stdio'],
  });
});

test('~ and ${workspaceFolder} are expanded', () => {
  assert.equal(
    serverCommand('${workspaceFolder}/.venv/bin/rl1-lsp', [], '/work/robot').command,
    '/work/robot/.venv/bin/rl1-lsp',
  );
  assert.equal(
    serverCommand('~/rl1/.venv/bin/rl1-lsp', [], undefined).command,
    path.join(os.homedir(), 'rl1/.venv/bin/rl1-lsp'),
  );
});

test('settings of the wrong kind are refused with a message naming the setting', () => {
  assert.throws(() => serverCommand(42, [], undefined), SettingError);
  assert.throws(() => serverCommand('rl1-lsp', '--stdio', undefined), /rl1\.server\.args must be a list of strings/);
  assert.throws(() => serverCommand('rl1-lsp', ['-v', 3], undefined), SettingError);
  assert.throws(
    () => serverCommand('${workspaceFolder}/rl1-lsp', [], undefined),
    /no folder is open/,
  );
});
