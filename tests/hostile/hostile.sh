#!/bin/sh
# hostile.sh SPLATC CASE — hostile inputs to `splatc build` (issue 34), run
# from the repository root by CTest (tests/hostile/suite.cmake), one CASE
# per test.  Every command runs under `timeout`, so a hang fails the test
# instead of stalling it; every refusal must be a located error
# (FILE:LINE:COL: error:) with exit status 1 and no pack written.
#   special  a FIFO, a character device (/dev/null), a folder, a unix
#            socket and a symbolic link to /dev/zero as the heightfield
#            (PNG and GDAL), an import, a texture, a painted mask (PNG and
#            GDAL) and an OBJ mesh
#   limits   values the runtime would refuse, refused at build time: a
#            texture whose header says 100000 x 100000, an OBJ vertex at
#            5000 m, undergrowth densities over the instance buffer,
#            max_height 1e300 (GDAL rasters at +-1.7e308: world.test_gdal)
#   mesh     OBJ files refused before tinyobjloader: `v nan`, a face of
#            100000 corners, a file over 64 MiB (sparse: nothing is read);
#            the rest of the text checks are unit.test_mesh's
#   masks    40 placed 16384^2 masks from one small PNG (BIG_PNG writes it),
#            one read by a material: builds, decoding that one only (max
#            RSS under 1 GB where /usr/bin/time measures it, unless
#            SANITIZE); 9 read ones: refused from their headers (over
#            splatc's 2 GiB bound) before any is decoded
#   depfile  an unwritable --depfile over an existing pack: the build fails
#            and the old pack stays byte-identical
set -u
SPLATC=$1
CASE=$2
BIG_PNG=${3:-}          # masks: tests/hostile/big_png
SANITIZE=${4:-OFF}      # masks: ON under ASan (no memory bound then)
TMP=$(mktemp -d "${TMPDIR:-/tmp}/splatc_hostile.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
fails=0
SECONDS_MAX=30     # a refusal takes well under a second; a hang is killed

. "$(dirname "$0")/../lib.sh"   # differ (through the fail below)
# every failure counted, the cases go on
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# The base scene: a 16x16 heightfield, a texture, a painted mask, an OBJ
# mesh, all regular files, in folder $1.  It builds.
base_scene() {
    d=$1
    mkdir -p "$d"
    cp tests/scene/hf16.png "$d/hf16.png" && cp tests/scene/mask.png "$d/mask.png" &&
        cp tests/scene/mask8x8.png "$d/tex.png" || fail "copy fixtures"
    printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > "$d/m.obj"
    printf 'material lib_unused { out albedo = vec3(0.5, 0.5, 0.5) }\n' > "$d/lib.sg"
    cat > "$d/scene.sg" <<'SG'
import "nodes/compositors.sg"
import "lib.sg"
texture rock { file = "tex.png" }
material base {
    node uv : terrain.uv
    node t : sample { tex = rock, uv = uv.out }
    out albedo = t.rgb
    undergrowth "m.obj" { density = 1 }
}
material west_paint {
    node p : painted { mask = "west" }
    out mask   = p.out
    out albedo = vec3(0.6, 0.5, 0.2)
}
scene s {
    heightfield = "hf16.png"
    size = 64 32
    max_height = 50
    materials = [base, west_paint]
    painted west = "mask.png"
}
SG
}

# build_fails DIR LINE WHAT: `splatc build DIR/scene.sg` exits 1 within
# SECONDS_MAX with an error located at DIR/scene.sg:LINE, writes no pack,
# and no sanitizer speaks.
build_fails() {
    dir=$1 line=$2 what=$3
    start=$(date +%s)
    timeout "$SECONDS_MAX" "$SPLATC" build "$dir/scene.sg" -o "$dir/pack" -I . \
        > "$dir/out" 2> "$dir/err"
    got=$?
    took=$(( $(date +%s) - start ))
    if [ "$got" != 1 ]; then
        fail "$what: exit $got after ${took}s, expected 1"; sed 's/^/    /' "$dir/err" | head -10
        return
    fi
    grep -q "^$dir/scene.sg:$line:[0-9]*: error: " "$dir/err" ||
        { fail "$what: no error at scene.sg:$line"; sed 's/^/    /' "$dir/err" | head -10; }
    if grep -q "Sanitizer" "$dir/err"; then
        fail "$what: sanitizer report"; grep -A5 Sanitizer "$dir/err" | head -20
    fi
    [ -e "$dir/pack" ] && fail "$what: a failed build wrote a pack"
    [ "$took" -le 10 ] || fail "$what: took ${took}s"
}

# make_special KIND PATH: replace PATH by a special file of KIND; false
# when this machine cannot make one.
make_special() {
    rm -rf "$2"
    case $1 in
    fifo)    mkfifo "$2" ;;
    chardev) ln -s /dev/null "$2" ;;
    zero)    ln -s /dev/zero "$2" ;;
    folder)  mkdir "$2" ;;
    socket)  command -v python3 > /dev/null &&
             python3 -c 'import socket, sys; socket.socket(socket.AF_UNIX).bind(sys.argv[1])' "$2" ;;
    esac
}

case $CASE in
special)
    base_scene "$TMP/ok"
    timeout 120 "$SPLATC" build "$TMP/ok/scene.sg" -o "$TMP/ok/pack" -I . > /dev/null 2> "$TMP/ok/err" ||
        { fail "the base scene does not build"; cat "$TMP/ok/err"; }
    n=0
    for kind in fifo chardev zero folder socket; do
        # slot: file name in the scene, the line that names it, a sed
        # edit of the scene that uses it (GDAL variants rename the file)
        for slot in hf hf_gdal import texture mask mask_gdal mesh ugtex; do
            d="$TMP/$kind.$slot"
            base_scene "$d"
            case $slot in
            hf)        file=hf16.png  line=16 ;;
            hf_gdal)   file=hf.tif    line=16; sed -i -e 's/"hf16.png"/"hf.tif"/' -e '/max_height/d' "$d/scene.sg" ;;
            import)    file=lib.sg    line=2 ;;
            texture)   file=tex.png   line=3 ;;
            mask)      file=mask.png  line=20 ;;
            mask_gdal) file=mask.tif  line=20; sed -i 's/"mask.png"/"mask.tif"/' "$d/scene.sg" ;;
            mesh)      file=m.obj     line=8 ;;
            ugtex)     file=ut.png    line=8
                       sed -i 's/undergrowth "m.obj" { density = 1 }/undergrowth "m.obj" { density = 1, texture = "ut.png" }/' "$d/scene.sg" ;;
            esac
            if ! make_special "$kind" "$d/$file"; then
                echo "skip: cannot make a $kind here"
                continue
            fi
            n=$((n + 1))
            build_fails "$d" "$line" "$kind as $slot"
        done
    done
    echo "$n special-file cases"
    [ "$n" -ge 28 ] || fail "only $n cases ran"
    ;;
limits)
    # a PNG header claiming 100000 x 100000 (stb_image refuses to say so)
    d="$TMP/lying_png"; base_scene "$d"
    printf '\211PNG\r\n\032\n\000\000\000\015IHDR\000\001\206\240\000\001\206\240\010\000\000\000\000\000\000\000\000' \
        > "$d/tex.png"
    build_fails "$d" 3 "texture header of 100000 x 100000"
    grep -q "100000 x 100000 texels, over the pack limit of 16384" "$d/err" ||
        fail "lying header: the message does not give the header's size"
    # an OBJ vertex at 5000 m (the runtime allows 1000)
    d="$TMP/far_vertex"; base_scene "$d"
    printf 'v 0 0 0\nv 5000 0 0\nv 0 1 0\nf 1 2 3\n' > "$d/m.obj"
    build_fails "$d" 8 "OBJ vertex at 5000 m"
    # two blocks at density 64: 128 per m^2, over the instance buffer every
    # device holds (about 83 per m^2); the error at the second block
    d="$TMP/density"; base_scene "$d"
    sed -i '8s/.*/    undergrowth grass { density = 64 } undergrowth stone { density = 64 }/' "$d/scene.sg"
    build_fails "$d" 8 "total undergrowth density 128"
    grep -q "128 MiB every device holds" "$d/err" || fail "density: the message lacks the limit"
    # one block at 64 fits
    d="$TMP/density_ok"; base_scene "$d"
    sed -i '8s/.*/    undergrowth grass { density = 64 }/' "$d/scene.sg"
    timeout 120 "$SPLATC" build "$d/scene.sg" -o "$d/pack" -I . > /dev/null 2> "$d/err" ||
        { fail "density 64 alone does not build"; cat "$d/err"; }
    # max_height far past any terrain
    d="$TMP/max_height"; base_scene "$d"
    sed -i 's/max_height = 50/max_height = 1e300/' "$d/scene.sg"
    build_fails "$d" 18 "max_height 1e300"
    ;;
mesh)
    d="$TMP/nan"; base_scene "$d"
    printf 'v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > "$d/m.obj"
    build_fails "$d" 8 "v nan"
    grep -q "line 1: 'v' value 'nan' is not a finite number" "$d/err" ||
        fail "v nan: the message lacks the OBJ line"
    d="$TMP/face"; base_scene "$d"
    { printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf'
      i=0; while [ $i -lt 1000 ]; do printf ' 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3 1'; i=$((i + 1)); done
      printf '\n'; } > "$d/m.obj"
    build_fails "$d" 8 "a face of 100000 corners"
    grep -q "a face of more than 1024 corners" "$d/err" || fail "face: wrong message"
    d="$TMP/huge"; base_scene "$d"
    truncate -s 65M "$d/m.obj" || fail "truncate"
    build_fails "$d" 8 "a 65 MiB OBJ file"
    grep -q "over the limit of 67108864" "$d/err" || fail "huge OBJ: wrong message"
    ;;
masks)
    d="$TMP/masks"; base_scene "$d"
    "$BIG_PNG" "$d/big.png" 16384 || fail "big_png"
    # mask 'west' (read by west_paint) and 39 others nobody reads, all
    # placed 16384^2 rasters over the terrain
    places=""
    i=0; while [ $i -lt 39 ]; do
        places="$places    painted unused$i = \"big.png\" { origin = 0 0, size = 64 32 }\n"
        i=$((i + 1)); done
    sed -i "s|    painted west = \"mask.png\"|${places}    painted west = \"big.png\" { origin = 0 0, size = 64 32 }|" "$d/scene.sg"
    [ "$(grep -c 'big.png' "$d/scene.sg")" = 40 ] || fail "masks: the scene has not 40 masks"
    if [ -x /usr/bin/time ]; then
        timeout 300 /usr/bin/time -f '%M' -o "$d/rss" "$SPLATC" build "$d/scene.sg" -o "$d/pack" \
            -I . > /dev/null 2> "$d/err" || { fail "40 placed masks, 1 read: no pack"; cat "$d/err"; }
        kb=$(tail -1 "$d/rss")
        echo "40 placed 16384^2 masks, 1 read: max RSS $((kb / 1024)) MiB"
        [ "$SANITIZE" = ON ] || [ "$kb" -lt 1048576 ] || fail "masks: max RSS ${kb} KiB, over 1 GiB"
    else
        timeout 300 "$SPLATC" build "$d/scene.sg" -o "$d/pack" -I . > /dev/null 2> "$d/err" ||
            { fail "40 placed masks, 1 read: no pack"; cat "$d/err"; }
    fi
    # nine read masks of 16384^2: 2304 MiB, refused at the ninth
    d="$TMP/masks_read"; base_scene "$d"
    "$BIG_PNG" "$d/big.png" 16384 || fail "big_png"
    i=0; places=""
    while [ $i -lt 9 ]; do
        places="$places    painted m$i = \"big.png\" { origin = 0 0, size = 64 32 }\n"
        i=$((i + 1)); done
    # one material reading the nine (summed), appended to the scene file
    {
        printf 'material nine {\n'
        i=0; while [ $i -lt 9 ]; do printf '    node p%d : painted { mask = "m%d" }\n' $i $i; i=$((i + 1)); done
        printf '    node s : add { a = p0.out, b = p1.out }\n'
        i=2; prev=s; while [ $i -lt 9 ]; do printf '    node s%d : add { a = %s.out, b = p%d.out }\n' $i $prev $i; prev=s$i; i=$((i + 1)); done
        printf '    out mask = %s.out\n}\n' $prev
    } > "$d/nine.sg"
    sed -i -e "s|    painted west = \"mask.png\"|${places}    painted west = \"mask.png\"|" \
           -e 's|materials = \[base, west_paint\]|materials = [base, west_paint, nine]|' \
           -e '2a import "nine.sg"' "$d/scene.sg"
    line=$(grep -n 'painted m8 ' "$d/scene.sg" | cut -d: -f1)
    build_fails "$d" "$line" "nine read 16384^2 masks"
    grep -q "over splatc's bound of 2048 MiB" "$d/err" || fail "masks: wrong message"
    ;;
depfile)
    d="$TMP/dep"; base_scene "$d"
    timeout 120 "$SPLATC" build "$d/scene.sg" -o "$d/pack" -I . > /dev/null 2> "$d/err" ||
        { fail "first build"; cat "$d/err"; }
    cp -r "$d/pack" "$TMP/pack.before" || fail "copy the pack"
    # a change, so the rebuild writes a new pack; the depfile's folder is
    # missing, so the depfile cannot be written
    sed -i 's/max_height = 50/max_height = 60/' "$d/scene.sg"
    timeout 120 "$SPLATC" build "$d/scene.sg" -o "$d/pack" -I . --depfile "$d/no/such/dir/pack.d" \
        > /dev/null 2> "$d/err"
    got=$?
    [ "$got" = 1 ] || fail "unwritable depfile: exit $got, expected 1"
    grep -q "pack.d" "$d/err" || fail "unwritable depfile: the error does not name it"
    if diff -r "$TMP/pack.before" "$d/pack" > "$TMP/diff"; then :; else
        fail "unwritable depfile: the old pack changed"; head -5 "$TMP/diff"; fi
    ls "$d" | grep -q 'tmp-' && fail "unwritable depfile: a temporary folder is left"
    # and with a writable one the same rebuild replaces the pack
    timeout 120 "$SPLATC" build "$d/scene.sg" -o "$d/pack" -I . --depfile "$d/pack.d" \
        > /dev/null 2> "$d/err" || { fail "rebuild with a depfile"; cat "$d/err"; }
    differ "$TMP/pack.before/manifest.json" "$d/pack/manifest.json" "the rebuild did not replace the pack"
    [ -s "$d/pack.d" ] || fail "no depfile written"
    ;;
*)
    echo "unknown case $CASE"; exit 2 ;;
esac

[ "$fails" = 0 ] || { echo "$fails failure(s)"; exit 1; }
echo "ok"
