#!/bin/sh
# check_pack.sh SPLATC SCENE OUT CACHE — build SCENE into OUT (SPIR-V cache in
# CACHE) and pass every shader of the pack through spirv-val and
# glslangValidator: the composites, the reference passes, the über-shader,
# the vertex shader and the compute variants (their SPIR-V made and
# validated by splatc too, the default) and their counting variants.
# The checks run two files at a time (colorado has some 500 shaders).
set -eu
. "$(dirname "$0")/../lib.sh"   # to, fail
splatc=$1 scene=$2 out=$3 cache=$4
"$splatc" build "$scene" -o "$out" --cache "$cache" -j 2
# the pack's shader files are zstd frames (compiler/PACK.md "Compressed
# shaders"): checked as the plain files they hold, under OUT.plain
pack=$out
out=$out.plain
rm -rf "$out" && mkdir -p "$out/shaders"
for f in "$pack"/shaders/*.zst; do
    b=${f##*/}
    must zstd -q -d "$f" -o "$out/shaders/${b%.zst}"
done
# the lists: ls fails (and so the test) when a kind of shader is missing
to "$out.spv.list" ls "$out"/shaders/*.spv
to "$out.comp.spv.list" ls "$out"/shaders/*.comp.spv
to "$out.glsl.list" ls "$out"/shaders/*.frag "$out"/shaders/*.vert "$out"/shaders/*.comp
to "$out.comp.list" ls "$out"/shaders/*.comp
n=$(wc -l < "$out.spv.list")
# each batch exits 255 on the first failure, which stops xargs (and set -e)
xargs -P 2 -n 16 < "$out.spv.list" sh -c '
    for f; do
        spirv-val --target-env vulkan1.2 "$f" || { echo "spirv-val: $f" >&2; exit 255; }
    done' sh
xargs -P 2 -n 8 < "$out.glsl.list" sh -c '
    for f; do
        if ! glslangValidator -V --target-env vulkan1.2 -o /dev/null "$f" >/dev/null; then
            glslangValidator -V --target-env vulkan1.2 -o /dev/null "$f" >&2
            exit 255
        fi
    done' sh
# the counting variant the runtime compiles from each compute shader (abi.h)
xargs -P 2 -n 8 < "$out.comp.list" sh -c '
    v=$(mktemp --suffix=.spv)
    for f; do
        if ! glslangValidator -V --target-env vulkan1.2 -DSPLAT_COUNT=1 -o "$v" "$f" >/dev/null ||
           ! spirv-val --target-env vulkan1.2 "$v"; then
            glslangValidator -V --target-env vulkan1.2 -DSPLAT_COUNT=1 -o /dev/null "$f" >&2
            rm -f "$v"
            exit 255
        fi
    done
    rm -f "$v"' sh
test -f "$pack/manifest.json"
echo "$scene: $n SPIR-V modules and their GLSL valid, and the counting variants"
