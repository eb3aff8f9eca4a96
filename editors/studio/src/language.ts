// RL/I highlighting: a stream tokenizer with the token classes of the language server's
// semantic tokens (lsp/tokens.py) and the VS Code grammar: labels (the lost-line
// handlers :96-:99 apart), jump targets, the `?` of a conditional jump, built-in calls,
// a camera's or a sensor's selector letter, variables (the reserved ones apart),
// numbers, operators and comments. Which names are built-ins, which take a selector
// and which variables are reserved come from the server (Builtins), not from here.

import { HighlightStyle, StreamLanguage, StringStream } from "@codemirror/language";
import { tags } from "@lezer/highlight";

export interface LanguageFacts {
  /** The built-ins' mnemonics, upper case, and the selector letters of those that take one. */
  readonly selectors: ReadonlyMap<string, ReadonlySet<string>>;
  /** The reserved variables (set by calls). */
  readonly reserved: ReadonlySet<string>;
}

const handlerLabel = tags.special(tags.labelName);
const builtinCall = tags.standard(tags.function(tags.variableName));
const reservedVariable = tags.special(tags.variableName);

interface State {
  /** What the last token was, for the scanner's three context-dependent cases. */
  previous: "start" | "lpar" | "mnemonic" | "operand" | "other";
  mnemonic: string;
}

const HANDLERS = /^:9[6-9](?![0-9])/;

function token(stream: StringStream, state: State, facts: LanguageFacts): string | null {
  if (stream.sol()) state.previous = "start";
  const atLineStart = state.previous === "start";
  if (stream.eatSpace()) return null;
  if (stream.match(/^'.*/)) return "comment";
  if (atLineStart && stream.match(HANDLERS)) return "handlerLabel";
  if (stream.match(/^:[0-9]*/)) {
    state.previous = "other";
    return atLineStart ? "labelName" : "invalid";
  }
  if (stream.match(/^#[0-9]*/)) {
    state.previous = "other";
    return /^#[0-9]{2}$/.test(stream.current()) ? "labelName" : "invalid";
  }
  if (stream.match(/^\$[0-9A-Za-z]*/) || stream.match(/^[0-9]+/)
      || (state.previous !== "operand" && stream.match(/^-[0-9]+/))) {
    state.previous = "operand";
    return "number";
  }
  const word = stream.match(/^[A-Za-z@][A-Za-z0-9@]*/) as RegExpMatchArray | null;
  if (word) {
    const text = word[0];
    if (state.previous === "lpar") {
      state.previous = "mnemonic";
      state.mnemonic = text.toUpperCase();
      return facts.selectors.has(state.mnemonic) ? "builtinCall" : "variableName.function";
    }
    const selectors = state.previous === "mnemonic" ? facts.selectors.get(state.mnemonic) : null;
    state.previous = "operand";
    if (selectors && selectors.has(text.toUpperCase())) return "atom";
    if (text.length > 1) return "invalid";
    return facts.reserved.has(text) ? "reservedVariable" : "variableName";
  }
  if (stream.match("++") || stream.match(/^--(?![0-9])/)) {
    state.previous = "operand";
    return "operator";
  }
  const next = stream.next() ?? "";
  state.previous = next === "(" ? "lpar" : next === ")" ? "operand" : "other";
  if (next === "?") return "controlKeyword";
  if ("+-&|^<>=".includes(next)) return "operator";
  if ("(),;".includes(next)) return "punctuation";
  return "invalid";
}

export function rl1Language(facts: LanguageFacts): StreamLanguage<State> {
  return StreamLanguage.define<State>({
    name: "rl1",
    startState: () => ({ previous: "start", mnemonic: "" }),
    copyState: (state) => ({ ...state }),
    token: (stream, state) => token(stream, state, facts),
    tokenTable: { handlerLabel, builtinCall, reservedVariable },
    // A label (`:10`), a jump target (`#10`) and the variable `@` are words: what
    // rename (F2) and double-click take.
    languageData: { commentTokens: { line: "'" }, wordChars: ":#@" },
  });
}

/** The colours, as classes that studio.css sets (light and dark). */
export const rl1Highlight = HighlightStyle.define([
  { tag: tags.comment, class: "tok-comment" },
  { tag: tags.labelName, class: "tok-label" },
  { tag: handlerLabel, class: "tok-label tok-handler" },
  { tag: tags.controlKeyword, class: "tok-keyword" },
  { tag: builtinCall, class: "tok-builtin" },
  { tag: tags.function(tags.variableName), class: "tok-function" },
  { tag: tags.atom, class: "tok-selector" },
  { tag: reservedVariable, class: "tok-variable tok-reserved" },
  { tag: tags.variableName, class: "tok-variable" },
  { tag: tags.number, class: "tok-number" },
  { tag: tags.operator, class: "tok-operator" },
  { tag: tags.invalid, class: "tok-invalid" },
]);
