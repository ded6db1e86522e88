#!/bin/sh
# bench/bench_ab.sh OLD NEW [RUNS [BENCH ARGS...]]
#
# Before/after speed of two builds of the benchmark (OLD and NEW: paths to
# build/bench binaries, e.g. one built in a `git worktree` of the commit
# before). Runs them alternated RUNS times (default 11), each first in every
# other run, with BENCH ARGS (default: --only "linear_rt vulkan" --size 128
# --runs 3), then prints for
# every (method, scene, rays) row the median M rays/s of each build and
# NEW / OLD, and per method the geometric mean of those ratios.
#
# Why medians of alternated runs: on a shared 2-core VM single runs are
# skewed (some come out up to 1.6x faster than the rest), so the best of a
# few runs picks whichever build was lucky; medians of 11 put rows whose
# code did not change within about 0.88-1.14x (docs/PERFORMANCE.md, "The
# machine and its noise"). Set LP_NUM_THREADS=1 for lavapipe rows.
# Results stay in $BENCH_AB_DIR (default: a new directory under /tmp).
set -eu
if [ $# -lt 2 ]; then sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 2; fi
old=$1 new=$2
shift 2
runs=11
if [ $# -gt 0 ]; then runs=$1; shift; fi
if [ $# -eq 0 ]; then set -- --only "linear_rt vulkan" --size 128 --runs 3; fi
dir=${BENCH_AB_DIR:-$(mktemp -d /tmp/bench_ab.XXXXXX)}
mkdir -p "$dir"
i=1
while [ "$i" -le "$runs" ]; do
    # each build first in every other run: the order may tilt a row by a few
    # percent (a change of no effect read 1.039 with the new build always
    # second and 0.998 with it first)
    if [ $((i % 2)) -eq 1 ]; then order="old new"; else order="new old"; fi
    for b in $order; do
        if [ "$b" = old ]; then exe=$old; else exe=$new; fi
        "$exe" "$@" --out "$dir/$b$i" >"$dir/$b$i.log" 2>&1 || { echo "bench_ab: $exe failed (log: $dir/$b$i.log)" >&2; exit 1; }
    done
    echo "bench_ab: run $i of $runs done" >&2
    i=$((i + 1))
done
# results.csv: method,device,exact,threads,scene,rays,count,build_ms,update_ms,trace_ms,mrays_per_s,...
# (quoted fields only at the end of a line, after the columns read here).
# Only this call's runs: a reused BENCH_AB_DIR may hold more from before
i=1
while [ "$i" -le "$runs" ]; do
    for b in old new; do
        tail -n +2 "$dir/$b$i/results.csv" | awk -F, -v b="$b" '{ print b "\t" $1 "\t" $5 "\t" $6 "\t" $11 }'
    done
    i=$((i + 1))
done | sort -t "$(printf '\t')" -k2,2 -k3,3 -k4,4 -k1,1 -k5,5g | awk -F '\t' '
    function median(n) { return n % 2 ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2 }
    function close_group() { if (cur == "new") nm = median(n); else if (cur == "old") om = median(n) }
    function flush() {
        if (om > 0 && nm > 0) {
            split(key, k, SUBSEP)
            printf "%-22s %-12s %-22s %9.3f %9.3f %6.2f\n", k[1], k[2], k[3], om, nm, nm / om
            logs[k[1]] += log(nm / om); rows[k[1]]++
        }
    }
    BEGIN { printf "%-22s %-12s %-22s %9s %9s %6s\n", "method", "scene", "rays", "old", "new", "new/old" }
    {
        row = $2 SUBSEP $3 SUBSEP $4
        if (row != key) { close_group(); flush(); key = row; om = nm = 0; cur = ""; n = 0 }
        if ($1 != cur) { close_group(); cur = $1; n = 0 }
        v[++n] = $5
    }
    END {
        close_group(); flush()
        for (m in rows) printf "%s: geometric mean new/old %.3f over %d rows\n", m, exp(logs[m] / rows[m]), rows[m]
    }'
echo "bench_ab: runs kept in $dir" >&2
