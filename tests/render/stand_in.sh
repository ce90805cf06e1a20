#!/bin/sh
# The cheap stand-ins of async pipelines (issue 29, first picture):
#   stand_in.sh SPLATC SPLATVIEW IMGCHECK SRC OUTDIR
# examples/minimal built with a far atlas, drawn on the screen path at
# 160x90 with SPLAT_VALIDATE=1 (splatview exits 3 on any validation
# message) and every cache empty per run.  For SPLAT_STAND_IN=flat and
# =atlas (and unset, the default, which takes the atlas where the pack has
# one on a GPU, the flat stand-in on a CPU's device such as lavapipe):
#   - the first frame (--frames 1) shades every tile with tiles from the
#     stand-in, none by the über-shader or a composite: --stats counts them
#     all as that stand-in's, and the only compute pipeline made is the
#     flat stand-in's (the atlas's is the runtime's own GLSL): the
#     über-shader is not made for the first picture;
#   - the picture is a terrain, not the sky alone or the flat colour alone
#     (imgcheck contrast), and differs from the final one (so the count is
#     not of tiles the composites drew);
#   - once the workers have made the pipelines (--frames 2
#     --wait-pipelines) the second frame equals the synchronous picture to
#     the bit, with no tile stood in.
set -u
SPLATC=$1 SV=$2 IC=$3 SRC=$4 OUT=$5/stand_in
rm -rf "$OUT"
mkdir -p "$OUT"
fail() { echo "FAIL: $*" >&2; exit 1; }
PACK=$OUT/minimal_far
"$SPLATC" build "$SRC/examples/minimal/scene.sg" -o "$PACK" --far-atlas --cache "$OUT/cache" \
    > /dev/null || fail "splatc build --far-atlas"
# one run with its own empty caches: $1 name, the rest splatview's options
run() {
    name=$1
    shift
    rm -rf "$OUT/c_$name"
    SPLATC_CACHE="$OUT/c_$name/spv" SPLAT_PIPELINE_CACHE="$OUT/c_$name/p.bin" \
        MESA_SHADER_CACHE_DIR="$OUT/c_$name/mesa" \
        "$SV" "$PACK" --headless --size 160x90 --shading screen --camera-preset overview \
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
    n=$(($1 + $2))
    [ "$want_flat" != 0 ] && want=1 || want=0
    [ "$n" = "$want" ] || fail "$mode: $n compute modules made for the first picture, want $want"
    "$IC" contrast "$OUT/$mode.png" 0.02 > /dev/null || fail "$mode: the picture has no terrain"
    ! "$IC" diff "$OUT/sync.f32" "$OUT/$mode.f32" 0.0039 > /dev/null ||
        fail "$mode: the stand-in picture equals the final one: nothing stood in"
    echo "$mode: $tiles tiles stood in, $n compute module(s) made"
    run ${mode}_final --async-pipelines on --frames 2 --wait-pipelines --float-out "$OUT/${mode}_final.f32"
    set -- $(sed -n 's/^stand-ins: \([0-9]*\) tiles.*/\1/p' "$OUT/${mode}_final.log")
    [ "${1:-x}" = 0 ] || fail "$mode: ${1:-?} tiles still stood in after the pipelines landed"
    "$IC" diff "$OUT/sync.f32" "$OUT/${mode}_final.f32" 0 ||
        fail "$mode: the picture once the pipelines landed differs from the synchronous one"
done
echo "stand-ins: flat and atlas first pictures, the final picture equal to the synchronous one"
