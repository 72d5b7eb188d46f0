#!/usr/bin/env bash
# Does each biased method converge to the right image? pm, gkde, splat and vcm at
# T, 4T and 16T on the realistic interiors against long path references:
# block-median ratio, relMSE, log-log plots (bench/consistency.py --help).
# usage: bench/consistency.sh [--build DIR] [consistency.py options]
#   e.g. bench/consistency.sh --time 12 --out out/consistency --plots docs
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
build=$here/build
if [ "${1:-}" = "--build" ]; then
  build=$2
  shift 2
fi
export PYTHONPATH=$here/python${PYTHONPATH:+:$PYTHONPATH}
export CANDELA_LIBRARY=${CANDELA_LIBRARY:-$build/libcandela.so}
# Debian's Python has numpy and matplotlib (tools/install-deps.sh)
exec /usr/bin/python3 "$here/bench/consistency.py" "$@"
