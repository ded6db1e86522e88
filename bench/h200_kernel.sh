#!/bin/sh
# bench/h200_kernel.sh [COMMIT] [OUT] - weigh linear_rt's trace kernel as the H200 ran it: the
# trace module (buffer depth) of COMMIT's shaders_spv.h (default a46c342, the commit of the
# H200's benchmark run in docs/PERFORMANCE.md), compiled by RADV for RDNA3 through
# build/gpu_stats --spv, its bindings read from the module's own decorations. Writes
# OUT/gpu-weights.tsv (default build/h200): this build's pipelines and the peers, and the
# old kernel as "h200 linear_rt trace" (an infinite tree) and "h200 linear_rt trace, back
# 16-bit" (a thickness tree: the yard back), for bench/calibrate.py.
set -eu
commit=${1:-a46c342}
out=${2:-build/h200}
mkdir -p "$out"
git show "$commit:shaders_spv.h" > "$out/shaders_spv.h"
mask=$(python3 - "$out/shaders_spv.h" "$out/trace_buffer.spv" <<'PY'
import re, struct, sys
text = open(sys.argv[1]).read()
m = re.search(r'lrt_spv_trace_buffer\[\]\s*=\s*\{(.*?)\};', text, re.S)
words = [int(x, 0) for x in re.findall(r'0x[0-9a-fA-F]+|\b\d+\b', m.group(1))]
open(sys.argv[2], 'wb').write(struct.pack('<%dI' % len(words), *words))
mask, k = 0, 5                       # past the SPIR-V header
while k < len(words):
    count, op = words[k] >> 16, words[k] & 0xffff
    if op == 71 and count >= 4 and words[k + 2] == 33:   # OpDecorate %x Binding n
        mask |= 1 << words[k + 3]
    k += max(count, 1)
print(hex(mask))
PY
)
echo "h200_kernel: $commit's trace module, bindings $mask"
# specialization constant 0: a thickness tree's back codes compiled in; 1: its node bits
build/gpu_stats --gpu navi31 --out "$out/gpu-stats.md" --weights "$out/gpu-weights.tsv" \
    --spv "h200 linear_rt trace=$out/trace_buffer.spv:$mask:0,16" \
    --spv "h200 linear_rt trace, back 16-bit=$out/trace_buffer.spv:$mask:1,16"
