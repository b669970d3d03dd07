#!/usr/bin/env bash
# Builds the `btc` binary as it is shipped: the release profile, and on
# Linux with glibc a static, position-dependent executable. Prints the
# binary's path as the last line of stdout (build output goes to stderr).
#
# Why static: on a 2-core VM a dynamically linked Rust binary spends about
# 0.4-0.8 ms before `main` in the kernel and the dynamic loader (mapping
# libc, libm and libgcc_s, resolving ~230 symbols); a static one does not.
# `btc --version` goes from ~1.4 ms to ~1 ms, and a whole `btc plan` on the
# ARIAC problem from ~2.3 ms to ~1.8 ms (docs/planner.md).
#
# Why a script and not `.cargo/config.toml`: the flags must reach only the
# binary's crates. Given without `--target`, cargo passes rustflags to proc
# macros and build scripts too, and a proc macro cannot be linked with
# `crt-static`. With `--target` (the host's own triple) they go to the
# target artifacts alone, which cargo builds in `target/<triple>/release`.
#
# Usage: dist/build-release.sh [cargo build options...]
set -euo pipefail
cd "$(dirname "$0")/.."

host=$(rustc -vV | sed -n 's/^host: //p')
case "$host" in
  *-linux-gnu)
    var="CARGO_TARGET_$(echo "$host" | tr 'a-z-' 'A-Z_')_RUSTFLAGS"
    export "$var=-C target-feature=+crt-static -C relocation-model=static"
    cargo build --release --locked --bin btc --target "$host" "$@" >&2
    bin="target/$host/release/btc"
    ;;
  *)
    # Elsewhere the ordinary release build is what ships.
    cargo build --release --locked --bin btc "$@" >&2
    bin="target/release/btc"
    ;;
esac

# The result must run: its version, and a plan of the bundled example.
"$bin" --version >&2
"$bin" plan examples/ariac/domain.pddl examples/ariac/problem.pddl --quiet >/dev/null
echo "$PWD/$bin"
