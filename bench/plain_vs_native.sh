#!/usr/bin/env bash
# bench/plain_vs_native.sh [RUNS] [BENCH OPTIONS...] - is the walk a plain
# build chooses at run time as fast as a -march=native build's?
#
# `make bench-plain-vs-native` builds build/bench-twin and calls this. That
# benchmark holds the library twice: built as users build it (plain -O3, the
# AVX2 walk chosen at run time) and built with -march=native, as the methods
# "linear_rt cpu N" and "linear_rt cpu N native". Each scene times both on
# the same rays one after the other, so the machine's slow and fast phases
# (docs/PERFORMANCE.md, "The machine and its noise": whole runs move by
# 10-40%) fall on both alike. This runs `--only "linear_rt cpu"` RUNS times
# (default 1), keeps each row's best M rays/s and prints plain / native per
# row, the rows below 0.9x and the geometric mean; it exits 1 when a row is
# below 0.9x. Results and logs: build/plain-vs-native/ (B=DIR: another build
# folder).
set -euo pipefail

B=${B:-build}
runs=${1:-1}
shift || true
case $runs in '' | *[!0-9]* | 0)
    echo "usage: bench/plain_vs_native.sh [RUNS >= 1] [bench options...]" >&2
    exit 2
    ;;
esac
bin=$B/bench-twin
[ -x "$bin" ] || {
    echo "plain_vs_native: no $bin: run make bench-plain-vs-native" >&2
    exit 2
}

out=$B/plain-vs-native
rm -rf "$out"
mkdir -p "$out"
for ((i = 1; i <= runs; ++i)); do
    echo "run $i: $bin --only \"linear_rt cpu\" $*"
    "$bin" --only "linear_rt cpu" --out "$out/run-$i" "$@" >"$out/run-$i.log" 2>&1 ||
        { tail -5 "$out/run-$i.log"; exit 1; }
done
head -1 "$out/run-1.log" | sed 's/.*linear_rt.s CPU walk/plain build: CPU walk/'
flags=$(cat "$B/twin-flags.stamp" 2>/dev/null || true)
echo "flags (plain / native): ${flags:- / -march=native}"
echo "  (the Makefile's PLAIN_CFLAGS / TWIN_CFLAGS; by default the native copy is -march=native)"

# results.csv: method,device,exact,threads,scene,rays,count,...,mrays_per_s (11th)
awk -F, -v runs="$runs" '
FNR == 1 { next }
$1 ~ /^linear_rt cpu/ {
    native = $1 ~ / native$/
    method = $1; sub(/ native$/, "", method)
    key = method "|" $5 "|" $6
    if (!native && !(key in seen)) { seen[key] = 1; order[++n] = key }
    if ($11 + 0 > best[native, key]) best[native, key] = $11 + 0
}
END {
    printf "%-18s %-22s %-20s %9s %9s %6s\n", "method", "scene", "rays", "plain", "native", "ratio"
    low = 0; logsum = 0; m = 0
    for (i = 1; i <= n; ++i) {
        split(order[i], f, "|")
        p = best[0, order[i]]; q = best[1, order[i]]
        if (p <= 0 || q <= 0) { printf "%-18s %-22s %-20s not measured in both builds\n", f[1], f[2], f[3]; low++; continue }
        r = p / q; logsum += log(r); m++
        if (r < 0.9) low++
        printf "%-18s %-22s %-20s %9.2f %9.2f %6.3f%s\n", f[1], f[2], f[3], p, q, r, (r < 0.9 ? "  < 0.9" : "")
    }
    printf "\n%d rows, M rays/s (best of %d run%s): plain / native geometric mean %.3f, %d rows below 0.9x\n",
           m, runs, (runs > 1 ? "s" : ""), (m ? exp(logsum / m) : 0), low
    exit low > 0
}' "$out"/run-*/results.csv
