#!/usr/bin/env python3
"""tools/loop_weights.py - the instructions of each compiled kernel's loops.

Reads what RADV prints with RADV_DEBUG=shaders (e.g. RADV_DEBUG=shaders
build/gpu_stats --gpu navi31 --out /tmp/gs.md > isa.txt 2>&1) and prints,
for each "disasm:" block in order (gpu_stats' table order), its static
instructions, those of its outermost loop (from the loop head to the last
branch back to it) and of the largest loop inside that one. Labels do not
count; s_delay_alu, s_waitcnt and the like do. bench/main.c's wave_weights
take linear_rt's node test as outer - inner (the walk without its texel
loop) and its texel test as inner.

    python3 tools/loop_weights.py isa.txt
"""
import re
import sys


def count(body, a, b):
    return sum(1 for line in body[a:b + 1] if line.strip() and not re.match(r'^BB\d+:', line.strip()))


def main(path):
    text = open(path).read().split('\n')
    starts = [k for k, line in enumerate(text) if line.startswith('disasm:')]
    for n, first in enumerate(starts):
        body = text[first + 1:]
        end = next((k for k, line in enumerate(body) if not line.strip()), len(body))
        body = body[:end]
        labels = {}
        for k, line in enumerate(body):
            m = re.match(r'^(BB\d+):', line)
            if m:
                labels[m.group(1)] = k
        heads = {}
        for k, line in enumerate(body):
            m = re.search(r's_c?branch\w*\s+(BB\d+)', line)
            if m and m.group(1) in labels and labels[m.group(1)] < k:
                a = labels[m.group(1)]
                heads[a] = max(heads.get(a, 0), k)
        spans = sorted(((b - a, a, b) for a, b in heads.items()), reverse=True)
        if not spans:
            print('%d: %d instructions, no loop' % (n, count(body, 0, len(body) - 1)))
            continue
        outer = spans[0]
        inner = [s for s in spans[1:] if outer[1] < s[1] and s[2] < outer[2]]
        big = max(inner) if inner else None
        print('%d: %d instructions, outer loop %d, largest inner loop %s' % (
            n, count(body, 0, len(body) - 1), count(body, outer[1], outer[2]),
            count(body, big[1], big[2]) if big else '-'))


if __name__ == '__main__':
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
