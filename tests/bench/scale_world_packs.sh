#!/bin/sh
# scale_world_packs.sh — the scale_world worlds' packs, built here for the
# device (splatc links GDAL, which the device lacks), for
# tests/bench/scale_world_gpu.sh.
#
#   sh tests/bench/scale_world_packs.sh BUILD_DIR DEST [--counts "8 32 ..."]
#       [--hf N] [--xz FILE] [--no-build]
#
# Per material count M (default 8 32 64 128 256, each a multiple of 8): the
# world scale_world.sh measures (gen_world --textures M/8 8 HF 16, HF
# default 1024) built with `splatc build -j 2 --no-cache` into DEST/wM.
# --xz FILE: then one archive of them as packs/wM, its shader files
# decompressed first (zstd -d, the manifest's ".zst" names edited to
# match: xz finds more across plain SPIR-V and GLSL than inside zstd
# frames), `tar cf - packs | xz -6e --lzma2=dict=256MiB -T2` (tar sorted,
# mtimes 0: the same packs give the same bytes), written
# atomically; unpack it on the device with
#   tar -C build-h100 -xJf FILE      # build-h100/packs/wM
# --no-build: DEST's wM as they are (scale_world.sh --packs DEST's copies
# of its cold packs) go into the archive, nothing is built.
# Prints each pack's size and the archive's.  DEST is replaced world by
# world (only the wM this run builds).
set -eu
if [ $# -lt 2 ]; then
    echo "usage: sh tests/bench/scale_world_packs.sh BUILD_DIR DEST [--counts LIST] [--hf N] [--xz FILE]" >&2
    exit 2
fi
B=$(cd "$1" && pwd)
D=$2
shift 2
COUNTS="8 32 64 128 256" HF=1024 XZ="" BUILD=yes
while [ $# -gt 0 ]; do
    case $1 in
    --counts) COUNTS=$2; shift ;;
    --hf) HF=$2; shift ;;
    --xz) XZ=$2; shift ;;
    --no-build) BUILD=no ;;
    *) echo "scale_world_packs.sh: unknown option '$1'" >&2; exit 2 ;;
    esac
    shift
done
SPLATC=$B/compiler/splatc
GEN=$B/tests/gen_world
for t in "$SPLATC" "$GEN"; do
    [ -x "$t" ] || { echo "scale_world_packs.sh: $t is not built (cmake --build $B)" >&2; exit 1; }
done
if [ -n "$XZ" ]; then
    for t in zstd xz tar; do
        command -v $t > /dev/null || { echo "scale_world_packs.sh: --xz needs $t" >&2; exit 1; }
    done
fi
mkdir -p "$D"
D=$(cd "$D" && pwd)
REPO=$(cd "$(dirname "$0")/../.." && pwd)
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
cd "$REPO"   # the scenes import nodes/ from the project root
for M in $COUNTS; do
    if [ "$BUILD" = no ]; then
        [ -f "$D/w$M/manifest.json" ] || { echo "scale_world_packs.sh: no pack $D/w$M" >&2; exit 1; }
        du -sb "$D/w$M" | awk -v m="$M" '{ printf "w%s\t%.1f MB\n", m, $1 / 1e6 }'
        continue
    fi
    NB=$((M / 8))
    [ $((NB * 8)) -eq "$M" ] && [ "$NB" -ge 1 ] ||
        { echo "scale_world_packs.sh: $M materials is not a multiple of 8" >&2; exit 2; }
    echo "[scale_world_packs] w$M: gen_world --textures $NB 8 $HF 16, splatc build -j 2" >&2
    rm -rf "$T/world" && mkdir -p "$T/world"
    "$GEN" --textures "$T/world" "$NB" 8 "$HF" 16 > /dev/null
    rm -rf "$D/w$M" "$D/w$M.tmp"
    "$SPLATC" build "$T/world/scene.sg" -o "$D/w$M.tmp" -j 2 --no-cache > "$T/build.log" 2>&1 ||
        { cat "$T/build.log" >&2; rm -rf "$D/w$M.tmp"; exit 1; }
    mv "$D/w$M.tmp" "$D/w$M"
    du -sb "$D/w$M" | awk -v m="$M" '{ printf "w%s\t%.1f MB\n", m, $1 / 1e6 }'
done
if [ -n "$XZ" ]; then
    mkdir -p "$T/packs"
    for M in $COUNTS; do
        cp -R "$D/w$M" "$T/packs/w$M"
        find "$T/packs/w$M" -name '*.zst' -exec zstd -q -d --rm {} +
        sed -i 's/\.zst"/"/g' "$T/packs/w$M/manifest.json"
    done
    echo "[scale_world_packs] xz -6e (plain shaders: $(du -sb "$T/packs" | awk '{ printf "%.1f MB", $1 / 1e6 }'))" >&2
    (cd "$T" && tar --sort=name --mtime=@0 --owner=0 --group=0 --numeric-owner -cf - packs | xz -6e --lzma2=dict=256MiB -T2) > "$XZ.tmp"
    mv "$XZ.tmp" "$XZ"
    du -b "$XZ" | awk '{ printf "archive\t%.1f MB\n", $1 / 1e6 }'
fi
