# Sourced by .ci/setup and scripts/test-suite.
# step NAME COMMAND...: runs COMMAND and returns its exit status; where MISALLOC_CI_TIMES
# names a folder, appends a line "NAME start end" (seconds since the epoch) to its
# steps.tsv, which scripts/ci-times reads, whether COMMAND failed or not.
step() {
  local name=$1 start rc=0
  shift
  start=$(date +%s.%N)
  "$@" || rc=$?
  if [ -n "${MISALLOC_CI_TIMES:-}" ]; then
    printf '%s\t%s\t%s\n' "$name" "$start" "$(date +%s.%N)" >>"$MISALLOC_CI_TIMES/steps.tsv"
  fi
  return $rc
}
