#!/usr/bin/env bash
# Builds btc's release archive: what a team without a Rust toolchain
# installs. Writes dist/out/btc-VERSION-HOST.tar.gz and its checksum
# (btc-VERSION-HOST.tar.gz.sha256, `sha256sum -c` reads it), and prints
# the archive's path as the last line of stdout.
#
# The archive holds:
#   bin/btc                      the binary as dist/build-release.sh builds it
#                                (static on Linux with glibc)
#   editors/btc-btrules.vsix     the VS Code package (needs npm to build;
#                                BTC_NO_VSIX=1 leaves it out, and says so)
#   editors/neovim.lua, editors/helix/, editors/README.md
#   python/btc_runtime.py        the runtime py_trees modules import
#                                (`btc compile --emit pytrees --runtime import`)
#   README.md, docs/
#
# Usage: dist/release-archive.sh
#   BTC_BIN=PATH packs that binary instead of building one (to try the
#   packing itself quickly; a release is built by this script).
set -euo pipefail
cd "$(dirname "$0")/.."

bin=${BTC_BIN:-$(bash dist/build-release.sh | tail -n 1)}
version=$("$bin" --version | awk '{ print $2 }')
host=$(rustc -vV | sed -n 's/^host: //p')
name="btc-$version-$host"
out="$PWD/dist/out"
stage="$out/$name"
rm -rf "$stage" "$out/$name.tar.gz" "$out/$name.tar.gz.sha256"
mkdir -p "$stage/bin" "$stage/editors" "$stage/python"

install -m 755 "$bin" "$stage/bin/btc"
cp editors/README.md editors/neovim.lua "$stage/editors/"
cp -r editors/helix "$stage/editors/"
cp emit/python/btc_runtime.py "$stage/python/"
cp README.md "$stage/"
cp -r docs "$stage/"

if [ "${BTC_NO_VSIX:-}" = 1 ]; then
  echo "release-archive: BTC_NO_VSIX=1: the VS Code package is left out" >&2
else
  (cd editors/vscode && npm ci --no-audit --no-fund --silent \
     && npx vsce package --out "$stage/editors/btc-btrules.vsix") >&2
fi

# The archive is reproducible from the same files: sorted names, no owner,
# the time of the last commit.
stamp=$(git log -1 --format=%ct 2>/dev/null || echo 0)
tar --sort=name --owner=0 --group=0 --numeric-owner --mtime="@$stamp" \
  -C "$out" -cf - "$name" | gzip -9n > "$out/$name.tar.gz"
(cd "$out" && sha256sum "$name.tar.gz" > "$name.tar.gz.sha256")

# What was packed must work: the binary inside runs, the checksum holds.
"$stage/bin/btc" --version >&2
(cd "$out" && sha256sum -c "$name.tar.gz.sha256" >&2)
echo "$out/$name.tar.gz"
