#!/usr/bin/env bash
# Builds VAL's `Validate` (KCL-Planning/VAL, the reference PDDL plan
# validator) from its source archive into a cache outside the checkout,
# keyed by the archive's sha256:
#   ${XDG_CACHE_HOME:-$HOME/.cache}/btc/val-<sha256>
# A second run with the same archive does nothing. Prints the path of the
# `Validate` binary as the last line of stdout; build output goes to stderr.
#
# Usage: build-val.sh [ARCHIVE]
#   ARCHIVE defaults to $BTC_VAL_ARCHIVE, then to
#   ../shared/vendor/VAL-3c7a1f3.tar.gz beside the repository.
# Needs cmake, make and a C++ compiler (`apt-get install cmake g++`); the
# archive carries its generated parser, so flex and bison are not needed.
set -euo pipefail

repo=$(cd "$(dirname "$0")/../.." && pwd)
archive=${1:-${BTC_VAL_ARCHIVE:-$repo/../shared/vendor/VAL-3c7a1f3.tar.gz}}
# shellcheck source=../cached-build.sh
. "$repo/integrations/cached-build.sh"
cached_build val "$archive" /bin/Validate

work=$(mktemp -d "$cache/val-build.XXXXXX")
trap 'rm -rf "$work"' EXIT

echo "building VAL from $archive into $prefix" >&2
tar xzf "$archive" -C "$work"
src=$(find "$work" -mindepth 1 -maxdepth 1 -type d | head -n 1)
jobs=${BTC_BUILD_JOBS:-2}
{
  cmake -S "$src" -B "$work/build" -DCMAKE_BUILD_TYPE=Release
  cmake --build "$work/build" -j"$jobs" --target Validate
} >&2
# `Validate` finds libVAL.so beside it (its runpath is `$ORIGIN`).
mkdir -p "$prefix/bin"
cp "$work/build/bin/Validate" "$prefix/bin/"
find "$work/build" -name 'libVAL.so*' -exec cp -P {} "$prefix/bin/" \;
echo "$archive_sha" >"$prefix/.btc-complete"
echo "$prefix/bin/Validate"
