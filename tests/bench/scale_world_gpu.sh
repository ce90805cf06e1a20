#!/bin/sh
# scale_world_gpu.sh — the H100 columns of the scale_world table (issue 29,
# "What must show it"): on the device, from the repository root, with
# h100_prepare.sh's build-h100 and the worlds' packs built here (splatc
# links GDAL, which the device lacks: tests/bench/scale_world_packs.sh
# builds them and packs them into one tar.xz).
#
#   sh tests/bench/scale_world_gpu.sh [--build DIR] [--packs DIR] [--out DIR]
#       [--counts "8 32 ..."] [--size WxH] [--frames N] [--warmup N]
#       [--camera NAME] [--timeout S]
#
# defaults: --build build-h100, --packs BUILD/packs (the worlds as wM, M
# the material count), --out $OUT/scale_world_gpu (else out/scale_world_gpu),
# --counts "8 32 64 128 256" (a world without its pack is skipped, said on
# stderr), --size 1920x1080, --frames 20 --warmup 2, --camera overview (the
# camera splatview's first picture shows, the one scale_world.sh measures on
# lavapipe), --timeout 240 (seconds, per splatbench process group).
#
# Per world, on the same camera held still (splatbench render --path preset
# --start-preset CAMERA):
#   first picture  tests/bench/first_picture.sh: process wall time, launch
#                  to exit, of one frame with no warm-up, every cache empty
#                  (cold: the SPIR-V cache, the Vulkan pipeline cache, the
#                  driver's own) and again with what the cold run left
#                  (warm), for the screen path (pipelines made up front),
#                  the screen path with async pipelines (a stand-in
#                  shading the tiles of pipelines still being made: the
#                  far atlas, the flat stand-in or a made über-shader,
#                  first_picture.sh) and the forward path (kind composite);
#                  for the async kind also the process's own first
#                  picture (launch to its first complete frame), the
#                  last two columns;
#   steady frame   one splatbench render of the screen and the forward path
#                  as two variants (frames interleaved), --frames timed
#                  frames after --warmup: GPU ms per frame (timestamp
#                  median, p10, p90), layers evaluated and needed per pixel
#                  and samples per pixel (the counting frame's; forward: per
#                  fragment shaded), the screen tiles the über-shader shaded.
# Writes OUT/scale_world_gpu.tsv (one row per world; the columns
# scale_world.gp plots when the file is put beside scale_world.tsv),
# OUT/first.txt (first_picture.sh's lines), OUT/wM_steady.csv and
# OUT/wM_steady.log, and prints the TSV.  Five worlds take a few minutes on
# an H100.  Nothing is asserted: figures only.
#
# On the device (tests/bench/HISTORY.md, "NVIDIA GPU through the device
# tool"), carrying build-h100 and .gl:
#   for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
#   tar -C build-h100 -xJf scale29_packs.tar.xz   # -> build-h100/packs/wM
#   sh tests/bench/scale_world_gpu.sh
# LD_LIBRARY_PATH gets BUILD/lib and VK_DRIVER_FILES NVIDIA's ICD when unset.
set -u
B=build-h100 PACKS="" O="${OUT:+$OUT/scale_world_gpu}" COUNTS="8 32 64 128 256"
SIZE=1920x1080 FRAMES=20 WARMUP=2 CAM=overview TO=240
while [ $# -gt 0 ]; do
    case $1 in
    --build) B=$2; shift ;;
    --packs) PACKS=$2; shift ;;
    --out) O=$2; shift ;;
    --counts) COUNTS=$2; shift ;;
    --size) SIZE=$2; shift ;;
    --frames) FRAMES=$2; shift ;;
    --warmup) WARMUP=$2; shift ;;
    --camera) CAM=$2; shift ;;
    --timeout) TO=$2; shift ;;
    *) echo "scale_world_gpu.sh: unknown option '$1'" >&2; exit 2 ;;
    esac
    shift
done
: "${PACKS:=$B/packs}" "${O:=out/scale_world_gpu}"
REPO=$(cd "$(dirname "$0")/../.." && pwd)
SB=$B/tests/splatbench
[ -x "$SB" ] || { echo "scale_world_gpu.sh: $SB is not there (h100_prepare.sh)" >&2; exit 1; }
if [ -d "$B/lib" ]; then
    LD_LIBRARY_PATH=$(cd "$B/lib" && pwd)${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
    export LD_LIBRARY_PATH
fi
ICD=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -z "${VK_DRIVER_FILES:-}" ] && [ -f "$ICD" ]; then
    VK_DRIVER_FILES=$ICD
    export VK_DRIVER_FILES
fi
mkdir -p "$O"
TSV=$O/scale_world_gpu.tsv
: > "$O/first.txt"

# csv_field CSV LABEL COLUMN: the row of variant LABEL, the column named
# COLUMN in the header (NA when absent; the quoted device column dropped)
csv_field() {
    [ -f "$1" ] || { echo NA; return 0; }
    sed 's/^"[^"]*",//; s/^device,//' "$1" | awk -F, -v l="$2" -v c="$3" '
        NR == 1 { for (i = 1; i <= NF; i++) if ($i == c) k = i; next }
        $5 == l && k { v = $k } END { print (v == "" ? "NA" : v) }'
}
# first_s LABEL KIND RUN: the seconds first_picture.sh printed (NA if none,
# FAILED if it failed)
# (field 5, launch to exit; FIELD=6: the process's own first picture)
first_s() {
    awk -v l="$1" -v k="$2" -v r="$3" -v f="${FIELD:-5}" '$1 == l && $3 == k && $4 == r { v = $f }
        END { print (v == "" ? "NA" : v) }' "$O/first.txt"
}

printf 'materials\tdevice\tsize\tcamera\tfirst_screen_cold_s\tfirst_screen_warm_s\tfirst_screen_async_cold_s\tfirst_screen_async_warm_s\tfirst_forward_cold_s\tfirst_forward_warm_s\tsteady_screen_gpu_ms\tsteady_screen_layers_px\tsteady_screen_needed_px\tsteady_screen_samples_px\tsteady_screen_tiles_uber\tsteady_forward_gpu_ms\tsteady_forward_layers_px\tsteady_forward_needed_px\tsteady_forward_samples_px\tsteady_screen_p10_ms\tsteady_screen_p90_ms\tsteady_forward_p10_ms\tsteady_forward_p90_ms\tframes\tfirst_async_picture_cold_s\tfirst_async_picture_warm_s\n' > "$TSV"
for M in $COUNTS; do
    P=$PACKS/w$M
    [ -f "$P/manifest.json" ] || { echo "scale_world_gpu.sh: no pack $P, skipped" >&2; continue; }
    echo "[scale_world_gpu] w$M: first picture $SIZE" >&2
    FP_ARGS="--start-preset $CAM" KINDS="screen screen,async composite" \
        timeout "$TO" bash "$REPO/tests/bench/first_picture.sh" "$SB" "$P" "$SIZE" "w$M" preset \
        >> "$O/first.txt" 2>&1 || echo "w$M preset first_picture.sh FAILED ($?)" >> "$O/first.txt"
    echo "[scale_world_gpu] w$M: steady frame, $WARMUP + $FRAMES frames" >&2
    C=$O/w${M}_steady.csv
    rm -f "$C"
    timeout "$TO" "$SB" render --pack "$P" --scene "w$M" --path preset --start-preset "$CAM" \
        --variant screen=screen --variant forward=composite --frames "$FRAMES" \
        --warmup "$WARMUP" --size "$SIZE" --csv "$C" > "$O/w${M}_steady.log" 2>&1 ||
        { echo "scale_world_gpu.sh: w$M: splatbench render failed ($?)" >&2; tail -5 "$O/w${M}_steady.log" >&2; }
    dev=$( [ -f "$C" ] && sed -n '2s/^"\([^"]*\)".*/\1/p' "$C" || true)
    printf '%s\t%s\t%s\t%s' "$M" "${dev:-NA}" "$SIZE" "$CAM" >> "$TSV"
    for k in screen screen,async composite; do
        printf '\t%s\t%s' "$(first_s "w$M" $k cold)" "$(first_s "w$M" $k warm)" >> "$TSV"
    done
    for f in screen:gpu_med_ms screen:layers_evaluated screen:layers_needed screen:samples_per_px \
             screen:tiles_uber forward:gpu_med_ms forward:layers_evaluated forward:layers_needed \
             forward:samples_per_px screen:gpu_p10_ms screen:gpu_p90_ms forward:gpu_p10_ms \
             forward:gpu_p90_ms; do
        printf '\t%s' "$(csv_field "$C" "${f%%:*}" "${f#*:}")" >> "$TSV"
    done
    printf '\t%s\t%s\t%s\n' "$FRAMES" "$(FIELD=6 first_s "w$M" screen,async cold)" \
        "$(FIELD=6 first_s "w$M" screen,async warm)" >> "$TSV"
done
cat "$TSV"
