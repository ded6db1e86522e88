#!/usr/bin/env bash
# bench/walk_ab.sh OLD [NEW] [RUNS] [-- walk_rays args]
#
# The CPU walk of two versions of linear_rt.h on the demo's rays (primary
# rays and random segments, bench/walk_rays.c), alternated: RUNS rounds
# (default 6), each running both builds, the first of a round swapping from
# round to round, so that this machine's slow and fast phases fall on both.
# OLD and NEW are commits (or a path to a header); NEW defaults to the
# working tree's linear_rt.h. Prints each set's median M rays/s and NEW / OLD.
# Both are built as the demo is (-O3, NATIVE=-march=native by default here:
# NATIVE= for a plain x86-64 build with the AVX2 walk chosen at run time).
# walk_rays args default to --size 512 --threads 2 --runs 5.
#
#   bench/walk_ab.sh c12ebe8                  # the demo's segments then and now
#   bench/walk_ab.sh c12ebe8 HEAD 8 -- --size 1024
set -eu
top=$(cd "$(dirname "$0")/.." && pwd)
if [ $# -lt 1 ]; then sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 2; fi
old=$1; shift
new=
runs=6
if [ $# -gt 0 ] && [ "$1" != "--" ]; then new=$1; shift; fi
if [ $# -gt 0 ] && [ "$1" != "--" ]; then runs=$1; shift; fi
if [ $# -gt 0 ] && [ "$1" = "--" ]; then shift; fi
if [ $# -eq 0 ]; then set -- --size 512 --threads 2 --runs 5; fi
native=${NATIVE--march=native}
dir=$(mktemp -d /tmp/walk_ab.XXXXXX)
header() { # $1: a commit or a file; $2: where the header goes
    if [ -z "$1" ]; then cp "$top/linear_rt.h" "$2"
    elif [ -f "$1" ]; then cp "$1" "$2"
    else git -C "$top" show "$1:linear_rt.h" > "$2"; fi
}
header "$old" "$dir/old.h"
header "$new" "$dir/new.h"
for v in old new; do
    # shellcheck disable=SC2086
    ${CC:-cc} -std=c99 -O3 $native -w -DLRT_HEADER="\"$dir/$v.h\"" -DLINEAR_RT_SELF="\"$dir/$v.h\"" \
        "$top/bench/walk_rays.c" -o "$dir/$v" -lm -lpthread
done
i=1
while [ "$i" -le "$runs" ]; do
    if [ $((i % 2)) -eq 1 ]; then order="old new"; else order="new old"; fi
    for v in $order; do "$dir/$v" "$@" | sed "s/^/$v /" >> "$dir/results.txt"; done
    i=$((i + 1))
done
awk -v o="${old}" -v n="${new:-working tree}" '
function median(list,   a, k, n2, t) {
    n2 = split(list, a, " ")
    for (k = 1; k <= n2; ++k) for (t = k + 1; t <= n2; ++t) if (a[t] + 0 < a[k] + 0) { x = a[k]; a[k] = a[t]; a[t] = x }
    return n2 % 2 ? a[(n2 + 1) / 2] : (a[n2 / 2] + a[n2 / 2 + 1]) / 2
}
{ v[$1 " " $2] = v[$1 " " $2] " " $3; hits[$1 " " $2] = $4 }
END {
    printf "%-10s %14s %14s %8s   (M rays/s, medians of %d runs; old %s, new %s)\n", "set", "old", "new", "new/old", '"$runs"', o, n
    split("primary segments", sets, " ")
    for (k = 1; k <= 2; ++k) {
        s = sets[k]; mo = median(v["old " s]); mn = median(v["new " s])
        printf "%-10s %14.3f %14.3f %8.3f%s\n", s, mo, mn, mn / mo, hits["old " s] == hits["new " s] ? "" : "   (the hits differ!)"
    }
}' "$dir/results.txt"
rm -rf "$dir"
