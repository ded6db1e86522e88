#!/usr/bin/env python3
"""bench/compaction.py STEPS_DIR WAVES_TSV WEIGHTS_TSV [--gpu navi31] [--wave 32] [--step N] | --self-test

What compacted passes pay, on the benchmark's estimate (issue: a wave pays
for its slowest ray). STEPS_DIR: `bench --only-counts --dump-steps DIR`, the
exact cell walk's steps per ray of each secondary set, in dispatch order. A
compacted trace (lrt_vk_cmd_trace_compacted) runs every ray for at most S
cell steps; the rays not done are appended, in order, to a list that the
next (indirect) dispatch runs in full waves, with a slice twice as long,
until none is left. Each wave of a pass pays its most steps in that pass
(its slowest lane, at most the slice) times the cell step's instructions,
and each wave of a later pass a resumed ray's set-up again: the kernel's
instructions outside its loop. Both weights are read from make gpu-stats'
weights file (the pipeline "linear_rt trace buffer, compacted round" of the
GPU asked for); --step N replaces the step's weight (a what-if: a cell step
of N instructions). Two schedules: as built (S and the number of rounds,
the last without a limit, read from linear_rt.h's LRT_K_VK_TRACE_SLICE and
_ROUNDS), and the first slice of 4, 6, 8, 12, 16, 24, 32 that the model
finds cheapest per set, rounds unbounded. Compared with the capped Hi-Z
walk's estimate of the same run (WAVES_TSV, `hiz64 vulkan`).
Not modelled: the store and load of a ray's state between passes, the
atomic counter, and the barrier and dispatch each pass costs the GPU."""
import glob
import math
import re
import os
import sys


def passes_cost(steps, first, wave, rounds=None):
    """(sum over passes and waves of the wave's most steps in that pass, waves run after the first pass,
    passes) for the rays' steps in dispatch order, the first slice `first`, doubling; with `rounds`,
    the last of that many passes has no limit (lrt_vk_cmd_trace_compacted)"""
    total = setups = 0
    passes, lst, s = 0, steps, first
    while lst:
        passes += 1
        if rounds is not None and passes == rounds:
            s = float("inf")
        nxt = []
        for i in range(0, len(lst), wave):
            g = lst[i:i + wave]
            total += max(min(r, s) for r in g)
            setups += passes > 1
            nxt.extend(r - s for r in g if r > s)
        lst, s = nxt, s * 2
    return total, setups, passes


def built_rounds(header):
    """(first slice, rounds) of the library's compacted trace, read from linear_rt.h's contract"""
    text = open(header).read()
    get = lambda name: int(re.search(r"#define %s (\d+)u" % name, text).group(1))
    return get("LRT_K_VK_TRACE_SLICE"), get("LRT_K_VK_TRACE_ROUNDS")


def self_test():
    """the model on rays worked out by hand; make test-bench runs it"""
    # 64 rays in two waves of 32: one slow ray (20 steps) in the first, the rest 1 step. One pass: 20 + 1.
    steps = [20] + [1] * 63
    assert passes_cost(steps, 10**9, 32) == (21, 0, 1)
    # slices 4, 8, 16: pass 1 pays 4 + 1, then the slow ray alone: 8 (16 left... 20 - 4 - 8 = 8 <= 16): 8
    assert passes_cost(steps, 4, 32) == (4 + 1 + 8 + 8, 2, 3)
    # two slow rays in different waves are packed into one wave of the second pass
    steps = [9] + [1] * 31 + [9] + [1] * 31
    assert passes_cost(steps, 4, 32) == (4 + 4 + 5, 1, 2)
    # two rounds: the second has no limit (20 - 4 = 16 steps in it)
    assert passes_cost([20] + [1] * 63, 4, 32, rounds=2) == (4 + 1 + 16, 1, 2)
    print("compaction: self-test passed")
    return 0


def main(argv):
    args = [a for a in argv[1:]]
    if args == ["--self-test"]:
        return self_test()
    gpu, wave, step_override = "navi31", 32, None
    for flag in ("--gpu", "--wave", "--step"):
        if flag in args:
            i = args.index(flag)
            value = args[i + 1]
            del args[i:i + 2]
            if flag == "--gpu":
                gpu = value
            elif flag == "--wave":
                wave = int(value)
            else:
                step_override = float(value)
    if len(args) != 3:
        print(__doc__.split("\n\n")[0])
        return 2
    steps_dir, waves_tsv, weights_tsv = args
    step = setup = None
    for line in open(weights_tsv):
        f = line.rstrip("\n").split("\t")
        if len(f) >= 6 and f[0] == gpu and f[1] == "linear_rt trace buffer, compacted round":
            step, setup = float(f[5]), float(f[2]) - float(f[5])
    if step is None:
        print("compaction: no 'linear_rt trace buffer, compacted round' row for %s in %s" % (gpu, weights_tsv))
        return 1
    first_built, rounds_built = built_rounds(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                                                          "linear_rt.h"))
    if step_override is not None:
        step = step_override
    hiz = {}
    for line in open(waves_tsv):
        f = line.rstrip("\n").split("\t")
        if len(f) >= 8 and f[2] == "hiz64 vulkan":
            hiz[(f[0].replace(" ", "-"), f[1].replace(" ", "-"))] = float(f[7])

    print("| scene | set | mean steps | wave / mean | estimate | slice | passes | wave / mean, compacted "
          "| estimate, compacted | hiz64 | linear_rt / hiz64 | compacted / hiz64 | as built / hiz64 |")
    print("|---|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|")
    rows = []
    for path in sorted(glob.glob(os.path.join(steps_dir, "*.u32"))):
        scene, rays = os.path.basename(path)[:-4].split("_", 1)
        if rays == "primary" or (scene, rays) not in hiz:
            continue
        data = open(path, "rb").read()
        steps = [int.from_bytes(data[i:i + 4], "little") for i in range(0, len(data), 4)]
        if not steps:
            continue
        groups = len(steps) / wave
        mean = sum(steps) / len(steps)
        plain = sum(max(steps[i:i + wave]) for i in range(0, len(steps), wave)) / groups
        best = None
        for first in (4, 6, 8, 12, 16, 24, 32):
            total, setups, passes = passes_cost(steps, first, wave)
            est = (total * step + setups * setup) / groups
            if best is None or est < best[0]:
                best = (est, first, passes, total / groups)
        h = hiz[(scene, rays)]
        total, setups, _ = passes_cost(steps, first_built, wave, rounds_built)
        built = (total * step + setups * setup) / groups
        rows.append((plain * step / h, best[0] / h, built / h))
        print("| %s | %s | %.2f | %.2f | %.0f | %d | %d | %.2f | %.0f | %.0f | %.2f | %.2f | %.2f |" % (
            scene, rays, mean, plain / mean if mean else 0, plain * step, best[1], best[2],
            best[3] / mean if mean else 0, best[0], h, plain * step / h, best[0] / h, built / h))
    if rows:
        g = [math.exp(sum(math.log(r[k]) for r in rows) / len(rows)) for k in range(3)]
        print("\n%s, wave%d: a cell step %.0f instructions%s, a resumed set-up %.0f (the round pipeline's). "
              "linear_rt / hiz64, geometric mean: %.2f in one pass, %.2f compacted with the best slice per set, "
              "%.2f as built (slices %d doubling, %d rounds); at most hiz64's on %d, %d and %d of %d sets." % (
                  gpu, wave, step, " (--step)" if step_override is not None else "", setup, g[0], g[1], g[2],
                  first_built, rounds_built, sum(1 for r in rows if r[0] <= 1.0), sum(1 for r in rows if r[1] <= 1.0),
                  sum(1 for r in rows if r[2] <= 1.0), len(rows)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
