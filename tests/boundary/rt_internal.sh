#!/bin/sh
# The runtime's library boundary: rt_internal.sh ROOT
#
# runtime/rt_internal.h (the structs behind rt_device and rt_pack, the
# Vulkan helpers, the pack's parsers, the quadtree, the pipelines) is for
# libsplatrt's own files.  Every other C file -- splatview (runtime/
# splatview.c is a program, not the library), the compiler, the examples,
# the test kit and the tests -- uses splatrt.h alone, except the files
# listed below, each with why it must see the insides.  Fails when another
# file includes rt_internal.h, when a listed file no longer does (take it
# off the list), and when a listed file has no reason.
set -eu
ROOT=$1
allowed='
tests/bench/bench.h                  times and compiles the compute shaders of single combinations (rt_glsl_compile, rt_pack.combos)
tests/fuzz/fuzz_combos.c             fuzzes the combos.bin parser (rt_combos_parse)
tests/fuzz/fuzz_manifest.c           fuzzes the in-place pack loader (rt_pack_load into a stack rt_pack)
tests/fuzz/fuzz_spirv.c              fuzzes the SPIR-V checks (rt_spirv_validate, rt_spirv_check)
tests/harness/harness.c              runs compute shaders on the runtime'"'"'s Vulkan buffers and images (rt_buffer, rt_image)
tests/pack/test_pack_checks.c        shrinks rt_device limits field by field against rt_pack_check_device; rt_spirv_check
tests/render/make_fixture.c          writes a pack by hand: combos.bin levels (rt_level_count) and SPIR-V (rt_glsl_compile)
tests/sparse/gpu_sparse.c            samples sparse masks from rt_image/rt_buffer uploads on the device
tests/unit/test_quadtree.c           tests the quadtree, its bounds and index permutations (rt_quadtree_select, rt_bounds)
tests/unit/test_fog.c                builds an rt_pack by hand (camera presets, size) for the fog default formula
tests/render/test_ug_look.c          asserts on the loaded undergrowth blocks (rt_pack.ug: wind, textures, cutout)
tests/render/test_shadow_gpu.c       compares the device shadow map with the CPU reference (rt_shadow_map)
tests/world/test_holes.c             checks the combination levels and node bounds over holes (rt_pack_level, rt_bounds_build)
tests/world/test_placed.c            reads the sparse painted store of the loaded pack (rt_pack.sparse)
tests/render/test_dclass.c           picks rock texels from the leaf combination map (rt_pack.levels, rt_pack.combos)
tests/render/test_vk_build.c         tests the internal Vulkan builder (vk_build.h, the device handles)
tests/unit/test_classify_view.c      checks the view classification against a search over every combination (rt_class_view_build)
'
cd "$ROOT"
# every C file but the library's own (runtime/*.c except splatview.c) and
# build trees
found=$(find . -path ./.git -prune -o -path './build*' -prune -o \
             \( -name '*.c' -o -name '*.h' -o -name '*.cpp' \) -type f -print |
        sed 's|^\./||' | grep -v '^runtime/' | sort)
found="$found
runtime/splatview.c"
users=$(for f in $found; do
            grep -l '^[[:space:]]*#[[:space:]]*include[[:space:]]*[<"]\([^">]*/\)\{0,1\}rt_internal\.h[">]' "$f" \
                2>/dev/null || true
        done | sort)
listed=$(echo "$allowed" | awk 'NF { print $1 }')
bad=0
echo "$allowed" | awk 'NF == 1 { print "FAIL: " $1 " is listed without a reason"; exit 1 }' || bad=1
for f in $users; do
    echo "$listed" | grep -qx "$f" ||
        { echo "FAIL: $f includes rt_internal.h: use splatrt.h (or list it here, with why)"; bad=1; }
done
for f in $listed; do
    [ -e "$f" ] || { echo "FAIL: $f is listed but does not exist"; bad=1; continue; }
    echo "$users" | grep -qx "$f" ||
        { echo "FAIL: $f is listed but no longer includes rt_internal.h (take it off)"; bad=1; }
done
n=$(echo "$users" | grep -c . || true)
[ $bad = 0 ] && echo "ok: $n files outside the library include rt_internal.h, each listed with its reason"
exit $bad
