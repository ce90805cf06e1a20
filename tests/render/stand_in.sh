#!/bin/sh
# The cheap stand-ins of async pipelines (issue 29, first picture):
#   stand_in.sh SPLATC SPLATVIEW IMGCHECK PACKEDIT SRC OUTDIR
# examples/minimal built with a far atlas, drawn on the screen path at
# 160x90 with SPLAT_VALIDATE=1 (splatview exits 3 on any validation
# message) and every cache empty per run.  For SPLAT_STAND_IN=flat and
# =atlas (and unset, the default, which takes the atlas where the pack has
# one on a GPU, the flat stand-in on a CPU's device such as lavapipe):
#   - the first frame (--frames 1) shades every tile with tiles from the
#     stand-in, none by the über-shader or a composite: --stats counts them
#     all as that stand-in's, and the only compute module made is the
#     stand-in's, from the pack's SPIR-V ("uber"."stand_in", PACK.md):
#     "1 from the pack or the SPIR-V cache, 0 compiled from GLSL" with
#     every cache empty, so nothing is compiled for the first picture and
#     the über-shader is not made;
#   - the same pack without "uber"."stand_in" (an older pack: the runtime
#     compiles the stand-in from the über-shader's compute GLSL, "0 from
#     the pack ..., 1 compiled from GLSL") draws the same first picture to
#     the bit, for the flat and the atlas stand-in;
#   - the picture is a terrain, not the sky alone or the flat colour alone
#     (imgcheck contrast), and differs from the final one (so the count is
#     not of tiles the composites drew);
#   - once the workers have made the pipelines (--frames 2
#     --wait-pipelines) the second frame equals the synchronous picture to
#     the bit, with no tile stood in.
set -u
SPLATC=$1 SV=$2 IC=$3 PE=$4 SRC=$5 OUT=$6/stand_in
rm -rf "$OUT"
mkdir -p "$OUT"
fail() { echo "FAIL: $*" >&2; exit 1; }
PACK=$OUT/minimal_far
"$SPLATC" build "$SRC/examples/minimal/scene.sg" -o "$PACK" --far-atlas --cache "$OUT/cache" \
    > /dev/null || fail "splatc build --far-atlas"
# the stand-ins as the pack's SPIR-V, and without (the GLSL fallback)
for k in flat atlas; do
    grep -q "\"shaders/${k}_stand_in.comp.spv.zst\"" "$PACK/manifest.json" ||
        fail "the manifest names no $k stand-in module"
done
GPACK=$OUT/minimal_far_glsl
cp -r "$PACK" "$GPACK" && "$PE" del "$GPACK/manifest.json" uber.stand_in ||
    fail "cannot drop uber.stand_in"
! grep -q stand_in "$GPACK/manifest.json" || fail "uber.stand_in still in the manifest"
# one run with its own empty caches: $1 name, the rest splatview's options
run() {
    name=$1
    shift
    rm -rf "$OUT/c_$name"
    SPLATC_CACHE="$OUT/c_$name/spv" SPLAT_PIPELINE_CACHE="$OUT/c_$name/p.bin" \
        MESA_SHADER_CACHE_DIR="$OUT/c_$name/mesa" \
        "$SV" "${RUN_PACK:-$PACK}" --headless --size 160x90 --shading screen --camera-preset overview \
        --stats "$@" > "$OUT/$name.log" 2>&1 || { cat "$OUT/$name.log" >&2; fail "splatview $name"; }
    ! grep -q "validation message" "$OUT/$name.log" || fail "validation messages ($name)"
}
run sync --async-pipelines off --float-out "$OUT/sync.f32"
for mode in flat atlas default; do
    if [ $mode = default ]; then unset SPLAT_STAND_IN; else export SPLAT_STAND_IN=$mode; fi
    run $mode --async-pipelines on --frames 1 --float-out "$OUT/$mode.f32" -o "$OUT/$mode.png"
    log=$OUT/$mode.log
    tiles=$(sed -n 's/^tiles: \([0-9]*\) of .*/\1/p' "$log")
    set -- $(sed -n 's/^stand-ins: \([0-9]*\) tiles (uber-shader \([0-9]*\), far atlas \([0-9]*\), flat \([0-9]*\))$/\1 \2 \3 \4/p' "$log")
    [ -n "$tiles" ] && [ "$tiles" -gt 0 ] && [ $# = 4 ] ||
        fail "$mode: no tiles or stand-ins line in --stats"
    want_flat=0 want_atlas=$tiles
    if [ $mode = flat ] || { [ $mode = default ] && grep -q "^device: .*llvmpipe" "$log"; }; then
        want_flat=$tiles want_atlas=0
    fi
    [ "$1" = "$tiles" ] && [ "$2" = 0 ] && [ "$3" = "$want_atlas" ] && [ "$4" = "$want_flat" ] ||
        fail "$mode: $tiles tiles, stand-ins $* (all, uber-shader, atlas, flat)"
    made=$(sed -n 's/^compute modules: \([0-9]*\) from the pack or the SPIR-V cache, \([0-9]*\) compiled.*/\1 \2/p' "$log")
    set -- $made
    [ $# = 2 ] || fail "$mode: no compute modules line"
    [ "$1 $2" = "1 0" ] ||
        fail "$mode: compute modules for the first picture: $1 from the pack, $2 compiled from GLSL; want 1 and 0"
    n=$1
    "$IC" contrast "$OUT/$mode.png" 0.02 > /dev/null || fail "$mode: the picture has no terrain"
    ! "$IC" diff "$OUT/sync.f32" "$OUT/$mode.f32" 0.0039 > /dev/null ||
        fail "$mode: the stand-in picture equals the final one: nothing stood in"
    echo "$mode: $tiles tiles stood in, $n compute module(s) made, from the pack"
    if [ $mode != default ]; then   # the GLSL fallback: compiled, the same picture
        RUN_PACK=$GPACK
        run ${mode}_glsl --async-pipelines on --frames 1 --float-out "$OUT/${mode}_glsl.f32"
        RUN_PACK=
        set -- $(sed -n 's/^compute modules: \([0-9]*\) from the pack or the SPIR-V cache, \([0-9]*\) compiled.*/\1 \2/p' "$OUT/${mode}_glsl.log")
        [ "$*" = "0 1" ] ||
            fail "$mode without uber.stand_in: compute modules '$*' (from the pack, compiled), want 0 1"
        "$IC" diff "$OUT/$mode.f32" "$OUT/${mode}_glsl.f32" 0 ||
            fail "$mode: the pack's stand-in module draws another picture than the GLSL-built one"
    fi
    run ${mode}_final --async-pipelines on --frames 2 --wait-pipelines --float-out "$OUT/${mode}_final.f32"
    set -- $(sed -n 's/^stand-ins: \([0-9]*\) tiles.*/\1/p' "$OUT/${mode}_final.log")
    [ "${1:-x}" = 0 ] || fail "$mode: ${1:-?} tiles still stood in after the pipelines landed"
    "$IC" diff "$OUT/sync.f32" "$OUT/${mode}_final.f32" 0 ||
        fail "$mode: the picture once the pipelines landed differs from the synchronous one"
done
echo "stand-ins: flat and atlas first pictures, the final picture equal to the synchronous one"
