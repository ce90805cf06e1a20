#!/bin/sh
# The runtime's caches across runs (screen path, lavapipe, SPLAT_VALIDATE=1):
#   spirv_cache.sh SPLATVIEW PACK OUTDIR GLSLPACK
# 0. PACK as splatc builds it by default: every compute module is the
#    build's SPIR-V, nothing is compiled (issue 29 "compile once, never
#    at load").  Then GLSLPACK, the same built with --glsl-compute:
# 1. A fresh SPIR-V cache: every compute module is compiled from GLSL and
#    stored, and the Vulkan pipeline cache file is written.
# 2. The same view again: every compute module comes from the SPIR-V cache,
#    none is compiled, and the picture is the same to the bit.
# 3. Every cache entry damaged (one byte flipped): each is a miss, the
#    modules are compiled again, and the picture is still the same.
set -eu
SV=$1 PACK=$2 OUT=$3/spirv_cache GLSLPACK=$4
rm -rf "$OUT"
mkdir -p "$OUT"
export SPLAT_VALIDATE=1 SPLATC_CACHE="$OUT/cache" SPLAT_PIPELINE_CACHE="$OUT/pipelines.bin"
. "$(dirname "$0")/../lib.sh"   # fail, same
render() {   # render N: the picture and the --stats line of run N
    "$SV" "$PACK" --headless --size 320x180 --shading screen --stats \
        -o "$OUT/run$1.png" > "$OUT/run$1.log" 2>&1 || { cat "$OUT/run$1.log"; fail "splatview run $1"; }
    grep '^compute modules:' "$OUT/run$1.log" || fail "run $1: no 'compute modules' line"
}
# counts N: "CACHED COMPILED" from run N's line
counts() { sed -n 's/^compute modules: \([0-9]*\) from the pack or the SPIR-V cache, \([0-9]*\) compiled.*/\1 \2/p' "$OUT/run$1.log"; }

# (--stats's counting frame afterwards compiles the counting variants, a
# #define added to the GLSL, into a cache of their own here)
SPLATC_CACHE="$OUT/cache0"
render 0
SPLATC_CACHE="$OUT/cache"
set -- $(counts 0)
[ "$1" -gt 0 ] && [ "$2" = 0 ] || fail "run 0 (the default pack): expected only the pack's modules, got $1 from the pack, $2 compiled"
cp "$OUT/run0.png" "$OUT/default.png"
PACK=$GLSLPACK
render 1
cmp "$OUT/default.png" "$OUT/run1.png" || fail "the --glsl-compute pack's picture differs from the default pack's"
set -- $(counts 1)
[ "$1" = 0 ] && [ "$2" -gt 0 ] || fail "run 1: expected only compiled modules, got $1 cached, $2 compiled"
compiled=$2
[ -s "$OUT/pipelines.bin" ] || fail "run 1 wrote no pipeline cache"
entries=$(find "$OUT/cache" -type f | wc -l)
[ "$entries" -ge "$compiled" ] || fail "$compiled modules compiled but $entries cache entries"

render 2
set -- $(counts 2)
[ "$1" = "$compiled" ] && [ "$2" = 0 ] ||
    fail "run 2: expected $compiled cached and 0 compiled, got $1 and $2"
same "$OUT/run1.png" "$OUT/run2.png" "run 2's picture differs from run 1's"

for f in $(find "$OUT/cache" -type f); do
    printf '\377' | dd of="$f" bs=1 seek=40 conv=notrunc status=none
done
render 3
set -- $(counts 3)
[ "$1" = 0 ] && [ "$2" = "$compiled" ] ||
    fail "run 3 (damaged entries): expected 0 cached and $compiled compiled, got $1 and $2"
same "$OUT/run1.png" "$OUT/run3.png" "run 3's picture differs from run 1's"
echo "ok: $compiled compute modules compiled, then all from the cache, then compiled again past damaged entries"
