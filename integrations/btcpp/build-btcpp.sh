#!/usr/bin/env bash
# Builds BehaviorTree.CPP from its source archive and installs it into a
# cache outside the checkout, keyed by the archive's sha256:
#   ${XDG_CACHE_HOME:-$HOME/.cache}/btc/btcpp-<sha256>
# A second run with the same archive does nothing. Prints the install
# prefix as the last line of stdout; build output goes to stderr.
#
# Usage: build-btcpp.sh [ARCHIVE]
#   ARCHIVE defaults to $BTC_BTCPP_ARCHIVE, then to
#   ../shared/vendor/BehaviorTree.CPP-4.10.0.tar.gz beside the repository.
# Needs cmake, make and a C++17 compiler (`apt-get install cmake g++`).
set -euo pipefail

repo=$(cd "$(dirname "$0")/../.." && pwd)
archive=${1:-${BTC_BTCPP_ARCHIVE:-$repo/../shared/vendor/BehaviorTree.CPP-4.10.0.tar.gz}}
if [ ! -f "$archive" ]; then
  echo "error: no BehaviorTree.CPP archive at $archive" >&2
  exit 2
fi
for tool in cmake make c++ sha256sum flock; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "error: \`$tool\` is not installed (apt-get install cmake g++ util-linux)" >&2
    exit 2
  fi
done

sha=$(sha256sum "$archive" | cut -d' ' -f1)
cache=${XDG_CACHE_HOME:-$HOME/.cache}/btc
prefix=$cache/btcpp-$sha
mkdir -p "$cache"

# One build at a time per archive: tests running in parallel wait for the
# first one instead of building side by side.
exec 9>"$prefix.lock"
flock 9

if [ -f "$prefix/.btc-complete" ]; then
  echo "$prefix"
  exit 0
fi

rm -rf "$prefix"
work=$(mktemp -d "$cache/btcpp-build.XXXXXX")
trap 'rm -rf "$work"' EXIT

echo "building BehaviorTree.CPP from $archive into $prefix" >&2
tar xzf "$archive" -C "$work"
src=$(find "$work" -mindepth 1 -maxdepth 1 -type d | head -n 1)
jobs=${BTC_BUILD_JOBS:-2}
{
  cmake -S "$src" -B "$work/build" -DCMAKE_BUILD_TYPE=Release \
    -DBTCPP_SHARED_LIBS=ON -DBTCPP_GROOT_INTERFACE=OFF -DBTCPP_SQLITE_LOGGING=OFF \
    -DBTCPP_EXAMPLES=OFF -DBUILD_TESTING=OFF -DBTCPP_BUILD_TOOLS=OFF \
    -DCMAKE_INSTALL_PREFIX="$prefix"
  cmake --build "$work/build" -j"$jobs"
  cmake --install "$work/build"
  # tinyxml2 is compiled into the library but its header is not installed;
  # the btlog and palette tests read XML with it too.
  mkdir -p "$prefix/include/btc-tinyxml2"
  cp "$src/3rdparty/tinyxml2/tinyxml2.h" "$prefix/include/btc-tinyxml2/"
} >&2
echo "$sha" >"$prefix/.btc-complete"
echo "$prefix"
