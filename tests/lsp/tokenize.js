// Tokenize LIG files with the VS Code extension's TextMate grammar, as VS Code itself does
// (vscode-textmate on the Oniguruma regex engine, vscode-oniguruma's WebAssembly build).
// Usage: node tokenize.js MODULES_DIR GRAMMAR.json FILE...
// Prints one JSON object a file: {"file": ..., "lines": [[[start, end, [scope, ...]], ...], ...]}.
"use strict";
const fs = require("fs");
const path = require("path");
const modules = process.argv[2];
const grammarPath = process.argv[3];
const files = process.argv.slice(4);
const vsctm = require(path.join(modules, "vscode-textmate"));
const oniguruma = require(path.join(modules, "vscode-oniguruma"));

async function main() {
  const wasm = fs.readFileSync(path.join(modules, "vscode-oniguruma", "release", "onig.wasm"));
  await oniguruma.loadWASM(wasm.buffer.slice(wasm.byteOffset, wasm.byteOffset + wasm.byteLength));
  const registry = new vsctm.Registry({
    onigLib: Promise.resolve({
      createOnigScanner: (patterns) => new oniguruma.OnigScanner(patterns),
      createOnigString: (s) => new oniguruma.OnigString(s),
    }),
    loadGrammar: async (scopeName) => {
      if (scopeName !== "source.lig") return null;
      return vsctm.parseRawGrammar(fs.readFileSync(grammarPath, "utf8"), grammarPath);
    },
  });
  const grammar = await registry.loadGrammar("source.lig");
  for (const file of files) {
    const text = fs.readFileSync(file, "utf8");
    let state = vsctm.INITIAL;
    const lines = [];
    for (const line of text.split("\n")) {
      const result = grammar.tokenizeLine(line, state);
      lines.push(result.tokens.map((t) => [t.startIndex, Math.min(t.endIndex, line.length), t.scopes]));
      state = result.ruleStack;
    }
    process.stdout.write(JSON.stringify({ file, lines }) + "\n");
  }
}

main().catch((err) => {
  process.stderr.write(String(err && err.stack ? err.stack : err) + "\n");
  process.exit(1);
});
