#!/bin/sh
# tools/run_tests.sh SLOTS LOGDIR TEST... - make test's runner (the Makefile's
# test-all): runs `make TEST` for every TEST, each even when one before it
# failed, SLOTS at a time, each into LOGDIR/TEST.log. A test's whole output
# is printed when it ends (never two interleaved), after a line with its
# result and time; at the end the failed ones and "N passed, M failed".
# Exit status 0 only when every test passed. MAKE names the make to run;
# TESTS_START, a start time in seconds (date +%s), adds "== done in N s".
#
# Why more than one at a time: most tests are one process on one core, so
# the 2-core machine CI runs on sat half idle while the tests ran one after
# the other (635 of a fresh clone's 893 s). Tests that share no output can
# run side by side; tests/hardening.mk and tests/threads.mk name each tool
# probe's file after its test for that reason.
set -u
make=${MAKE:-make}

if [ "${1:-}" = --one ]; then # one test (run by xargs, below)
    logs=$2 t=$3
    t0=$(date +%s)
    if $make --no-print-directory "$t" >"$logs/$t.log" 2>&1; then r=ok; else r=FAILED; fi
    echo "$r" >"$logs/$t.result"
    s=$(($(date +%s) - t0))
    until mkdir "$logs/.print" 2>/dev/null; do sleep 1; done # one report at a time
    echo "== $t: $r ($s s)"
    cat "$logs/$t.log"
    rmdir "$logs/.print"
    exit 0
fi

if [ $# -lt 3 ]; then sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; exit 2; fi
slots=$1 logs=$2
shift 2
rm -rf "$logs"
mkdir -p "$logs" || exit 1
printf '%s\n' "$@" | MAKE=$make xargs -P "$slots" -n 1 sh "$0" --one "$logs"
pass=0 fail=0 failed=
for t in "$@"; do
    if [ "$(cat "$logs/$t.result" 2>/dev/null)" = ok ]; then pass=$((pass + 1)); else
        fail=$((fail + 1))
        failed="$failed $t"
    fi
done
if [ -n "${TESTS_START:-}" ]; then echo "== done in $(($(date +%s) - TESTS_START)) s"; fi
if [ $fail -ne 0 ]; then echo "failed:$failed"; fi
echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
