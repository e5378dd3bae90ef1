#!/usr/bin/env bash
# scripts/portable-bundle: the bundle holds every library misalloc loads, and its misalloc
# runs through the bundle's own loader on the bundle's own glibc, as on a machine that
# has none of Debian's packages.
#   tests/bundle/portable_bundle.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
source_dir=$1 build_dir=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
MISALLOC_BUILD_DIR=$build_dir bash "$source_dir/scripts/portable-bundle" "$out/bundle" 2>/dev/null
lib=$out/bundle/lib
missing=""
for l in $(ldd "$build_dir/misalloc" | awk '/=>/ {print $3}'); do
  [[ -e $lib/$(basename "$l") ]] || missing="$missing $(basename "$l")"
done
[[ -z $missing ]] || { echo "not in the bundle:$missing"; exit 1; }
LD_DEBUG=libs "$lib/ld-linux-x86-64.so.2" --library-path "$lib" "$out/bundle/bin/misalloc" paper \
  >"$out/stdout" 2>"$out/libs"
grep -q "000-C" "$out/stdout" || { echo "the bundle's misalloc listed no paper example:"; cat "$out/stdout"; exit 1; }
# The loader opened the bundle's libc, not the system's.
grep -q "calling init: $lib/libc.so.6" "$out/libs" || {
  echo "libc came from elsewhere:"; grep "calling init" "$out/libs"; exit 1; }
echo "misalloc ran from the bundle on its own libraries"
