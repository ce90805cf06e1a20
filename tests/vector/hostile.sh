#!/bin/sh
# vectors.bin is untrusted input (runtime/pack_sections.c rt_pk_read_vectors): a
# copy of the probe pack with its vectors.bin or manifest entry corrupted
# one way at a time must be refused by splatview --check (exit non-zero,
# an error naming vectors), never loaded or crashed on; the intact copy
# loads.
#   hostile.sh SPLATVIEW PACK OUTDIR
set -u
SV=$1 PACK=$2 OUT=$3/hostile
fail() { echo "FAIL: $*"; exit 1; }
export SPLAT_VALIDATE=1
word() {   # word N of vectors.bin's buffer (after the 16-byte header)
    od -An -tu4 -j $((16 + 4 * $2)) -N4 "$1" | tr -d ' '
}
put() {    # put FILE WORD VALUE: little-endian u32 at buffer word WORD
    v=$3
    printf "$(printf '\\%03o\\%03o\\%03o\\%03o' $((v & 255)) $((v >> 8 & 255)) \
        $((v >> 16 & 255)) $((v >> 24 & 255)))" |
        dd of="$1" bs=1 seek=$((16 + 4 * $2)) conv=notrunc 2>/dev/null || fail "dd"
}
fresh() {
    rm -rf "$OUT/$1" && mkdir -p "$OUT" && cp -r "$PACK" "$OUT/$1" || fail "copy"
    F="$OUT/$1/vectors.bin"
}
refused() {   # refused NAME: --check fails and says why
    if "$SV" "$OUT/$1" --check > "$OUT/$1.log" 2>&1; then
        fail "$1: the corrupt pack loaded"
    fi
    st=$?
    [ $st -lt 128 ] || fail "$1: splatview crashed (status $st)"
    grep -q "vectors" "$OUT/$1.log" || { cat "$OUT/$1.log"; fail "$1: no error naming vectors"; }
    echo "refused $1: $(head -1 "$OUT/$1.log")"
}
fresh intact
"$SV" "$OUT/intact" --check > "$OUT/intact.log" 2>&1 || { cat "$OUT/intact.log"; fail "the intact pack does not load"; }
ncx=$(word "$F" 0) ncz=$(word "$F" 1) ns=$(word "$F" 2) nseg=$(word "$F" 3) nent=$(word "$F" 4)
cells=$((8 + 4 * ns)) ent=$((8 + 4 * ns + 6 * ncx * ncz))
segs=$((ent + nent))
echo "vectors.bin: $ncx x $ncz cells, $ns shapes, $nseg segments, $nent entries"
[ "$nent" -gt 0 ] && [ "$nseg" -gt 0 ] || fail "the probe pack has no segments listed"

fresh truncated;  truncate -s -4 "$F";                    refused truncated
fresh magic;      printf 'X' | dd of="$F" bs=1 seek=0 conv=notrunc 2>/dev/null; refused magic
fresh version;    printf '\002' | dd of="$F" bs=1 seek=8 conv=notrunc 2>/dev/null; refused version
fresh shapes;     put "$F" 2 $((ns + 1));                   refused shapes
fresh grid;       put "$F" 0 100000;                        refused grid
fresh entry;      put "$F" $ent $nseg;                      refused entry
fresh count;      put "$F" $((cells + 1)) 65;               refused count
fresh first;      put "$F" $cells $nent; put "$F" $((cells + 1)) 1; refused first
fresh nan;        put "$F" $segs 2143289344;                refused nan     # a quiet NaN
fresh seg_shape;  put "$F" $((segs + 4)) $ns;               refused seg_shape
fresh width;      put "$F" 8 2139095040;                    refused width   # +inf
fresh inside;     put "$F" $((cells + 2)) $((1 << ns));     refused inside
fresh words
sed -i 's/"words": \([0-9]*\)/"words": 99/' "$OUT/words/manifest.json"
refused words
echo "hostile: every corrupt vectors.bin refused"
