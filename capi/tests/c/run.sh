#!/usr/bin/env bash
# Builds the C ABI crate (release), compiles capi/tests/c/example.c against include/dhcd.h,
# links it statically and dynamically, and runs both. Exit status non-zero on any failure.
set -euo pipefail
cd "$(dirname "$0")/../../.."
cargo build --release -p dhcd-capi
target="${CARGO_TARGET_DIR:-target}/release"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
CC="${CC:-cc}"
flags=(-std=c11 -Wall -Wextra -Werror -pedantic -Iinclude)
example=capi/tests/c/example.c
# Static: the archive plus the system libraries Rust's std needs.
"$CC" "${flags[@]}" "$example" "$target/libdhcd_capi.a" -lpthread -ldl -lm -o "$out/example-static"
"$out/example-static"
# Dynamic: against libdhcd_capi.so.
"$CC" "${flags[@]}" "$example" -L"$target" -ldhcd_capi -lm -o "$out/example-dynamic"
LD_LIBRARY_PATH="$target${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$out/example-dynamic" >/dev/null
echo "capi/tests/c: static and dynamic example passed"
