// The token snapshots: which sources are tokenized, where their expectation files live,
// and the readable one-token-a-line format those files use.

import * as fs from 'node:fs';
import * as path from 'node:path';
import { PACKAGE_ROOT, ROOT_SCOPE, Token } from './textmate';

const CASES_DIR = path.join(PACKAGE_ROOT, 'test', 'cases');
const EXPECTED_DIR = path.join(PACKAGE_ROOT, 'test', 'expected');
const SAMPLE = path.resolve(PACKAGE_ROOT, '..', '..', 'examples', 'sample.rob');

export interface Snapshot {
  /** The source, relative to the package, as named in the expectation file. */
  name: string;
  source: string;
  expected: string;
}

/** Listing 1 of the paper, then every test/cases/*.rob. */
export function snapshots(): Snapshot[] {
  const cases = fs
    .readdirSync(CASES_DIR)
    .filter((file) => file.endsWith('.rob'))
    .sort()
    .map((file) => path.join(CASES_DIR, file));
  return [SAMPLE, ...cases].map((source) => ({
    name: path.relative(PACKAGE_ROOT, source).split(path.sep).join('/'),
    source,
    expected: path.join(EXPECTED_DIR, path.basename(source, '.rob') + '.tokens'),
  }));
}

/**
 * One block per source line: `N: text`, then one indented line per non-blank token:
 * its column, its text as a JSON string, and its scopes below source.rl1 (`-` if none).
 */
export function render(name: string, lines: string[], tokens: Token[][]): string {
  const out = [
    `# TextMate tokens of ${name} (syntaxes/rl1.tmLanguage.json).`,
    '# Per token: column, text, scopes below source.rl1. Blank tokens are left out.',
    '# Checked by `npm test`; after a deliberate grammar change, `npm run test:update`',
    '# rewrites this file: review its diff before committing it.',
  ];
  lines.forEach((line, index) => {
    out.push(`${index + 1}: ${line}`);
    for (const token of tokens[index]) {
      if (token.text.trim() === '') {
        continue;
      }
      const scopes = token.scopes.filter((scope) => scope !== ROOT_SCOPE);
      const text = JSON.stringify(token.text).padEnd(8);
      out.push(`  ${String(token.column).padStart(3)}  ${text}  ${scopes.join(' ') || '-'}`);
    }
  });
  return out.join('\n') + '\n';
}
