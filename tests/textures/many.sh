#!/bin/sh
# many.sh GEN SPLATC SPLATVIEW IMGCHECK DIR N — N textures in one scene
# (gen_many.c): the pack puts them into one texture array per size and
# sampler state (six: 8, 16, 32 texels, sRGB or not), and the albedo view
# of the flat terrain is their mean on every pixel, on the screen-space and
# the forward path, with the validation layer silent (SPLAT_VALIDATE=1).
set -u
GEN=$1 SPLATC=$2 SV=$3 IMG=$4 D=$5 N=$6
fail() { echo "FAIL: $*"; exit 1; }
rm -rf "$D" && mkdir -p "$D" || fail "cannot make $D"
want=$("$GEN" "$D" "$N") || fail "gen_many"
"$SPLATC" build "$D/scene.sg" -o "$D/pack" -j 2 --no-cache > "$D/build.txt" 2>&1 ||
    { cat "$D/build.txt"; fail "splatc build"; }
n=$(grep -o '"file": "textures/t[0-9]*.png"' "$D/pack/manifest.json" | wc -l)
[ "$n" -eq "$N" ] || fail "the manifest names $n textures, not $N"
arrays=$(grep -o '"binding": [0-9]*' "$D/pack/manifest.json" | sort -u | wc -l)
[ "$arrays" -eq 6 ] || fail "$arrays texture arrays, expected 6 (3 sizes x sRGB or not)"
for path in screen forward; do
    "$SV" "$D/pack" --headless --size 64x64 --view albedo --shading $path \
        --float-out "$D/$path.f32" -o "$D/$path.png" > "$D/$path.txt" 2>&1 ||
        { cat "$D/$path.txt"; fail "splatview ($path)"; }
    [ -s "$D/$path.txt" ] && { cat "$D/$path.txt"; fail "messages on the $path path"; }
    # every pixel within 1/255 of the mean: `near` fails (exit 1) above MAX
    # = 0.9999, which is what a pass must do
    out=$("$IMG" near "$D/$path.f32" "$want" 0.004 0.9999)
    [ $? -eq 1 ] || fail "$path: not every pixel is the mean $want: $out"
    echo "$path: $out"
done
echo ok
