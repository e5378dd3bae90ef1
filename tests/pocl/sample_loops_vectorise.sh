#!/bin/bash
# The sampling kernels' work-item loops hold no short vector on PoCL's haswell target
# (docs/pocl.md, rule 8): a value of type <2 x …>, which LLVM's SLP vectoriser makes of
# two like scalar computations, keeps the loop scalar ("instruction return type cannot
# be vectorized"), and the AVX-512 target, which this project's machines mostly run, does
# not show it. Per-pixel frames (2026-11-27) made the BRDF technique 4.4x slower on AVX2
# CPUs that way, unseen for three days. Renders of the kernels without statistics, with
# a fresh PoCL cache so that they compile, PoCL's remarks on. Then exact's statistics
# kernel, whose loops PoCL leaves scalar without a remark: it must vectorise as many of
# samplePixelStage's work-group loops as the kernel without statistics does, so that an
# exact render counts twice equal's (its pilot's share columns took a second Phong lobe
# per sample, and its pilot ran 4-5x as slow per sample, until 2026-12-01). The grid
# search's loops are not counted there: its lanes are explicit float16 combinations.
# And no technique's sample loop is copied more than rule 12 of docs/pocl.md allows: a
# loop around a barrier that may run no turn makes PoCL copy each later technique's loops
# once per way around it, and only the first technique's may (the last's copies
# nothing), so that two techniques compile 1 + 2 sample loops and three (--split-brdf)
# 1 + 2 + 2: 5/3 as many. Every technique's loops could run no turn until 2026-12-01:
# 1 + 3 and 1 + 3 + 9 sample loops, 15-27 s to compile each such kernel.
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
# misalloc render with a fresh PoCL cache and its remarks in $work/log.
render_with_remarks() {
  mkdir -p "$work/cache"
  if ! POCL_VECTORIZER_REMARKS=1 POCL_KERNELLIB_NAME=avx2 POCL_CACHE_DIR="$work/cache" "$misalloc" render \
      --device cpu --reference none --scene spheres --size 32x32 --out "$work/r.exr" --report "$work/r.json" \
      --no-preview "$@" >"$work/log" 2>&1; then
    echo "FAIL: misalloc render $* failed:"; tail -5 "$work/log"; exit 1
  fi
  rm -rf "$work/cache"
  grep -q '"device": "pthread' "$work/r.json" || { echo "skipped: the CPU's OpenCL device is not PoCL's"; exit 77; }
  grep -q "pthread-haswell" "$work/r.json" || { echo "FAIL: $* did not run on PoCL's haswell target"; exit 1; }
}
# The vectorised loops of samplePixelStage's work-group functions in $work/log: each
# remark belongs to the function that the inliner's remarks before it last named.
pixel_stage_loops() {
  sed 's/<unknown>:0:0: /\n/g' "$work/log" | awk '/into .[A-Za-z_0-9]+. /{ match($0, /into .[A-Za-z_0-9]+./);
    f = substr($0, RSTART + 6, RLENGTH - 7) } /vectorized loop \(/ && f ~ /samplePixelStage_workgroup/ { n++ }
    END { print n + 0 }'
}
status=0
for config in "--envmap-pdf plain" "--envmap-pdf plain --split-brdf" "--envmap-pdf optimal-pixel" \
  "--envmap-pdf optimal-pixel --product"; do
  # shellcheck disable=SC2086
  render_with_remarks --method equal --spp 8 $config
  vectorised=$(grep -o "vectorized loop (vectorization width" "$work/log" | wc -l)
  short=$(grep -o "instruction return type cannot be vectorized" "$work/log" | wc -l)
  echo "$config: $vectorised loops vectorised, $short kept scalar by a short vector"
  if [ "$short" -ne 0 ] || [ "$vectorised" -eq 0 ]; then
    echo "FAIL: $config: a work-item loop holds a short vector, or none is vectorised"; status=1
  fi
  [ "$config" = "--envmap-pdf plain" ] && two_loops=$(pixel_stage_loops)
  [ "$config" = "--envmap-pdf plain --split-brdf" ] && three_loops=$(pixel_stage_loops)
  [ "$config" = "--envmap-pdf optimal-pixel" ] && equal_loops=$(pixel_stage_loops)
done
echo "samplePixelStage's work-group loops vectorised: $two_loops (two techniques), $three_loops (three)"
if [ "$two_loops" -eq 0 ] || [ $((3 * three_loops)) -ne $((5 * two_loops)) ]; then
  echo "FAIL: three techniques' sample loops are not 5/3 of two's: copied (docs/pocl.md, rule 12)"; status=1
fi
render_with_remarks --method exact --spp 64 --envmap-pdf optimal-pixel
exact_loops=$(pixel_stage_loops)
echo "samplePixelStage's work-group loops vectorised: $equal_loops (equal), $exact_loops (exact, with its statistics kernel)"
if [ "$equal_loops" -eq 0 ] || [ "$exact_loops" -lt $((2 * equal_loops)) ]; then
  echo "FAIL: exact's statistics kernel vectorises fewer loops than the kernel without statistics"; status=1
fi
[ $status -eq 0 ] && echo "PASS" || echo "FAIL (docs/pocl.md, rules 8 and 12)"
exit $status
