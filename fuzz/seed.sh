#!/usr/bin/env bash
# Seeds fuzz/corpus/<target>/ from the repository and the IPC corpus.
set -euo pipefail
cd "$(dirname "$0")"
root=..
corpus=${BTC_CORPUS:-../../shared/corpus/ipc}
mkdir -p corpus/{pddl,plan,rules,tree,scenario,compile,trial}
n=0
for f in "$root"/examples/*/*.pddl "$root"/tests/fixtures/diagnostics/*/*.pddl; do
  cp "$f" "corpus/pddl/$((n++)).pddl"
done
if [ -d "$corpus" ]; then
  for f in $(find "$corpus" -name '*.pddl' | head -400); do cp "$f" "corpus/pddl/$((n++)).pddl"; done
  for f in $(find "$corpus" \( -name '*.plan' -o -name '*.tplan' -o -name 'sas_plan*' \) | head -200); do cp "$f" "corpus/plan/$((n++)).plan"; done
fi
for f in "$root"/examples/*/plan.* "$root"/tests/fixtures/diagnostics/L*/*; do
  [ -f "$f" ] && cp "$f" "corpus/plan/$((n++)).plan"
done
for f in "$root"/examples/*/rules.btrules "$root"/stdlib/*.btrules "$root"/tests/corpus_rules/*/rules.btrules \
         "$root"/tests/fixtures/diagnostics/R*/*.btrules "$root"/lang/tests/fixtures/*.btrules; do
  [ -f "$f" ] && cp "$f" "corpus/rules/$((n++)).btrules"
done
for f in "$root"/examples/ariac/faults/*.toml; do cp "$f" "corpus/scenario/$((n++)).toml"; done
for f in $(find "$root"/tests "$root"/runtime/tests -name '*.xml' | head -200); do cp "$f" "corpus/tree/$((n++)).xml"; done
for f in "$root"/examples/ariac_cell/trials/*.yaml "$root"/agent/tests/fixtures/trials/*.yaml \
         "$root"/examples/ariac_cell/cell.toml "$root"/tests/fixtures/diagnostics/T*/*; do
  [ -f "$f" ] && cp "$f" "corpus/trial/$((n++)).$(basename "$f")"
done
btc="$root/target/debug/btc"
if [ -x "$btc" ]; then
  for fmt in btcpp json; do
    "$btc" compile "$root/examples/ariac/rules.btrules" --plan "$root/examples/ariac/plan.txt" --emit $fmt \
      > "corpus/tree/ariac.$fmt" 2>/dev/null || true
  done
fi
{ cat "$root/examples/ariac/rules.btrules"; printf '\n%%%%\n'; cat "$root/examples/ariac/plan.txt"; } > corpus/compile/ariac
for f in "$root"/examples/ariac/plan*; do
  { cat "$root/examples/ariac/rules.btrules"; printf '\n%%%%\n'; cat "$f"; } > "corpus/compile/$((n++))"
done
echo "seeded: $(find corpus -type f | wc -l) files"
