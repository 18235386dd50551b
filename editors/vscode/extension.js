// extension.js: the VS Code client of `sdfc lsp`. It starts the server for `.sdf` files
// (saved or not) and restarts it on `sdfc: Restart the language server` or when the
// `sdfc.path` setting changes; `sdfc: View the scene` opens `sdfc view` on the file in a
// terminal, a window that follows each save. Everything else (diagnostics, hover,
// completion, navigation, rename, quick fixes, formatting) is the server's (docs/editors.md).
const vscode = require("vscode");
const { LanguageClient, TransportKind } = require("vscode-languageclient/node");

let client;

function program() {
  return vscode.workspace.getConfiguration("sdfc").get("path") || "sdfc";
}

function start() {
  const command = program();
  const server = { command, args: ["lsp"], transport: TransportKind.stdio };
  client = new LanguageClient(
    "sdfc",
    "sdfc language server",
    { run: server, debug: server },
    {
      documentSelector: [
        { scheme: "file", language: "sdf" },
        { scheme: "untitled", language: "sdf" },
      ],
      // An imported file changed on disk: the server checks the open documents again.
      synchronize: { fileEvents: vscode.workspace.createFileSystemWatcher("**/*.sdf") },
    },
  );
  return client.start().catch((e) => {
    vscode.window.showErrorMessage(
      `sdfc: could not start \`${command} lsp\` (${e.message || e}); set sdfc.path to the sdfc program`,
    );
  });
}

async function restart() {
  if (client) {
    await client.stop().catch(() => {});
  }
  return start();
}

// `sdfc view FILE` in a terminal of its own (the program run directly, no shell quoting).
function view() {
  const editor = vscode.window.activeTextEditor;
  const doc = editor && editor.document;
  if (!doc || doc.languageId !== "sdf" || doc.isUntitled) {
    vscode.window.showErrorMessage("sdfc: View the scene needs a saved .sdf file in the editor");
    return;
  }
  const terminal = vscode.window.createTerminal({
    name: "sdfc view",
    shellPath: program(),
    shellArgs: ["view", doc.fileName],
  });
  terminal.show(true);
}

function activate(context) {
  context.subscriptions.push(
    vscode.commands.registerCommand("sdfc.restart", restart),
    vscode.commands.registerCommand("sdfc.view", view),
    vscode.workspace.onDidChangeConfiguration((e) => {
      if (e.affectsConfiguration("sdfc.path")) {
        restart();
      }
    }),
  );
  return start();
}

function deactivate() {
  return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate };
