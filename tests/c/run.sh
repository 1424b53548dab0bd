#!/usr/bin/env bash
# Builds the library (release), compiles tests/c/example.c against include/dhcd.h, links it
# statically and dynamically, and runs both. Exit status non-zero on any failure.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --lib
target="${CARGO_TARGET_DIR:-target}/release"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
CC="${CC:-cc}"
flags=(-std=c11 -Wall -Wextra -Werror -pedantic -Iinclude)
# Static: the archive plus the system libraries Rust's std needs.
"$CC" "${flags[@]}" tests/c/example.c "$target/libdhcd.a" -lpthread -ldl -lm -o "$out/example-static"
"$out/example-static"
# Dynamic: against libdhcd.so.
"$CC" "${flags[@]}" tests/c/example.c -L"$target" -ldhcd -lm -o "$out/example-dynamic"
LD_LIBRARY_PATH="$target${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$out/example-dynamic" >/dev/null
echo "tests/c: static and dynamic example passed"
