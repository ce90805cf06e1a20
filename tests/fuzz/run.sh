#!/bin/sh
# run.sh FUZZBUILD SECONDS [TARGET...] — run each libFuzzer target of a
# -DSPLAT_FUZZ=ON build for SECONDS from seeds made of the project's files
# (graph files, a pack built by the fuzz build's splatc: its manifest,
# combos.bin, painted.sparse and SPIR-V, the heightfield and mask rasters).
# Corpora grow in FUZZBUILD/corpus/TARGET; a finding stops that target with
# libFuzzer's report and a crash file in FUZZBUILD, and run.sh exits 1.
# Prints per target: seconds, executions, corpus size.
set -u
FB=$1 SECS=$2
shift 2
TARGETS=${*:-fuzz_parse fuzz_manifest fuzz_combos fuzz_sparse fuzz_heightfield fuzz_spirv fuzz_obj}
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
C="$FB/corpus"
mkdir -p "$C" && cd "$ROOT" || exit 2
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0
export LSAN_OPTIONS=suppressions=$ROOT/.ci/lsan.supp:print_suppressions=0
PACK="$FB/seed_pack"
if [ ! -f "$PACK/manifest.json" ]; then
    "$FB/compiler/splatc" build examples/minimal/scene.sg -o "$PACK" --no-cache > /dev/null ||
        { echo "run.sh: cannot build the seed pack"; exit 2; }
fi
seed() {   # TARGET FILES...: copy seeds once
    t=$1; shift
    mkdir -p "$C/$t"
    [ -n "$(ls -A "$C/$t")" ] && return 0
    for f in "$@"; do [ -f "$f" ] && cp "$f" "$C/$t/$(echo "$f" | tr / _)"; done
    return 0
}
seed fuzz_parse nodes/*.sg graphs/*.sg examples/*/*.sg tests/golden/*.sg
seed fuzz_manifest "$PACK/manifest.json"
seed fuzz_sparse "$PACK/painted.sparse"
mkdir -p "$C/fuzz_combos" "$C/fuzz_heightfield" "$C/fuzz_spirv"
# combos.bin of the seed pack with its header: 9 x 9 cells, its combination
# count, the offsets of its 5 levels (0, 162, 212, 230, 238)
[ -n "$(ls -A "$C/fuzz_combos")" ] || {
    printf '\010\010\004\000\000\000\000\000\242\000\000\000\324\000\000\000\346\000\000\000\356\000\000\000'
    cat "$PACK/combos.bin"; } > "$C/fuzz_combos/seed"
[ -n "$(ls -A "$C/fuzz_heightfield")" ] || {
    { printf '\000'; cat tests/scene/hf16.png; } > "$C/fuzz_heightfield/png"
    { printf '\001\020\000\020\000'; cat tests/scene/hf.r16; } > "$C/fuzz_heightfield/r16"
    { printf '\002\020\000\020\000'; cat tests/scene/mask.png; } > "$C/fuzz_heightfield/mask"
    printf '\003ncols 4\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 10\nNODATA_value -9999\n1 2 3 4\n5 6 -9999 8\n9 10 11 12\n' \
        > "$C/fuzz_heightfield/gdal_asc"; }
seed fuzz_obj tests/golden/inc/*.obj
[ -n "$(ls -A "$C/fuzz_spirv")" ] || for f in "$PACK"/shaders/*.spv.zst; do
    { printf '\001'; zstd -q -dc "$f"; } > "$C/fuzz_spirv/$(basename "$f" .zst)"; done
rc=0
for t in $TARGETS; do
    log="$FB/$t.log"
    SPLAT_FUZZ_PACK="$PACK" "$FB/tests/$t" -max_total_time="$SECS" -max_len=65536 -timeout=10 \
        -rss_limit_mb=3072 -artifact_prefix="$FB/$t-" -print_final_stats=1 "$C/$t" > "$log" 2>&1
    r=$?
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    echo "$t: $SECS s, ${execs:-?} executions, corpus $(ls "$C/$t" | wc -l) files, exit $r"
    if [ $r != 0 ]; then
        tail -40 "$log"
        rc=1
    fi
done
exit $rc
