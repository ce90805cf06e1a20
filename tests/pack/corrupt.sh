#!/bin/sh
# The corrupt-pack suite: corrupt.sh SPLATC SPLATVIEW PACKEDIT OUTDIR
#
# examples/minimal and tests/destruction/scene.sg are built by splatc
# (sparse BC4 and dense painted masks, a destructible area), then each case
# copies one of them, corrupts it in one way and hands it to
# `splatview --check` (the pack loaded, every shader read and validated,
# a renderer set up) with SPLAT_VALIDATE=1.  Every case must end with
# exit status 1, a message naming the pack file and the problem (the
# pattern given), no validation message, no picture, in under 5 s.  The
# classes: files that are not regular files inside the pack (FIFO, symlink
# to /dev/zero or out of the pack, folders, "..", absolute paths), SPIR-V
# that does not fit what it is bound to (wrong stage, a fragment shader of
# another pack or with a foreign interface: bindings, kinds, block sizes,
# push constants, spec constants, varyings, outputs), forged or truncated
# binary files (painted.sparse, combos.bin, heightfield, PNG), sizes over
# the pack limits (heightfield, textures, mips, painted layers, destruction
# grid, cells), painted_format against the shaders and the file,
# manifest fields of the wrong type or range, and the stand-ins' modules
# ("uber"."stand_in": types, files, roles, zstd frames).
set -u
SC=$1 SV=$2 PE=$3 OUT=$4
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
export SPLAT_VALIDATE=1
export SPLAT_PIPELINE_CACHE="$OUT/pipelines.bin"
fail() { echo "FAIL: $*"; exit 1; }
rm -rf "$OUT" && mkdir -p "$OUT/glsl" || fail "cannot make $OUT"
cd "$ROOT" || fail "no repository root"

"$SC" build examples/minimal/scene.sg -o "$OUT/bc4" --no-cache > /dev/null || fail "build bc4"
"$SC" build examples/minimal/scene.sg -o "$OUT/dense" --painted dense --no-cache > /dev/null ||
    fail "build dense"
"$SC" build tests/destruction/scene.sg -o "$OUT/destr" --no-cache > /dev/null || fail "build destr"
# with a far atlas: the atlas stand-in's module too (PACK.md "Stand-ins")
"$SC" build examples/minimal/scene.sg -o "$OUT/far" --far-atlas --far-bake cpu --no-cache \
    > /dev/null || fail "build far"
"$SV" "$OUT/bc4" --headless --size 32x32 -o "$OUT/ok.png" || fail "the intact pack does not render"
# The compiler writes each shader as a zstd frame (PACK.md "Compressed
# shaders"); a pack may also hold plain files, named without ".zst".  The
# cases that swap or cut shader files work on plain copies (unzst), so
# they corrupt the SPIR-V itself; the "zst_" cases below corrupt the
# frames of the compiler's own pack (bc4z).
unzst() {
    for f in "$1"/shaders/*.zst; do zstd -q -d --rm "$f" || fail "unzst $f"; done
    sed -i 's/\.zst"/"/g' "$1/manifest.json"
}
cp -r "$OUT/bc4" "$OUT/bc4z"
for p in bc4 dense destr far; do unzst "$OUT/$p"; done
"$SV" "$OUT/bc4" --headless --size 32x32 -o "$OUT/ok_plain.png" || fail "the plain pack does not render"
cmp -s "$OUT/ok.png" "$OUT/ok_plain.png" || fail "the plain pack renders another picture"

# Shaders with a foreign interface, compiled here: frag NAME BODY
frag() {
    printf '#version 450\n%s\n' "$2" > "$OUT/glsl/$1.frag"
    glslangValidator -V --target-env vulkan1.2 -o "$OUT/glsl/$1.spv" "$OUT/glsl/$1.frag" \
        > "$OUT/glsl/$1.log" 2>&1 || { cat "$OUT/glsl/$1.log"; fail "glslang: $1"; }
}
OUTC='layout(location = 0) out vec4 o;'
frag binding "$OUTC layout(set = 1, binding = 9) uniform sampler2D t; void main() { o = texture(t, vec2(0)); }"
frag kind "$OUTC layout(set = 0, binding = 1) uniform sampler2D t; void main() { o = texture(t, vec2(0)); }"
frag push "$OUTC layout(push_constant) uniform P { vec4 v[16]; } p; void main() { o = p.v[15]; }"
frag spec "$OUTC layout(constant_id = 7) const uint k = 1u; void main() { o = vec4(float(k)); }"
frag specfloat "$OUTC layout(constant_id = 0) const float k = 1.0; void main() { o = vec4(k); }"
frag outloc "layout(location = 2) out vec4 o; void main() { o = vec4(1); }"
frag inloc "$OUTC layout(location = 4) in vec3 v; void main() { o = vec4(v, 1); }"
frag intype "$OUTC layout(location = 1) in vec4 v; void main() { o = v; }"
frag ssbo "$OUTC layout(set = 0, binding = 30) buffer B { vec4 v[]; } b; void main() { o = b.v[0]; }"
frag params "$OUTC layout(set = 1, binding = 0) uniform Q { vec4 slot[64]; } q; void main() { o = q.slot[63]; }"
frag array "$OUTC layout(set = 1, binding = 1) uniform sampler2D t[2]; void main() { o = texture(t[1], vec2(0)); }"
frag uinttex "$OUTC layout(set = 0, binding = 0) uniform usampler2D t; void main() { o = vec4(texture(t, vec2(0))); }"
printf '#version 450\nlayout(location = 0) in vec2 g;\nlayout(location = 0) out vec3 a;\nlayout(location = 1) out vec2 b;\nvoid main() { a = vec3(g, 0); b = g; gl_Position = vec4(g, 0, 1); }\n' \
    > "$OUT/glsl/novary.vert"
glslangValidator -V --target-env vulkan1.2 -o "$OUT/glsl/novary.spv" "$OUT/glsl/novary.vert" \
    > /dev/null || fail "glslang: novary.vert"
printf 'outside the pack\n' > "$OUT/outside.txt"
cp "$OUT/bc4/textures/grass_albedo.png" "$OUT/outside.png"

n=0
# case NAME BASE PATTERN: copy BASE to NAME, run the corruption (stdin, in
# the copy), then splatview must refuse it as above.
case_() {
    name=$1 base=$2 want=$3
    P="$OUT/c/$name"
    rm -rf "$P" && mkdir -p "$OUT/c" && cp -r "$OUT/$base" "$P" || fail "$name: copy"
    (cd "$P" && sh -e) || fail "$name: the corruption itself failed"
    t0=$(date +%s%N)
    timeout 20 "$SV" "$P" --check --size 32x32 > "$P.log" 2>&1
    rc=$?
    t1=$(date +%s%N)
    ms=$(( (t1 - t0) / 1000000 ))
    n=$((n + 1))
    echo "[$n] $name: exit $rc, $ms ms: $(head -c 300 "$P.log" | tr '\n' ' ')"
    [ $rc = 1 ] || fail "$name: exit $rc, expected 1"
    grep -q -- "$want" "$P.log" || fail "$name: message lacks '$want'"
    grep -qi "validation" "$P.log" && fail "$name: validation message"
    [ -e "$P.png" ] && fail "$name: wrote a picture"
    [ $ms -lt 5000 ] || fail "$name: took $ms ms"
    return 0
}
M=manifest.json
G="$OUT/glsl"

# -- files that are not regular files inside the pack
case_ fifo bc4 "shaders/0000.spv', which is not a regular file (a FIFO)" <<EOF
rm shaders/0000.spv; mkfifo shaders/0000.spv
EOF
case_ symlink_devzero bc4 "heightfield.r16', which is a symbolic link" <<EOF
rm heightfield.r16; ln -s /dev/zero heightfield.r16
EOF
case_ symlink_out bc4 "textures/grass_albedo.png', which is a symbolic link" <<EOF
rm textures/grass_albedo.png; ln -s ../../outside.png textures/grass_albedo.png
EOF
case_ symlink_folder bc4 "names 'shaders/ref_0000.spv', which is inside a symbolic link" <<EOF
mv shaders ../../shaders_moved_\$\$; ln -s ../../shaders_moved_\$\$ shaders
EOF
case_ symlink_manifest bc4 "manifest.json': is a symbolic link" <<EOF
mv manifest.json real.json; ln -s real.json manifest.json
EOF
case_ folder bc4 "0001.spv', which is not a regular file (a folder)" <<EOF
rm shaders/0001.spv; mkdir shaders/0001.spv
EOF
case_ painted_dotdot bc4 "names '../x', which is outside the pack" <<EOF
"$PE" set $M painted_file '"../x"'
EOF
case_ texture_dotdot bc4 "names 'textures/../../outside.png', which is outside the pack" <<EOF
"$PE" set $M textures.0.file '"textures/../../outside.png"'
EOF
# texture arrays (PACK.md): noise and rock share binding 2
case_ array_unlike bc4 "its textures differ in size, mip levels or sampler state" <<EOF
"$PE" set $M textures.2.wrap '"clamp"'
EOF
case_ array_layer_twice bc4 "its layers must be 0, 1, … once each" <<EOF
"$PE" set $M textures.2.layer 0
EOF
case_ array_gap bc4 "the bindings must be dense" <<EOF
"$PE" set $M textures.0.binding 3
EOF
case_ spirv_absolute bc4 "names '/etc/passwd', which is outside the pack" <<EOF
"$PE" set $M combinations.1.spirv '"/etc/passwd"'
EOF

# -- SPIR-V against what it is bound to
case_ wrong_stage bc4 "0000.spv: error: a composite fragment shader does not fit the runtime: it has no fragment entry point 'main'" <<EOF
cp shaders/terrain.vert.spv shaders/0000.spv
EOF
case_ vertex_is_fragment bc4 "terrain.vert.spv: error: the vertex shader does not fit the runtime: it has no vertex entry point" <<EOF
cp shaders/0000.spv shaders/terrain.vert.spv
EOF
case_ foreign_dense_shader bc4 "0002.spv: error: a composite fragment shader does not fit the runtime: 'u_painted' (set 0 binding 2) is a float 2D array image; the runtime binds a float 2D image there" <<EOF
cp ../../dense/shaders/0002.spv shaders/0002.spv
EOF
case_ foreign_binding bc4 "does not fit the runtime: 't' is bound to set 1 binding 9, which the pipeline layout does not have" <<EOF
cp "$G/binding.spv" shaders/0001.spv
EOF
case_ foreign_kind bc4 "'t' (set 0 binding 1) is a combined image sampler; the pipeline layout has a uniform block there" <<EOF
cp "$G/kind.spv" shaders/uber.spv
EOF
case_ foreign_push bc4 "push-constant block 'p' has 256 bytes; the runtime pushes 48" <<EOF
cp "$G/push.spv" shaders/0000.spv
EOF
case_ foreign_spec bc4 "specialization constant 7, which the runtime does not set" <<EOF
cp "$G/spec.spv" shaders/0000.spv
EOF
case_ foreign_spec_type bc4 "specialization constant 0 is not a 32-bit integer" <<EOF
cp "$G/specfloat.spv" shaders/0000.spv
EOF
case_ foreign_output bc4 "output 'o' at location 2 is not one of the 1 RGBA32F colour target(s)" <<EOF
cp "$G/outloc.spv" shaders/0000.spv
EOF
case_ foreign_input bc4 "input 'v' at location 4 is not in the ABI's interface" <<EOF
cp "$G/inloc.spv" shaders/ref_0001.spv
EOF
case_ foreign_input_type bc4 "input 'v' at location 1 is not the ABI's vec2" <<EOF
cp "$G/intype.spv" shaders/0000.spv
EOF
case_ foreign_ssbo bc4 "'B' is bound to set 0 binding 30, which the pipeline layout does not have" <<EOF
cp "$G/ssbo.spv" shaders/0000.spv
EOF
case_ foreign_params_size bc4 "'Q' (set 1 binding 0) declares 1024 bytes; the runtime binds" <<EOF
cp "$G/params.spv" shaders/0000.spv
EOF
case_ foreign_array bc4 "'t' (set 1 binding 1) is an array" <<EOF
cp "$G/array.spv" shaders/0000.spv
EOF
case_ foreign_component bc4 "'t' (set 0 binding 0) is a uint 2D image; the runtime binds a float 2D image" <<EOF
cp "$G/uinttex.spv" shaders/0000.spv
EOF
case_ vertex_missing_varying bc4 "the vertex shader does not fit the runtime: it writes no output at location 2" <<EOF
cp "$G/novary.spv" shaders/terrain.vert.spv
EOF
case_ spirv_truncated bc4 "0001.spv: error: corrupt SPIR-V" <<EOF
head -c 400 shaders/0001.spv > x && mv x shaders/0001.spv
EOF

# -- forged and truncated binary files
case_ sparse_forged_header bc4 "painted.sparse', which is not a sparse mask file: truncated: the header describes" <<EOF
printf '\310\0\0\0' | dd of=painted.sparse bs=1 seek=48 conv=notrunc 2>/dev/null
EOF
case_ sparse_forged_place bc4 "painted.sparse', which is not a sparse mask file: inconsistent header" <<EOF
printf '\0\0\0\0' | dd of=painted.sparse bs=1 seek=52 conv=notrunc 2>/dev/null
EOF
case_ sparse_huge_field bc4 "painted.sparse', which is not a sparse mask file: inconsistent header (a field over 65536)" <<EOF
printf '\377\377\377\177' | dd of=painted.sparse bs=1 seek=12 conv=notrunc 2>/dev/null
EOF
case_ sparse_truncated bc4 "is not a sparse mask file: truncated" <<EOF
head -c 500 painted.sparse > x && mv x painted.sparse
EOF
case_ combos_truncated bc4 "combos.bin: error: level 0 (9x9 nodes at offset 0) runs past the end of the file (100 bytes)" <<EOF
head -c 100 combos.bin > x && mv x combos.bin
EOF
case_ combos_level_shape bc4 "quadtree.levels\[0\] must be 9x9 nodes" <<EOF
"$PE" set $M quadtree.levels.0.width 99
EOF
case_ heightfield_truncated bc4 "heightfield.r16', which has 1000 bytes" <<EOF
head -c 1000 heightfield.r16 > x && mv x heightfield.r16
EOF
case_ png_truncated bc4 "textures/rock.png', which is not an image stb_image can read" <<EOF
head -c 100 textures/rock.png > x && mv x textures/rock.png
EOF

# -- sizes over the pack limits
case_ heightfield_oversize bc4 "scene.heightfield.width: must be an integer in \[1, 16384\]" <<EOF
"$PE" set $M scene.heightfield.width 65536
EOF
case_ texture_oversize bc4 "textures/noise.png', which is 16385x2, over the pack limit of 16384" <<EOF
"$PE" png textures/noise.png 16385 2
EOF
case_ mips_over_log2 bc4 "textures\[0\].mips is 9: 10 levels with the base, more than the 9 (log2(256) + 1)" <<EOF
"$PE" set $M textures.0.mips 9
EOF
case_ painted_layers bc4 "painted: has 257 masks, over the pack limit of 256" <<EOF
"$PE" repeat $M painted 257
EOF
case_ destruction_grid destr "scene.destruction: size / cell_size is 51200 cells per side, over the pack limit of 1024" <<EOF
"$PE" set $M scene.destruction.cell_size 0.01
EOF
case_ cell_not_pow2 bc4 "scene.cell_texels: must be a power of two" <<EOF
"$PE" set $M scene.cell_texels 24
EOF

# -- painted_format against the shaders and the file
case_ painted_format_dense bc4 "(the manifest's painted_format is dense; the shader was built for sparse)" <<EOF
cp ../../dense/painted.r8 . && "$PE" set $M painted_format '"dense"' && "$PE" set $M painted_file '"painted.r8"'
EOF
case_ painted_format_sparse dense "(the manifest's painted_format is sparse; the shader was built for dense)" <<EOF
cp ../../bc4/painted.sparse . && "$PE" set $M painted_format '"bc4"' && "$PE" set $M painted_file '"painted.sparse"'
EOF
case_ painted_format_r8 bc4 "painted.sparse', which holds bc4 masks, the manifest's painted_format is r8" <<EOF
"$PE" set $M painted_format '"r8"'
EOF

# -- manifest fields of the wrong type or range
case_ type_width bc4 "scene.heightfield.width: must be an integer" <<EOF
"$PE" set $M scene.heightfield.width '"257"'
EOF
case_ type_materials bc4 "manifest.materials: must be an array" <<EOF
"$PE" set $M materials '{}'
EOF
case_ type_painted_format bc4 "manifest.painted_format: must be a string" <<EOF
"$PE" set $M painted_format 5
EOF
case_ param_default_length bc4 "params\[0\].default: must have 4 numbers" <<EOF
"$PE" set $M params.0.default '[1, 2]'
EOF
case_ combo_material_range bc4 "combinations\[0\] materials: index out of range" <<EOF
"$PE" set $M combinations.0.materials '[99]'
EOF
case_ max_height_negative bc4 "scene: size, max_height and height_offset must be finite" <<EOF
"$PE" set $M scene.max_height -1
EOF
case_ ug_far_self bc4 "undergrowth.meshes: far: must name another mesh that has no far version" <<EOF
"$PE" set $M undergrowth.meshes.0.far 0
EOF
case_ ug_far_range bc4 "undergrowth.meshes\[0\].far: must be an integer in \[0, 3\]" <<EOF
"$PE" set $M undergrowth.meshes.0.far 9
EOF
case_ ug_wind_sway bc4 "undergrowth.blocks\[0\] wind: the sway must be in \[0, 2\]" <<EOF
"$PE" set $M undergrowth.blocks.0.wind '[1, 0, 7, 0.5]'
EOF
case_ ug_wind_dir bc4 "undergrowth.blocks\[0\] wind: its direction (x, z) must be a unit vector" <<EOF
"$PE" set $M undergrowth.blocks.0.wind '[3, 0, 0.5, 0.5]'
EOF
case_ ug_wind_length bc4 "undergrowth.blocks\[0\].wind: must have 4 numbers" <<EOF
"$PE" set $M undergrowth.blocks.0.wind '[1, 0]'
EOF
case_ ug_root_blend bc4 "undergrowth.blocks\[0\] root_blend: must be in \[0, 1\]" <<EOF
"$PE" set $M undergrowth.blocks.0.root_blend 4
EOF
case_ ug_texture_range bc4 "undergrowth.blocks\[0\].texture: must be an integer in \[-1, -1\]" <<EOF
"$PE" set $M undergrowth.blocks.0.texture 3
EOF
case_ ug_alpha_untextured bc4 "undergrowth.blocks\[0\] cutout: \"alpha\" needs a texture" <<EOF
"$PE" set $M undergrowth.blocks.0.cutout '"alpha"'
EOF
case_ ug_textures_count bc4 "undergrowth.textures: must be an array of 1 to 8 entries" <<EOF
"$PE" set $M undergrowth.textures '[]'
EOF
case_ ug_lighting bc4 "undergrowth.blocks\[0\] lighting: must be \"terrain\" or \"mesh\"" <<EOF
"$PE" set $M undergrowth.blocks.0.lighting '"sun"'
EOF
# -- compressed shader files (zst.h): every frame's stated size checked
# against the file and the limit (64 MiB) before anything is allocated
case_ zst_not_frame bc4z "names 'shaders/0001.spv.zst', which is not a zstd frame" <<EOF
head -c 64 /dev/urandom > shaders/0001.spv.zst
EOF
case_ zst_bomb bc4z "names 'shaders/0000.spv.zst', which states 100000000 bytes of content, more than the limit" <<EOF
head -c 100000000 /dev/zero | zstd -q --stream-size=100000000 -c > shaders/0000.spv.zst
EOF
case_ zst_glsl_bomb bc4z "names 'shaders/uber.comp.zst', which states 100000000 bytes of content, more than the limit" <<EOF
head -c 100000000 /dev/zero | zstd -q --stream-size=100000000 -c > shaders/uber.comp.zst
EOF
case_ zst_no_size bc4z "names 'shaders/0000.spv.zst', which is a zstd frame without its content size" <<EOF
zstd -q -dc shaders/0000.spv.zst | zstd -q -c > x && mv x shaders/0000.spv.zst
EOF
case_ zst_truncated bc4z "names 'shaders/0001.spv.zst', which is not exactly one zstd frame (the frame is cut short)" <<EOF
head -c 100 shaders/0001.spv.zst > x && mv x shaders/0001.spv.zst
EOF
case_ zst_trailing bc4z "names 'shaders/ref_0000.spv.zst', which is not exactly one zstd frame (bytes after it)" <<EOF
printf 'more' >> shaders/ref_0000.spv.zst
EOF
case_ zst_two_frames bc4z "names 'shaders/uber.spv.zst', which is not exactly one zstd frame (bytes after it)" <<EOF
cat shaders/0000.spv.zst >> shaders/uber.spv.zst
EOF
case_ zst_checksum bc4z "names 'shaders/0000.spv.zst', which does not decompress" <<EOF
s=\$(stat -c %s shaders/0000.spv.zst)
printf '\\377\\377\\377\\377' | dd of=shaders/0000.spv.zst bs=1 seek=\$((s - 4)) conv=notrunc 2>/dev/null
EOF
case_ zst_corrupt_spirv bc4z "0001.spv.zst: error: corrupt SPIR-V" <<EOF
head -c 400 /dev/urandom | zstd -q --stream-size=400 -c > shaders/0001.spv.zst
EOF

# -- the stand-ins' SPIR-V ("uber"."stand_in", PACK.md "Stand-ins"):
# optional, but what is there must be right
case_ stand_in_type bc4 "uber.stand_in: must be an object" <<EOF
"$PE" set $M uber.stand_in '"flat"'
EOF
case_ stand_in_flat_type bc4 "uber.stand_in.flat: must be an object" <<EOF
"$PE" set $M uber.stand_in.flat '["shaders/flat_stand_in.comp.spv"]'
EOF
case_ stand_in_unknown bc4 "uber.stand_in: 'counting' is not a stand-in (\"flat\" or \"atlas\")" <<EOF
"$PE" set $M uber.stand_in.counting '{"spirv": "shaders/flat_stand_in.comp.spv"}'
EOF
case_ stand_in_no_spirv bc4 "uber.stand_in.flat: missing field spirv" <<EOF
"$PE" del $M uber.stand_in.flat.spirv
EOF
case_ stand_in_spirv_type bc4 "uber.stand_in.flat.spirv: must be a string" <<EOF
"$PE" set $M uber.stand_in.flat.spirv 7
EOF
case_ stand_in_hash_type bc4 "uber.stand_in.flat.hash: must be a string" <<EOF
"$PE" set $M uber.stand_in.flat.hash 7
EOF
case_ stand_in_missing_file bc4 "uber.stand_in.flat.spirv names 'shaders/flat_stand_in.comp.spv', which" <<EOF
rm shaders/flat_stand_in.comp.spv
EOF
case_ stand_in_outside bc4 "uber.stand_in.flat.spirv names '../../outside.txt', which is outside the pack" <<EOF
"$PE" set $M uber.stand_in.flat.spirv '"../../outside.txt"'
EOF
case_ stand_in_atlas_no_far bc4 "uber.stand_in.atlas: the pack has no far atlas (far_atlas)" <<EOF
"$PE" set $M uber.stand_in.atlas '{"spirv": "shaders/flat_stand_in.comp.spv"}'
EOF
case_ stand_in_fragment bc4 "flat_stand_in.comp.spv: error: a compute shading shader does not fit the runtime: it has no compute entry point" <<EOF
cp shaders/0000.spv shaders/flat_stand_in.comp.spv
EOF
case_ stand_in_atlas_as_flat far "flat_stand_in.comp.spv: error: a compute shading shader does not fit the runtime: 'u_far_albedo' is bound to set 2 binding 5, which the pipeline layout does not have" <<EOF
cp shaders/atlas_stand_in.comp.spv shaders/flat_stand_in.comp.spv
EOF
case_ stand_in_atlas_foreign far "atlas_stand_in.comp.spv: error: the far atlas's compute shader does not fit the runtime: it has no compute entry point" <<EOF
cp shaders/uber.spv shaders/atlas_stand_in.comp.spv
EOF
case_ stand_in_truncated bc4 "flat_stand_in.comp.spv: error: corrupt SPIR-V" <<EOF
head -c 400 shaders/flat_stand_in.comp.spv > x && mv x shaders/flat_stand_in.comp.spv
EOF
case_ zst_stand_in_truncated bc4z "uber.stand_in.flat.spirv names 'shaders/flat_stand_in.comp.spv.zst', which is not exactly one zstd frame (the frame is cut short)" <<EOF
head -c 100 shaders/flat_stand_in.comp.spv.zst > x && mv x shaders/flat_stand_in.comp.spv.zst
EOF
case_ zst_stand_in_bomb bc4z "names 'shaders/flat_stand_in.comp.spv.zst', which states 100000000 bytes of content, more than the limit" <<EOF
head -c 100000000 /dev/zero | zstd -q --stream-size=100000000 -c > shaders/flat_stand_in.comp.spv.zst
EOF

# The fragment GLSL the forward counting variant reads when first needed
# (the cost view on the forward path): the same checks then, and the pack
# still draws without it.
P="$OUT/c/frag_symlink"
rm -rf "$P" && cp -r "$OUT/bc4" "$P" || fail "frag_symlink: copy"
for f in "$P"/shaders/[0-9][0-9][0-9][0-9].frag "$P/shaders/uber.frag"; do
    rm "$f" && ln -s ../../../outside.txt "$f" || fail "frag_symlink: the corruption itself failed"
done
"$SV" "$P" --headless --size 32x32 --shading forward -o "$P.png" > "$P.log" 2>&1 ||
    fail "frag_symlink: the final view needs no fragment GLSL (exit $?)"
timeout 20 "$SV" "$P" --headless --size 32x32 --shading forward --view cost -o "$P.cost.png" > "$P.cost.log" 2>&1
rc=$?
n=$((n + 1))
echo "[$n] frag_symlink: exit $rc: $(head -c 300 "$P.cost.log" | tr '\n' ' ')"
[ $rc = 1 ] || fail "frag_symlink: exit $rc, expected 1"
grep -q -- "\.glsl names 'shaders/[0-9a-z]*\.frag', which is a symbolic link" "$P.cost.log" ||
    fail "frag_symlink: message lacks the file and the problem"
[ -e "$P.cost.png" ] && fail "frag_symlink: wrote a picture"
# Shaders are read and checked on first use (pack_shaders.c): a frame that
# does not need a corrupt module draws, a frame that does is refused with
# the module's message and writes no picture, and --check (every module)
# refuses the pack.  ref_0001 is drawn only by the multi-pass reference.
P="$OUT/c/lazy"
rm -rf "$P" && cp -r "$OUT/bc4" "$P" && cp "$G/inloc.spv" "$P/shaders/ref_0001.spv" ||
    fail "lazy: copy"
want="ref_0001.spv: error: a multi-pass reference fragment shader does not fit the runtime"
"$SV" "$P" --headless --size 32x32 -o "$P.png" > "$P.log" 2>&1 ||
    { cat "$P.log"; fail "lazy: the final view needs no reference shader (exit $?)"; }
"$SV" "$P" --check > "$P.check.log" 2>&1 && fail "lazy: --check took a corrupt module"
grep -q -- "$want" "$P.check.log" || { cat "$P.check.log"; fail "lazy: --check's message"; }
"$SV" "$P" --headless --size 32x32 --reference multipass -o "$P.mp.png" > "$P.mp.log" 2>&1
rc=$?
[ $rc = 1 ] || fail "lazy: the multi-pass reference drew with a corrupt module (exit $rc)"
grep -q -- "$want" "$P.mp.log" || { cat "$P.mp.log"; fail "lazy: the frame's message"; }
grep -qi "validation" "$P.mp.log" && fail "lazy: validation message"
[ -e "$P.mp.png" ] && fail "lazy: wrote a picture"
n=$((n + 1))
echo "[$n] lazy: drawn without the module, refused by --check and by the frame that needs it"
echo "PASS: $n corrupt packs refused"
[ $n -ge 30 ] || fail "only $n cases"
