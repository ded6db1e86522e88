/* bench/visits.c - what linear_rt's walk costs per ray: its node tests by
   level, and the exact tests of the texels that the level-1 codes let
   through, counted through the library's profiling hooks
   (LINEAR_RT_COUNT_NODE_TEST, LINEAR_RT_COUNT_TEXEL_TEST) in a copy of the
   library of this file's own (LINEAR_RT_STATIC), so the timed copy
   (m_linear_rt.c) counts nothing. The copy walks as SSE2 (LINEAR_RT_NO_AVX):
   its level-1 tests read the codes, as the kernels' do, where the AVX2
   walk reads float depth. Its node tests come within 3% of the AVX2
   walk's, which the counts before this copy came from (at 512x512: the
   yard's shadows 1.538 level-1 tests a ray against 1.583, the pole
   edge-on 37.779 against 37.805). The counters are this file's: one
   thread at a time. */
#include <stddef.h>

static size_t visits_tests[4]; /* level 0, level 1, above; texels through the level-1 codes */
#define LINEAR_RT_COUNT_NODE_TEST(level) (++visits_tests[(level) > 1u ? 2 : (level)])
#define LINEAR_RT_COUNT_TEXEL_TEST() (++visits_tests[3])
static size_t visits_finish; /* a budget's finish: its samples (march and bisection) */
#define LINEAR_RT_COUNT_FINISH_SAMPLE() (++visits_finish)
/* 1: walk as the kernels do (bench_wave_linear_rt): every walk from the
   level-1 node of the texel where the segment starts, never the CPU's rule
   (lrt__from_origin) of starting some at the start node */
static int visits_as_kernels;
#define LINEAR_RT_WALK_AS_KERNELS visits_as_kernels
#define LINEAR_RT_NO_AVX
#define LINEAR_RT_STATIC
#define LINEAR_RT_IMPLEMENTATION
#include "bench.h"

#include <stdlib.h>
#include <string.h>

/* The scene's tree as linear_rt's bench methods build it (node_bits, the
   scene's thickness): 0, or 1 with nothing to destroy */
static int visits_build(const bench_scene *sc, uint32_t node_bits, lrt_bvh *bvh)
{
    lrt_build_options o;
    memset(&o, 0, sizeof o);
    o.node_bits = node_bits;
    o.thickness = bench_lrt_thickness(sc);
    if (lrt_bvh_build(bvh, bench_lrt_depth(sc), &o, NULL) == LRT_SUCCESS) return 0;
    lrt_bvh_destroy(bvh);
    return 1;
}

int bench_visits(const bench_scene *sc, const bench_rays *rs, uint32_t node_bits, double per_ray[4])
{
    const lrt_depth *depth = bench_lrt_depth(sc);
    lrt_bvh bvh = {0};
    lrt_hit *hits;
    lrt_result r;
    int k;
    memset(per_ray, 0, 4 * sizeof *per_ray);
    if (!rs->count) return 0;
    if (visits_build(sc, node_bits, &bvh)) return 1;
    if (!(hits = (lrt_hit *)malloc(sizeof(lrt_hit) * rs->count))) {
        lrt_bvh_destroy(&bvh);
        return 1;
    }
    memset(visits_tests, 0, sizeof visits_tests);
    r = lrt_trace(&bvh, depth, rs->rays, hits, rs->count, 0);
    for (k = 0; k < 4; ++k) per_ray[k] = (double)visits_tests[k] / (double)rs->count;
    free(hits);
    lrt_bvh_destroy(&bvh);
    return r != LRT_SUCCESS;
}

/* The node tests of one ray (lrt_trace of a single ray): the sum over levels */
static size_t visits_of_ray(const lrt_bvh *bvh, const lrt_depth *depth, const lrt_ray *ray, lrt_hit *hit)
{
    memset(visits_tests, 0, sizeof visits_tests);
    if (lrt_trace(bvh, depth, ray, hit, 1, 0) != LRT_SUCCESS) hit->kind = 0xffffu; /* never alike */
    return visits_tests[0] + visits_tests[1] + visits_tests[2];
}

int bench_visits_thickness(const bench_scene *sc, const bench_rays *rs, double out[6])
{
    lrt_build_options o;
    lrt_bvh thick = {0}, inf = {0};
    size_t i, n[2], alike = 0, differ = 0, sums[4] = {0, 0, 0, 0}; /* alike thick, alike infinite, other thick, other infinite */
    memset(out, 0, 6 * sizeof *out);
    if (!sc->back || !rs->count) return 1;
    memset(&o, 0, sizeof o);
    o.node_bits = 16u;
    o.thickness = LRT_THICKNESS_BACK_MAP;
    if (lrt_bvh_build(&thick, bench_lrt_depth(sc), &o, NULL) != LRT_SUCCESS) return 1;
    o.thickness = LRT_THICKNESS_INFINITE;
    if (lrt_bvh_build(&inf, &sc->lrt, &o, NULL) != LRT_SUCCESS) {
        lrt_bvh_destroy(&thick);
        return 1;
    }
    for (i = 0; i < rs->count; ++i) {
        lrt_hit a, b;
        const size_t ct = visits_of_ray(&thick, bench_lrt_depth(sc), rs->rays + i, &a);
        const size_t ci = visits_of_ray(&inf, &sc->lrt, rs->rays + i, &b);
        const int same = a.kind == b.kind && a.kind != 0xffffu && (a.kind != LRT_HIT || (a.x == b.x && a.y == b.y));
        sums[same ? 0 : 2] += ct;
        sums[same ? 1 : 3] += ci;
        alike += (size_t)same;
        differ += (size_t)(same && ct != ci);
    }
    n[0] = alike;
    n[1] = rs->count - alike;
    out[0] = 100.0 * (double)alike / (double)rs->count;
    for (i = 0; i < 4; ++i) out[1 + i] = n[i / 2] ? (double)sums[i] / (double)n[i / 2] : 0.0;
    out[5] = (double)differ;
    lrt_bvh_destroy(&inf);
    lrt_bvh_destroy(&thick);
    return 0;
}

/* The kernels' walk, ray by ray (lrt_trace of one ray, walking as
   shaders/linear_rt.glsl's lrt_trace_ray: from the origin's level-1 node
   whenever the start node is above level 0): steps[i] the node tests of ray
   i at any level, texels the exact texel tests of the whole set. */
int bench_wave_linear_rt(const bench_scene *sc, const bench_rays *rs, uint32_t node_bits, uint32_t *steps, double *texels)
{
    const lrt_depth *depth = bench_lrt_depth(sc);
    lrt_bvh bvh = {0};
    size_t i, tex = 0;
    int bad = 0;
    *texels = 0.0;
    if (visits_build(sc, node_bits, &bvh)) return 1;
    visits_as_kernels = 1;
    for (i = 0; i < rs->count; ++i) {
        lrt_hit hit;
        steps[i] = (uint32_t)visits_of_ray(&bvh, depth, rs->rays + i, &hit);
        bad |= hit.kind == 0xffffu;
        tex += visits_tests[3];
    }
    visits_as_kernels = 0;
    *texels = (double)tex;
    lrt_bvh_destroy(&bvh);
    return bad;
}

/* A budget's finish (LRT_TRACE_BUDGET(budget) | BENCH_FINISH), ray by ray:
   samples[i] the samples ray i's finish takes (0 where the budget did not
   stop it). The budgeted walk is the kernels' step for step, and so is the
   finish (lrt_finish). */
int bench_finish_samples(const bench_scene *sc, const bench_rays *rs, uint32_t budget, uint32_t *samples)
{
    const lrt_depth *depth = bench_lrt_depth(sc);
    lrt_bvh bvh = {0};
    size_t i;
    int bad = 0;
    if (visits_build(sc, 16u, &bvh)) return 1;
    for (i = 0; i < rs->count; ++i) {
        lrt_hit h;
        visits_finish = 0;
        bad |= lrt_trace(&bvh, depth, rs->rays + i, &h, 1, LRT_TRACE_BUDGET(budget) | BENCH_FINISH) != LRT_SUCCESS;
        samples[i] = (uint32_t)visits_finish;
    }
    lrt_bvh_destroy(&bvh);
    return bad;
}

/* ---- the kernels' cell walk, step for step ----------------------------------
   linear_rt.h's lrt__walk_cells, the C twin of the kernels' exact ordinary
   pass, counts what a wave pays. A ray the kernels' ordinary pass leaves to
   the rare pass (a rare ray, or one the cell walk does not trace) is
   counted as the walk of that pass: the node tests above. */

/* The kernels' exact ordinary pass, ray by ray: steps[i] the cell walk's
   steps of ray i, texels its texel tests over the set. Each hit is checked
   against lrt_trace's (the same texel, or both a miss): 1 if any differs. */
int bench_wave_cells(const bench_scene *sc, const bench_rays *rs, uint32_t node_bits, uint32_t *steps, double *texels)
{
    const lrt_depth *depth = bench_lrt_depth(sc);
    lrt_bvh bvh = {0};
    size_t i, tex = 0;
    int bad = 0;
    *texels = 0.0;
    if (visits_build(sc, node_bits, &bvh)) return 1;
    visits_as_kernels = 1;
    for (i = 0; i < rs->count; ++i) {
        uint32_t hx = 0, hy = 0;
        int hit = 0;
        lrt_hit h;
        if (!lrt__walk_cells_ray(&bvh, depth, rs->rays + i, &steps[i], &tex, &hit, &hx, &hy)) {
            steps[i] = (uint32_t)visits_of_ray(&bvh, depth, rs->rays + i, &h); /* the rare pass: the 8-child walk */
            continue;
        }
        visits_of_ray(&bvh, depth, rs->rays + i, &h);
        bad |= h.kind == 0xffffu || (h.kind == LRT_HIT) != hit || (hit && (h.x != hx || h.y != hy));
    }
    visits_as_kernels = 0;
    *texels = (double)tex;
    lrt_bvh_destroy(&bvh);
    return bad;
}
