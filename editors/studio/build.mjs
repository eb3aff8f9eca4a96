// Builds the page into lsp/studio/static/, which the Python package ships (so that
// `pipx install` needs no Node.js): studio.js and studio.css bundled by esbuild, whose
// output is the same bytes for the same sources and lock file, and index.html copied.
// tests/project/test_studio_bundle.py rebuilds it and compares.
import { build } from "esbuild";
import { copyFileSync, mkdirSync } from "node:fs";

const out = new URL("../../lsp/studio/static/", import.meta.url).pathname;
mkdirSync(out, { recursive: true });
await build({
  // main.ts imports studio.css, which esbuild writes beside studio.js.
  entryPoints: { studio: "src/main.ts" },
  outdir: out,
  bundle: true,
  format: "esm",
  target: "es2022",
  minify: true,
  legalComments: "eof",
  charset: "utf8",
  logLevel: "warning",
});
copyFileSync("src/index.html", out + "index.html");
