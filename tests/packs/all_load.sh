#!/bin/sh
# Every pack the suite built loads: all_load.sh SPLATVIEW BUILDDIR
# Runs after every other test (CTest DEPENDS, top-level CMakeLists.txt).
# Each folder under BUILDDIR/tests and BUILDDIR/examples whose manifest.json
# says "splatc-pack" goes through `splatview PACK --check` (the pack loaded
# and checked, a renderer set up on the device: uploads, layouts, the
# runtime's own pipelines) with the validation layer on: a pack that
# splatc built and the runtime refuses fails here.  Left out: the packs the
# suite corrupts on purpose after building them (below).
set -u
SV=$1 B=$2
fail() { echo "FAIL: $*"; exit 1; }
corrupted='/tests/corrupt/c/|/tests/render/out/bad_packs/|/tests/far/bad$|/tests/mips/bad\.pack$|/fuzz/|/tests/vector/hostile/'
list=$(find "$B/tests" "$B/examples" -name manifest.json 2>/dev/null |
       xargs grep -l '"splatc-pack"' 2>/dev/null | sed 's|/manifest.json$||' |
       grep -Ev "$corrupted" | sort)
n=$(echo "$list" | grep -c . || true)
[ "$n" -ge 10 ] || fail "only $n packs under $B: run the whole suite first"
bad=0
for p in $list; do
    if ! out=$(SPLAT_VALIDATE=1 timeout 120 "$SV" "$p" --check 2>&1); then
        echo "FAIL: $p: $out"
        bad=$((bad + 1))
    fi
done
[ $bad = 0 ] || fail "$bad of $n packs the suite built are refused by the runtime"
echo "ok: all $n packs the suite built load in splatview"
