#!/usr/bin/env bash
# vcm's two halves on the McGuire Cornell box:
#  - vcm_mode connect is bdpt: the same light paths, the same strategies and
#    weights (eta = 0), so the same pixels (max relative difference <= 1e-6);
#  - vcm_mode merge (merging alone, a progressive photon mapper over the same
#    light paths) converges to the reference: from N to 4N passes the median
#    of the 16x16 block ratios moves towards 1 (or is within 1 % already) and
#    the relative MSE falls;
#  - merging with 4 light paths per pixel (merge_paths 4: 3 merged with
#    only) agrees with the reference as closely (block median within 1 %,
#    or no further off than one path's) at lower relative MSE: the count
#    in eta and the merges' normalization match.
# (Full vcm against the reference: reference.sh.)
# usage: vcm_modes.sh CANDELA IMAGE_MAXREL REF.exr N -- SCENE render args...
set -u
candela=$1 maxrel=$2 ref=$3 n=$4
shift 5
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
ok() { echo "ok  : $*"; }
bad() { echo "FAIL: $*"; fail=1; }
key() { "$candela" diff "$1" "$ref" | tr -s ' ' '\n' | awk -v k="$2" 'p {print; exit} $0 == k {p = 1}'; }
render() { # out args...
  local out=$1
  shift
  "$candela" render "$@" -q -o "$out" >/dev/null || { bad "render $* exited $?"; exit 1; }
}

# connect vs bdpt: small and quick, every strategy incl. light tracing
render "$tmp/bdpt.exr" "$@" -i bdpt --res 64x64 --spp 4 --seed 3
render "$tmp/vc.exr" "$@" -i vcm --vcm-mode connect --res 64x64 --spp 4 --seed 3
d=$("$maxrel" "$tmp/vc.exr" "$tmp/bdpt.exr") || bad "image_maxrel exited $?"
if [[ $d =~ ^[0-9.eE+-]+$ ]] && awk -v d="$d" 'BEGIN {exit !(d + 0 <= 1e-6)}'; then ok "vcm connect = bdpt: max relative difference $d"
else bad "vcm connect vs bdpt: max relative difference $d (> 1e-6)"; fi

# merge alone: bias shrinking with the passes (one render, snapshots at N and 4N
# would need the API; two renders with the same seed share their first N passes)
render "$tmp/m1.exr" "$@" -i vcm --vcm-mode merge --spp "$n" --seed 1
render "$tmp/m4.exr" "$@" -i vcm --vcm-mode merge --spp $((4 * n)) --seed 1
b1=$(key "$tmp/m1.exr" block_median_ratio) b4=$(key "$tmp/m4.exr" block_median_ratio)
e1=$(key "$tmp/m1.exr" relmse) e4=$(key "$tmp/m4.exr" relmse)
# check CONDITION(a, b, da, db) A B MESSAGE: da, db are |a - 1|, |b - 1|
check() {
  if awk -v a="$2" -v b="$3" "BEGIN {da = a > 1 ? a - 1 : 1 - a; db = b > 1 ? b - 1 : 1 - b; exit !($1)}"; then
    ok "$4"
  else
    bad "$4"
  fi
}
check "db < da || db < 0.01" "$b1" "$b4" "vcm merge: block median $b1 at $n passes, $b4 at $((4 * n)) (towards 1, or within 1 %)"
check "b < a" "$e1" "$e4" "vcm merge: relMSE $e1 -> $e4 (falls)"

render "$tmp/k4.exr" "$@" -i vcm --vcm-mode merge --merge-paths 4 --spp "$n" --seed 1
bk=$(key "$tmp/k4.exr" block_median_ratio) ek=$(key "$tmp/k4.exr" relmse)
check "db <= da + 0.002 || db < 0.01" "$b1" "$bk" \
  "vcm merge, 4 light paths per pixel: block median $bk at $n passes (one path: $b1; within 1 % or no further off)"
check "b < 0.8 * a" "$e1" "$ek" "vcm merge, 4 light paths per pixel: relMSE $ek (one path: $e1; below 0.8 of it)"

exit $fail
