#!/usr/bin/env bash
# Writes the converged path-traced references of the occluded interiors
# (tests/interior.sh, tests/consistency.py): 160x120, --maxdepth 16, 32768 spp
# each (8-10 min per scene on 2 cores; CDL_REF_SCENES="a b" for some of them).
# usage: tests/data/make_interior_refs.sh CANDELA
set -eu
candela=$1
here=$(cd "$(dirname "$0")" && pwd)
scenes=$here/../../scenes/generated
for n in ${CDL_REF_SCENES:-doorslit tworoom livingroom doorajar}; do
  # shellcheck disable=SC2046 # the .cam file holds options
  "$candela" render "$scenes/$n.obj" $(cat "$scenes/$n.cam") --res 160x120 --maxdepth 16 -i path \
    --spp 32768 --seed 7 -q -o "$here/${n}_path_160.exr"
done
