#!/bin/sh
# check_links.sh ROOT [FILE.md...] — every relative link of the user docs
# resolves (CTest docs.links).  FILEs are relative to ROOT; by default
# README.md and docs/*.md.
#
# A link is an inline Markdown link or image, `[text](target)` or
# `![alt](target)`, outside fenced code blocks and `code spans`.  Targets
# with a scheme (https:, mailto:) are not checked.  A relative target must
# name an existing file or folder, relative to the linking file's folder;
# a `#anchor` must match a heading of the target Markdown file (or of the
# linking file itself for `#anchor` alone), slugged as GitHub does for
# ASCII headings: lower case, spaces to '-', other punctuation dropped.
#
# PENDING names files that another branch is writing and the docs already
# link; a link to one of them is reported as a note while the file is
# missing, and checked like any other once it exists.  Take a name out of
# the list when its file has been merged (none is pending now).
set -u
PENDING=""

ROOT=${1:?usage: check_links.sh ROOT [FILE.md...]}
shift
cd "$ROOT" || exit 1
[ $# -gt 0 ] || set -- README.md docs/*.md

# links FILE: "LINE<TAB>TARGET" for each inline link outside code
links() {
    awk '
        /^[ \t]*(```|~~~)/ { fence = !fence; next }
        fence { next }
        {
            line = $0
            gsub(/`[^`]*`/, "", line)
            while (match(line, /\]\([^)]*\)/)) {
                t = substr(line, RSTART + 2, RLENGTH - 3)
                sub(/[ \t].*$/, "", t)          # a "title" after the target
                printf "%d\t%s\n", NR, t
                line = substr(line, RSTART + RLENGTH)
            }
        }' "$1"
}

# anchors FILE: the slug of each heading, one a line
anchors() {
    awk '
        /^[ \t]*(```|~~~)/ { fence = !fence; next }
        fence { next }
        /^#+[ \t]/ {
            h = $0
            sub(/^#+[ \t]+/, "", h)
            sub(/[ \t]+#*[ \t]*$/, "", h)
            h = tolower(h)
            gsub(/[^a-z0-9 _-]/, "", h)
            gsub(/ /, "-", h)
            print h
        }' "$1"
}

fail=0
checked=0
tab=$(printf '\t')
for f in "$@"; do
    if [ ! -f "$f" ]; then
        echo "$f: no such file"
        fail=1
        continue
    fi
    dir=$(dirname "$f")
    list=$(links "$f") || { echo "$f: cannot read"; fail=1; continue; }
    [ -n "$list" ] || continue
    while IFS="$tab" read -r line target; do
        case $target in
            ''|[a-zA-Z]*:*) continue ;;       # empty, or a scheme (https:, mailto:)
        esac
        checked=$((checked + 1))
        path=${target%%#*}
        anchor=
        case $target in *'#'*) anchor=${target#*#} ;; esac
        if [ -z "$path" ]; then
            file=$f
        else
            case $path in
                /*) file=.$path ;;
                *) file=$dir/$path ;;
            esac
            # the file as named from ROOT, without ./ and dir/../
            norm=$(printf '%s\n' "$file" | awk -F/ '{
                n = 0
                for (i = 1; i <= NF; i++) {
                    if ($i == "" || $i == ".") continue
                    if ($i == ".." && n > 0 && p[n] != "..") { n--; continue }
                    p[++n] = $i
                }
                s = ""
                for (i = 1; i <= n; i++) s = s (i > 1 ? "/" : "") p[i]
                print s
            }')
            if [ ! -e "$file" ]; then
                pending=0
                for p in $PENDING; do
                    [ "$norm" = "$p" ] && pending=1
                done
                if [ $pending = 1 ]; then
                    echo "note: $f:$line: $target: not written yet (pending on another branch)"
                else
                    echo "$f:$line: broken link: $target ($norm does not exist)"
                    fail=1
                fi
                continue
            fi
        fi
        if [ -n "$anchor" ]; then
            case $file in
                *.md)
                    if ! anchors "$file" | grep -qxF -- "$anchor"; then
                        echo "$f:$line: broken link: $target (no heading '#$anchor' in $file)"
                        fail=1
                    fi ;;
            esac
        fi
    done <<EOF
$list
EOF
done
echo "docs.links: $checked relative links checked in $# files"
exit $fail
