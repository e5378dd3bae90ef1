#!/usr/bin/env bash
# Submits a sharded misalloc run to Slurm: a job array of N shards, at most K running
# at once (%K), and the merge, which waits for every shard to succeed.
#   submit.sh compare|render N K OUT [--wait] -- OPTIONS...
# OPTIONS are those of `misalloc compare` or `misalloc render`, without --shard,
# --out-dir, --out and --report; compare's --shard-unit repeat reaches every shard, and
# N may then reach the scenes times --repeats. MISALLOC names the binary (default:
# misalloc on PATH); OUT must be on a file system every node sees, and so should
# --cache-dir. --wait returns when the merge has finished, with its exit status.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
refuse() {
  echo "submit.sh: $*" >&2
  exit 2
}
kind=$1 n=$2 k=$3 out=$(realpath -m "$4")
shift 4
wait=()
if [ "${1:-}" = --wait ]; then
  wait=(--wait)
  shift
fi
[ "${1:-}" = -- ] && shift
case "$kind" in
  compare) script="$here/compare-shard.sbatch" ;;
  render) script="$here/render-band.sbatch" ;;
  *) refuse "the first argument is compare or render, not '$kind'" ;;
esac
[[ $n =~ ^[1-9][0-9]*$ ]] || refuse "N '$n': the number of shards is a whole number, at least 1"
[[ $k =~ ^[1-9][0-9]*$ ]] || refuse "K '$k': the shards running at once are a whole number, at least 1"
# sbatch expands % in --output (%x, %A, %j): a path holding one would send the logs elsewhere.
[[ $out != *%* ]] || refuse "OUT '$out' holds '%', which sbatch's --output patterns expand; choose another folder"
mkdir -p "$out"
array=$(sbatch --parsable --array="0-$((n - 1))%$k" --output="$out/%x-%A_%a.out" "$script" "$out" "$@")
array=${array%%;*}
echo "submitted the $kind shards as job array $array"
# ${wait[@]+...}: an empty array under set -u is an unbound variable to bash before 4.4.
sbatch ${wait[@]+"${wait[@]}"} --parsable --dependency="afterok:$array" --kill-on-invalid-dep=yes --output="$out/%x-%j.out" \
  "$here/merge.sbatch" "$kind" "$out" "$n"
