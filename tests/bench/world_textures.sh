#!/bin/sh
# The generated world with textures (issue 29; gen_world --textures):
#   world_textures.sh GEN_WORLD SPLATC DIR
# 2 biomes x 4 materials over a base, each of the 8 with its own texture
# (64^2 and 128^2, sRGB): the pack builds; its manifest names the 8
# textures, each a layer of a texture array, the arrays at most 20 and
# exactly 2 here (one per size: same mips and sampler state), numbered
# densely from binding 1, the layers of each array 0..n-1 once; every
# combination's materials come from leaf cells (the build report: largest
# composite <= largest leaf-cell overlap); and the generator is
# deterministic (a second run gives the same bytes).
set -u
. "$(dirname "$0")/../lib.sh"   # fail, same
GEN=$1 SPLATC=$2 D=$3
rm -rf "$D" && mkdir -p "$D/a" "$D/b" || fail "cannot make $D"
"$GEN" --textures "$D/a" 2 4 256 16 || fail "gen_world --textures"
"$GEN" --textures "$D/b" 2 4 256 16 > /dev/null || fail "gen_world --textures (again)"
# (the first line names the output folder)
sed -i '1d' "$D/b/scene.sg" && sed '1d' "$D/a/scene.sg" > "$D/a.scene" || fail "sed"
same "$D/a.scene" "$D/b/scene.sg" "gen_world --textures: the scene differs between two runs"
for f in "$D"/a/textures/*.png "$D"/a/*.png; do
    same "$f" "$D/b/${f#$D/a/}" "gen_world --textures: $f differs between two runs"
done
n=$(ls "$D"/a/textures/*.png | wc -l)
[ "$n" -eq 8 ] || fail "$n textures written, expected 8"
"$SPLATC" build "$D/a/scene.sg" -o "$D/pack" -j 2 --no-cache --stats > "$D/stats.txt" 2>&1 ||
    { cat "$D/stats.txt"; fail "splatc build"; }
line=$(grep '^combinations found in leaf cells:' "$D/stats.txt") || fail "no report line"
echo "$line"
set -- $(echo "$line" | sed -n 's/.*(largest composite \([0-9]*\) layers, largest leaf-cell overlap \([0-9]*\);.*/\1 \2/p')
[ $# -eq 2 ] || fail "cannot read '$line'"
[ "$1" -le "$2" ] || fail "largest composite $1 layers > largest leaf-cell overlap $2"
# the manifest's textures, flattened: "file":…,"binding":B,"layer":L
tr -d ' \n' < "$D/pack/manifest.json" |
    grep -o '"file":"textures/[^"]*","binding":[0-9]*,"layer":[0-9]*' > "$D/textures.txt"
n=$(wc -l < "$D/textures.txt")
[ "$n" -eq 8 ] || fail "the manifest names $n textures with a binding and a layer, expected 8"
for m in 0 1 2 3; do
    for b in 0 1; do
        grep -q "\"file\":\"textures/b${b}_m$m.png\"" "$D/textures.txt" ||
            fail "texture b${b}_m$m.png is no layer of an array"
    done
done
arrays=$(sed 's/.*"binding":\([0-9]*\),.*/\1/' "$D/textures.txt" | sort -n | uniq)
na=$(echo "$arrays" | wc -l)
[ "$na" -le 20 ] || fail "$na texture arrays, more than 20"
[ "$na" -eq 2 ] || fail "$na texture arrays, expected 2 (64^2 and 128^2)"
[ "$(echo "$arrays" | tr '\n' ' ')" = "1 2 " ] || fail "bindings $(echo $arrays) are not 1, 2"
for a in $arrays; do
    got=$(grep "\"binding\":$a," "$D/textures.txt" | sed 's/.*"layer":\([0-9]*\)$/\1/' | sort -n | tr '\n' ' ')
    k=$(grep -c "\"binding\":$a," "$D/textures.txt")
    want=$(seq 0 $((k - 1)) | tr '\n' ' ')
    [ "$got" = "$want" ] || fail "array $a has layers $got, expected $want"
    # one size an array: the even materials 64^2, the odd 128^2
    sizes=$(grep "\"binding\":$a," "$D/textures.txt" | sed 's/.*_m\([0-9]*\)\.png.*/\1/' |
            awk '{ print $1 % 2 }' | sort -u | wc -l)
    [ "$sizes" -eq 1 ] || fail "array $a mixes texture sizes"
done
# every combination shades leaf cells (none is only a coarse node's union:
# "cells" >= 1), one per pipeline built, and binds exactly the textures of
# its materials (material k > 0 samples texture k - 1; the base none)
built=$(echo "$line" | sed -n 's/.*pipelines built: \([0-9]*\).*/\1/p')
tr -d ' \n' < "$D/pack/manifest.json" |
    grep -o '"materials":\[[0-9,]*\],"glsl":"[^"]*","spirv":"[^"]*","textures":\[[0-9,]*\],"params":\[[0-9,]*\],"cells":[0-9]*' \
    > "$D/combos.txt"
nc=$(wc -l < "$D/combos.txt")
[ "$nc" -eq "$built" ] || fail "the manifest lists $nc combinations, the report $built built"
awk -F'[][]' '{
        split($2, m, ","); want = ""
        for (i = length(m); i >= 1; i--) if (m[i] > 0) want = want (want == "" ? "" : ",") m[i] - 1
        n = split($4, t, ","); got = ""
        # textures ascending, materials top first: compare as sorted sets
        for (i = 1; i <= n; i++) got = got (got == "" ? "" : ",") t[i]
        if (got != want) { print "FAIL: combination " NR ": materials [" $2 "] bind textures [" $4 "], expected [" want "]"; bad = 1 }
        c = $0; sub(/.*"cells":/, "", c)
        if (c + 0 < 1) { print "FAIL: combination " NR " (materials [" $2 "]) shades no leaf cell: a coarse node union"; bad = 1 }
    } END { exit bad }' "$D/combos.txt" || exit 1
echo "8 textures in $na arrays, $nc combinations each on leaf cells binding its own textures: ok"
