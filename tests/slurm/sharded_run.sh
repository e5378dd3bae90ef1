#!/usr/bin/env bash
# A sharded compare and render under a real one-node Slurm on localhost: writes its own
# slurm.conf, starts munged, slurmctld and slurmd as root (docs/testing.md), submits
# both with scripts/slurm/submit.sh (job arrays, each with its merge after afterok), checks
# the merged outputs against the unsharded runs, and stops the daemons it started by
# their process ids. Exit 77 (skipped), saying why, where it cannot run.
#   sharded_run.sh MISALLOC_BINARY SOURCE_DIR
set -euo pipefail
misalloc=$1 source=$2
skip() { echo "SKIPPED: $*"; exit 77; }

# submit.sh's refusals, made before it creates OUT or submits anything: they need no
# Slurm, and run wherever this test does, against an sbatch that only records its call.
stub=$(mktemp -d /tmp/misalloc_submit.XXXXXX)
trap 'rm -rf "$stub"' EXIT
mkdir "$stub/bin"
printf '#!/bin/sh\necho "$*" >>"%s/calls"\necho 1\n' "$stub" >"$stub/bin/sbatch"
chmod +x "$stub/bin/sbatch"
refused() {  # expected message, then submit.sh's arguments
  local expected=$1 output
  shift
  if output=$(PATH="$stub/bin:$PATH" bash "$source/scripts/slurm/submit.sh" "$@" 2>&1); then
    echo "FAILED: submit.sh $* was not refused"; exit 1
  fi
  [[ $output == *"$expected"* ]] || { echo "FAILED: submit.sh $*: '$output' lacks '$expected'"; exit 1; }
  [ ! -e "$stub/calls" ] || { echo "FAILED: submit.sh $* called sbatch"; exit 1; }
}
for n in 0 -1 x 1.5 ""; do refused "N '$n'" render "$n" 1 "$stub/out" -- --envmap sun; done
for k in 0 -2 y; do refused "K '$k'" compare 2 "$k" "$stub/out" -- --suite; done
refused "holds '%'" render 2 1 "$stub/out%j" -- --envmap sun
[ ! -e "$stub/out" ] && [ ! -e "$stub/out%j" ] || { echo "FAILED: a refused submit.sh created OUT"; exit 1; }
# Without --wait, its array is empty: the merge's sbatch gets no empty argument.
PATH="$stub/bin:$PATH" bash "$source/scripts/slurm/submit.sh" render 2 1 "$stub/out" -- --envmap sun >/dev/null
grep -q -- '^--parsable --dependency=afterok:1 ' "$stub/calls" || { cat "$stub/calls"; echo "FAILED: the merge's sbatch"; exit 1; }
rm -rf "$stub"
echo "submit.sh: its refusals before any work, and a submission without --wait"
[ "$(id -u)" -eq 0 ] || skip "a one-node Slurm starts its daemons as root; this runs as $(id -un)"
for tool in munged slurmctld slurmd sbatch sinfo; do
  command -v "$tool" >/dev/null || skip "$tool is missing: .ci/setup installs Debian's slurm-wlm and munge"
done
id munge >/dev/null 2>&1 || skip "there is no munge user: install Debian's munge"

scratch=$(mktemp -d /tmp/misalloc_slurm.XXXXXX)
chmod 0755 "$scratch"  # munged, as the munge user, reaches its folder inside
pids=()
stop() {
  # ${pids[@]+...}: none started yet is an unbound variable under set -u to bash before 4.4.
  for pid in ${pids[@]+"${pids[@]}"}; do kill "$pid" 2>/dev/null || true; done
  for pid in ${pids[@]+"${pids[@]}"}; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  done
  rm -rf "$scratch"
}
trap stop EXIT

# munge, on a socket and key of its own: a munged of the system, if any, is left alone.
install -d -o munge -g munge -m 0711 "$scratch/munge"
head -c 1024 /dev/urandom >"$scratch/munge/munge.key"
chown munge:munge "$scratch/munge/munge.key"
chmod 0400 "$scratch/munge/munge.key"
socket=$scratch/munge/munge.socket
runuser -u munge -- munged --socket="$socket" --key-file="$scratch/munge/munge.key" \
  --pid-file="$scratch/munge/munged.pid" --log-file="$scratch/munge/munged.log" \
  --seed-file="$scratch/munge/munged.seed"
pids+=("$(cat "$scratch/munge/munged.pid")")

# Ports of this process's own, so that two runs on one machine do not meet.
port=$((20000 + ($$ % 10000) * 2))
node=$(hostname)
mkdir -p "$scratch/state" "$scratch/spool"
export SLURM_CONF=$scratch/slurm.conf
cat >"$SLURM_CONF" <<CONF
ClusterName=misalloc-test
SlurmctldHost=$node
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
StateSaveLocation=$scratch/state
SlurmdSpoolDir=$scratch/spool
SlurmctldPidFile=$scratch/slurmctld.pid
SlurmdPidFile=$scratch/slurmd.pid
SlurmctldLogFile=$scratch/slurmctld.log
SlurmdLogFile=$scratch/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
NodeName=$node CPUs=$(nproc) State=UNKNOWN
PartitionName=debug Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
slurmctld
for _ in $(seq 100); do [ -s "$scratch/slurmctld.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$scratch/slurmctld.pid")")
slurmd
for _ in $(seq 100); do [ -s "$scratch/slurmd.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$scratch/slurmd.pid")")
for _ in $(seq 300); do sinfo -h -o %T 2>/dev/null | grep -q idle && break; sleep 0.1; done
sinfo -h -o %T | grep -q idle || { cat "$scratch/slurmctld.log" "$scratch/slurmd.log"; echo "FAILED: the node never became idle"; exit 1; }
echo "slurm: one node ($node) idle"

export MISALLOC=$misalloc
out=$scratch/out
cache="--cache-dir $scratch/cache"
render="--envmap sun --size 16x40 --spp 32 --method exact --skip-image-below 0 --stages 2 --cost 1,1.5 --device cpu --reference none"
compare="--suite --size 8x8 --methods equal,exact --budgets 16 --repeats 1 --cost 1,1.5 --reference-spp 64 --device cpu"

"$misalloc" render $render --no-preview --out "$scratch/whole.exr" --report "$scratch/whole.json" >/dev/null
"$misalloc" compare $compare $cache --out-dir "$scratch/whole" >/dev/null 2>&1
# Both at once; then until the queue is empty, polled more often than sbatch --wait does.
bash "$source/scripts/slurm/submit.sh" render 3 2 "$out/render" -- $render
bash "$source/scripts/slurm/submit.sh" compare 2 1 "$out/compare" -- $compare $cache
for _ in $(seq 1200); do [ -z "$(squeue -h -o %i)" ] && break; sleep 0.1; done
[ -z "$(squeue -h -o %i)" ] || { squeue; echo "FAILED: the jobs did not finish in 2 minutes"; exit 1; }

cmp "$scratch/whole.exr" "$out/render/merged.exr"
grep -q '"node"' "$out/render/merged.json"
(cd "$scratch/whole" && find . -type f | sort) >"$scratch/whole.files"
(cd "$out/compare/merged" && find . -type f | sort) >"$scratch/merged.files"
diff "$scratch/whole.files" "$scratch/merged.files"
images=0
while read -r f; do
  case "$f" in *.exr | *.png) cmp "$scratch/whole/$f" "$out/compare/merged/$f"; images=$((images + 1)) ;; esac
done <"$scratch/whole.files"
[ "$images" -gt 0 ]
echo "PASSED: under Slurm, the merged render is the unsharded one bit for bit, and the merged compare has its $images images bit for bit"
