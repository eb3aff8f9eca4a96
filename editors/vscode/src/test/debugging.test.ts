// The debugger of type `rl1` as package.json declares it, held to what `rl1-dap`
// (lsp/dap.py) accepts, and the pure parts of F5 without a launch.json and of Simulate.

import * as assert from 'node:assert/strict';
import * as fs from 'node:fs';
import * as path from 'node:path';
import { test } from 'node:test';
import { DEBUG_TYPE, launchForFile, replayFor, simulateCommandLine, WORLD_SETTING, worldFor, wroteReplay } from '../debugging';
import { TOOL_SETTINGS } from '../rl1cCommand';
import { SettingError } from '../serverCommand';
import { PACKAGE_ROOT } from './textmate';

const contributes = JSON.parse(fs.readFileSync(path.join(PACKAGE_ROOT, 'package.json'), 'utf8')).contributes;
const [debuggerContribution] = contributes.debuggers;
const launch = debuggerContribution.configurationAttributes.launch;
const DAP_SOURCE = fs.readFileSync(path.join(PACKAGE_ROOT, '..', '..', 'lsp', 'dap.py'), 'utf8');

/** The body of a function of lsp/dap.py, up to the next definition. */
function pythonFunction(name: string): string {
  const start = DAP_SOURCE.indexOf(`def ${name}(`);
  assert.ok(start >= 0, `lsp/dap.py has no ${name}`);
  const end = DAP_SOURCE.slice(start + 1).search(/\n\s*def /);
  return end < 0 ? DAP_SOURCE.slice(start) : DAP_SOURCE.slice(start, start + 1 + end);
}

/** The launch arguments rl1-dap reads: those its launch request and what it calls take. */
function dapLaunchArguments(): string[] {
  const body = ['_on_launch', '_image', '_device_maker'].map(pythonFunction).join('\n');
  const names = [...body.matchAll(/(?:arguments\.get|_text)\(\s*(?:arguments,\s*)?"(\w+)"/g)].map((found) => found[1]);
  return [...new Set(names)].sort();
}

test('the launch attributes are exactly the arguments rl1-dap reads', () => {
  const read = dapLaunchArguments();
  assert.ok(read.includes('program') && read.includes('world'), `read from lsp/dap.py: ${read}`);
  assert.deepEqual(Object.keys(launch.properties).sort(), read);
  assert.deepEqual(launch.required, ['program']);
});

test('each launch attribute has the type rl1-dap accepts', () => {
  const types = Object.fromEntries(
    Object.entries(launch.properties).map(([name, property]) => [name, (property as { type: string }).type]),
  );
  assert.deepEqual(types, {
    program: 'string',
    sensors: 'string',
    world: 'string',
    level: 'integer',
    seed: 'integer',
    budget: 'integer',
    stopOnEntry: 'boolean',
  });
  const levels = /level in \(([^)]*)\)/.exec(pythonFunction('_image'));
  assert.ok(levels !== null, 'lsp/dap.py names the levels it accepts');
  assert.deepEqual(launch.properties.level.enum, levels[1].split(',').map((level) => Number(level.trim())));
  assert.equal(launch.properties.level.default, 0);
  assert.equal(launch.properties.budget.minimum, 1);
});

test('the debugger runs for RL/I files, and breakpoints can be set in them', () => {
  assert.equal(debuggerContribution.type, DEBUG_TYPE);
  assert.deepEqual(debuggerContribution.languages, ['rl1']);
  assert.deepEqual(contributes.breakpoints, [{ language: 'rl1' }]);
});

/** A snippet's body with its escapes (`^"\${file}"`) read as launch.json would hold them. */
function unescaped(body: Record<string, unknown>): Record<string, unknown> {
  return Object.fromEntries(
    Object.entries(body).map(([key, value]) => [
      key,
      typeof value === 'string' ? value.replace(/^\^"(.*)"$/, '$1').replace(/\\\$/g, '$') : value,
    ]),
  );
}

test('the initial configurations and the snippets launch the file in a world and with a sensor script, at level 0', () => {
  const configurations: Record<string, unknown>[] = debuggerContribution.initialConfigurations;
  const snippets: { label: string; body: Record<string, unknown> }[] = debuggerContribution.configurationSnippets;
  assert.deepEqual(
    snippets.map((snippet) => unescaped(snippet.body)),
    configurations,
  );
  const devices = configurations.map((configuration) => ('world' in configuration ? 'world' : 'sensors'));
  assert.deepEqual(devices.sort(), ['sensors', 'world']);
  for (const configuration of configurations) {
    const { type, request, name, ...attributes } = configuration;
    assert.equal(type, DEBUG_TYPE);
    assert.equal(request, 'launch');
    assert.equal(typeof name, 'string');
    assert.equal(attributes.program, '${file}');
    assert.equal(attributes.level, 0, `${name}: at -O1 the dead-store pass leaves variables stale`);
    assert.ok(!('world' in attributes && 'sensors' in attributes), `${name}: rl1-dap takes one device`);
    for (const key of Object.keys(attributes)) {
      assert.ok(key in launch.properties, `${name}: ${key} is no launch attribute`);
    }
  }
  for (const snippet of snippets) {
    assert.equal(snippet.label, snippet.body.name);
  }
});

test('the settings the debugger and Simulate read are declared', () => {
  const declared = contributes.configuration.properties;
  for (const setting of [...Object.values(TOOL_SETTINGS), WORLD_SETTING]) {
    assert.equal(declared[setting]?.type, 'string', setting);
    assert.equal(declared[setting]?.default, '', setting);
  }
});

const files = (...existing: string[]) => (file: string) => existing.includes(file);

test('F5 without a launch.json debugs the file in its world, else with its sensor script, at level 0', () => {
  const world = path.join('/r', 'a.world.toml');
  const toml = path.join('/r', 'a.sensors.toml');
  const json = path.join('/r', 'a.sensors.json');
  assert.deepEqual(launchForFile('/r/a.rob', files(world, toml)), {
    type: DEBUG_TYPE,
    request: 'launch',
    name: 'Debug a.rob in its world',
    program: '/r/a.rob',
    world,
    level: 0,
  });
  assert.equal(launchForFile('/r/a.rob', files(json))?.sensors, json);
  assert.equal(launchForFile('/r/a.rob', files(toml, json))?.sensors, toml);
  assert.equal(launchForFile('/r/a.rob', files()), undefined);
});

test('Simulate runs in the world setting, else the world beside the file, else asks', () => {
  const beside = path.join('/r', 'a.world.toml');
  assert.equal(worldFor('/r/a.rob', '${workspaceFolder}/w.toml', '/ws', files(beside)), '/ws/w.toml');
  assert.equal(worldFor('/r/a.rob', '', '/ws', files(beside)), beside);
  assert.equal(worldFor('/r/a.rob', undefined, undefined, files()), undefined);
  assert.throws(() => worldFor('/r/a.rob', 3, undefined, files()), /rl1\.simulate\.world must be the path of a world file/);
  assert.throws(() => worldFor('/r/a.rob', '${workspaceFolder}/w.toml', undefined, files()), SettingError);
});

test('Simulate runs rl1c sim with the world and writes the replay beside the file', () => {
  assert.deepEqual(simulateCommandLine('/v/rl1c', '/r/line 2.rob', '/w/x.world.toml'), {
    command: '/v/rl1c',
    args: ['sim', '/r/line 2.rob', '--world', '/w/x.world.toml', '--html', path.join('/r', 'line 2.replay.html')],
  });
  assert.equal(replayFor('/r/a.ROB'), path.join('/r', 'a.replay.html'));
});

test('the replay is offered after a run that wrote one: an ending, a missed goal or a fault', () => {
  assert.deepEqual(
    [0, 1, 2, 10, 11, 12, 13, 20, 130, undefined].map(wroteReplay),
    [true, false, false, true, true, true, true, true, false, false],
  );
});
