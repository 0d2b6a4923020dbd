#!/usr/bin/env bash
# Runs each libFuzzer harness for FUZZ_SECONDS (default 60) from the seed corpus in
# tests/fuzz/corpus/<name> plus what earlier runs found (BUILD/fuzz-corpus/<name>), after
# replaying tests/fuzz/regressions/<name>. A crash, hang (> 10 s), leak or sanitizer report
# stops the run and leaves the input in BUILD/fuzz-artifacts/; copy it into
# tests/fuzz/regressions/<name>/ once fixed. Usage: run.sh BUILD_DIR [NAME...]
set -euo pipefail
build=$1
shift
names=("$@")
[ ${#names[@]} -gt 0 ] || names=(scene mesh)
here=$(cd "$(dirname "$0")" && pwd)
seconds=${FUZZ_SECONDS:-60}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
# Third-party leaks only (see the file).
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$here/../sanitize/lsan.supp:print_suppressions=0}
for name in "${names[@]}"; do
  bin=$build/bin/fuzz_$name
  work=$build/fuzz-corpus/$name
  artifacts=$build/fuzz-artifacts/$name/
  mkdir -p "$work" "$artifacts"
  case $name in
    scene) extra=(-dict="$here/scene.dict" -max_len=16384) ;;
    mesh) extra=(-max_len=65536) ;;
  esac
  # A harness may have no regression inputs yet (git keeps no empty folder).
  regressions=""
  if [ -d "$here/regressions/$name" ]; then
    regressions=$(find "$here/regressions/$name" -type f | sort)
  fi
  if [ -n "$regressions" ]; then
    echo "fuzz_$name: replaying $(echo "$regressions" | wc -l) regression inputs"
    # shellcheck disable=SC2086
    "$bin" -timeout=10 -rss_limit_mb=4096 $regressions >"$build/fuzz-$name-regressions.log" 2>&1 ||
      { tail -50 "$build/fuzz-$name-regressions.log"; exit 1; }
  fi
  echo "fuzz_$name: fuzzing for $seconds s (log: $build/fuzz-$name.log)"
  status=0
  "$bin" "${extra[@]}" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 \
    -print_final_stats=1 -artifact_prefix="$artifacts" "$work" "$here/corpus/$name" \
    >"$build/fuzz-$name.log" 2>&1 || status=$?
  grep -E '^(#[0-9]+ +DONE|stat::number_of_executed_units|Done )' "$build/fuzz-$name.log" || true
  if [ $status -ne 0 ]; then
    tail -60 "$build/fuzz-$name.log"
    echo "fuzz_$name: FAILED (status $status); the input is in $artifacts"
    exit $status
  fi
done
