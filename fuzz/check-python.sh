#!/usr/bin/env bash
# Parses every py_trees module the `compile` target saved (run it with
# BTC_FUZZ_PY_OUT=DIR) with Python's `ast`: btc must never write a module
# that is not Python. Exits 1 naming the first file that does not parse.
set -euo pipefail
dir=${1:?usage: check-python.sh DIR}
python3 - "$dir" <<'PY'
import ast, pathlib, sys
files = sorted(pathlib.Path(sys.argv[1]).glob("*.py"))
for f in files:
    try:
        ast.parse(f.read_text(encoding="utf-8"), filename=str(f))
    except SyntaxError as e:
        print(f"{f}: {e}")
        sys.exit(1)
print(f"{len(files)} modules parse")
PY
