#!/bin/sh
# The screen-space path against the forward path (splatview --shading):
#   screen.sh SPLATVIEW IMGCHECK PACK OUTDIR KIND PRESET...
# at 320x180 (lavapipe), SPLAT_VALIDATE=1 (splatview exits 3 on any
# validation message).  For each preset:
#   - screen vs forward, RGBA32F.  KIND textured: PSNR >= 45 dB and
#     >= 99.9 % of pixels within 4/255 (both paths sample with the
#     compiler's gradients from the same position derivatives, so they
#     pick the same mip levels: billingsley's nearest-mip noise textures
#     too, 99.986 % or more within); KIND notex (no
#     texture sampled): >= 99.8 % of pixels within 1e-5 and none over 1e-3
#     (the position from depth and the interpolated varyings differ in
#     their last fp32 bits; the heightfield's bilinear filter quantises
#     the texel fraction to 8 bits, so such a difference can cross a
#     weight step and move the slope, which steep slope ramps amplify:
#     measured 2 and 73 of 57600 pixels over 1e-5, largest 3.3e-4);
#   - soundness: screen vs screen with every tile on the über-shader
#     (--reference uber) within 1/255, so classification dropped no
#     material that is present.
# The screen path's depth ray cast in compute (--screen-depth raycast)
# against its geometry pass with every patch at full detail (--lod-pixels
# 0.01), at the first preset: the same surface, >= 99.9 % of pixels within
# 4/255 and PSNR >= 60 dB (colorado: 80 dB, 1 pixel of 57600 over).  At
# the default LOD the patches are coarser far away and the two differ
# there (colorado overview 33 dB, 96 % within 4/255): the ray caster shows
# the heightfield's own surface.
# With CRATER=R (a pack with a destructible area): at the first preset, a
# crater of radius R where the view's centre ray meets the terrain, then
# screen vs forward as above, and the crater must change the picture.
# Pixel sorting (--pixel-sort on against off) at the first preset: the
# same picture to the bit, the same layers needed, no more evaluated; the
# tiles classified in 4x4 blocks (--tile-order blocks): the same picture.
# Then, at the first preset: the tiles and cost views render (the cost
# view on both paths), --stats prints the per-pass times and the counting
# lines with needed <= evaluated on both paths, and the two paths' layers
# needed per pixel agree within 5 % (the same pixels and weights, counted
# by two different shaders; the forward path counts fragments, so
# overdraw the depth test let through counts too).
set -u
SV=$1 IC=$2 PACK=$3 OUT=$4/screen_$(basename "$3") KIND=$5
shift 5
mkdir -p "$OUT"
export SPLAT_VALIDATE=1
# the paths at the full shading on every device: the CPU shading LOD
# (rt_shading_lod, on by default on lavapipe) has its own test,
# shading_lod.sh (its sharp plain ramps move notex's worst pixel over 1e-3)
export SPLAT_SHADING_LOD=0
export SPLAT_PIPELINE_CACHE="$OUT/pipelines.bin"
. "$(dirname "$0")/../lib.sh"   # fail
run() { echo "+ splatview $*"; "$SV" "$@" || fail "splatview $* (exit $?)"; }
SIZE="--size 320x180"
for cam in "$@"; do
    c="--camera-preset $cam"
    run "$PACK" --headless $SIZE $c --shading forward --float-out "$OUT/$cam.f.f32"
    run "$PACK" --headless $SIZE $c --shading screen --float-out "$OUT/$cam.s.f32"
    run "$PACK" --headless $SIZE $c --shading screen --reference uber --float-out "$OUT/$cam.u.f32"
    case $KIND in
    textured)   "$IC" close "$OUT/$cam.f.f32" "$OUT/$cam.s.f32" 0.0157 0.999 45 ||
                    fail "$cam: screen and forward differ (above)" ;;
    notex)      "$IC" close "$OUT/$cam.f.f32" "$OUT/$cam.s.f32" 1e-5 0.998 80 ||
                    fail "$cam: screen and forward differ (above)"
                "$IC" diff "$OUT/$cam.f.f32" "$OUT/$cam.s.f32" 1e-3 ||
                    fail "$cam: screen and forward differ by more than 1e-3" ;;
    *)          fail "unknown kind $KIND" ;;
    esac
    "$IC" diff "$OUT/$cam.s.f32" "$OUT/$cam.u.f32" 0.0039 ||
        fail "$cam: classification changed the picture (composites vs über-shader)"
done
c="--camera-preset $1"
# pipelines follow the view: the compute modules this process made (from
# the SPIR-V cache or compiled) are at most one per list that got tiles,
# and the über-shader's, not one per combination of the pack
run "$PACK" --headless $SIZE $c --shading screen --stats > "$OUT/made.log"
lists=$(sed -n 's/^tiles: .* shaded, \([0-9]*\) lists.*/\1/p' "$OUT/made.log")
made=$(sed -n 's/^compute modules: \([0-9]*\) from the pack or the SPIR-V cache, \([0-9]*\) compiled.*/\1 \2/p' "$OUT/made.log")
[ -n "$lists" ] && [ -n "$made" ] || fail "no tiles or compute modules line in --stats"
set -- $made "$@"
[ $(($1 + $2)) -le $((lists + 1)) ] ||
    fail "$(($1 + $2)) compute pipelines made for $lists lists in view"
echo "pipelines follow the view: $(($1 + $2)) made for $lists lists with tiles"
# so do the shader files read (read, decompressed and validated on first
# use, pack_shaders.c): one per compute module made and the vertex
# shader's, undergrowth masks aside (none generated here)
ug=$(sed -n 's/^undergrowth: \([0-9]*\) cells.*/\1/p' "$OUT/made.log")
read=$(sed -n 's/^shader files read: \([0-9]*\) of \([0-9]*\).*/\1 \2/p' "$OUT/made.log")
[ -n "$read" ] || fail "no shader files line in --stats"
set -- $read "$@"
if [ "${ug:-0}" = 0 ]; then
    [ "$1" -le $(($3 + $4 + 1)) ] && [ "$1" -lt "$2" ] ||
        fail "$1 of $2 shader files read for $(($3 + $4)) compute modules made"
fi
echo "shader files follow the view: $1 of $2 read"
shift 4
# pipelines made on workers (--async-pipelines on): the first frame has
# none but the über-shader's, which stands in for every list with tiles;
# its picture is the final one within 1/255 (the soundness bound above).
# SPLAT_STAND_IN=always: the über-shader stands in even where making the
# composites costs less (rt_pipelines_stand_in would make them instead)
SPLAT_STAND_IN=always SPLATC_CACHE="$OUT/async_cache" run "$PACK" --headless $SIZE $c --shading screen \
    --async-pipelines on --frames 1 --stats --float-out "$OUT/async.f32" > "$OUT/async.log"
cat "$OUT/async.log"
tiles=$(sed -n 's/^tiles: \([0-9]*\) of .*/\1/p' "$OUT/async.log")
uber=$(sed -n 's/^tiles: .* lists, \([0-9]*\) by the uber-shader.*/\1/p' "$OUT/async.log")
stood=$(sed -n 's/^pipelines pending: [0-9]* (tiles the uber-shader stood in for: \([0-9]*\))/\1/p' "$OUT/async.log")
# every tile: stood in for, or classified to the über-shader (no cover)
[ -n "$tiles" ] && [ "$tiles" -gt 0 ] && [ -n "$stood" ] && [ -n "$uber" ] &&
    [ $((stood + uber)) = "$tiles" ] && [ "$stood" -gt 0 ] ||
    fail "async: expected the über-shader to stand in for all $tiles tiles but the $uber it shades anyway, got '$stood'"
"$IC" diff "$OUT/$1.s.f32" "$OUT/async.f32" 0.0039 ||
    fail "the picture with pipelines pending differs from the final one by more than 1/255"
# the classification GPUs run (a workgroup per tile), forced here: the same
# picture as the one CPU drivers run (an invocation per tile)
SPLAT_CLASSIFY=wide run "$PACK" --headless $SIZE $c --shading screen --float-out "$OUT/wide.f32"
"$IC" diff "$OUT/$1.s.f32" "$OUT/wide.f32" 0 || fail "the two classifications differ"
# both in 4x4 blocks of tiles (--tile-order blocks; the unsorted run below)
SPLAT_CLASSIFY=wide run "$PACK" --headless $SIZE $c --shading screen --tile-order blocks \
    --float-out "$OUT/wide_blocks.f32"
"$IC" diff "$OUT/$1.s.f32" "$OUT/wide_blocks.f32" 0 ||
    fail "the classification a workgroup per tile in 4x4 blocks changed the picture"
# pixel sorting (abi.h SPLAT_SORT; off unless asked): the
# same picture to the bit, as each pixel is computed the same whichever
# lane computes it; the same layers needed per pixel, and no more
# evaluated than unsorted (2 % slack: a subgroup straddling two keys)
for so in off on; do
    run "$PACK" --headless $SIZE $c --shading screen --pixel-sort $so --float-out "$OUT/sort_$so.f32"
    run "$PACK" --headless $SIZE $c --shading screen --pixel-sort $so --stats --frames 1 \
        > "$OUT/sort_$so.txt"
done
"$IC" diff "$OUT/sort_off.f32" "$OUT/sort_on.f32" 0 || fail "sorting the pixels changed the picture"
grep -q "shading: screen, pixels sorted by layer set" "$OUT/sort_on.txt" ||
    fail "--pixel-sort on: --stats does not say the pixels were sorted"
sorted_layers() {
    sed -n 's/^layers per pixel: evaluated \([0-9.]*\), needed \([0-9.]*\).*/\1 \2/p' "$1"
}
echo "sorted: $(sorted_layers "$OUT/sort_on.txt"), unsorted: $(sorted_layers "$OUT/sort_off.txt")"
echo "$(sorted_layers "$OUT/sort_on.txt") $(sorted_layers "$OUT/sort_off.txt")" |
    awk '{ exit !($2 == $4 && $1 <= 1.02 * $3) }' ||
    fail "sorted: layers needed must equal unsorted's, evaluated not exceed it"
# the tiles classified in 4x4 blocks (--tile-order blocks): only the lists'
# order changes, so the picture is the same to the bit, sorted or not (a
# tile lost or given twice by the block order would show)
for so in off on; do
    run "$PACK" --headless $SIZE $c --shading screen --pixel-sort $so --tile-order blocks \
        --float-out "$OUT/blocks_$so.f32"
    "$IC" diff "$OUT/sort_off.f32" "$OUT/blocks_$so.f32" 0 ||
        fail "--tile-order blocks changed the picture (--pixel-sort $so)"
done
run "$PACK" --headless $SIZE $c --shading screen --screen-depth raycast --float-out "$OUT/ray.f32"
run "$PACK" --headless $SIZE $c --shading screen --screen-depth raster --lod-pixels 0.01 \
    --float-out "$OUT/full.f32"
"$IC" close "$OUT/full.f32" "$OUT/ray.f32" 0.0157 0.999 60 ||
    fail "ray-cast depth and the full-detail geometry pass's differ (above)"
if [ -n "${CRATER:-}" ]; then
    run "$PACK" --headless $SIZE $c --crater-at-view "$CRATER" --shading forward \
        --float-out "$OUT/crater.f.f32"
    run "$PACK" --headless $SIZE $c --crater-at-view "$CRATER" --shading screen \
        --float-out "$OUT/crater.s.f32"
    "$IC" close "$OUT/crater.f.f32" "$OUT/crater.s.f32" 0.0157 0.999 45 ||
        fail "after a crater: screen and forward differ (above)"
    # imgcheck diff exits 1 when the pictures differ; 2 (a missing image) or
    # a crash is no difference found
    "$IC" diff "$OUT/$1.s.f32" "$OUT/crater.s.f32" 0.01 && rc=0 || rc=$?
    [ $rc = 1 ] || fail "the crater did not change the screen path's picture (imgcheck diff: $(kit_status $rc))"
fi
run "$PACK" --headless $SIZE $c --shading screen --view tiles -o "$OUT/tiles.png"
"$IC" nonuniform "$OUT/tiles.png" || fail "the tiles view is uniform"
run "$PACK" --headless $SIZE $c --shading screen --view cost -o "$OUT/cost.png"
"$IC" nonuniform "$OUT/cost.png" || fail "the cost view is uniform"
run "$PACK" --headless $SIZE $c --shading screen --stats --frames 2 > "$OUT/stats.txt"
cat "$OUT/stats.txt"
for line in "  depth" "classification" "shading (compute)" "tiles:" \
            "layers per pixel: evaluated" "texture samples per pixel:" "shading: screen"; do
    grep -q "$line" "$OUT/stats.txt" || fail "--stats lacks '$line'"
done
run "$PACK" --headless $SIZE $c --shading forward --view cost -o "$OUT/cost.f.png"
"$IC" nonuniform "$OUT/cost.f.png" || fail "the forward path's cost view is uniform"
run "$PACK" --headless $SIZE $c --shading forward --stats --frames 2 > "$OUT/stats.f.txt"
cat "$OUT/stats.f.txt"
for line in "layers per pixel: evaluated" "texture samples per pixel:" "shading: forward"; do
    grep -q "$line" "$OUT/stats.f.txt" || fail "forward --stats lacks '$line'"
done
layers() {
    sed -n 's/^layers per pixel: evaluated \([0-9.]*\), needed \([0-9.]*\).*/\1 \2/p' "$1"
}
for f in stats stats.f; do
    # (no line is no figure: awk's END sees NR = 0)
    layers "$OUT/$f.txt" > "$OUT/$f.layers"
    awk '{ ok = $2 > 0 && $2 <= $1 + 1e-9 } END { exit !(NR == 1 && ok) }' "$OUT/$f.layers" ||
        fail "$f: layers needed must be > 0 and <= evaluated ($(cat "$OUT/$f.layers"))"
done
echo "$(layers "$OUT/stats.txt") $(layers "$OUT/stats.f.txt")" |
    awk '{ d = $2 - $4; if (d < 0) d = -d; exit !(d <= 0.05 * $2) }' ||
    fail "screen and forward count different layers needed per pixel"
echo "ok"
