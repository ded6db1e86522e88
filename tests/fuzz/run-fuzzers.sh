#!/bin/sh
# tests/fuzz/run-fuzzers.sh SECONDS [--quick] NAME... - runs each built
# harness build/fuzz/NAME for SECONDS, one after the other, on a working
# corpus build/fuzz/corpus-NAME (new inputs go there; --quick: a fresh
# build/fuzz/quick-NAME instead) seeded read-only from tests/fuzz/corpus/NAME,
# and prints the executions reached and the harness's own closing line, or
# where the failing input and the log are. Exits 1 if any failed.
# Run from the repository root (the Makefile's fuzz and test-fuzz do).
set -u
seconds=$1
shift
quick=0
if [ "${1:-}" = --quick ]; then
    quick=1
    shift
fi
failed=0
for name in "$@"; do
    bin=build/fuzz/$name
    work=build/fuzz/corpus-$name
    log=build/fuzz/$name.log
    if [ $quick -eq 1 ]; then
        work=build/fuzz/quick-$name
        log=build/fuzz/quick-$name.log
        rm -rf "$work"
    fi
    mkdir -p "$work"
    # -timeout: an input that takes 20 s is a hang; -rss_limit_mb: the default 2 GiB
    "$bin" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 -print_final_stats=1 \
        -artifact_prefix="build/fuzz/$name-" "$work" "tests/fuzz/corpus/$name" >"$log" 2>&1
    rc=$?
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
    rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log")
    counts=$(grep "^$name: " "$log" | tail -n 1) # the harness's own closing line
    if [ "$rc" -eq 0 ]; then
        echo "$name: ${execs:-?} executions in $seconds s (${rate:-?}/s), corpus $(ls "$work" | wc -l) files"
        [ -n "$counts" ] && echo "  $counts"
    else
        failed=1
        echo "$name: FAILED (exit $rc) after ${execs:-?} executions; log: $log"
        grep -E "^$name: |runtime error|ERROR: |SUMMARY" "$log" | head -n 6 | sed 's/^/  /'
        ls build/fuzz/"$name"-crash-* build/fuzz/"$name"-oom-* build/fuzz/"$name"-timeout-* build/fuzz/"$name"-leak-* \
            2>/dev/null | sed 's/^/  input: /'
    fi
done
exit $failed
