#!/usr/bin/env bash
# The 3D view's budget: page size and time to the first frame in headless Chromium.
#
#   bench/view.sh                 # 3DBenchy from the shared corpus, sliced by conduit
#   bench/view.sh FILE.gcode ...  # any G-code files
#
# For each file: `conduit view` writes the page (with the model for Benchy), then Chromium
# (Debian's `chromium`, software WebGL) loads it 5 times with a fresh profile and prints the DOM
# once the page has loaded; the page stamps `data-first-frame-ms` on <body> when its first
# frame is drawn (milliseconds since navigation start: HTML parsed, three.js and the data
# decoded, buffers built, one frame rendered). The median of the 5 is reported. Targets: the
# Benchy page under 10 MB, its first frame under 2 s.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bin="${CONDUIT:-$root/target/release/conduit}"
[ -x "$bin" ] || { echo "view.sh: no conduit binary at $bin (cargo build --release)" >&2; exit 2; }
chromium="${CONDUIT_CHROMIUM:-$(command -v chromium || true)}"
[ -n "$chromium" ] || { echo "view.sh: chromium not found (apt-get install chromium)" >&2; exit 2; }
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

pages=()
if [ $# -eq 0 ]; then
    benchy="$root/../shared/corpus/3DBenchy/Single-part/3DBenchy.3mf"
    [ -f "$benchy" ] || { echo "view.sh: $benchy not found; give G-code files" >&2; exit 2; }
    "$bin" -q slice "$benchy" -o "$work/benchy.gcode"
    "$bin" -q view "$work/benchy.gcode" -o "$work/benchy.html"
    "$bin" -q view "$work/benchy.gcode" --model "$benchy" -o "$work/benchy_model.html"
    pages=("$work/benchy.html" "$work/benchy_model.html")
else
    i=0
    for f in "$@"; do
        i=$((i + 1))
        "$bin" -q view "$f" -o "$work/page_$i.html"
        pages+=("$work/page_$i.html")
    done
fi

printf '%-22s %10s %16s %12s\n' page "size MB" "first frame ms" "runs (ms)"
for page in "${pages[@]}"; do
    runs=()
    for _ in 1 2 3 4 5; do
        profile="$(mktemp -d -p "$work")"
        ms=$("$chromium" --headless --no-sandbox --disable-gpu --enable-unsafe-swiftshader \
            --use-angle=swiftshader --disable-background-networking --disable-component-update \
            --disable-sync --disable-quic --no-first-run --window-size=1280,800 \
            --user-data-dir="$profile" --dump-dom "file://$page" 2>/dev/null \
            | grep -o 'data-first-frame-ms="[0-9]*"' | grep -o '[0-9]*' || echo "-")
        runs+=("$ms")
    done
    median=$(printf '%s\n' "${runs[@]}" | grep -v -- - | sort -n | sed -n 3p)
    size=$(awk -v b="$(stat -c %s "$page")" 'BEGIN { printf "%.2f", b / 1e6 }')
    printf '%-22s %10s %16s %12s\n' "$(basename "$page")" "$size" "${median:--}" "${runs[*]}"
done
