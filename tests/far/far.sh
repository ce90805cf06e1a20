#!/bin/sh
# tests/far/far.sh CASE SPLATC SPLATVIEW SPLATBENCH SRC OUT
# The far atlas (compiler/far_atlas.h, runtime/far.c) on colorado:
#   build     two builds with --far-atlas=4 give byte-identical packs
#   error     screen path at the valley camera (320x180): per distance band
#             [D_k, D_k+1) the tiles the atlas shades there against the same
#             tiles shaded by their composites (images with far distance D_k
#             and D_k+1 differ in exactly those tiles); the band's mean
#             absolute error per colour channel must stay within BOUND and
#             every band must have tiles; zero validation messages
#   forward   the forward path at the valley camera (320x180): with
#             --far-atlas-distance 5000 some patches, not all, are shaded
#             from the atlas (--stats), fewer texture samples per pixel than
#             without; its picture within FWD_PSNR dB of the screen path's
#             at the same distance (both shade the far terrain from the atlas;
#             they differ only where a tile and a patch disagree about
#             being wholly beyond it) and its mean error against the
#             composites within BOUND; at the trinidad camera (over the
#             destructible area) with D = 1 m some patches are still not
#             far: those over the destructible area; zero validation messages
#   small     examples/minimal's pack with its atlas (quick: in the ASan
#             run): forward and screen at D = 600 m both shade some, not
#             all, of the terrain from the atlas, within FWD_PSNR dB of
#             each other; zero validation messages
#   corrupt   on examples/minimal's pack: a truncated far.atlas, a wrong
#             magic, levels over the chain, a manifest width that does not
#             match the file, a symbolic link: each refused with an error
#             naming far_atlas
# Prints the bands as a table (the RESULTS.md rows come from it).
set -eu
CASE=$1 SPLATC=$2 VIEW=$3 BENCH=$4 SRC=$5 OUT=$6
PACK=${FAR_PACK:-$OUT/colorado_far}   # FAR_PACK: measure another pack
mkdir -p "$OUT"
fail() { echo "FAIL: $*" >&2; exit 1; }

build_pack() {   # $1: folder
    "$SPLATC" build "$SRC/examples/colorado/scene.sg" -o "$1" --far-atlas=4 -j 2 \
        --cache "$OUT/cache" >/dev/null
}

case $CASE in
build)
    rm -rf "$PACK" "$PACK.2"
    build_pack "$PACK"
    build_pack "$PACK.2"   # the cache is warm: only the bake runs again
    cmp "$PACK/far.atlas" "$PACK.2/far.atlas" || fail "far.atlas differs between two builds"
    cmp "$PACK/manifest.json" "$PACK.2/manifest.json" || fail "manifest differs"
    grep -q '"far_atlas"' "$PACK/manifest.json" || fail "no far_atlas in the manifest"
    # without the option: no atlas, no manifest entry
    "$SPLATC" build "$SRC/examples/minimal/scene.sg" -o "$OUT/minimal_nofar" --cache "$OUT/cache" >/dev/null
    [ ! -e "$OUT/minimal_nofar/far.atlas" ] || fail "far.atlas written without --far-atlas"
    ! grep -q far_atlas "$OUT/minimal_nofar/manifest.json" || fail "far_atlas in a pack without one"
    echo "far.atlas: $(wc -c < "$PACK/far.atlas") bytes, identical on two builds"
    ;;
error)
    [ -f "$PACK/far.atlas" ] || build_pack "$PACK"
    BOUND=${FAR_BOUND:-0.05}
    R="--headless --shading screen --size 320x180 --camera-preset valley --no-undergrowth --stats"
    render() {   # $1: distance -> $OUT/far_$1.f32; prints the far tiles
        SPLAT_VALIDATE=1 "$VIEW" "$PACK" $R --far-atlas-distance "$1" -o "$OUT/far_$1.png" \
            --float-out "$OUT/far_$1.f32" > "$OUT/far_$1.log" 2>&1 ||
            { cat "$OUT/far_$1.log" >&2; fail "splatview at distance $1"; }
        grep -q "validation message" "$OUT/far_$1.log" && fail "validation messages at $1"
        sed -n 's/.*, \([0-9]*\) from the far atlas/\1/p' "$OUT/far_$1.log"
    }
    render 0 > /dev/null
    BANDS="1000 2000 5000 10000 20000 40000"
    printf "%-16s %8s %12s %10s\n" "band (m)" "tiles" "mean_abs" "max_abs"
    prev=""; prev_tiles=0; bad=0
    for d in $BANDS 0; do
        tiles=0
        [ "$d" = 0 ] || tiles=$(render "$d")
        if [ -n "$prev" ]; then
            # band [prev, d): images prev and d differ in its tiles only
            n=$((prev_tiles - tiles))
            line=$("$BENCH" compare "$OUT/far_$prev.f32" "$OUT/far_$d.f32")
            max=$(echo "$line" | awk '{print $2}')
            mean=$(echo "$line" | awk -v n="$n" '{ printf "%.5f", (n > 0 ? $4 * 320 * 180 / (64 * n) : 0) }')
            hi=$([ "$d" = 0 ] && echo inf || echo "$d")
            printf "%-16s %8d %12s %10s\n" "[$prev, $hi)" "$n" "$mean" "$max"
            [ "$n" -gt 0 ] || { echo "band [$prev, $hi) has no tiles" >&2; bad=1; }
            awk -v m="$mean" -v b="$BOUND" 'BEGIN { exit !(m <= b) }' ||
                { echo "band [$prev, $hi): mean error $mean over $BOUND" >&2; bad=1; }
        fi
        prev=$d; prev_tiles=$tiles
    done
    [ $bad = 0 ] || fail "far atlas error"
    ;;
forward)
    [ -f "$PACK/far.atlas" ] || build_pack "$PACK"
    BOUND=${FAR_BOUND:-0.05}
    R="--headless --size 320x180 --camera-preset valley --no-undergrowth --stats"
    shade() {   # $1: path, $2: distance -> $OUT/fwd_$1_$2.f32 and .log
        SPLAT_VALIDATE=1 "$VIEW" "$PACK" $R --shading "$1" --far-atlas-distance "$2" \
            -o "$OUT/fwd_$1_$2.png" --float-out "$OUT/fwd_$1_$2.f32" > "$OUT/fwd_$1_$2.log" 2>&1 ||
            { cat "$OUT/fwd_$1_$2.log" >&2; fail "splatview $1 at distance $2"; }
        ! grep -q "validation message" "$OUT/fwd_$1_$2.log" || fail "validation messages ($1, $2)"
    }
    shade forward 0; shade forward 5000; shade screen 5000
    far=$(sed -n 's/^far atlas: \([0-9]*\) of \([0-9]*\) patches$/\1 \2/p' "$OUT/fwd_forward_5000.log")
    none=$(sed -n 's/^far atlas: \([0-9]*\) of [0-9]* patches$/\1/p' "$OUT/fwd_forward_0.log")
    [ -n "$far" ] && [ "$none" = 0 ] || fail "no far patch count in --stats (or patches at distance 0)"
    set -- $far
    [ "$1" -gt 0 ] && [ "$1" -lt "$2" ] || fail "far patches $1 of $2: expected some, not all"
    spp() { sed -n 's/^texture samples per pixel: //p' "$OUT/fwd_forward_$1.log"; }
    awk -v a="$(spp 5000)" -v b="$(spp 0)" 'BEGIN { exit !(a < b) }' ||
        fail "samples per pixel $(spp 5000) with the atlas, $(spp 0) without"
    vs_screen=$("$BENCH" compare "$OUT/fwd_forward_5000.f32" "$OUT/fwd_screen_5000.f32")
    vs_full=$("$BENCH" compare "$OUT/fwd_forward_5000.f32" "$OUT/fwd_forward_0.f32")
    echo "far patches: $1 of $2; samples per pixel $(spp 0) -> $(spp 5000)"
    echo "forward with the atlas vs screen with the atlas: $vs_screen"
    echo "forward with the atlas vs forward composites:   $vs_full"
    psnr=$(echo "$vs_screen" | awk '{print $6}')
    awk -v p="$psnr" -v m="${FWD_PSNR:-40}" 'BEGIN { exit !(p >= m) }' ||
        fail "forward vs screen far shading: $psnr dB < ${FWD_PSNR:-40}"
    mean=$(echo "$vs_full" | awk '{print $4}')
    awk -v m="$mean" -v b="$BOUND" 'BEGIN { exit !(m <= b) }' || fail "mean error $mean over $BOUND"
    # every patch is beyond 1 m; only the destructible area's stay composites
    R="--headless --size 320x180 --camera-preset trinidad --no-undergrowth --stats"
    shade forward 1
    set -- $(sed -n 's/^far atlas: \([0-9]*\) of \([0-9]*\) patches$/\1 \2/p' "$OUT/fwd_forward_1.log")
    echo "trinidad, D = 1 m: $1 of $2 patches far"
    [ "$1" -gt 0 ] && [ "$1" -lt "$2" ] || fail "trinidad at 1 m: $1 of $2 patches far"
    ;;
small)
    PACK=$OUT/minimal_far_small
    "$SPLATC" build "$SRC/examples/minimal/scene.sg" -o "$PACK" --far-atlas --cache "$OUT/cache" \
        >/dev/null
    for sh in forward screen; do
        SPLAT_VALIDATE=1 "$VIEW" "$PACK" --headless --size 160x90 --shading $sh \
            --far-atlas-distance 600 --stats --float-out "$OUT/small_$sh.f32" \
            -o "$OUT/small_$sh.png" > "$OUT/small_$sh.log" 2>&1 ||
            { cat "$OUT/small_$sh.log" >&2; fail "splatview $sh"; }
        ! grep -q "validation message" "$OUT/small_$sh.log" || fail "validation messages ($sh)"
    done
    set -- $(sed -n 's/^far atlas: \([0-9]*\) of \([0-9]*\) patches$/\1 \2/p' "$OUT/small_forward.log")
    [ -n "${2:-}" ] && [ "$1" -gt 0 ] && [ "$1" -lt "$2" ] || fail "forward far patches: ${1:-?} of ${2:-?}"
    tiles=$(sed -n 's/.*, \([0-9]*\) from the far atlas/\1/p' "$OUT/small_screen.log")
    [ "${tiles:-0}" -gt 0 ] || fail "no screen tile from the far atlas"
    line=$("$BENCH" compare "$OUT/small_forward.f32" "$OUT/small_screen.f32")
    echo "forward: $1 of $2 patches far; screen: $tiles tiles far; forward vs screen: $line"
    psnr=$(echo "$line" | awk '{print $6}')
    awk -v p="$psnr" -v m="${FWD_PSNR:-40}" 'BEGIN { exit !(p >= m) }' ||
        fail "forward vs screen far shading: $psnr dB < ${FWD_PSNR:-40}"
    ;;
corrupt)
    # its own small pack (examples/minimal), so the case is quick under ASan
    PACK=$OUT/minimal_far
    "$SPLATC" build "$SRC/examples/minimal/scene.sg" -o "$PACK" --far-atlas --cache "$OUT/cache" \
        >/dev/null
    try() {   # $1: what; the pack in $OUT/bad must be refused naming far_atlas
        if "$VIEW" "$OUT/bad" --headless --shading screen --size 64x36 -o "$OUT/bad.png" \
            > "$OUT/bad.log" 2>&1; then
            fail "$1: accepted"
        fi
        grep -q "far_atlas" "$OUT/bad.log" || { cat "$OUT/bad.log" >&2; fail "$1: error does not name far_atlas"; }
        echo "$1: refused: $(grep -m1 far_atlas "$OUT/bad.log")"
    }
    fresh() { rm -rf "$OUT/bad"; cp -r "$PACK" "$OUT/bad"; }
    fresh; head -c 1000 "$PACK/far.atlas" > "$OUT/bad/far.atlas"; try "truncated"
    fresh; printf 'XPLATFAR' | dd of="$OUT/bad/far.atlas" conv=notrunc 2>/dev/null; try "magic"
    fresh; sed -i "s/\"levels\": [0-9][0-9]*/\"levels\": 99/" "$OUT/bad/manifest.json"; try "levels"
    fresh; awk '/"far_atlas"/ { f = 1 } f && /"width"/ { sub(/[0-9]+/, "100"); f = 0 } { print }' \
        "$PACK/manifest.json" > "$OUT/bad/manifest.json"; try "width"
    fresh; rm "$OUT/bad/far.atlas"; ln -s "$PACK/far.atlas" "$OUT/bad/far.atlas"; try "symlink"
    ;;
*)
    echo "unknown case $CASE" >&2; exit 2 ;;
esac
