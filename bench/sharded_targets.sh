#!/usr/bin/env bash
# The sharding targets of docs/results.md ("Sharded runs"): a compare sweep unsharded
# and as shards run one at a time, and a render unsharded and as 16 bands; for each, the
# CPU seconds of all shards against the unsharded run's, the merge's wall time against
# the sweep's, and the merged outputs against the unsharded ones (images bit for bit;
# the sweep's runs, times left out, to the digit).
#   bench/sharded_targets.sh MISALLOC_BINARY SCRATCH_DIR
# COMPARE_OPTIONS and RENDER_OPTIONS replace the sweep's and the render's options;
# COMPARE_SHARDS (default 7, the suite's scenes) and SHARD_UNIT (scene or repeat,
# compare --shard-unit; default scene) the sweep's split.
set -euo pipefail
misalloc=$1 scratch=$2
mkdir -p "$scratch"
cache="--cache-dir $scratch/cache"
compare=${COMPARE_OPTIONS:-"--suite --size 64x64 --methods equal,heuristic,exact --budgets 50,100,200 --repeats 2 --cost 1,1.5 --device cpu"}
render=${RENDER_OPTIONS:-"--envmap forest_slope --size 256x256 --spp 200 --method exact --cost 1,1.5 --device cpu --reference none"}
# "wall user sys" of a command, its output discarded.
measure() { /usr/bin/time -f "%e %U %S" -o "$scratch/time" "$@" >/dev/null 2>&1; cat "$scratch/time"; }
sum() { awk '{w += $1; c += $2 + $3} END {printf "%.2f %.2f\n", w, c}'; }

# The references once, outside the timings.
"$misalloc" compare $compare $cache --out-dir "$scratch/warm" >/dev/null 2>&1
read -r wall user sys < <(measure "$misalloc" compare $compare $cache --out-dir "$scratch/whole")
echo "compare unsharded: wall $wall s, CPU $(awk "BEGIN {print $user + $sys}") s"
shards=${COMPARE_SHARDS:-7} unit=${SHARD_UNIT:-scene}
for ((k = 0; k < shards; ++k)); do
  measure "$misalloc" compare $compare $cache --shard "$k/$shards" --shard-unit "$unit" --out-dir "$scratch/shard$k"
done | sum | { read -r w c; echo "compare $shards shards by $unit: wall $w s, CPU $c s"; }
parts=()
for ((k = 0; k < shards; ++k)); do parts+=("$scratch/shard$k"); done
read -r wall user sys < <(measure "$misalloc" merge --out-dir "$scratch/merged" "${parts[@]}")
echo "compare merge: wall $wall s"
same=0 differ=0
while read -r f; do
  if cmp -s "$scratch/whole/$f" "$scratch/merged/$f"; then same=$((same + 1)); else differ=$((differ + 1)); fi
done < <(cd "$scratch/whole" && find . -name '*.exr' -o -name '*.png')
echo "compare images: $same bit for bit, $differ differ"
# runs.csv without its times (wall, kernel, allocation, host, efficiency): every error and count.
untimed() { cut -d, -f1-5,10-13,15- "$1"; }
if diff -q <(untimed "$scratch/whole/runs.csv") <(untimed "$scratch/merged/runs.csv") >/dev/null; then
  echo "compare runs: $(($(wc -l <"$scratch/whole/runs.csv") - 1)), the same but their times"
else
  echo "compare runs: DIFFER from the unsharded run's"
fi

read -r wall user sys < <(measure "$misalloc" render $render --no-preview --out "$scratch/whole.exr" --report "$scratch/whole.json")
echo "render unsharded: wall $wall s, CPU $(awk "BEGIN {print $user + $sys}") s"
bands=()
for ((k = 0; k < 16; ++k)); do
  measure "$misalloc" render $render --shard "$k/16" --out "$scratch/band$k.exr" --report "$scratch/band$k.json"
done | sum | { read -r w c; echo "render 16 bands: wall $w s, CPU $c s"; }
for ((k = 0; k < 16; ++k)); do bands+=("$scratch/band$k.exr"); done
read -r wall user sys < <(measure "$misalloc" merge --out "$scratch/merged.exr" --report "$scratch/merged.json" "${bands[@]}")
echo "render merge: wall $wall s"
cmp -s "$scratch/whole.exr" "$scratch/merged.exr" && echo "render: merged bit for bit" || echo "render: merged DIFFERS"
