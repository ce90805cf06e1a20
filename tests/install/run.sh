#!/bin/sh
# run.sh BUILD_DIR THIS_DIR CC CMAKE HEIGHTFIELD — the install test
# (suite.cmake).  Everything happens in a fresh folder under /tmp, which has
# no nodes/ folder above it, with $SPLATC_PATH unset: the scene's import of
# nodes/masks.sg can only be found in the prefix's share/splatc.
set -u
BUILD=$1 HERE=$2 CC=$3 CMAKE=$4 HF=$5
T=$(mktemp -d /tmp/splat_install.XXXXXX)
trap 'rm -rf "$T"' EXIT
unset SPLATC_PATH
fail() { echo "FAIL: $*"; exit 1; }
P="$T/prefix"
"$CMAKE" --install "$BUILD" --prefix "$P" > "$T/install.log" 2>&1 ||
    { cat "$T/install.log"; fail "cmake --install"; }
for f in bin/splatc bin/splatview lib/libsplatc.a lib/libsplatrt.a include/splatc/splatrt.h \
         include/splatc/splatc.h include/splatc/abi.h lib/pkgconfig/splatc.pc \
         lib/pkgconfig/splatrt.pc lib/cmake/splatc/splatcConfig.cmake \
         share/splatc/nodes/masks.sg share/splatc/nodes/compositors.sg; do
    [ -e "$P/$f" ] || fail "not installed: $f"
done
[ -e "$P/include/splatc/rt_internal.h" ] && fail "the runtime's internal header was installed"
# the runtime's public header stands on abi.h and the C library alone: no
# Vulkan, no compiler internals (rt_device and rt_pack are opaque)
grep '^#include' "$P/include/splatc/splatrt.h" | grep -v -e '<std[a-z]*\.h>' -e '"abi.h"' &&
    fail "splatrt.h includes more than abi.h and the C library"
# the compiler's internal headers stay in the source tree: splatc.h is
# libsplatc's one public header (abi.h is splatrt.h's include)
for h in sg_internal.h sg.h ir.h util.h scene.h scene_load.h compose.h build.h; do
    [ -e "$P/include/splatc/$h" ] && fail "an internal header was installed: $h"
done
for h in "$P"/include/splatc/*.h; do
    case ${h##*/} in
    splatc.h|splatrt.h|abi.h) ;;
    *) fail "a header not on the public list was installed: ${h##*/}" ;;
    esac
done

# 1. a scene outside any project, importing the node library, no -I
mkdir "$T/work" && cp "$HF" "$T/work/heightfield.png" || fail "copy"
cat > "$T/work/scene.sg" <<'SG'
import "nodes/compositors.sg"
import "nodes/masks.sg"
material ground {
    out albedo = vec3(0.3, 0.45, 0.2)
}
material rock {
    node m : slope_ramp { lo = 0.3, hi = 0.5 }
    out mask   = m.out
    out albedo = vec3(0.5, 0.5, 0.5)
}
scene outside {
    heightfield = "heightfield.png"
    size = 1024 1024
    max_height = 160
    materials = [ground, rock]
    compositor = linear_alpha
}
SG
( cd "$T/work" && "$P/bin/splatc" build scene.sg -o pack --no-cache --depfile pack.d ) \
    > "$T/build.log" 2>&1 || { cat "$T/build.log"; fail "installed splatc build"; }
[ -f "$T/work/pack/manifest.json" ] || fail "no pack"
grep -q "$P/share/splatc/nodes/masks.sg" "$T/work/pack.d" ||
    { cat "$T/work/pack.d"; fail "masks.sg not read from the prefix"; }

# 2. a tiny C program against libsplatrt: pkg-config, then find_package
cat > "$T/work/tiny.c" <<'C'
#include <stdio.h>
#include <string.h>
#include <splatrt.h>
#include <splatc.h>
int main(void)
{
    /* a runtime function (libsplatrt) and compiler ones (libsplatc,
     * through its one public header) */
    char views[256];
    rt_view_list(views, sizeof views);
    sg_diags d;
    sg_diags_init(&d);
    sg_diags_free(&d);
    printf("%s %s %s\n", rt_view_name(SPLAT_VIEW_FINAL), views, splatc_version());
    return strncmp(views, "final|", 6) != 0 || !*splatc_version();
}
C
export PKG_CONFIG_PATH="$P/lib/pkgconfig"
pkg-config --exists splatrt || fail "pkg-config does not find splatrt"
# shellcheck disable=SC2046
"$CC" -o "$T/work/tiny_pc" "$T/work/tiny.c" $(pkg-config --cflags --libs splatrt) \
    > "$T/pc.log" 2>&1 || { cat "$T/pc.log"; fail "link through pkg-config"; }
"$T/work/tiny_pc" || fail "the pkg-config program failed"
# the opaque handles from the installed header: a missing pack is refused
# with a message, and no handle comes back
cat > "$T/work/opaque.c" <<'C'
#include <stdio.h>
#include <splatrt.h>
int main(void)
{
    rt_pack *p = (rt_pack *)&p;
    rt_error e = { 0 };
    bool ok = rt_pack_open("no such pack", &p, &e);
    printf("%s\n", e.msg ? e.msg : "(no message)");
    int bad = ok || p != NULL || e.id == RT_OK || !e.msg;
    rt_error_clear(&e);
    rt_pack_close(NULL);
    return bad || rt_device_close(NULL) != 0;
}
C
# shellcheck disable=SC2046
"$CC" -o "$T/work/opaque" "$T/work/opaque.c" $(pkg-config --cflags --libs splatrt) \
    > "$T/opaque.log" 2>&1 || { cat "$T/opaque.log"; fail "the opaque handles do not build"; }
"$T/work/opaque" || fail "rt_pack_open on a missing folder"

mkdir "$T/cm" && cp "$T/work/tiny.c" "$T/cm/" || fail "copy"
cat > "$T/cm/CMakeLists.txt" <<'CM'
cmake_minimum_required(VERSION 3.25)
project(tiny C CXX)
find_package(splatc REQUIRED)
add_executable(tiny tiny.c)
target_link_libraries(tiny splatc::splatrt)
CM
"$CMAKE" -S "$T/cm" -B "$T/cm/build" -DCMAKE_PREFIX_PATH="$P" -DCMAKE_C_COMPILER="$CC" \
    > "$T/cm.log" 2>&1 && "$CMAKE" --build "$T/cm/build" >> "$T/cm.log" 2>&1 ||
    { cat "$T/cm.log"; fail "link through find_package(splatc)"; }
"$T/cm/build/tiny" || fail "the find_package program failed"
echo ok
