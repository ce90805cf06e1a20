#!/bin/sh
# make demo: compile the colorado scene into a shader pack and render it
# headless (lavapipe on a machine without a GPU).  Usage: demo.sh BUILD_DIR
set -e
build=${1:-build}
out=out
mkdir -p "$out"
splatc="$build/compiler/splatc"
splatview="$build/runtime/splatview"
jobs=$(nproc 2>/dev/null || echo 2)

echo "== splatc build examples/colorado/scene.sg -> $out/colorado.pack"
"$splatc" build examples/colorado/scene.sg -o "$out/colorado.pack" -j "$jobs" --stats \
    | grep -E '^(cells|combinations|largest|naive|total|analysis time)' || true

camera=${SPLAT_DEMO_CAMERA:-blanca}
echo "== splatview --headless (camera preset '$camera')"
"$splatview" "$out/colorado.pack" --headless --size 1280x720 --camera-preset "$camera" \
    -o "$out/demo.png" --stats | grep -E '^(device|patches|pipelines|combinations|gpu)'
"$splatview" "$out/colorado.pack" --headless --size 1280x720 --camera-preset "$camera" \
    --view combos -o "$out/demo_combos.png"

cat <<MSG

Pictures:
  $out/demo.png         the colorado scene, lit
  $out/demo_combos.png  one colour per material combination (seed 000 Fig. 14)
Open the viewer (needs a display):
  $splatview $out/colorado.pack --scene examples/colorado/scene.sg
MSG
