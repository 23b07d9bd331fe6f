#!/usr/bin/env bash
# Slices each model with conduit and with the peer slicers (PrusaSlicer 2.5, CuraEngine 4.13) using
# the shared benchmark settings, in the same run, and prints wall time, peak memory and layer count
# for each, plus conduit's wall-time and memory ratio to CuraEngine.
#
# usage: bench/slice_vs_peers.sh [MODEL.stl...]   (default: the four ../shared/corpus/bench-models)
# needs: apt-get install prusa-slicer cura-engine; /usr/bin/time (package time)
set -euo pipefail
cd "$(dirname "$0")/.."
shared=../shared
[ $# -gt 0 ] || set -- "$shared"/corpus/bench-models/*.stl
cargo build --release --quiet --bin conduit
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT

measure() { # name output-file command... → "wall rss"
    local name=$1 o=$2; shift 2
    /usr/bin/time -v -o "$out/$name.time" "$@" >"$out/$name.log" 2>&1 || true
    awk -F': ' '
        /Elapsed \(wall clock\)/ { n = split($2, t, ":"); s = 0; for (i = 1; i <= n; i++) s = s * 60 + t[i]; w = s }
        /Maximum resident set size/ { r = $2 / 1024 }
        END { printf "%.2f %.1f\n", w, r }' "$out/$name.time"
}

printf '%-36s %-12s %8s %11s %6s\n' model slicer wall_s peak_rss_mb layers
for model in "$@"; do
    base=$(basename "$model" .stl)
    read -r cw cr < <(measure conduit "$out/$base.conduit.gcode" \
        ./target/release/conduit slice "$model" -c "$shared/bench/configs/prusaslicer.ini" -o "$out/$base.conduit.gcode")
    cl=$(awk -f "$shared/bench/gcode_layers.awk" "$out/$base.conduit.gcode" 2>/dev/null || echo -)
    printf '%-36s %-12s %8s %11s %6s\n' "$base" conduit "$cw" "$cr" "$cl"
    PEERS="prusaslicer curaengine" bash "$shared/bench/peers.sh" "$model" "$out/peers-$base" \
        | awk -v m="$base" '!/^#/ { printf "%-36s %-12s %8s %11s %6s\n", m, $1, $2, $3, $4 }' \
        | tee "$out/$base.peers"
    awk -v cw="$cw" -v cr="$cr" -v m="$base" '$2 == "curaengine" && $3 > 0 {
        printf "%-36s %-12s %8.2fx %10.2fx\n", m, "ratio/cura", cw / $3, cr / $4 }' "$out/$base.peers"
done
