// Tokenizes text with the extension's TextMate grammar exactly as VS Code does: the
// same vscode-textmate engine over the same Oniguruma regular expressions (WebAssembly).

import * as fs from 'node:fs';
import * as path from 'node:path';
import * as oniguruma from 'vscode-oniguruma';
import * as vsctm from 'vscode-textmate';

export const PACKAGE_ROOT = path.resolve(__dirname, '..', '..');
export const ROOT_SCOPE = 'source.rl1';
const GRAMMAR_FILE = path.join(PACKAGE_ROOT, 'syntaxes', 'rl1.tmLanguage.json');

export interface Token {
  /** 1-based, in UTF-16 code units as VS Code counts them. */
  column: number;
  text: string;
  scopes: string[];
}

let grammar: Promise<vsctm.IGrammar> | undefined;

/** The grammar, loaded once: Oniguruma's WebAssembly can be initialised only once. */
export function rl1Grammar(): Promise<vsctm.IGrammar> {
  grammar ??= loadGrammar();
  return grammar;
}

async function loadGrammar(): Promise<vsctm.IGrammar> {
  const wasm = fs.readFileSync(require.resolve('vscode-oniguruma/release/onig.wasm'));
  await oniguruma.loadWASM({ data: wasm });
  const registry = new vsctm.Registry({
    onigLib: Promise.resolve({
      createOnigScanner: (patterns: string[]) => new oniguruma.OnigScanner(patterns),
      createOnigString: (text: string) => new oniguruma.OnigString(text),
    }),
    loadGrammar: async (scopeName: string) =>
      scopeName === ROOT_SCOPE
        ? vsctm.parseRawGrammar(fs.readFileSync(GRAMMAR_FILE, 'utf8'), GRAMMAR_FILE)
        : null,
  });
  const loaded = await registry.loadGrammar(ROOT_SCOPE);
  if (loaded === null) {
    throw new Error(`${GRAMMAR_FILE} does not define the scope ${ROOT_SCOPE}`);
  }
  return loaded;
}

/** The lines of a text the way the rl1 compiler splits them (LF, CRLF or lone CR). */
export function splitLines(text: string): string[] {
  const lines = text.split(/\r\n|\r|\n/);
  if (lines.length > 0 && lines[lines.length - 1] === '') {
    lines.pop();
  }
  return lines;
}

/** Each line's tokens; the state carries over from line to line as in the editor. */
export function tokenize(rl1: vsctm.IGrammar, lines: string[]): Token[][] {
  let state = vsctm.INITIAL;
  return lines.map((line) => {
    const result = rl1.tokenizeLine(line, state);
    state = result.ruleStack;
    return result.tokens.map((token) => ({
      column: token.startIndex + 1,
      text: line.slice(token.startIndex, token.endIndex),
      scopes: token.scopes,
    }));
  });
}
