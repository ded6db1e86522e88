#!/usr/bin/env python3
"""bench/calibrate.py - is the wave estimate a model of GPU time? Checked on the H200.

The estimate (bench/main.c, "What a wave pays") is a hypothesis: a ray's time
on a GPU ~ the steps its wave takes x what a step issues. This script fits
its free parameters on the only real GPU data there is, the H200's measured
M rays/s of the benchmark's Vulkan peers (bench/h200.tsv, copied from
docs/PERFORMANCE.md), and says how well each model orders and sizes them.
The peers' kernels have not changed since that run, so their compiled
weights (make gpu-stats --weights) and counted steps (build/bench
--only-counts --size 1024 --weights W: DIR/waves.tsv) are what ran there.

Models, each "time per ray = k x ...", k fitted (a scale):
  instr      wave steps x instructions per step (today's estimate)
  instr+mem  wave steps x (instructions + c x loads) per step, c fitted: a
             load's cost in instructions (the H200's memory, at its 345 MHz
             idle SM clock, was fast against its SM: c is what that ratio
             comes to)
  blocks     as a wave executes each loop: every trip (the wave's most)
             the body but its exit blocks, and the exit blocks (those that
             store a lane's answer, gpu_stats' loop_exits) once for each
             trip in which some lane of the wave left (bench counts them:
             trips32, exit_trips32; the march leaves by its refinement)
Both for wave32 (an NVIDIA warp) and wave64 steps. Fitted on the 60
secondary points (5 scenes x reflection, ao, shadow, segments x march64,
dda, hiz64), least squares in log time; then per set the order of the
three peers (60 pairs) and march64 against hiz64 (20).

Then the check: linear_rt as the H200 ran it, its one-pass kernel of that
run (the SPIR-V of its commit, weighed by gpu_stats --spv under the name
"h200 linear_rt trace" in WEIGHTS.tsv) on the 8-child walk's counted steps
(waves.tsv's "linear_rt vulkan 16, 8-child walk"), with the scale fitted on
the peers: its predicted / measured time per set, and the order of all four
methods.

    python3 bench/calibrate.py WAVES.tsv WEIGHTS.tsv [H200.tsv]
"""
import math
import sys

PEERS = ["march64 vulkan", "dda vulkan", "hiz64 vulkan"]
SECONDARY = ["reflection", "ao", "shadow", "segments"]


def read_tsv(path):
    rows = []
    for line in open(path):
        if line.startswith('#') or not line.strip():
            continue
        rows.append(line.rstrip('\n').split('\t'))
    return rows


def main(waves_path, weights_path, h200_path):
    waves = {}
    for r in read_tsv(waves_path):
        scene, rays, method = r[0], r[1], r[2]
        waves[(scene, rays, method)] = dict(method=method, mean=float(r[3]), w32=float(r[4]), w64=float(r[5]),
                                            instr=float(r[7]), loads=float(r[8]),
                                            texels=float(r[6]),
                                            trips=float(r[9]) if len(r) > 9 else 0.0,
                                            refine=float(r[10]) if len(r) > 10 else 0.0)
    pipeline = {"march64 vulkan": "bench march64", "dda vulkan": "bench dda", "hiz64 vulkan": "bench hiz64"}
    loops = {}
    inner, loads = {}, {}
    for r in read_tsv(weights_path):
        if r[0] == 'navi31' and len(r) > 10:
            loops[r[1]] = (float(r[5]), float(r[10]))
            inner[r[1]] = float(r[6])
            loads[r[1]] = float(r[7])
    per_loop = {"march64 vulkan": 9.0, "dda vulkan": 1.0, "hiz64 vulkan": 1.0}  # the march: a sample, 8 bisections
    for m in PEERS:
        if pipeline[m] not in loops:
            sys.exit('calibrate: %s has no loop_exits of %s (make gpu-stats --weights)' % (weights_path, pipeline[m]))
    header = None
    for line in open(h200_path):
        if line.startswith('# scene'):
            header = line[2:].rstrip('\n').split('\t')
    meas = {}
    for r in read_tsv(h200_path):
        for k in range(2, len(r)):
            meas[(r[0], r[1], header[k])] = float(r[k])
    points = []  # (scene, set, method, measured ns per ray, wave row)
    for (scene, rays, method), mrays in meas.items():
        if rays not in SECONDARY or method not in PEERS:
            continue
        w = waves.get((scene, rays, method))
        if w is None or w['instr'] <= 0 or mrays <= 0:
            continue
        points.append((scene, rays, method, 1e3 / mrays, w))
    if len(points) < 10:
        sys.exit('calibrate: %d points: need waves.tsv with weights (bench --weights) and h200.tsv' % len(points))

    def per_ray(w, lanes, c):
        name = pipeline[w['method']]
        body, exits = loops[name]
        if lanes == 'blocks':
            return w['trips'] * (body - exits) + w['refine'] * exits
        # a step: the loop body's instructions and loads (the march's: a ninth of its trip)
        step, step_loads = body / per_loop[w['method']], loads[name] / per_loop[w['method']]
        return (w['w32'] if lanes == 32 else w['w64']) * (step + c * step_loads)

    def fit(lanes, c):
        res = [math.log(t) - math.log(per_ray(w, lanes, c)) for (_, _, _, t, w) in points]
        logk = sum(res) / len(res)
        err = sum((x - logk) ** 2 for x in res)
        return logk, err

    def evaluate(name, lanes, c):
        logk, err = fit(lanes, c)
        pred = {(s, r, m): math.exp(logk) * per_ray(w, lanes, c) for (s, r, m, t, w) in points}
        truth = {(s, r, m): t for (s, r, m, t, w) in points}
        pairs = right = mh = mh_right = 0
        within = 0
        for key, t in truth.items():
            within += 1 if max(pred[key] / t, t / pred[key]) <= 1.5 else 0
        sets = sorted(set((s, r) for (s, r, m, t, w) in points))
        for s, r in sets:
            for a in range(len(PEERS)):
                for b in range(a + 1, len(PEERS)):
                    ka, kb = (s, r, PEERS[a]), (s, r, PEERS[b])
                    if ka not in truth or kb not in truth:
                        continue
                    pairs += 1
                    ok = (pred[ka] < pred[kb]) == (truth[ka] < truth[kb])
                    right += ok
                    if {PEERS[a], PEERS[b]} == {"march64 vulkan", "hiz64 vulkan"}:
                        mh += 1
                        mh_right += ok
        rms = math.sqrt(err / len(points))
        print('| %s | %s | %s | %.3g | %d of %d | %d of %d | %d of %d | %.2fx |' % (
            name, 'wave%d' % lanes if lanes != 'blocks' else 'wave32, blocks', '%.0f' % c if c else '-',
            math.exp(logk), right, pairs, mh_right, mh, within, len(points), math.exp(rms)))
        return pred, truth

    print('Fitted on %d H200 points (the peers on the secondary sets):\n' % len(points))
    print('| model | steps | c (a load, in instructions) | k (ns per instruction-step) | peer pairs ordered right '
          '| march64 / hiz64 right | within 1.5x | rms error |')
    print('|---|---|--:|--:|--:|--:|--:|--:|')
    best = None
    for lanes in (32, 64):
        evaluate('instructions', lanes, 0.0)
        cs = [x * 0.5 for x in range(0, 4001)]
        c = min(cs, key=lambda x: fit(lanes, x)[1])
        evaluate('instructions + c x loads', lanes, c)
    pred, truth = evaluate('blocks', 'blocks', 0.0)
    logk = fit('blocks', 0.0)[0]
    print('\nPer point, the blocks model: predicted / measured time per ray\n')
    print('| scene | rays | march64 | dda | hiz64 |\n|---|---|--:|--:|--:|')
    for s, r in sorted(set((s, r) for (s, r, m) in truth)):
        cells = []
        for m in PEERS:
            k = (s, r, m)
            cells.append('%.2f' % (pred[k] / truth[k]) if k in truth else '-')
        print('| %s | %s | %s |' % (s, r, ' | '.join(cells)))

    olds = ['h200 linear_rt trace', 'h200 linear_rt trace, back 16-bit']
    if any(o not in loops for o in olds):
        print('\nNo "%s" in %s: the check on linear_rt is not made (bench/h200_kernel.sh)' % (olds, weights_path))
        return
    lrt = {}
    for (s, r, m), w in waves.items():
        key = (s, r, 'linear_rt vulkan 16')
        old = olds[1] if s == 'yard back' else olds[0]  # the yard back is a thickness tree
        body, texel = loops[old][0] - inner[old], inner[old]
        if m == 'linear_rt vulkan 16, 8-child walk' and r in SECONDARY and key in meas:
            lrt[key] = (math.exp(logk) * w['w32'] * (body + texel * w['texels']), 1e3 / meas[key])
    if not lrt:
        print('\nNo 8-child walk rows in %s: the check on linear_rt is not made' % waves_path)
        return
    within = sum(1 for p, t in lrt.values() if max(p / t, t / p) <= 1.5)
    print('\nThe check: linear_rt vulkan 16 as the H200 ran it (its kernel, infinite tree: %d instructions a node '
          'test, %d a texel test; thickness tree %d and %d), predicted / measured time per ray, %d of %d sets within '
          '1.5x:\n' % (loops[olds[0]][0] - inner[olds[0]], inner[olds[0]], loops[olds[1]][0] - inner[olds[1]],
                        inner[olds[1]], within, len(lrt)))
    print('| scene | rays | predicted / measured |\n|---|---|--:|')
    for k, (p, t) in sorted(lrt.items()):
        print('| %s | %s | %.2f |' % (k[0], k[1], p / t))
    allp = dict(pred)
    allt = dict(truth)
    for k, (p, t) in lrt.items():
        allp[k], allt[k] = p, t
    methods = PEERS + ['linear_rt vulkan 16']
    pairs = right = 0
    for s, r in sorted(set((k[0], k[1]) for k in allt)):
        for a in range(len(methods)):
            for b in range(a + 1, len(methods)):
                ka, kb = (s, r, methods[a]), (s, r, methods[b])
                if ka in allt and kb in allt:
                    pairs += 1
                    right += (allp[ka] < allp[kb]) == (allt[ka] < allt[kb])
    ratio_ok = 0
    print('\nlinear_rt 16 / hiz64, predicted and measured on the H200:\n\n| scene | rays | predicted | measured | '
          'predicted / measured |\n|---|---|--:|--:|--:|')
    for s, r in sorted(set((k[0], k[1]) for k in lrt)):
        kl, kh = (s, r, 'linear_rt vulkan 16'), (s, r, 'hiz64 vulkan')
        if kh in allt:
            pr, mr = allp[kl] / allp[kh], allt[kl] / allt[kh]
            ratio_ok += max(pr / mr, mr / pr) <= 1.5
            print('| %s | %s | %.2f | %.2f | %.2f |' % (s, r, pr, mr, pr / mr))
    print('\nAll four methods: %d of %d pairs ordered right; linear_rt 16 / hiz64 within 1.5x of the H200\'s ratio on '
          '%d of %d sets' % (right, pairs, ratio_ok, len(lrt)))


if __name__ == '__main__':
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], sys.argv[3] if len(sys.argv) == 4 else 'bench/h200.tsv')
