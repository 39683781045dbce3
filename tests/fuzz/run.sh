#!/bin/sh
# Runs each fuzz target for a bounded time on its seeds (tests/fuzz/<name>/) and what earlier
# runs found (<dir>/corpus/<name>/); prints the executions per target and fails when a target
# finds a crash, a leak, undefined behaviour, a timeout or a broken property (the input is
# kept in <dir>/artifacts/).
#   run.sh BUILD_FUZZ_DIR SECONDS TARGET...
set -u
dir=$1; seconds=$2; shift 2
here=$(dirname "$0")
mkdir -p "$dir/artifacts" "$dir/logs"
status=0
summary=""
for bin in "$@"; do
  name=$(basename "$bin" | sed 's/^fuzz_//')
  seeds="$here/$name"
  corpus="$dir/corpus/$name"
  mkdir -p "$corpus"
  log="$dir/logs/$name.log"
  ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 \
  LSAN_OPTIONS=suppressions="$here/lsan.supp":print_suppressions=0 UBSAN_OPTIONS=print_stacktrace=1 \
    "$bin" -max_total_time="$seconds" -print_final_stats=1 -timeout=10 -rss_limit_mb=2560 \
      -artifact_prefix="$dir/artifacts/$name-" "$corpus" "$seeds" >"$log" 2>&1
  rc=$?
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  if [ $rc -ne 0 ]; then
    status=1
    echo "fuzz: $name FAILED (exit $rc); log $log:"
    grep -E "ERROR|runtime error|fuzz property failed|Test unit written|SUMMARY" "$log" | head -20
    summary="$summary $name=FAILED"
  else
    summary="$summary $name=${execs:-?}"
  fi
done
echo "fuzz: executions in ${seconds} s each:$summary"
exit $status
