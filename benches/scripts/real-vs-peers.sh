#!/bin/sh
# One run of everything docs/PERFORMANCE.md quotes for the real frames, so that the ratios
# come from one sitting: CGAL's self_intersections, the criterion `real/*` bench (dhcd's three
# methods and parry3d), and `dhcd bench` on 1 and 2 threads. From the project root:
#
#   benches/scripts/real-vs-peers.sh > real-vs-peers.log 2>&1
#
# Needs ../shared (the frames and the CGAL harness, which apt-installs libcgal-dev if missing).
set -eu
DATA=../shared/data/real-frames
[ -d "$DATA" ] || { echo "no $DATA: nothing to measure"; exit 0; }
[ -x target/cgal_self ] || OUT=target/cgal_self ../shared/peers/cgal/build.sh
cargo build --release -p dhcd-cli
echo "== date: $(date -u +%FT%TZ); load: $(cut -d' ' -f1-3 /proc/loadavg)"
for f in "$DATA"/*.ply; do
    printf '== cgal %s: ' "$(basename "$f")"
    target/cgal_self "$f" seq 5 2>&1 >/dev/null | tail -1
done
for pair in cloth-ball-92:93 rod-twist-3036:3037 n-body-simulation-18:19 armadillo-rollers-326:327; do
    name=${pair%:*}; next=${name%-*}-${pair#*:}
    for t in 1 2; do
        echo "== dhcd bench $name $next --threads $t"
        target/release/dhcd bench self "$DATA/$name.ply" "$DATA/$next.ply" --method all --repeat 5 --threads "$t" | grep -v '^  step'
    done
done
cargo bench --bench real -- --warm-up-time 1 --measurement-time 3 2>&1 | grep -E '^real/|time:|contacts'
echo "== load at end: $(cut -d' ' -f1-3 /proc/loadavg)"
