#!/bin/sh
# cycles.sh OBJ... : the call cycles between source files.  An object file
# calls another when it has an undefined symbol the other defines; every
# strongly connected set of two or more files is printed on one line,
# largest first.  Exit status: 0 when there is none, 1 when there are.
set -eu
# (nm's output goes to a file and its status is checked: exit 2 when nm
# fails, not a silent "no cycle")
[ $# -gt 0 ] || { echo "usage: cycles.sh OBJ..." >&2; exit 2; }
T=$(mktemp -d "${TMPDIR:-/tmp}/splat-cycles.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
for o in "$@"; do
	[ -f "$o" ] || { echo "cycles.sh: $o: no such file" >&2; exit 2; }
	nm -g --defined-only "$o" > "$T/nm" || { echo "cycles.sh: nm $o failed" >&2; exit 2; }
	awk -v f="$o" 'NF == 3 { print "D", f, $3 }' "$T/nm"
	nm -u "$o" > "$T/nm" || { echo "cycles.sh: nm -u $o failed" >&2; exit 2; }
	awk -v f="$o" 'NF == 2 { print "U", f, $2 }' "$T/nm"
done > "$T/symbols"
awk '
function name(o,   n) { n = o; sub(/.*\//, "", n); sub(/\.o$/, "", n); return n }
$1 == "D" { def[$3] = $2; next }
$1 == "U" { use[++nu] = $2 SUBSEP $3 }
function strong(v,   i, w, c, n) {
	index_[v] = low[v] = ++counter; stack[++sp] = v; on[v] = 1
	for (i = 1; i <= deg[v]; i++) {
		w = adj[v, i]
		if (!(w in index_)) { strong(w); if (low[w] < low[v]) low[v] = low[w] }
		else if (on[w] && index_[w] < low[v]) low[v] = index_[w]
	}
	if (low[v] == index_[v]) {
		c = ""; n = 0
		do { w = stack[sp--]; on[w] = 0; c = c " " name(w); n++ } while (w != v)
		if (n > 1) sets[++ns] = n ":" c
	}
}
END {
	for (k = 1; k <= nu; k++) {
		split(use[k], p, SUBSEP); from = p[1]; to = def[p[2]]
		if (to == "" || to == from || ((from, to) in edge)) continue
		edge[from, to] = 1; adj[from, ++deg[from]] = to; node[from] = node[to] = 1
	}
	for (v in node) if (!(v in index_)) strong(v)
	for (k = 1; k <= ns; k++) print sets[k]
}' "$T/symbols" > "$T/sets" || exit 2
sort -t: -k1,1nr -k2 "$T/sets" | awk -F: '{ n++; print "cycle of " $1 " files:" $2 } END { exit n > 0 }'
