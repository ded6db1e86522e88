/* tests/test_core.c - the CPU path of linear_rt.h against docs/MODEL.md.

   Every traced ray is judged by the separate exact reference of
   tests/support/reference.h (ref_check: docs/MODEL.md's "Right, and how right"). Also:
   the named cases of docs/MODEL.md, Morton mapping and level geometry, update
   versus rebuild byte for byte, every bad argument's result code, the
   allocator hooks and caller-owned memory.

   Prints one line per failure and ends with "N passed, M failed". */
#define LINEAR_RT_IMPLEMENTATION
#include "../linear_rt.h"
#include "support/reference.h"
#include "../examples/scene.h"
#include "support/rays.h"
#include "support/check.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <float.h>


/* Traces rays with the BVH and judges every answer by the reference. */
static void trace_and_judge(const char *what, const lrt_bvh *bvh, const test_map *m, const lrt_ray *rays,
                            const int *kinds, size_t n, uint32_t flags)
{
    lrt_hit *hits = (lrt_hit *)malloc(sizeof(lrt_hit) * (n ? n : 1));
    size_t i, bad = 0;
    lrt_result r = lrt_trace(bvh, test_map_depth(m), rays, hits, n, flags);
    CHECK(r == LRT_SUCCESS, "%s: trace returned %s", what, lrt_result_string(r));
    for (i = 0; i < n && r == LRT_SUCCESS; ++i) {
        ref_ray q = ref_ray_of(&rays[i]);
        ref_answer a = to_answer(&hits[i]);
        char why[256];
        if (!ref_check(&m->ref, &q, &a, 0 /* closest hit */, why, sizeof why)) {
            if (bad < 5)
                printf("FAIL %s ray %zu (%s) o=(%.9g %.9g %.9g) v=(%.9g %.9g %.9g) t=[%.9g %.9g]: %s\n", what, i,
                       ray_names[kinds[i]], q.o[0], q.o[1], q.o[2], q.v[0], q.v[1], q.v[2], q.tmin, q.tmax, why);
            ++bad;
        }
    }
    CHECK(bad == 0, "%s: %zu of %zu rays disagree with the reference", what, bad, n);
    free(hits);
}

/* ---- 1. randomised differential runs ---------------------------------------- */
/* thick: a thickness model (lrt_thickness); the constant and relative ones
   take a projection of their own per map (near and far planes that put
   the maps' depths at close, middle and far distances, the far plane
   finite or not) */
static void differential(int w, int h, int shape, lrt_format format, int reversed, uint32_t node_bits, size_t nrays,
                         int padded, int thick)
{
    test_map m;
    lrt_bvh bvh = {0};
    lrt_build_options opt;
    lrt_ray *rays = (lrt_ray *)malloc(sizeof(lrt_ray) * nrays);
    int *kinds = (int *)calloc(nrays, sizeof(int));
    char what[160];
    size_t i;
    lrt_result r;
    make_map(&m, w, h, shape, format, reversed, padded);
    if (thick == LRT_THICKNESS_BACK_MAP) add_back(&m);
    if (thick == LRT_THICKNESS_CONSTANT) add_model(&m, (uint32_t)thick, (w & 1) ? 0.05f : 2.0f, (h & 1) ? 0.1f : 1.0f, (w & 2) ? 100.0f : INFINITY);
    if (thick == LRT_THICKNESS_RELATIVE) add_model(&m, (uint32_t)thick, (w & 1) ? 0.02f : 0.5f, (h & 1) ? 0.1f : 1.0f, (w & 2) ? 100.0f : INFINITY);
    opt = m.model;
    opt.node_bits = node_bits;
    r = lrt_bvh_build(&bvh, test_map_depth(&m), &opt, NULL);
    snprintf(what, sizeof what, "%dx%d %s fmt=%d%s nodes=%u%s%s", w, h, m.name, (int)format, reversed ? " reversed" : "",
             bvh.layout.node_bits, padded ? " strided" : "", model_name(&m));
    CHECK(r == LRT_SUCCESS, "%s: build returned %s", what, lrt_result_string(r));
    if (r == LRT_SUCCESS && rays && kinds) {
        for (i = 0; i < nrays; ++i) {
            kinds[i] = (int)(i % RAY_KIND_COUNT);
            rays[i] = make_ray(&m, kinds[i]);
        }
        trace_and_judge(what, &bvh, &m, rays, kinds, nrays, 0);
    }
    lrt_bvh_destroy(&bvh);
    free_map(&m);
    free(rays);
    free(kinds);
}

static void test_differential(void)
{
    static const int sizes[][2] = {{1, 1}, {1, 23}, {23, 1}, {3, 5}, {7, 9}, {4, 2}, {8, 8}, {33, 20}, {64, 64}, {100, 37}, {5, 300}};
    const size_t nsizes = sizeof sizes / sizeof sizes[0];
    size_t s;
    int shape, f;
    for (s = 0; s < nsizes; ++s)
        for (shape = 0; shape < SHAPE_COUNT; ++shape)
            for (f = 1; f <= 3; ++f) {
                if (shape == SHAPE_WILD && f != 3) continue;
                differential(sizes[s][0], sizes[s][1], shape, (lrt_format)f, (int)(s & 1), (s % 3 == 0) ? 8u : 0u,
                             2600, (int)(s & 2), 0);
            }
    /* node precision both ways on each format, reversed Z on each */
    for (f = 1; f <= 3; ++f) {
        differential(61, 47, SHAPE_SCENE, (lrt_format)f, 0, 8, 4000, 0, 0);
        differential(61, 47, SHAPE_SCENE, (lrt_format)f, 1, 16, 4000, 1, 0);
        differential(61, 47, SHAPE_TERRACES, (lrt_format)f, 1, 8, 4000, 0, 0);
    }
    /* thickness from a back map: every shape, format, node width, Z direction, strided or not */
    for (f = 1; f <= 3; ++f) {
        differential(61, 47, SHAPE_SCENE, (lrt_format)f, 0, 8, 4000, 0, 1);
        differential(61, 47, SHAPE_POLES, (lrt_format)f, 1, 16, 4000, 1, 1);
        differential(37, 29, SHAPE_NOISE, (lrt_format)f, f == 2, 0, 3000, f == 3, 1);
    }
    differential(203, 131, SHAPE_TERRACES, LRT_FORMAT_FLOAT32, 0, 16, 8000, 0, 1);
    differential(203, 131, SHAPE_WILD, LRT_FORMAT_FLOAT32, 0, 8, 4000, 1, 1);
    differential(1024, 1024, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 16, 20000, 0, 1);
    /* constant and relative thickness: b computed from d (every format: a
       unorm's d is v / max in float first), thin and thick layers */
    for (f = 1; f <= 3; ++f) {
        int model;
        for (model = LRT_THICKNESS_CONSTANT; model <= LRT_THICKNESS_RELATIVE; ++model) {
            differential(61, 47, SHAPE_SCENE, (lrt_format)f, 0, 8, 4000, 0, model);
            differential(62, 47, SHAPE_POLES, (lrt_format)f, 1, 16, 4000, 1, model);
            differential(37, 30, SHAPE_NOISE, (lrt_format)f, f == 2, 0, 3000, f == 3, model);
            differential(39, 29, SHAPE_FAR, (lrt_format)f, f == 1, 0, 3000, 0, model);
        }
    }
    differential(203, 131, SHAPE_WILD, LRT_FORMAT_FLOAT32, 0, 16, 4000, 1, LRT_THICKNESS_CONSTANT);
    differential(512, 512, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 16, 20000, 0, LRT_THICKNESS_CONSTANT);
    differential(514, 512, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 16, 20000, 0, LRT_THICKNESS_RELATIVE);
    /* the large sizes of the issue */
    differential(1282, 1110, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 0, 30000, 0, 0);
    differential(1282, 1110, SHAPE_SCENE, LRT_FORMAT_UNORM16, 1, 8, 3000, 1, 0);
    differential(1024, 1024, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 8, 30000, 0, 0);
    differential(1024, 1024, SHAPE_SCENE, LRT_FORMAT_UNORM8, 0, 0, 3000, 0, 0);
    differential(1024, 1024, SHAPE_POLES, LRT_FORMAT_FLOAT32, 1, 16, 3000, 0, 0);
}

/* ---- 1b. thickness where it breaks: rays that skim a back face ------------------ */
/* Rays aimed at every texel's back plane (and its front plane) from a few
   texels away, level or nearly so, passing a few ulps above, on or below
   it: under a thin slab, along a pole's edge, just behind a sphere. Every
   answer against the reference. */
static void test_thickness_grazing(void)
{
    static const int shapes[3] = {SHAPE_SCENE, SHAPE_POLES, SHAPE_TERRACES};
    int si;
    for (si = 0; si < 3; ++si) {
        test_map m;
        lrt_bvh bvh = {0};
        lrt_build_options opt;
        lrt_ray *rays;
        int *kinds, i, j;
        size_t n = 0;
        char what[96];
        make_map(&m, 45, 33, shapes[si], LRT_FORMAT_FLOAT32, 0, 0);
        add_back(&m);
        memset(&opt, 0, sizeof opt);
        opt.thickness = LRT_THICKNESS_BACK_MAP;
        rays = (lrt_ray *)malloc(sizeof(lrt_ray) * 45 * 33 * 8);
        kinds = (int *)calloc(45 * 33 * 8, sizeof(int));
        CHECK(lrt_bvh_build(&bvh, m.pair, &opt, NULL) == LRT_SUCCESS, "grazing: build");
        for (j = 0; j < 33; ++j) {
            for (i = 0; i < 45; ++i) {
                const float b = (float)m.ref.b[(size_t)j * 45 + (size_t)i], d = (float)m.ref.d[(size_t)j * 45 + (size_t)i];
                int k;
                for (k = 0; k < 8; ++k) {
                    lrt_ray *r = &rays[n];
                    const float z = k < 6 ? b : d;
                    const int ulps = (k % 3) - 1; /* one below, on, one above */
                    r->origin[0] = (k & 1) ? (float)i + 0.5f : (float)i - 3.25f;
                    r->origin[1] = (k & 1) ? (float)j - 2.75f : (float)j + 0.5f;
                    r->origin[2] = ulps < 0 ? nextafterf(z, 0.0f) : ulps > 0 ? nextafterf(z, 2.0f) : z;
                    r->dir[0] = (k & 1) ? 0.0f : 1.0f;
                    r->dir[1] = (k & 1) ? 1.0f : 0.0f;
                    r->dir[2] = k >= 3 && k < 6 ? -1e-4f : 0.0f; /* rising a little: from under a back */
                    r->tmin = 0.0f;
                    r->tmax = 6.0f;
                    kinds[n++] = 0;
                }
            }
        }
        snprintf(what, sizeof what, "grazing the back faces of %s", m.name);
        trace_and_judge(what, &bvh, &m, rays, kinds, n, 0);
        lrt_bvh_destroy(&bvh);
        free_map(&m);
        free(rays);
        free(kinds);
    }
}

/* The fuzzer's finds on back-map trees (tests/fuzz/fuzz_core.c), each failing
   before its fix: (a) a z so slow beside x that the ray's z is scaled by
   2^zk (lrt__setup_rare): the nodes' unscaled back codes culled the texel
   it starts in; (b) a hit entering by a texel's back took the node's
   rounded back plane as its t, one ulp late, and was told as inside. */
static void test_thickness_found(void)
{
    static const struct {
        int w, h, tx, ty;
        uint16_t d, back;
        float o[3], v[3], tmin, tmax;
        int face;
    } cases[2] = {
        {42, 1, 40, 0, 3654, 57837, {40.5f, 0.5f, 0.7f}, {-5.0f, 0.0f, -0x1p-131f}, 0.0f, 0.8125f, LRT_FACE_INSIDE},
        {4, 4, 0, 2, 176, 176, {0.75f, 3.0f, 0x1.8b162cp-2f}, {0.0f, -0.125f, -0x1.1p-4f}, 0.0f, 0x1.3ap+3f, LRT_FACE_BACK},
    };
    int k;
    for (k = 0; k < 2; ++k) {
        uint16_t depth[64], back[64];
        lrt_depth pair[2];
        lrt_build_options opt;
        lrt_bvh bvh = {0};
        lrt_ray r;
        lrt_hit h;
        ref_map m;
        ref_ray q;
        ref_answer a;
        char why[256];
        int i, n = cases[k].w * cases[k].h;
        for (i = 0; i < n; ++i) depth[i] = back[i] = 65535;
        depth[cases[k].ty * cases[k].w + cases[k].tx] = cases[k].d;
        back[cases[k].ty * cases[k].w + cases[k].tx] = cases[k].back;
        memset(pair, 0, sizeof pair);
        pair[0].data = depth;
        pair[0].width = pair[1].width = (uint32_t)cases[k].w;
        pair[0].height = pair[1].height = (uint32_t)cases[k].h;
        pair[0].format = pair[1].format = LRT_FORMAT_UNORM16;
        pair[0].back = &pair[1];
        pair[1].data = back;
        memset(&opt, 0, sizeof opt);
        opt.node_bits = 16;
        opt.thickness = LRT_THICKNESS_BACK_MAP;
        memcpy(r.origin, cases[k].o, sizeof r.origin);
        memcpy(r.dir, cases[k].v, sizeof r.dir);
        r.tmin = cases[k].tmin;
        r.tmax = cases[k].tmax;
        CHECK(lrt_bvh_build(&bvh, pair, &opt, NULL) == LRT_SUCCESS && lrt_trace(&bvh, pair, &r, &h, 1, 0) == LRT_SUCCESS,
              "thickness find %d: build and trace", k);
        CHECK(h.kind == LRT_HIT && (int)h.x == cases[k].tx && (int)h.y == cases[k].ty && h.face == cases[k].face,
              "thickness find %d: kind %u (%u,%u) face %u", k, h.kind, h.x, h.y, h.face);
        ref_map_from_raw(&m, depth, cases[k].w, cases[k].h, 0, REF_FORMAT_UNORM16, 0);
        ref_map_set_back_from_raw(&m, back, 0, REF_FORMAT_UNORM16, 0);
        q = ref_ray_of(&r);
        a = to_answer(&h);
        CHECK(ref_check(&m, &q, &a, 0, why, sizeof why), "thickness find %d: %s", k, why);
        ref_map_free(&m);
        lrt_bvh_destroy(&bvh);
    }
}

/* ---- 2. the named cases of docs/MODEL.md ------------------------------------------ */
static lrt_hit trace1(const lrt_bvh *bvh, const test_map *m, float ox, float oy, float oz, float vx, float vy, float vz,
                      float tmin, float tmax)
{
    lrt_ray r;
    lrt_hit h;
    ref_ray q;
    ref_answer a;
    char why[256];
    r.origin[0] = ox; r.origin[1] = oy; r.origin[2] = oz;
    r.dir[0] = vx; r.dir[1] = vy; r.dir[2] = vz;
    r.tmin = tmin; r.tmax = tmax;
    memset(&h, 0xff, sizeof h);
    CHECK(lrt_trace(bvh, &m->depth, &r, &h, 1, 0) == LRT_SUCCESS, "trace1 failed");
    q = ref_ray_of(&r);
    a = to_answer(&h);
    CHECK(ref_check(&m->ref, &q, &a, 0, why, sizeof why), "named case disagrees with the reference: %s", why);
    return h;
}

static void test_named_cases(void)
{
    /* a 8x6 float map: floor at 0.8, a near block at 0.25 on texels (2..3, 1..2), a far-plane hole at (6,4) */
    float d[6][8];
    test_map m;
    lrt_bvh bvh = {0};
    lrt_hit h;
    int i, j;
    for (j = 0; j < 6; ++j)
        for (i = 0; i < 8; ++i) d[j][i] = (i >= 2 && i <= 3 && j >= 1 && j <= 2) ? 0.25f : 0.8f;
    d[4][6] = 1.0f;
    memset(&m, 0, sizeof m);
    m.depth.data = d;
    m.depth.width = 8;
    m.depth.height = 6;
    m.depth.format = LRT_FORMAT_FLOAT32;
    ref_map_from_raw(&m.ref, d, 8, 6, 0, REF_FORMAT_FLOAT32, 0);
    CHECK(lrt_bvh_build(&bvh, &m.depth, NULL, NULL) == LRT_SUCCESS, "named: build");

    h = trace1(&bvh, &m, 2.5f, 1.5f, 0.0f, 0, 0, 1, 0, 1); /* primary ray: own texel at t = d */
    CHECK(h.kind == LRT_HIT && h.t == 0.25f && h.x == 2 && h.y == 1, "primary ray: kind %u t %g (%u,%u)", h.kind, h.t, h.x, h.y);
    CHECK(h.face == LRT_FACE_TOP, "primary ray: face %u, not the top", h.face);
    h = trace1(&bvh, &m, 6.5f, 4.5f, 0.0f, 0, 0, 1, 0, 1); /* far-plane texel: hit at z = 1 = tmax */
    CHECK(h.kind == LRT_HIT && h.t == 1.0f && h.x == 6 && h.y == 4, "far-plane texel: kind %u t %g", h.kind, h.t);
    h = trace1(&bvh, &m, 6.5f, 4.5f, 0.0f, 0, 0, 1, 0, 0.999f); /* ... not reached before tmax */
    CHECK(h.kind == LRT_MISS_TMAX && h.face == LRT_FACE_NONE, "far-plane texel before tmax: kind %u face %u", h.kind, h.face);
    h = trace1(&bvh, &m, 0.5f, 0.5f, 0.9f, 1, 0, 0, 0.25f, 2); /* origin inside the solid at tmin */
    CHECK(h.kind == LRT_HIT && h.t == 0.25f && h.face == LRT_FACE_INSIDE, "inside at tmin: kind %u t %g face %u", h.kind, h.t,
          h.face);
    h = trace1(&bvh, &m, 0.5f, 3.5f, 0.5f, 1, 0, 0, 0, 100); /* over the floor, out the right edge */
    CHECK(h.kind == LRT_MISS_OFF_SCREEN, "leaves the screen: kind %u", h.kind);
    h = trace1(&bvh, &m, 0.5f, 3.5f, 0.5f, 1, 0, 0, 0, 3); /* over the floor, ends on screen */
    CHECK(h.kind == LRT_MISS_TMAX, "reaches tmax: kind %u", h.kind);
    h = trace1(&bvh, &m, -5.0f, -5.0f, 0.9f, -1, 0, 0, 0, 3); /* whole interval off the screen */
    CHECK(h.kind == LRT_MISS_OFF_SCREEN, "whole interval off screen: kind %u", h.kind);
    h = trace1(&bvh, &m, 0.5f, 1.5f, 0.5f, 1, 0, 0, 0, 7); /* into the side of the near block */
    CHECK(h.kind == LRT_HIT && h.t == 1.5f && h.x == 2 && h.y == 1, "block side: kind %u t %g (%u,%u)", h.kind, h.t, h.x, h.y);
    CHECK(h.face == LRT_FACE_SIDE, "block side: face %u", h.face);
    h = trace1(&bvh, &m, 4.5f, 3.5f, 1.5f, 0, 0, -1, 0, 2); /* from behind the far plane, towards the camera */
    CHECK(h.kind == LRT_HIT && h.t == 0.5f && h.face == LRT_FACE_BACK, "from behind: kind %u t %g face %u", h.kind, h.t,
          h.face);
    h = trace1(&bvh, &m, 4.5f, 1.5f, 0.85f, 0, 0, 0, 0, 1); /* v = 0 inside */
    CHECK(h.kind == LRT_HIT && h.t == 0.0f, "v=0 inside: kind %u t %g", h.kind, h.t);
    h = trace1(&bvh, &m, 4.5f, 1.5f, 0.5f, 0, 0, 0, 0.5f, 1); /* v = 0 outside */
    CHECK(h.kind == LRT_MISS_TMAX, "v=0 outside: kind %u", h.kind);
    h = trace1(&bvh, &m, 4.0f, 0.0f, 0.5f, 0, 1, 0.1f, 0, 10); /* along the cell edge x = 4, next to the block */
    CHECK(h.kind == LRT_HIT, "along a cell edge: kind %u", h.kind);
    h = trace1(&bvh, &m, 2.0f, 1.0f, 0.25f, 1, 1, 0, 0, 3); /* through corners, grazing the block top */
    CHECK(h.kind == LRT_HIT && h.t == 0.0f, "corner on the block top: kind %u t %g", h.kind, h.t);
    h = trace1(&bvh, &m, 2.5f, 1.5f, 0.25f, 0.5f, 0.3f, 0.2f, 0, 1); /* starts on its own surface, moves deeper */
    CHECK(h.kind == LRT_HIT && h.t == 0.0f && h.x == 2 && h.y == 1, "own surface: kind %u t %g", h.kind, h.t);
    CHECK(h.face == LRT_FACE_TOP, "own surface: face %u, not the top it starts on", h.face);
    h = trace1(&bvh, &m, 1e30f, 1.5f, 0.5f, -1e30f, 0, 0, 0, 2); /* huge finite values */
    CHECK(h.kind == LRT_HIT && h.x == 3 && h.y == 1, "huge values: kind %u (%u,%u)", h.kind, h.x, h.y);
    h = trace1(&bvh, &m, 1.0f, 1.0f, 0.0f, NAN, 0, 1, 0, 1);
    CHECK(h.kind == LRT_MISS_INVALID_RAY, "NaN direction: kind %u", h.kind);
    h = trace1(&bvh, &m, 1.0f, 1.0f, 0.0f, 0, 0, 1, -1, 1);
    CHECK(h.kind == LRT_MISS_INVALID_RAY, "tmin < 0: kind %u", h.kind);
    h = trace1(&bvh, &m, 1.0f, 1.0f, 0.0f, 0, 0, 1, 1, 0.5f);
    CHECK(h.kind == LRT_MISS_INVALID_RAY, "tmin > tmax: kind %u", h.kind);
    h = trace1(&bvh, &m, 1.0f, 1.0f, 0.0f, 0, 0, 1, 0, INFINITY);
    CHECK(h.kind == LRT_MISS_INVALID_RAY, "infinite tmax: kind %u", h.kind);
    lrt_bvh_destroy(&bvh);
    ref_map_free(&m.ref);
}

/* the rays the fuzzer found wrong once: each must now agree with the reference */
static void test_found_cases(void)
{
    test_map m;
    lrt_ray r;
    int k;
    for (k = 0; found_case(k, &m, &r); ++k) {
        lrt_bvh bvh = {0};
        lrt_hit h;
        ref_ray q;
        ref_answer a;
        char why[256];
        CHECK(lrt_bvh_build(&bvh, &m.depth, NULL, NULL) == LRT_SUCCESS, "found case %d: build", k);
        CHECK(lrt_trace(&bvh, &m.depth, &r, &h, 1, 0) == LRT_SUCCESS, "found case %d: trace", k);
        q = ref_ray_of(&r);
        a = to_answer(&h);
        CHECK(ref_check(&m.ref, &q, &a, 0, why, sizeof why), "found case %d: %s", k, why);
        lrt_bvh_destroy(&bvh);
        free_map(&m);
    }
    { /* a one-row map spans one row, whatever its stride */
        float row[60] = {0};
        lrt_depth d = {row, 60, 1, 0, LRT_FORMAT_FLOAT32, 0, NULL};
        lrt_bvh bvh = {0};
        d.row_stride = (size_t)PTRDIFF_MAX - sizeof row + 2;
        CHECK(lrt_bvh_build(&bvh, &d, NULL, NULL) == LRT_SUCCESS, "one row with a huge stride builds");
        lrt_bvh_destroy(&bvh);
    }
}

/* A direction of 2^16 or more is only scaled (lrt__huge_direction), not
   set up as a rare ray, when nothing else about the ray is odd: rays at
   each edge of that rule (the largest v_k up to 2^127, a v_k 2^100 or 2^101
   below it, a tmax that stays finite scaled or not, an origin far off the
   screen), each right by the reference, and the same answer traced alone
   (lrt__setup_ray) as in a batch of 8 (the AVX2 walk's lrt__setup8) */
static void test_huge_directions(void)
{
    static const int es[] = {16, 17, 40, 100, 124, 125, 126, 127};
    test_map m;
    lrt_bvh bvh = {0};
    lrt_ray rays[512];
    lrt_hit all[512], one;
    size_t n = 0, i;
    make_map(&m, 37, 23, SHAPE_NOISE, LRT_FORMAT_FLOAT32, 0, 0);
    CHECK(lrt_bvh_build(&bvh, &m.depth, NULL, NULL) == LRT_SUCCESS, "huge directions: build");
    for (i = 0; i < sizeof es / sizeof es[0]; ++i) {
        const int e = es[i];
        int k;
        for (k = 0; k < 32 && n < 512; ++k) {
            lrt_ray *r = &rays[n++];
            const float big = ldexpf(k & 1 ? -1.5f : 1.25f, e); /* the largest component */
            const float small = ldexpf(1.0f, e - ((k >> 1) & 1 ? 101 : 100));
            r->origin[0] = 3.25f + (float)(k % 7) * 4.5f;
            r->origin[1] = 2.75f + (float)(k % 5) * 4.0f;
            r->origin[2] = (k >> 2) & 1 ? 0.0f : 0.4f;
            if ((k >> 3) & 1) r->origin[0] = 1e6f; /* far off the screen */
            r->dir[0] = (k >> 4) & 1 ? small : big;
            r->dir[1] = (k >> 4) & 1 ? -big * 0.5f : -small;
            r->dir[2] = ldexpf(k & 2 ? 0.75f : -0.75f, e - (k % 3) * 8);
            r->tmin = (k >> 2) & 1 ? 0.0f : ldexpf(1.0f, -126);
            r->tmax = (k >> 3) & 1 ? 3.40282347e38f : ldexpf(1.99f, 127 - e > -126 ? 127 - e : -126);
        }
    }
    CHECK(lrt_trace(&bvh, &m.depth, rays, all, n, 0) == LRT_SUCCESS, "huge directions: trace");
    for (i = 0; i < n; ++i) {
        ref_ray q = ref_ray_of(&rays[i]);
        ref_answer a = to_answer(&all[i]);
        char why[256];
        CHECK(lrt_trace(&bvh, &m.depth, &rays[i], &one, 1, 0) == LRT_SUCCESS, "huge directions: trace one");
        CHECK(memcmp(&one, &all[i], sizeof one) == 0, "huge direction %zu: alone kind %u t %g, in a batch kind %u t %g", i,
              one.kind, one.t, all[i].kind, all[i].t);
        CHECK(ref_check(&m.ref, &q, &a, 0, why, sizeof why), "huge direction %zu: %s", i, why);
    }
    lrt_bvh_destroy(&bvh);
    free_map(&m);
}

/* ---- 3. Morton mapping and level geometry --------------------------------------- */
static uint32_t ilog2(uint32_t v) { uint32_t k = 0; while ((1u << k) < v) ++k; return k; }

static void test_layout(void)
{
    static const int sizes[][2] = {{1, 1}, {1, 16384}, {16384, 1}, {3, 5}, {7, 9}, {1282, 1110}, {1024, 1024},
                                   {16384, 16384}, {4, 2}, {5, 3}, {64, 256}};
    size_t s;
    for (s = 0; s < sizeof sizes / sizeof sizes[0]; ++s) {
        lrt_layout L;
        uint32_t w = (uint32_t)sizes[s][0], h = (uint32_t)sizes[s][1], lv, cw = w, ch = h;
        size_t offset = 0;
        int ok = 1;
        CHECK(lrt_layout_compute(w, h, 8, &L) == LRT_SUCCESS, "layout %ux%u", w, h);
        /* independent recomputation: 4x2 on even levels, 2x4 on odd, ceil */
        for (lv = 0; lv < L.level_count; ++lv) {
            uint32_t bw = (lv & 1) ? 2 : 4, bh = (lv & 1) ? 4 : 2;
            cw = (cw + bw - 1) / bw;
            ch = (ch + bh - 1) / bh;
            ok &= L.levels[lv + 1].width == cw && L.levels[lv + 1].height == ch;
            ok &= L.levels[lv].block_w == bw && L.levels[lv].block_h == bh;
        }
        ok &= cw == 1 && ch == 1; /* the root level is the first 1x1 one */
        ok &= L.level_count == 1 || L.levels[L.level_count - 1].width * L.levels[L.level_count - 1].height > 1;
        for (lv = 1; lv <= L.level_count; ++lv) {
            size_t slots = lv == L.level_count ? 1 : (size_t)L.levels[lv + 1].width * L.levels[lv + 1].height * 8;
            ok &= L.levels[lv].offset == offset && L.levels[lv].count == slots;
            offset += slots;
        }
        /* 8 bits: a 6-byte level-1 node (word and scale) where it has a parent, 16 bytes for every other */
        ok &= L.node_count == offset && L.bytes == (L.level_count >= 2 ? L.levels[1].count * 6 + (offset - L.levels[1].count) * 16 : offset * 16);
        CHECK(ok, "level sizes/offsets of %ux%u", w, h);
        /* memory: about 1.04 bytes per texel at 8 bits for sizes that fill their blocks (the
           issue's bound: 1.14) */
        if (w >= 64 && h >= 64 && (w % 64) == 0 && (h % 64) == 0)
            CHECK((double)L.bytes / ((double)w * h) < 1.06, "%ux%u: %.3f bytes per texel", w, h, (double)L.bytes / ((double)w * h));
        /* Morton: every real node of every level gets a distinct index in its level */
        if ((size_t)w * h <= (size_t)1 << 21) {
            for (lv = 1; lv <= L.level_count; ++lv) {
                size_t n = L.levels[lv].count, x, y;
                unsigned char *seen = (unsigned char *)calloc(n, 1);
                int distinct = 1;
                for (y = 0; y < L.levels[lv].height; ++y)
                    for (x = 0; x < L.levels[lv].width; ++x) {
                        size_t k = lrt_layout_node_index(&L, lv, (uint32_t)x, (uint32_t)y);
                        if (k >= n || seen[k]) distinct = 0;
                        else seen[k] = 1;
                    }
                free(seen);
                CHECK(distinct, "%ux%u level %u: Morton indices not distinct/in range", w, h, lv);
            }
        }
    }
    { /* bit by bit, as SEED.md writes it, where the parent grid width is a power of two */
        lrt_layout L;
        uint32_t lv, x, y;
        int ok = 1;
        lrt_layout_compute(1024, 1024, 16, &L);
        for (lv = 1; lv < L.level_count; ++lv) {
            uint32_t xb = ilog2(L.levels[lv + 1].width * L.levels[lv].block_w); /* bits of x at this level */
            for (y = 0; y < L.levels[lv].height; y += 3)
                for (x = 0; x < L.levels[lv].width; x += 5) {
                    uint64_t code = 0;
                    int bit = 0, b;
                    if (L.levels[lv].block_w == 4) { /* y_n..y_1 | x_n..x_2 | y_0 x_1 x_0 */
                        code |= (uint64_t)((x >> 0) & 1) << bit++;
                        code |= (uint64_t)((x >> 1) & 1) << bit++;
                        code |= (uint64_t)((y >> 0) & 1) << bit++;
                        for (b = 2; b < (int)xb; ++b) code |= (uint64_t)((x >> b) & 1) << bit++;
                        for (b = 1; b < 31; ++b) code |= (uint64_t)((y >> b) & 1) << bit++;
                    } else { /* y_n..y_2 | x_n..x_1 | y_1 y_0 x_0 */
                        code |= (uint64_t)((x >> 0) & 1) << bit++;
                        code |= (uint64_t)((y >> 0) & 1) << bit++;
                        code |= (uint64_t)((y >> 1) & 1) << bit++;
                        for (b = 1; b < (int)xb; ++b) code |= (uint64_t)((x >> b) & 1) << bit++;
                        for (b = 2; b < 31; ++b) code |= (uint64_t)((y >> b) & 1) << bit++;
                    }
                    ok &= code == lrt_layout_node_index(&L, lv, x, y);
                }
        }
        CHECK(ok, "Morton codes differ from the bit-by-bit patterns of SEED.md");
    }
}

/* ---- 3b. 8-bit trees: compact level-1 nodes --------------------------------- */
/* Read against a 16-bit tree of the same map, independently of the
   library's own decoding: above level 1 the two trees hold the same codes;
   a level-1 node's own height H in its parent is the largest of its
   texels' 16-bit codes; its word holds 4 bits a texel, a step j, and its
   scale (after all the level's words) is 16 (H - lowest) / 15 rounded
   down, kept within [16, 65535]; H - ((j * scale) >> 4) is the texel's
   code or above it by at most scale / 16 (below the last step), and j the
   greatest step for which it is not below the code (searched here, not
   divided). */
static int compact_tree_right(const lrt_bvh *b8, const lrt_bvh *b16, const char *what)
{
    const lrt_layout *L = &b16->layout;
    const size_t count1 = L->levels[1].count, rest = (L->node_count - count1) * 16u;
    const uint16_t *n16 = (const uint16_t *)b16->nodes;
    int copies;
    uint32_t bad = 0, nx, ny, k;
    if (b8->layout.bytes != (count1 * 6u + rest) * (L->back_codes ? 2u : 1u)) {
        printf("FAIL %s: %zu bytes\n", what, b8->layout.bytes);
        return 0;
    }
    for (copies = 0; copies < (L->back_codes ? 2 : 1); ++copies) { /* heights, then back codes */
        const unsigned char *c8 = (const unsigned char *)b8->nodes + copies * (b8->layout.bytes / 2u);
        const uint16_t *c16 = n16 + copies * (L->bytes / 4u);
        const uint16_t *scales = (const uint16_t *)(const void *)(c8 + count1 * 4u);
        const uint16_t *up8 = (const uint16_t *)(const void *)(c8 + count1 * 6u); /* levels 2 and up */
        if (memcmp(up8, c16 + count1 * 8u, rest) != 0) {
            printf("FAIL %s: codes above level 1 differ from the 16-bit tree's\n", what);
            return 0;
        }
        for (ny = 0; ny < L->levels[1].height; ++ny)
            for (nx = 0; nx < L->levels[1].width; ++nx) {
                const size_t node = lrt_layout_node_index(L, 1, nx, ny);
                const size_t parent = L->levels[2].offset + lrt_layout_node_index(L, 2, nx >> 1, ny >> 2);
                const uint32_t own = up8[(parent - count1) * 8u + (((ny & 3u) << 1) | (nx & 1u))];
                const uint32_t scale = scales[node];
                uint32_t word, top = 0, low = 65535u, want;
                memcpy(&word, c8 + node * 4u, 4);
                for (k = 0; k < 8; ++k) {
                    top = c16[node * 8u + k] > top ? c16[node * 8u + k] : top;
                    low = c16[node * 8u + k] < low ? c16[node * 8u + k] : low;
                }
                want = (top - low) * 16u / 15u;
                want = want < 16u ? 16u : want > 65535u ? 65535u : want;
                if (own != top || scale != want) {
                    if (bad++ < 5) printf("FAIL %s: level-1 node (%u, %u): height %u (want %u), scale %u (want %u)\n", what, nx, ny, own, top, scale, want);
                    continue;
                }
                for (k = 0; k < 8; ++k) {
                    const uint32_t step = (word >> (4u * k)) & 15u, code = c16[node * 8u + k];
                    const uint32_t drop = (step * scale) >> 4, bound = top - drop;
                    const int greatest = step == 15u || ((step + 1u) * scale >> 4) > top - code;
                    if (drop > top || bound < code || (step < 15u && bound - code > scale / 16u) || !greatest)
                        if (bad++ < 5) printf("FAIL %s: level-1 node (%u, %u) slot %u: %u for the code %u\n", what, nx, ny, k, bound, code);
                }
                /* the node's lowest texel lands within one code of its own (spreads up to 61439) */
                if (top - low <= 61439u) {
                    uint32_t lowest = 65535u;
                    for (k = 0; k < 8; ++k) {
                        const uint32_t b = top - ((((word >> (4u * k)) & 15u) * scale) >> 4);
                        lowest = b < lowest ? b : lowest;
                    }
                    if (lowest - low > 1u && bad++ < 5) printf("FAIL %s: level-1 node (%u, %u): lowest %u for %u\n", what, nx, ny, lowest, low);
                }
            }
    }
    return bad == 0;
}

/* Every step boundary of every spread: for each spread d (a node whose
   texels include H and H - d, so its scale is d's), texels at H - g for g
   on both sides of each step's drop (j * scale) >> 4, the only places where
   a step found by a reciprocal (the SSE2 refit) could differ from the
   greatest step by the definition (compact_tree_right) */
static void test_compact_boundaries(void)
{
    /* at most 30 boundary texels a spread: 5 nodes of 6 free slots (slot 0
       is H, slot 1 H - d); codes are 65535 - v for unorm16 v, so H = 65535
       (v = 0) and a texel at H - g holds g */
    const uint32_t w = 2048, per_node = 6, spreads = 65535, nodes_max = spreads * 5u;
    const uint32_t h = (nodes_max + w / 4u - 1u) / (w / 4u) * 2u; /* 4x2 texels a node */
    uint16_t *map = (uint16_t *)calloc((size_t)w * h, sizeof(uint16_t));
    uint32_t d, j, n = 0, s;
    size_t nodes = 0;
    lrt_depth dm;
    lrt_build_options opt;
    lrt_bvh b8 = {0}, b16 = {0};
    for (d = 1; d <= spreads; ++d) {
        uint32_t scale = d * 16u / 15u, gs[30], m = 0;
        scale = scale < 16u ? 16u : scale > 65535u ? 65535u : scale;
        for (j = 1; j < 16u; ++j) { /* both sides of step j's drop, within the spread */
            const uint32_t drop = (j * scale) >> 4;
            if (drop - 1u <= d) gs[m++] = drop - 1u;
            if (drop <= d) gs[m++] = drop;
        }
        n += m;
        for (j = 0; j < m; j += per_node, ++nodes) { /* the last node padded with the lowest */
            const uint32_t x = (uint32_t)(nodes % (w / 4u)) * 4u, y = (uint32_t)(nodes / (w / 4u)) * 2u;
            map[(size_t)y * w + x + 1] = (uint16_t)d;
            for (s = 2; s < 8u; ++s)
                map[(size_t)(y + (s >> 2)) * w + x + (s & 3u)] = (uint16_t)(j + s - 2u < m ? gs[j + s - 2u] : d);
        }
    }
    dm = packed_depth(map, w, h, LRT_FORMAT_UNORM16);
    memset(&opt, 0, sizeof opt);
    opt.node_bits = 8;
    CHECK(lrt_bvh_build(&b8, &dm, &opt, NULL) == LRT_SUCCESS, "compact boundaries: 8-bit build");
    opt.node_bits = 16;
    CHECK(lrt_bvh_build(&b16, &dm, &opt, NULL) == LRT_SUCCESS, "compact boundaries: 16-bit build");
    CHECK(compact_tree_right(&b8, &b16, "compact boundaries"), "compact boundaries: %zu nodes, %u texels at a boundary", nodes, n);
    lrt_bvh_destroy(&b8);
    lrt_bvh_destroy(&b16);
    free(map);
}

static void test_compact_codes(void)
{
    static const int sizes[][2] = {{37, 21}, {64, 64}, {130, 67}, {5, 3}};
    uint32_t seed = 12345u;
    size_t z, k;
    for (z = 0; z < sizeof sizes / sizeof sizes[0]; ++z) {
        const int w = sizes[z][0], h = sizes[z][1];
        float *d = (float *)malloc(sizeof(float) * w * h), *back = (float *)malloc(sizeof(float) * w * h);
        lrt_depth dm[2];
        lrt_bvh b8 = {0}, b16 = {0};
        lrt_build_options opt;
        int thick;
        char what[64];
        for (k = 0; k < (size_t)(w * h); ++k) { /* a far floor, with objects and holes */
            seed = seed * 1664525u + 1013904223u;
            d[k] = 1.0f - (float)(seed >> 8) / 16777216.0f * ((k % 7u) == 0 ? 0.5f : 0.004f);
            back[k] = d[k] + 0.01f * (float)(seed & 3u);
        }
        d[0] = 0.0f;
        d[1] = 1.0f;
        d[2] = -0.5f; /* clamped to 0 */
        d[3] = 1e-42f; /* subnormal: 0 */
        memset(dm, 0, sizeof dm);
        dm[0].data = d;
        dm[0].width = (uint32_t)w;
        dm[0].height = (uint32_t)h;
        dm[0].format = LRT_FORMAT_FLOAT32;
        dm[1] = dm[0];
        dm[1].data = back;
        for (thick = 0; thick < 2; ++thick) {
            memset(&opt, 0, sizeof opt);
            if (thick) {
                opt.thickness = LRT_THICKNESS_BACK_MAP;
                dm[0].back = &dm[1];
            }
            opt.node_bits = 8;
            CHECK(lrt_bvh_build(&b8, dm, &opt, NULL) == LRT_SUCCESS, "compact codes: 8-bit build");
            opt.node_bits = 16;
            CHECK(lrt_bvh_build(&b16, dm, &opt, NULL) == LRT_SUCCESS, "compact codes: 16-bit build");
            snprintf(what, sizeof what, "%dx%d%s", w, h, thick ? " back map" : "");
            if (b16.layout.level_count < 2) /* one node: no parent to hold its height, 16-bit codes */
                CHECK(b8.layout.bytes == b16.layout.bytes && memcmp(b8.nodes, b16.nodes, b8.layout.bytes) == 0,
                      "compact codes %s: a one-node 8-bit tree is not the 16-bit one", what);
            else
                CHECK(compact_tree_right(&b8, &b16, what), "compact codes %s: the 8-bit tree", what);
            lrt_bvh_destroy(&b8);
            lrt_bvh_destroy(&b16);
        }
        free(d);
        free(back);
    }
}

/* ---- 4. update equals rebuild ------------------------------------------------- */
/* a back map that moves with the depth: 0.03 behind it, 0.2 behind the sphere
   (inside the rect where the depth changes, as a back-face pass would) */
static void paint_back(const float *d, float *back, int w, int h, int frame)
{
    int k;
    for (k = 0; k < w * h; ++k) back[k] = d[k] + (d[k] < 0.5f ? 0.2f : 0.03f) + 0.001f * (float)(frame % 3);
}

static void test_update(void)
{
    const int w = 203, h = 131;
    float *d = (float *)malloc(sizeof(float) * w * h), *prev = (float *)malloc(sizeof(float) * w * h);
    float *back = (float *)malloc(sizeof(float) * w * h);
    lrt_depth dm[2];
    lrt_bvh live = {0}, fresh = {0};
    lrt_build_options opt;
    int frame, bits, thick;
    static const char *models[4] = {"", " back map", " constant thickness", " relative thickness"};
    for (thick = 0; thick <= LRT_THICKNESS_RELATIVE; ++thick) {
        for (bits = 8; bits <= 16; bits += 8) {
            int same_full = 1, same_rect = 1;
            memset(dm, 0, sizeof dm);
            dm[0].data = d;
            dm[0].width = dm[1].width = w;
            dm[0].height = dm[1].height = h;
            dm[0].format = dm[1].format = LRT_FORMAT_FLOAT32;
            dm[0].back = thick == LRT_THICKNESS_BACK_MAP ? &dm[1] : NULL;
            dm[1].data = back;
            memset(&opt, 0, sizeof opt);
            opt.node_bits = (uint32_t)bits;
            opt.thickness = (uint32_t)thick;
            opt.thickness_value = thick == LRT_THICKNESS_CONSTANT ? 0.3f : 0.05f;
            opt.near_z = 0.1f;
            opt.far_z = 50.0f;
            paint_frame(d, w, h, 0);
            paint_back(d, back, w, h, 0);
            CHECK(lrt_bvh_build(&live, dm, &opt, NULL) == LRT_SUCCESS, "update: build");
            for (frame = 1; frame < 24; ++frame) {
                lrt_rect rect;
                memcpy(prev, d, sizeof(float) * w * h);
                paint_frame(d, w, h, frame);
                rect = changed_rect(prev, d, w, h);
                /* odd frames (whole updates) also move the back everywhere; even
                   ones keep that offset, so the back moves only inside the rect */
                paint_back(d, back, w, h, (frame & 1) ? frame : frame - 1);
                /* even frames: dirty rect; odd frames: whole map */
                CHECK(lrt_bvh_update(&live, dm, (frame & 1) ? NULL : &rect) == LRT_SUCCESS, "update frame %d", frame);
                CHECK(lrt_bvh_build(&fresh, dm, &opt, NULL) == LRT_SUCCESS, "rebuild frame %d", frame);
                if (memcmp(live.nodes, fresh.nodes, live.layout.bytes) != 0) {
                    if (frame & 1) same_full = 0;
                    else same_rect = 0;
                }
                lrt_bvh_destroy(&fresh);
            }
            CHECK(same_full, "%d-bit%s: update of the whole map differs from a rebuild", bits, models[thick]);
            CHECK(same_rect, "%d-bit%s: update of the dirty rect differs from a rebuild", bits, models[thick]);
            lrt_bvh_destroy(&live);
        }
    }
    { /* a back map changed outside the rect: the update must miss it (the test above can fail) */
        lrt_rect corner = {0, 0, 4, 4};
        paint_frame(d, w, h, 0);
        paint_back(d, back, w, h, 0);
        dm[0].back = &dm[1];
        opt.thickness = LRT_THICKNESS_BACK_MAP;
        lrt_bvh_build(&live, dm, &opt, NULL);
        back[(size_t)(h / 2) * (size_t)w + (size_t)(w / 2)] = 1.0f;
        lrt_bvh_update(&live, dm, &corner);
        lrt_bvh_build(&fresh, dm, &opt, NULL);
        CHECK(memcmp(live.nodes, fresh.nodes, live.layout.bytes) != 0, "a stale back map went unnoticed");
        CHECK(live.layout.bytes == 2 * live.layout.node_count * live.layout.node_bytes, "a back-map tree holds two codes a slot");
        lrt_bvh_destroy(&fresh);
        lrt_bvh_destroy(&live);
    }
    { /* an update with a rect that misses the change must NOT equal a rebuild: the test can fail */
        lrt_rect elsewhere = {0, 0, 4, 4};
        dm[0].back = NULL;
        paint_frame(d, w, h, 0);
        lrt_bvh_build(&live, dm, NULL, NULL);
        paint_frame(d, w, h, 9);
        lrt_bvh_update(&live, dm, &elsewhere);
        lrt_bvh_build(&fresh, dm, NULL, NULL);
        CHECK(memcmp(live.nodes, fresh.nodes, live.layout.bytes) != 0, "a stale update went unnoticed");
        lrt_bvh_destroy(&fresh);
        lrt_bvh_destroy(&live);
    }
    free(d);
    free(prev);
    free(back);
}

/* ---- 4b. back codes of a thickness model: the row's lanes against one texel --- */
/* A row's CONSTANT and RELATIVE back codes (four at a time where the build
   has SSE2: lrt__model_back_codes4) against the scalar recipe, one texel a
   row (lrt__model_back_bits, its plate included), and the 8-bit look-up
   table against both: every unorm value, float depths the model clamps
   (NaN, infinities, above 1, below 0, -0, subnormal) and ones near its
   edges (0, 1, the least normal, just below 1), each Z direction, far
   planes finite and not, thin and thick layers. The node bytes rest on it. */
static void test_model_back_codes(void)
{
    static const float models[][4] = {/* thickness, value, near, far */
        {LRT_THICKNESS_CONSTANT, 0.3f, 0.1f, 100.0f}, {LRT_THICKNESS_CONSTANT, 1e-6f, 0.1f, 100.0f},
        {LRT_THICKNESS_CONSTANT, 1e3f, 0.01f, 1e5f}, {LRT_THICKNESS_CONSTANT, 0.3f, 0.1f, INFINITY},
        {LRT_THICKNESS_CONSTANT, 1e-3f, 1.0f, 2.0f}, {LRT_THICKNESS_RELATIVE, 0.05f, 0.1f, 100.0f},
        {LRT_THICKNESS_RELATIVE, 1e-7f, 0.1f, 100.0f}, {LRT_THICKNESS_RELATIVE, 10.0f, 0.1f, INFINITY},
        {LRT_THICKNESS_RELATIVE, 0.5f, 1.0f, 1.5f}};
    static const uint32_t specials[] = {0x7fc00000u, 0xffc00001u, 0x7f800001u, 0x7f800000u, 0xff800000u, 0x3fc00000u,
                                        0x3f800000u, 0x3f7fffffu, 0x3f7ffffeu, 0x00000000u, 0x80000000u, 0x00000001u,
                                        0x007fffffu, 0x00800000u, 0x80800000u, 0xbe800000u, 0x33800000u, 0x3f000000u};
    const uint32_t n = 65536u, nspecial = (uint32_t)(sizeof specials / sizeof specials[0]);
    unsigned char *row = (unsigned char *)malloc((size_t)n * 4u);
    uint32_t *lanes = (uint32_t *)malloc((size_t)n * 4u), *one = (uint32_t *)malloc((size_t)n * 4u), table[256];
    uint32_t i, m, seed = 2463534242u; /* a generator of its own: the other tests' maps stay as they were */
    int f, reversed;
    for (f = 1; f <= 3; ++f) {
        const lrt_format format = (lrt_format)f;
        const uint32_t count = format == LRT_FORMAT_UNORM8 ? 256u : n, bpp = format == LRT_FORMAT_FLOAT32 ? 4u : (uint32_t)f;
        for (i = 0; i < count; ++i) {
            if (format == LRT_FORMAT_UNORM8) {
                row[i] = (unsigned char)i;
            } else if (format == LRT_FORMAT_UNORM16) {
                const uint16_t v = (uint16_t)i;
                memcpy(row + (size_t)i * 2u, &v, 2);
            } else { /* the specials, then any bits, uniform depths, depths near 1 and 8-bit steps */
                float d, u;
                seed ^= seed << 13;
                seed ^= seed >> 17;
                seed ^= seed << 5;
                u = (float)(seed >> 8) / 16777216.0f;
                memcpy(&d, i < nspecial ? &specials[i] : &seed, 4);
                if (i >= nspecial && i % 4u != 0u) d = i % 4u == 1u ? u : i % 4u == 2u ? 1.0f - u * 1e-4f : (float)(i % 256u) / 255.0f;
                memcpy(row + (size_t)i * 4u, &d, 4);
            }
        }
        for (reversed = 0; reversed <= 1; ++reversed)
            for (m = 0; m < sizeof models / sizeof models[0]; ++m) {
                lrt_build_options opt;
                lrt_layout L;
                lrt_depth dm;
                uint32_t bad = 0, first = 0;
                memset(&opt, 0, sizeof opt);
                opt.thickness = (uint32_t)models[m][0];
                opt.thickness_value = models[m][1];
                opt.near_z = models[m][2];
                opt.far_z = models[m][3];
                dm = packed_depth(row, count, 1, format);
                dm.flags = reversed ? LRT_DEPTH_REVERSED_Z : 0u;
                CHECK(lrt__options_layout(16, 16, format, &opt, &L) == LRT_SUCCESS, "model back codes: layout of model %u", m);
                lrt__row_model_back_codes(&L, &dm, (size_t)count * bpp, 0, 0, count, 65535u, lanes, NULL);
                for (i = 0; i < count; ++i) lrt__row_model_back_codes(&L, &dm, (size_t)count * bpp, 0, i, 1, 65535u, one + i, NULL);
                if (format == LRT_FORMAT_UNORM8) lrt__unorm8_model_table(&L, &dm, 65535u, table);
                for (i = 0; i < count; ++i)
                    if (lanes[i] != one[i] || (format == LRT_FORMAT_UNORM8 && table[i] != one[i])) {
                        if (bad++ == 0) first = i;
                    }
                CHECK(bad == 0, "model back codes: format %d%s model %u: %u of %u differ, the first texel %u: row %u, one %u, table %u",
                      f, reversed ? " reversed" : "", m, bad, count, first, lanes[first], one[first],
                      format == LRT_FORMAT_UNORM8 ? table[first] : one[first]);
            }
    }
    free(row);
    free(lanes);
    free(one);
}

/* ---- 5. bad arguments ------------------------------------------------------------ */
static int g_allocs, g_frees;
static void *count_alloc(void *user, size_t n) { ++*(int *)user; ++g_allocs; return malloc(n); }
static void count_free(void *user, void *p) { (void)user; ++g_frees; free(p); }
static void *fail_alloc(void *user, size_t n) { (void)user; (void)n; return NULL; }

static void test_bad_arguments(void)
{
    float d[6] = {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f};
    lrt_depth dm, bad;
    lrt_bvh bvh = {0}, untouched = {0}, other = {0};
    lrt_build_options opt;
    lrt_allocator a;
    lrt_ray ray;
    lrt_hit hit;
    lrt_rect rect;
    size_t bytes;
    int user = 0;
    unsigned char sentinel[sizeof(lrt_bvh)];
    dm = packed_depth(d, 3, 2, LRT_FORMAT_FLOAT32);
    memset(&opt, 0, sizeof opt);
    memset(&untouched, 0xab, sizeof untouched);
    memcpy(sentinel, &untouched, sizeof sentinel);

#define EXPECT_BUILD(depth_ptr, opt_ptr, code, what)                                                          \
    do {                                                                                                      \
        lrt_result r_ = lrt_bvh_build(&untouched, depth_ptr, opt_ptr, NULL);                                  \
        CHECK(r_ == code, "%s: got %s", what, lrt_result_string(r_));                                         \
        CHECK(memcmp(&untouched, sentinel, sizeof sentinel) == 0, "%s: the lrt_bvh was written", what);       \
    } while (0)

    EXPECT_BUILD(NULL, NULL, LRT_ERROR_NULL_POINTER, "null depth");
    bad = dm; bad.data = NULL;
    EXPECT_BUILD(&bad, NULL, LRT_ERROR_NULL_POINTER, "null data");
    bad = dm; bad.width = 0;
    EXPECT_BUILD(&bad, NULL, LRT_ERROR_INVALID_SIZE, "zero width");
    bad = dm; bad.height = 0;
    EXPECT_BUILD(&bad, NULL, LRT_ERROR_INVALID_SIZE, "zero height");
    bad = dm; bad.width = LINEAR_RT_MAX_DIM + 1;
    EXPECT_BUILD(&bad, NULL, LRT_ERROR_INVALID_SIZE, "oversized width");
    bad = dm; bad.row_stride = 11;
    EXPECT_BUILD(&bad, NULL, LRT_ERROR_INVALID_STRIDE, "stride smaller than a row");
    bad = dm; bad.format = (lrt_format)7;
    EXPECT_BUILD(&bad, NULL, LRT_ERROR_INVALID_FORMAT, "unknown format");
    bad = dm; bad.format = (lrt_format)0;
    EXPECT_BUILD(&bad, NULL, LRT_ERROR_INVALID_FORMAT, "format 0");
    bad = dm; bad.flags = 0x80;
    EXPECT_BUILD(&bad, NULL, LRT_ERROR_INVALID_OPTION, "unknown depth flag");
    bad = dm; bad.row_stride = (size_t)-1 / 2 + 1;
    EXPECT_BUILD(&bad, NULL, LRT_ERROR_SIZE_OVERFLOW, "byte count overflows");
    opt.node_bits = 12;
    EXPECT_BUILD(&dm, &opt, LRT_ERROR_INVALID_OPTION, "node bits 12");
    opt.node_bits = 0;
    { /* thickness: the back map and the model must come together, and match the depth */
        float back[6] = {0.6f, 0.6f, 0.6f, 0.6f, 0.6f, 0.6f};
        lrt_depth pair[2];
        lrt_bvh thick = {0};
        pair[0] = dm;
        pair[0].back = &pair[1];
        pair[1] = dm;
        pair[1].data = back;
        opt.thickness = 4;
        EXPECT_BUILD(pair, &opt, LRT_ERROR_INVALID_THICKNESS, "unknown thickness model");
        opt.thickness = LRT_THICKNESS_BACK_MAP;
        EXPECT_BUILD(&dm, &opt, LRT_ERROR_THICKNESS_MISMATCH, "a back-map tree without a back map");
        opt.thickness = LRT_THICKNESS_INFINITE;
        EXPECT_BUILD(pair, &opt, LRT_ERROR_THICKNESS_MISMATCH, "a back map for an infinite tree");
        opt.thickness = LRT_THICKNESS_BACK_MAP;
        pair[1].data = NULL;
        EXPECT_BUILD(pair, &opt, LRT_ERROR_NULL_POINTER, "a null back map");
        pair[1].data = back;
        pair[1].width = 2;
        EXPECT_BUILD(pair, &opt, LRT_ERROR_SIZE_MISMATCH, "a back map of another size");
        pair[1].width = 3;
        pair[1].format = LRT_FORMAT_UNORM16;
        EXPECT_BUILD(pair, &opt, LRT_ERROR_DEPTH_MISMATCH, "a back map of another format");
        pair[1].format = LRT_FORMAT_FLOAT32;
        pair[1].flags = LRT_DEPTH_REVERSED_Z;
        EXPECT_BUILD(pair, &opt, LRT_ERROR_DEPTH_MISMATCH, "a back map of the other Z direction");
        pair[1].flags = 0;
        pair[1].row_stride = 8;
        EXPECT_BUILD(pair, &opt, LRT_ERROR_INVALID_STRIDE, "a back map stride smaller than a row");
        pair[1].row_stride = (size_t)-1 / 2 + 1;
        EXPECT_BUILD(pair, &opt, LRT_ERROR_SIZE_OVERFLOW, "a back map whose byte count overflows");
        pair[1].row_stride = 0;
        CHECK(lrt_bvh_memory_size(3, 2, LRT_FORMAT_FLOAT32, &opt, &bytes) == LRT_SUCCESS &&
                  lrt_bvh_build(&thick, pair, &opt, NULL) == LRT_SUCCESS && bytes >= thick.layout.bytes,
              "a back-map tree: build and its memory size");
        ray.origin[0] = 1.5f; ray.origin[1] = 0.5f; ray.origin[2] = 0.0f; ray.tmin = 0.0f;
        ray.dir[0] = 0.0f; ray.dir[1] = 0.0f; ray.dir[2] = 1.0f; ray.tmax = 1.0f;
        CHECK(lrt_trace(&thick, &dm, &ray, &hit, 1, 0) == LRT_ERROR_THICKNESS_MISMATCH, "trace without its back map");
        CHECK(lrt_bvh_update(&thick, &dm, NULL) == LRT_ERROR_THICKNESS_MISMATCH, "update without its back map");
        back[4] = NAN; /* a NaN back reads as 1: far */
        CHECK(lrt_bvh_update(&thick, pair, NULL) == LRT_SUCCESS && lrt_trace(&thick, pair, &ray, &hit, 1, 0) == LRT_SUCCESS &&
                  hit.kind == LRT_HIT && hit.t == 0.5f && hit.face == LRT_FACE_TOP,
              "a back-map tree traces: kind %u t %g", hit.kind, hit.t);
        ray.origin[0] = 0.0f; ray.origin[1] = 1.5f; ray.origin[2] = 0.7f; /* level, under row 1's slabs */
        ray.dir[0] = 1.0f; ray.dir[2] = 0.0f; ray.tmax = 3.0f;
        CHECK(lrt_trace(&thick, pair, &ray, &hit, 1, 0) == LRT_SUCCESS && hit.kind == LRT_HIT && hit.x == 1 &&
                  hit.y == 1 && hit.t == 1.0f && hit.face == LRT_FACE_SIDE,
              "under a slab [0.5, 0.6], into the NaN back's column: kind %u (%u, %u) face %u", hit.kind, hit.x, hit.y,
              hit.face);
        lrt_bvh_destroy(&thick);
        opt.thickness = LRT_THICKNESS_INFINITE;
        CHECK(lrt_bvh_build(&thick, &dm, &opt, NULL) == LRT_SUCCESS &&
                  lrt_trace(&thick, pair, &ray, &hit, 1, 0) == LRT_ERROR_THICKNESS_MISMATCH,
              "an infinite tree traced with a back map");
        lrt_bvh_destroy(&thick);
    }
    { /* constant and relative thickness: their numbers, and no back map */
        static const float zero[6] = {0, 0, 0, 0, 0, 0};
        float back[6] = {1, 1, 1, 1, 1, 1};
        lrt_depth flat, pair[2];
        lrt_bvh thick = {0};
        int model;
        flat = packed_depth(zero, 3, 2, LRT_FORMAT_FLOAT32);
        pair[0] = flat;
        pair[0].back = &pair[1];
        pair[1] = flat;
        pair[1].data = back;
        for (model = LRT_THICKNESS_CONSTANT; model <= LRT_THICKNESS_RELATIVE; ++model) {
            const char *name = model == LRT_THICKNESS_CONSTANT ? "constant" : "relative";
            static const float bad_values[4] = {0.0f, -1.0f, NAN, INFINITY};
            int k;
            memset(&opt, 0, sizeof opt);
            opt.thickness = (uint32_t)model;
            opt.thickness_value = 1.0f;
            opt.near_z = 1.0f;
            opt.far_z = INFINITY;
            CHECK(lrt_bvh_build(&thick, &flat, &opt, NULL) == LRT_SUCCESS &&
                      thick.layout.bytes == 2 * thick.layout.node_count * thick.layout.node_bytes,
                  "%s thickness: build, two codes a slot", name);
            lrt_bvh_destroy(&thick);
            EXPECT_BUILD(pair, &opt, LRT_ERROR_THICKNESS_MISMATCH, "a back map for a constant or relative tree");
            for (k = 0; k < 4; ++k) {
                opt.thickness_value = bad_values[k];
                CHECK(lrt_bvh_build(&thick, &flat, &opt, NULL) == LRT_ERROR_INVALID_THICKNESS &&
                          lrt_bvh_memory_size(3, 2, LRT_FORMAT_FLOAT32, &opt, &bytes) == LRT_ERROR_INVALID_THICKNESS,
                      "%s thickness %g: not an error", name, (double)bad_values[k]);
                opt.thickness_value = 1.0f;
                opt.near_z = bad_values[k];
                CHECK(lrt_bvh_build(&thick, &flat, &opt, NULL) == LRT_ERROR_INVALID_THICKNESS,
                      "%s thickness, near plane %g: not an error", name, (double)bad_values[k]);
                opt.near_z = 1.0f;
                opt.far_z = k == 3 ? 0.5f : bad_values[k]; /* 0, -1, NaN, in front of near */
                CHECK(lrt_bvh_build(&thick, &flat, &opt, NULL) == LRT_ERROR_INVALID_THICKNESS,
                      "%s thickness, far plane %g: not an error", name, (double)opt.far_z);
                opt.far_z = INFINITY;
            }
            opt.far_z = 1.0f; /* far on near */
            EXPECT_BUILD(&flat, &opt, LRT_ERROR_INVALID_THICKNESS, "far plane on the near plane");
            opt.far_z = 1.0000001f; /* the constants overflow float */
            opt.thickness_value = model == LRT_THICKNESS_CONSTANT ? 1e30f : 1e38f;
            opt.near_z = model == LRT_THICKNESS_CONSTANT ? 1e-30f : 1.0f;
            EXPECT_BUILD(&flat, &opt, LRT_ERROR_INVALID_THICKNESS, "constants beyond float");
        }
        /* T = 1 at near 1, far infinite: depth 0 is z 1, its back z 2, depth 0.5 */
        memset(&opt, 0, sizeof opt);
        opt.thickness = LRT_THICKNESS_CONSTANT;
        opt.thickness_value = 1.0f;
        opt.near_z = 1.0f;
        opt.far_z = INFINITY;
        CHECK(lrt_bvh_build(&thick, &flat, &opt, NULL) == LRT_SUCCESS, "constant thickness: build");
        CHECK(lrt_trace(&thick, pair, &ray, &hit, 1, 0) == LRT_ERROR_THICKNESS_MISMATCH, "a constant tree traced with a back map");
        CHECK(lrt_bvh_update(&thick, pair, NULL) == LRT_ERROR_THICKNESS_MISMATCH, "a constant tree updated with a back map");
        ray.origin[0] = -1.0f; ray.origin[1] = 0.5f; ray.origin[2] = 0.75f; ray.tmin = 0.0f;
        ray.dir[0] = 1.0f; ray.dir[1] = 0.0f; ray.dir[2] = 0.0f; ray.tmax = 10.0f;
        CHECK(lrt_trace(&thick, &flat, &ray, &hit, 1, 0) == LRT_SUCCESS && hit.kind == LRT_MISS_OFF_SCREEN,
              "under the slab [0, 0.5]: kind %u", hit.kind);
        ray.origin[2] = 0.25f;
        CHECK(lrt_trace(&thick, &flat, &ray, &hit, 1, 0) == LRT_SUCCESS && hit.kind == LRT_HIT && hit.t == 1.0f &&
                  hit.face == LRT_FACE_SIDE,
              "into the slab's side: kind %u t %g face %u", hit.kind, (double)hit.t, hit.face);
        ray.origin[0] = 1.5f; ray.origin[2] = 0.9f;
        ray.dir[0] = 0.0f; ray.dir[2] = -1.0f;
        CHECK(lrt_trace(&thick, &flat, &ray, &hit, 1, 0) == LRT_SUCCESS && hit.kind == LRT_HIT &&
                  fabsf(hit.t - 0.4f) < 1e-6f && hit.face == LRT_FACE_BACK,
              "up into the slab's back: kind %u t %.9g face %u", hit.kind, (double)hit.t, hit.face);
        lrt_bvh_destroy(&thick);
    }
    CHECK(lrt_bvh_build(NULL, &dm, NULL, NULL) == LRT_ERROR_NULL_POINTER, "null bvh");

    a.alloc = fail_alloc; a.free = count_free; a.user = NULL;
    CHECK(lrt_bvh_build(&untouched, &dm, NULL, &a) == LRT_ERROR_OUT_OF_MEMORY, "out of memory");
    CHECK(memcmp(&untouched, sentinel, sizeof sentinel) == 0, "out of memory: the lrt_bvh was written");
    a.alloc = NULL;
    CHECK(lrt_bvh_build(&untouched, &dm, NULL, &a) == LRT_ERROR_NULL_POINTER, "allocator without alloc");

    /* allocator hooks: one allocation, freed by destroy */
    a.alloc = count_alloc; a.free = count_free; a.user = &user;
    g_allocs = g_frees = 0;
    CHECK(lrt_bvh_build(&bvh, &dm, NULL, &a) == LRT_SUCCESS && user == 1 && g_allocs == 1, "allocator hooks used");
    lrt_bvh_destroy(&bvh);
    CHECK(g_frees == 1, "destroy frees through the hooks");
    lrt_bvh_destroy(&bvh); /* twice is harmless */
    CHECK(g_frees == 1, "second destroy frees nothing");

    /* caller-owned memory */
    CHECK(lrt_bvh_memory_size(3, 2, LRT_FORMAT_FLOAT32, NULL, &bytes) == LRT_SUCCESS && bytes == 16 + 15, "memory size 3x2 16-bit: %zu", bytes);
    CHECK(lrt_bvh_memory_size(0, 2, LRT_FORMAT_FLOAT32, NULL, &bytes) == LRT_ERROR_INVALID_SIZE, "memory size of 0 width");
    CHECK(lrt_bvh_memory_size(3, 2, (lrt_format)9, NULL, &bytes) == LRT_ERROR_INVALID_FORMAT, "memory size of bad format");
    CHECK(lrt_bvh_memory_size(3, 2, LRT_FORMAT_FLOAT32, NULL, NULL) == LRT_ERROR_NULL_POINTER, "memory size to NULL");
    {
        unsigned char mem[32];
        CHECK(lrt_bvh_build_in(&untouched, &dm, NULL, mem + 1, 30) == LRT_ERROR_BUFFER_TOO_SMALL, "buffer too small");
        CHECK(memcmp(&untouched, sentinel, sizeof sentinel) == 0, "buffer too small: the lrt_bvh was written");
        CHECK(lrt_bvh_build_in(&untouched, &dm, NULL, NULL, 16) == LRT_ERROR_NULL_POINTER, "null caller memory");
        CHECK(lrt_bvh_build_in(&bvh, &dm, NULL, mem + 1, 31) == LRT_SUCCESS, "build in caller memory (unaligned)");
        CHECK((unsigned char *)bvh.nodes >= mem + 1 && (unsigned char *)bvh.nodes + 16 <= mem + 32, "nodes inside caller memory");
        ray.origin[0] = 1.5f; ray.origin[1] = 0.5f; ray.origin[2] = 0.0f;
        ray.dir[0] = 0; ray.dir[1] = 0; ray.dir[2] = 1;
        ray.tmin = 0; ray.tmax = 1;
        CHECK(lrt_trace(&bvh, &dm, &ray, &hit, 1, 0) == LRT_SUCCESS && hit.kind == LRT_HIT && hit.t == 0.5f,
              "trace in caller memory");
        lrt_bvh_destroy(&bvh); /* does not free caller memory (ASan would see it) */
    }

    /* update and trace arguments */
    CHECK(lrt_bvh_build(&bvh, &dm, NULL, NULL) == LRT_SUCCESS, "build");
    CHECK(lrt_bvh_update(NULL, &dm, NULL) == LRT_ERROR_NULL_POINTER, "update null bvh");
    CHECK(lrt_bvh_update(&bvh, NULL, NULL) == LRT_ERROR_NULL_POINTER, "update null depth");
    bad = dm; bad.width = 4; bad.row_stride = 16;
    CHECK(lrt_bvh_update(&bvh, &bad, NULL) == LRT_ERROR_SIZE_MISMATCH, "update with another size");
    rect.x = 2; rect.y = 0; rect.width = 2; rect.height = 1;
    CHECK(lrt_bvh_update(&bvh, &dm, &rect) == LRT_ERROR_INVALID_RECT, "rect past the right edge");
    rect.x = 0; rect.y = 1; rect.width = 1; rect.height = 0xffffffffu;
    CHECK(lrt_bvh_update(&bvh, &dm, &rect) == LRT_ERROR_INVALID_RECT, "rect height wrapping around");
    rect.x = 3; rect.y = 2; rect.width = 0; rect.height = 0;
    CHECK(lrt_bvh_update(&bvh, &dm, &rect) == LRT_SUCCESS, "empty rect at the corner");
    memset(&other, 0, sizeof other);
    CHECK(lrt_trace(&other, &dm, &ray, &hit, 1, 0) == LRT_ERROR_INVALID_BVH, "trace an unbuilt bvh");
    CHECK(lrt_bvh_update(&other, &dm, NULL) == LRT_ERROR_INVALID_BVH, "update an unbuilt bvh");
    CHECK(lrt_trace(NULL, &dm, &ray, &hit, 1, 0) == LRT_ERROR_NULL_POINTER, "trace null bvh");
    CHECK(lrt_trace(&bvh, &dm, NULL, &hit, 1, 0) == LRT_ERROR_NULL_POINTER, "trace null rays");
    CHECK(lrt_trace(&bvh, &dm, &ray, NULL, 1, 0) == LRT_ERROR_NULL_POINTER, "trace null hits");
    CHECK(lrt_trace(&bvh, &dm, NULL, NULL, 0, 0) == LRT_SUCCESS, "trace no rays");
    CHECK(lrt_trace(&bvh, &dm, &ray, &hit, 1, 0x10000) == LRT_ERROR_INVALID_OPTION, "trace unknown flag");
    CHECK(lrt_trace(&bvh, &dm, &ray, &hit, 1, 0x80000000u) == LRT_ERROR_INVALID_OPTION, "trace unknown flag (bit 31)");
    CHECK(lrt_trace(&bvh, &dm, &ray, &hit, 1, LRT_TRACE_BUDGET(LRT_TRACE_BUDGET_MAX + 1u)) == LRT_ERROR_INVALID_OPTION,
          "trace budget past LRT_TRACE_BUDGET_MAX");
    CHECK(lrt_trace(&bvh, &dm, &ray, &hit, 1, LRT_TRACE_BUDGET(LRT_TRACE_BUDGET_MAX)) == LRT_SUCCESS, "trace budget max");
    CHECK(lrt_trace(&bvh, &dm, &ray, &hit, 1, LRT_TRACE_FINISH(3)) == LRT_ERROR_INVALID_OPTION, "trace finish without a budget");
    CHECK(lrt_trace(&bvh, &dm, &ray, &hit, 1, LRT_TRACE_BUDGET(4) | LRT_TRACE_FINISH(8)) == LRT_ERROR_INVALID_OPTION,
          "trace finish of 2^8 samples");
    CHECK(lrt_trace(&bvh, &dm, &ray, &hit, 1, LRT_TRACE_BUDGET(4) | 0x100000u) == LRT_ERROR_INVALID_OPTION,
          "trace flag past the finish's bits");
    CHECK(lrt_trace(&bvh, &dm, &ray, &hit, 1, LRT_TRACE_BUDGET(4) | LRT_TRACE_FINISH(7)) == LRT_SUCCESS,
          "trace finish of 2^7 samples");
    CHECK(lrt_trace(&bvh, &dm, &ray, &hit, (size_t)LINEAR_RT_MAX_RAYS_PER_CALL + 1, 0) == LRT_ERROR_TOO_MANY_RAYS,
          "too many rays");
    CHECK(lrt_trace_range(&bvh, &dm, &ray, &hit, 2, 1, 0) == LRT_ERROR_TOO_MANY_RAYS, "range end before first");
    CHECK(lrt_layout_compute(3, 2, 8, NULL) == LRT_ERROR_NULL_POINTER, "layout to NULL");
    CHECK(lrt_layout_compute(16385, 2, 8, &bvh.layout) == LRT_ERROR_INVALID_SIZE, "layout oversized");
    lrt_bvh_destroy(&bvh);
    CHECK(strcmp(lrt_result_string(LRT_ERROR_INVALID_RECT), "unknown result code") != 0 &&
              strcmp(lrt_result_string((lrt_result)999), "unknown result code") == 0,
          "result strings");
#undef EXPECT_BUILD
}

/* ---- 6. ranges: slices of a batch give what the whole batch gives ----------------- */
static void test_ranges(void)
{
    test_map m;
    lrt_bvh bvh = {0};
    enum { N = 3000 };
    static lrt_ray rays[N];
    static lrt_hit whole[N], parts[N];
    size_t i;
    make_map(&m, 90, 70, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 0);
    lrt_bvh_build(&bvh, &m.depth, NULL, NULL);
    for (i = 0; i < N; ++i) rays[i] = make_ray(&m, (int)(i % RAY_KIND_COUNT));
    lrt_trace(&bvh, &m.depth, rays, whole, N, 0);
    CHECK(lrt_trace_range(&bvh, &m.depth, rays, parts, 0, 1234, 0) == LRT_SUCCESS &&
              lrt_trace_range(&bvh, &m.depth, rays, parts, 1234, N, 0) == LRT_SUCCESS,
          "trace_range");
    CHECK(memcmp(whole, parts, sizeof whole) == 0, "two ranges differ from one batch");
    lrt_bvh_destroy(&bvh);
    free_map(&m);
}

/* ---- 6. the planes of a camera, for constant and relative thickness ------------- */
static void test_camera_planes(void)
{
    /* the float matrix holds far only to about 1.2e-7 * far / near (its z row is -1 - near / far) */
    static const float planes[][2] = {{0.1f, 100.0f}, {1.0f, 3.0f}, {0.05f, 500.0f}, {2.0f, 2.5f}};
    float proj[16], n = -1.0f, f = -1.0f;
    lrt_camera cam;
    size_t k;
    uint32_t flags;
    for (k = 0; k < sizeof planes / sizeof planes[0]; ++k) {
        for (flags = 0; flags <= LRT_DEPTH_REVERSED_Z; flags += LRT_DEPTH_REVERSED_Z) {
            lrt_perspective(proj, 1.0f, 1.5f, planes[k][0], planes[k][1], flags);
            CHECK(lrt_camera_init(&cam, proj, 64, 48, flags) == LRT_SUCCESS && lrt_camera_planes(&cam, &n, &f) &&
                      fabsf(n - planes[k][0]) <= 1e-5f * planes[k][0] && fabsf(f - planes[k][1]) <= (2e-7f * planes[k][1] / planes[k][0] + 1e-6f) * planes[k][1],
                  "camera planes %g..%g%s: got %g..%g", (double)planes[k][0], (double)planes[k][1],
                  flags ? " reversed" : "", (double)n, (double)f);
        }
    }
    /* an infinite far plane, written by hand: depth (-zv - n) / -zv, reversed n / -zv */
    for (flags = 0; flags <= LRT_DEPTH_REVERSED_Z; flags += LRT_DEPTH_REVERSED_Z) {
        memset(proj, 0, sizeof proj);
        proj[0] = 1.0f;
        proj[5] = -1.0f;
        proj[11] = -1.0f;
        proj[10] = flags ? 0.0f : -1.0f;
        proj[14] = flags ? 0.25f : -0.25f;
        CHECK(lrt_camera_init(&cam, proj, 8, 8, flags) == LRT_SUCCESS && lrt_camera_planes(&cam, &n, &f) && n == 0.25f &&
                  f == INFINITY,
              "an infinite far plane%s: got %g..%g", flags ? " reversed" : "", (double)n, (double)f);
    }
    /* not perspective: an orthographic camera; and null pointers */
    memset(proj, 0, sizeof proj);
    proj[0] = proj[5] = proj[15] = 1.0f;
    proj[10] = -0.01f;
    n = f = 7.0f;
    CHECK(lrt_camera_init(&cam, proj, 8, 8, 0) == LRT_SUCCESS && !lrt_camera_planes(&cam, &n, &f) && n == 7.0f && f == 7.0f,
          "an orthographic camera has no planes for thickness");
    CHECK(!lrt_camera_planes(NULL, &n, &f) && !lrt_camera_planes(&cam, NULL, &f) && !lrt_camera_planes(&cam, &n, NULL),
          "camera planes: null pointers");
}

/* ---- 1d. a step budget (LRT_TRACE_BUDGET) ---------------------------------------- */
/* A budget's finish (LRT_TRACE_FINISH(finish)) against the budget alone
   (budgeted): a ray the budget did not stop gets the same answer bit for
   bit, one it stopped the same budget miss or an estimate at or past the
   budget miss's t (proven free up to there), on the map, with a face, whose
   point lies in its texel's column and at or below its depth (within what
   a float t tells of the point). Counts the estimates and those on the exact hit's texel. */
static void finish_check(const test_map *m, const lrt_ray *rays, const lrt_hit *exact, const lrt_hit *budgeted, size_t n,
                         const lrt_bvh *bvh, uint32_t budget, uint32_t finish, size_t *estimated, size_t *on_exact)
{
    lrt_hit *fin = (lrt_hit *)malloc(sizeof(lrt_hit) * n);
    size_t i, changed = 0, bad = 0;
    const lrt_depth *dm = test_map_depth(m);
    CHECK(lrt_trace(bvh, dm, rays, fin, n, LRT_TRACE_BUDGET(budget) | LRT_TRACE_FINISH(finish)) == LRT_SUCCESS,
          "finish %u at budget %u: trace", finish, budget);
    for (i = 0; i < n; ++i) {
        const lrt_hit *g = &fin[i], *b = &budgeted[i];
        const lrt_ray *r = &rays[i];
        double p[3], slack[3];
        int k;
        if (b->kind != LRT_MISS_BUDGET || g->kind == LRT_MISS_BUDGET) {
            changed += memcmp(g, b, sizeof *g) != 0;
            continue;
        }
        ++*estimated;
        *on_exact += exact[i].kind == LRT_HIT && exact[i].x == g->x && exact[i].y == g->y;
        for (k = 0; k < 3; ++k) { /* the point, and what float t and a restart's origin can tell of it */
            p[k] = (double)r->origin[k] + (double)g->t * r->dir[k];
            slack[k] = 1e-4 * (1.0 + fabs(p[k])) + 4.0 * FLT_EPSILON * (fabs(r->origin[k]) + fabs(g->t * r->dir[k]));
        }
        bad += g->kind != LRT_HIT_ESTIMATE || !(g->t >= b->t && g->t <= r->tmax) || g->x >= dm->width ||
               g->y >= dm->height || g->face < LRT_FACE_TOP || g->face > LRT_FACE_BACK ||
               !(p[0] >= (double)g->x - slack[0] && p[0] <= (double)g->x + 1.0 + slack[0]) ||
               !(p[1] >= (double)g->y - slack[1] && p[1] <= (double)g->y + 1.0 + slack[1]) ||
               !(p[2] >= (double)depth_at(m, (int)g->x, (int)g->y) - slack[2]);
    }
    CHECK(changed == 0, "finish %u at budget %u: %zu answers the budget alone gives otherwise", finish, budget, changed);
    CHECK(bad == 0, "finish %u at budget %u: %zu estimates before the free t, off the map or outside their texel", finish,
          budget, bad);
    free(fin);
}

/* A ladder of budgets on the demo's kinds of rays: every answer that is not
   a budget miss is the exact one bit for bit; a budget miss has t in
   [tmin, tmax], never past the exact hit (its segment proven free up to
   there), x, y 0 and no face; a budget no ray needs changes nothing. */
static void test_budget(void)
{
    static const int shapes[] = {SHAPE_SCENE, SHAPE_POLES, SHAPE_NOISE, SHAPE_TERRACES};
    static const uint32_t ladder[] = {1, 2, 3, 4, 6, 8, 12, 16, 32, 64}, finishes[] = {0, 3, 5};
    size_t c, i, b, f, estimated = 0, on_exact = 0;
    for (c = 0; c < 8; ++c) {
        test_map m;
        lrt_bvh bvh = {0};
        lrt_build_options opt;
        const size_t n = 3000;
        lrt_ray *rays = (lrt_ray *)malloc(sizeof(lrt_ray) * n);
        lrt_hit *exact = (lrt_hit *)malloc(sizeof(lrt_hit) * n), *hits = (lrt_hit *)malloc(sizeof(lrt_hit) * n);
        size_t stopped_at_1 = 0, stopped_at_64 = 0;
        make_map(&m, 100 + (int)c * 17, 60 + (int)c * 9, shapes[c % 4], (lrt_format)(1 + c % 3), (int)(c & 1), 0);
        if (c >= 6) add_model(&m, LRT_THICKNESS_CONSTANT, 0.5f, 0.1f, 100.0f);
        opt = m.model;
        opt.node_bits = (c & 2) ? 8u : 16u;
        CHECK(lrt_bvh_build(&bvh, test_map_depth(&m), &opt, NULL) == LRT_SUCCESS, "budget %zu: build", c);
        for (i = 0; i < n; ++i) rays[i] = make_ray(&m, (int)(i % RAY_KIND_COUNT));
        CHECK(lrt_trace(&bvh, test_map_depth(&m), rays, exact, n, 0) == LRT_SUCCESS, "budget %zu: exact trace", c);
        for (b = 0; b < sizeof ladder / sizeof ladder[0]; ++b) {
            size_t not_exact = 0, bad = 0, stopped = 0;
            CHECK(lrt_trace(&bvh, test_map_depth(&m), rays, hits, n, LRT_TRACE_BUDGET(ladder[b])) == LRT_SUCCESS,
                  "budget %zu: trace at %u", c, ladder[b]);
            for (i = 0; i < n; ++i) {
                const lrt_hit *g = &hits[i];
                if (g->kind != LRT_MISS_BUDGET) {
                    not_exact += memcmp(g, &exact[i], sizeof *g) != 0;
                    continue;
                }
                ++stopped;
                bad += !(g->t >= rays[i].tmin && g->t <= rays[i].tmax) || g->x || g->y || g->face != LRT_FACE_NONE ||
                       (exact[i].kind == LRT_HIT && g->t > exact[i].t);
            }
            CHECK(not_exact == 0, "budget %zu at %u: %zu answers that are not budget misses differ from the exact walk", c,
                  ladder[b], not_exact);
            CHECK(bad == 0, "budget %zu at %u: %zu budget misses with a bad t, texel or face", c, ladder[b], bad);
            if (ladder[b] == 1) stopped_at_1 = stopped;
            if (ladder[b] == 64) stopped_at_64 = stopped;
            for (f = 0; f < 3; ++f) finish_check(&m, rays, exact, hits, n, &bvh, ladder[b], finishes[f], &estimated, &on_exact);
        }
        CHECK(stopped_at_1 > stopped_at_64, "budget %zu: %zu rays stopped at 1, %zu at 64", c, stopped_at_1, stopped_at_64);
        if (c == 7) {
            CHECK(estimated > 1000 && on_exact * 4 > estimated,
                  "finish: %zu estimates, %zu of them on the exact hit's texel", estimated, on_exact);
            printf("finish: %zu estimates, %zu of them on the exact hit's texel\n", estimated, on_exact);
        }
        CHECK(lrt_trace(&bvh, test_map_depth(&m), rays, hits, n, LRT_TRACE_BUDGET(LRT_TRACE_BUDGET_MAX)) == LRT_SUCCESS &&
                  memcmp(hits, exact, sizeof(lrt_hit) * n) == 0,
              "budget %zu: the largest budget changes answers", c);
        lrt_bvh_destroy(&bvh);
        free_map(&m);
        free(rays);
        free(exact);
        free(hits);
    }
}

int main(int argc, char **argv)
{
    check_select(argc, argv);
    printf("walk: %s\n", lrt_cpu_path());
    RUN_TEST(test_named_cases);
    RUN_TEST(test_found_cases);
    RUN_TEST(test_huge_directions);
    RUN_TEST(test_layout);
    RUN_TEST(test_compact_codes);
    RUN_TEST(test_compact_boundaries);
    RUN_TEST(test_update);
    RUN_TEST(test_model_back_codes);
    RUN_TEST(test_bad_arguments);
    RUN_TEST(test_ranges);
    RUN_TEST(test_differential);
    RUN_TEST(test_budget);
    RUN_TEST(test_thickness_grazing);
    RUN_TEST(test_thickness_found);
    RUN_TEST(test_camera_planes);
    return check_summary();
}
