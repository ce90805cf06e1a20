#!/bin/sh
# The library boundary: internal_includes.sh ROOT
# Outside runtime/, only the files listed below include rt_internal.h:
# tests and tools that test or time the runtime's insides (pipelines,
# passes, packs' internals).  splatview and any new program or test must
# make do with the public splatrt.h, so this fails when another file
# includes the internal header, and when a listed file no longer does
# (then take it off the list).
set -eu
ROOT=$1
allowed="tests/bench/bench.h
tests/destruction/test_destruction.c
tests/extreme/extreme.c
tests/fuzz/fuzz_combos.c
tests/fuzz/fuzz_manifest.c
tests/fuzz/fuzz_spirv.c
tests/harness/harness.c
tests/pack/test_pack_checks.c
tests/reload/test_reload.c
tests/render/imgcheck.c
tests/render/make_fixture.c
tests/render/test_brdf.c
tests/render/test_dclass.c
tests/render/test_lighting.c
tests/render/test_shadow.c
tests/render/test_shadow_gpu.c
tests/render/test_undergrowth.c
tests/sparse/gpu_sparse.c
tests/unit/test_quadtree.c
tests/world/test_far.c
tests/world/test_holes.c
tests/world/test_placed.c"
cd "$ROOT"
found=$(grep -rl --include='*.c' --include='*.h' --include='*.cpp' '#include "rt_internal.h"' \
            compiler tests examples 2>/dev/null | sort || true)
bad=0
for f in $found; do
    echo "$allowed" | grep -qx "$f" || { echo "FAIL: $f includes rt_internal.h (use splatrt.h)"; bad=1; }
done
for f in $allowed; do
    [ -e "$f" ] || continue
    echo "$found" | grep -qx "$f" || { echo "FAIL: $f is listed but no longer includes rt_internal.h"; bad=1; }
done
[ $bad = 0 ] && echo "ok: $(echo "$found" | grep -c .) listed files include rt_internal.h, no other outside runtime/"
exit $bad
