#!/bin/sh
# The vector masks on the GPU against the CPU reference:
#   probe.sh SPLATVIEW PROBE_CHECK PACK SCENE OUTDIR
# renders tests/vector/probe.sg's pack straight down at the albedo view
# (SPLAT_VALIDATE=1: any validation message fails) on both shading paths,
# once per value (road mask, road across, yard mask), and checks every
# pixel with probe_check (probe_check.c says how).
set -u
SV=$1 PC=$2 PACK=$3 SCENE=$4 OUT=$5/probe
mkdir -p "$OUT"
export SPLAT_VALIDATE=1
fail() { echo "FAIL: $*"; exit 1; }
for path in forward screen; do
    for which in 0 1 2; do
        img="$OUT/$path.$which.f32"
        "$SV" "$PACK" --headless --size 512x512 --camera-preset top --view albedo \
            --shading $path --param probe.which=$which --float-out "$img" -o "$OUT/$path.$which.png" ||
            fail "splatview ($path, value $which) exit $?"
        "$PC" "$SCENE" "$img" $which || fail "$path path, value $which (above)"
    done
done
echo "probe: the GPU's vector masks equal the CPU reference on both paths"
