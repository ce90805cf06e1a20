#!/bin/sh
# demo.sh BUILD — what `make demo` runs after building: compile the colorado
# scene into a shader pack and render it headless (lavapipe where there is no
# GPU): the lit picture and the combinations view beside it (Andersson 2007 Fig. 14).
set -eu
BUILD=${1:-build}
SPLATC="$BUILD/compiler/splatc"
VIEW="$BUILD/runtime/splatview"
CAMERA=${SPLAT_DEMO_CAMERA:-valley}
SIZE=${SPLAT_DEMO_SIZE:-1280x720}
for tool in "$SPLATC" "$VIEW"; do
    if [ ! -x "$tool" ]; then
        echo "demo: $tool is missing: build first (make build)" >&2
        exit 1
    fi
done
mkdir -p out
JOBS=$(nproc 2>/dev/null || echo 2)
"$SPLATC" build examples/colorado/scene.sg -o out/colorado.pack -j "$JOBS" --stats
"$VIEW" out/colorado.pack --headless -o out/demo.png --size "$SIZE" --camera-preset "$CAMERA"
# the combination of each patch, as the paper's figure draws it (the
# default screen path would show each 8x8 tile's choice)
"$VIEW" out/colorado.pack --headless -o out/demo_combos.png --size "$SIZE" \
    --camera-preset "$CAMERA" --view combos --shading forward
# on the ground, where the undergrowth grows (none from the air)
"$VIEW" out/colorado.pack --headless -o out/demo_meadow.png --size "$SIZE" --camera-preset meadow
echo
echo "pictures:  out/demo.png  out/demo_combos.png  (camera preset '$CAMERA'),"
echo "           out/demo_meadow.png  (preset 'meadow': undergrowth)"
echo "viewer:    $VIEW out/colorado.pack --camera-preset $CAMERA"
echo "other presets: valley overview blanca spanish_peaks pivots trinidad meadow ground mid cliffs far top_down (SPLAT_DEMO_CAMERA=...)"
