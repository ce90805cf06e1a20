#!/bin/sh
# tests/plan/plan.sh SPLATC SPLATVIEW SRC OUT
# The frame plan (runtime/render_plan.c) as `splatview --print-plan`
# prints it, on examples/minimal with its far atlas (160x90, 2 frames: the
# second frame's plan, after the shadow map was made):
#   forward, screen, far (both paths), multipass, ray cast, cost view:
#             the pass names in order, and the reads and writes of the
#             passes that set each path apart
#   stats     with --stats every GPU pass has a time in ms
#   sync      with the plan's barriers left out (SPLAT_PLAN_BARRIERS=0)
#             synchronization validation reports hazards on the screen
#             path and the counting variant: the checks are on, and the
#             declared barriers are what keeps them silent
# Every run is under SPLAT_VALIDATE=1 (synchronization validation on):
# splatview exits 3 on any validation message.
set -eu
SPLATC=$1 SV=$2 SRC=$3 OUT=$4
PACK=$OUT/minimal_far
mkdir -p "$OUT"
fail() { echo "FAIL: $*" >&2; exit 1; }
"$SPLATC" build "$SRC/examples/minimal/scene.sg" -o "$PACK" --far-atlas --cache "$OUT/cache" \
    > "$OUT/build.log" 2>&1 || { cat "$OUT/build.log"; fail "splatc build"; }

plan() {   # name, splatview options...: the plan into $OUT/NAME.txt
    name=$1
    shift
    SPLAT_VALIDATE=1 "$SV" "$PACK" --size 160x90 --frames 2 -o "$OUT/$name.png" --print-plan \
        "$@" > "$OUT/$name.txt" 2> "$OUT/$name.err" ||
        { cat "$OUT/$name.txt" "$OUT/$name.err"; fail "$name: splatview exit $?"; }
    cat "$OUT/$name.txt"
}
# the pass names, comma-separated
names() { sed -n 's/^ *[0-9][0-9]* \(.\{22\}\).*/\1/p' "$OUT/$1.txt" | sed 's/ *$//' |
          paste -sd, -; }
expect() {   # name, the names
    got=$(names "$1")
    [ "$got" = "$2" ] || fail "$1: passes '$got', expected '$2'"
}
line() {   # name, pass: its line
    grep "^ *[0-9]* $2  " "$OUT/$1.txt" || fail "$1: no pass '$2'"
}
has() {   # name, pass, text
    line "$1" "$2" | grep -qF -- "$3" || fail "$1: '$2' lacks '$3': $(line "$1" "$2")"
}

UG="undergrowth generation"
plan forward --shading forward
expect forward "$UG,forward,sky,readback"
has forward forward "reads frame height destruction shadow  writes color(transfer-src) depth(attachment)"
has forward readback "reads color(transfer-src)  writes readback"
grep -q "^plan: forward path, 160x90, 4 passes" "$OUT/forward.txt" || fail "forward: header"

plan screen --shading screen
expect screen "$UG,depth,tile lists reset,classification,shading,tile counts,readback"
has screen depth "writes depth(shader-read)"
has screen classification "depth(shader-read)  writes tiles color(general)"
has screen shading "tiles  writes tiles color(general)"
has screen "tile counts" "reads tiles  writes tiles-host"

plan far_forward --shading forward --far-atlas-distance 600
expect far_forward "$UG,forward,far,sky,readback"
has far_forward far "reads frame far-atlas height  writes color(transfer-src) depth(attachment)"

plan far_screen --shading screen --far-atlas-distance 600
expect far_screen "$UG,depth,tile lists reset,classification,shading,far,tile counts,readback"
has far_screen far "reads frame far-atlas tiles  writes tiles color(general)"

plan multipass --reference multipass
expect multipass "$UG,multipass,resolve,readback"
has multipass resolve "reads frame shadow gbuffer  writes color(transfer-src)"

plan raycast --shading screen --screen-depth raycast
expect raycast "$UG,depth (ray cast),tile lists reset,classification,shading,tile counts,readback"
has raycast classification "ray-depth(general)  writes"

# the preview scale: the frame at 80x45, one more pass makes the 160x90
# output from the colour and the path's depth; the readback reads it
plan preview --shading screen --preview-scale 2
expect preview "$UG,depth,tile lists reset,classification,shading,tile counts,upscale,readback"
grep -q "^plan: screen path, 80x45, 8 passes" "$OUT/preview.txt" || fail "preview: header"
has preview upscale "reads depth(shader-read) color(general)  writes output(general)"
has preview readback "reads output(transfer-src)  writes readback"
plan preview_raycast --shading screen --screen-depth raycast --preview-scale 4
has preview_raycast upscale "reads ray-depth(general) color(general)  writes output(general)"
plan preview_forward --shading forward --preview-scale 2
expect preview_forward "$UG,forward,sky,upscale,readback"
has preview_forward upscale "reads color(general)  writes output(general)"

plan cost --shading forward --view cost
expect cost "counters reset,forward,counters read,readback"
has cost forward "writes color(transfer-src) depth(attachment) counters"
has cost "counters read" "reads counters  writes counters-host"

plan stats --shading screen --stats
expect stats "$UG,depth,tile lists reset,classification,shading,tile counts,readback"
n=$(grep -c "^ *[0-9][0-9]* .\{22\} \{0,6\}\(rp\|group\|\) *[0-9][0-9.]* ms  reads" "$OUT/stats.txt") ||
    true
[ "$n" = 6 ] || fail "stats: $n passes with a GPU time, expected 6 (all but readback)"
has stats readback "own             -  reads"

for sh in screen cost; do
    opts="--shading screen"
    [ $sh = cost ] && opts="--shading forward --view cost"
    rc=0
    SPLAT_PLAN_BARRIERS=0 SPLAT_VALIDATE=1 "$SV" "$PACK" --headless --size 160x90 --frames 2 \
        $opts -o "$OUT/nobar_$sh.png" > "$OUT/nobar_$sh.log" 2>&1 || rc=$?
    [ $rc = 3 ] || { cat "$OUT/nobar_$sh.log"; fail "no barriers ($sh): exit $rc, expected 3"; }
    grep -q "SYNC-HAZARD" "$OUT/nobar_$sh.log" || fail "no barriers ($sh): no hazard reported"
done
echo "ok: 11 plans as expected; without the plan's barriers validation reports hazards"
