#!/usr/bin/env bash
# bench/gpu_check.sh [OUT] - the device check for a lent GPU, in one command
# (under 8 minutes on an H200): test_vulkan, the demo and `bench --only
# vulkan`, with the GPU at its working clock, and nvidia-smi's SM clock
# logged beside them. Two files go into OUT (default $OUT, else
# build/gpu-check; the device tool brings back 8 files at most):
# gpu_check.md (the device, each step's last lines, the clock during each
# step, the benchmark's results.md) and clocks.csv (every sample, by step);
# the full logs stay in a temporary folder.
#
# Build here first, where the packages are (the device machine reaches no
# registry), and carry the programs and the Vulkan loader:
#   make build/test_vulkan build/demo build/bench
#   (once) the loader's .deb files into .gl/, as the device tool's README says
#   device run: carry [".gl", "build/test_vulkan", "build/demo", "build/bench"]
#     command: bench/gpu_check.sh        (timeout_s 540)
# Sizes: GPU_CHECK_SIZE (the bench's, default 1024), GPU_CHECK_DEMO_SIZE (1024),
# GPU_CHECK_RUNS (default 5). Without nvidia-smi (lavapipe, say) the
# clock is not logged and the warm-up is skipped: the rest runs the same.
set -u
top=$(cd "$(dirname "$0")/.." && pwd)
cd "$top" || exit 2
out=${1:-${OUT:-build/gpu-check}}
size=${GPU_CHECK_SIZE:-1024}
demo_size=${GPU_CHECK_DEMO_SIZE:-1024}
runs=${GPU_CHECK_RUNS:-5}
mkdir -p "$out"
tmp=$(mktemp -d /tmp/gpu_check.XXXXXX)
md="$out/gpu_check.md"
: > "$md"
say() { printf '%s\n' "$*" | tee -a "$md"; }

# the loader and NVIDIA's driver files, where the machine is bare
if [ -d .gl ] && ! ldconfig -p 2>/dev/null | grep -q libvulkan.so.1; then
    for f in .gl/*.deb; do dpkg -x "$f" / 2>/dev/null; done
    ldconfig
fi
if [ -f /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ] && [ -z "${VK_DRIVER_FILES:-}" ]; then
    export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
for p in build/test_vulkan build/demo build/bench; do
    [ -x "$p" ] || { say "gpu_check: $p is missing: build it here first (make $p) and carry it"; exit 2; }
done

say "# linear_rt on a GPU: $(date -u '+%Y-%m-%d %H:%M UTC')"
say ""
smi=0
: > "$out/clocks.csv"
if command -v nvidia-smi >/dev/null 2>&1; then
    smi=1
    say "    $(nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,clocks.max.mem --format=csv,noheader)"
fi
logger=
clock_start() { # nvidia-smi's samples every 250 ms into a file of this step's own
    [ "$smi" = 1 ] || return 0
    nvidia-smi --query-gpu=timestamp,clocks.sm,clocks.mem,utilization.gpu,temperature.gpu,power.draw \
        --format=csv,noheader -lms 250 > "$tmp/clock_$1.csv" 2>/dev/null &
    logger=$!
}
clock_stop() { # the step's samples into clocks.csv, prefixed by its name
    [ -n "$logger" ] || return 0
    kill "$logger" 2>/dev/null
    wait "$logger" 2>/dev/null
    logger=
    sed "s/^/$1, /" "$tmp/clock_$1.csv" >> "$out/clocks.csv"
}
run() { # name, limit in s, command...: its log in tmp, its last lines in the results file
    local name=$1 limit=$2 rc
    shift 2
    clock_start "$name"
    timeout "$limit" "$@" > "$tmp/$name.log" 2>&1
    rc=$?
    clock_stop "$name"
    say ""
    say "## $name (exit $rc): $*"
    say ""
    tail -n "${TAIL:-12}" "$tmp/$name.log" | sed 's/^/    /' | tee -a "$md" > /dev/null
    return $rc
}

status=0
# exactness first: every GPU answer against the CPU's, the trees byte for byte
TAIL=6 run test_vulkan 240 build/test_vulkan || status=1
# the clock: back-to-back dispatches until it is up (the demo's 1M rays, a
# few times), so that the timed runs below start at the working clock
if [ "$smi" = 1 ]; then
    clock_start warm-up
    for _ in 1 2 3; do timeout 60 build/demo --no-pictures --size "$demo_size" > /dev/null 2>&1; done
    clock_stop warm-up
fi
TAIL=40 run demo 120 build/demo --no-pictures --size "$demo_size" --threads "$(nproc)" || status=1
# the benchmark's Vulkan methods (each trace a batch of about 10 ms of
# back-to-back dispatches, the mean of a batch its time)
TAIL=3 run bench 300 build/bench --only vulkan --size "$size" --runs "$runs" --out "$tmp/bench" || status=1

if [ "$smi" = 1 ]; then
    say ""
    say "## SM clock (MHz) during each step: min / median / max of nvidia-smi's samples every 250 ms"
    say ""
    awk -F', *' '{ v = $3 + 0; n[$1]++; s[$1, n[$1]] = v }
        END {
            for (k in n) {
                m = n[k]
                for (i = 1; i <= m; ++i) for (j = i + 1; j <= m; ++j) if (s[k, j] < s[k, i]) { t = s[k, i]; s[k, i] = s[k, j]; s[k, j] = t }
                printf "    %-12s %6d / %6d / %6d  (%d samples)\n", k, s[k, 1], s[k, int((m + 1) / 2)], s[k, m], m
            }
        }' "$out/clocks.csv" | sort | tee -a "$md"
fi
if [ -f "$tmp/bench/results.md" ]; then
    say ""
    cat "$tmp/bench/results.md" >> "$md"
fi
say ""
say "gpu_check: exit $status; $md (the full logs: $tmp)"
exit $status
