#!/bin/sh
# check_pack.sh SPLATC SCENE OUT CACHE — build SCENE into OUT (SPIR-V cache in
# CACHE) and pass every shader of the pack through spirv-val and
# glslangValidator: the composites, the reference passes, the über-shader and
# the vertex shader.
set -e
splatc=$1 scene=$2 out=$3 cache=$4
"$splatc" build "$scene" -o "$out" --cache "$cache" -j 2
n=0
for f in "$out"/shaders/*.spv; do
    spirv-val --target-env vulkan1.2 "$f" || { echo "spirv-val: $f" >&2; exit 1; }
    n=$((n + 1))
done
for f in "$out"/shaders/*.frag "$out"/shaders/*.vert; do
    if ! glslangValidator -V --target-env vulkan1.2 -o /dev/null "$f" >/dev/null; then
        glslangValidator -V --target-env vulkan1.2 -o /dev/null "$f" >&2
        exit 1
    fi
done
test -f "$out/manifest.json"
echo "$scene: $n SPIR-V modules and their GLSL valid"
