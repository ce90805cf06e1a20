#!/bin/sh
# h100_prepare.sh BUILD_DIR DEST — gather what tests/bench/run.sh needs on a
# machine without this project's Debian packages (the H100 of the device
# tool): the programs in BUILD_DIR's layout (compiler/splatc,
# tests/splatbench, tests/test_quadtree, tests/gpu_sparse) and the shared
# libraries they load that a CUDA image lacks (jansson, xxhash, stb, the
# Vulkan loader, SPIRV-Cross), under DEST/lib, and the example packs
# under DEST/packs (built here; run from the repository root).  DEST should be an ignored folder of the
# repository (build-h100/ is, through /build*/) so it can be carried.
# On the device, from the repository root (see tests/bench/HISTORY.md, "NVIDIA GPU through the device tool"):
#   export LD_LIBRARY_PATH=$PWD/DEST/lib:$LD_LIBRARY_PATH
#   export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
#   sh tests/bench/run.sh DEST --quick --out $OUT/bench
set -eu
B=$1 D=$2
mkdir -p "$D/compiler" "$D/tests" "$D/lib"
cp "$B/compiler/splatc" "$D/compiler/"
cp "$B/tests/splatbench" "$D/tests/"
for t in test_quadtree gpu_sparse; do
    [ -x "$B/tests/$t" ] && cp "$B/tests/$t" "$D/tests/"
done
for l in libjansson.so.4 libxxhash.so.0 libstb.so.0 libvulkan.so.1 libspirv-cross-c-shared.so.0 libzstd.so.1; do
    p=$(ldconfig -p | awk -v l="$l" '$1 == l && /x86-64/ { print $NF; exit }')
    [ -n "$p" ] && cp -L "$p" "$D/lib/"
done
# The example packs, built here: splatc needs libgdal and its many
# libraries, which a CUDA image lacks and which would not fit the carry.
mkdir -p "$D/packs"
for s in colorado minimal billingsley; do
    "$B/compiler/splatc" build "examples/$s/scene.sg" -o "$D/packs/$s" -j 2 --no-cache > /dev/null
done
du -sh "$D"
