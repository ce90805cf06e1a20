#!/bin/sh
# tests/render/shading_lod.sh SPLATVIEW IMGCHECK PACK OUT PRESET
# The CPU shading LOD (runtime/DESIGN.md "CPU shading LOD"; splatview
# --shading-lod) at 320x180, every run under SPLAT_VALIDATE=1 (splatview
# exits 3 on a message):
#   on/off   the screen path with it on against off: another picture
#            (imgcheck diff exits 1), over the PSNR floor (measured on
#            lavapipe, colorado valley: 42.6 dB)
#   paths    with it on, screen against forward within screen.sh's
#            textured bounds: both paths drop the same footprint
#            derivatives and sample the same nearest levels
#   samples  the node library's LOD side (view.shading_lod: one hex-tile
#            read of three, one tri-planar tap, no parallax steps) is what
#            runs: texture samples per pixel (--stats, the counting frame)
#            at most 0.85 of off's (measured on lavapipe, valley: 20.2 ->
#            14.1; the prelude's part alone left 0.996)
#   auto     auto is on where the device is a CPU: on lavapipe the picture
#            of auto equals on's to the bit; $SPLAT_SHADING_LOD=0 turns
#            auto off (the picture of off)
set -u
SV=$1 IC=$2 PACK=$3 OUT=$4 PRESET=$5
mkdir -p "$OUT"
. "$(dirname "$0")/../lib.sh"   # fail, kit_status
export SPLAT_VALIDATE=1
export SPLAT_PIPELINE_CACHE="$OUT/pipelines.bin"
unset SPLAT_SHADING_LOD
render() {   # name, options...
    name=$1
    shift
    "$SV" "$PACK" --headless --size 320x180 --camera-preset "$PRESET" \
        --float-out "$OUT/$name.f32" "$@" > "$OUT/$name.log" 2>&1 ||
        { cat "$OUT/$name.log"; fail "$name: splatview exit $?"; }
}
render off --shading screen --shading-lod off --stats
render on --shading screen --shading-lod on --stats
render on_forward --shading forward --shading-lod on
"$IC" diff "$OUT/off.f32" "$OUT/on.f32" 0 && rc=0 || rc=$?
[ $rc = 1 ] || fail "the LOD did not change the picture (imgcheck diff: $(kit_status $rc))"
"$IC" close "$OUT/off.f32" "$OUT/on.f32" 1 0 38 ||
    fail "on against off: PSNR under 38 dB (above)"
"$IC" close "$OUT/on_forward.f32" "$OUT/on.f32" 0.0157 0.999 45 ||
    fail "with the LOD on, screen and forward differ (above)"
samples() { sed -n 's/^texture samples per pixel: //p' "$OUT/$1.log"; }
s_off=$(samples off) s_on=$(samples on)
[ -n "$s_off" ] && [ -n "$s_on" ] || fail "no 'texture samples per pixel' in the --stats logs"
awk -v a="$s_on" -v b="$s_off" 'BEGIN { exit !(a <= 0.85 * b) }' ||
    fail "samples per pixel on $s_on, off $s_off: the node library's LOD side did not run"
if grep -qi 'llvmpipe' "$OUT/off.log"; then   # --stats names the device
    render auto --shading screen
    "$IC" diff "$OUT/on.f32" "$OUT/auto.f32" 0 || fail "auto is not on on a CPU device"
    SPLAT_SHADING_LOD=0 render auto0 --shading screen
    "$IC" diff "$OUT/off.f32" "$OUT/auto0.f32" 0 || fail "SPLAT_SHADING_LOD=0 did not turn auto off"
fi
echo "shading LOD: on differs from off, within the floor; the paths agree; samples per pixel $s_off -> $s_on"
