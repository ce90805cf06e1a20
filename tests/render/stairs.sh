#!/bin/sh
# stairs.sh SPLATVIEW STAIRS PACK OUT — issue 31's stair-step measure:
# colorado's valley camera, the mask view of snowfield, 1280x720, rendered
# by both shading paths.  The 0.5 contour of the mask, where it is a
# resolved edge (no silhouette, no one-pixel step: stairs.c STEEP), must
# follow a cubic spline with knots every 12 px (about 4 heightfield texels
# there) within 1 px RMS and 1.5 px at most.  With the terrain inputs
# bilinear between texels (before issue 31) the one such edge, on the west
# shoulder of the Blanca massif, measured 1.06 px RMS, 2.23 px at most;
# with the B-spline 0.36 px and 0.95 px.
set -e
splatview=$1 stairs=$2 pack=$3 out=$4
mkdir -p "$out"
for path in screen forward; do
    "$splatview" "$pack" --headless --shading $path --camera-preset valley \
        --view mask:snowfield --no-undergrowth --size 1280x720 \
        -o "$out/valley_mask_$path.png" --float-out "$out/valley_mask_$path.f32"
    echo "$path:"
    STAIRS_DEBUG="$out/valley_edge_$path.png" "$stairs" measure "$out/valley_mask_$path.f32" 12 1 1.5
done
