# Sourced by the build scripts of vendored sources (build-btcpp.sh,
# build-val.sh): checks the archive and the tools, and takes the cache
# entry keyed by the archive's sha256,
#   ${XDG_CACHE_HOME:-$HOME/.cache}/btc/NAME-<sha256>
# under a lock held until the script exits (tests running in parallel wait
# for the first build instead of building side by side). Sets `prefix` and
# `cache`; when the entry is complete, prints `$prefix$RESULT` and exits.
#
# Usage: cached_build NAME ARCHIVE RESULT
cached_build() {
  local name=$1 archive=$2 result=$3
  if [ ! -f "$archive" ]; then
    echo "error: no $name archive at $archive" >&2
    exit 2
  fi
  for tool in cmake make c++ sha256sum flock; do
    if ! command -v "$tool" >/dev/null 2>&1; then
      echo "error: \`$tool\` is not installed (apt-get install cmake g++ util-linux)" >&2
      exit 2
    fi
  done
  local sha
  sha=$(sha256sum "$archive" | cut -d' ' -f1)
  cache=${XDG_CACHE_HOME:-$HOME/.cache}/btc
  prefix=$cache/$name-$sha
  mkdir -p "$cache"
  exec 9>"$prefix.lock"
  flock 9
  if [ -f "$prefix/.btc-complete" ]; then
    echo "$prefix$result"
    exit 0
  fi
  rm -rf "$prefix"
  archive_sha=$sha
}
