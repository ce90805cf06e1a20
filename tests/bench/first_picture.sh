#!/bin/bash
# first_picture.sh SPLATBENCH PACK SIZE LABEL [PATH]: process wall time from
# launch to exit of one frame (no warm-up) on the screen and forward paths,
# first with every cache empty (the SPIR-V cache, the Vulkan pipeline
# cache, the driver's own: Mesa's and NVIDIA's), then again with the caches
# the first run left.  One line per run:
#   LABEL PATH KIND cold|warm SECONDS
# KINDS (default "screen screen,async composite") picks splatbench kinds;
# screen,async is the first picture with the über-shader standing in for
# pipelines still being made.  FP_ARGS (default none): more splatbench
# render arguments, e.g. FP_ARGS="--start-preset overview" with PATH preset
# (a camera preset of the pack, the view splatview's first picture shows).
set -u
SB=$1 PACK=$2 SIZE=$3 LABEL=$4 P=${5:-topdown}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
TIMEFORMAT=%R
for kind in ${KINDS:-screen screen,async composite}; do
    rm -rf "$TMP/c"
    mkdir -p "$TMP/c"
    for run in cold warm; do
        t=$( { time SPLATC_CACHE="$TMP/c/spv" SPLAT_PIPELINE_CACHE="$TMP/c/pipelines.bin" \
                 MESA_SHADER_CACHE_DIR="$TMP/c/mesa" __GL_SHADER_DISK_CACHE_PATH="$TMP/c/nv" \
                 "$SB" render --pack "$PACK" --variant "x=$kind" --path "$P" --frames 1 \
                 --warmup 0 ${FP_ARGS:-} --size "$SIZE" --csv "$TMP/r.csv" > "$TMP/log" 2>&1; } 2>&1 ) ||
            { cat "$TMP/log"; echo "$LABEL $P $kind $run FAILED"; continue; }
        echo "$LABEL $P $kind $run $t"
    done
done
