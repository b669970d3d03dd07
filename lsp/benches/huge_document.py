#!/usr/bin/env python3
"""Drives `btc lsp` over stdio on a huge rules file (the large fixture's
rules repeated, renamed, to about 6.5 MB) and prints how long each answer
took: diagnostics after didOpen and after an edit, and one of each request.

Usage: lsp/benches/huge_document.py [path/to/btc] [megabytes]
"""

import json
import os
import queue
import subprocess
import sys
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BTC = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "target/debug/btc")
MB = float(sys.argv[2]) if len(sys.argv) > 2 else 6.5

with open(os.path.join(ROOT, "lang/tests/fixtures/large.btrules")) as f:
    fixture = f.read()
head, _, rules = fixture.partition("\nrule ")
rules = "rule " + rules
copies, parts = 0, [head, "\n"]
while sum(map(len, parts)) < MB * 1e6:
    parts.append(rules.replace('"move ', f'"m{copies} ').replace('"grasp ', f'"g{copies} '))
    copies += 1
text = "".join(parts)
path = os.path.join(ROOT, "lsp/tests/fixtures/huge.btrules")
uri = "file://" + path

p = subprocess.Popen([BTC, "lsp"], stdin=subprocess.PIPE, stdout=subprocess.PIPE, cwd=ROOT)
inbox = queue.Queue()


def reader():
    while True:
        n = None
        while True:
            line = p.stdout.readline()
            if not line:
                return
            if line.strip() == b"":
                break
            if line.lower().startswith(b"content-length:"):
                n = int(line.split(b":")[1])
        inbox.put((time.monotonic(), json.loads(p.stdout.read(n))))


threading.Thread(target=reader, daemon=True).start()


def send(msg):
    body = json.dumps(msg).encode()
    p.stdin.write(b"Content-Length: %d\r\n\r\n" % len(body) + body)
    p.stdin.flush()


WAIT = float(os.environ.get("LSP_WAIT", "600"))


def wait(pred, timeout=WAIT):
    end = time.monotonic() + timeout
    while True:
        t, m = inbox.get(timeout=max(0.01, end - time.monotonic()))
        if "id" in m and "method" in m:  # a request of the server's
            send({"jsonrpc": "2.0", "id": m["id"], "result": None})
        elif pred(m):
            return t, m


ids = iter(range(1, 10**6))


def request(method, params):
    i = next(ids)
    t0 = time.monotonic()
    send({"jsonrpc": "2.0", "id": i, "method": method, "params": params})
    t, m = wait(lambda m: m.get("id") == i)
    return t - t0, m


def diagnostics_after(msg):
    t0 = time.monotonic()
    send(msg)
    t, m = wait(
        lambda m: m.get("method") == "textDocument/publishDiagnostics" and m["params"]["uri"] == uri
    )
    return t - t0, len(m["params"]["diagnostics"])


request("initialize", {"processId": None, "rootUri": "file://" + ROOT, "capabilities": {}})
send({"jsonrpc": "2.0", "method": "initialized", "params": {}})
lines = text.count("\n")
print(f"document: {len(text) / 1e6:.2f} MB, {lines} lines, {copies} copies of the fixture's rules")
dt, n = diagnostics_after(
    {
        "jsonrpc": "2.0",
        "method": "textDocument/didOpen",
        "params": {
            "textDocument": {"uri": uri, "languageId": "btrules", "version": 1, "text": text}
        },
    }
)
print(f"didOpen -> publishDiagnostics: {dt * 1000:.0f} ms ({n} diagnostics)")
mid = lines // 2
dt, n = diagnostics_after(
    {
        "jsonrpc": "2.0",
        "method": "textDocument/didChange",
        "params": {
            "textDocument": {"uri": uri, "version": 2},
            "contentChanges": [
                {
                    "range": {
                        "start": {"line": mid, "character": 0},
                        "end": {"line": mid, "character": 0},
                    },
                    "text": "// x\n",
                }
            ],
        },
    }
)
print(f"didChange -> publishDiagnostics: {dt * 1000:.0f} ms ({n} diagnostics)")
doc = {"textDocument": {"uri": uri}}
at = dict(doc, position={"line": 12, "character": 10})
for method, params in [
    ("textDocument/documentSymbol", doc),
    ("workspace/symbol", {"query": "move"}),
    ("textDocument/formatting", dict(doc, options={"tabSize": 4, "insertSpaces": True})),
    ("textDocument/hover", at),
    ("textDocument/completion", at),
    ("textDocument/definition", at),
    ("textDocument/references", dict(at, context={"includeDeclaration": True})),
    ("textDocument/semanticTokens/full", doc),
    ("textDocument/foldingRange", doc),
    (
        "textDocument/codeAction",
        dict(
            doc,
            range={"start": {"line": 12, "character": 0}, "end": {"line": 12, "character": 5}},
            context={"diagnostics": []},
        ),
    ),
]:
    dt, m = request(method, params)
    what = (
        "error " + str(m["error"].get("code"))
        if "error" in m
        else ("result" if m.get("result") is not None else "null")
    )
    print(f"{method}: {dt * 1000:.0f} ms ({what})")
request("shutdown", None)
send({"jsonrpc": "2.0", "method": "exit"})
p.wait(timeout=10)
