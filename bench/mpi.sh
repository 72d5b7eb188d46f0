#!/usr/bin/env bash
# MPI on one machine and a cost model for many (issue 15). Prints Markdown.
#  1. Overhead: 1 process x 2 threads against mpirun -np 2 x 1 thread, equal
#     passes, per method on the default Cornell box (256x256): render time
#     (the summary line's, communication included) and wall time (mpirun's
#     start-up included), best of 2.
#  2. The reduction: the bytes each rank sends (its accumulators, 8 bytes per
#     double: 7 per pixel + 4) and the time of the MPI_Reduce measured here at
#     512x512 (2 ranks, shared memory).
#  3. A model of efficiency at N ranks for a 512x512 film: P passes of t_pass
#     seconds (measured here, per method, 2 threads) split over N ranks, each
#     rank's load time L (measured) and the reduction as a binomial tree of
#     ceil(log2 N) steps of (alpha + B / beta) on the network assumed (10 GbE:
#     alpha 50 us, beta 1.1 GB/s; InfiniBand HDR: 2 us, 12 GB/s), and the last
#     round's imbalance (P not a multiple of N: ceil(P / N) passes on some ranks):
#       E(N) = P t_pass / (N (L + ceil(P / N) t_pass + ceil(log2 N) (alpha + B / beta))).
# usage: bench/mpi.sh [BUILD_DIR] [PASSES P for the model, default 1024]
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
P=${2:-1024}
candela=$build/candela
scene=$here/scenes/cornell-box/CornellBox-Original.obj
cam="--lookat 0,1,3.9,0,1,0,0,1,0 --fov 39.3077"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$candela" --version | grep -q MPI || { echo "candela is built without MPI"; exit 1; }
now() { date +%s.%N; }
secs() { sed -n 's/.* spp in \([0-9.]*\) s.*/\1/p' "$1"; }
comm() { sed -n 's/.*communication \([0-9.]*\) s.*/\1/p' "$1"; }
best() { awk 'BEGIN {m = 1e30} {if ($1 < m) m = $1} END {print m}'; }

echo "## MPI on one machine ($(nproc) cores): 1 process x 2 threads vs 2 ranks x 1 thread"
echo
echo "| method | passes | render 1x2 (s) | render 2x1 (s) | render ratio | wall 1x2 (s) | wall 2x1 (s) | wall ratio |"
echo "|---|---|---|---|---|---|---|---|"
for spec in "path 256" "bdpt 32" "pm 32" "rigi 32"; do
  set -- $spec
  m=$1 n=$2
  r1=() r2=() w1=() w2=()
  for rep in 1 2; do
    t=$(now)
    # shellcheck disable=SC2086
    "$candela" render "$scene" $cam --res 256x256 -i "$m" --spp "$n" --threads 2 -q -o "$tmp/a.exr" > "$tmp/a.out"
    w1+=("$(echo "$(now) - $t" | bc)")
    r1+=("$(secs "$tmp/a.out")")
    t=$(now)
    # shellcheck disable=SC2086
    mpirun -np 2 --oversubscribe "$candela" render "$scene" $cam --res 256x256 -i "$m" --spp "$n" --threads 1 -q \
      -o "$tmp/b.exr" > "$tmp/b.out"
    w2+=("$(echo "$(now) - $t" | bc)")
    r2+=("$(secs "$tmp/b.out")")
  done
  a=$(printf '%s\n' "${r1[@]}" | best) b=$(printf '%s\n' "${r2[@]}" | best)
  c=$(printf '%s\n' "${w1[@]}" | best) d=$(printf '%s\n' "${w2[@]}" | best)
  printf '| %s | %s | %.2f | %.2f | %.3f | %.2f | %.2f | %.3f |\n' "$m" "$n" "$a" "$b" "$(echo "$b / $a" | bc -l)" \
    "$c" "$d" "$(echo "$d / $c" | bc -l)"
done
echo

# the reduction at 512x512 and each method's pass time there
# shellcheck disable=SC2086
mpirun -np 2 --oversubscribe "$candela" render "$scene" $cam --res 512x512 --spp 2 --threads 1 -q -o "$tmp/r.exr" > "$tmp/r.out"
tred=$(comm "$tmp/r.out")
bytes=$(( (7 * 512 * 512 + 4) * 8 ))
t=$(now)
"$candela" render "$scene" $cam --res 8x8 --spp 1 -q -o "$tmp/l.exr" > /dev/null
load=$(printf "%.3f" "$(echo "$(now) - $t" | bc)")
echo "## The reduction and a model for N ranks (512x512 film, P = $P passes)"
echo
echo "Each rank sends $bytes bytes ($(echo "scale=1; $bytes / 1048576" | bc) MiB) once, at the end; measured here"
echo "(2 ranks, shared memory, communication = reduce + waiting for the slower rank): $tred s. Load L = $load s"
echo "(the Cornell box; every rank loads the scene)."
echo
echo "| method | t_pass 512x512, 2 threads (s) | network | E(8) | E(64) | E(512) |"
echo "|---|---|---|---|---|---|"
for m in path bdpt pm rigi; do
  # shellcheck disable=SC2086
  "$candela" render "$scene" $cam --res 512x512 -i "$m" --spp 4 --threads 2 -q -o "$tmp/p.exr" > "$tmp/p.out"
  tp=$(echo "$(secs "$tmp/p.out") / 4" | bc -l)
  for net in "10GbE 50e-6 1.1e9" "IB-HDR 2e-6 12e9"; do
    set -- $net
    awk -v tp="$tp" -v P="$P" -v L="$load" -v B="$bytes" -v a="$2" -v bw="$3" -v name="$1" -v m="$m" 'BEGIN {
      printf "| %s | %.3f | %s |", m, tp, name
      split("8 64 512", Ns, " ")
      for (i = 1; i <= 3; i++) {
        N = Ns[i]; k = int(P / N); if (k * N < P) k++
        steps = log(N) / log(2); if (int(steps) < steps) steps = int(steps) + 1
        E = P * tp / (N * (L + k * tp + steps * (a + B / bw)))
        printf " %.3f |", E
      }
      printf "\n"
    }'
  done
done
