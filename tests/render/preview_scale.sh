#!/bin/sh
# tests/render/preview_scale.sh SPLATVIEW IMGCHECK PACK OUT
# The preview scale (runtime/upscale.c) on examples/minimal at 320x180,
# every run under SPLAT_VALIDATE=1 (splatview exits 3 on a message):
#   floors   each path (screen with the geometry pass's depth, screen ray
#            cast, forward) at --preview-scale 2 and 4 against 1: the
#            output has the full size and a PSNR over the floor (measured
#            on lavapipe: 30.8-31.6 dB at 2, 28.4-29.1 dB at 4)
#   guide    the depth-aware upsample leaves more pixels within 0.05 of
#            full resolution than a bilinear one (SPLAT_UPSCALE=bilinear:
#            silhouettes blurred into halos); measured 5034 against 5838
#            pixels over on the screen path
#   refused  --preview-scale 3
set -u
SV=$1 IC=$2 PACK=$3 OUT=$4
mkdir -p "$OUT"
fail() { echo "FAIL: $*" >&2; exit 1; }
render() {   # name, options...
    name=$1
    shift
    SPLAT_VALIDATE=1 "$SV" "$PACK" --headless --size 320x180 -o "$OUT/$name.png" \
        --float-out "$OUT/$name.f32" "$@" > "$OUT/$name.log" 2>&1 ||
        { cat "$OUT/$name.log"; fail "$name: splatview exit $?"; }
}
for path in raster raycast forward; do
    opts="--shading screen --screen-depth $path"
    [ $path = forward ] && opts="--shading forward"
    render "${path}_1" $opts
    for s in 2 4; do
        floor=29.5
        [ $s = 4 ] && floor=27
        render "${path}_$s" $opts --preview-scale $s
        "$IC" close "$OUT/${path}_1.f32" "$OUT/${path}_$s.f32" 1 0 $floor ||
            fail "$path at 1/$s: PSNR under $floor dB (or another size)"
    done
done
over() {   # A B: the pixels over 0.05
    "$IC" close "$1" "$2" 0.05 0 0 | sed -n 's/.*(\([0-9]*\) over.*/\1/p'
}
SPLAT_UPSCALE=bilinear render raster_bilinear --shading screen --screen-depth raster --preview-scale 2
g=$(over "$OUT/raster_1.f32" "$OUT/raster_2.f32")
b=$(over "$OUT/raster_1.f32" "$OUT/raster_bilinear.f32")
echo "pixels over 0.05 of full resolution: depth-aware $g, bilinear $b"
[ -n "$g" ] && [ -n "$b" ] && [ "$g" -lt "$b" ] ||
    fail "the depth guide does not beat bilinear ($g against $b pixels over 0.05)"
if "$SV" "$PACK" --headless --size 32x18 --preview-scale 3 -o "$OUT/x.png" > "$OUT/three.log" 2>&1
then
    fail "--preview-scale 3 was accepted"
fi
echo "ok: preview scales 2 and 4 over their PSNR floors on three paths; the depth guide beats bilinear"
