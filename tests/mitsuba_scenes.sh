#!/usr/bin/env bash
# The shared Mitsuba scenes against their pbrt-v3 twins (issue 14):
#  1. veach-mis/mitsuba3 agrees with the pbrt-v3 reference (block-median
#     mean within 1 %, trimmed relMSE falling as 1/N: reference.sh, ROBUST=1)
#     once two deliberate differences of the Mitsuba file are undone: its
#     plates carry specular_reflectance 0.3 (pbrt's metal has no such factor),
#     and its max_depth 3 counts segments (2 bounces) where pbrt's maxdepth 3
#     counts bounces, so --maxdepth 3 is given; and its film's tent filter
#     is replaced by the reference's box (--pixel-filter box).
#  2. veach-bidir/mitsuba3 and its pbrt-v3 twin, both rendered by candela
#     with bdpt at equal settings: means within 2 % (OBJ meshes, glass, lamps).
#  3. sponza-dabrovic/mitsuba (37 serialized meshes, 10 JPEG textures) renders
#     as the OBJ conversion with a point light of the same power does: mean
#     within 2 % (direct light; same camera). The conversion kept the
#     serialized uv as they are, and Mitsuba flips an OBJ's v but not a
#     serialized mesh's, so the textures differ by a v flip, as they would in
#     Mitsuba: 1.018 (1.007 when candela read serialized v flipped, before
#     Mitsuba 3's various_shapes test showed Mitsuba's convention; issue 27).
# usage: mitsuba_scenes.sh CANDELA SHARED_DIR
set -u
candela=$1 shared=$2
here=$(cd "$(dirname "$0")" && pwd)
scenes=$shared/scenes
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
ratio() { "$candela" diff "$1" "$2" | tr -s ' ' '\n' | awk 'p {print; exit} $0 == "mean_ratio" {p = 1}'; }
within() { awk -v r="$1" -v t="$2" 'BEGIN {exit !(r >= 1 - t && r <= 1 + t)}'; }

# the reference is pbrt-v3's, whose plates are GGX: the Mitsuba file's
# beckmann (rendered as such since issue 27) is made ggx to match
sed -e 's/"specular_reflectance" value="0.3, 0.3, 0.3"/"specular_reflectance" value="1, 1, 1"/' \
  -e 's/"distribution" value="beckmann"/"distribution" value="ggx"/' \
  "$scenes/veach-mis/mitsuba3/scene.xml" > "$tmp/veach-mis.xml"
ROBUST=1 bash "$here/reference.sh" "$candela" "$shared/references/veach-mis_bdpt_320x180.exr" 16 0.01 -- \
  "$tmp/veach-mis.xml" -i bdpt --maxdepth 3 --res 320x180 --pixel-filter box || fail=1

common="-i bdpt --maxdepth 7 --res 128x128 --spp 32 -q"
# shellcheck disable=SC2086
"$candela" render "$scenes/veach-bidir/mitsuba3/scene.xml" $common -o "$tmp/vb_m.exr" >/dev/null 2>&1 &&
  "$candela" render "$scenes/veach-bidir/pbrt-v3/scene.pbrt" $common -o "$tmp/vb_p.exr" >/dev/null 2>&1 || fail=1
r=$(ratio "$tmp/vb_m.exr" "$tmp/vb_p.exr")
if within "$r" 0.02; then echo "ok  : veach-bidir Mitsuba / pbrt-v3 mean ratio $r"
else echo "FAIL: veach-bidir Mitsuba / pbrt-v3 mean ratio $r (1 +- 0.02)"; fail=1; fi

sp="--res 160x120 --spp 16 -i path --maxdepth 1 -q"
# shellcheck disable=SC2086
"$candela" render "$scenes/sponza-dabrovic/mitsuba/sponza.xml" $sp -o "$tmp/sp_m.exr" >/dev/null 2>&1 &&
  "$candela" render "$scenes/sponza-dabrovic/obj-converted/sponza.obj" $sp -o "$tmp/sp_o.exr" \
    --lookat 14.4499,6.89415,-1.18547,13.4563,6.78438,-1.15861,-0.109708,0.993957,0.00374357 --fov 74.14 \
    --point-light 0,17,0,157,157,157 >/dev/null || fail=1
r=$(ratio "$tmp/sp_m.exr" "$tmp/sp_o.exr")
if within "$r" 0.02; then echo "ok  : sponza Mitsuba (serialized) / OBJ mean ratio $r"
else echo "FAIL: sponza Mitsuba (serialized) / OBJ mean ratio $r (1 +- 0.02)"; fail=1; fi
exit $fail
