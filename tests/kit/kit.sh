#!/bin/sh
# The shell test kit's own test (tests/lib.sh): each helper passes what it
# must pass and fails what it must fail, under sh -u and sh -eu.  Every
# failing case runs in a child shell whose exit status is checked, so a
# helper that lets a wrong case through fails here.
#   sh tests/kit/kit.sh
set -u
LIB=$(cd "$(dirname "$0")/.." && pwd)/lib.sh
T=$(mktemp -d "${TMPDIR:-/tmp}/splat-kit.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT
printf 'a\n' > "$T/a"; printf 'a\n' > "$T/a2"; printf 'b\n' > "$T/b"
# a command that crashes (SIGSEGV) after printing a line, as a splatc that
# dies halfway through its --stats would
printf '#!/bin/sh\necho "far atlas  1.5"\nkill -SEGV $$\n' > "$T/crash"
printf '#!/bin/sh\necho "far atlas  1.5"\n' > "$T/good"
chmod +x "$T/crash" "$T/good"
bad=0
# expect STATUS FLAGS SNIPPET: sh FLAGS runs lib.sh then SNIPPET; its exit
# status must be STATUS (0: passes, 1: fails the test)
expect() {
    printf '. "%s"\n%s\necho reached\n' "$LIB" "$3" > "$T/case.sh"
    (cd "$T" && ${KIT_SH:-sh} $2 "$T/case.sh") > "$T/out" 2> "$T/err"
    got=$?
    if [ "$got" != "$1" ]; then
        echo "FAIL: sh $2 '$3': exit $got, expected $1"; sed 's/^/    /' "$T/err"; bad=1
    elif [ "$1" = 0 ] && ! grep -qx reached "$T/out"; then
        echo "FAIL: sh $2 '$3' did not run to its end"; bad=1
    elif [ "$1" = 1 ] && ! grep -q '^FAIL: ' "$T/err"; then
        echo "FAIL: sh $2 '$3' failed without a FAIL: line"; bad=1
    fi
}
for flags in -u -eu; do
    expect 0 "$flags" 'must true'
    expect 1 "$flags" 'must false'
    expect 1 "$flags" 'must ./crash'
    expect 0 "$flags" 'must_fail false'
    expect 1 "$flags" 'must_fail true'
    expect 1 "$flags" 'must_fail ./crash'          # a crash is no error exit
    expect 1 "$flags" 'must_fail ./no-such-tool'   # 127: not run
    expect 0 "$flags" 'same a a2'
    expect 1 "$flags" 'same a b'
    expect 1 "$flags" 'same a missing'
    expect 1 "$flags" 'same missing a'
    expect 0 "$flags" 'differ a b'
    expect 1 "$flags" 'differ a a2'
    expect 1 "$flags" 'differ a missing'           # what `cmp -s a missing && fail` let through
    expect 1 "$flags" 'differ missing b'
    expect 0 "$flags" 'to o ./good; grep -q "far atlas" o'
    expect 1 "$flags" 'to o ./crash'
    expect 0 "$flags" 'get s "sed -n \"s/^far atlas  *//p\"" ./good; [ "$s" = 1.5 ] || fail "s=$s"'
    expect 1 "$flags" 'get s "sed -n \"s/^far atlas  *//p\"" ./crash'   # `./crash | sed` exits 0
    expect 1 "$flags" 'get s "exit 3" ./good'
    expect 0 "$flags" 'filter "tr a-z A-Z" ./good > o; grep -q "^FAR ATLAS" o'
    expect 1 "$flags" 'filter "tr a-z A-Z" ./crash > o'
    expect 1 "$flags" 's=$(filter "cat" ./crash) || exit 1'
done
# the hole the kit closes: without it, the pipe passes a crash
(cd "$T" && sh -u -c 's=$(./crash | sed -n "s/^far atlas  *//p"); [ "$s" = 1.5 ]') 2>/dev/null ||
    { echo "FAIL: the unprotected pipe did not pass the crash: this test shows nothing"; bad=1; }
[ $bad = 0 ] && echo "ok: tests/lib.sh"
exit $bad
