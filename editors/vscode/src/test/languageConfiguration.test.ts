import * as assert from 'node:assert/strict';
import * as fs from 'node:fs';
import * as path from 'node:path';
import { test } from 'node:test';
import { PACKAGE_ROOT } from './textmate';

const configuration = JSON.parse(
  fs.readFileSync(path.join(PACKAGE_ROOT, 'language-configuration.json'), 'utf8'),
);

test("' starts a line comment and ( ) are the brackets", () => {
  assert.equal(configuration.comments.lineComment, "'");
  assert.deepEqual(configuration.brackets, [['(', ')']]);
});

test('a word is a label, a jump target, a hex constant, a name or a number', () => {
  const words = new RegExp(configuration.wordPattern, 'g');
  assert.deepEqual(':10 A=$FF+#20-@ (CAM P c); ?x<#96; B=-12'.match(words), [
    ':10', 'A', '$FF', '#20', '@', 'CAM', 'P', 'c', 'x', '#96', 'B', '12',
  ]);
});
