#!/bin/sh
# Peers on the same data: voltex, Mitsuba 3 and Blender Cycles render one exported volume from
# one camera, and `voltex pareto --peers` charts them together. Not part of CI.
#
#   tools/peers/run.sh [SCENE] [OUT]      (default scenes/volumes/absorbing_box.ron, out/peers/<stem>)
#
# Needs target/release/voltex, a venv with mitsuba and numpy (PEERS_VENV, default
# /tmp/peers-venv) and one with bpy 5.0 and numpy (BPY_VENV, default /tmp/bpy-venv):
#   python3 -m venv /tmp/peers-venv && /tmp/peers-venv/bin/pip install mitsuba numpy
#   python3 -m venv /tmp/bpy-venv && /tmp/bpy-venv/bin/pip install bpy numpy
# SPP (default 1,4,16,64,256) sets the sample counts. The truth: for a purely absorbing medium
# (ALBEDO 0, the default) voltex's exact Reference with SUPERSAMPLE^2 samples a pixel (default
# 8); for a scattering one (ALBEDO > 0, e.g. tools/peers/scattering_box.ron) Mitsuba at
# TRUTH_SPP samples a pixel (default 1024), and voltex's own images are compared with it
# instead of charted (its shading is not a phase function: the error is the model's).
set -eu
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
SCENE=${1:-$ROOT/scenes/volumes/absorbing_box.ron}
STEM=$(basename "$SCENE" .ron)
OUT=${2:-$ROOT/out/peers/$STEM}
VOLTEX=${VOLTEX:-$ROOT/target/release/voltex}
PEERS_VENV=${PEERS_VENV:-/tmp/peers-venv}
BPY_VENV=${BPY_VENV:-/tmp/bpy-venv}
SPP=${SPP:-1,4,16,64,256}
ALBEDO=${ALBEDO:-0.0}
export VOLTEX
mkdir -p "$OUT"

echo "== export: the volume (density_scale applied, world transform) and the view"
"$VOLTEX" export "$SCENE" --out "$OUT/export" --view -q
VDB=$(ls "$OUT"/export/*.vdb | head -n 1)

echo "== Mitsuba: $VDB to .vol"
"$BPY_VENV/bin/python" "$ROOT/tools/peers/vdb_to_vol.py" "$VDB" "$OUT/grid" 2>/dev/null

if [ "$ALBEDO" = "0.0" ] || [ "$ALBEDO" = "0" ]; then
    echo "== truth: the exact Reference (optical depth of every voxel cell), ${SUPERSAMPLE:-8}^2 samples a pixel"
    "$VOLTEX" render "$SCENE" --method reference --supersample "${SUPERSAMPLE:-8}" -o "$OUT/truth.exr" | tail -n 1
    echo "== the truth checked: voltex's Reference at the pixel centres against analytic.py's exact f64 transmittance"
    "$VOLTEX" render "$SCENE" --method reference -o "$OUT/reference.exr" > /dev/null
    "$BPY_VENV/bin/python" "$ROOT/tools/peers/analytic.py" --view "$OUT/export/view.json" --vdb "$VDB" \
        --out "$OUT/analytic.exr" 2>/dev/null
    echo "Reference against analytic: $("$VOLTEX" compare "$OUT/reference.exr" "$OUT/analytic.exr" --json)"
else
    echo "== truth: Mitsuba at ${TRUTH_SPP:-1024} samples a pixel"
    "$PEERS_VENV/bin/python" "$ROOT/tools/peers/mitsuba_peer.py" --view "$OUT/export/view.json" --vol "$OUT/grid" \
        --spp "${TRUTH_SPP:-1024}" --albedo "$ALBEDO" --out "$OUT/truth"
    cp "$OUT/truth/mitsuba_${TRUTH_SPP:-1024}.exr" "$OUT/truth.exr"
fi
"$PEERS_VENV/bin/python" "$ROOT/tools/peers/mitsuba_peer.py" --view "$OUT/export/view.json" --vol "$OUT/grid" \
    --truth "$OUT/truth.exr" --spp "$SPP" --albedo "$ALBEDO" --out "$OUT"

echo "== Cycles"
"$BPY_VENV/bin/python" "$ROOT/tools/peers/cycles_peer.py" --view "$OUT/export/view.json" --vdb "$VDB" \
    --truth "$OUT/truth.exr" --spp "$SPP" --albedo "$ALBEDO" --out "$OUT" 2>&1 | grep -E "spp|Blender"

if [ "$ALBEDO" != "0.0" ] && [ "$ALBEDO" != "0" ]; then
    echo "== voltex against Mitsuba's converged image (the difference of the shading models)"
    for method in scene reference; do
        if [ $method = scene ]; then opt=""; else opt="--method reference"; fi
        "$VOLTEX" render "$SCENE" $opt -o "$OUT/voltex_$method.exr" > /dev/null
        echo "voltex $method: $("$VOLTEX" compare "$OUT/voltex_$method.exr" "$OUT/truth.exr" --json)"
    done
    exit 0
fi

echo "== voltex pareto with the peers"
"$VOLTEX" pareto "$SCENE" --methods reference,ray-march --ray-steps "${RAY_STEPS:-0.0078125,0.015625,0.03125,0.0625,0.125}" \
    --out "$OUT/pareto" --peers "$OUT/mitsuba.csv" "$OUT/cycles.csv"
