// The client: starts `liganimate lsp` (the language server of the liganimate Python package)
// over stdio for .lig files. Highlighting comes from the TextMate grammar alone.
"use strict";
const vscode = require("vscode");
const { LanguageClient, TransportKind } = require("vscode-languageclient/node");

let client;

function activate(context) {
  const config = vscode.workspace.getConfiguration("liganimate");
  if (!config.get("server.enabled", true)) {
    return undefined;
  }
  const command = config.get("server.command", "liganimate");
  const serverOptions = { command, args: ["lsp"], transport: TransportKind.stdio };
  const clientOptions = {
    documentSelector: [
      { scheme: "file", language: "lig" },
      { scheme: "untitled", language: "lig" },
    ],
  };
  client = new LanguageClient("liganimate", "LIG ANIMATE", serverOptions, clientOptions);
  context.subscriptions.push(client);
  return client.start().catch((err) => {
    vscode.window.showWarningMessage(
      `LIG ANIMATE: could not start "${command} lsp" (${err.message}); install it with pip install liganimate, ` +
        "or set liganimate.server.command. Highlighting still works."
    );
  });
}

function deactivate() {
  return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate };
