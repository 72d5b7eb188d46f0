#!/usr/bin/env bash
# The public API's promises that a compiler and nm can check:
#   api.sh LIBCANDELA.so SOURCE_DIR
# - libcandela.so exports exactly the functions candela.h declares CDL_API,
#   all cdl_-prefixed, and nothing else;
# - candela.h compiles alone as C11 and C++17 with -Wall -Wextra -pedantic;
# - the candela command's sources include nothing but the public header and
#   their own (the build has no src/ on their include path either), and the
#   library includes nothing of the command's.
set -eu
lib=$1 src=$2
fail=0
exported=$(nm -D --defined-only "$lib" | awk '$2 ~ /^[TDBRVW]$/ {print $3}' | sort)
declared=$(grep -o '^CDL_API [^(]*(' "$src/include/candela/candela.h" | sed 's/.*[ *]\([a-z_0-9]*\)($/\1/' | sort)
if [ -z "$declared" ] || [ "$exported" != "$declared" ]; then
  echo "FAIL: exported symbols differ from candela.h's CDL_API functions:"
  diff <(echo "$declared") <(echo "$exported") | sed 's/^/  /'
  fail=1
fi
bad=$(echo "$exported" | grep -v '^cdl_' || true)
[ -z "$bad" ] || { echo "FAIL: symbols outside cdl_: $bad"; fail=1; }
n=$(echo "$exported" | wc -l)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf '#include <candela/candela.h>\nint main(void) { return cdl_version() ? 0 : 1; }\n' > "$tmp/c.c"
cp "$tmp/c.c" "$tmp/c.cpp"
cc -std=c11 -Wall -Wextra -pedantic -Werror -I"$src/include" -c "$tmp/c.c" -o "$tmp/c.o" ||
  { echo "FAIL: candela.h as C11"; fail=1; }
c++ -std=c++17 -Wall -Wextra -pedantic -Werror -I"$src/include" -c "$tmp/c.cpp" -o "$tmp/cpp.o" ||
  { echo "FAIL: candela.h as C++17"; fail=1; }
inc=$(grep -h '^#include "' "$src"/src/cli/*.c "$src"/src/cli/*.h | grep -v '"cli.h"' || true)
[ -z "$inc" ] || { echo "FAIL: the CLI includes internal headers: $inc"; fail=1; }
up=$(grep -rl '#include "cli' "$src/src" --include='*.[ch]' | grep -v '/src/cli/' || true)
[ -z "$up" ] || { echo "FAIL: the library includes the driver: $up"; fail=1; }
[ $fail -eq 0 ] && echo "ok: $n exported functions, all declared in candela.h; header clean as C11 and C++17; CLI on the public API"
exit $fail
