#!/bin/bash
# first_picture.sh SPLATBENCH PACK SIZE LABEL [PATH]: one frame (no warm-up)
# per kind, first with every cache empty (the SPIR-V cache, the Vulkan
# pipeline cache, the driver's own: Mesa's and NVIDIA's), then again with
# the caches the first run left.  One line per run:
#   LABEL PATH KIND cold|warm EXIT_S FIRST_S
# EXIT_S: process wall time from launch to exit; FIRST_S: the process's
# own first picture, launch to its first complete frame on the GPU
# (splatbench's first_picture_s column, rt_seconds_since_launch).  Exit
# also waits for the pipelines the workers are making then (not those
# only queued) and splatbench's counting frame.
# KINDS (default "screen screen,async screen,async+uber composite") picks
# splatbench kinds; KIND+STANDIN runs KIND with SPLAT_STAND_IN=STANDIN:
#   screen,async       the default stand-in: the far atlas where the pack
#                      has one, else the flat stand-in (no über-shader
#                      made before the first picture)
#   screen,async+flat  the flat stand-in even where there is an atlas
#   screen,async+uber  the über-shader standing in where making it costs
#                      less than the lists' composites (the stand-in
#                      before the flat one: the figures before it)
# FP_ARGS (default none): more splatbench render arguments, e.g.
# FP_ARGS="--start-preset overview" with PATH preset (a camera preset of
# the pack, the view splatview's first picture shows).
set -u
SB=$1 PACK=$2 SIZE=$3 LABEL=$4 P=${5:-topdown}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
TIMEFORMAT=%R
for entry in ${KINDS:-screen screen,async screen,async+uber composite}; do
    kind=${entry%%+*}
    stand=
    [ "$kind" != "$entry" ] && stand=${entry#*+}
    rm -rf "$TMP/c"
    mkdir -p "$TMP/c"
    for run in cold warm; do
        rm -f "$TMP/r.csv"
        t=$( { time SPLAT_STAND_IN="$stand" SPLATC_CACHE="$TMP/c/spv" \
                 SPLAT_PIPELINE_CACHE="$TMP/c/pipelines.bin" \
                 MESA_SHADER_CACHE_DIR="$TMP/c/mesa" __GL_SHADER_DISK_CACHE_PATH="$TMP/c/nv" \
                 "$SB" render --pack "$PACK" --variant "x=$kind" --path "$P" --frames 1 \
                 --warmup 0 ${FP_ARGS:-} --size "$SIZE" --csv "$TMP/r.csv" > "$TMP/log" 2>&1; } 2>&1 ) ||
            { cat "$TMP/log"; echo "$LABEL $P $entry $run FAILED"; continue; }
        first=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "first_picture_s") c = i }
                         NR == 2 && c { print $c }' "$TMP/r.csv")
        echo "$LABEL $P $entry $run $t ${first:-?}"
    done
done
