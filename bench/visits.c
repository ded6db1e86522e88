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

int bench_visits(const bench_scene *sc, const bench_rays *rs, uint32_t node_bits, double per_ray[4])
{
    const lrt_depth *depth = bench_lrt_depth(sc);
    lrt_build_options o;
    lrt_bvh bvh = {0};
    lrt_hit *hits;
    lrt_result r;
    int k;
    memset(per_ray, 0, 4 * sizeof *per_ray);
    if (!rs->count) return 0;
    memset(&o, 0, sizeof o);
    o.node_bits = node_bits;
    o.thickness = bench_lrt_thickness(sc);
    if (lrt_bvh_build(&bvh, depth, &o, NULL) != LRT_SUCCESS) return 1;
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
    lrt_build_options o;
    lrt_bvh bvh = {0};
    size_t i, tex = 0;
    int bad = 0;
    *texels = 0.0;
    memset(&o, 0, sizeof o);
    o.node_bits = node_bits;
    o.thickness = bench_lrt_thickness(sc);
    if (lrt_bvh_build(&bvh, depth, &o, NULL) != LRT_SUCCESS) return 1;
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

/* ---- the kernels' cell walk, step for step ----------------------------------
   The exact ordinary pass of the Vulkan kernels walks one cell a step
   (shaders/linear_rt.glsl's lrt_walk_cells, which says why its answer is
   the CPU's): this is that walk in C over this copy's tree, its floats the
   kernels' (a cell's code plane is lrt__kernel_cull_setup's, a texel's test
   lrt__test_texel), to count what a wave pays. A ray the kernels' ordinary
   pass leaves to the rare pass (a rare ray, or one the cell walk does not
   trace) is counted as the walk of that pass: the node tests above. */

/* lrt_split_level_x (rows 0) and lrt_split_level_y (rows 1) */
static int cells_split(int a, int b, int rows)
{
    uint32_t d = (uint32_t)(a ^ b);
    int m = 31;
    if (!d) return -1;
    while (!(d >> m)) --m;
    return (2 * m + rows) / 3;
}

/* lrt_cross_texel */
static int cells_cross(float o, float v, float iv, uint32_t neg, float t, int lo, int hi, int cur)
{
    float q, e;
    int c, b;
    if (v == 0.0f) return cur;
    q = o + t * v;
    q = q < (float)lo ? (float)lo : q > (float)hi ? (float)hi : q;
    c = (int)floorf(q);
    b = neg ? c + 1 : c - 1;
    e = ((float)(neg ? c + 1 : c) - o) * iv;
    return (b >= lo && b <= hi && t <= lrt__widen(e)) ? b : c;
}

/* lrt_cell_axis */
static void cells_axis(int a, int n, float o, float v, float iv, uint32_t neg, float *en, float *ex, float *leave, int *past,
                       int *last)
{
    float ta = ((float)a - o) * iv, tb = ((float)(a + n) - o) * iv;
    LRT__ROUNDED(ta);
    LRT__ROUNDED(tb);
    lrt__slab((float)a, (float)(a + n), o, iv, neg, en, ex);
    *leave = v == 0.0f ? INFINITY : neg ? ta : tb;
    *past = neg ? a - 1 : a + n;
    *last = neg ? a : a + n - 1;
}

/* lrt_walk_cells of a set-up thin ray: its steps (cells and texels tested),
   *texels the texels among them, *hit 1 with its texel (hx, hy) */
static uint32_t cells_walk(const lrt__walk *w, const lrt__ray_setup *s, size_t *texels, int *hit, uint32_t *hx, uint32_t *hy)
{
    const lrt_layout *L = w->L;
    lrt__kernel_cull c;
    int x, y, lv = 0, pend = 0;
    uint32_t steps = 0;
    lrt__kernel_cull_setup(w, s, &c);
    x = cells_cross(s->o[0], s->v[0], s->iv[0], s->neg_x, s->t_lo, 0, (int)L->width - 1, (int)s->o[0]);
    y = cells_cross(s->o[1], s->v[1], s->iv[1], s->neg_y, s->t_lo, 0, (int)L->height - 1, (int)s->o[1]);
    *hit = 0;
    for (;;) {
        const int sw = lv + ((lv + 1) >> 1), sh = lv + (lv >> 1);
        const int cx = x >> sw, cy = y >> sh; /* x, y >= 0: a move to -1 ends the walk */
        float en = s->t_lo, ex = s->t_hi, lx, ly;
        int px, py, lastx, lasty, met = 0, to = lv - 1;
        cells_axis(cx << sw, 1 << sw, s->o[0], s->v[0], s->iv[0], s->neg_x, &en, &ex, &lx, &px, &lastx);
        cells_axis(cy << sh, 1 << sh, s->o[1], s->v[1], s->iv[1], s->neg_y, &en, &ex, &ly, &py, &lasty);
        ++steps;
        if (lv == 0) {
            const int on = (uint32_t)x < L->width && (uint32_t)y < L->height;
            const uint32_t slot = (((uint32_t)y & 1u) << 2) | ((uint32_t)x & 3u);
            const uint32_t code =
                on && w->exact_codes ? *lrt__codes(w, lrt__node_slot(w, 1, (uint32_t)x >> 2, (uint32_t)y >> 1) + slot) : 0u;
            float t, planes[2];
            ++*texels;
            if (lrt__test_texel(w, s, (uint32_t)x, (uint32_t)y, en, ex, code, &t, planes)) {
                *hit = 1;
                *hx = (uint32_t)x;
                *hy = (uint32_t)y;
                return steps;
            }
        } else if ((uint32_t)x < L->width && (uint32_t)y < L->height) {
            const uint32_t bw = ((uint32_t)lv & 1u) ? 1u : 2u, bh = 3u - bw;
            const size_t code = lrt__node_slot(w, (uint32_t)lv + 1u, (uint32_t)cx >> bw, (uint32_t)cy >> bh) +
                                ((((uint32_t)cy & ((1u << bh) - 1u)) << bw) | ((uint32_t)cx & ((1u << bw) - 1u)));
            float tz = (float)*lrt__codes(w, code) * c.za, e0 = en, x0 = lrt__widen(ex);
            LRT__ROUNDED(tz);
            tz += c.zb;
            if (s->neg_z) x0 = tz < x0 ? tz : x0;
            else e0 = tz > e0 ? tz : e0;
            if (w->back_codes) {
                float tb = (float)*lrt__codes(w, w->back_codes + code) * c.ba;
                LRT__ROUNDED(tb);
                tb += c.bb;
                if (s->neg_z) e0 = tb > e0 ? tb : e0;
                else x0 = tb < x0 ? tb : x0;
            }
            met = e0 <= x0;
        }
        if (!met) {
            const int bx = cells_split(lastx, px, 0), by = cells_split(lasty, py, 1);
            const float lt = lx < ly ? lx : ly;
            if (pend) {
                x += (pend & 1) == (int)s->neg_x ? 1 : -1;
                y += (pend & 1) == (int)s->neg_y ? -1 : 1;
                to = pend >> 2;
                pend = 0;
            } else if (!(lt <= lrt__widen(s->t_hi))) {
                return steps;
            } else if ((lx > ly ? lx : ly) <= lrt__widen(lt)) {
                const int a_first = bx <= by;
                x = a_first ? px : lastx;
                y = a_first ? lasty : py;
                to = a_first ? bx : by;
                pend = ((bx > by ? bx : by) << 2) | 2 | a_first;
            } else if (lx < ly) {
                y = cells_cross(s->o[1], s->v[1], s->iv[1], s->neg_y, lx, cy << sh, ((cy + 1) << sh) - 1, y);
                x = px;
                to = bx;
            } else {
                x = cells_cross(s->o[0], s->v[0], s->iv[0], s->neg_x, ly, cx << sw, ((cx + 1) << sw) - 1, x);
                y = py;
                to = by;
            }
            if (to >= (int)L->level_count) return steps;
        }
        lv = to;
    }
}

/* The kernels' exact ordinary pass, ray by ray: steps[i] the cell walk's
   steps of ray i, texels its texel tests over the set. Each hit is checked
   against lrt_trace's (the same texel, or both a miss): 1 if any differs. */
int bench_wave_cells(const bench_scene *sc, const bench_rays *rs, uint32_t node_bits, uint32_t *steps, double *texels)
{
    const lrt_depth *depth = bench_lrt_depth(sc);
    lrt_build_options o;
    lrt_bvh bvh = {0};
    lrt__walk w;
    size_t i, tex = 0, stride = 0;
    int bad = 0;
    *texels = 0.0;
    memset(&o, 0, sizeof o);
    o.node_bits = node_bits;
    o.thickness = bench_lrt_thickness(sc);
    if (lrt_bvh_build(&bvh, depth, &o, NULL) != LRT_SUCCESS || lrt__check_depth(depth, &stride) != LRT_SUCCESS) {
        lrt_bvh_destroy(&bvh);
        return 1;
    }
    lrt__walk_init(&w, &bvh, depth, stride);
    visits_as_kernels = 1;
    for (i = 0; i < rs->count; ++i) {
        const lrt_ray *ray = rs->rays + i;
        lrt__ray_setup s;
        float t_scale;
        uint32_t kind, hx = 0, hy = 0;
        int hit = 0, rare = lrt__rare_bits(ray) | lrt__far_origin(ray->origin, depth->width, depth->height);
        lrt_hit h;
        rare = rare && !lrt__huge_direction(ray, depth->width, depth->height);
        if (!rare && !lrt__setup_ray(ray, depth->width, depth->height, &s, &t_scale, &kind)) {
            steps[i] = 0; /* nothing to walk */
            continue;
        }
        if (rare || lrt__in_grid_plane(&s)) { /* the rare pass (lrt_walk_cells_takes) */
            steps[i] = (uint32_t)visits_of_ray(&bvh, depth, ray, &h);
            continue;
        }
        steps[i] = cells_walk(&w, &s, &tex, &hit, &hx, &hy);
        visits_of_ray(&bvh, depth, ray, &h);
        bad |= h.kind == 0xffffu || (h.kind == LRT_HIT) != hit || (hit && (h.x != hx || h.y != hy));
    }
    visits_as_kernels = 0;
    *texels = (double)tex;
    lrt_bvh_destroy(&bvh);
    return bad;
}
