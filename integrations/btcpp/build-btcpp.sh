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
# shellcheck source=../cached-build.sh
. "$repo/integrations/cached-build.sh"
cached_build btcpp "$archive" ""

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
echo "$archive_sha" >"$prefix/.btc-complete"
echo "$prefix"
