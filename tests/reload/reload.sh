#!/bin/sh
# Hot reload of each input kind: reload.sh SPLATC PACKEDIT TEST_RELOAD OUTDIR
# examples/minimal (sparse painted masks, three textures) and the
# destruction scene are built by splatc; each variant changes one input of
# a copy: the heightfield's contents, the terrain's scale, a texture's
# pixels, a texture's sampler, a painted mask (a byte of the BC4 atlas), the
# destructible area; test_reload must refuse each by name, and take the
# variants that change only shaders or parameters.
set -u
. "$(dirname "$0")/../lib.sh"   # fail, differ
SC=$1 PE=$2 TR=$3 OUT=$4
export SPLAT_VALIDATE=1
rm -rf "$OUT" && mkdir -p "$OUT" || fail "cannot make $OUT"
cd "$(dirname "$0")/../.." || fail "no repository root"
"$SC" build examples/minimal/scene.sg -o "$OUT/base" --no-cache > /dev/null || fail "build minimal"
"$SC" build tests/destruction/scene.sg -o "$OUT/dbase" --no-cache > /dev/null || fail "build destruction"
# variant NAME BASE: a copy whose change is read from stdin (run in the copy)
variant() {
    rm -rf "$OUT/$1" && cp -r "$OUT/$2" "$OUT/$1" && (cd "$OUT/$1" && sh -e) || fail "variant $1"
}
M=manifest.json
variant heights base <<EOF2
printf '\377\377' | dd of=heightfield.r16 bs=1 seek=5000 conv=notrunc 2>/dev/null
EOF2
variant scale base <<EOF2
"$PE" set $M scene.max_height 300
EOF2
variant texture base <<EOF2
"$PE" png textures/rock.png 256 256
EOF2
# texture 0 (the grass set's albedo) is alone in its texture array: a
# sampler change there is a valid pack that hot reload must refuse
variant sampler base <<EOF2
"$PE" set $M textures.0.wrap '"clamp"'
EOF2
variant mask base <<EOF2
printf '\125\252' | dd of=painted.sparse bs=1 seek=1100 conv=notrunc 2>/dev/null
EOF2
variant params base <<EOF2
"$PE" set $M params.0.default '[0.5, 0, 0, 0]'
EOF2
variant shader base <<EOF2
cp shaders/0001.spv.zst shaders/0000.spv.zst
EOF2
variant area dbase <<EOF2
"$PE" set $M scene.destruction.cell_size 8
EOF2
variant dshader dbase <<EOF2
"$PE" set $M params.0.default '[0.5, 0, 0, 0]'
EOF2
differ "$OUT/base/painted.sparse" "$OUT/mask/painted.sparse" "the mask variant changed nothing"
# both shading paths (--screen: the screen-space path's tile classification)
for path in "" --screen; do
    "$TR" $path "$OUT/base" "$OUT/heights=the heightfield's contents changed" \
        "$OUT/scale=max_height" "$OUT/texture=a texture" "$OUT/sampler=a texture" \
        "$OUT/mask=a painted mask changed" "$OUT/params=ok" "$OUT/shader=ok" ||
        fail "minimal $path"
    "$TR" $path "$OUT/dbase" "$OUT/area=the destructible area changed" "$OUT/dshader=ok" ||
        fail "destruction $path"
done
echo ok
