# tests/lib.sh — the shell half of the test kit (issue 32), sourced by the
# test scripts before they change folder:
#
#     . "$(dirname "$0")/../lib.sh"
#
# POSIX sh has no pipefail: in `splatc build … | sed …` a crashing splatc
# leaves the status of sed, 0, and the test passes.  `cmp -s A B && fail`
# passes when B is missing (cmp exits 2).  These helpers check every status
# instead.  A pipe stays only where its first command reads a file (`sed …
# FILE | sort`): the program under test never writes into a pipe.
#
#   fail MSG...           print "FAIL: MSG" on stderr, exit 1.  A script may
#                         define its own fail after sourcing (one that counts
#                         failures and goes on); the helpers call whichever
#                         is defined.
#   must CMD ARGS...      run CMD; fail unless it exits 0 (the message names
#                         the command and its exit status or signal).
#   must_fail CMD ARGS... run CMD; fail unless it exits with an error (1 to
#                         125): 0 is a wrong success, 126/127 a command not
#                         run, above 128 a crash.
#   same A B [MSG]        both files exist and are byte-identical.
#   differ A B [MSG]      both files exist and differ.
#   to FILE CMD ARGS...   CMD's standard output into FILE; fail unless CMD
#                         exits 0.  Filter FILE afterwards.
#   get VAR FILTER CMD ARGS...
#                         VAR = CMD's output through FILTER, a shell command
#                         line reading stdin (e.g. "sed -n 's/^x //p'"): the
#                         output goes to a temporary file, CMD's status is
#                         checked, then FILTER reads the file and its status is
#                         checked too.  VAR is set in the calling shell, so a
#                         failure fails the test (a `$(…)` would only leave
#                         its subshell).
#   filter FILTER CMD ARGS...
#                         the same, writing the filtered output to stdout
#                         (`filter F cmd > file`).  Inside `$(…)` a failure
#                         leaves only the subshell: write `x=$(filter …) ||
#                         exit 1`, or use get.
#
# Every helper is safe under `set -eu`.

# the exit status RC in words: "exit RC" or "killed by signal N"
kit_status() {
    if [ "$1" -gt 128 ] && [ "$1" -lt 160 ]; then
        echo "killed by signal $(($1 - 128))"
    else
        echo "exit $1"
    fi
}

fail() { echo "FAIL: $*" >&2; exit 1; }

must() {
    "$@" && return 0
    kit_rc=$?
    fail "'$*': $(kit_status $kit_rc)"
}

must_fail() {
    "$@" && kit_rc=0 || kit_rc=$?
    if [ $kit_rc = 0 ]; then
        fail "'$*' succeeded, expected an error"
        return 1
    fi
    [ $kit_rc -ge 1 ] && [ $kit_rc -le 125 ] && return 0
    fail "'$*': $(kit_status $kit_rc), expected an error exit (1 to 125)"
}

# kit_files A B: both exist (named in the failure) and are regular files
kit_files() {
    for kit_f in "$1" "$2"; do
        [ -f "$kit_f" ] || { fail "$kit_f is missing (comparing $1 and $2)"; return 1; }
    done
}

same() {
    kit_files "$1" "$2" || return 1
    cmp -s "$1" "$2" && return 0
    fail "${3:-$1 and $2 differ}"
}

differ() {
    kit_files "$1" "$2" || return 1
    cmp -s "$1" "$2" && kit_rc=0 || kit_rc=$?
    [ $kit_rc = 1 ] && return 0
    if [ $kit_rc = 0 ]; then fail "${3:-$1 and $2 are identical}"; else fail "cmp $1 $2: exit $kit_rc"; fi
}

to() {
    kit_out=$1
    shift
    "$@" > "$kit_out" && return 0
    kit_rc=$?
    fail "'$*' > $kit_out: $(kit_status $kit_rc)"
}

# kit_tmp: a fresh temporary file's name in $kit_tmp
kit_tmp() {
    kit_tmp=$(mktemp "${TMPDIR:-/tmp}/splat-test.XXXXXX") || fail "mktemp failed"
}

filter() {
    kit_filter=$1
    shift
    kit_tmp || return 1
    "$@" > "$kit_tmp" && kit_rc=0 || kit_rc=$?
    if [ $kit_rc != 0 ]; then
        rm -f "$kit_tmp"
        fail "'$*': $(kit_status $kit_rc)"
        return 1
    fi
    (eval "$kit_filter") < "$kit_tmp" && kit_rc=0 || kit_rc=$?
    if [ $kit_rc != 0 ]; then
        rm -f "$kit_tmp"
        fail "the filter '$kit_filter' of '$*': $(kit_status $kit_rc)"
        return 1
    fi
    rm -f "$kit_tmp"
}

get() {
    kit_var=$1
    shift
    kit_tmp || return 1
    kit_get_out=$kit_tmp
    filter "$@" > "$kit_get_out" || { rm -f "$kit_get_out"; return 1; }
    # $(…) strips trailing newlines, as VAR=$(CMD | FILTER) would
    kit_val=$(cat "$kit_get_out")
    rm -f "$kit_get_out"
    eval "$kit_var=\$kit_val"
}
