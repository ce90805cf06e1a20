#!/bin/sh
# scale_world.sh — the `scale_world` benchmark group (issue 29, "What must
# show it"): gen_world's synthetic worlds (tests/bench/gen_world.c
# --textures: B biomes x 8 materials over a base, a texture each) side by
# side for 8, 32, 64, 128 and 256 materials, one table.
#
#   sh tests/bench/scale_world.sh BUILD_DIR [--smoke] [--out DIR]
#       [--counts "8 32 ..."] [--reps N] [--size WxH] [--hf N]
#       [--view-timeout S] [--no-view] [--keep-work] [--packs DIR]
#       [--steady-frames N] [--steady-warmup N] [--steady-timeout S]
#
# Per material count (a multiple of 8):
#   combinations   the leaf cells' combinations and the pipelines built,
#                  the largest composite and the largest leaf-cell overlap
#                  (layers), from `splatc build --stats`;
#   cold build     splatc build -j 2 into a fresh pack folder with a fresh,
#                  empty SPIR-V cache folder (nothing to hit: a cold build
#                  that also fills the cache the rebuild reads), wall time
#                  and peak RSS (GNU time, else tests/bench/peakrss);
#   edit rebuild   material b0_m1's colour constant edited in the scene,
#                  the same pack rebuilt with the warm cache: wall time and
#                  the shaders recompiled (--stats: "shaders: N (H from
#                  cache, C compiled)"), beside the combinations that hold
#                  b0_m1 (the manifest);
#   pack           du -sb of the pack folder, and its texture arrays;
#   first picture  splatview --headless at SIZE (default 1280x720), process
#                  wall time launch to exit, on the screen path (pipelines
#                  made up front: headless waits for all), the screen path
#                  with --async-pipelines on (the uber-shader shades the
#                  tiles of pipelines still compiling) and the forward
#                  path, each with a fresh Mesa shader cache and pipeline
#                  cache, and the screen path again with the caches its
#                  first run left (warm); a run past --view-timeout (default 900 s) is
#                  written as "timeout"; peak RSS of the viewer (the largest
#                  of its runs);
#   steady frame   tests/splatbench render on the same pack and camera (the
#                  scene's 'overview' preset, splatview's first picture's,
#                  held still: --path preset), the screen path and the
#                  forward path (kind composite) as two variants of one run,
#                  frames interleaved, after --steady-warmup untimed frames
#                  (default 1: lavapipe JIT-compiles inside the first frame)
#                  --steady-frames timed frames (default 3,
#                  --smoke 1; 0 skips): GPU ms
#                  per frame (timestamp median), layers evaluated and layers
#                  needed per pixel and texture samples per pixel (the
#                  counting frame's; forward: per fragment shaded), the
#                  über-shader's screen tiles, and splatbench's peak RSS;
#                  a run past --steady-timeout (default 2700 s: at 256
#                  materials on this machine at load 10 it took over 900 s,
#                  mostly making 291 compute and 291 forward pipelines) is
#                  written as NA.
# --reps N repeats every build and picture N times (default 1) and reports
# medians (the steady frame runs once: its figures are already medians of
# frames).  --no-view: builds only (the picture and steady columns NA).
# --packs DIR: a copy of each cold-built pack as DIR/wM (M the material
# count; what tests/bench/scale_world_gpu.sh renders on the H100).  --smoke: 8 and 16 materials on a 256^2 heightfield, pictures at
# 320x180 (bench.smoke, a minute or two).
#
# Writes OUT/scale_world.tsv (one row per material count), OUT/scale_world.md
# (the same as a Markdown table) and, with gnuplot, OUT/scale_world.png
# (tests/bench/scale_world.gp; it adds the H100's figures when
# OUT/scale_world_gpu.tsv is there, tests/bench/scale_world_gpu.sh's output).  Nothing is asserted: figures only (the
# structure is asserted by bench.world_* in `make test`).
set -eu
. "$(dirname "$0")/../lib.sh"   # differ

if [ $# -lt 1 ]; then
    echo "usage: sh tests/bench/scale_world.sh BUILD_DIR [--smoke] [--out DIR] [--counts LIST] [--reps N]" >&2
    exit 2
fi
B=$(cd "$1" && pwd)
shift
MODE=full OUT=out/bench COUNTS="" REPS=1 SIZE="" HF="" VT=900 KEEP=no NOVIEW=no PACKS=""
SFRAMES="" SWARM="" STO=2700
while [ $# -gt 0 ]; do
    case $1 in
    --smoke) MODE=smoke ;;
    --out) OUT=$2; shift ;;
    --counts) COUNTS=$2; shift ;;
    --reps) REPS=$2; shift ;;
    --size) SIZE=$2; shift ;;
    --hf) HF=$2; shift ;;
    --view-timeout) VT=$2; shift ;;
    --keep-work) KEEP=yes ;;
    --no-view) NOVIEW=yes ;;
    --packs) PACKS=$2; shift ;;
    --steady-frames) SFRAMES=$2; shift ;;
    --steady-warmup) SWARM=$2; shift ;;
    --steady-timeout) STO=$2; shift ;;
    *) echo "scale_world.sh: unknown option '$1'" >&2; exit 2 ;;
    esac
    shift
done
if [ "$MODE" = smoke ]; then
    : "${COUNTS:=8 16}" "${SIZE:=320x180}" "${HF:=256}" "${SFRAMES:=1}" "${SWARM:=1}"
else
    : "${COUNTS:=8 32 64 128 256}" "${SIZE:=1280x720}" "${HF:=1024}" "${SFRAMES:=3}" "${SWARM:=1}"
fi
REPO=$(cd "$(dirname "$0")/../.." && pwd)
SPLATC=$B/compiler/splatc
VIEW=$B/runtime/splatview
GEN=$B/tests/gen_world
SB=$B/tests/splatbench
for t in "$SPLATC" "$VIEW" "$GEN" "$SB"; do
    [ -x "$t" ] || { echo "scale_world.sh: $t is not built (cmake --build $B)" >&2; exit 1; }
done
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
if [ -n "$PACKS" ]; then
    mkdir -p "$PACKS"
    PACKS=$(cd "$PACKS" && pwd)
fi
W=$OUT/scale_world_work
rm -rf "$W" "$OUT/scale_world.tsv" "$OUT/scale_world.md" "$OUT/scale_world.png"
mkdir -p "$W"
cd "$REPO"   # the scenes import nodes/ from the project root
START=$(date +%s)
LOAD0=$(cut -d' ' -f1-3 /proc/loadavg)
log() { echo "[scale_world $(( $(date +%s) - START ))s] $*"; }

# measure OUTFILE CMD... : runs CMD (stdout to OUTFILE) and prints
# "WALL_S PEAK_KB" (PEAK_KB: the largest resident set of the process tree's
# largest process, GNU time's %M / getrusage's ru_maxrss)
if [ -x /usr/bin/time ] && /usr/bin/time -f %M true >/dev/null 2>&1; then
    measure() {
        o=$1; shift
        rc=0
        /usr/bin/time -f "%e %M" -o "$W/time.txt" "$@" > "$o" 2>&1 || rc=$?
        [ $rc -eq 0 ] || { echo "NA NA $rc"; return 0; }
        cat "$W/time.txt"
    }
else
    [ -x "$B/tests/peakrss" ] || { echo "scale_world.sh: neither GNU time nor $B/tests/peakrss" >&2; exit 1; }
    measure() {
        o=$1; shift
        rc=0
        "$B/tests/peakrss" -o "$W/time.txt" "$@" > "$o" 2>&1 || rc=$?
        [ $rc -eq 0 ] || { echo "NA NA $rc"; return 0; }
        cat "$W/time.txt"
    }
fi
# median of the numbers on stdin ("NA" where any is not a number)
median() { sort -g | awk '/^[0-9.]+$/ { v[n++] = $1; next } { bad = 1 }
    END { if (bad || n == 0) print "NA"; else print n % 2 ? v[(n - 1) / 2] : (v[n / 2 - 1] + v[n / 2]) / 2 }'; }
# stat FILE REGEX FIELD: a field of the first line of --stats output matching
stat_field() { awk -v re="$2" -v f="$3" '$0 ~ re { print $f; exit }' "$1"; }

# csv_field CSV LABEL COLUMN: splatbench's row of variant LABEL, the
# column named COLUMN in the header (NA when absent; the device column, the
# first, is quoted and dropped first)
csv_field() {
    [ -f "$1" ] || { echo NA; return 0; }
    sed 's/^"[^"]*",//; s/^device,//' "$1" | awk -F, -v l="$2" -v c="$3" '
        NR == 1 { for (i = 1; i <= NF; i++) if ($i == c) k = i; next }
        $5 == l && k { v = $k } END { print (v == "" ? "NA" : v) }'
}

TSV=$OUT/scale_world.tsv
printf 'materials\tbiomes\tcombinations\tpipelines\tlargest_layers\tleaf_overlap\tcold_build_s\tbuild_peak_mb\tglslang_s\tvalidation_s\tedit_rebuild_s\tedit_shaders_recompiled\tshaders\tedit_combos_with_material\tpack_mb\ttextures\ttexture_arrays\tview_screen_s\tview_screen_async_s\tview_forward_s\tview_peak_mb\tsize\theightfield\treps\tview_screen_warm_s\tsteady_screen_gpu_ms\tsteady_screen_layers_px\tsteady_screen_needed_px\tsteady_screen_samples_px\tsteady_screen_tiles_uber\tsteady_forward_gpu_ms\tsteady_forward_layers_px\tsteady_forward_needed_px\tsteady_forward_samples_px\tsteady_peak_mb\tsteady_camera\tsteady_frames\n' > "$TSV"

for M in $COUNTS; do
    NB=$((M / 8))
    [ $((NB * 8)) -eq "$M" ] && [ "$NB" -ge 1 ] ||
        { echo "scale_world.sh: $M materials is not a multiple of 8" >&2; exit 2; }
    D=$W/m$M
    rm -rf "$D" && mkdir -p "$D"
    log "$M materials: gen_world --textures $NB x 8, ${HF}^2 heightfield"
    mkdir -p "$D/world"
    "$GEN" --textures "$D/world" "$NB" 8 "$HF" 16 > /dev/null
    # ---- cold build (REPS times, the last one's pack and cache kept) ----
    : > "$D/cold.txt"
    r=0
    while [ $r -lt "$REPS" ]; do
        rm -rf "$D/pack" "$D/cache"
        log "$M materials: cold build ($((r + 1))/$REPS)"
        measure "$D/cold_stats.txt" "$SPLATC" build "$D/world/scene.sg" -o "$D/pack" -j 2 \
            --cache "$D/cache" --stats >> "$D/cold.txt"
        r=$((r + 1))
    done
    if [ ! -f "$D/pack/manifest.json" ]; then   # the build failed: say so, go on
        log "$M materials: splatc build failed"
        tail -5 "$D/cold_stats.txt"
        printf '%s\t%s\tfailed' "$M" "$NB" >> "$TSV"
        for k in $(seq 4 37); do printf '\tNA' >> "$TSV"; done
        echo >> "$TSV"
        continue
    fi
    if [ -n "$PACKS" ]; then   # the cold pack, before the edit below changes it
        rm -rf "$PACKS/w$M"
        cp -R "$D/pack" "$PACKS/w$M"
    fi
    cold=$(awk '{ print $1 }' "$D/cold.txt" | median)
    bpeak=$(awk '{ print $2 }' "$D/cold.txt" | median)
    S=$D/cold_stats.txt
    line=$(grep '^combinations found in leaf cells:' "$S" || true)
    found=$(echo "$line" | sed -n 's/^combinations found in leaf cells: \([0-9]*\), pipelines built: \([0-9]*\) (largest composite \([0-9]*\) layers, largest leaf-cell overlap \([0-9]*\).*/\1 \2 \3 \4/p')
    set -- $found NA NA NA NA
    combos=$1 pipes=$2 largest=$3 overlap=$4
    gl=$(stat_field "$S" '^glslang ' 2); va=$(stat_field "$S" '^validation ' 2)
    shaders=$(sed -n 's/^shaders: \([0-9]*\) .*/\1/p' "$S")
    # ---- pack ----
    pack_mb=$(du -sb "$D/pack" | awk '{ printf "%.1f", $1 / 1e6 }')
    tr -d ' \n' < "$D/pack/manifest.json" > "$D/manifest.flat"
    ntex=$(grep -o '"file":"textures/[^"]*"' "$D/manifest.flat" | wc -l)
    narr=$(grep -o '"binding":[0-9]*,"layer"' "$D/manifest.flat" | sort -u | wc -l)
    # ---- one-material edit: b0_m1's colour constant, warm cache ----
    # (material index 2: the base, b0_m0, b0_m1)
    with=$(grep -o '"materials":\[[0-9,]*\]' "$D/manifest.flat" | grep -c '[[,]2[],]' || true)
    : > "$D/edit.txt"
    r=0
    while [ $r -lt "$REPS" ]; do
        # a different constant each time, so every rebuild has one edit
        awk -v v="0.9$r$r" '/^material b0_m1 /{ inm = 1 }
            inm && /vec3\(/ && !done { sub(/vec3\([0-9.]+/, "vec3(" v); done = 1 }
            /^}/{ inm = 0 } { print }' "$D/world/scene.sg" > "$D/world/scene.sg.new"
        differ "$D/world/scene.sg" "$D/world/scene.sg.new" "scale_world.sh: the edit changed nothing"
        mv "$D/world/scene.sg.new" "$D/world/scene.sg"
        log "$M materials: one-material edit, rebuild ($((r + 1))/$REPS)"
        measure "$D/edit_stats.txt" "$SPLATC" build "$D/world/scene.sg" -o "$D/pack" -j 2 \
            --cache "$D/cache" --stats >> "$D/edit.txt"
        r=$((r + 1))
    done
    edit=$(awk '{ print $1 }' "$D/edit.txt" | median)
    recompiled=$(sed -n 's/^shaders: [0-9]* ([0-9]* from cache, \([0-9]*\) compiled)/\1/p' "$D/edit_stats.txt")
    # ---- first picture: screen, screen with async pipelines, forward ----
    : > "$D/vpeak.txt"
    VIEWS="screen screen_warm screen_async forward"
    [ "$NOVIEW" = yes ] && { VIEWS=""; t_screen=NA t_screen_warm=NA t_screen_async=NA t_forward=NA; }
    for v in $VIEWS; do
        case $v in
        screen|screen_warm) args="--shading screen --async-pipelines off" ;;
        screen_async) args="--shading screen --async-pipelines on" ;;
        forward) args="--shading forward" ;;
        esac
        : > "$D/view_$v.txt"
        r=0
        while [ $r -lt "$REPS" ]; do
            log "$M materials: first picture $v $SIZE ($((r + 1))/$REPS)"
            # shellcheck disable=SC2086
            # cold: a fresh Mesa shader disk cache and pipeline cache file
            # (lavapipe keeps what it compiled in ~/.cache/mesa_shader_cache:
            # a second run of the same pack would find it there); warm: the
            # caches the screen run before it left
            c=$D/caches/$v.$r
            [ "$v" = screen_warm ] && c=$D/caches/screen.$r
            mkdir -p "$c"
            res=$(measure "$D/view_$v.log" env MESA_SHADER_CACHE_DIR="$c/mesa" \
                SPLAT_PIPELINE_CACHE="$c/pipelines.bin" timeout "$VT" "$VIEW" "$D/pack" \
                --headless --size "$SIZE" $args -o "$D/$v.png")
            case $res in
            "NA NA 124") echo "timeout" >> "$D/view_$v.txt" ;;
            NA*) echo "failed" >> "$D/view_$v.txt"; sed 's/^/  /' "$D/view_$v.log" | tail -5 ;;
            *) echo "$res" | awk '{ print $1 }' >> "$D/view_$v.txt"
               echo "$res" | awk '{ print $2 }' >> "$D/vpeak.txt" ;;
            esac
            r=$((r + 1))
        done
        if grep -q timeout "$D/view_$v.txt"; then eval "t_$v=timeout"
        elif grep -q failed "$D/view_$v.txt"; then eval "t_$v=failed"
        else eval "t_$v=$(median < "$D/view_$v.txt")"; fi
    done
    vpeak=$(sort -g "$D/vpeak.txt" | tail -1)
    # ---- steady frame: the same camera, held still, both paths ----
    st_screen_ms=NA st_screen_lay=NA st_screen_need=NA st_screen_spp=NA st_uber=NA
    st_fwd_ms=NA st_fwd_lay=NA st_fwd_need=NA st_fwd_spp=NA st_peak_mb=NA
    if [ "$NOVIEW" = no ] && [ "$SFRAMES" -gt 0 ]; then
        log "$M materials: steady frame $SIZE, screen and forward ($SWARM + $SFRAMES frames)"
        c=$D/caches/steady
        mkdir -p "$c"
        rm -f "$D/steady.csv"
        res=$(measure "$D/steady.log" env MESA_SHADER_CACHE_DIR="$c/mesa" \
            SPLAT_PIPELINE_CACHE="$c/pipelines.bin" timeout "$STO" "$SB" render \
            --pack "$D/pack" --scene "w$M" --path preset --start-preset overview \
            --variant screen=screen --variant forward=composite --frames "$SFRAMES" \
            --warmup "$SWARM" --size "$SIZE" --csv "$D/steady.csv")
        case $res in
        NA*) log "$M materials: splatbench render failed ($res)"; tail -5 "$D/steady.log" | sed 's/^/  /' ;;
        *) st_peak_mb=$(echo "$res" | awk '{ printf "%.0f", $2 / 1024 }')
           st_screen_ms=$(csv_field "$D/steady.csv" screen gpu_med_ms)
           st_screen_lay=$(csv_field "$D/steady.csv" screen layers_evaluated)
           st_screen_need=$(csv_field "$D/steady.csv" screen layers_needed)
           st_screen_spp=$(csv_field "$D/steady.csv" screen samples_per_px)
           st_uber=$(csv_field "$D/steady.csv" screen tiles_uber)
           st_fwd_ms=$(csv_field "$D/steady.csv" forward gpu_med_ms)
           st_fwd_lay=$(csv_field "$D/steady.csv" forward layers_evaluated)
           st_fwd_need=$(csv_field "$D/steady.csv" forward layers_needed)
           st_fwd_spp=$(csv_field "$D/steady.csv" forward samples_per_px)
           cp "$D/steady.csv" "$OUT/scale_world_m${M}_steady.csv" ;;
        esac
    fi
    vpeak_mb=$( [ -n "$vpeak" ] && echo "$vpeak" | awk '{ printf "%.0f", $1 / 1024 }' || echo NA)
    bpeak_mb=$(echo "$bpeak" | awk '/^[0-9.]+$/ { printf "%.0f", $1 / 1024; next } { print "NA" }')
    # shellcheck disable=SC2154
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' \
        "$M" "$NB" "$combos" "$pipes" "$largest" "$overlap" "$cold" "$bpeak_mb" "$gl" "$va" \
        "$edit" "$recompiled" "$shaders" "$with" "$pack_mb" "$ntex" "$narr" \
        "$t_screen" "$t_screen_async" "$t_forward" "$vpeak_mb" "$SIZE" "$HF" "$REPS" \
        "$t_screen_warm" "$st_screen_ms" "$st_screen_lay" "$st_screen_need" "$st_screen_spp" \
        "$st_uber" "$st_fwd_ms" "$st_fwd_lay" "$st_fwd_need" "$st_fwd_spp" "$st_peak_mb" \
        overview "$SFRAMES" >> "$TSV"
    log "$M materials: $(tail -1 "$TSV")"
    # the pictures stay (small); the packs go unless kept
    for v in screen screen_async forward; do
        [ -f "$D/$v.png" ] && cp "$D/$v.png" "$OUT/scale_world_m${M}_$v.png"
    done
    [ "$KEEP" = yes ] || rm -rf "$D/pack" "$D/cache" "$D/caches" "$D/world/textures"
done

# ---- the table ----
{
    echo "| materials | combinations (leaf) / pipelines | largest composite / leaf overlap (layers) | cold build -j 2 | peak RSS build | edit rebuild (shaders recompiled / combos with it) | pack | textures / arrays | first picture $SIZE screen | screen, warm caches | screen, async pipelines | forward | peak RSS viewer |"
    echo "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    awk -F'\t' 'NR > 1 {
        printf "| %s | %s / %s | %s / %s | %s s | %s MB | %s s (%s / %s) | %s MB | %s / %s | %s | %s | %s | %s | %s MB |\n",
            $1, $3, $4, $5, $6, $7, $8, $11, $12, $14, $15, $16, $17,
            ($18 ~ /^[0-9.]+$/ ? $18 " s" : $18), ($25 ~ /^[0-9.]+$/ ? $25 " s" : $25),
            ($19 ~ /^[0-9.]+$/ ? $19 " s" : $19),
            ($20 ~ /^[0-9.]+$/ ? $20 " s" : $20), $21 }' "$TSV"
    echo
    echo "Steady frame, $SIZE, camera 'overview' held still (splatbench render --path preset, $SFRAMES frame(s) after $SWARM untimed; GPU ms: timestamp median; forward: per fragment shaded):"
    echo
    echo "| materials | screen GPU ms | screen layers evaluated / needed per px | screen samples/px | über-shader tiles | forward GPU ms | forward layers evaluated / needed | forward samples | splatbench peak RSS |"
    echo "|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    awk -F'\t' 'NR > 1 {
        printf "| %s | %s | %s / %s | %s | %s | %s | %s / %s | %s | %s MB |\n",
            $1, $26, $27, $28, $29, $30, $31, $32, $33, $34, $35 }' "$TSV"
    echo
    echo "gen_world --textures B 8 $HF 16 (B biomes x 8 materials, a texture each, over a base);"
    echo "$(nproc) CPUs, load average at the start: $LOAD0, at the end: $(cut -d' ' -f1-3 /proc/loadavg); medians of $REPS run(s)"
    echo "(the TSV's glslang_s and validation_s: the last cold build's --stats phases)."
} > "$OUT/scale_world.md"
cat "$OUT/scale_world.md"

if command -v gnuplot >/dev/null 2>&1; then
    log "plots"
    noview=""
    [ "$NOVIEW" = yes ] && noview="noview = 1"
    (cd "$OUT" && gnuplot -e "$noview" "$REPO/tests/bench/scale_world.gp") || echo "scale_world.sh: gnuplot failed (plots skipped)"
else
    log "gnuplot not installed: plots skipped"
fi
[ "$KEEP" = yes ] || rm -rf "$W"
log "done: $TSV"
