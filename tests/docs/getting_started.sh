#!/bin/sh
# getting_started.sh DOC BINDIR... — follow docs/getting-started.md verbatim:
# its ```sh blocks, in order, as one script (`set -eu`: the first failing
# command fails the test), in an empty folder outside the repository, with
# the built splatc and splatview first on PATH (BINDIR...) and nothing else
# from the repository.  ```console blocks are shown, not run (a window, or
# an example of an error).
set -u
DOC=$1; shift
[ -r "$DOC" ] || { echo "FAIL: cannot read $DOC"; exit 1; }
for d in "$@"; do d=$(cd "$d" && pwd) || exit 1; PATH="$d:$PATH"; done
export PATH
unset SPLATC_PATH
WORK=$(mktemp -d "${TMPDIR:-/tmp}/splat_getting_started.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
# the sh blocks, verbatim
awk '/^```sh[ \t]*$/ { on = 1; n++; print "echo \"--- step " n "\""; next }
     /^```/ { on = 0; next }
     on { print }' "$DOC" > "$WORK/steps.sh"
steps=$(grep -c '^echo "--- step' "$WORK/steps.sh")
[ "$steps" -ge 8 ] || { echo "FAIL: only $steps sh blocks in $DOC"; exit 1; }
mkdir "$WORK/run"
cd "$WORK/run" || exit 1
if ! sh -eu "$WORK/steps.sh"; then
    echo "FAIL: a command of $DOC failed (the last step shown above)"
    exit 1
fi
# what the guide promises to have made
for f in first-scene/pack/manifest.json first-scene/first.png first-scene/ridge.png \
         first-scene/low_snow.png first-scene/swatch_rock.png; do
    [ -s "$f" ] || { echo "FAIL: the guide made no $f"; exit 1; }
done
echo "$steps steps of $DOC ran"
