#!/bin/sh
# The über-shader of a world whose pixels need layers deep in its chain
# (issue 29): uber_deep.sh GEN_WORLD SPLATC SPLATVIEW IMGCHECK DIR
# 13 biomes x 8 materials over a base, 105 layers, seen from inside biome 2
# (gen_world --view 2): its pixels need layers 80 or more down the
# über-shader's chain.  The über-shader nested a guard per layer, and
# llvmpipe ignores conditions nested deeper than 80: it drew a flat slate
# there (max diff 1.23).  Here it must draw what the composites draw, within
# 1/255, on the forward path (--reference uber) and on the screen path
# (--reference uber --shading screen: every tile the über-shader's, as the
# tiles the classification cannot cover), the validation layer silent
# (SPLAT_VALIDATE=1: splatview exits non-zero if it says anything).
set -u
GEN=$1 SPLATC=$2 SV=$3 IC=$4 D=$5
fail() { echo "FAIL: $*"; exit 1; }
export SPLAT_VALIDATE=1
rm -rf "$D" && mkdir -p "$D/world" || fail "cannot make $D"
"$GEN" --view 2 "$D/world" 13 8 256 16 > /dev/null || fail "gen_world"
"$SPLATC" build "$D/world/scene.sg" -o "$D/pack" -j 2 --no-cache > "$D/build.txt" 2>&1 ||
    { cat "$D/build.txt"; fail "splatc build"; }
# the world is as deep as meant: the über-shader's header lists 105 layers
# (a zstd frame in the pack: compiler/PACK.md "Compressed shaders")
zstd -q -d -f "$D/pack/shaders/uber.frag.zst" -o "$D/uber.frag" || fail "zstd -d uber.frag.zst"
n=$(sed -n 3p "$D/uber.frag" | grep -o '([0-9]*)' | wc -l)
[ "$n" -eq 105 ] || fail "the über-shader has $n layers, expected 105"
view() {   # view NAME ARGS...: a 160x90 frame of the 'biome' camera
    name=$1; shift
    echo "+ splatview $*"
    "$SV" "$D/pack" --headless --size 160x90 --camera-preset biome --stats \
        --float-out "$D/$name.f32" -o "$D/$name.png" "$@" > "$D/$name.txt" 2>&1 ||
        { cat "$D/$name.txt"; fail "splatview $* (exit $?)"; }
}
view composites --shading forward
view uber --shading forward --reference uber
view composites_screen --shading screen
view uber_screen --shading screen --reference uber
# the über-shader did draw them: every patch, every tile
grep -q '^size: .* reference: uber' "$D/uber.txt" || fail "forward: not the über-shader"
grep -q '^size: .* reference: uber' "$D/uber_screen.txt" || fail "screen: not the über-shader"
grep -q '^size: .* reference: none' "$D/composites.txt" || fail "forward: not the composites"
# 1/255: a layer more or less anywhere is far more (the bug was 1.23)
for p in "uber composites" "uber_screen composites_screen" "uber_screen composites"; do
    set -- $p
    "$IC" diff "$D/$1.f32" "$D/$2.f32" 0.0039 || fail "$1 differs from $2 by more than 1/255"
done
echo "uber_deep: the über-shader equals the composites on both paths (105 layers)"
