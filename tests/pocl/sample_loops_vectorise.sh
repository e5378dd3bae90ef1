#!/bin/bash
# The sampling kernels' work-item loops hold no short vector on PoCL's haswell target
# (docs/pocl.md, rule 8): a value of type <2 x …>, which LLVM's SLP vectoriser makes of
# two like scalar computations, keeps the loop scalar ("instruction return type cannot
# be vectorized"), and the AVX-512 target, which this project's machines mostly run, does
# not show it. Per-pixel frames (2026-11-27) made the BRDF technique 4.4x slower on AVX2
# CPUs that way, unseen for three days. Renders of the kernels without statistics, with
# a fresh PoCL cache so that they compile, PoCL's remarks on.
#
# usage: sample_loops_vectorise.sh MISALLOC
# Skipped (77) where the CPU has no AVX2, PoCL no haswell kernel library, or the CPU's
# OpenCL device is not PoCL's.
set -u
misalloc=$1
grep -qw avx2 /proc/cpuinfo || { echo "skipped: this CPU has no AVX2"; exit 77; }
ls /usr/share/pocl/kernel-*-avx2.bc >/dev/null 2>&1 || { echo "skipped: PoCL has no avx2 kernel library"; exit 77; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
status=0
for config in "--envmap-pdf plain" "--envmap-pdf optimal-pixel" "--envmap-pdf optimal-pixel --product"; do
  mkdir -p "$work/cache"
  # shellcheck disable=SC2086
  if ! POCL_VECTORIZER_REMARKS=1 POCL_KERNELLIB_NAME=avx2 POCL_CACHE_DIR="$work/cache" "$misalloc" render \
      --device cpu --reference none --scene spheres --method equal $config --size 32x32 --spp 8 --out "$work/r.exr" \
      --report "$work/r.json" --no-preview >"$work/log" 2>&1; then
    echo "FAIL: misalloc render $config failed:"; tail -5 "$work/log"; exit 1
  fi
  grep -q '"device": "pthread' "$work/r.json" || { echo "skipped: the CPU's OpenCL device is not PoCL's"; exit 77; }
  grep -q "pthread-haswell" "$work/r.json" || { echo "FAIL: $config did not run on PoCL's haswell target"; exit 1; }
  vectorised=$(grep -o "vectorized loop (vectorization width" "$work/log" | wc -l)
  short=$(grep -o "instruction return type cannot be vectorized" "$work/log" | wc -l)
  echo "$config: $vectorised loops vectorised, $short kept scalar by a short vector"
  if [ "$short" -ne 0 ] || [ "$vectorised" -eq 0 ]; then status=1; fi
  rm -rf "$work/cache"
done
[ $status -eq 0 ] && echo "PASS" || echo "FAIL: a work-item loop holds a short vector (docs/pocl.md, rule 8)"
exit $status
