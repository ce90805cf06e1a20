#!/bin/sh
# The generated world's pack with merging (issue 29):
#   world.sh SPLATC WORLDDIR
# splatc build --max-combinations 6 --stats: the report says how many
# combinations the leaf cells have and how many pipelines were built, and
# the second is at most 6 while the first is more; the manifest holds
# exactly the pipelines built, and no composite has more layers than the
# build report's largest.
set -u
SPLATC=$1 W=$2
fail() { echo "FAIL: $*"; exit 1; }
P=6
rm -rf "$W/pack"
"$SPLATC" build "$W/scene.sg" -o "$W/pack" -j 2 --no-cache --max-combinations $P --stats \
    > "$W/stats.txt" || fail "splatc build --max-combinations $P (exit $?)"
line=$(grep '^combinations found in leaf cells:' "$W/stats.txt") || fail "no 'combinations found' line"
echo "$line"
found=$(echo "$line" | sed -n 's/^combinations found in leaf cells: \([0-9]*\), pipelines built: \([0-9]*\).*/\1/p')
built=$(echo "$line" | sed -n 's/^combinations found in leaf cells: \([0-9]*\), pipelines built: \([0-9]*\).*/\2/p')
[ -n "$found" ] && [ -n "$built" ] || fail "cannot read '$line'"
[ "$built" -le $P ] || fail "$built pipelines built, more than --max-combinations $P"
[ "$found" -gt $P ] || fail "only $found leaf combinations: the merge had nothing to do"
grep -q "^combinations: $found in leaf cells, $built compiled (merged to at most $P)" "$W/stats.txt" ||
    fail "the analysis report disagrees"
n=$(grep -o '"glsl": "shaders/[0-9]*\.frag\.zst"' "$W/pack/manifest.json" | wc -l)
[ "$n" -eq "$built" ] || fail "the manifest names $n composites, the report $built"
# a bad bound is a usage error, nothing written
"$SPLATC" build "$W/scene.sg" -o "$W/bad" --max-combinations -1 2> "$W/bad.txt" && fail "accepted -1"
grep -q "expects a count" "$W/bad.txt" || fail "no message for a bad bound"
[ ! -e "$W/bad" ] || fail "a pack was written for a bad bound"
echo ok
