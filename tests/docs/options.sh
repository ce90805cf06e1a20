#!/bin/sh
# README.md's option lists are the programs' option tables (compiler/args.h):
# each region between "<!-- options: COMMAND -->" and "<!-- /options -->"
# must be, byte for byte, a blank line, `COMMAND --help-markdown`'s output
# and a blank line.  Fails with the diff when a table changed and the
# README did not (or the README was edited by hand); --update rewrites the
# regions instead.
#   options.sh [--update] README.md BINDIR_OF_SPLATC BINDIR_OF_SPLATVIEW
set -eu
update=0
if [ "$1" = --update ]; then update=1; shift; fi
README=$1 SPLATC_DIR=$2 SPLATVIEW_DIR=$3
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
regions=$(sed -n 's/^<!-- options: \(.*\) -->$/\1/p' "$README")
# every program's list is there (a region deleted with its list fails too)
for want in "splatc" "splatc build" "splatview"; do
    echo "$regions" | grep -qx "$want" ||
        { echo "FAIL: $README has no '<!-- options: $want -->' region"; exit 1; }
done
n=0
for cmd in $(echo "$regions" | tr ' ' '+'); do
    cmd=$(echo "$cmd" | tr '+' ' ')
    prog=${cmd%% *} rest=
    [ "$prog" = "$cmd" ] || rest=${cmd#* }
    case $prog in
    splatc) bin=$SPLATC_DIR/splatc ;;
    splatview) bin=$SPLATVIEW_DIR/splatview ;;
    *) echo "FAIL: no program '$prog' for the region '$cmd'"; exit 1 ;;
    esac
    # $rest is a subcommand word or empty: split on purpose
    # shellcheck disable=SC2086
    "$bin" $rest --help-markdown > "$TMP/$n.md" ||
        { echo "FAIL: '$cmd --help-markdown' exited $?"; exit 1; }
    [ -s "$TMP/$n.md" ] || { echo "FAIL: '$cmd --help-markdown' printed nothing"; exit 1; }
    n=$((n + 1))
done
awk -v dir="$TMP" '
    /^<!-- options: .* -->$/ {
        print; print ""
        f = dir "/" i++ ".md"
        while ((getline line < f) > 0) print line
        close(f); print ""; skip = 1; next
    }
    /^<!-- \/options -->$/ { skip = 0 }
    !skip { print }
    END { if (skip) { print "unclosed options region" > "/dev/stderr"; exit 1 } }
' "$README" > "$TMP/README.md"
if [ $update = 1 ]; then
    cp "$TMP/README.md" "$README"
    echo "options.sh: $n option lists written into $README"
    exit 0
fi
diff -u "$README" "$TMP/README.md" || {
    echo "FAIL: $README's option lists differ from the programs' tables:"
    echo "      sh tests/docs/options.sh --update README.md build/compiler build/runtime"
    exit 1
}
echo "options.sh: $n option lists match their tables"
