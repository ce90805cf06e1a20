#!/bin/sh
# mips.sh SPLATC SPLATVIEW IMGCHECK OUTDIR — stored mip levels end to end
# on examples/billingsley, whose uniform-noise texture comes with its
# nearest-neighbour levels (graphs/textures/uniform.mipK.png).
set -eu
. "$(dirname "$0")/../lib.sh"   # fail, must_fail
SPLATC=$1 SV=$2 IC=$3 OUT=$4
rm -rf "$OUT" && mkdir -p "$OUT"
PACK=$OUT/bl.pack
"$SPLATC" build examples/billingsley/scene.sg -o "$PACK" -j 2 > "$OUT/build.log" 2>&1 ||
    { cat "$OUT/build.log"; fail "build failed"; }

# the pack holds every level, byte for byte, and the manifest counts them
n=0
for src in graphs/textures/uniform.mip*.png; do
    n=$((n + 1))
    same "$src" "$PACK/textures/uniform.mip$n.png" "level $n not copied"
done
[ "$n" -gt 0 ] || fail "no mip files in graphs/textures (splatc texgen writes them)"
grep -q "\"mips\": $n" "$PACK/manifest.json" || fail "manifest does not say \"mips\": $n"
[ "$(grep -c '"mips"' "$PACK/manifest.json")" = 1 ] || fail "only the uniform texture has mips"

# rendered with the stored levels, from far enough that the small levels
# are read; then again with the manifest's "mips" taken away (the runtime
# blits box-filtered levels instead): the pictures must differ
VIEW="--size 96x64 --camera-preset overview"
"$SV" "$PACK" --headless $VIEW -o "$OUT/stored.png" --float-out "$OUT/stored.f32" ||
    fail "render with stored levels failed"
"$IC" nonuniform "$OUT/stored.png" || fail "stored-level picture is uniform"
cp -r "$PACK" "$OUT/blit.pack" && chmod -R u+w "$OUT/blit.pack"
sed -i '/"mips": /d; s/"srgb": \(true\|false\),$/"srgb": \1/' "$OUT/blit.pack/manifest.json"
"$SV" "$OUT/blit.pack" --headless $VIEW -o "$OUT/blit.png" --float-out "$OUT/blit.f32" ||
    fail "render with blitted levels failed"
# (imgcheck diff exits 1 when they differ; a crash is no difference found)
"$IC" diff "$OUT/stored.f32" "$OUT/blit.f32" 0 > "$OUT/diff.txt" && rc=0 || rc=$?
[ $rc = 1 ] || fail "stored levels made no difference (imgcheck diff: $(kit_status $rc)): the runtime did not upload them"

# a level of the wrong size is refused with the manifest field named
cp -r "$PACK" "$OUT/bad.pack" && chmod -R u+w "$OUT/bad.pack"
cp "$OUT/bad.pack/textures/uniform.mip1.png" "$OUT/bad.pack/textures/uniform.mip2.png"
"$SV" "$OUT/bad.pack" --headless --size 16x16 -o "$OUT/bad.png" 2> "$OUT/bad.txt" && rc=0 || rc=$?
[ $rc = 1 ] || fail "a wrong-size level: splatview $(kit_status $rc), expected exit 1"
grep -q "mips\[2\].*its level needs" "$OUT/bad.txt" || { cat "$OUT/bad.txt"; fail "unclear message"; }
[ -e "$OUT/bad.png" ] && fail "wrote a picture from a bad pack"
echo "mips: $n stored levels copied, uploaded and checked"
