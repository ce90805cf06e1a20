#!/bin/sh
# Per-pixel cost follows presence (issue 29), at a scale past 256 materials:
#   world_presence.sh GEN_WORLD SPLATC SPLATVIEW IMGCHECK DIR
# gen_world makes 33 biomes x 8 materials over a base (265 materials) with
# camera 'biome' looking down into biome 14, and the same terrain and masks
# with only biome 14's materials (--only 14, 9 materials).  From that
# camera, on the screen path, the full world must classify every tile to a
# combination (none left to the über-shader: its material sets are wider
# than 256 bits), evaluate the same layers and texture samples per pixel as
# the 9-material world, and give the same picture within 1/255.
set -eu
. "$(dirname "$0")/../lib.sh"
GEN=$1 SPLATC=$2 SV=$3 IMG=$4 D=$5
rm -rf "$D" && mkdir -p "$D/full" "$D/only" || fail "cannot make $D"
must "$GEN" --view 14 "$D/full" 33 8 256 16
must "$GEN" --only 14 "$D/only" 33 8 256 16
for w in full only; do
    must "$SPLATC" build "$D/$w/scene.sg" -o "$D/$w.pack" -j 2 --no-cache
    to "$D/$w.txt" "$SV" "$D/$w.pack" --headless -o "$D/$w.png" --float-out "$D/$w.f32" \
        --size 160x90 --camera-preset biome --shading screen --stats
done
get n "grep -c '^material'" cat "$D/full/scene.sg"
[ "$n" -eq 265 ] || fail "the full world has $n materials, expected 265"
# "tiles: T of T shaded, L lists, U by the uber-shader, F from the far atlas"
for w in full only; do
    get uber "sed -n 's/^tiles: .* lists, \([0-9]*\) by the uber-shader.*/\1/p'" cat "$D/$w.txt"
    [ -n "$uber" ] || fail "$w: no tiles line in --stats"
    [ "$uber" -eq 0 ] || fail "$w: $uber tiles shaded by the über-shader, expected none"
done
# the classification's cover search follows the view (screen.c
# rt_class_view): the materials renumbered to those in view, in
# ceil(in view / 32) words (1 up to 32), not the world's 9
for w in full only; do
    get cm "sed -n 's/^classification: [0-9]* candidates, \([0-9]*\) materials in view.*/\1/p'" cat "$D/$w.txt"
    get cw "sed -n 's/^classification: .*, \([0-9]*\) words per set/\1/p'" cat "$D/$w.txt"
    [ -n "$cm" ] && [ -n "$cw" ] || fail "$w: no classification line in --stats"
    [ "$cm" -lt 133 ] || fail "$w: $cm of 265 materials in view, expected under half"
    want=$(( cm <= 32 ? 1 : 9 ))
    [ "$cw" -eq "$want" ] || fail "$w: $cw words per set for $cm materials in view, expected $want"
done
get lf "sed -n 's/^layers per pixel: evaluated \([0-9.]*\),.*/\1/p'" cat "$D/full.txt"
get lo "sed -n 's/^layers per pixel: evaluated \([0-9.]*\),.*/\1/p'" cat "$D/only.txt"
get sf "sed -n 's/^texture samples per pixel: \([0-9.]*\)/\1/p'" cat "$D/full.txt"
get so "sed -n 's/^texture samples per pixel: \([0-9.]*\)/\1/p'" cat "$D/only.txt"
[ -n "$lf" ] && [ -n "$lo" ] && [ -n "$sf" ] && [ -n "$so" ] || fail "no layers or samples line"
echo "layers per pixel: 265 materials $lf, 9 materials $lo; samples $sf, $so"
awk -v a="$lf" -v b="$lo" 'BEGIN { exit !(a <= 1.2 * b) }' ||
    fail "layers per pixel $lf with 265 materials, over 1.2 x the 9-material world's $lo"
awk -v a="$sf" -v b="$so" 'BEGIN { exit !(a <= 1.2 * b + 1e-9) }' ||
    fail "samples per pixel $sf with 265 materials, over 1.2 x the 9-material world's $so"
must "$IMG" diff "$D/full.f32" "$D/only.f32" 0.00392
echo "world_presence: 265 materials cost what 9 do at a view inside one biome"
