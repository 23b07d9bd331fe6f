#!/usr/bin/env bash
# Router benchmark: wires (one net each, fixed pseudo-random pad pairs at various heights)
# routed by conduit::route::route with the default RouteParams through a solid block 10 mm tall
# of 50 layers: `small` (20 wires, 40 × 40 mm, median of 5 runs) and `board` (100 wires,
# 60 × 60 mm, one run). Prints the wall time, the routed count and the total trace length
# against the straight-line lower bound. See examples/route_bench.rs.
# usage: bench/route.sh [small|board]   (both without an argument)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet --example route_bench
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=(small board)
for case in "${cases[@]}"; do
    ./target/release/examples/route_bench "$case"
done
