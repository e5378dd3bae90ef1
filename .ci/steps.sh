# Sourced by .ci/setup and scripts/test-suite.
# step NAME COMMAND...: runs COMMAND; where MISALLOC_CI_TIMES names a folder, appends a
# line "NAME start end" (seconds since the epoch) to its steps.tsv, which scripts/ci-times
# reads. A failing COMMAND fails the script (set -e) before anything is written.
step() {
  local name=$1 start
  shift
  start=$(date +%s.%N)
  "$@"
  if [ -n "${MISALLOC_CI_TIMES:-}" ]; then
    printf '%s\t%s\t%s\n' "$name" "$start" "$(date +%s.%N)" >>"$MISALLOC_CI_TIMES/steps.tsv"
  fi
}
