#!/usr/bin/env bash
# Mitsuba's one-sided bsdfs (issue 27): two rectangles lit by a point light
# on the camera's side, the upper one facing the camera, the lower one
# turned away. With a bare diffuse bsdf the lower one is black in every
# method (Mitsuba renders a back face black) and the upper one lit; inside
# a twosided wrapper both are lit alike.
#   one_sided.sh CANDELA
set -u
candela=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
scene() { # BSDF-XML > file
  cat <<XML
<scene version="3.0.0">
  <sensor type="perspective">
    <float name="fov" value="70"/>
    <transform name="to_world"><lookat origin="0, 0, -4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/><rfilter type="box"/></film>
  </sensor>
  <emitter type="point"><point name="position" x="0" y="0" z="-3"/><rgb name="intensity" value="10"/></emitter>
  $1
  <shape type="rectangle">
    <transform name="to_world"><rotate y="1" angle="180"/><translate y="1.2"/></transform><ref id="m"/>
  </shape>
  <shape type="rectangle"><transform name="to_world"><translate y="-1.2"/></transform><ref id="m"/></shape>
</scene>
XML
}
scene '<bsdf type="diffuse" id="m"/>' >"$tmp/one.xml"
scene '<bsdf type="twosided" id="m"><bsdf type="diffuse"/></bsdf>' >"$tmp/two.xml"
mean() { # image region -> mean
  "$candela" diff "$1" "$1" --region "$2" | sed -n 's/.*(mean test \([^,]*\),.*/\1/p'
}
fail=0
for m in path bdpt ir rigi pm gkde splat sppm vcm; do
  for s in one two; do
    if ! "$candela" render "$tmp/$s.xml" -i $m --spp 4 -q -o "$tmp/$m-$s.exr" >/dev/null 2>"$tmp/err"; then
      echo "FAIL $m $s: render failed: $(cat "$tmp/err")"
      fail=1
      continue
    fi
  done
  up1=$(mean "$tmp/$m-one.exr" 0,0,32,16) lo1=$(mean "$tmp/$m-one.exr" 0,16,32,32)
  up2=$(mean "$tmp/$m-two.exr" 0,0,32,16) lo2=$(mean "$tmp/$m-two.exr" 0,16,32,32)
  if awk -v a="$up1" -v b="$lo1" -v c="$up2" -v d="$lo2" \
    'BEGIN {exit !(a > 0.01 && b < 1e-6 && c > 0.01 && d > 0.7 * c && d < 1.3 * c)}'; then
    echo "ok   $m: one-sided front $up1 back $lo1; twosided front $up2 back $lo2"
  else
    echo "FAIL $m: one-sided front $up1 back $lo1 (want > 0.01, 0); twosided front $up2 back $lo2 (want alike)"
    fail=1
  fi
done
exit $fail
