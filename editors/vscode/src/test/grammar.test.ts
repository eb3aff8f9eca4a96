// The TextMate grammar, run by vscode-textmate as VS Code runs it: the token snapshots
// of Listing 1 and test/cases/*.rob, and the rules that matter most stated outright.

import * as assert from 'node:assert/strict';
import * as fs from 'node:fs';
import { describe, test } from 'node:test';
import { render, snapshots } from './expectations';
import { rl1Grammar, splitLines, Token, tokenize } from './textmate';

describe('token snapshots', () => {
  for (const snapshot of snapshots()) {
    test(snapshot.name, async () => {
      assert.ok(
        fs.existsSync(snapshot.expected),
        `${snapshot.expected} is missing: run \`npm run test:update\` and review the new file`,
      );
      const lines = splitLines(fs.readFileSync(snapshot.source, 'utf8'));
      const actual = render(snapshot.name, lines, tokenize(await rl1Grammar(), lines));
      assert.equal(actual, fs.readFileSync(snapshot.expected, 'utf8'));
    });
  }
});

/** The tokens of one line, as `text` -> innermost scope, blank tokens left out. */
async function innermost(line: string): Promise<[string, string][]> {
  const [tokens] = tokenize(await rl1Grammar(), [line]);
  return tokens
    .filter((token: Token) => token.text.trim() !== '')
    .map((token: Token) => [token.text, token.scopes[token.scopes.length - 1]]);
}

describe('rules', () => {
  test('after an operand, `--5` is a minus and a negative constant', async () => {
    assert.deepEqual(await innermost('A=B--5'), [
      ['A', 'variable.other.rl1'],
      ['=', 'keyword.operator.assignment.rl1'],
      ['B', 'variable.other.rl1'],
      ['-', 'keyword.operator.arithmetic.rl1'],
      ['-5', 'constant.numeric.decimal.rl1'],
    ]);
  });

  test('`--` not followed by a digit is a decrement, spaces or not', async () => {
    for (const line of ['C--', 'C --']) {
      assert.deepEqual(await innermost(line), [
        ['C', 'variable.other.rl1'],
        ['--', 'keyword.operator.decrement.rl1'],
      ]);
    }
  });

  test('a first argument may be negative; a later one after a comma too', async () => {
    const tokens = await innermost('(MOV -3,-12)');
    assert.deepEqual(tokens.slice(2, 5), [
      ['-3', 'constant.numeric.decimal.rl1'],
      [',', 'punctuation.separator.arguments.rl1'],
      ['-12', 'constant.numeric.decimal.rl1'],
    ]);
  });

  test('CAM and ULT take a selector letter; a wrong letter is marked', async () => {
    assert.deepEqual((await innermost('(CAM A 90)')).slice(1, 4), [
      ['CAM', 'support.function.builtin.rl1'],
      ['A', 'constant.language.selector.rl1'],
      ['90', 'constant.numeric.decimal.rl1'],
    ]);
    assert.deepEqual((await innermost('(ULT A)'))[2], ['A', 'constant.language.selector.rl1']);
    assert.deepEqual((await innermost('(ULT E)'))[2], ['E', 'invalid.illegal.selector.ultrasonic.rl1']);
  });

  test('labels are two digits at the start of a line; :96-:99 are handlers', async () => {
    assert.deepEqual(await innermost(':5'), [[':5', 'invalid.illegal.label.rl1']]);
    assert.deepEqual((await innermost(':10 A=1'))[0], [':10', 'entity.name.label.rl1']);
    assert.deepEqual(await innermost(':97'), [[':97', 'entity.name.label.handler.rl1']]);
    assert.deepEqual((await innermost('A=1 :10'))[3], [':10', 'invalid.illegal.label.rl1']);
  });

  test('s-z are reserved variables, the other letters and @ are not', async () => {
    for (const letter of 'stuvwxyz') {
      assert.deepEqual((await innermost(`A=${letter}`))[2], [letter, 'variable.language.reserved.rl1']);
    }
    for (const letter of 'Sar@') {
      assert.deepEqual((await innermost(`A=${letter}`))[2], [letter, 'variable.other.rl1']);
    }
  });

  test('a comment runs to the line end, whatever its script', async () => {
    const tokens = await innermost("(FRE) ' 停止 (MOV 3,3)");
    assert.deepEqual(tokens.slice(-2), [
      ["'", 'punctuation.definition.comment.rl1'],
      [' 停止 (MOV 3,3)', 'comment.line.quote.rl1'],
    ]);
  });

  test('hex constants are 16-bit patterns', async () => {
    assert.deepEqual((await innermost('A=$FFFF'))[2], ['$FFFF', 'constant.numeric.hex.rl1']);
    assert.deepEqual((await innermost('A=$10000'))[2], ['$10000', 'invalid.illegal.hex.rl1']);
    assert.deepEqual((await innermost('A=$G'))[2], ['$G', 'invalid.illegal.hex.rl1']);
  });

  test('an unclosed call ends with its line', async () => {
    const [, next] = tokenize(await rl1Grammar(), ['(STX D', 'A=1']);
    assert.deepEqual(next[0].scopes, ['source.rl1', 'variable.other.rl1']);
  });
});
