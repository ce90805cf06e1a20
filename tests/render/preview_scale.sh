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
#            pixels over on the screen path (5048 since the smooth fast path)
#   refused  --preview-scale 3
#   window   P cycles the scale (1, 1/2, 1/4, 1) under xvfb, validation
#            silent, each picture another, back at 1 the first
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
# the window: P cycles 1 -> 1/2 -> 1/4 -> 1, validation silent; each scale
# shows another picture, and back at 1 the first one again
command -v xvfb-run > /dev/null || { echo "SKIP: no xvfb-run for the window part"; exit 77; }
rm -f "$OUT"/win_*.png
SPLAT_VALIDATE=1 xvfb-run -a -s "-screen 0 640x480x24" "$SV" "$PACK" --size 320x200 --script \
    "frames=3;screenshot=$OUT/win_1.png;key=P;frames=3;screenshot=$OUT/win_2.png;key=P;frames=3;screenshot=$OUT/win_4.png;key=P;frames=3;screenshot=$OUT/win_1b.png;quit" \
    > "$OUT/window.log" 2>&1 || { cat "$OUT/window.log"; fail "window: splatview exit $?"; }
for k in 2 4 1; do
    grep -q "^splatview: preview scale 1/$k$" "$OUT/window.log" || fail "window: no 'preview scale 1/$k'"
done
for k in 1 2 4 1b; do
    "$IC" nonuniform "$OUT/win_$k.png" || fail "window: the picture at $k is uniform"
done
cmp -s "$OUT/win_1.png" "$OUT/win_2.png" && fail "window: P changed nothing"
cmp -s "$OUT/win_2.png" "$OUT/win_4.png" && fail "window: 1/2 and 1/4 look the same"
cmp -s "$OUT/win_1.png" "$OUT/win_1b.png" || fail "window: back at scale 1, another picture"
echo "ok: the window's P key cycles the preview scale"
