// Runs extension.js's activate() and deactivate() in plain Node, with a stub
// of the `vscode` module and the real vscode-languageclient (needs `npm ci`;
// skipped otherwise). The server it spawns is replaced by test-fixtures/fake-server.js,
// so the test checks the exact command line (`btc lsp`, from `btc.path`),
// the file watcher, and a complete LSP handshake and shutdown.
'use strict';

const { test } = require('node:test');
const assert = require('node:assert/strict');
const fs = require('node:fs');
const os = require('node:os');
const path = require('node:path');
const Module = require('node:module');
const cp = require('node:child_process');

const ext = path.resolve(__dirname, '..');
const installed = fs.existsSync(path.join(ext, 'node_modules/vscode-languageclient/package.json'));
const skip = installed ? false : 'vscode-languageclient is not installed (run `npm ci` in editors/vscode)';

/**
 * A `vscode` module: every property is a callable stub, except the ones in
 * `overrides`, by dotted path ('workspace.getConfiguration').
 */
function fakeVscode(overrides) {
  const make = (where) =>
    new Proxy(function () {}, {
      get(_, key) {
        if (key === '__esModule' || key === 'then') return undefined;
        if (key === Symbol.iterator) return function* () {};
        if (key === Symbol.toPrimitive) return () => `<${where}>`;
        if (typeof key === 'symbol') return undefined;
        const at = where === '' ? key : `${where}.${key}`;
        return Object.prototype.hasOwnProperty.call(overrides, at) ? overrides[at] : make(at);
      },
      apply: () => make(`${where}()`),
      construct: () => make(`new ${where}`),
    });
  return make('');
}

/** Loads a fresh extension.js against `vscode`, with spawn redirected to the fake server. */
async function run(settings) {
  const calls = [];
  const logFile = path.join(fs.mkdtempSync(path.join(os.tmpdir(), 'btc-vscode-')), 'server.log');
  const vscode = fakeVscode({
    version: '1.95.0',
    'workspace.getConfiguration': (section) => ({
      get: (key, dflt) => (`${section}.${key}` in settings ? settings[`${section}.${key}`] : dflt),
      has: (key) => `${section}.${key}` in settings,
    }),
    'workspace.createFileSystemWatcher': (glob) => {
      calls.push(['watcher', glob]);
      return fakeVscode({});
    },
    'window.showErrorMessage': (message) => {
      calls.push(['error', message]);
      return Promise.resolve(undefined);
    },
  });

  const origLoad = Module._load;
  const origSpawn = cp.spawn;
  Module._load = function (request, ...rest) {
    return request === 'vscode' ? vscode : origLoad.call(this, request, ...rest);
  };
  cp.spawn = function (command, args, options) {
    calls.push(['spawn', command, args]);
    return origSpawn.call(this, process.execPath, [path.join(ext, 'test-fixtures/fake-server.js'), ...args], {
      ...options,
      env: { ...process.env, FAKE_SERVER_LOG: logFile },
    });
  };
  try {
    for (const id of Object.keys(require.cache)) {
      if (id.startsWith(ext + path.sep) && !id.includes(`${path.sep}test${path.sep}`)) delete require.cache[id];
    }
    const extension = require(path.join(ext, 'extension.js'));
    const context = { subscriptions: [] };
    await extension.activate(context);
    await extension.deactivate();
    const server = fs.existsSync(logFile)
      ? fs.readFileSync(logFile, 'utf8').trim().split('\n').map((l) => JSON.parse(l))
      : [];
    return { calls, server, subscriptions: context.subscriptions.length };
  } finally {
    Module._load = origLoad;
    cp.spawn = origSpawn;
  }
}

test('activate starts `btc lsp` on stdio and deactivate shuts it down', { skip }, async () => {
  const { calls, server, subscriptions } = await run({});
  assert.deepEqual(calls.filter((c) => c[0] === 'error'), []);
  assert.deepEqual(calls.filter((c) => c[0] === 'spawn'), [['spawn', 'btc', ['lsp']]]);
  assert.deepEqual(calls.filter((c) => c[0] === 'watcher'), [['watcher', '**/*.{pddl,btrules}']]);
  assert.deepEqual(server[0], { argv: ['lsp'] });
  assert.deepEqual(
    server.slice(1).map((e) => e.method),
    ['initialize', 'initialized', 'shutdown'],
  );
  assert.ok(subscriptions >= 3, 'output channel, command and configuration listener are disposed with the extension');
});

test('btc.path names the server executable', { skip }, async () => {
  const { calls } = await run({ 'btc.path': '/opt/btc/bin/btc' });
  assert.deepEqual(calls.filter((c) => c[0] === 'spawn'), [['spawn', '/opt/btc/bin/btc', ['lsp']]]);
  const blank = await run({ 'btc.path': '  ' });
  assert.deepEqual(blank.calls.filter((c) => c[0] === 'spawn'), [['spawn', 'btc', ['lsp']]]);
});
