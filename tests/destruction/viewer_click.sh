#!/bin/sh
# The viewer makes a crater where the mouse clicks: viewer_click.sh SPLATVIEW
# IMGCHECK PACK OUTDIR.  The mask view of burnt_dirt is all black before
# (checked) and shows the crater after a click at the window's centre.
set -u
SV=$1 IC=$2 PACK=$3 OUT=$4
mkdir -p "$OUT"
command -v xvfb-run > /dev/null || { echo "SKIP: no xvfb-run"; exit 77; }   # CTest SKIP_RETURN_CODE
fail() { echo "FAIL: $*"; exit 1; }
xvfb-run -a -s "-screen 0 640x480x24" "$SV" "$PACK" --size 320x320 --camera-preset above \
    --view mask:burnt_dirt \
    --script "frames=2;screenshot=$OUT/before.png;click=160,160;frames=2;screenshot=$OUT/click.png;quit" \
    > "$OUT/viewer.log" 2>&1
rc=$?
cat "$OUT/viewer.log"
[ $rc = 0 ] || fail "viewer exit $rc"
black=$("$IC" count "$OUT/before.png" 0,0,0)
[ "$black" = 102400 ] || fail "the mask shows destruction before any click ($black of 102400 black)"
grep -q "^crater: done" "$OUT/viewer.log" || fail "the click made no crater"
black=$("$IC" count "$OUT/click.png" 0,0,0)
echo "black pixels after the click: $black of 102400"
# a 24 m crater seen from 700 m over 320 pixels: ~280 pixels
[ "$black" -lt 102200 ] || fail "no crater in the picture after the click"
echo ok
