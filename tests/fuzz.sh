#!/usr/bin/env bash
# Runs the libFuzzer targets (built with -DCDL_FUZZ=ON into FUZZ_BUILD):
#   fuzz.sh FUZZ_BUILD SOURCE_DIR SECONDS [CORPUS_ROOT] [TARGET...]
# For each target: first its regression files (fuzz/regressions/TARGET, every
# crash ever found), then SECONDS of fuzzing from a seed corpus drawn from
# the tests' inputs (bad-input corpora, scenes, images, option rows; and
# fuzz/seeds/TARGET for what the tests do not cover), two
# targets at a time. CORPUS_ROOT keeps the corpora between runs (default: a
# temporary directory). A crash, leak, sanitizer report or timeout fails the
# run and leaves its input in CORPUS_ROOT/TARGET-artifacts/. Prints per target
# the executions and the coverage (edges, features) reached.
set -u
build=$1 src=$2 secs=$3
root=${4:-}
shift $(( $# < 4 ? $# : 4 ))
targets=${*:-obj pbrt ply image options mitsuba}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export LSAN_OPTIONS="suppressions=$src/fuzz/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
[ -n "$root" ] || root=$tmp/corpora
mkdir -p "$root"

seed() { # seed TARGET DIR
  local t=$1 d=$2 f
  mkdir -p "$d"
  cp "$src"/fuzz/seeds/"$t"/* "$d"/ 2>/dev/null
  case $t in
    obj)
      cp "$src"/tests/bad_input/*.obj "$d"/ 2>/dev/null
      for f in "$src"/scenes/cornell-box/*.obj; do
        { sed 's/^mtllib .*/mtllib m.mtl/' "$f"; printf '\n#MTL\n'; cat "${f%.obj}.mtl" 2>/dev/null; } > "$d/$(basename "$f").seed"
      done ;;
    pbrt)
      cp "$src"/tests/bad_pbrt/*.pbrt "$d"/ 2>/dev/null
      find "$src/scenes" "$src/tests/data" -name '*.pbrt' -size -64k -exec cp {} "$d"/ \; 2>/dev/null ;;
    mitsuba)
      cp "$src"/tests/bad_mitsuba/*.xml "$d"/ 2>/dev/null
      # Mitsuba 3's render-test scenes: every plugin the reader knows
      find "$src/../shared/scenes/mitsuba3-tests" "$src/../shared/scenes/veach-mis" -name '*.xml' -size -64k \
        -exec cp {} "$d"/ \; 2>/dev/null ;;
    ply)
      cp "$src"/tests/bad_ply/*.ply "$d"/ 2>/dev/null
      find "$src/tests/data" "$src/../shared/scenes/veach-bidir" -name '*.ply' -size -64k -exec cp {} "$d"/ \; 2>/dev/null ;;
    image)
      find "$src/tests/bad_input" "$src/tests/data" "$src/scenes" \( -name '*.exr' -o -name '*.png' -o -name '*.pfm' \) \
        -size -64k -exec cp {} "$d"/ \; 2>/dev/null ;;
    options)
      # every option of the manifest rows, "name=value" per line
      awk -F'\t' '!/^#/ && NF >= 4 {print $4}' "$src"/tests/bad_input/MANIFEST.tsv | while read -r line; do
        echo "$line" | tr ' ' '\n' | awk '/^-/ {if (o) print o; o = $0; next} o {print o "=" $0; o = ""} END {if (o) print o}' \
          | sed 's/^-*//'
      done | split -l 6 - "$d/row"
      printf 'integrator=pm\nphotons=1000\nimportance\nres=4x4\nlookat=0,0,3,0,0,0,0,1,0\nfov=30\n' > "$d/pm"
      printf 'integrator=splat\nmode=sh\ncache=0.5\nfilter=100\nfractions=0.3,0.6,0.1\nC=0.6\n' > "$d/splat"
      printf 'integrator=rigi\nlight-paths=16\ninterleave=2\naov=pathlength\nthreshold=2\nstrata=distance\n' > "$d/rigi" ;;
  esac
}

run() { # run TARGET: regressions, then fuzzing
  local t=$1 bin=$build/fuzz/fuzz_$1 log=$tmp/$1.log
  # the OBJ target's leak suppression (fuzz/lsan.supp) needs whole stacks
  [ "$t" = obj ] && export ASAN_OPTIONS="fast_unwind_on_malloc=0${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
  local art=$root/$t-artifacts/
  mkdir -p "$art" "$root/$t"
  local regs=("$src"/fuzz/regressions/"$t"/*)
  if [ -e "${regs[0]}" ] && ! "$bin" -rss_limit_mb=4096 "${regs[@]}" > "$log.reg" 2>&1; then
    echo "FAIL fuzz_$t: a regression file crashes again:"; tail -30 "$log.reg"; return 1
  fi
  seed "$t" "$tmp/seed-$t"
  local n=$(ls "$tmp/seed-$t" | wc -l)
  if ! "$bin" -max_total_time="$secs" -timeout=20 -rss_limit_mb=4096 -print_final_stats=1 \
       -artifact_prefix="$art" "$root/$t" "$tmp/seed-$t" > "$log" 2>&1; then
    echo "FAIL fuzz_$t (input in $art):"
    if grep -q -E "ERROR|runtime error|Sanitizer|timeout|deadly" "$log"; then
      grep -A30 -m1 -E "ERROR|runtime error|Sanitizer|timeout|deadly" "$log" | head -40
    else
      tail -20 "$log"
    fi
    return 1
  fi
  local execs cov ft
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$')
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*')
  ft=$(grep -o 'ft: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*')
  echo "ok fuzz_$t: ${secs} s, $execs executions ($((execs / (secs > 0 ? secs : 1)))/s), coverage $cov edges, $ft features, $n seeds, $(ls "$root/$t" | wc -l) in the corpus"
}

fail=0
pids=()
set -- $targets
while [ $# -gt 0 ]; do
  run "$1" > "$tmp/$1.out" & pids+=($!:$1)
  if [ $# -gt 1 ]; then run "$2" > "$tmp/$2.out" & pids+=($!:$2); shift; fi
  shift
  for p in "${pids[@]}"; do
    wait "${p%%:*}" || fail=1
    cat "$tmp/${p#*:}.out"
  done
  pids=()
done
exit $fail
