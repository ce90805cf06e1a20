#!/bin/sh
# Sparse painted masks through the whole pipeline: seams.sh SPLATC SPLATVIEW
# IMGCHECK OUTDIR.  examples/minimal's fields mask (81 tiles of 32 texels,
# most of them different) built dense, sparse R8 and sparse BC4; the mask
# view of `field` (the painted mask itself) and the lit view rendered from
# the overview camera, which sees every tile border.  R8 must equal dense
# up to the GPU's 8-bit sub-texel filter weights (<= 1/255 for a 0..1 step
# between neighbours; a seam or an offset reading the wrong texels would
# show as far more); BC4 stays within its block error.
set -u
SC=$1 SV=$2 IC=$3 OUT=$4
mkdir -p "$OUT"
export SPLAT_VALIDATE=1
export SPLAT_PIPELINE_CACHE="$OUT/pipelines.bin"
fail() { echo "FAIL: $*"; exit 1; }
for f in dense r8 bc4; do
    "$SC" build examples/minimal/scene.sg -o "$OUT/$f" --painted $f --no-cache > /dev/null ||
        fail "splatc build --painted $f"
    for v in mask:field final; do
        n=$(echo "$v" | tr : _)
        "$SV" "$OUT/$f" --headless --size 480x300 --camera-preset overview --view "$v" \
            --float-out "$OUT/${f}_$n.f32" -o "$OUT/${f}_$n.png" || fail "splatview $f $v"
    done
done
grep -q '"painted_format": "r8"' "$OUT/r8/manifest.json" || fail "r8 pack is not sparse r8"
[ -e "$OUT/bc4/painted.sparse" ] && [ ! -e "$OUT/bc4/painted.r8" ] || fail "bc4 pack files"
"$IC" nonuniform "$OUT/dense_mask_field.png" || fail "the mask view shows no mask"
"$IC" diff "$OUT/r8_mask_field.f32" "$OUT/dense_mask_field.f32" 0.00393 || fail "R8 mask differs from dense"
"$IC" diff "$OUT/r8_final.f32" "$OUT/dense_final.f32" 0.00393 || fail "R8 picture differs from dense"
# BC4: 8-bit endpoints and 3-bit indices per 4x4 block (sparse.h: ~0.07 max)
"$IC" diff "$OUT/bc4_mask_field.f32" "$OUT/dense_mask_field.f32" 0.08 || fail "BC4 mask error"
echo ok
