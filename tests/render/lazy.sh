#!/bin/sh
# lazy.sh — lazy branches on the GPU (compiler/DESIGN.md 6.1): colorado's
# pack (895 lazy branches: tri-planar taps, mask mixes, parallax steps) and
# the same scene built with --no-lazy render the same pictures, forward and
# screen-space, within 1e-5 (the branches only skip sides whose weight is
# 0, whose eager value is then multiplied away).
#   sh lazy.sh SPLATC SPLATVIEW IMGCHECK LAZY_PACK SPV_CACHE OUT
set -u
SPLATC=$1 SV=$2 IC=$3 PACK=$4 CACHE=$5 OUT=$6/lazy
mkdir -p "$OUT"
export SPLAT_VALIDATE=1
fail() { echo "FAIL: $*"; exit 1; }
run() { echo "+ splatview $*"; "$SV" "$@" || fail "splatview $* (exit $?)"; }
rm -rf "$OUT/eager"   # --stats prints the branch count only when it builds
"$SPLATC" build examples/colorado/scene.sg -o "$OUT/eager" -j 2 --cache "$CACHE" \
    --no-lazy --stats > "$OUT/stats.txt" 2>&1 || fail "splatc build --no-lazy"
grep -q "^lazy branches: 0 " "$OUT/stats.txt" || fail "--no-lazy made lazy branches"
n=$(zstd -q -dc "$PACK"/shaders/0*.frag.zst | grep -c "splat_quad_any(.* != 0.0)")
[ "$n" -gt 0 ] || fail "the colorado pack has no lazy mul branches"
for cam in valley overview; do
    for sh in forward screen; do
        run "$PACK" --headless --size 320x180 --camera-preset $cam --shading $sh \
            --float-out "$OUT/lazy_${cam}_$sh.f32"
        run "$OUT/eager" --headless --size 320x180 --camera-preset $cam --shading $sh \
            --float-out "$OUT/eager_${cam}_$sh.f32"
        "$IC" finite "$OUT/lazy_${cam}_$sh.f32" || fail "NaN or Inf ($cam, $sh)"
        "$IC" diff "$OUT/lazy_${cam}_$sh.f32" "$OUT/eager_${cam}_$sh.f32" 1e-5 ||
            fail "lazy and eager differ ($cam, $sh)"
    done
done
echo "lazy: ok"
