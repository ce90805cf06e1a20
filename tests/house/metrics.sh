#!/bin/sh
# metrics.sh BUILD_DIR: the rows of issue 32's before/after table, measured
# on the working tree and on BUILD_DIR (a configured and built tree):
#
#   files over 1,000 lines   source files (.c .h .cpp) outside tests/, not
#                            generated tables (a file whose first 3 lines say
#                            "generated"), over 1,000 lines (wc -l)
#   functions over 100 lines from the definition's first line (the last line
#                            at column 0 above the body's `{`) to the `}` at
#                            column 0 that closes it, in compiler/, runtime/
#                            and tests/bench's programs (.c .cpp)
#   duplicates               `duplicates` pairs over the tracked files outside
#                            tests/ (a copy of them, so no pair has a side in
#                            tests/), its first line's figures
#   headers installed        the headers `cmake --install BUILD_DIR` puts under
#                            include/ (the install rules as they stand)
#   rt_internal.h includes   files outside runtime/ that include rt_internal.h
#   call cycles              tests/house/cycles.sh on the object files of
#                            libsplatc and libsplatrt in BUILD_DIR
#
# Prints a Markdown table (metric, figure, detail) on stdout.  Run from
# anywhere; reads the repository this script is in.
#   sh tests/house/metrics.sh build
set -eu
. "$(dirname "$0")/../lib.sh"   # fail, must, to
[ $# = 1 ] || { echo "usage: sh tests/house/metrics.sh BUILD_DIR" >&2; exit 2; }
REPO=$(cd "$(dirname "$0")/../.." && pwd)
B=$(cd "$1" && pwd) || fail "no build folder $1"
T=$(mktemp -d "${TMPDIR:-/tmp}/splat-metrics.XXXXXX") || fail "mktemp"
trap 'rm -rf "$T"' EXIT
cd "$REPO"
row() { printf '| %s | %s | %s |\n' "$1" "$2" "$3"; }
echo "| metric | figure | detail |"
echo "|---|---:|---|"

# ---- files over 1,000 lines ---------------------------------------------------
to "$T/files" git ls-files -- '*.c' '*.h' '*.cpp'
: > "$T/big"
while read -r f; do
    case $f in tests/*) continue ;; esac
    [ -f "$f" ] || continue
    head -n 3 "$f" | grep -qi generated && continue
    n=$(wc -l < "$f")
    [ "$n" -gt 1000 ] && echo "$n $f" >> "$T/big"
done < "$T/files"
sort -rn "$T/big" > "$T/big.sorted"
row "source files over 1,000 lines (outside tests/)" "$(wc -l < "$T/big.sorted" | tr -d ' ')" \
    "$(awk '{ printf "%s%s %s", (NR > 1 ? ", " : ""), $2, $1 }' "$T/big.sorted")"

# ---- functions over 100 lines -------------------------------------------------
: > "$T/long"
for f in $(grep -E '^(compiler|runtime|tests/bench)/[^/]*\.(c|cpp)$' "$T/files"); do
    [ -f "$f" ] || continue
    awk -v file="$f" '
        /^[A-Za-z_]/ && !/^(typedef|struct|union|enum)\b/ { def = NR; sig = $0 }
        /^\{/ { start = def; name = sig; sub(/\(.*/, "", name); sub(/.*[ *]/, "", name); infn = 1; next }
        /^\}/ && infn { n = NR - start + 1; if (n > 100) print n, file ":" start, name; infn = 0 }
    ' "$f" >> "$T/long"
done
sort -rn "$T/long" > "$T/long.sorted"
row "functions over 100 lines (compiler/, runtime/, tests/bench/)" \
    "$(wc -l < "$T/long.sorted" | tr -d ' ')" \
    "$(awk '{ f = $2; sub(/:.*/, "", f); sub(/.*\//, "", f); printf "%s%s %s %s", (NR > 1 ? ", " : ""), f, $3, $1 }' "$T/long.sorted")"
row "functions over 150 lines" "$(awk '$1 > 150' "$T/long.sorted" | wc -l | tr -d ' ')" \
    "$(awk '$1 > 150 { f = $2; sub(/:.*/, "", f); sub(/.*\//, "", f); printf "%s%s %s %s", (n++ ? ", " : ""), f, $3, $1 }' "$T/long.sorted")"

# ---- duplicates outside tests/ ------------------------------------------------------
if command -v duplicates > /dev/null; then
    mkdir "$T/tree"
    to "$T/tracked" git ls-files
    grep -v '^tests/' "$T/tracked" | while read -r f; do
        [ -f "$f" ] && printf '%s\n' "$f"
    done > "$T/outside"
    must tar -cf "$T/tree.tar" -T "$T/outside"
    must tar -xf "$T/tree.tar" -C "$T/tree"
    (cd "$T/tree" && duplicates --seconds 300 --most 1) > "$T/dup" || fail "duplicates"
    head -n 1 "$T/dup" > "$T/dup.1"
    pairs=$(sed -n 's/^\([0-9][0-9]*\) pairs.*/\1/p' "$T/dup.1")
    case $(cat "$T/dup.1") in no\ duplicates*) pairs=0 ;; esac
    [ -n "$pairs" ] || fail "cannot read duplicates' first line: $(cat "$T/dup.1")"
    row "duplicates pairs (outside tests/)" "$pairs" "$(sed 's/|/\\|/g' "$T/dup.1")"
else
    row "duplicates pairs (outside tests/)" "n/a" "the duplicates tool is not installed"
fi

# ---- headers installed ----------------------------------------------------------------
must cmake --install "$B" --prefix "$T/prefix" > "$T/install.log"
[ -d "$T/prefix/include" ] || fail "cmake --install $B installed no include/ folder"
to "$T/headers.found" find "$T/prefix/include" -type f -name '*.h'
sed "s|^$T/prefix/include/||" "$T/headers.found" | sort > "$T/headers"
row "headers installed (cmake --install)" "$(wc -l < "$T/headers" | tr -d ' ')" \
    "$(awk '{ sub(/.*\//, ""); printf "%s%s", (NR > 1 ? " " : ""), $0 }' "$T/headers")"

# ---- includes of rt_internal.h outside runtime/ ----------------------------------------
grep -lE '^[[:space:]]*#[[:space:]]*include[[:space:]]*[<"]([^">]*/)?rt_internal\.h[">]' \
    $(grep -v '^runtime/' "$T/files") 2> /dev/null | sort > "$T/internal" || true
row "files outside runtime/ including rt_internal.h" "$(wc -l < "$T/internal" | tr -d ' ')" \
    "$(awk '{ printf "%s%s", (NR > 1 ? " " : ""), $0 }' "$T/internal")"

# the runtime's own programs (splatview), which the boundary covers too
grep -lE '^[[:space:]]*#[[:space:]]*include[[:space:]]*[<"]rt_internal\.h[">]' runtime/splatview.c \
    2> /dev/null > "$T/internal.prog" || true
row "runtime programs including rt_internal.h" "$(wc -l < "$T/internal.prog" | tr -d ' ')" \
    "$(awk '{ printf "%s%s", (NR > 1 ? " " : ""), $0 }' "$T/internal.prog")"

# ---- call cycles ---------------------------------------------------------------------------
for lib in compiler/CMakeFiles/splatc.dir:libsplatc runtime/CMakeFiles/splatrt.dir:libsplatrt; do
    dir=$B/${lib%%:*}
    find "$dir" -name '*.o' | sort > "$T/objs"
    [ -s "$T/objs" ] || fail "no object files under $dir (build $B first)"
    # exit 0: no cycle, 1: cycles (listed), anything else: cycles.sh failed
    sh "$REPO/tests/house/cycles.sh" $(cat "$T/objs") > "$T/cycles" && rc=0 || rc=$?
    [ $rc -le 1 ] || fail "cycles.sh on $dir: exit $rc"
    row "call cycles, ${lib#*:}" "$(wc -l < "$T/cycles" | tr -d ' ')" \
        "$(sed 's/^cycle of \([0-9]*\) files: /\1: /' "$T/cycles" | awk '{ printf "%s%s", (NR > 1 ? "; " : ""), $0 }')"
done
