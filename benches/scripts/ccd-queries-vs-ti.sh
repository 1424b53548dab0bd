#!/bin/sh
# Per-query CCD on the sample queries of Wang et al. 2021 (../shared/data/ccd/sample-queries),
# one thread: Tight Inclusion (the C++ library, tolerance 1e-6, t_max 1, 1e6 iterations,
# filters per query; `../shared/peers/tight-inclusion/ti_bench.cpp`) and dhcd's exact
# `ccd::vertex_face` / `ccd::edge_edge` (`cargo bench --bench ccd`, table only) in one run,
# joined per folder and kind. From the project root:
#
#   benches/scripts/ccd-queries-vs-ti.sh TI_SNAPSHOT > ccd-queries-vs-ti.log 2>&1
#
# TI_SNAPSHOT: a bare git clone of github.com/Continuous-Collision-Detection/Tight-Inclusion
# (built once into target/ti; needs `apt-get install cmake g++ libeigen3-dev libspdlog-dev
# libfmt-dev libgmp-dev`, see ../shared/peers/tight-inclusion/README.md).
#
# The timings differ in method: Tight Inclusion's median is over one timed call per query
# (its driver's extra pass) and its mean is its best whole-set loop / queries; dhcd's median
# and mean are over per-query times, each the best of 15 runs of 8 calls.
set -eu
PEER=../shared/peers/tight-inclusion
QUERIES=../shared/data/ccd/sample-queries
[ -d "$QUERIES" ] || { echo "no $QUERIES: nothing to measure"; exit 0; }
if [ ! -x target/ti/build/ti_bench ]; then
    [ $# -ge 1 ] || { echo "usage: $0 TI_SNAPSHOT (a bare git clone of Tight-Inclusion)" >&2; exit 2; }
    bash "$PEER/build.sh" "$1" target/ti
fi
cargo bench --bench ccd --no-run
out=$(mktemp -d)
echo "== date: $(date -u +%FT%TZ); commit: $(git rev-parse --short HEAD); load: $(cut -d' ' -f1-3 /proc/loadavg)"
target/ti/build/ti_bench "$QUERIES" 5 > "$out/ti.txt"
CCD_BENCH_TABLE_ONLY=1 cargo bench --bench ccd > "$out/dhcd.txt" 2>/dev/null
echo "== load at end: $(cut -d' ' -f1-3 /proc/loadavg)"
python3 - "$out/ti.txt" "$out/dhcd.txt" <<'EOF'
import sys
ti = {}
for line in open(sys.argv[1]):
    f = line.split()
    # folder kind config N pos FN FP maxitr FP_maxitr avg_us avg_rest median_us worst_q_us
    if line.startswith("#") or len(f) != 13 or f[2] != "per-query":
        continue
    ti[f"{f[0]}/{f[1]}"] = dict(n=int(f[3]), fp=int(f[6]), fn=int(f[5]),
                                mean_ns=1e3 * float(f[9]), median_ns=1e3 * float(f[11]))
dh = {}
for line in open(sys.argv[2]):
    f = line.split()
    if len(f) == 5 and "/" in f[0]:
        dh[f[0]] = dict(n=int(f[1]), median_ns=float(f[2]), mean_ns=float(f[3]))
print("| set | queries | TI false pos. | TI median ns | dhcd median ns | TI / dhcd | TI mean ns | dhcd mean ns | TI / dhcd |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
for k in sorted(dh):
    if k not in ti:
        continue
    t, d = ti[k], dh[k]
    assert t["n"] == d["n"], k
    print(f"| {k} | {d['n']} | {t['fp']} | {t['median_ns']:.0f} | {d['median_ns']:.0f} | "
          f"{t['median_ns'] / d['median_ns']:.1f}x | {t['mean_ns']:.0f} | {d['mean_ns']:.0f} | "
          f"{t['mean_ns'] / d['mean_ns']:.1f}x |")
EOF
rm -rf "$out"
