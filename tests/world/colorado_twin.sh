#!/bin/sh
# colorado_twin.sh SPLATC GEN_GEOTIFF OUTDIR — examples/colorado's GeoTIFF
# twin: the heightfield and the three painted masks (the roads are splines)
# written as GeoTIFFs
# (UTM 13N, UInt16 heights with the PNG's scale and offset, Byte masks) by
# gen_geotiff, a copy of scene.sg that names them and leaves size,
# max_height and height_offset to the file, then both scenes built: every
# file of the two packs must be the same bytes, the manifest too once its
# "inputs" key (a hash of the input files) and the "source" paths (of the
# scene and graph files, relative to the pack) are left out.  The second
# build takes its SPIR-V from the first one's cache (same GLSL, same key).
# Run from the repository root.
set -eu
SPLATC=$1 GEN=$2 OUT=$3
fail() { echo "FAIL: $*" >&2; exit 1; }
rm -rf "$OUT"
mkdir -p "$OUT/twin/masks"
C=examples/colorado
"$GEN" $C/trinidad.png "$OUT/twin/trinidad.tif" 176473.5 111212.6 2962.242 1358.652
for m in field_wheat field_plowed field_fallow; do
    "$GEN" $C/masks/$m.png "$OUT/twin/masks/$m.tif" 176473.5 111212.6
done
sed -e 's/"trinidad.png"/"trinidad.tif"/' \
    -e 's/^\( *painted [a-z_]* *= *"masks\/[a-z_]*\)\.png"/\1.tif"/' \
    -e '/^ *size = /d' -e '/^ *max_height = /d' -e '/^ *height_offset = /d' \
    $C/scene.sg > "$OUT/twin/scene.sg"
grep -q '"trinidad.tif"' "$OUT/twin/scene.sg" || fail "sed did not rename the heightfield"
[ "$(grep -c '\.tif"' "$OUT/twin/scene.sg")" = 4 ] || fail "sed did not rename the masks"
grep -q 'max_height' "$OUT/twin/scene.sg" && fail "max_height left in the twin"

"$SPLATC" build $C/scene.sg -o "$OUT/png.pack" --cache "$OUT/cache" -j 2 2> "$OUT/png.err" ||
    { cat "$OUT/png.err"; fail "the PNG scene does not build"; }
SPLATC_PATH=$(pwd) "$SPLATC" build "$OUT/twin/scene.sg" -o "$OUT/tif.pack" --cache "$OUT/cache" -j 2 \
    2> "$OUT/tif.err" || { cat "$OUT/tif.err"; fail "the GeoTIFF twin does not build"; }
grep -q 'error' "$OUT/tif.err" && { cat "$OUT/tif.err"; fail "errors from the twin"; }

(cd "$OUT/png.pack" && find . -type f | sort) > "$OUT/png.files"
(cd "$OUT/tif.pack" && find . -type f | sort) > "$OUT/tif.files"
cmp "$OUT/png.files" "$OUT/tif.files" || fail "the packs hold different files"
n=0
while read -r f; do
    if [ "$f" = ./manifest.json ]; then
        for p in png tif; do
            grep -v -e '"inputs"' -e '"source":' "$OUT/$p.pack/$f" > "$OUT/$p.manifest"
        done
        cmp "$OUT/png.manifest" "$OUT/tif.manifest" || fail "manifests differ"
    else
        cmp "$OUT/png.pack/$f" "$OUT/tif.pack/$f" || fail "$f differs"
    fi
    n=$((n + 1))
done < "$OUT/png.files"
echo "colorado GeoTIFF twin: $n files, the same pack"
