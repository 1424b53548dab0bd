#!/bin/sh
# Self-proximity on the real frames at IPC's default distance (dhat = 1e-3 x the bounding-box
# diagonal), f64, one thread: the IPC Toolkit's NormalCollisions.build (LBVH broad phase;
# `../shared/peers/ipctk/proximity.py`, best of 3) and `dhcd bench proximity` (each method,
# least of 5 steps per frame) in one run. From the project root:
#
#   benches/scripts/proximity-vs-ipctk.sh > proximity-vs-ipctk.log 2>&1
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
    printf '== ipctk %s: ' "$name"
    target/ipctk-venv/bin/python "$PEER/proximity.py" "$DATA/$name.ply" --relative 1e-3 --repeat 3 | tail -1
    for m in dh sphere aabb; do
        printf '== dhcd %s %s: ' "$name" "$m"
        target/release/dhcd bench proximity "$DATA/$name.ply" "$DATA/$next.ply" --relative 1e-3 \
            --precision f64 --method "$m" --repeat 5 --json |
            python3 -c 'import json,sys; d=json.load(sys.stdin); f=d["frames"][0]
print("%.1f ms least (frame %s), %d pairs, %d exact tests" % (f["step_ms"]["min"], sys.argv[1], f["contacts"], f["counters"]["prim_tests"]))' "$name"
    done
done
echo "== load at end: $(cut -d' ' -f1-3 /proc/loadavg)"
