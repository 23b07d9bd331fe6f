#!/usr/bin/env bash
# Runs the documented sample commands (README, the guide in docs/, samples/) into a temporary
# folder and prints one sha256 per output file, sorted by name: the byte-level fingerprint of
# conduit's behaviour.
#
#   bench/golden.sh                 # uses target/release/conduit (build it first)
#   CONDUIT=path/to/conduit bench/golden.sh
#   bench/golden.sh > bench/golden.txt   # record (only on purpose: name every changed hash)
#
# A refactor proves itself by printing the same lines as bench/golden.txt (the test
# `golden_outputs_are_unchanged` runs this script and compares). Reports are hashed with their
# wall-clock fields (`stage_seconds`, `wall_seconds`) removed; everything else is hashed as
# written. Commands whose input is the shared corpus (a peer slicer's G-code for postprocess)
# run only when ../shared/corpus exists, and their lines are marked `corpus:`.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bin="${CONDUIT:-$root/target/release/conduit}"
[ -x "$bin" ] || { echo "golden.sh: no conduit binary at $bin (cargo build --release)" >&2; exit 2; }
corpus="${CONDUIT_CORPUS:-$root/../shared/corpus}"

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work"
ln -s "$root/samples" samples
mkdir out
export NO_COLOR=1

# GOLDEN_KEEP=DIR keeps a copy of every output in DIR (the browser tests view them).
# run NAME ARGS...: runs conduit with ARGS in the work folder; stdout is kept as out/NAME.stdout.
# A failing command fails the script (its stderr is shown).
run() {
    local name="$1"
    shift
    if ! "$bin" "$@" > "out/$name.stdout" 2> "out/$name.stderr"; then
        echo "golden.sh: '$name' failed: conduit $*" >&2
        cat "out/$name.stderr" >&2
        exit 1
    fi
    rm -f "out/$name.stderr"
}

# --- slice -----------------------------------------------------------------------------------
run slice_bracket slice samples/l_bracket.obj -o out/l_bracket.gcode
run slice_cube slice samples/cube_20mm.stl -o out/cube.gcode --report out/cube.json
run slice_hole slice samples/cube_with_hole.stl -o out/hole.gcode --report out/hole.json
run slice_thin slice samples/thin_walls.stl -o out/thin_walls.gcode
run slice_overhangs slice samples/overhangs.stl --set slice.support_material=true -o out/overhangs.gcode
run slice_overhangs_brim slice samples/overhangs.stl --set slice.brim_width=4 --set slice.brim_type=ears -o out/overhangs_brim.gcode
run slice_bracket_two_tool slice samples/l_bracket.obj -c samples/two_tool_printer.toml \
    -o out/bracket_two_tool.gcode
run convert_parts convert samples/cube_20mm.stl -o out/cube.3mf
run slice_demo slice samples/circuit_demo/block.stl --circuit samples/circuit_demo/led_coin.sch \
    --placement samples/circuit_demo/placement.toml -o out/demo.gcode --report out/demo.json
run slice_tops slice samples/thick_dish.stl --curved tops -o out/tops.gcode --report out/tops.json
run slice_dish_buffer slice samples/dish_shell.stl --curved clfff --set curved.buffer=true \
    -o out/dish.gcode --report out/dish.json
run slice_dish_split slice samples/dish_shell.stl --curved clfff --split-sections -o out/dish_split.gcode
run slice_thick_sandwich slice samples/thick_dish.stl --curved clfff --set curved.sandwich=true \
    -o out/thick.gcode --report out/thick.json

# --- postprocess: conduit's own cube as the host file, then peer slicers' cubes ----------------
cp out/cube.gcode out/pp_plain.gcode
run postprocess_plain postprocess out/pp_plain.gcode --report out/pp_plain.json
cp out/cube.gcode out/pp_circuit.gcode
run postprocess_circuit postprocess out/pp_circuit.gcode --circuit samples/postprocess/cube_led.sch \
    --placement samples/postprocess/cube_led.toml --report out/pp_circuit.json
if [ -d "$corpus/peer-gcode" ]; then
    for host in prusaslicer-2.5 curaengine-4.13 slic3r-1.3; do
        cp "$corpus/peer-gcode/20mm_cube.$host.gcode" "out/corpus_pp_$host.gcode"
        run "corpus_pp_$host" postprocess "out/corpus_pp_$host.gcode" \
            --circuit samples/postprocess/cube_led.sch --placement samples/postprocess/cube_led.toml \
            --report "out/corpus_pp_$host.json"
        cp "$corpus/peer-gcode/20mm_cube.$host.gcode" "out/corpus_pp_plain_$host.gcode"
        run "corpus_pp_plain_$host" postprocess "out/corpus_pp_plain_$host.gcode" \
            --report "out/corpus_pp_plain_$host.json"
    done
fi

# --- conform, 3-axis and every robot dialect -------------------------------------------------
run conform_monopole conform --surface samples/conform/wrinkled_film.xyz \
    --design samples/conform/monopole.svg --set 'printer.start_gcode=G28' \
    -o out/monopole.gcode --report out/monopole.json
for design in spiral hilbert_loop lines; do
    run "conform_$design" conform --surface samples/conform/wrinkled_film.xyz \
        --design "samples/conform/$design.svg" -o "out/conform_$design.gcode" \
        --report "out/conform_$design.json"
done
for dialect in urscript krl rapid poses-csv gcode-5axis; do
    run "conform_$dialect" conform --surface samples/conform/wrinkled_film.xyz \
        --design samples/conform/monopole.svg --tool-axis normal --dialect "$dialect" \
        -o "out/monopole_$dialect.out" --report "out/monopole_$dialect.json"
done

# --- aerosol jet ---------------------------------------------------------------------------
run jet_star jet samples/jet/star8.svg --width 20 --layers 32 --layer-height 5 \
    -o out/star.gcode --report out/star.json
run jet_dog jet samples/jet/dog.svg --width 20 --layers 8 --layer-height 5 --set jet.fill=contour \
    -o out/dog.gcode --report out/dog.json
# Every branch of the jet's G-code: chords instead of arcs, no E words, the shutter on the fly
# (on walls, on contour fills, with chords), serpentine fills, another flavour with snippets
# that have blank lines and trailing blanks.
run jet_star_chords jet samples/jet/star8.svg --width 20 --layers 4 --layer-height 5 \
    --set jet.arcs=false -o out/star_chords.gcode --report out/star_chords.json
run jet_star_no_e jet samples/jet/star8.svg --width 20 --layers 4 --layer-height 5 \
    --set jet.e_words=false -o out/star_no_e.gcode --report out/star_no_e.json
run jet_star_lead jet samples/jet/star8.svg --width 20 --layers 4 --layer-height 5 \
    --set jet.shutter_lead_time=0.05 -o out/star_lead.gcode --report out/star_lead.json
run jet_star_lead_chords jet samples/jet/star8.svg --width 20 --layers 4 --layer-height 5 \
    --set jet.shutter_lead_time=0.05 --set jet.arcs=false --set jet.e_words=false \
    -o out/star_lead_chords.gcode --report out/star_lead_chords.json
run jet_dog_lead jet samples/jet/dog.svg --width 20 --layers 4 --layer-height 5 \
    --set jet.fill=contour --set jet.shutter_lead_time=0.05 \
    -o out/dog_lead.gcode --report out/dog_lead.json
run jet_dog_serpentine jet samples/jet/dog.svg --width 20 --layers 2 --layer-height 5 \
    --set jet.fill=serpentine --set jet.speed=3.5 --set jet.travel_speed=25 \
    -o out/dog_serpentine.gcode --report out/dog_serpentine.json
run jet_star_snippets jet samples/jet/star8.svg --width 20 --layers 2 --layer-height 5 \
    --set printer.flavor=klipper --set 'jet.start_gcode="G28\n\n  M400  \n"' \
    --set 'jet.shutter_open_gcode="SET_PIN PIN=shutter VALUE=1  \nG4 P10\n"' \
    --set 'jet.shutter_close_gcode=""' --set 'jet.end_gcode="M84\n\nM117 done"' \
    -o out/star_snippets.gcode --report out/star_snippets.json
run jet_model jet model --angle 30 --width 35 --height 14 --roi 150 --json

# --- robot calibration and gap compensation ----------------------------------------------------
run calibrate_tcp calibrate tcp samples/robot/pivot.csv --report out/tcp.json
run calibrate_register calibrate register samples/robot/scanner_points.csv \
    samples/robot/robot_points.csv --report out/register.json
run compensate_pattern compensate pattern circle --size 10 --surface sphere:15 -o out/circle.csv
run compensate_simulate compensate out/circle.csv --simulate sphere:15 --shift 3,1.5,0 --tilt 0.5 \
    --noise 2 --passes 2 --readings-out out/gaps.csv -o out/circle.comp.csv --report out/sim.json
run compensate_gaps compensate out/circle.csv --gaps out/gaps.csv -o out/circle.gaps.csv \
    --program out/circle.src --dialect krl --report out/gaps.json

# --- route, preview, convert ------------------------------------------------------------------
# README and guide: a board's layout placed, sliced, checked.
run place_led_coin place --model samples/circuit_demo/block.stl \
    --from-brd samples/circuit_demo/led_coin.brd -o out/led_coin.toml
run slice_led_coin slice samples/circuit_demo/block.stl --circuit samples/circuit_demo/led_coin.sch \
    --placement out/led_coin.toml -o out/led_coin.gcode
run check_led_coin check out/led_coin.gcode --circuit samples/circuit_demo/led_coin.sch \
    --placement out/led_coin.toml --model samples/circuit_demo/block.stl
run place_led_coin_auto place --model samples/circuit_demo/block.stl --auto \
    --circuit samples/circuit_demo/led_coin.sch -o out/led_coin_auto.toml
run slice_led_coin_auto slice samples/circuit_demo/block.stl \
    --circuit samples/circuit_demo/led_coin.sch --placement out/led_coin_auto.toml \
    -o out/led_coin_auto.gcode
run route_demo route samples/circuit_demo/block.stl --circuit samples/circuit_demo/led_coin.sch \
    --placement samples/circuit_demo/placement.toml --out-dir out/route --report out/route.json
run preview_demo preview out/demo.gcode -o out/preview_demo
run preview_star preview out/star.gcode -o out/preview_star
run convert_stl convert samples/l_bracket.obj -o out/l_bracket.stl
run convert_obj convert samples/cube_with_hole.stl -o out/cube_with_hole.obj
mkdir -p out/batch
run convert_batch convert samples/cube_20mm.stl samples/dish_shell.stl --to 3mf --out-dir out/batch

# --- what commands print --------------------------------------------------------------------
run info info --json samples/cube_20mm.stl samples/l_bracket.obj samples/circuit_demo/led_coin.sch \
    samples/conform/monopole.svg samples/conform/wrinkled_film.xyz
run check_demo check out/demo.gcode --json
run check_bracket check out/bracket_two_tool.gcode -c samples/two_tool_printer.toml --json
run config_defaults config --defaults

# --- view: the 3D pages of a planar print and of the circuit demo with its model --------------
run view_cube view out/cube.gcode -o out/view_cube.html
run view_demo view out/demo.gcode --model samples/circuit_demo/block.stl \
    --circuit samples/circuit_demo/led_coin.sch --placement samples/circuit_demo/placement.toml \
    -o out/view_demo.html

if [ -n "${GOLDEN_KEEP:-}" ]; then
    mkdir -p "$GOLDEN_KEEP"
    cp -r out/. "$GOLDEN_KEEP"/
fi

# Hash every output, reports without their wall-clock fields.
cd out
find . -type f | LC_ALL=C sort | while read -r f; do
    name="${f#./}"
    tag=""
    case "$name" in corpus_*) tag="corpus:" ;; esac
    case "$name" in
        *.json)
            hash=$(python3 -c '
import json, sys
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items() if k not in ("stage_seconds", "wall_seconds")}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v
text = open(sys.argv[1], "rb").read()
try:
    doc = json.loads(text)
except ValueError:
    sys.stdout.write(text.decode("utf-8", "replace")); sys.exit(0)
sys.stdout.write(json.dumps(strip(doc), indent=1))
' "$name" | sha256sum | cut -d' ' -f1) ;;
        *) hash=$(sha256sum "$name" | cut -d' ' -f1) ;;
    esac
    echo "$hash  $tag$name"
done
