// A stand-in for `btc lsp` in test/activate.test.js (kept out of test/, where
// `node --test` would run it as a test): answers the LSP handshake on
// stdio and writes what it received to the file named by FAKE_SERVER_LOG.
'use strict';

const fs = require('node:fs');
const path = require('node:path');
const rpc = require(path.join(__dirname, '../node_modules/vscode-jsonrpc/node'));

const log = (entry) => fs.appendFileSync(process.env.FAKE_SERVER_LOG, JSON.stringify(entry) + '\n');
log({ argv: process.argv.slice(2) });

const conn = rpc.createMessageConnection(
  new rpc.StreamMessageReader(process.stdin),
  new rpc.StreamMessageWriter(process.stdout),
);
conn.onRequest('initialize', (params) => {
  log({ method: 'initialize', clientName: params.clientInfo && params.clientInfo.name });
  return { capabilities: { textDocumentSync: 2 }, serverInfo: { name: 'fake-btc' } };
});
conn.onNotification('initialized', () => log({ method: 'initialized' }));
conn.onRequest('shutdown', () => {
  log({ method: 'shutdown' });
  return null;
});
conn.onNotification('exit', () => process.exit(0));
conn.listen();
