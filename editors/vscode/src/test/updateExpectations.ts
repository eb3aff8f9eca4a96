// `npm run test:update`: rewrite the token snapshots from the current grammar.
// The tests never do this; they compare.

import * as fs from 'node:fs';
import * as path from 'node:path';
import { render, snapshots } from './expectations';
import { rl1Grammar, splitLines, tokenize } from './textmate';

async function main(): Promise<void> {
  const grammar = await rl1Grammar();
  for (const snapshot of snapshots()) {
    const lines = splitLines(fs.readFileSync(snapshot.source, 'utf8'));
    const text = render(snapshot.name, lines, tokenize(grammar, lines));
    fs.mkdirSync(path.dirname(snapshot.expected), { recursive: true });
    const temporary = `${snapshot.expected}.tmp`;
    fs.writeFileSync(temporary, text);
    fs.renameSync(temporary, snapshot.expected);
    console.log(`wrote ${path.relative(process.cwd(), snapshot.expected)}`);
  }
}

main().catch((error: unknown) => {
  console.error(error instanceof Error ? error.message : error);
  process.exitCode = 1;
});
