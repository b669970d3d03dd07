// Cheap checks of the extension's static parts, in plain Node (no VS Code,
// no npm packages): `node --test editors/vscode/test/`.
//
// - every regex of the TextMate grammar compiles under JavaScript's RegExp
//   (TextMate engines use Oniguruma; patterns with Oniguruma-only syntax are
//   skipped, by name, and counted);
// - package.json, the grammar and the language configuration agree;
// - the grammar's keyword, variable, comment, string and number patterns
//   match in the ARIAC example, examples/ariac/rules.btrules.
'use strict';

const { test } = require('node:test');
const assert = require('node:assert/strict');
const fs = require('node:fs');
const path = require('node:path');

const ext = path.resolve(__dirname, '..');
const repo = path.resolve(__dirname, '../../..');
const pkg = JSON.parse(fs.readFileSync(path.join(ext, 'package.json'), 'utf8'));
const grammarContribution = pkg.contributes.grammars[0];
const grammarPath = path.join(ext, grammarContribution.path);
const grammar = JSON.parse(fs.readFileSync(grammarPath, 'utf8'));
const samplePath = path.join(repo, 'examples/ariac/rules.btrules');
const sample = fs.readFileSync(samplePath, 'utf8');

// Oniguruma syntax that JavaScript's RegExp lacks or reads differently.
const ONIGURUMA_ONLY = [
  [/\\[GAzZ]/, '\\G, \\A, \\z or \\Z anchor'],
  [/\\[hHR]/, '\\h, \\H or \\R class'],
  [/\(\?>/, 'atomic group (?>...)'],
  [/\(\?[imx]+[:)-]/, 'inline flags (?i) / (?x)'],
  [/(?<!\\)[*+?}]\+/, 'possessive quantifier'],
  [/\\p\{/, '\\p{...} property (needs the u flag)'],
  [/\\k<|\\g</, 'Oniguruma back-reference or subexpression call'],
  [/\[\[:/, 'POSIX bracket [[:alpha:]]'],
];

/** Every regex in the grammar, with where it is. */
function regexes(node, where, out = []) {
  if (Array.isArray(node)) {
    node.forEach((n, i) => regexes(n, `${where}[${i}]`, out));
  } else if (node !== null && typeof node === 'object') {
    for (const [key, value] of Object.entries(node)) {
      if (['match', 'begin', 'end', 'while'].includes(key) && typeof value === 'string') {
        out.push({ where: `${where}.${key}`, source: value });
      } else {
        regexes(value, `${where}.${key}`, out);
      }
    }
  }
  return out;
}

/** Every `include` in the grammar. */
function includes(node, out = []) {
  if (Array.isArray(node)) {
    node.forEach((n) => includes(n, out));
  } else if (node !== null && typeof node === 'object') {
    for (const [key, value] of Object.entries(node)) {
      if (key === 'include' && typeof value === 'string') out.push(value);
      else includes(value, out);
    }
  }
  return out;
}

/** The repository entry `name`'s match regexes (for entries with `patterns`, all of them). */
function matchesOf(name) {
  const entry = grammar.repository[name];
  assert.ok(entry, `repository has #${name}`);
  return regexes(entry, name).filter((r) => r.where.endsWith('.match') || r.where.endsWith('.begin'));
}

/** Everything `re` matches in `text` (line by line, as TextMate reads). */
function allMatches(source, text) {
  const re = new RegExp(source, 'g');
  const found = [];
  for (const line of text.split('\n')) {
    for (const m of line.matchAll(re)) {
      if (m[0] !== '') found.push(m[0]);
    }
  }
  return found;
}

test('every grammar regex compiles under RegExp, except explicit Oniguruma-only ones', (t) => {
  const all = regexes(grammar, '$');
  assert.ok(all.length > 40, `found ${all.length} regexes`);
  let skipped = 0;
  for (const { where, source } of all) {
    const only = ONIGURUMA_ONLY.find(([re]) => re.test(source));
    if (only) {
      skipped += 1;
      t.diagnostic(`skipped ${where} (${only[1]}): ${source}`);
      continue;
    }
    assert.doesNotThrow(() => new RegExp(source), `${where}: ${source}`);
    // The stricter unicode mode catches needless escapes such as `\:`.
    assert.doesNotThrow(() => new RegExp(source, 'u'), `${where} (u flag): ${source}`);
  }
  t.diagnostic(`${all.length - skipped} compiled, ${skipped} skipped as Oniguruma-only`);
});

test('grammar: scope name and includes resolve', () => {
  assert.equal(grammar.scopeName, 'source.btrules');
  assert.equal(grammar.scopeName, grammarContribution.scopeName);
  for (const inc of includes(grammar)) {
    if (inc === '$self' || inc === '$base') continue;
    assert.ok(inc.startsWith('#'), `include ${inc} is local`);
    assert.ok(grammar.repository[inc.slice(1)], `include ${inc} names a repository entry`);
  }
  // Every repository entry is used.
  const used = new Set(includes(grammar).map((i) => i.slice(1)));
  for (const name of Object.keys(grammar.repository)) {
    assert.ok(used.has(name), `#${name} is included somewhere`);
  }
});

test('package.json: language, grammar, configuration and entry point agree', () => {
  assert.equal(pkg.name, 'btc-btrules');
  assert.equal(pkg.publisher, 'btc');
  // vsce refuses to package without a `repository`. The project has no
  // public URL yet: the field says where the extension is in the btc
  // repository, and gains a `url` when there is one.
  assert.equal(pkg.repository.type, 'git');
  assert.equal(pkg.repository.directory, 'editors/vscode');
  assert.ok(pkg.license);
  assert.ok(pkg.engines && pkg.engines.vscode);
  assert.deepEqual(pkg.activationEvents.filter((e) => e.startsWith('onLanguage:')), ['onLanguage:btrules']);

  const [lang] = pkg.contributes.languages;
  assert.equal(lang.id, 'btrules');
  assert.deepEqual(lang.extensions, ['.btrules']);
  assert.equal(grammarContribution.language, lang.id);
  assert.ok(fs.existsSync(grammarPath), `${grammarContribution.path} exists`);
  const langConfigPath = path.join(ext, lang.configuration);
  assert.ok(fs.existsSync(langConfigPath), `${lang.configuration} exists`);
  assert.ok(fs.existsSync(path.join(ext, pkg.main)), `${pkg.main} exists`);

  const setting = pkg.contributes.configuration.properties['btc.path'];
  assert.equal(setting.type, 'string');
  assert.equal(setting.default, 'btc');

  // The runtime dependency of extension.js is declared (not only a dev one).
  assert.ok(pkg.dependencies['vscode-languageclient']);
  const lock = JSON.parse(fs.readFileSync(path.join(ext, 'package-lock.json'), 'utf8'));
  assert.equal(lock.packages[''].dependencies['vscode-languageclient'], pkg.dependencies['vscode-languageclient']);

  // extension.js reads the setting the manifest declares.
  const source = fs.readFileSync(path.join(ext, pkg.main), 'utf8');
  assert.match(source, /getConfiguration\('btc'\)\.get\('path'\)/);
  assert.match(source, /require\('vscode-languageclient\/node'\)/);
  assert.match(source, /language: 'btrules'/);
});

test('language configuration: comments, brackets and quotes', () => {
  const [lang] = pkg.contributes.languages;
  const conf = JSON.parse(fs.readFileSync(path.join(ext, lang.configuration), 'utf8'));
  assert.equal(conf.comments.lineComment, '//');
  assert.deepEqual(conf.comments.blockComment, ['/*', '*/']);
  assert.deepEqual(conf.brackets, [['{', '}'], ['(', ')'], ['[', ']']]);
  const opens = conf.autoClosingPairs.map((p) => p.open);
  for (const open of ['{', '(', '[', '"']) assert.ok(opens.includes(open), `auto-closes ${open}`);
  for (const re of [conf.wordPattern, conf.indentationRules.increaseIndentPattern, conf.indentationRules.decreaseIndentPattern, conf.folding.markers.start, conf.folding.markers.end]) {
    assert.doesNotThrow(() => new RegExp(re));
  }
  // `?robot` is one word: the server completes variables expecting the
  // editor to replace the whole `?r` it sees (see README).
  assert.equal(new RegExp(conf.wordPattern).exec('?robot-2 x')[0], '?robot-2');
});

test('the ARIAC example: keywords, variables, comments, strings and numbers match', () => {
  const found = (name) => matchesOf(name).flatMap(({ source }) => allMatches(source, sample));

  const keywords = new Set(found('keywords'));
  for (const k of ['domain', 'action', 'condition', 'plan', 'rule', 'reactive_sequence', 'sequence', 'retry', 'steps', 'effect', 'skip']) {
    assert.ok(keywords.has(k), `keyword ${k} matched (got ${[...keywords].join(' ')})`);
  }
  const variables = new Set(found('variables'));
  for (const v of ['?robot', '?here', '?part', '?bin', '?agv', '?c']) {
    assert.ok(variables.has(v), `variable ${v} matched`);
  }
  const comments = found('comments');
  const commentLines = sample.split('\n').filter((l) => l.trimStart().startsWith('//'));
  assert.ok(commentLines.length > 0);
  assert.ok(comments.length >= commentLines.length, `${comments.length} comments for ${commentLines.length} comment lines`);
  assert.ok(comments.includes('// Rules for the ARIAC 2023 floor robot (domain from the paper, Listing 1).'));

  assert.ok(found('strings').length > 0, 'a string starts');
  assert.ok(found('numbers').includes('3'), 'retry(3)');
  assert.ok(new Set(found('node-calls')).has('MoveTo'));
  assert.ok(found('operators').includes('=>'));
  assert.ok(found('effect').includes('effect'));

  // Interpolations inside "move {?robot} to {?to}".
  const strings = grammar.repository.strings.patterns[0].patterns;
  const interp = strings.find((p) => p.name === 'meta.interpolation.variable.btrules');
  assert.deepEqual(allMatches(interp.match, sample), ['{?robot}', '{?to}']);
  // Keywords are whole words: no `plan` in `planner`, no `in` in `?in-bin`.
  const kw = matchesOf('keywords').map(({ source }) => new RegExp(source, 'g'));
  for (const text of ['planner', 'in-bin', '?in', 'rule_set', 'my-effect']) {
    assert.ok(kw.every((re) => !re.test(text)), `no keyword in ${text}`);
  }
});
