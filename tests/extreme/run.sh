#!/bin/sh
# run.sh — extreme-value renders (extreme-value stability): every scene `extreme gen`
# writes (max height 0 m / 1 m / 10 km over vertical cliffs and 0|65535
# checkerboards, flat ground, 1x1 and 2x2 heightfields, a 1e6 m height
# offset, a 100 km terrain, painted masks all 0 / all 1) is built with
# `splatc build` and rendered headless (lavapipe, SPLAT_VALIDATE=1) in the
# final, normal, slope and mask views; `extreme check` fails on any NaN/Inf
# pixel, any mask or slope value outside 0..1, and on flat ground on a
# normal farther than 1e-6 from straight up.  Two extra cameras: 1 m above
# the 100 km terrain, and 0.1 degrees below the horizon (89.9 degrees from
# the vertical) over flat ground.
#   sh tests/extreme/run.sh EXTREME SPLATC SPLATVIEW OUTDIR
set -eu
X=$1 SPLATC=$2 VIEW=$3 OUT=$4
rm -rf "$OUT/scenes" "$OUT/img"
mkdir -p "$OUT/img"
"$X" gen "$OUT/scenes"
status=0
check() {  # IMAGE ARGS...
    "$X" check "$@" || { echo "FAIL: $1"; status=1; }
}
render() {  # CASE LABEL [splatview camera args...]
    c=$1 l=$2; shift 2
    for v in final normal slope mask:x_step mask:x_slope mask:x_painted; do
        f=$OUT/img/$l-$(echo "$v" | tr ':' '_').f32
        if ! "$VIEW" "$OUT/$c.pack" --headless --size 160x90 --view "$v" --clear 0,0,0 \
                --float-out "$f" "$@" > /dev/null; then
            echo "FAIL: splatview $c $v"; status=1; continue
        fi
        case $v in
        final) check "$f" ;;
        normal) if [ "$c" = flat ] || [ "$c" = hf1x1 ]; then
                    check "$f" --expect 0.5,1,0.5 1e-6 --clear 0,0,0
                else check "$f"; fi ;;
        *) check "$f" --mask ;;
        esac
    done
}
for d in "$OUT"/scenes/*/; do
    c=$(basename "$d")
    if ! "$SPLATC" build "$d/scene.sg" -o "$OUT/$c.pack" -I . --no-cache > "$OUT/$c.build.txt" 2>&1; then
        echo "FAIL: splatc build $c"; cat "$OUT/$c.build.txt"; status=1; continue
    fi
    render "$c" "$c"
done
# 1 m above the 100 km terrain, over texel (128, 128) whose height is exact
h=$(awk 'BEGIN { printf "%.6f", (32767.5 + 32767.5 * sin(128 * 0.05) * cos(128 * 0.07)) / 65535 * 2000 }')
x=$(awk 'BEGIN { printf "%.6f", 128.5 / 256 * 1e5 }')
render world100km world100km-1m --camera "$x,$(awk "BEGIN { print $h + 1 }"),$x" \
    --look "$(awk "BEGIN { print $x + 100 }"),$h,$x"
# grazing: 0.1 degrees below the horizon, 0.2 m above flat ground
y=$(awk 'BEGIN { printf "%.6f", 32768 / 65535 * 100 + 0.2 }')
ly=$(awk "BEGIN { printf \"%.6f\", $y - 1000 * sin(0.1 * 3.14159265358979 / 180) }")
render flat flat-grazing89.9 --camera "10,$y,128" --look "1010,$ly,128"
[ $status = 0 ] && echo "extreme renders: all views finite, masks within 0..1"
exit $status
