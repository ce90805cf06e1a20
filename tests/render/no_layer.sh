#!/bin/sh
# A run that asks for validation where the layer is not installed must
# fail loudly, never pass without checking: no_layer.sh SPLATVIEW PACK OUTDIR
# hides the Khronos layer from the Vulkan loader (VK_LAYER_PATH names an
# empty folder, which replaces the loader's search of the system's layer
# folders) and expects exit 1 and RT_E_NO_VALIDATION's message.
set -u
SV=$1 PACK=$2 OUT=$3/no_layer
mkdir -p "$OUT/empty"
SPLAT_VALIDATE=1 VK_LAYER_PATH="$OUT/empty" "$SV" "$PACK" --headless --size 64x36 \
    -o "$OUT/x.png" > "$OUT/out.txt" 2>&1
rc=$?
cat "$OUT/out.txt"
[ "$rc" = 1 ] || { echo "FAIL: exit $rc, expected 1"; exit 1; }
grep -q "validation requested (SPLAT_VALIDATE=1) but VK_LAYER_KHRONOS_validation is not installed" \
    "$OUT/out.txt" || { echo "FAIL: no message naming the missing layer"; exit 1; }
echo ok
