#!/bin/sh
# CCD over the real simulation steps (frame N -> N+1), f64, one thread: the IPC Toolkit's
# earliest time of impact (LBVH broad phase + Tight Inclusion, `compute_collision_free_stepsize`;
# `../shared/peers/ipctk/ccd.py`, best of 3) and `dhcd bench ccd` (DH, the earliest time and
# every colliding pair, least of 3 steps) in one run. From the project root:
#
#   benches/scripts/ccd-vs-ipctk.sh > ccd-vs-ipctk.log 2>&1
#
# Needs ../shared (the frames and the ipctk harness). The IPC Toolkit comes from PyPI into a
# virtual environment of its own (target/ipctk-venv, made once by the peer's setup.sh).
set -eu
DATA=../shared/data/real-frames
PEER=../shared/peers/ipctk
[ -d "$DATA" ] || { echo "no $DATA: nothing to measure"; exit 0; }
[ -x target/ipctk-venv/bin/python ] || bash "$PEER/setup.sh" target/ipctk-venv
cargo build --release -p dhcd-cli
echo "== date: $(date -u +%FT%TZ); commit: $(git rev-parse --short HEAD); load: $(cut -d' ' -f1-3 /proc/loadavg)"
for pair in armadillo-rollers-326:327 cloth-ball-92:93 n-body-simulation-18:19 rod-twist-3036:3037; do
    name=${pair%:*}; next=${name%-*}-${pair#*:}
    echo "== ipctk $name:"
    target/ipctk-venv/bin/python "$PEER/ccd.py" "$DATA/$name.ply" "$DATA/$next.ply" --repeat 3
    for mode in --earliest ""; do
        printf '== dhcd %s dh %s: ' "$name" "${mode:-all}"
        # shellcheck disable=SC2086
        target/release/dhcd bench ccd "$DATA/$name.ply" "$DATA/$next.ply" $mode --method dh \
            --repeat 3 --json |
            python3 -c 'import json,sys; d=json.load(sys.stdin); f=d["frames"][0]
print("%.1f ms least, %d pairs reported, %d exact tests, %d BV tests" % (f["step_ms"]["min"], f["contacts"], f["counters"]["prim_tests"], f["counters"]["bv_tests"]))'
    done
done
echo "== load at end: $(cut -d' ' -f1-3 /proc/loadavg)"
