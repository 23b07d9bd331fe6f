#!/usr/bin/env bash
# Retractions and separate infill runs, conduit against PrusaSlicer, on the bench models.
#
# A retraction is a move that lowers E without XY motion (absolute or relative E, `G92 E`
# resets followed), or a `G10` firmware retraction (not RepRapFirmware's `G10 P…`/`L…` tool
# offsets). An infill run is a stretch of extruding XY moves under one `;TYPE:` of infill
# (`Internal infill`, `Solid infill`, `Top solid infill`, `Bridge infill`); any other move
# (travel, retraction, a move of another type) ends it. Both slicers' files are counted by the
# same awk program.
#
# usage: bench/retractions.sh [MODEL.stl...]   (default: the four ../shared/corpus/bench-models)
#        bench/retractions.sh --count FILE.gcode...   (the counts of existing G-code files)
# env:   OUT=DIR keeps the G-code there (default: a temp dir, removed at the end)
# needs: apt-get install prusa-slicer; a release build (cargo build --release)
set -euo pipefail

# Prints "retractions infill_runs" for one G-code file.
count() {
    awk '
    function word(s, letter,   re) {
        re = "(^|[ \t])" letter "[-+.0-9]+"
        if (match(s, re)) { w = substr(s, RSTART, RLENGTH); sub(/^[ \t]*[A-Z]/, "", w); return w + 0 }
        return "none"
    }
    BEGIN { rel = 0; e = 0; retr = 0; runs = 0; inrun = 0; type = "" }
    /^;TYPE:/ { type = substr($0, 7); next }
    {
        line = $0; sub(/;.*/, "", line); line = toupper(line)
        if (line ~ /^[ \t]*$/) next
        split(line, f, /[ \t]+/); cmd = f[1]; if (cmd == "") cmd = f[2]
        if (cmd == "M83") { rel = 1; next }
        if (cmd == "M82") { rel = 0; next }
        if (cmd == "G92") { v = word(line, "E"); if (v != "none") e = v; next }
        if (cmd == "G10") {
            if (line !~ /[ \t][PLSR]/) { retr++; inrun = 0 }
            next
        }
        if (cmd != "G0" && cmd != "G1" && cmd != "G2" && cmd != "G3") next
        xy = (word(line, "X") != "none" || word(line, "Y") != "none")
        v = word(line, "E"); de = 0
        if (v != "none") { de = rel ? v : v - e; e = rel ? e + v : v }
        if (!xy && de < 0) { retr++; inrun = 0; next }
        if (!xy) next
        infill = (type ~ /infill/) && de > 0
        if (infill && !inrun) runs++
        inrun = infill
    }
    END { print retr, runs }' "$1"
}

if [ "${1:-}" = --count ]; then
    shift
    for f in "$@"; do printf '%s %s\n' "$(count "$f")" "$f"; done
    exit 0
fi

# Paths given relative to the caller's folder, before moving to the repository root.
models=()
for m in "$@"; do models+=("$(realpath "$m")"); done
if [ -n "${OUT:-}" ]; then mkdir -p "$OUT"; out=$(realpath "$OUT"); else out=$(mktemp -d); trap 'rm -rf "$out"' EXIT; fi
cd "$(dirname "$0")/.."
shared=../shared
[ ${#models[@]} -gt 0 ] || models=("$shared"/corpus/bench-models/*.stl)
[ -x target/release/conduit ] || { echo "build first: cargo build --release" >&2; exit 2; }

printf '%-36s %10s %10s %7s %10s %10s %7s\n' model retr_cnd retr_ps ratio runs_cnd runs_ps ratio
for model in "${models[@]}"; do
    base=$(basename "$model" .stl)
    ./target/release/conduit -q slice "$model" -c "$shared/bench/configs/prusaslicer.ini" \
        -o "$out/$base.conduit.gcode"
    [ -s "$out/$base.prusaslicer.gcode" ] ||
        PEERS=prusaslicer bash "$shared/bench/peers.sh" "$model" "$out" >/dev/null
    read -r cr ci < <(count "$out/$base.conduit.gcode")
    read -r pr pi < <(count "$out/$base.prusaslicer.gcode")
    awk -v m="$base" -v cr="$cr" -v pr="$pr" -v ci="$ci" -v pi="$pi" 'BEGIN {
        printf "%-36s %10d %10d %6.2fx %10d %10d %6.2fx\n", m, cr, pr, pr ? cr / pr : 0, ci, pi, pi ? ci / pi : 0 }'
done
