// The VS Code client of the btc language server. Plain JavaScript (CommonJS),
// loaded as is: no build step. It starts `btc lsp` (the executable named by
// the `btc.path` setting) over stdio for `.btrules` files, and sends it the
// PDDL files too, so that domains and problems get their diagnostics.
'use strict';

const vscode = require('vscode');
const { LanguageClient } = require('vscode-languageclient/node');

/** @type {LanguageClient | undefined} */
let client;
/** @type {vscode.OutputChannel | undefined} */
let output;

/** The server executable: the `btc.path` setting, `btc` (on PATH) by default. */
function serverPath() {
  const configured = vscode.workspace.getConfiguration('btc').get('path');
  const trimmed = typeof configured === 'string' ? configured.trim() : '';
  return trimmed === '' ? 'btc' : trimmed;
}

function createClient() {
  const command = serverPath();
  /** @type {import('vscode-languageclient/node').ServerOptions} */
  // stdio, but no `transport` field: with `TransportKind.stdio` the client
  // would append `--stdio` to the arguments, which `btc lsp` refuses.
  const serverOptions = {
    run: { command, args: ['lsp'] },
    debug: { command, args: ['lsp'] },
  };
  /** @type {import('vscode-languageclient/node').LanguageClientOptions} */
  const clientOptions = {
    documentSelector: [
      { scheme: 'file', language: 'btrules' },
      // PDDL has no built-in language id in VS Code (a PDDL extension may
      // add one), so select the files by name: the server checks open
      // domains and problems and reports their diagnostics.
      { scheme: 'file', pattern: '**/*.pddl' },
    ],
    synchronize: {
      // A domain edited outside the editor re-checks the rules that use it.
      fileEvents: vscode.workspace.createFileSystemWatcher('**/*.{pddl,btrules}'),
    },
    outputChannel: output,
    traceOutputChannel: output,
  };
  return new LanguageClient('btc', 'btc language server', serverOptions, clientOptions);
}

async function startClient() {
  try {
    client = createClient();
    await client.start();
  } catch (err) {
    const message = err instanceof Error ? err.message : String(err);
    const choice = await vscode.window.showErrorMessage(
      `btc: could not start the language server \`${serverPath()} lsp\` (${message}). ` +
        'Install btc (`cargo install --path .` in the btc repository) or set `btc.path`.',
      'Open Settings',
    );
    if (choice === 'Open Settings') {
      await vscode.commands.executeCommand('workbench.action.openSettings', 'btc.path');
    }
  }
}

async function stopClient() {
  const old = client;
  client = undefined;
  if (old !== undefined && old.isRunning()) {
    await old.stop();
  }
}

async function restartClient() {
  await stopClient();
  await startClient();
}

/** @param {vscode.ExtensionContext} context */
async function activate(context) {
  output = vscode.window.createOutputChannel('btc');
  context.subscriptions.push(
    output,
    vscode.commands.registerCommand('btc.restartServer', restartClient),
    vscode.workspace.onDidChangeConfiguration((e) => {
      if (e.affectsConfiguration('btc.path')) {
        void restartClient();
      }
    }),
  );
  await startClient();
}

function deactivate() {
  return stopClient();
}

module.exports = { activate, deactivate };
