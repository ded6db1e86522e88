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
                                            trips=float(r[9]) if len(r) > 9 else 0.0,
                                            refine=float(r[10]) if len(r) > 10 else 0.0)
    pipeline = {"march64 vulkan": "bench march64", "dda vulkan": "bench dda", "hiz64 vulkan": "bench hiz64"}
    loops = {}
    for r in read_tsv(weights_path):
        if r[0] == 'navi31' and len(r) > 10:
            loops[r[1]] = (float(r[5]), float(r[10]))
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
        if lanes == 'blocks':
            body, exits = loops[pipeline[w['method']]]
            return w['trips'] * (body - exits) + w['refine'] * exits
        # a step's instructions and loads, from the estimate's (wave32 steps x per step)
        steps = w['w32'] if w['w32'] > 0 else 1.0
        instr, loads = w['instr'] / steps, w['loads'] / steps
        return (w['w32'] if lanes == 32 else w['w64']) * (instr + c * loads)

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
    print('\nPer point, the blocks model: predicted / measured time per ray\n')
    print('| scene | rays | march64 | dda | hiz64 |\n|---|---|--:|--:|--:|')
    for s, r in sorted(set((s, r) for (s, r, m) in truth)):
        cells = []
        for m in PEERS:
            k = (s, r, m)
            cells.append('%.2f' % (pred[k] / truth[k]) if k in truth else '-')
        print('| %s | %s | %s |' % (s, r, ' | '.join(cells)))


if __name__ == '__main__':
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], sys.argv[3] if len(sys.argv) == 4 else 'bench/h200.tsv')
