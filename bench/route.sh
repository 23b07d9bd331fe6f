#!/usr/bin/env bash
# Router benchmark: 20 wires (one net each, fixed pseudo-random pad pairs at various heights)
# routed by conduit::route::route with the default RouteParams through a solid 40 × 40 × 10 mm
# block of 50 layers. Prints the median wall time of 5 runs, the routed count and the total
# trace length against the straight-line lower bound. See examples/route_bench.rs.
# usage: bench/route.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet --example route_bench
./target/release/examples/route_bench
