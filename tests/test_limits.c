/* tests/test_limits.c - the size limits of linear_rt.h's CPU path.

   (a) every size from 1x1 to LINEAR_RT_MAX_DIM x LINEAR_RT_MAX_DIM that
       matters (1xN, Nx1, N-1, N, powers of two and odd ones): the level
       sizes, offsets, node counts and byte counts of lrt_layout_compute and
       lrt_bvh_memory_size against an independent computation in uint64_t
       (so a size_t truncation on a 32-bit build shows), and 16384^2 against
       constants worked out by hand;
   (b) sizes past the limit and byte spans past PTRDIFF_MAX: the documented
       result code, decided before any texel is read (the data pointer is a
       one-texel dummy) and at the exact boundary (largest legal stride:
       success, one byte more: LRT_ERROR_SIZE_OVERFLOW);
   (c) a real 8192x8192 float map: build, a dirty-rect update equal to a
       fresh build byte for byte, and a sample of rays (primary rays of whole
       rows and columns, rays of every kind of tests/support/rays.h) judged by the
       exact reference of tests/support/reference.h; real 1x16384 and 16384x1 maps
       judged the same way; a real 16384x16384 8-bit map (primary rays of
       its edges judged by docs/MODEL.md's rule: own texel, t = d);
   (d) ray counts: more than LINEAR_RT_MAX_RAYS_PER_CALL, SIZE_MAX and
       first > end give LRT_ERROR_TOO_MANY_RAYS before any ray is read or
       hit written (a 4-ray array with guards, a count of 2^30 + 1).
   Built as a 64-bit and, where gcc-multilib is installed, a 32-bit (-m32)
   program by tests/hardening.mk. The real 8192^2 and 16384^2 maps take
   about 1.1 GiB at the peak and a few seconds; LRT_TEST_LIMITS=quick skips
   them (valgrind runs it so: the same code paths, 60 s less). Ends with
   "N passed, M failed". */
#define LINEAR_RT_IMPLEMENTATION
#include "../linear_rt.h"
#include "support/reference.h"
#include "../examples/scene.h"
#include "support/rays.h"
#include "support/check.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <stdint.h>
#include <math.h>
#include <time.h>

/* ---- compile-time: the largest byte counts fit this size_t --------------------- */
#define LIMITS_STATIC_ASSERT(name, cond) typedef char limits_assert_##name[(cond) ? 1 : -1]
/* 16384^2 16-bit nodes: 38347929 slots of 16 bytes (worked out below) */
LIMITS_STATIC_ASSERT(nodes_fit_size_t, (uint64_t)38347929u * 16u <= (uint64_t)SIZE_MAX);
/* the largest float map, packed: 1 GiB, below PTRDIFF_MAX on 32-bit too */
LIMITS_STATIC_ASSERT(map_fits_ptrdiff,
                     (uint64_t)LINEAR_RT_MAX_DIM * LINEAR_RT_MAX_DIM * 4u <= (uint64_t)PTRDIFF_MAX);
/* the documented largest side (a texel coordinate in 14 bits) */
LIMITS_STATIC_ASSERT(dim_fits_14_bits, LINEAR_RT_MAX_DIM <= 16384u);
/* the ray limit is a count a size_t and a uint32_t both hold */
LIMITS_STATIC_ASSERT(ray_limit_fits, (uint64_t)LINEAR_RT_MAX_RAYS_PER_CALL + 1u <= (uint64_t)SIZE_MAX &&
                                         (uint64_t)LINEAR_RT_MAX_RAYS_PER_CALL + 1u <= 0xffffffffu);

static double now_s(void) { return (double)clock() / CLOCKS_PER_SEC; }

/* ---- (a) layout arithmetic against an independent computation ------------------- */
typedef struct want_layout {
    uint32_t level_count;
    uint64_t w[LINEAR_RT_MAX_LEVELS + 2], h[LINEAR_RT_MAX_LEVELS + 2];
    uint64_t offset[LINEAR_RT_MAX_LEVELS + 2], count[LINEAR_RT_MAX_LEVELS + 2];
    uint64_t node_count, bytes;
} want_layout;

/* Level k groups 4x2 into k+1 when k is even, 2x4 when odd, up to the first
   1x1 level above the texels; level k (1..n) has 8 slots per node of level
   k+1 (the root: 1); a slot is 16 bytes (8 children of 16 bits), but
   with 8 bits a level-1 slot is 6 (a word of steps and a 16-bit scale)
   where the tree has two levels or more. */
static int want_layout_of(uint64_t width, uint64_t height, uint64_t bits, want_layout *o)
{
    uint32_t k = 0, lv;
    memset(o, 0, sizeof *o);
    o->w[0] = width;
    o->h[0] = height;
    do {
        uint64_t bw = (k & 1) ? 2 : 4, bh = (k & 1) ? 4 : 2;
        if (k + 1 > LINEAR_RT_MAX_LEVELS) return 0;
        o->w[k + 1] = (o->w[k] + bw - 1) / bw;
        o->h[k + 1] = (o->h[k] + bh - 1) / bh;
        ++k;
    } while (o->w[k] != 1 || o->h[k] != 1);
    o->level_count = k;
    for (lv = 1; lv <= k; ++lv) {
        o->offset[lv] = o->node_count;
        o->count[lv] = lv == k ? 1 : 8 * o->w[lv + 1] * o->h[lv + 1];
        o->node_count += o->count[lv];
    }
    o->bytes = bits == 8 && k >= 2 ? o->count[1] * 6 + (o->node_count - o->count[1]) * 16 : o->node_count * 16;
    return 1;
}

static int same_layout(const lrt_layout *L, const want_layout *want, uint32_t bits)
{
    uint32_t lv;
    int ok = L->level_count == want->level_count && L->node_bits == bits && L->node_bytes == 16 &&
             (uint64_t)L->node_count == want->node_count && (uint64_t)L->bytes == want->bytes;
    for (lv = 1; ok && lv <= L->level_count; ++lv)
        ok = L->levels[lv].width == want->w[lv] && L->levels[lv].height == want->h[lv] &&
             (uint64_t)L->levels[lv].offset == want->offset[lv] && (uint64_t)L->levels[lv].count == want->count[lv];
    return ok;
}

static void test_layout_sizes(void)
{
    static const uint32_t dims[] = {1, 2, 3, 4, 5, 7, 8, 9, 31, 33, 255, 1000, 1023, 1025, 4095, 4097,
                                    8191, 8192, 8193, 12345, 16383, LINEAR_RT_MAX_DIM};
    const size_t n = sizeof dims / sizeof dims[0];
    size_t a, b, bad = 0, checked = 0;
    uint32_t bits;
    for (a = 0; a < n; ++a)
        for (b = 0; b < n; ++b)
            for (bits = 8; bits <= 16; bits += 8) {
                lrt_layout L;
                want_layout want;
                size_t mem = 0;
                lrt_format f;
                lrt_result r = lrt_layout_compute(dims[a], dims[b], bits, &L);
                ++checked;
                if (r != LRT_SUCCESS || !want_layout_of(dims[a], dims[b], bits, &want) || !same_layout(&L, &want, bits)) {
                    if (bad++ < 5)
                        printf("FAIL layout %ux%u %u-bit: %s, %zu bytes\n", dims[a], dims[b], bits,
                               lrt_result_string(r), r == LRT_SUCCESS ? L.bytes : 0);
                    continue;
                }
                /* memory size: the nodes + 15 alignment bytes, auto bits by format */
                for (f = LRT_FORMAT_UNORM8; f <= LRT_FORMAT_FLOAT32; f = (lrt_format)(f + 1)) {
                    lrt_build_options opt;
                    uint64_t auto_bits = f == LRT_FORMAT_UNORM8 ? 8 : 16;
                    want_layout wa;
                    memset(&opt, 0, sizeof opt);
                    opt.node_bits = bits;
                    if (lrt_bvh_memory_size(dims[a], dims[b], f, &opt, &mem) != LRT_SUCCESS ||
                        (uint64_t)mem != want.bytes + 15u)
                        if (bad++ < 5) printf("FAIL memory size %ux%u %u-bit format %d\n", dims[a], dims[b], bits, (int)f);
                    want_layout_of(dims[a], dims[b], auto_bits, &wa);
                    if (lrt_bvh_memory_size(dims[a], dims[b], f, NULL, &mem) != LRT_SUCCESS || (uint64_t)mem != wa.bytes + 15u)
                        if (bad++ < 5) printf("FAIL memory size %ux%u auto bits format %d\n", dims[a], dims[b], (int)f);
                }
            }
    CHECK(bad == 0, "%zu of %zu layouts/memory sizes differ from the independent computation", bad, checked);

    { /* 16384^2 by hand: levels 4096x8192, 2048^2, 512x1024, 256^2, 64x128,
         32^2, 8x16, 4x4, 1x2, 1x1 */
        static const uint64_t counts[11] = {0, 33554432u, 4194304u, 524288u, 65536u, 8192u, 1024u, 128u, 16u, 8u, 1u};
        lrt_layout L;
        uint32_t lv;
        int ok;
        CHECK(lrt_layout_compute(16384, 16384, 16, &L) == LRT_SUCCESS, "layout 16384^2");
        ok = L.level_count == 10 && (uint64_t)L.node_count == 38347929u && (uint64_t)L.bytes == 613566864u;
        for (lv = 1; ok && lv <= 10; ++lv) ok = (uint64_t)L.levels[lv].count == counts[lv];
        CHECK(ok, "16384^2 16-bit: %u levels, %zu slots, %zu bytes (want 10, 38347929, 613566864)", L.level_count,
              L.node_count, L.bytes);
        CHECK(lrt_layout_compute(16384, 16384, 8, &L) == LRT_SUCCESS && (uint64_t)L.bytes == 278022544u,
              "16384^2 8-bit: %zu bytes (want 278022544: 33554432 level-1 nodes of 6 bytes, 4793497 of 16)", L.bytes);
        /* 1 x 16384: 1x8192, 1x2048, 1x1024, 1x256, 1x128, 1x32, 1x16, 1x4, 1x2, 1x1 */
        CHECK(lrt_layout_compute(1, 16384, 8, &L) == LRT_SUCCESS && L.level_count == 10 &&
                  L.levels[1].width == 1 && L.levels[1].height == 8192,
              "1x16384: %u levels, level 1 %ux%u", L.level_count, L.levels[1].width, L.levels[1].height);
        CHECK(lrt_layout_compute(16384, 1, 8, &L) == LRT_SUCCESS && L.levels[1].width == 4096 && L.levels[1].height == 1,
              "16384x1: level 1 %ux%u", L.levels[1].width, L.levels[1].height);
    }
    { /* the last node of every level of 16384^2 maps inside its level */
        lrt_layout L;
        uint32_t lv;
        int ok = 1;
        lrt_layout_compute(16384, 16384, 16, &L);
        for (lv = 1; lv <= L.level_count; ++lv) {
            size_t k = lrt_layout_node_index(&L, lv, L.levels[lv].width - 1, L.levels[lv].height - 1);
            ok &= k < L.levels[lv].count;
        }
        CHECK(ok, "16384^2: the last node of a level maps outside it");
    }
}

/* ---- (b) impossible sizes and spans --------------------------------------------- */
static void test_impossible_sizes(void)
{
    static const uint32_t bad_dims[][2] = {{LINEAR_RT_MAX_DIM + 1, 1}, {1, LINEAR_RT_MAX_DIM + 1},
                                           {LINEAR_RT_MAX_DIM + 1, LINEAR_RT_MAX_DIM + 1}, {0, 1}, {1, 0}, {0, 0},
                                           {0xffffffffu, 0xffffffffu}, {0x80000000u, 2}, {65536, 65536}};
    float texel = 0.5f;
    lrt_bvh bvh = {0}, small = {0};
    lrt_depth d;
    lrt_layout L;
    size_t i, bytes;
    unsigned char sentinel[sizeof(lrt_bvh)], mem[64];
    memset(&bvh, 0xab, sizeof bvh);
    memcpy(sentinel, &bvh, sizeof sentinel);
    for (i = 0; i < sizeof bad_dims / sizeof bad_dims[0]; ++i) {
        const uint32_t w = bad_dims[i][0], h = bad_dims[i][1];
        lrt_result r1, r2, r3, r4;
        memset(&d, 0, sizeof d);
        d.data = &texel; /* one texel: nothing may be read past it */
        d.width = w;
        d.height = h;
        d.format = LRT_FORMAT_FLOAT32;
        r1 = lrt_layout_compute(w, h, 16, &L);
        r2 = lrt_bvh_memory_size(w, h, LRT_FORMAT_FLOAT32, NULL, &bytes);
        r3 = lrt_bvh_build(&bvh, &d, NULL, NULL);
        r4 = lrt_bvh_build_in(&bvh, &d, NULL, mem, sizeof mem);
        CHECK(r1 == LRT_ERROR_INVALID_SIZE && r2 == LRT_ERROR_INVALID_SIZE && r3 == LRT_ERROR_INVALID_SIZE &&
                  r4 == LRT_ERROR_INVALID_SIZE,
              "%ux%u: layout %s, memory size %s, build %s, build_in %s", w, h, lrt_result_string(r1),
              lrt_result_string(r2), lrt_result_string(r3), lrt_result_string(r4));
        CHECK(memcmp(&bvh, sentinel, sizeof sentinel) == 0, "%ux%u: the lrt_bvh was written", w, h);
    }

    /* the byte span stride*(H-1) + row <= PTRDIFF_MAX, at its exact boundary:
       checked by a zero-ray trace, which validates the depth and reads nothing */
    {
        static float column[LINEAR_RT_MAX_DIM];
        const size_t row = 4, rows = LINEAR_RT_MAX_DIM;
        const size_t largest = ((size_t)PTRDIFF_MAX - row) / (rows - 1);
        lrt_depth big;
        lrt_result r;
        memset(&d, 0, sizeof d);
        for (i = 0; i < rows; ++i) column[i] = 0.5f;
        d.data = column;
        d.width = 1;
        d.height = (uint32_t)rows;
        d.format = LRT_FORMAT_FLOAT32;
        CHECK(lrt_bvh_build(&small, &d, NULL, NULL) == LRT_SUCCESS, "build 1x16384");
        big = d;
        big.row_stride = largest;
        r = lrt_trace(&small, &big, NULL, NULL, 0, 0);
        CHECK(r == LRT_SUCCESS, "largest legal stride %zu: %s", largest, lrt_result_string(r));
        big.row_stride = largest + 1;
        r = lrt_trace(&small, &big, NULL, NULL, 0, 0);
        CHECK(r == LRT_ERROR_SIZE_OVERFLOW, "stride %zu past PTRDIFF_MAX: %s", largest + 1, lrt_result_string(r));
        r = lrt_bvh_update(&small, &big, NULL);
        CHECK(r == LRT_ERROR_SIZE_OVERFLOW, "update with a span past PTRDIFF_MAX: %s", lrt_result_string(r));
        big.row_stride = SIZE_MAX;
        r = lrt_bvh_build(&bvh, &big, NULL, NULL);
        CHECK(r == LRT_ERROR_SIZE_OVERFLOW, "build with stride SIZE_MAX: %s", lrt_result_string(r));
        CHECK(memcmp(&bvh, sentinel, sizeof sentinel) == 0, "stride SIZE_MAX: the lrt_bvh was written");
        big.height = 2; /* a 2-row map: the span is stride + row */
        big.row_stride = (size_t)PTRDIFF_MAX - row + 1;
        CHECK(lrt_bvh_build(&bvh, &big, NULL, NULL) == LRT_ERROR_SIZE_OVERFLOW, "2 rows: span PTRDIFF_MAX + 1");
        lrt_bvh_destroy(&small);
    }
    { /* a dirty rect whose end wraps around uint32_t */
        float t4[4] = {0.5f, 0.5f, 0.5f, 0.5f};
        lrt_rect rect;
        d = packed_depth(t4, 4, 1, LRT_FORMAT_FLOAT32);
        lrt_bvh_build(&small, &d, NULL, NULL);
        rect.x = 1; rect.y = 0; rect.width = 0xffffffffu; rect.height = 1;
        CHECK(lrt_bvh_update(&small, &d, &rect) == LRT_ERROR_INVALID_RECT, "rect x + width wraps");
        rect.x = 0xffffffffu; rect.width = 2;
        CHECK(lrt_bvh_update(&small, &d, &rect) == LRT_ERROR_INVALID_RECT, "rect x = 2^32-1");
        rect.x = 3; rect.width = 1; rect.y = 0; rect.height = 1;
        CHECK(lrt_bvh_update(&small, &d, &rect) == LRT_SUCCESS, "rect on the last texel");
        lrt_bvh_destroy(&small);
    }
}

/* ---- (c) real big maps ------------------------------------------------------------ */
static void judge_rays(const char *what, const lrt_bvh *bvh, const test_map *m, const lrt_ray *rays, const int *kinds,
                       size_t n)
{
    lrt_hit *hits = (lrt_hit *)malloc(sizeof(lrt_hit) * (n ? n : 1));
    size_t i, bad = 0;
    lrt_result r;
    if (!hits) {
        CHECK(0, "%s: out of memory", what);
        return;
    }
    r = lrt_trace(bvh, &m->depth, rays, hits, n, 0);
    CHECK(r == LRT_SUCCESS, "%s: trace returned %s", what, lrt_result_string(r));
    for (i = 0; i < n && r == LRT_SUCCESS; ++i) {
        ref_ray q = ref_ray_of(&rays[i]);
        ref_answer a = to_answer(&hits[i]);
        char why[256];
        if (!ref_check(&m->ref, &q, &a, 0, why, sizeof why)) {
            if (bad++ < 5)
                printf("FAIL %s ray %zu (%s) o=(%.9g %.9g %.9g) v=(%.9g %.9g %.9g) t=[%.9g %.9g]: %s\n", what, i,
                       kinds ? ray_names[kinds[i]] : "primary", q.o[0], q.o[1], q.o[2], q.v[0], q.v[1], q.v[2], q.tmin,
                       q.tmax, why);
        }
    }
    CHECK(bad == 0, "%s: %zu of %zu rays disagree with the reference", what, bad, n);
    free(hits);
}

static lrt_ray primary_ray(uint32_t i, uint32_t j)
{
    lrt_ray r;
    memset(&r, 0, sizeof r);
    r.origin[0] = (float)i + 0.5f;
    r.origin[1] = (float)j + 0.5f;
    r.dir[2] = 1.0f;
    r.tmax = 1.0f;
    return r;
}

/* Primary rays of the given rows and columns, then n_random rays of every
   kind of tests/support/rays.h, all judged by the reference. */
static void trace_sample(const char *what, const lrt_bvh *bvh, const test_map *m, const uint32_t *rows, size_t nrows,
                         const uint32_t *cols, size_t ncols, size_t n_random)
{
    const uint32_t w = m->depth.width, h = m->depth.height;
    size_t n = nrows * w + ncols * h + n_random, k = 0, i;
    lrt_ray *rays = (lrt_ray *)malloc(sizeof(lrt_ray) * n);
    int *kinds = (int *)calloc(n, sizeof(int)); /* RAY_PRIMARY is 0 */
    uint32_t x;
    if (!rays || !kinds) {
        CHECK(0, "%s: out of memory", what);
        free(rays);
        free(kinds);
        return;
    }
    for (i = 0; i < nrows; ++i)
        for (x = 0; x < w; ++x) rays[k++] = primary_ray(x, rows[i]);
    for (i = 0; i < ncols; ++i)
        for (x = 0; x < h; ++x) rays[k++] = primary_ray(cols[i], x);
    for (i = 0; i < n_random; ++i) {
        kinds[k] = (int)(i % RAY_KIND_COUNT);
        rays[k] = make_ray(m, kinds[k]);
        ++k;
    }
    judge_rays(what, bvh, m, rays, kinds, n);
    free(rays);
    free(kinds);
}

static void test_8192(void)
{
    const int n = 8192;
    const uint32_t rows[] = {0, 1, 4095, 4096, 8190, 8191}, cols[] = {0, 4097, 8191};
    test_map m;
    lrt_bvh bvh = {0}, fresh = {0};
    lrt_rect rect;
    double t0 = now_s(), t_build, t_update;
    unsigned char *texels;
    uint32_t i, j;
    lrt_result r;
    make_map(&m, n, n, SHAPE_TERRACES, LRT_FORMAT_FLOAT32, 0, 0);
    t0 = now_s();
    r = lrt_bvh_build(&bvh, &m.depth, NULL, NULL);
    t_build = now_s() - t0;
    CHECK(r == LRT_SUCCESS, "8192^2 build: %s", lrt_result_string(r));
    if (r != LRT_SUCCESS) {
        free_map(&m);
        return;
    }
    CHECK(bvh.layout.node_bits == 16 && bvh.layout.bytes > (size_t)n * n * 2, "8192^2: %u-bit nodes, %zu bytes",
          bvh.layout.node_bits, bvh.layout.bytes);
    trace_sample("8192^2 built", &bvh, &m, rows, 2, cols, 1, 6500);

    /* a near block across the right edge and a far hole at the bottom: the
       dirty rect covers both, the update must equal a fresh build */
    texels = (unsigned char *)m.storage + 1; /* make_map's data, unaligned by 1: written by memcpy */
    rect.x = 7900; rect.y = 8000; rect.width = 292; rect.height = 192;
    for (j = rect.y; j < rect.y + rect.height; ++j)
        for (i = rect.x; i < rect.x + rect.width; ++i) {
            float v = (i < 8100) ? 0.05f + 0.0001f * (float)(j - rect.y) : 1.0f;
            memcpy(texels + ((size_t)j * n + i) * 4, &v, 4);
            m.ref.d[(size_t)j * n + i] = (double)v;
        }
    t0 = now_s();
    r = lrt_bvh_update(&bvh, &m.depth, &rect);
    t_update = now_s() - t0;
    CHECK(r == LRT_SUCCESS, "8192^2 update: %s", lrt_result_string(r));
    if (lrt_bvh_build(&fresh, &m.depth, NULL, NULL) == LRT_SUCCESS) {
        CHECK(memcmp(bvh.nodes, fresh.nodes, bvh.layout.bytes) == 0, "8192^2: dirty-rect update differs from a rebuild");
        lrt_bvh_destroy(&fresh);
    } else {
        CHECK(0, "8192^2 rebuild failed");
    }
    {
        const uint32_t rows2[] = {8000, 8100, 8191}, cols2[] = {7950, 8150};
        trace_sample("8192^2 updated", &bvh, &m, rows2, 3, cols2, 2, 6500);
    }
    printf("8192^2 float: build %.2f s, update of %ux%u %.4f s, %zu node bytes\n", t_build, rect.width, rect.height,
           t_update, bvh.layout.bytes);
    lrt_bvh_destroy(&bvh);
    free_map(&m);
}

static void test_thin_maps(void)
{
    static const int shapes[] = {SHAPE_NOISE, SHAPE_POLES};
    int s, vertical;
    for (vertical = 0; vertical < 2; ++vertical)
        for (s = 0; s < 2; ++s) {
            const int w = vertical ? 1 : LINEAR_RT_MAX_DIM, h = vertical ? LINEAR_RT_MAX_DIM : 1;
            const uint32_t line[] = {0};
            test_map m;
            lrt_bvh bvh = {0};
            char what[64];
            lrt_format format = s ? LRT_FORMAT_UNORM16 : LRT_FORMAT_UNORM8;
            make_map(&m, w, h, shapes[s], format, s, s);
            snprintf(what, sizeof what, "%dx%d %s", w, h, shape_names[shapes[s]]);
            if (lrt_bvh_build(&bvh, &m.depth, NULL, NULL) != LRT_SUCCESS) {
                CHECK(0, "%s: build failed", what);
            } else {
                if (vertical) trace_sample(what, &bvh, &m, NULL, 0, line, 1, 2600);
                else trace_sample(what, &bvh, &m, line, 1, NULL, 0, 2600);
                lrt_bvh_destroy(&bvh);
            }
            free_map(&m);
        }
}

/* 1x16384 and 16384x1 float maps over moving frames (tests/support/rays.h): the
   update of the changed rect equals a rebuild byte for byte */
static void test_thin_updates(void)
{
    const int n = LINEAR_RT_MAX_DIM;
    float *d = (float *)malloc(sizeof(float) * n), *prev = (float *)malloc(sizeof(float) * n);
    int vertical, frame;
    for (vertical = 0; vertical < 2 && d && prev; ++vertical) {
        const int w = vertical ? 1 : n, h = vertical ? n : 1;
        lrt_depth dm;
        lrt_bvh live = {0}, fresh = {0};
        int same = 1, ok = 1;
        dm = packed_depth(d, (uint32_t)w, (uint32_t)h, LRT_FORMAT_FLOAT32);
        paint_frame(d, w, h, 0);
        ok &= lrt_bvh_build(&live, &dm, NULL, NULL) == LRT_SUCCESS;
        for (frame = 1; ok && frame < 6; ++frame) {
            lrt_rect rect;
            memcpy(prev, d, sizeof(float) * n);
            paint_frame(d, w, h, frame * 977);
            rect = changed_rect(prev, d, w, h);
            ok &= lrt_bvh_update(&live, &dm, &rect) == LRT_SUCCESS;
            ok &= lrt_bvh_build(&fresh, &dm, NULL, NULL) == LRT_SUCCESS;
            if (ok) same &= memcmp(live.nodes, fresh.nodes, live.layout.bytes) == 0;
            lrt_bvh_destroy(&fresh);
        }
        CHECK(ok && same, "%dx%d: update of the changed rect differs from a rebuild (calls ok: %d)", w, h, ok);
        lrt_bvh_destroy(&live);
    }
    free(d);
    free(prev);
}

/* 16384^2 8-bit, 256 MiB of depth and 293 MiB of nodes:
   primary rays of the edge rows and columns and of the middle, each must hit
   its own texel at t = d (docs/MODEL.md), and random segments must hit or miss
   without reading outside the map (no reference twin: it would be 2 GiB). */
static void test_16384(void)
{
    const uint32_t n = LINEAR_RT_MAX_DIM;
    uint8_t *d = (uint8_t *)malloc((size_t)n * n);
    lrt_depth dm;
    lrt_bvh bvh = {0};
    lrt_ray *rays;
    lrt_hit *hits;
    size_t i, k = 0, bad = 0, count = 4 * (size_t)n + 4096;
    double t0;
    if (!d) {
        printf("  note: 16384^2: no 256 MiB for the depth: skipped\n");
        return;
    }
    for (i = 0; i < (size_t)n * n; ++i) d[i] = (uint8_t)(1u + ((i * 2654435761u) >> 7) % 254u);
    memset(&dm, 0, sizeof dm);
    dm.data = d;
    dm.width = dm.height = n;
    dm.format = LRT_FORMAT_UNORM8;
    t0 = now_s();
    if (lrt_bvh_build(&bvh, &dm, NULL, NULL) != LRT_SUCCESS) {
        CHECK(0, "16384^2 build failed");
        free(d);
        return;
    }
    printf("16384^2 unorm8: build %.2f s, %zu node bytes\n", now_s() - t0, bvh.layout.bytes);
    rays = (lrt_ray *)malloc(sizeof(lrt_ray) * count);
    hits = (lrt_hit *)malloc(sizeof(lrt_hit) * count);
    if (rays && hits) {
        for (i = 0; i < n; ++i) {
            rays[k++] = primary_ray((uint32_t)i, 0);
            rays[k++] = primary_ray((uint32_t)i, n - 1);
            rays[k++] = primary_ray(0, (uint32_t)i);
            rays[k++] = primary_ray(n - 1, (uint32_t)i);
        }
        while (k < count) {
            lrt_ray r = primary_ray(rnd() % n, rnd() % n);
            if (k & 1) { /* a segment across the map, from above the surface */
                r.dir[0] = (float)(rnd() % n) - r.origin[0];
                r.dir[1] = (float)(rnd() % n) - r.origin[1];
            }
            rays[k++] = r;
        }
        CHECK(lrt_trace(&bvh, &dm, rays, hits, count, 0) == LRT_SUCCESS, "16384^2 trace");
        for (i = 0; i < count; ++i) {
            const lrt_ray *r = &rays[i];
            if (r->dir[0] == 0.0f && r->dir[1] == 0.0f) {
                uint32_t x = (uint32_t)r->origin[0], y = (uint32_t)r->origin[1];
                float want = (float)((double)d[(size_t)y * n + x] / 255.0);
                if (hits[i].kind != LRT_HIT || hits[i].x != x || hits[i].y != y ||
                    fabsf(hits[i].t - want) > 1e-5f * (1.0f + want)) {
                    if (bad++ < 5)
                        printf("FAIL 16384^2 primary ray at (%u,%u): kind %u (%u,%u) t %.9g, want t %.9g\n", x, y,
                               hits[i].kind, hits[i].x, hits[i].y, hits[i].t, want);
                }
            } else if (hits[i].kind != LRT_HIT && hits[i].kind != LRT_MISS_TMAX) {
                if (bad++ < 5) printf("FAIL 16384^2 segment %zu: kind %u\n", i, hits[i].kind);
            } else if (hits[i].kind == LRT_HIT && (hits[i].x >= n || hits[i].y >= n)) {
                if (bad++ < 5) printf("FAIL 16384^2 segment %zu: texel (%u,%u)\n", i, hits[i].x, hits[i].y);
            }
        }
        CHECK(bad == 0, "16384^2: %zu of %zu rays wrong", bad, count);
    } else {
        printf("  note: 16384^2: no memory for the rays: skipped\n");
    }
    free(rays);
    free(hits);
    lrt_bvh_destroy(&bvh);
    free(d);
}

/* ---- (d) ray counts --------------------------------------------------------------- */
/* 4 rays and 4 hits between guards: a count check after the first read
   would write hits[0..] and, with a huge count, past the guards */
typedef struct ray_io {
    lrt_ray rays[4];
    lrt_hit guard0[2], hits[4], guard1[2];
} ray_io;

static void test_ray_counts(void)
{
    float d4[4] = {0.5f, 0.5f, 0.5f, 0.5f};
    lrt_depth dm;
    lrt_bvh bvh = {0};
    ray_io io;
    unsigned char before[sizeof io];
    const size_t over = (size_t)LINEAR_RT_MAX_RAYS_PER_CALL + 1;
    size_t i;
    dm = packed_depth(d4, 2, 2, LRT_FORMAT_FLOAT32);
    CHECK(lrt_bvh_build(&bvh, &dm, NULL, NULL) == LRT_SUCCESS, "build 2x2");
    memset(&io, 0x5a, sizeof io);
    for (i = 0; i < 4; ++i) io.rays[i] = primary_ray((uint32_t)(i & 1), (uint32_t)(i >> 1));
    memcpy(before, &io, sizeof io);
#define EXPECT_RANGE(first, end, what)                                                                         \
    do {                                                                                                       \
        lrt_result r_ = lrt_trace_range(&bvh, &dm, io.rays, io.hits, (first), (end), 0);                       \
        CHECK(r_ == LRT_ERROR_TOO_MANY_RAYS, "%s: %s", what, lrt_result_string(r_));                          \
        CHECK(memcmp(before, &io, sizeof io) == 0, "%s: hits or guards were written", what);                  \
    } while (0)
    CHECK(lrt_trace(&bvh, &dm, io.rays, io.hits, over, 0) == LRT_ERROR_TOO_MANY_RAYS, "2^30 + 1 rays");
    CHECK(memcmp(before, &io, sizeof io) == 0, "2^30 + 1 rays: hits or guards were written");
    CHECK(lrt_trace(&bvh, &dm, io.rays, io.hits, SIZE_MAX, 0) == LRT_ERROR_TOO_MANY_RAYS,
          "SIZE_MAX rays, any-hit");
    CHECK(memcmp(before, &io, sizeof io) == 0, "SIZE_MAX rays: hits or guards were written");
    CHECK(lrt_trace(&bvh, &dm, NULL, NULL, over, 0) == LRT_ERROR_TOO_MANY_RAYS, "2^30 + 1 rays, NULL arrays");
    EXPECT_RANGE(0, over, "range [0, 2^30 + 1)");
    EXPECT_RANGE(2, over + 2, "range [2, 2^30 + 3)");
    EXPECT_RANGE(1, 0, "range end before first");
    EXPECT_RANGE(SIZE_MAX, 0, "range [SIZE_MAX, 0)");
    EXPECT_RANGE(SIZE_MAX, SIZE_MAX - 1, "range [SIZE_MAX, SIZE_MAX - 1)");
    EXPECT_RANGE(0, SIZE_MAX, "range [0, SIZE_MAX)");
#undef EXPECT_RANGE
    /* the same slice at a huge index: no ray is read (empty) */
    CHECK(lrt_trace_range(&bvh, &dm, io.rays, io.hits, SIZE_MAX, SIZE_MAX, 0) == LRT_SUCCESS &&
              memcmp(before, &io, sizeof io) == 0,
          "empty range at SIZE_MAX");
    /* and a legal call still works: exactly the 4 hits are written */
    CHECK(lrt_trace(&bvh, &dm, io.rays, io.hits, 4, 0) == LRT_SUCCESS && io.hits[3].kind == LRT_HIT &&
              io.hits[3].t == 0.5f && io.hits[3].x == 1 && io.hits[3].y == 1,
          "4 rays");
    CHECK(memcmp(io.guard0, before + offsetof(ray_io, guard0), sizeof io.guard0) == 0 &&
              memcmp(io.guard1, before + offsetof(ray_io, guard1), sizeof io.guard1) == 0,
          "4 rays: a guard was written");
    lrt_bvh_destroy(&bvh);
}

int main(int argc, char **argv)
{
    const char *mode = getenv("LRT_TEST_LIMITS");
    const int quick = mode && strcmp(mode, "quick") == 0;
    double t0 = now_s();
    check_select(argc, argv);
    printf("size_t: %u bits, LINEAR_RT_MAX_DIM %u, LINEAR_RT_MAX_RAYS_PER_CALL %u\n", (unsigned)(sizeof(size_t) * 8),
           LINEAR_RT_MAX_DIM, LINEAR_RT_MAX_RAYS_PER_CALL);
    RUN_TEST(test_layout_sizes);
    RUN_TEST(test_impossible_sizes);
    RUN_TEST(test_ray_counts);
    RUN_TEST(test_thin_maps);
    RUN_TEST(test_thin_updates);
    if (quick) {
        printf("  note: LRT_TEST_LIMITS=quick: the real 8192^2 and 16384^2 maps are skipped\n");
    } else {
        RUN_TEST(test_8192);
        RUN_TEST(test_16384);
    }
    printf("test_limits: %.1f s of CPU\n", now_s() - t0);
    return check_summary();
}
