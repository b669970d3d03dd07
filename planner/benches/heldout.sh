#!/usr/bin/env bash
# Assembles the planner benchmark's held-out problems (IPC problems the
# corpus in ../shared/corpus does not have) from a copy of
# AI-Planning/classical-domains, outside the checkout's tracked files: the
# project does not carry third-party benchmark files itself.
#
#   planner/benches/heldout.sh SOURCE [DEST]
#
# SOURCE: a checkout of github.com/AI-Planning/classical-domains, or its git
# folder (a bare clone or mirror); files are read at the pinned commit when
# SOURCE is a git folder. DEST: default target/heldout (what
# `cargo bench --bench planner_process` reads; BTC_HELDOUT names another).
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
src=${1:?usage: planner/benches/heldout.sh CLASSICAL_DOMAINS [DEST]}
dest=${2:-$here/target/heldout}
commit=4bd0b42d89ea02bd38af6f93cf20a0ab0cbda9d9
if git --git-dir="$src" cat-file -e "$commit" 2>/dev/null; then
  read_file() { git --git-dir="$src" show "$commit:$1"; }
elif git --git-dir="$src/.git" cat-file -e "$commit" 2>/dev/null; then
  read_file() { git --git-dir="$src/.git" show "$commit:$1"; }
elif [ -d "$src/classical" ]; then
  read_file() { cat "$src/$1"; }
else
  echo "heldout.sh: $src is neither a classical-domains checkout nor its git folder" >&2
  exit 2
fi
n=0
while read -r file origin; do
  case $file in ''|'#'*) continue ;; esac
  mkdir -p "$dest/$(dirname "$file")"
  read_file "$origin" > "$dest/$file.tmp"
  mv "$dest/$file.tmp" "$dest/$file"
  n=$((n + 1))
done < "$here/planner/benches/heldout.txt"
echo "heldout.sh: $n files in $dest"
