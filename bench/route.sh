#!/usr/bin/env bash
# Router benchmark: wires (one net each, fixed pseudo-random pad pairs at various heights)
# routed by conduit::route::route with the default RouteParams through a solid block 10 mm tall
# of 50 layers: `small` (20 wires, 40 × 40 mm, median of 5 runs) and `board` (100 wires,
# 60 × 60 mm, one run). Prints the wall time, the routed count and the total trace length
# against the straight-line lower bound. See examples/route_bench.rs.
#
# With --time-limit SECONDS it checks route.time_limit instead: the corpus RedBot board (198
# wires, far more than SECONDS of routing) packed by `conduit place --auto` into a 120 × 110 ×
# 4 mm block and sliced with route.time_limit = SECONDS. It prints the routing time, the whole
# run's time and the wires routed, and fails unless routing stopped within SECONDS + 10 %.
# A second argument, `negotiated`, routes with route.strategy = "negotiated" instead.
# usage: bench/route.sh [small|board] [ordered|negotiated]   (both cases, ordered, without one)
#        bench/route.sh --time-limit SECONDS   (the corpus is ../shared/corpus, or
#        CONDUIT_CORPUS)
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${1:-}" != "--time-limit" ]; then
    cargo build --release --quiet --example route_bench
    cases=("${1:-}")
    [ -n "${1:-}" ] || cases=(small board)
    for case in "${cases[@]}"; do
        ./target/release/examples/route_bench "$case" ${2:+"$2"}
    done
    exit 0
fi
limit="${2:?usage: bench/route.sh --time-limit SECONDS}"
root="$(pwd)"
corpus="${CONDUIT_CORPUS:-$root/../shared/corpus}"
sch="$(find "$corpus/eagle/RedBot" -name '*.sch' | head -n 1)"
[ -n "$sch" ] || { echo "route.sh: no RedBot schematic under $corpus/eagle" >&2; exit 2; }
cargo build --release --quiet
bin="$root/target/release/conduit"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
python3 - "$work/block.stl" <<'PY'
import sys
x, y, z = 120.0, 110.0, 4.0
v = [(a, b, c) for a in (0, x) for b in (0, y) for c in (0, z)]
faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
with open(sys.argv[1], "w") as f:
    f.write("solid block\n")
    for q in faces:
        for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3])):
            f.write(" facet normal 0 0 0\n  outer loop\n")
            for i in t:
                f.write("   vertex %g %g %g\n" % v[i])
            f.write("  endloop\n endfacet\n")
    f.write("endsolid block\n")
PY
"$bin" -q place --model "$work/block.stl" --auto --circuit "$sch" -o "$work/placement.toml"
started=$(date +%s.%N)
"$bin" -q slice "$work/block.stl" --circuit "$sch" --placement "$work/placement.toml" \
    -o "$work/board.gcode" --report "$work/report.json" --allow-unrouted \
    --set "route.time_limit=$limit"
ended=$(date +%s.%N)
python3 - "$work/report.json" "$limit" "$started" "$ended" <<'PY'
import json, sys
report = json.load(open(sys.argv[1]))
limit, started, ended = float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
e = report["electronics"]
routing = e["routing"]
seconds = routing["wall_seconds"]
print("RedBot, route.time_limit = %g s: routing %.2f s (limit reached: %s), whole run %.2f s, "
      "%d of %d wires routed, %d rip-up round(s)"
      % (limit, seconds, routing["time_limit_reached"], ended - started, e["routed"],
         e["routed"] + e["unrouted"], routing["rounds"]))
if seconds > limit * 1.1:
    print("route.sh: routing took %.2f s, more than the limit + 10 %% (%.2f s)"
          % (seconds, limit * 1.1), file=sys.stderr)
    sys.exit(1)
PY
