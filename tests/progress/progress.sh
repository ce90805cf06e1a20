#!/bin/sh
# splatc build's progress (compiler/progress.c): progress.sh SPLATC SCENE OUTDIR
#   - not a terminal: stderr carries no progress (logs and tests stay clean);
#   - SPLATC_PROGRESS=lines: a line as each phase ends, "PHASE N/N";
#   - a terminal (script(1) gives one): the bar, with k/N and an ETA, and
#     the line cleared before the report.
set -eu
SPLATC=$1 SCENE=$2 OUT=$3/progress
rm -rf "$OUT"
mkdir -p "$OUT"
. "$(dirname "$0")/../lib.sh"   # fail, same
"$SPLATC" build "$SCENE" -o "$OUT/a" --no-cache 2> "$OUT/quiet.err" > /dev/null || fail "build"
if grep -q 'splatc: \(compose\|glslang\|spirv-val\)' "$OUT/quiet.err"; then
    cat "$OUT/quiet.err"; fail "progress printed where stderr is not a terminal"
fi
SPLATC_PROGRESS=lines "$SPLATC" build "$SCENE" -o "$OUT/b" --no-cache 2> "$OUT/lines.err" > /dev/null ||
    fail "build (lines)"
for phase in compose glsl glslang+spirv-val; do
    grep -q "^splatc: $phase \([0-9]*\)/\1 " "$OUT/lines.err" ||
        { cat "$OUT/lines.err"; fail "no finished '$phase' line"; }
done
if command -v script > /dev/null; then
    script -qec "'$SPLATC' build '$SCENE' -o '$OUT/c' --no-cache" "$OUT/tty.log" > /dev/null ||
        fail "build on a terminal"
    grep -q 'splatc: glslang+spirv-val .*ETA' "$OUT/tty.log" || { cat -v "$OUT/tty.log"; fail "no bar on a terminal"; }
    grep -q "$(printf '\r\033\\[K')" "$OUT/tty.log" || fail "the bar's line is not cleared"
fi
same "$OUT/a/manifest.json" "$OUT/b/manifest.json" "progress changed the pack"
echo "ok"
