#!/bin/sh
# lanes_check.sh SPLATBENCH PACK OUTDIR — the model of bench_lanes.c
# (splatbench render --lanes) against this device's own counters: for each
# path, the layers view's sets and evaluated counts must give the counting
# frame's layers needed and evaluated per pixel (the CSV, the same frame),
# and the assignment the shading pass uses now ("rows"), predicted for this
# device's subgroup size, must give the measured efficiency.  lavapipe's
# subgroups are 8 lanes; a device of 32 or 64 matches that column.
set -u
SB=$1 PACK=$2 OUT=$3
mkdir -p "$OUT"
fail() { echo "FAIL: $*"; exit 1; }
for path in topdown grazing; do
    rm -f "$OUT/$path.csv"
    "$SB" render --pack "$PACK" --path "$path" --variant s=screen --size 256x144 \
        --frames 2 --warmup 0 --lanes --csv "$OUT/$path.csv" > "$OUT/$path.txt" 2>&1 ||
        fail "splatbench ($path): $(tail -3 "$OUT/$path.txt")"
    cat "$OUT/$path.txt"
    awk -F, -v path="$path" '
        FNR == NR && FNR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
        FNR == NR { ev = $col["layers_evaluated"]; nd = $col["layers_needed"]; next }
        /^lanes s: [0-9]+ terrain pixels/ {
            px = $0; sub(/.*pixels, /, "", px); need = px + 0
            m = $0; sub(/.*device: /, "", m); meas = m + 0
            e = $0; sub(/.*efficiency /, "", e); eff = e + 0; have = 1
        }
        /^lanes s:   rows/ { split($0, f, " "); r8 = f[5] + 0; r32 = f[7] + 0; r64 = f[9] + 0; rows = 1 }
        END {
            d = absv(need - nd) > 2e-4 || absv(meas - ev) > 2e-4
            if (!have || !rows) { print "no lanes lines (" path ")"; exit 1 }
            if (need < 0.5 || meas < need) { print "implausible counts (" path ")"; exit 1 }
            if (d) { printf "%s: view %.4f / %.4f per pixel, counters %.4f / %.4f\n", path, need, meas, nd, ev; exit 1 }
            if (absv(eff - r8) > 0.011 && absv(eff - r32) > 0.011 && absv(eff - r64) > 0.011) {
                printf "%s: measured %.2f %%, rows predicts %.2f / %.2f / %.2f %%\n", path, eff, r8, r32, r64; exit 1
            }
        }
        function absv(x) { return x < 0 ? -x : x }
    ' "$OUT/$path.csv" "$OUT/$path.txt" || fail "the lanes model disagrees with the counters ($path)"
done
echo "lanes model: ok"
