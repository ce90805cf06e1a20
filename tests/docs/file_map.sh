#!/bin/sh
# file_map.sh REPO DIR DOC: every file git tracks directly in DIR (a folder
# of REPO) has its line in the file map of DOC, a table row that starts
# `| NAME |`; and every row of that form names a file that exists.
#   sh tests/docs/file_map.sh . runtime runtime/DESIGN.md
set -u
. "$(dirname "$0")/../lib.sh"   # fail, to
cd "$1" || fail "no repository $1"
DIR=$2 DOC=$3
[ -f "$DOC" ] || fail "$DOC is missing"
T=$(mktemp -d "${TMPDIR:-/tmp}/splat-filemap.XXXXXX") || fail "mktemp"
trap 'rm -rf "$T"' EXIT
to "$T/tracked" git ls-files -- "$DIR"
# files directly in DIR, not in its subfolders
sed -n "s|^$DIR/\([^/]*\)$|\1|p" "$T/tracked" | sort > "$T/files"
[ -s "$T/files" ] || fail "git tracks no file in $DIR"
sed -n 's/^| \([A-Za-z0-9_.+-]*\.[A-Za-z0-9]*\|CMakeLists\.txt\) |.*/\1/p' "$DOC" | sort -u > "$T/rows"
bad=0
while read -r f; do
    grep -qxF "$f" "$T/rows" || { echo "FAIL: $DIR/$f has no line in $DOC's file map"; bad=1; }
done < "$T/files"
while read -r f; do
    [ -e "$DIR/$f" ] || { echo "FAIL: $DOC's file map names $f, which is not in $DIR"; bad=1; }
done < "$T/rows"
[ $bad = 0 ] || exit 1
echo "ok: $(wc -l < "$T/files" | tr -d ' ') files of $DIR, each with its line in $DOC"
