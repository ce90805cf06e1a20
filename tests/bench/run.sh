#!/bin/sh
# run.sh — the speed–accuracy benchmark (`make bench`,
# `make bench-smoke`, CTest bench.smoke).
#
#   sh tests/bench/run.sh BUILD_DIR [--smoke] [--quick] [--out DIR]
#                         [--frames N] [--keep-work] [--only scale_world|look]
#
# Writes into DIR (default out/bench): compile.csv (per scene: phases of
# `splatc build --stats`, cold and warm, peak memory; colorado_geotiff:
# the same scene imported from GeoTIFFs through GDAL), scale_hf.csv
# (analysis vs heightfield texels 1x/4x/16x), scale_mat.csv (compile phases
# vs material count 4/8/15/30), render.csv (splatbench: GPU/CPU ms per frame
# and error vs the reference of the same frames, one row per variant),
# sparse.txt / quadtree.txt (figures printed by the sparse and quadtree
# tests), summary.md (ratios and targets, met or missed) and, when gnuplot
# is installed, PNG plots.  Every CSV row names the Vulkan device.
#
# Runs from a build folder carried to another machine: only BUILD_DIR's
# compiler/splatc, runtime/splatview and tests/splatbench are needed (plus
# the repository's examples, graphs and nodes); the caller sets the Vulkan
# loader up (VK_DRIVER_FILES / VK_ICD_FILENAMES, LD_LIBRARY_PATH).
# --smoke: examples/minimal only, tiny frames, a minute at most.
# --quick: the full set of comparisons with fewer frames (a fast GPU run).
# --frames N: frames per camera path (medians over them; default 4, smoke 2).
# --keep-work: keep OUT/work (packs, scene mirrors, the last frame of every
# variant as RGBA32F); by default it is deleted at the end.
# The group scale_world (tests/bench/scale_world.sh: gen_world's textured
# worlds of 8, 32, 64, 128 and 256 materials, one table: combinations,
# largest composite, cold and one-material-edit builds, pack, first picture
# on both paths, steady GPU ms and layers and samples per pixel on the same
# camera, peak memory; scale_world.tsv, scale_world.md, scale_world.png)
# runs last, scaled down to 8 and 16 materials in --smoke; --only
# scale_world runs it alone (40 minutes and more on lavapipe; its H100
# columns: tests/bench/scale_world_gpu.sh).
# --only look: the group `look` alone (colorado's look additions on and
# off, render.csv; about 15 minutes on lavapipe with --frames 2).
set -eu
# must, differ, to: statuses checked (no pipe without pipefail)
. "$(dirname "$0")/../lib.sh"

if [ $# -lt 1 ]; then
    echo "usage: sh tests/bench/run.sh BUILD_DIR [--smoke] [--quick] [--out DIR]" >&2
    exit 2
fi
B=$(cd "$1" && pwd)
shift
MODE=full
OUT=out/bench
NFRAMES=""
KEEP=no
ONLY=""
while [ $# -gt 0 ]; do
    case $1 in
    --only) ONLY=$2; shift ;;
    --smoke) MODE=smoke ;;
    --quick) MODE=quick ;;
    --out) OUT=$2; shift ;;
    --frames) NFRAMES=$2; shift ;;
    --keep-work) KEEP=yes ;;
    *) echo "run.sh: unknown option '$1'" >&2; exit 2 ;;
    esac
    shift
done
REPO=$(cd "$(dirname "$0")/../.." && pwd)
# scale_world.sh's options: the mode, the output folder, --keep-work
scale_world() {
    set -- "$B" --out "$OUT"
    [ "$MODE" = smoke ] && set -- "$@" --smoke
    [ "$KEEP" = yes ] && set -- "$@" --keep-work
    sh "$REPO/tests/bench/scale_world.sh" "$@"
}
case $ONLY in
"") ;;
scale_world) scale_world; exit 0 ;;
look) ;;
*) echo "run.sh: --only expects scale_world or look, found '$ONLY'" >&2; exit 2 ;;
esac
SPLATC=$B/compiler/splatc
BENCH=$B/tests/splatbench
for t in "$SPLATC" "$BENCH"; do
    [ -x "$t" ] || { echo "run.sh: $t is not built (cmake --build $B)" >&2; exit 1; }
done
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
W=$OUT/work
rm -rf "$W" "$OUT"/*.csv "$OUT"/*.png "$OUT"/*.dat "$OUT"/summary.md
mkdir -p "$W"
cd "$REPO"
START=$(date +%s)
log() { echo "[bench $(( $(date +%s) - START ))s] $*"; }

# Peak memory of a command (KB) through GNU time when it is installed.
TIME=""
if [ -x /usr/bin/time ] && /usr/bin/time -f %M true >/dev/null 2>&1; then TIME=/usr/bin/time; fi

case $MODE in
smoke) FRAMES=2; WARM=1; SIZES=320x180; PATHS=ground; SCENES=minimal ;;
quick) FRAMES=3; WARM=1; SIZES="1280x720 1920x1080"; PATHS="ground topdown grazing"; SCENES="minimal colorado" ;;
*)     FRAMES=4; WARM=1; SIZES="1280x720 1920x1080"; PATHS="ground topdown grazing"; SCENES="minimal colorado" ;;
esac
[ -n "$NFRAMES" ] && FRAMES=$NFRAMES

# ---- mirrors: a scene variant lives in ROOT/examples/NAME with the
# example's files linked, ROOT/nodes linked and ROOT/graphs a folder of
# links, so a variant may replace one graph file (imports search the
# nearest folder above the scene that has nodes/).
mirror() {  # ROOT
    mkdir -p "$1/graphs" "$1/examples"
    [ -e "$1/nodes" ] || ln -s "$REPO/nodes" "$1/nodes"
    for f in "$REPO"/graphs/*; do
        [ -e "$1/graphs/$(basename "$f")" ] || ln -s "$f" "$1/graphs/"
    done
}
mirror_scene() {  # ROOT EXAMPLE NAME  -> ROOT/examples/NAME (scene.sg not linked)
    d=$1/examples/$3
    mkdir -p "$d"
    for f in "$REPO/examples/$2"/*; do
        [ "$(basename "$f")" = scene.sg ] || ln -sf "$f" "$d/"
    done
    echo "$d"
}

# ---- splatc build with --stats into a CSV row ------------------------------
# build_row LABEL SCENE PACK CACHEARGS...  (appends to $CSV; prints the pack)
COMPILE_HEAD="device,scene,label,texels,materials,combinations,load_s,analysis_s,codegen_s,glslang_s,validation_s,write_s,total_s,wall_s,peak_mb,per_combo_ms,analysis_ns_per_texel"
build_row() {
    label=$1; scene=$2; pack=$3; shift 3
    st=$W/stats.txt
    t0=$(date +%s.%N)
    if [ -n "$TIME" ]; then
        $TIME -f "PEAKKB %M" -o "$W/time.txt" "$SPLATC" build "$scene" -o "$pack" -j 2 --stats "$@" > "$st"
    else
        "$SPLATC" build "$scene" -o "$pack" -j 2 --stats "$@" > "$st"; echo "PEAKKB NA" > "$W/time.txt"
    fi
    t1=$(date +%s.%N)
    if [ "$label" = warm ]; then
        # "nothing changed" is what a user waits for without --stats (which
        # re-runs the cheap analysis to print its report): time that
        t0=$(date +%s.%N)
        "$SPLATC" build "$scene" -o "$pack" -j 2 "$@" > /dev/null
        t1=$(date +%s.%N)
    fi
    awk -v dev="$DEVICE" -v label="$label" -v name="$(basename "$(dirname "$scene")")" \
        -v wall="$(echo "$t1 $t0" | awk '{printf "%.3f", $1 - $2}')" \
        -v peak="$(awk '{print $2}' "$W/time.txt")" '
        /^scene /{ m = $3; split($0, a, "heightfield "); split(a[2], b, " "); tex = b[1] * b[3] }
        /^load /{ load = $2 } /^analysis /{ an = $2 } /^compose\+codegen/{ cg = $2 }
        /^glslang /{ gl = $2 } /^validation /{ va = $2 } /^write /{ wr = $2 } /^total /{ tot = $2 }
        /^combinations: [0-9]+ \(/{ nc = $2 }
        /^analysis time:/{ anms = $3 }
        END {
            pk = peak == "NA" ? "NA" : sprintf("%.1f", peak / 1024)
            # a pack that is up to date prints no scene line: texels unknown
            printf "\"%s\",%s,%s,%s,%s,%d,%s,%s,%s,%s,%s,%s,%s,%s,%s,%.2f,%s\n", dev, name, label,
                   tex ? tex : "", tex ? m : "", nc, load, an, cg, gl, va, wr, tot, wall, pk,
                   nc ? 1000 * (cg + gl + va) / nc : 0,
                   tex && anms != "" ? sprintf("%.2f", anms * 1e6 / tex) : ""
        }' "$st" >> "$CSV"
}

# The device name: one tiny render of the minimal pack.
log "device"
"$SPLATC" build examples/minimal/scene.sg -o "$W/minimal" --flat --cache "$W/cache" >/dev/null
to "$W/device.csv" "$BENCH" render --pack "$W/minimal" --variant c=composite --size 64x36 --frames 1 \
    --warmup 0
DEVICE=$(awk -F'"' 'NR == 2 { print $2 }' "$W/device.csv")
[ -n "$DEVICE" ] || { echo "run.sh: no Vulkan device answers" >&2; exit 1; }
log "device: $DEVICE"

# ---- (a) compile figures: every scene cold (empty cache) and warm --------
# (--only look: none of (a); its pack is built with the renders below)
if [ "$ONLY" != look ]; then
CSV=$OUT/compile.csv
echo "$COMPILE_HEAD" > "$CSV"
case $MODE in smoke) CSCENES=minimal ;; *) CSCENES="minimal colorado billingsley" ;; esac
for s in $CSCENES; do
    log "compile $s (cold, warm)"
    rm -rf "$W/cache-$s" "$W/pack-$s"
    build_row cold "examples/$s/scene.sg" "$W/pack-$s" --cache "$W/cache-$s"
    build_row warm "examples/$s/scene.sg" "$W/pack-$s" --cache "$W/cache-$s"
    # the packs the renders use: with the flat variants (branching benchmark)
    "$SPLATC" build "examples/$s/scene.sg" -o "$W/$s" -j 2 --flat --cache "$W/cache-$s" >/dev/null
done

# ---- (a) the GeoTIFF import: colorado's twin (tests/world/colorado_twin.sh)
# through GDAL, heightfield and masks as GeoTIFFs written by gen_geotiff ----
GEN=$B/tests/gen_geotiff
if [ "$MODE" != smoke ] && [ -x "$GEN" ]; then
    log "compile colorado_geotiff (cold)"
    T=$W/colorado_geotiff
    mkdir -p "$T/masks"
    "$GEN" examples/colorado/trinidad.png "$T/trinidad.tif" 176473.5 111212.6 2962.242 1358.652
    for m in field_wheat field_plowed field_fallow road; do
        "$GEN" examples/colorado/masks/$m.png "$T/masks/$m.tif" 176473.5 111212.6
    done
    sed -e 's/"trinidad.png"/"trinidad.tif"/' \
        -e 's/^\( *painted [a-z_]* *= *"masks\/[a-z_]*\)\.png"/\1.tif"/' \
        -e '/^ *size = /d' -e '/^ *max_height = /d' -e '/^ *height_offset = /d' \
        examples/colorado/scene.sg > "$T/scene.sg"
    export SPLATC_PATH="$REPO"
    build_row cold "$T/scene.sg" "$W/pack-colorado_geotiff" --cache "$W/cache-colorado_geotiff"
    unset SPLATC_PATH
fi

# ---- (a) a painted mask at its own resolution: 1 px/m over 10 x 10 km of
# colorado, 10^8 texels (tests/world/test_placed.c writes the inputs) --------
PLACED=$B/tests/test_placed
if [ "$MODE" != smoke ] && [ -x "$PLACED" ]; then
    log "compile placed_1e8 (cold)"
    T=$W/placed_1e8
    mkdir -p "$T"
    "$PLACED" --inputs "$T"
    export SPLATC_PATH="$REPO"
    build_row cold "$T/scene.sg" "$W/pack-placed" --no-cache
    unset SPLATC_PATH
    rm -rf "$W/pack-placed" "$T/road.tif"
fi

# ---- (a) scaling with heightfield texels: 1x, 4x, 16x ---------------------
CSV=$OUT/scale_hf.csv
echo "$COMPILE_HEAD" > "$CSV"
case $MODE in smoke) HS=minimal; KS="1 2" ;; *) HS=colorado; KS="1 2 4" ;; esac
R=$W/mirror-hf
mirror "$R"
hf=$(awk -F'"' '/^[ \t]*heightfield[ \t]*=/{ print $2; exit }' "examples/$HS/scene.sg")
for k in $KS; do
    log "scale heightfield $HS x$((k * k))"
    d=$(mirror_scene "$R" "$HS" "${HS}_x$((k * k))")
    if [ "$k" = 1 ]; then
        cp "examples/$HS/scene.sg" "$d/scene.sg"
    else
        "$BENCH" upscale "examples/$HS/$hf" "$k" "$d/hf.r16" > "$W/upscale.txt"
        size=$(awk '{ print $2, $4 }' "$W/upscale.txt")
        sed_masks=""
        for m in $(awk -F'"' '/^[ \t]*painted[ \t]/{ print $2 }' "examples/$HS/scene.sg"); do
            mkdir -p "$d/$(dirname "$m").scaled"
            "$BENCH" upscale "examples/$HS/$m" "$k" "$d/$(dirname "$m").scaled/$(basename "$m")" >/dev/null
            sed_masks="$sed_masks -e s|\"$m\"|\"$(dirname "$m").scaled/$(basename "$m")\"|"
        done
        # shellcheck disable=SC2086
        sed -e "s|heightfield *= *\"$hf\"|heightfield = \"hf.r16\"\n    heightfield_size = $size|" \
            -e "s|^\([ \t]*cell\) *= *\([0-9]*\)|\1 = \2|" $sed_masks \
            "examples/$HS/scene.sg" > "$d/scene.sg"
    fi
    # three builds each: the machine is shared, the smallest analysis time
    # of the three is the one least disturbed (summary.sh takes it)
    for rep in 1 2 3; do
        rm -rf "$W/pack-hf"   # an up-to-date pack would skip the analysis
        build_row "x$((k * k))" "$d/scene.sg" "$W/pack-hf" --cache "$W/cache-$HS"
        [ "$MODE" = smoke ] && break
    done
done
rm -rf "$W/pack-hf"

# ---- (a) scaling with the material count: 4, 8, 15, 30 (colorado's stack;
# 30 = the 15 twice, the copies renamed) -------------------------------------
CSV=$OUT/scale_mat.csv
echo "$COMPILE_HEAD" > "$CSV"
if [ "$MODE" != smoke ]; then
    R=$W/mirror-mat
    mirror "$R"
    stack=$(awk '/materials *=/,/\]/' examples/colorado/scene.sg | tr -d '[],' | sed 's/materials *=//' | tr -s ' \n' ' ')
    for g in $stack; do   # renamed copies: material NAME -> NAME_b
        sed "s/^material $g\b/material ${g}_b/" "graphs/$g.sg" > "$R/graphs/${g}_b.sg"
    done
    for n in 4 8 15 30; do
        log "scale materials $n"
        d=$(mirror_scene "$R" colorado "colorado_m$n")
        list=$(echo $stack $(for g in $stack; do echo "${g}_b"; done) | tr ' ' '\n' | head -n $n | tr '\n' ' ')
        imports=$(for g in $list; do echo "import \"graphs/$g.sg\""; done)
        awk -v imports="$imports" -v list="$(echo $list | sed 's/ /, /g')" '
            /^import "graphs\//{ next }
            /^import "nodes\/compositors.sg"/{ print; print imports; next }
            /materials *=/{ skip = 1; print "    materials = [" list "]" }
            skip { if (/\]/) skip = 0; next }
            { print }' examples/colorado/scene.sg > "$d/scene.sg"
        build_row "m$n" "$d/scene.sg" "$W/pack-mat" --no-cache
    done
    rm -rf "$W/pack-mat"
fi
fi   # --only look

# ---- compositor and knob packs ------------------------------------------------
# compositor variants: the scene with another `compositor =`
comp_pack() {  # SCENE COMPOSITOR -> pack dir
    R=$W/mirror-comp
    mirror "$R"
    d=$(mirror_scene "$R" "$1" "$1_$2")
    sed -e "s/compositor *= *[a-z_]*/compositor = $2/" \
        -e 's|^import "nodes/compositors.sg"|import "nodes/compositors.sg"\nimport "nodes/compositors_extra.sg"\nimport "nodes/stochastic.sg"\nimport "nodes/height_softmax.sg"|' \
        "examples/$1/scene.sg" > "$d/scene.sg"
    "$SPLATC" build "$d/scene.sg" -o "$W/$1_$2" -j 2 --cache "$W/cache-$1" >/dev/null
    echo "$W/$1_$2"
}
# cliffs_pack COMPOSITOR OUT -> OUT: tests/bench/cliffs (Far Cry 5's dear
# cliff surfaces over cheap masks) on colorado's terrain, with COMPOSITOR
cliffs_pack() {
    R=$W/mirror-cliffs
    mirror "$R"
    cp "$REPO/tests/bench/cliffs/cliffs.sg" "$R/graphs/cliffs.sg"
    d=$(mirror_scene "$R" colorado cliffs)
    sed -e "s/compositor *= *[a-z_]*/compositor = $1/" "$REPO/tests/bench/cliffs/scene.sg" > "$d/scene.sg"
    "$SPLATC" build "$d/scene.sg" -o "$2" -j 2 --cache "$W/cache-cliffs" -I "$R" >/dev/null
    echo "$2"
}
# look_pack SCENE LABEL SED... -> pack dir: the scene with node-library
# files edited, each SED "FILE:SCRIPT" (nodes/FILE.sg through sed SCRIPT),
# so a look addition (issue 31) is switched off in whatever graphs use it
# (group look)
look_pack() {
    R=$W/mirror-look-$2
    mirror "$R"
    rm -f "$R/nodes"
    mkdir -p "$R/nodes"
    for f in "$REPO"/nodes/*; do ln -sf "$f" "$R/nodes/"; done
    scene=$1; label=$2; shift 2
    for e in "$@"; do
        f=${e%%:*}
        rm -f "$R/nodes/$f.sg"
        sed -e "${e#*:}" "nodes/$f.sg" > "$R/nodes/$f.sg"
        differ "nodes/$f.sg" "$R/nodes/$f.sg" "run.sh: look $label: the edit does not change nodes/$f.sg"
    done
    d=$(mirror_scene "$R" "$scene" "$scene")
    cp "examples/$scene/scene.sg" "$d/scene.sg"
    "$SPLATC" build "$d/scene.sg" -o "$W/${scene}_look_$label" -j 2 --cache "$W/cache-$scene" -I "$R" >/dev/null
    echo "$W/${scene}_look_$label"
}
# the look additions' off switches (nodes/detile.sg, variation.sg, cavity.sg)
LOOK_PLAIN='detile:s/: hex_tile { tex = tex, uv = \([a-z]*\)\.out, sharpness = sharpness }/: sample { tex = tex, uv = \1.out }/;s/b = far_amount }/b = 0.0 }/'
LOOK_HEXNEAR='detile:s/b = far_amount }/b = 0.0 }/'
LOOK_NOMACRO='variation:s/out vec3 out = r.out/out vec3 out = albedo/'
LOOK_NOCAVITY='cavity:s/out vec3 out = s.out/out vec3 out = albedo/'
# the footprint filtering (nodes/footprint.sg): aa_* ramps with no widening
# (the plain ramps: fwidth and the neighbours' normal gathers go dead) and
# aa_footprint 1 mm (aa_coverage 1, aa_line the sharp band: graphs/road.sg)
LOOK_NOFOOTPRINT='footprint:s/node fc  : mul { a = fs.out, b = cap.out }/node fc  : mul { a = 0.0, b = cap.out }/;s/node fpn : max { a = fpm.out, b = 0.001 }/node fpn : max { a = 0.0, b = 0.001 }/'

# graph knob variants: one graph file with a node type replaced
KNOB_BUILD_ARGS=""
# knob_pack SCENE LABEL GRAPH GRAPH-SED [SCENE-SED] -> pack dir: the scene
# with graphs/GRAPH.sg edited by the sed script (GRAPH "" for none) and the
# scene file by SCENE-SED
knob_pack() {
    R=$W/mirror-knob-$2
    mirror "$R"
    if [ -n "$3" ]; then
        rm -f "$R/graphs/$3.sg"
        sed -e "$4" "graphs/$3.sg" > "$R/graphs/$3.sg"
        differ "graphs/$3.sg" "$R/graphs/$3.sg" "run.sh: knob $2: the edit does not change graphs/$3.sg"
    fi
    d=$(mirror_scene "$R" "$1" "$1")
    sed -e "${5:-}" "examples/$1/scene.sg" > "$d/scene.sg"
    # -I first: imports search -I folders before the current folder (REPO)
    "$SPLATC" build "$d/scene.sg" -o "$W/$1_knob_$2" -j 2 --cache "$W/cache-$1" -I "$R" $KNOB_BUILD_ARGS >/dev/null
    # the variant must differ from the scene's own pack, or the knob is void
    # (a warning: both manifests exist, the builds above succeeded)
    if cmp -s "$W/$1_knob_$2/manifest.json" "$W/$1/manifest.json"; then
        echo "run.sh: warning: knob $2 did not change $1's pack" >&2
    fi
    echo "$W/$1_knob_$2"
}

# ---- (b)-(d) renders --------------------------------------------------------------
CSV=$OUT/render.csv
rm -f "$CSV"
render() {  # GROUP SCENE PATH SIZE VARIANT... (first variant = reference)
    group=$1; scene=$2; path=$3; size=$4; shift 4
    log "render $group $scene $path $size"
    args=""
    for v in "$@"; do args="$args --variant $v"; done
    preset=""
    [ "$scene" = colorado ] && [ "$path" = ground ] && preset="--start-preset ${PRESET:-trinidad}"
    [ "$scene" = billingsley ] && [ "$path" = ground ] && preset="--start-preset ground"
    [ -n "${GROUND_START:-}" ] && preset="--start $GROUND_START"
    mkdir -p "$W/img/$group-$scene-$path-$size"
    # shellcheck disable=SC2086
    "$BENCH" render --pack "$W/$scene" $args --path "$path" $preset --size "$size" \
        --frames "$FRAMES" --warmup "$WARM" --scene "$scene" --view "${VIEW:-final}" \
        --save "$W/img/$group-$scene-$path-$size" > "$W/render.txt"
    awk -v g="$group" -F, 'NR > 1 { print g "," $0 }' "$W/render.txt" >> "$CSV.body"
}
# the look additions (issue 31), each switched off in the node library
# against the scene as it stands (everything on), same frames: detile
# as a plain top-down read (1 sample) and hex-tiled near only (3), no
# macro variation, no cavity darkening, no footprint filtering (masks
# and the road's coverage), all of them off; and the height_softmax
# compositor.  samples_per_px and GPU ms side by side.
look_group() {
    lp=$(look_pack colorado plain "$LOOK_PLAIN")
    lh=$(look_pack colorado hexnear "$LOOK_HEXNEAR")
    lm=$(look_pack colorado nomacro "$LOOK_NOMACRO")
    lc=$(look_pack colorado nocavity "$LOOK_NOCAVITY")
    lf=$(look_pack colorado nofootprint "$LOOK_NOFOOTPRINT")
    lo=$(look_pack colorado off "$LOOK_PLAIN" "$LOOK_NOMACRO" "$LOOK_NOCAVITY" "$LOOK_NOFOOTPRINT")
    hs=$(comp_pack colorado height_softmax)
    for p in ground topdown; do
        render look colorado "$p" 1280x720 on=composite "detile_plain=composite,pack=$lp" \
            "detile_hex_near=composite,pack=$lh" "no_macro=composite,pack=$lm" \
            "no_cavity=composite,pack=$lc" "no_footprint=composite,pack=$lf" \
            "all_off=composite,pack=$lo" "height_softmax=composite,pack=$hs" on_screen=screen \
            "no_footprint_screen=screen,pack=$lf" "all_off_screen=screen,pack=$lo" \
            "height_softmax_screen=screen,pack=$hs"
    done
}
rm -f "$CSV.body"
if [ "$ONLY" = look ]; then
    log "only look: colorado"
    "$SPLATC" build examples/colorado/scene.sg -o "$W/colorado" -j 2 --cache "$W/cache-colorado" >/dev/null
    look_group
    { echo "group,$(sed -n 1p "$W/render.txt")"; cat "$CSV.body"; } > "$CSV"
    rm -f "$CSV.body"
    [ "$KEEP" = yes ] || rm -rf "$W"
    log "done: $CSV"
    exit 0
fi
for s in $SCENES; do
    for size in $SIZES; do
        for p in $PATHS; do
            # 1080p: the ground path only (lavapipe time)
            [ "$size" = 1920x1080 ] && [ "$p" != ground ] && [ "$MODE" = full ] && continue
            render main "$s" "$p" "$size" ref=multipass composite=composite uber=uber flat=flat
        done
    done
done
# (e) screen-space shading against forward on the same frames: the
# runtime's choice of depth for the device (screen), both depths, the
# pixels sorted by layer set (--pixel-sort on), and the über-shader on
# every tile (the classification's soundness reference)
for s in $SCENES; do
    for size in $SIZES; do
        for p in $PATHS; do
            [ "$size" = 1920x1080 ] && [ "$MODE" = full ] && [ "$p" != ground ] && continue
            render shading "$s" "$p" "$size" forward=composite screen=screen \
                screen_raster=screen_raster screen_raycast=screen_raycast \
                screen_sorted=screen,sort=on screen_uber=screen_uber
        done
    done
done
# (f) preview lighting (issue 16): the GGX sun with the terrain's shadows,
# without them, and the lighting before issue 16, on the same frames
for s in $SCENES; do
    for size in $SIZES; do
        for p in $PATHS; do
            [ "$size" = 1920x1080 ] && [ "$MODE" = full ] && [ "$p" != ground ] && continue
            render lighting "$s" "$p" "$size" lit=composite noshadow=composite,noshadow \
                lambert=lambert,noshadow
        done
    done
done
# (g) undergrowth (issue 12): the ground path (2 m above the terrain and
# moving, so cells enter the disc every frame and are generated) with and
# without it, on both paths; scenes whose materials carry undergrowth
for s in $SCENES; do
    [ "$s" = billingsley ] && continue
    for size in $SIZES; do
        render undergrowth "$s" ground "$size" off=composite on=composite,ug \
            screen_off=screen screen_on=screen,ug
    done
done
if [ "$MODE" = smoke ]; then
    stoch=$(comp_pack minimal stochastic_select)
    render knobs minimal ground 320x180 composite=composite fp16=fp16 sobel=sobel \
        "stochastic=composite,pack=$stoch" lod6=composite,lod=6
    KNOB_BUILD_ARGS="--far-atlas"
    mf=$(knob_pack minimal far "" "")
    KNOB_BUILD_ARGS=""
    render knob_far minimal ground 320x180 "screen=screen,pack=$mf" "far50=screen,far=50,pack=$mf"
    render knob_preview minimal ground 320x180 full=screen half=screen,preview=2
    # the cliffs stack still compiles under both compositors (a full run
    # renders it: group compositor_cliffs)
    cliffs_pack linear_alpha "$W/cliffs" >/dev/null
    cliffs_pack stochastic_select "$W/cliffs_stochastic" >/dev/null
    differ "$W/cliffs/manifest.json" "$W/cliffs_stochastic/manifest.json" \
        "run.sh: the cliffs stack's compositor did not change its pack"
else
    # (c) compositors, against the alpha composite of the same frames
    for s in minimal colorado; do
        hb=$(comp_pack "$s" height_blend)
        st=$(comp_pack "$s" stochastic_select)
        for p in ground topdown; do
            render compositor "$s" "$p" 1280x720 linear_alpha=composite \
                "height_blend=composite,pack=$hb" "stochastic=composite,pack=$st"
        done
    done
    # Billingsley's max-height selection (his scene: masks + linear_alpha)
    # against its multi-pass reference, and stochastic selection on it
    st=$(comp_pack billingsley stochastic_select)
    render compositor billingsley ground 1280x720 ref=multipass max_height=composite \
        "stochastic=composite,pack=$st"
    # Far Cry 5's case for stochastic selection (seed 004): surfaces of 7
    # samples over masks that share one tap, on colorado's terrain; the
    # ground path up Blanca's west flank, where the cliffs blend, and top-down
    cliffs_pack linear_alpha "$W/cliffs" >/dev/null
    cst=$(cliffs_pack stochastic_select "$W/cliffs_stochastic")
    for p in ground topdown; do
        [ "$p" = ground ] && GROUND_START=45000,47087,1,0
        render compositor_cliffs cliffs "$p" 1280x720 linear_alpha=composite \
            "stochastic=composite,pack=$cst" linear_alpha_screen=screen \
            "stochastic_screen=screen,pack=$cst"
        GROUND_START=""
    done
    # (d) knobs: arithmetic precision, normal filter, LOD threshold (the
    # ground path; LOD against the finest threshold measured)
    render knob_precision colorado ground 1280x720 fp32=composite fp16=fp16
    render knob_normal colorado ground 1280x720 cross=composite sobel=sobel
    # normal filters against the exact normal: minimal's scene over an
    # analytic heightfield (splatbench analytic-hf), in the normal view and lit
    R=$W/mirror-analytic
    mirror "$R"
    d=$(mirror_scene "$R" minimal minimal)
    "$BENCH" analytic-hf 257 257 "$d/hf.r16"
    sed 's|heightfield *= *"heightfield.png"|heightfield = "hf.r16"\n    heightfield_size = 257 257|' \
        examples/minimal/scene.sg > "$d/scene.sg"
    "$SPLATC" build "$d/scene.sg" -o "$W/minimal_analytic" -j 2 --cache "$W/cache-minimal" >/dev/null
    for p in ground topdown; do
        VIEW=normal
        render knob_normal_exact_nview minimal "$p" 1280x720 \
            "analytic=analytic,pack=$W/minimal_analytic" "cross=composite,pack=$W/minimal_analytic" \
            "sobel=sobel,pack=$W/minimal_analytic"
        VIEW=final
        render knob_normal_exact minimal "$p" 1280x720 \
            "analytic=analytic,pack=$W/minimal_analytic" "cross=composite,pack=$W/minimal_analytic" \
            "sobel=sobel,pack=$W/minimal_analytic"
    done
    render knob_lod colorado ground 1280x720 lod1=composite,lod=1 lod2=composite,lod=2 \
        lod3=composite,lod=3 lod6=composite,lod=6 lod12=composite,lod=12
    # fBm octaves (forest_floor: texture fBm 2/4/6/8) and texture fBm vs ALU
    # gradient fBm at 4 octaves, against 8 texture octaves; mud's ALU
    # gradient fBm 2/4/8 against 8
    f2=$(knob_pack colorado tfbm2 forest_floor "s/: *texture_fbm4 /: texture_fbm2 /")
    f6=$(knob_pack colorado tfbm6 forest_floor "s/: *texture_fbm4 /: texture_fbm6 /")
    f8=$(knob_pack colorado tfbm8 forest_floor "s/: *texture_fbm4 /: texture_fbm8 /")
    # ALU: 4 octaves of gradient noise on 16 lattice cells per texture
    # repeat (another pattern than the noise texture's: its error is the
    # pattern change, its time the cost of ALU noise vs texture fetches)
    ga=$(knob_pack colorado alu4 forest_floor \
        's|node pat *: *texture_fbm4 {[^}]*}|node puv : mul { a = uv.uv, b = 16.0 }\n    node pat : gradient_fbm4 { p = puv.out }|; s|pat\.out|pat.unorm|g')
    m8=$(knob_pack colorado mud8 mud "s/: *gradient_fbm2 /: gradient_fbm8 /")
    m4=$(knob_pack colorado mud4 mud "s/: *gradient_fbm2 /: gradient_fbm4 /")
    for p in topdown ground; do
        render knob_fbm colorado "$p" 1280x720 "tfbm8=composite,pack=$f8" \
            "tfbm6=composite,pack=$f6" tfbm4=composite "tfbm2=composite,pack=$f2" \
            "alu_gfbm4=composite,pack=$ga"
    done
    render knob_alu_octaves colorado ground 1280x720 "mud_gfbm8=composite,pack=$m8" \
        "mud_gfbm4=composite,pack=$m4" mud_gfbm2=composite
    # steep parallax step counts (rock: 8 steps) on a ground path up the west
    # flank of Blanca Peak (parallax fades out beyond 300 m)
    p4=$(knob_pack colorado par4 rock "s/: *parallax8 /: parallax4 /")
    p16=$(knob_pack colorado par16 rock "s/: *parallax8 /: parallax16 /")
    # steps by view angle and distance with an early exit (nodes/parallax.sg
    # parallax_adaptive; rock.png is 256 texels a repeat), and 16 fixed
    # steps without lazy branches (every step sampled)
    pa=$(knob_pack colorado paradapt rock \
        "s/: *parallax8 { tex = \"textures\/rock.png\"/: parallax_adaptive { texels = 256.0, tex = \"textures\/rock.png\"/")
    KNOB_BUILD_ARGS="--no-lazy"
    p16e=$(knob_pack colorado par16eager rock "s/: *parallax8 /: parallax16 /")
    KNOB_BUILD_ARGS=""
    GROUND_START=45000,47087,1,0
    render knob_parallax colorado ground 1280x720 "parallax16=composite,pack=$p16" \
        parallax8=composite "parallax4=composite,pack=$p4" \
        "parallax16_eager=composite,pack=$p16e" "parallax_adaptive=composite,pack=$pa" \
        "parallax16_screen=screen,pack=$p16" "parallax16_eager_screen=screen,pack=$p16e" \
        "parallax_adaptive_screen=screen,pack=$pa"
    GROUND_START=""
    # distance classes (issue 11, compiler/distance.c) on and off, on both
    # paths, against the über-shader on every tile of the same frames: the
    # ground path up Blanca's west flank (rock's parallax fades out at
    # 300 m: the classes drop it beyond) and top-down
    for p in ground topdown; do
        [ "$p" = ground ] && GROUND_START=45000,47087,1,0
        render distclass colorado "$p" 1280x720 uber=screen_uber screen_on=screen \
            screen_off=screen,distclass=0 forward_on=composite forward_off=composite,distclass=0
        GROUND_START=""
    done
    # painted masks: dense raster (the reference) vs sparse R8, BC4 (the
    # default) and BC4 with every mask limited to quad-tree level 2
    KNOB_BUILD_ARGS="--painted dense"
    pd=$(knob_pack colorado dense "" "")
    KNOB_BUILD_ARGS="--painted r8"
    pr=$(knob_pack colorado r8 "" "")
    KNOB_BUILD_ARGS=""
    pl=$(knob_pack colorado lvl2 "" "" 's|^\([ \t]*painted [a-z_]* *= *"[^"]*"\)[ \t]*$|\1 { max_level = 2 }|')
    render knob_painted colorado ground 1280x720 "dense=composite,pack=$pd" \
        "sparse_r8=composite,pack=$pr" sparse_bc4=composite "bc4_level2=composite,pack=$pl"
    # laziness inside materials (compiler/DESIGN.md 6.1): the same pack with
    # every mix/select/mul side evaluated eagerly (the reference) and with
    # lazy branches (the default), forward and screen-space
    KNOB_BUILD_ARGS="--no-lazy"
    pe=$(knob_pack colorado eager "" "")
    KNOB_BUILD_ARGS=""
    for p in ground topdown; do
        render knob_lazy colorado "$p" 1280x720 "eager=composite,pack=$pe" lazy=composite \
            "eager_screen=screen,pack=$pe" lazy_screen=screen
    done
    look_group
    # the preview scale (issue 33; runtime/upscale.c): depth,
    # classification and shading at 1/2 and 1/4 of the size, upsampled
    # along the depth edges, against full resolution on the same frames
    for p in ground topdown; do
        render knob_preview colorado "$p" 1280x720 full=screen half=screen,preview=2 \
            quarter=screen,preview=4
    done
    # the far atlas (issue 11 part 3; splatc build --far-atlas, one texel per
    # heightfield texel): the screen path with the tiles at least D m away
    # shaded from the atlas, against the same pack's composites on the same
    # frames; tiles_far says how many tiles the atlas took; the same on the
    # forward path (tiles_far: patches wholly beyond D)
    KNOB_BUILD_ARGS="--far-atlas"
    cf=$(knob_pack colorado far "" "")
    KNOB_BUILD_ARGS=""
    for p in topdown ground; do
        render knob_far colorado "$p" 1280x720 "forward=composite,pack=$cf" \
            "forward10k=composite,far=10000,pack=$cf" "forward5k=composite,far=5000,pack=$cf"
        render knob_far colorado "$p" 1280x720 "screen=screen,pack=$cf" \
            "far40k=screen,far=40000,pack=$cf" "far20k=screen,far=20000,pack=$cf" \
            "far10k=screen,far=10000,pack=$cf" "far5k=screen,far=5000,pack=$cf" \
            "far2k=screen,far=2000,pack=$cf"
    done
fi
{ echo "group,$(sed -n 1p "$W/render.txt")"; cat "$CSV.body"; } > "$CSV"
rm -f "$CSV.body"

# ---- the far atlas's bake: the CPU reference against the device ------------------
# (splatc build --far-bake cpu, its --stats phase; splatbench far-bake, the
# device's pipelines and shading) on the same machine, one run each
# (each command's output goes to a file, its status checked, then filtered:
# `splatc build … | sed` under sh passed a crashing splatc)
far_bake() {   # SCENE N
    rm -rf "$W/farbake_cpu"
    to "$W/farbake_cpu.txt" "$SPLATC" build "examples/$1/scene.sg" -o "$W/farbake_cpu" \
        --far-atlas="$2" --far-bake cpu -j 2 --cache "$W/cache-$1" --stats
    s=$(sed -n 's/^far atlas  *\([0-9.]*\)$/\1/p' "$W/farbake_cpu.txt")
    [ -n "$s" ] || fail "splatc build --far-bake cpu --stats printed no 'far atlas' time"
    echo "$1,$2,cpu,,,$s"
    to "$W/farbake_device.txt" "$BENCH" far-bake --pack "$W/$1" --far-atlas "$2" --runs 1
    awk -F, -v s="$1" -v n="$2" 'NR > 2 { print s "," n ",device," $2 "," $3 "," $5 }' \
        "$W/farbake_device.txt"
}
{
    echo "scene,far_atlas_n,bake,combos,compile_s,total_s"
    if [ "$MODE" = smoke ]; then
        far_bake minimal 1
    else
        far_bake colorado 4
        far_bake colorado 1
    fi
} > "$OUT/far_bake.csv"

# ---- the shadow map: the CPU reference against the device --------------------------
# (splatbench shadow: the two marches interleaved, the sun turned a little
# between maps so each is made whole; medians of wall ms per map)
shadow_map() {   # SCENE RUNS
    "$BENCH" shadow --pack "$W/$1" --runs "$2" > "$W/shadow.txt"
    sed -n 's/^shadow map \([a-z]*\) ms: median \([0-9.]*\)  p10 \([0-9.]*\)  p90 \([0-9.]*\)$/\1,\2,\3,\4/p' \
        "$W/shadow.txt" | sed "s/^/$1,/"
}
{
    echo "scene,march,median_ms,p10_ms,p90_ms"
    if [ "$MODE" = smoke ]; then
        shadow_map minimal 2
    else
        shadow_map colorado 5
        shadow_map minimal 5
    fi
} > "$OUT/shadow.csv"

# ---- figures printed by tests: sparse masks, quadtree selection -----------------
: > "$OUT/sparse.txt"
: > "$OUT/quadtree.txt"
if [ "$MODE" != smoke ]; then
    if [ -x "$B/tests/gpu_sparse" ]; then
        log "sparse mask accuracy (gpu_sparse)"
        "$B/tests/gpu_sparse" > "$OUT/sparse.txt" 2>&1 || echo "gpu_sparse failed" >> "$OUT/sparse.txt"
    fi
    if [ -x "$B/tests/test_quadtree" ]; then
        log "quadtree selection (test_quadtree)"
        "$B/tests/test_quadtree" > "$OUT/quadtree.txt" 2>&1 || echo "test_quadtree failed" >> "$OUT/quadtree.txt"
    fi
fi

# ---- scale_world: gen_world's textured worlds, 8..256 materials ------------------
log "scale_world"
scale_world

# ---- summary and plots --------------------------------------------------------------
log "summary"
sh "$REPO/tests/bench/summary.sh" "$OUT" "$MODE" > "$OUT/summary.md"
if [ -f "$OUT/scale_world.md" ]; then
    { echo; echo "## scale_world (tests/bench/scale_world.sh)"; echo; cat "$OUT/scale_world.md"; } >> "$OUT/summary.md"
fi
# plot data: one file per knob/compositor group and view (label, GPU ms,
# mean error) with its Pareto front; the ratio bars; the scaling curves
awk -F, -v dir="$OUT" 'NR > 1 && $1 != "main" {
        f = dir "/knob_" $1 "_" $3 "_" $4 ".dat"
        print $7, $12, $20 > f
    }' "$OUT/render.csv"
for f in "$OUT"/knob_*.dat; do
    [ -e "$f" ] || continue
    sort -g -k2 "$f" | awk 'NR == 1 || $3 < best { print; best = $3 }' > "$OUT/pareto_${f##*/knob_}"
done
awk -F, 'NR > 1 && $1 == "main" { k = $3 "-" $4 "-" $5 "x" $6; t[k, $8] = $12; keys[k] = 1 }
    END { for (k in keys) if (t[k, "composite"] > 0)
        printf "%s %.3f %.3f %.3f\n", k, t[k, "multipass"] / t[k, "composite"],
               t[k, "flat"] / t[k, "composite"], t[k, "uber"] / t[k, "composite"] }' \
    "$OUT/render.csv" | sort > "$OUT/ratios.dat"
# screen-space shading: forward's time beside the screen path's passes
awk -F, 'NR > 1 && $1 == "shading" { k = $3 "-" $4 "-" $5 "x" $6; keys[k] = 1
        if ($8 == "composite") f[k] = $12
        if ($8 == "screen") { d[k] = $26; c[k] = $27; s[k] = $28; t[k] = $12 } }
    END { for (k in keys) if (k in t)
        printf "%s %.3f %.3f %.3f %.3f %.3f\n", k, f[k], d[k], c[k], s[k], t[k] - d[k] - c[k] - s[k] }' \
    "$OUT/render.csv" | sort > "$OUT/shading.dat"
awk -F, 'NR > 1 { print $4, $17, $8 * 10 }' "$OUT/scale_hf.csv" > "$OUT/scale_hf.dat"
awk -F, 'NR > 1 { print $5, $6, $9, $10, $13 }' "$OUT/scale_mat.csv" > "$OUT/scale_mat.dat"
if command -v gnuplot >/dev/null 2>&1; then
    log "plots"
    (cd "$OUT" && gnuplot "$REPO/tests/bench/plots.gp") || echo "run.sh: gnuplot failed (plots skipped)"
else
    log "gnuplot not installed: plots skipped"
fi
# the work folder holds packs and images (hundreds of MB): gone unless kept
[ "$KEEP" = yes ] || rm -rf "$W"
log "done: $OUT/summary.md"
cat "$OUT/summary.md"
