#!/usr/bin/env bash
# Read throughput of the STL and 3MF readers on the 3DBenchy benchmark model, and the time of
# the mesh topology check and repair.
# usage: bench/read_throughput.sh [MODEL.stl]   (default ../shared/corpus/bench-models/3DBenchy.stl)
set -euo pipefail
cd "$(dirname "$0")/.."
model=${1:-../shared/corpus/bench-models/3DBenchy.stl}
[ -r "$model" ] || { echo "cannot read $model" >&2; exit 2; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cargo build --release --quiet --bin conduit --example read_throughput
./target/release/conduit convert "$model" -o "$tmp/model.3mf"
./target/release/conduit convert "$model" --ascii -o "$tmp/model_ascii.stl"
./target/release/examples/read_throughput "$model" "$tmp/model_ascii.stl" "$tmp/model.3mf"
