#!/usr/bin/env bash
# Bad-input test runner for candela.
#
#   run.sh CANDELA_BINARY CORPUS_DIR
#
# Runs every row of CORPUS_DIR/MANIFEST.tsv from inside CORPUS_DIR, each with a
# 60 s timeout, and checks that candela rejects the input cleanly:
#   - the exit status equals the expected one (1 bad scene/file, 2 bad option);
#   - stderr is exactly one non-empty line, starting with "candela: error:"
#     and containing the expected substring (a fixed string, not a pattern);
#   - stdout is empty;
#   - no "Sanitizer" or "runtime error" appears in the output (no crash, no
#     timeout, no signal).
# Prints one line per failure, then "N passed, M failed"; exits non-zero if
# anything failed.
#
# MANIFEST.tsv rows: name<TAB>status<TAB>substring<TAB>command words...
# Lines that are blank or start with '#' are skipped. In the command, words are
# separated by spaces; @CANDELA@ is the binary (prepended if the command does
# not start with it) and @OUT@ is a fresh temporary directory, created per case
# with an empty subdirectory adir/ in it.
set -u

if [[ $# -ne 2 ]]; then
    echo "usage: $0 CANDELA_BINARY CORPUS_DIR" >&2
    exit 2
fi

# Absolute path of the binary, since the cases run inside the corpus directory.
bin=$1
if [[ $bin != */* ]]; then
    bin=$(command -v -- "$bin") || { echo "$0: $1: not found" >&2; exit 2; }
fi
bin=$(cd -- "$(dirname -- "$bin")" && pwd)/$(basename -- "$bin")
if [[ ! -f $bin || ! -x $bin ]]; then
    echo "$0: $1: not an executable file" >&2
    exit 2
fi

cd -- "$2" || exit 2
if [[ ! -f MANIFEST.tsv ]]; then
    echo "$0: $2/MANIFEST.tsv: no such file" >&2
    exit 2
fi

ulimit -c 0 2>/dev/null  # no core files in the corpus directory

scratch=$(mktemp -d "${TMPDIR:-/tmp}/candela-bad-input.XXXXXX") || exit 2
trap 'rm -rf -- "$scratch"' EXIT

passed=0
failed=0

fail() {  # fail NAME REASON STDERR_FILE
    local first
    first=$(head -c 300 -- "$3" | head -n 1)
    echo "FAIL $1: $2${first:+ [stderr: $first]}"
    failed=$((failed + 1))
}

lineno=0
while IFS= read -r row || [[ -n $row ]]; do
    lineno=$((lineno + 1))
    [[ -z ${row//[[:space:]]/} || $row == \#* ]] && continue

    IFS=$'\t' read -r name status expect cmd <<<"$row"
    if [[ -z ${cmd:-} || ! $status =~ ^[0-9]+$ ]]; then
        echo "FAIL MANIFEST.tsv:$lineno: malformed row"
        failed=$((failed + 1))
        continue
    fi

    case_dir=$scratch/$name
    out=$case_dir/out
    mkdir -p -- "$out/adir"

    # Split the command into words and substitute the placeholders.
    read -r -a words <<<"$cmd"
    [[ ${words[0]} == @CANDELA@ ]] || words=(@CANDELA@ "${words[@]}")
    args=()
    for w in "${words[@]}"; do
        w=${w//@CANDELA@/$bin}
        args+=("${w//@OUT@/$out}")
    done

    # The braces catch bash's own "Segmentation fault" notice; the case's
    # stderr is captured separately.
    { timeout -k 5 60 "${args[@]}" </dev/null >"$case_dir/stdout" 2>"$case_dir/stderr"; } 2>/dev/null
    got=$?

    err=$case_dir/stderr
    nlines=$(grep -c '' "$err")
    line=$(head -n 1 "$err")

    if [[ $got -eq 124 || $got -eq 137 ]]; then
        fail "$name" "timed out after 60 s (status $got)" "$err"
    elif [[ $got -gt 128 ]]; then
        fail "$name" "killed by signal $((got - 128))" "$err"
    elif grep -q -e 'Sanitizer' -e 'runtime error' "$err" "$case_dir/stdout"; then
        fail "$name" "sanitizer report" "$err"
    elif [[ $got -ne $status ]]; then
        fail "$name" "exit status $got, expected $status" "$err"
    elif [[ $nlines -ne 1 || -z $line ]]; then
        fail "$name" "stderr has $nlines lines, expected exactly one non-empty line" "$err"
    elif [[ $line != "candela: error:"* ]]; then
        fail "$name" "stderr does not start with 'candela: error:'" "$err"
    elif [[ $line != *"$expect"* ]]; then
        fail "$name" "stderr does not contain '$expect'" "$err"
    elif [[ -s $case_dir/stdout ]]; then
        fail "$name" "stdout is not empty" "$err"
    else
        passed=$((passed + 1))
    fi
done <MANIFEST.tsv

echo "$passed passed, $failed failed"
[[ $failed -eq 0 && $passed -gt 0 ]]
