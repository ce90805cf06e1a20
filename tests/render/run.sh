#!/bin/sh
# Render test cases: run.sh CASE SPLATVIEW IMGCHECK PACK OUTDIR
# Every splatview run has SPLAT_VALIDATE=1; splatview itself exits non-zero
# (3) when the validation layer said anything, and fails when the layer is
# not installed (RT_E_NO_VALIDATION).  Exit 77 is a skip (CTest
# SKIP_RETURN_CODE), never a pass.
#
# Tolerances, and why:
#   composite vs multi-pass 1e-5: both render into RGBA32F and compute the
#     same sums in another order and another pass (blending of fp32 values
#     in the multi-pass case); they agree to 2.4e-7 on lavapipe and 3.6e-7
#     on an H200 (tests/bench/HISTORY.md).  1e-5 is ~40 fp32 ulps of 1.0:
#     a compositor error of even 1/255 on one pixel fails.  No driver tested
#     needs more; one that does gets 1e-4 here, named, with its measurement.
#     Under the GGX sun (view dependent: a highlight's slope turns those
#     ulps of the normal into up to 5.8e-4, on 10 of 64000 pixels of the
#     fixture's overview) the final image is held to 1e-5 on >= 99.9 % of
#     pixels and 2e-3 on all: a 1/255 compositor error still fails.  (1e-3
#     until the default fog followed the cameras: the overview's fog went
#     from 7.3e-4 to 2.3e-4 per metre and the same 10 highlight pixels
#     from 5.8e-4 to 1.34e-3 on lavapipe.)
#   composite vs uber 1e-5: the same material code, other branching.
#   culled vs not culled 1e-6: the same triangles front-facing; only hidden
#     back faces are dropped, so equal up to nothing (1e-6 absorbs nothing
#     visible but keeps the check from depending on bitwise equal floats).
set -u
. "$(dirname "$0")/../lib.sh"   # fail, differ, must_fail
case_=$1 SV=$2 IC=$3 PACK=$4 OUT=$5/$1
mkdir -p "$OUT"
export SPLAT_VALIDATE=1
# the cases were written for the forward path; screen.sh tests the other
export SPLAT_SHADING=forward
export SPLAT_PIPELINE_CACHE="$OUT/pipelines.bin"
run() { echo "+ splatview $*"; "$SV" "$@" || fail "splatview $* (exit $?)"; }
# viewer_until_shot SHOT LOG ARGS...: the viewer in the background (pid in
# $pid), back once its script wrote SHOT (the first screenshot)
viewer_until_shot() {
    shot=$1 log=$2; shift 2
    xvfb-run -a -s "-screen 0 640x480x24" "$SV" "$@" > "$log" 2>&1 &
    pid=$!
    i=0
    while [ ! -e "$shot" ] && [ $i -lt 120 ]; do sleep 0.5; i=$((i + 1)); done
    [ -e "$shot" ] || { kill $pid; fail "no first screenshot ($shot)"; }
    sleep 1
}

# viewer_done LOG [WHAT]: wait for the viewer viewer_until_shot started,
# show its log, fail unless it exited 0
viewer_done() {
    wait $pid
    rc=$?
    cat "$1"
    [ $rc = 0 ] || fail "viewer exit $rc${2:+ ($2)}"
}

# minimal_copy: examples/minimal with the graphs and nodes it imports
# under $OUT/src (fresh), its scene in $SCENE
minimal_copy() {
    ROOT=$(cd "$(dirname "$0")/../.." && pwd)
    rm -rf "$OUT/src" "$OUT/pack" "$OUT/cache" "$OUT"/*.png
    mkdir -p "$OUT/src/examples"
    cp -r "$ROOT/examples/minimal" "$OUT/src/examples/" && cp -r "$ROOT/graphs" "$ROOT/nodes" "$OUT/src/" ||
        fail "copy"
    SCENE="$OUT/src/examples/minimal/scene.sg"
}

case $case_ in
final)
    run "$PACK" --headless --size 320x200 -o "$OUT/final.png"
    "$IC" nonuniform "$OUT/final.png" || fail "final view is uniform"
    run "$PACK" --headless --size 320x200 --camera-preset ridge -o "$OUT/ridge.png"
    "$IC" nonuniform "$OUT/ridge.png" || fail "ridge view is uniform"
    ;;
combos)
    # as many colours as combinations in view (flat colours, background excluded)
    run "$PACK" --headless --size 320x200 --view combos --clear 0,0,0 --stats -o "$OUT/combos.png" > "$OUT/stats.txt"
    cat "$OUT/stats.txt"
    want=$(sed -n 's/^combinations in view: \([0-9]*\) of.*/\1/p' "$OUT/stats.txt")
    # coarse patches no compiled combination covers are drawn by the
    # über-shader (compositions come from leaf cells only): one more colour
    uber=$(sed -n 's/^uber-shader fallback: \([0-9]*\) of.*/\1/p' "$OUT/stats.txt")
    [ -n "$want" ] && [ "${uber:-0}" -gt 0 ] && want=$((want + 1))
    got=$("$IC" colors "$OUT/combos.png" 0,0,0)
    echo "combinations in view: $want, colours: $got"
    [ -n "$want" ] && [ "$want" -ge 2 ] || fail "fewer than 2 combinations in view"
    [ "$got" = "$want" ] || fail "$got colours for $want combinations"
    ;;
views)
    for v in lod normal slope albedo mask:rock mask:snow; do
        f=$(echo "$v" | tr : _)
        run "$PACK" --headless --size 160x100 --view "$v" -o "$OUT/$f.png"
        "$IC" nonuniform "$OUT/$f.png" || fail "view $v is uniform"
    done
    "$SV" "$PACK" --headless --size 16x16 --view mask:nothing -o "$OUT/x.png" 2> "$OUT/err.txt" &&
        fail "an unknown material in --view was accepted"
    grep -q "no material 'nothing'" "$OUT/err.txt" || fail "unclear error: $(cat "$OUT/err.txt")"
    ;;
reference_multipass)
    # composite vs multi-pass alpha blending: 1e-5 (tolerances above)
    for cam in overview ridge; do
        run "$PACK" --headless --size 320x200 --camera-preset $cam --float-out "$OUT/c_$cam.f32"
        run "$PACK" --headless --size 320x200 --camera-preset $cam --reference multipass --float-out "$OUT/m_$cam.f32"
        "$IC" close "$OUT/c_$cam.f32" "$OUT/m_$cam.f32" 1e-5 0.999 80 &&
            "$IC" diff "$OUT/c_$cam.f32" "$OUT/m_$cam.f32" 2e-3 || fail "multipass differs ($cam)"
    done
    ;;
reference_uber)
    # uber vs per-combination: identical within float rounding
    for cam in overview ridge; do
        run "$PACK" --headless --size 320x200 --camera-preset $cam --float-out "$OUT/c_$cam.f32"
        run "$PACK" --headless --size 320x200 --camera-preset $cam --reference uber --float-out "$OUT/u_$cam.f32"
        "$IC" diff "$OUT/c_$cam.f32" "$OUT/u_$cam.f32" 1e-5 || fail "uber differs ($cam)"
    done
    ;;
cracks)
    # a steep view over rugged terrain full of LOD transitions: no magenta
    # background shows through; without stitching it does (the test can fail)
    args="--headless --size 400x300 --view albedo --clear 1,0,1 --lod-pixels 4 --camera 1024,700,800 --look 1024,0,600"
    run "$PACK" $args --stats -o "$OUT/stitched.png"
    holes=$("$IC" count "$OUT/stitched.png" 255,0,255)
    run "$PACK" $args --no-stitch -o "$OUT/unstitched.png"
    cracks=$("$IC" count "$OUT/unstitched.png" 255,0,255)
    echo "background pixels: stitched $holes, unstitched $cracks"
    [ "$holes" = 0 ] || fail "$holes background pixels through the terrain"
    [ "$cracks" -gt 0 ] || fail "the unstitched render shows no cracks: the view tests nothing"
    ;;
stats)
    run "$PACK" --headless --size 320x200 --frames 5 --stats > "$OUT/stats.txt"
    cat "$OUT/stats.txt"
    for key in "device:" "patches drawn:" "pipelines bound:" "gpu ms/frame:" "quadtree cpu ms/frame:"; do
        grep -q "^$key" "$OUT/stats.txt" || fail "--stats lacks '$key'"
    done
    ;;
bad_packs)
    # name, expected message part[, --check: a shader's corruption, which a
    # frame finds only where it needs that shader (read on first use) and
    # --check finds in every shader]
    expect_error() {
        rm -f "$OUT/$1.png"   # from an earlier run
        "$SV" "$OUT/$1" --headless ${3:-} --size 32x32 -o "$OUT/$1.png" > "$OUT/$1.log" 2>&1
        rc=$?
        cat "$OUT/$1.log"
        [ $rc = 1 ] || fail "$1: exit $rc, expected 1"
        grep -q "$2" "$OUT/$1.log" || fail "$1: message lacks '$2'"
        grep -qi "validation" "$OUT/$1.log" && fail "$1: validation message"
        [ -e "$OUT/$1.png" ] && fail "$1: wrote a picture"
        return 0
    }
    fresh() { rm -rf "$OUT/$1"; cp -r "$PACK" "$OUT/$1"; }
    fresh no_manifest; rm "$OUT/no_manifest/manifest.json"
    expect_error no_manifest "cannot read '.*manifest.json'"
    fresh bad_json; printf '{"format": "splatc-pack",\n  "version": 1,,\n' > "$OUT/bad_json/manifest.json"
    expect_error bad_json "manifest.json:2:"
    fresh corrupt_spirv; head -c 64 /dev/urandom > "$OUT/corrupt_spirv/shaders/0001.spv"
    expect_error corrupt_spirv "0001.spv: error: corrupt SPIR-V" --check
    fresh bad_spirv_body; { head -c 20 "$PACK/shaders/0000.spv"; head -c 400 /dev/zero; } > "$OUT/bad_spirv_body/shaders/0000.spv"
    expect_error bad_spirv_body "corrupt SPIR-V" --check
    fresh missing_file; rm "$OUT/missing_file/shaders/0000.spv"
    expect_error missing_file "names 'shaders/0000.spv', which cannot be read"
    fresh short_heightfield; head -c 1000 "$PACK/heightfield.r16" > "$OUT/short_heightfield/heightfield.r16"
    expect_error short_heightfield "heightfield.r16', which has 1000 bytes"
    fresh combo_range; printf '\377\177' | dd of="$OUT/combo_range/combos.bin" bs=1 seek=2 conv=notrunc 2>/dev/null
    expect_error combo_range "combination id 32767 out of range"
    fresh bad_version; sed -i 's/"abi": [0-9]*/"abi": 99/' "$OUT/bad_version/manifest.json"
    expect_error bad_version "abi 99"
    ;;
viewer)
    command -v xvfb-run > /dev/null || { echo "SKIP: no xvfb-run"; exit 77; }
    rm -f "$OUT/shot.png"
    rm -f "$OUT/after.png"
    # the window's own default path (not the SPLAT_SHADING above)
    env -u SPLAT_SHADING xvfb-run -a -s "-screen 0 640x480x24" "$SV" "$PACK" --size 320x200 \
        --script "frames=10;view=combos;frames=5;screenshot=$OUT/shot.png;key=Q;screenshot=$OUT/after.png" \
        > "$OUT/viewer.log" 2>&1
    rc=$?
    cat "$OUT/viewer.log"
    [ $rc = 0 ] || fail "viewer exit $rc"
    "$IC" nonuniform "$OUT/shot.png" || fail "viewer screenshot is uniform"
    [ -e "$OUT/after.png" ] && fail "the viewer went on after the Q key"
    # the window's path is headless's: screen-space where the pack has
    # compute variants (issue 33)
    want=forward
    { [ -e "$PACK/shaders/uber.comp" ] || [ -e "$PACK/shaders/uber.comp.zst" ]; } && want=screen-space
    grep -q "^splatview: $want shading" "$OUT/viewer.log" ||
        fail "the window did not open on the $want path"
    ;;
overlay)
    # the help overlay (key H, runtime/overlay.c) drawn on the device,
    # validation silent: headless --overlay changes only the top-left box
    # and puts text (near-white pixels) in it; in the window H shows it and
    # H again hides it
    run "$PACK" --headless --size 640x360 -o "$OUT/plain.png"
    run "$PACK" --headless --size 640x360 --overlay -o "$OUT/help.png"
    "$IC" overlay "$OUT/plain.png" "$OUT/help.png" 480 200 1000 ||
        fail "the overlay is not text in the top-left box alone"
    run "$PACK" --headless --size 640x360 --view mask:rock --overlay -o "$OUT/help_mask.png"
    "$IC" nonuniform "$OUT/help_mask.png" || fail "overlay on the mask view: uniform"
    command -v xvfb-run > /dev/null || { echo "SKIP: no xvfb-run for the window's part"; exit 77; }
    rm -f "$OUT"/win*.png
    xvfb-run -a -s "-screen 0 800x600x24" "$SV" "$PACK" --size 640x360 --script \
        "frames=5;screenshot=$OUT/win0.png;key=H;frames=2;screenshot=$OUT/win1.png;key=H;frames=2;screenshot=$OUT/win2.png" \
        > "$OUT/window.log" 2>&1
    rc=$?
    cat "$OUT/window.log"
    [ $rc = 0 ] || fail "viewer exit $rc"
    w0=$("$IC" white "$OUT/win0.png" 480 200) && w1=$("$IC" white "$OUT/win1.png" 480 200) &&
        w2=$("$IC" white "$OUT/win2.png" 480 200) || fail "imgcheck white"
    echo "near-white pixels in the box: $w0 before H, $w1 with the help, $w2 after H again"
    [ "$w1" -ge $((w0 + 1000)) ] || fail "H shows no help text in the window"
    [ "$w2" -le $((w0 + 50)) ] || fail "H again does not hide the help"
    ;;
hot_reload_search)
    # hot reload resolves imports as `splatc build` does: a scene outside
    # any project whose graphs and nodes are found only through -I (first
    # run) or $SPLATC_PATH (second run).  An edit must rebuild, not fail
    # with "cannot import" (the viewer used to search only "." and the
    # project root).
    command -v xvfb-run > /dev/null || { echo "SKIP: no xvfb-run"; exit 77; }
    ROOT=$(cd "$(dirname "$0")/../.." && pwd)
    T=$(mktemp -d /tmp/splat_search.XXXXXX)
    trap 'rm -rf "$T"' EXIT
    mkdir -p "$T/lib" "$T/scene"
    cp -r "$ROOT/graphs" "$ROOT/nodes" "$T/lib/" && cp "$ROOT"/examples/minimal/*.sg \
        "$ROOT"/examples/minimal/*.png "$T/scene/" || fail "copy"
    SCENE="$T/scene/scene.sg"
    for how in include env; do
        rm -f "$OUT"/$how-*.png
        # its rock texture is named relative to examples/minimal: point it at lib
        sed "s|\.\./\.\./graphs/|$T/lib/graphs/|" "$ROOT/examples/minimal/scene.sg" > "$SCENE"
        if [ $how = include ]; then
            unset SPLATC_PATH; INC="-I $T/lib"
        else
            export SPLATC_PATH="$T/lib"; INC=""
        fi
        "$SPLATC" build "$SCENE" -o "$T/pack" --no-cache $INC > /dev/null || fail "splatc build ($how)"
        viewer_until_shot "$OUT/$how-a.png" "$OUT/$how.log" "$T/pack" --size 160x100 $INC \
            --scene "$SCENE" --camera-preset overview \
            --script "frames=2;screenshot=$OUT/$how-a.png;wait_reload=150;frames=2;screenshot=$OUT/$how-b.png;quit"
        sed -i 's/vec3(0.55, 0.47, 0.22)/vec3(0.9, 0.05, 0.05)/' "$SCENE"
        viewer_done "$OUT/$how.log" "$how"
        grep -q "does not compile" "$OUT/$how.log" && fail "hot reload could not resolve the imports ($how)"
        grep -q "reloaded" "$OUT/$how.log" || fail "no reload ($how)"
    done
    unset SPLATC_PATH
    ;;
hot_reload)
    # edit a material of a copy of examples/minimal while the viewer runs:
    # first a syntax error (shown, survived), then a new colour (reloaded)
    command -v xvfb-run > /dev/null || { echo "SKIP: no xvfb-run"; exit 77; }
    minimal_copy
    "$SPLATC" build "$SCENE" -o "$OUT/pack" --no-cache > /dev/null || fail "splatc build"
    # no --scene: the viewer finds the scene through the manifest's scene.source
    viewer_until_shot "$OUT/a.png" "$OUT/viewer.log" "$OUT/pack" --size 320x200 \
        --camera-preset overview \
        --script "frames=3;screenshot=$OUT/a.png;wait_reload=150;frames=2;screenshot=$OUT/b.png;quit"
    sed -i 's/node rows : mul {/node rows : mul {{/' "$SCENE"
    sleep 2
    sed -i 's/node rows : mul {{/node rows : mul {/; s/vec3(0.55, 0.47, 0.22)/vec3(0.9, 0.05, 0.05)/; s/a = 0.8, b = 1.0/a = 0.2, b = 1.0/' "$SCENE"
    viewer_done "$OUT/viewer.log"
    grep -q "does not compile" "$OUT/viewer.log" || fail "the syntax error was not reported"
    grep -q "reloaded" "$OUT/viewer.log" || fail "no reload"
    differ "$OUT/a.png" "$OUT/b.png" "the picture did not change after the edit"
    ;;
hot_reload_far)
    # a pack with a far atlas keeps it across a hot reload, rebaked on the
    # viewer's own device (SPLAT_FAR_BAKE=gpu: lavapipe is a CPU's device,
    # where auto drops the atlas); the edit changes the atlas
    command -v xvfb-run > /dev/null || { echo "SKIP: no xvfb-run"; exit 77; }
    minimal_copy
    "$SPLATC" build "$SCENE" -o "$OUT/pack" --far-atlas --far-bake cpu --no-cache > /dev/null ||
        fail "splatc build"
    cp "$OUT/pack/far.atlas" "$OUT/far_before.atlas"
    export SPLAT_FAR_BAKE=gpu
    viewer_until_shot "$OUT/a.png" "$OUT/viewer.log" "$OUT/pack" --size 320x200 \
        --camera-preset overview --far-atlas-distance 600 \
        --script "frames=3;screenshot=$OUT/a.png;wait_reload=150;frames=2;screenshot=$OUT/b.png;quit"
    unset SPLAT_FAR_BAKE
    sed -i 's/vec3(0.55, 0.47, 0.22)/vec3(0.9, 0.05, 0.05)/' "$SCENE"
    viewer_done "$OUT/viewer.log"
    grep -q "reloaded in .*far atlas baked on the device" "$OUT/viewer.log" ||
        fail "the far atlas was not rebaked on the device"
    grep -q '"far_atlas"' "$OUT/pack/manifest.json" || fail "the reloaded pack lost its far atlas"
    differ "$OUT/far_before.atlas" "$OUT/pack/far.atlas" "the far atlas did not change"
    grep -q "validation message" "$OUT/viewer.log" && fail "validation messages"
    differ "$OUT/a.png" "$OUT/b.png" "the picture did not change after the edit"
    ;;
preview)
    # splatview --material: one material of a copy of examples/minimal alone
    # on the built-in test hill (splatc build --preview), headless, then in
    # the viewer across an edit of that material (hot reload rebuilds it)
    minimal_copy
    export XDG_CACHE_HOME="$OUT/cache"
    "$SPLATC" build "$SCENE" -o "$OUT/pack" --no-cache > /dev/null || fail "splatc build"
    run "$OUT/pack" --material field --headless --size 160x100 -o "$OUT/field.png"
    run "$OUT/pack" --material rock --headless --size 160x100 -o "$OUT/rock.png"
    for m in field rock; do
        "$IC" nonuniform "$OUT/$m.png" || fail "the $m swatch is uniform"
    done
    differ "$OUT/field.png" "$OUT/rock.png" "two materials gave the same swatch"
    ls "$OUT"/cache/splatc/preview/*/field/manifest.json > /dev/null || fail "no swatch pack in the cache"
    "$SV" "$OUT/pack" --material nope --headless --size 16x16 -o "$OUT/x.png" 2> "$OUT/err.txt" &&
        fail "an unknown material was previewed"
    grep -q "no material 'nope' in scene 'minimal' to preview" "$OUT/err.txt" ||
        fail "unclear error: $(cat "$OUT/err.txt")"
    "$SV" "$OUT/pack" --material ../x --headless --size 16x16 -o "$OUT/x.png" 2> "$OUT/err.txt"
    [ $? = 2 ] || fail "a material name with a path was accepted"
    [ -e "$OUT/x.png" ] && fail "a picture was written for a bad material"
    command -v xvfb-run > /dev/null || { echo "SKIP: no xvfb-run for the viewer part"; exit 77; }
    viewer_until_shot "$OUT/a.png" "$OUT/viewer.log" "$OUT/pack" --material field --size 160x100 \
        --script "frames=3;screenshot=$OUT/a.png;wait_reload=150;frames=2;screenshot=$OUT/b.png;quit"
    sed -i 's/vec3(0.55, 0.47, 0.22)/vec3(0.9, 0.05, 0.05)/' "$SCENE"
    viewer_done "$OUT/viewer.log"
    grep -q "reloaded" "$OUT/viewer.log" || fail "no reload"
    differ "$OUT/a.png" "$OUT/b.png" "the swatch did not change after the edit"
    ;;
real)
    # a pack written by splatc build: pictures, combination colours, and the
    # exactness of the composites against both references
    run "$PACK" --headless --size 320x200 -o "$OUT/default.png"
    "$IC" nonuniform "$OUT/default.png" || fail "default view is uniform"
    run "$PACK" --headless --size 320x200 --view combos --clear 0,0,0 --stats -o "$OUT/combos.png" > "$OUT/stats.txt"
    want=$(sed -n 's/^combinations in view: \([0-9]*\) of.*/\1/p' "$OUT/stats.txt")
    # coarse patches no compiled combination covers are drawn by the
    # über-shader (compositions come from leaf cells only): one more colour
    uber=$(sed -n 's/^uber-shader fallback: \([0-9]*\) of.*/\1/p' "$OUT/stats.txt")
    [ -n "$want" ] && [ "${uber:-0}" -gt 0 ] && want=$((want + 1))
    got=$("$IC" colors "$OUT/combos.png" 0,0,0)
    echo "combinations in view: $want, colours: $got"
    [ "$got" = "$want" ] || fail "$got colours for $want combinations"
    run "$PACK" --headless --size 320x200 --float-out "$OUT/c.f32"
    run "$PACK" --headless --size 320x200 --reference multipass --float-out "$OUT/m.f32"
    run "$PACK" --headless --size 320x200 --reference uber --float-out "$OUT/u.f32"
    "$IC" finite "$OUT/c.f32" || fail "NaN or Inf in the composite render"
    "$IC" diff "$OUT/c.f32" "$OUT/m.f32" 1e-5 || fail "multipass differs"
    "$IC" diff "$OUT/c.f32" "$OUT/u.f32" 1e-5 || fail "uber differs"
    # back faces culled (camera above the terrain, inside it) and not: the
    # same pixels; the default camera (outside the terrain) culls nothing
    grep -q "^back faces culled: no" "$OUT/stats.txt" || fail "outside camera culled"
    cam="--camera 300,300,250 --look 800,20,700"
    run "$PACK" --headless --size 320x200 $cam --stats --float-out "$OUT/cu.f32" > "$OUT/cull.txt"
    grep -q "^back faces culled: yes" "$OUT/cull.txt" || fail "camera above: back faces not culled"
    run "$PACK" --headless --size 320x200 $cam --no-cull --stats --float-out "$OUT/nc.f32" > "$OUT/nocull.txt"
    grep -q "^back faces culled: no" "$OUT/nocull.txt" || fail "--no-cull culled"
    "$IC" nonuniform "$OUT/cu.f32" || fail "the culled view is uniform: it compares nothing"
    "$IC" diff "$OUT/cu.f32" "$OUT/nc.f32" 1e-6 || fail "culling back faces changed the picture"
    ;;
*)
    fail "unknown case $case_"
    ;;
esac
echo "PASS: $case_"
