#!/bin/sh
# gallery.sh BUILD OUT — what `make gallery` runs: colorado and billingsley
# from six camera presets each (ground, meadow, mid, cliffs, far, top_down),
# rendered headless (lavapipe where there is no GPU) into OUT (docs/gallery).
set -eu
BUILD=${1:-build}
OUT=${2:-docs/gallery}
SIZE=${SPLAT_GALLERY_SIZE:-960x540}
SPLATC="$BUILD/compiler/splatc"
VIEW="$BUILD/runtime/splatview"
for tool in "$SPLATC" "$VIEW"; do
    if [ ! -x "$tool" ]; then
        echo "gallery: $tool is missing: build first (make build)" >&2
        exit 1
    fi
done
JOBS=$(nproc 2>/dev/null || echo 2)
WORK=$(mktemp -d "${TMPDIR:-/tmp}/splat-gallery.XXXXXX")
trap 'rm -rf "$WORK"' EXIT INT TERM
mkdir -p "$OUT"
for scene in colorado billingsley; do
    "$SPLATC" build "examples/$scene/scene.sg" -o "$WORK/$scene.pack" -j "$JOBS"
    for preset in ground meadow mid cliffs far top_down; do
        "$VIEW" "$WORK/$scene.pack" --headless --size "$SIZE" \
            --camera-preset "$preset" -o "$WORK/${scene}_$preset.png"
        mv "$WORK/${scene}_$preset.png" "$OUT/${scene}_$preset.png"
        echo "gallery: $OUT/${scene}_$preset.png"
    done
done
