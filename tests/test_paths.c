/* tests/test_paths.c - every build of linear_rt.h gives the same answers,
   bit for bit. This file's own copy is built as the tests build it
   (-std=c99, plain x86-64 flags: the walk twice, AVX2 chosen at run time
   where the CPU has it); the others are separate copies of the
   implementation (tests/paths_tu.c), linked side by side:
   - the traversal paths: plain C (LINEAR_RT_NO_SIMD), SSE2 alone
     (LINEAR_RT_NO_AVX), AVX2 compiled in (-mavx2 -mfma, run only where the
     CPU has it);
   - an engine's builds (the Makefile's PATHS_BUILDS): GNU C modes, whose
     default -ffp-contract=fast fuses a * b + c wherever it may, -ffast-math
     and -Ofast, -O0 to -O3, with and without -march=native, C and C++, gcc
     and clang. linear_rt.h keeps its floating-point rules whatever the
     includer's flags (section impl);
   - on x86, the own and scalar copies again with subnormals flushed (MXCSR's
     FTZ and DAZ), as a GPU may run the kernels and as -ffast-math's start-up
     code sets them for a whole program.
   The maps: every size, shape, format, Z direction and node width of
   tests/support/rays.h, and the benchmark's five scenes (bench/scenes.h)
   under every thickness model and step budget.
   test_core judges every path against the reference within docs/MODEL.md's
   tolerance; this test holds them to the same floats, which the header
   promises and the GPU comparison of test_vulkan relies on.
   Prints one line per failure and ends with "N passed, M failed". */
#define LINEAR_RT_IMPLEMENTATION
#include "../linear_rt.h"
#include "support/reference.h"
#include "../examples/scene.h"
#include "support/rays.h"
#include "support/check.h"
#include "support/build_trace.h"
#include "../bench/scenes.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PATHS_DECLARE(fn) \
    int fn(const lrt_depth *depth, const lrt_build_options *opt, const lrt_ray *rays, lrt_hit *hits, size_t n, uint32_t flags);
/* the Makefile's PATHS_BUILDS, each one's flags in its name */
#define PATHS_BUILDS(X)                                                                                            \
    X(paths_trace_gnu99_contract, "gcc -std=gnu99 -ffp-contract=fast", 0)                                           \
    X(paths_trace_gcc_gnu11_native, "gcc -std=gnu11 -O2 -march=native", 0)                                          \
    X(paths_trace_gcc_fast_native, "gcc -std=gnu11 -O3 -march=native -ffast-math", 0)                               \
    X(paths_trace_gcc_ofast, "gcc -std=gnu11 -Ofast", 0)                                                            \
    X(paths_trace_gcc_o0, "gcc -std=c99 -O0", 0)                                                                    \
    X(paths_trace_gcc_fast_nosimd, "gcc -std=gnu11 -O2 -ffast-math -DLINEAR_RT_NO_SIMD", 0)                         \
    X(paths_trace_gxx_fast_native, "g++ -std=gnu++14 -O3 -march=native -ffast-math", 0)                             \
    X(paths_trace_gxx_o1, "g++ -std=c++11 -O1", 0)                                                                  \
    PATHS_CLANG_BUILDS(X)
#if PATHS_HAVE_CLANG
#define PATHS_CLANG_BUILDS(X)                                                                                      \
    X(paths_trace_clang_fast, "clang -std=gnu11 -O3 -ffast-math", 0)                                                \
    X(paths_trace_clang_ofast_native, "clang -std=gnu11 -Ofast -march=native", 0)                                   \
    X(paths_trace_clang_o1_contract, "clang -std=c99 -O1 -ffp-contract=fast", 0)                                    \
    X(paths_trace_clangxx_fast_native, "clang++ -std=c++17 -O2 -march=native -ffast-math", 0)
#else
#define PATHS_CLANG_BUILDS(X)
#endif
#define PATHS_ROW(fn, name, avx2) {name, fn, avx2},
#define PATHS_DECLARE_ROW(fn, name, avx2) PATHS_DECLARE(fn)
PATHS_DECLARE(paths_trace_scalar)
PATHS_DECLARE(paths_trace_avx2)
PATHS_DECLARE(paths_trace_sse2)
PATHS_BUILDS(PATHS_DECLARE_ROW)
typedef int (*paths_fn)(const lrt_depth *, const lrt_build_options *, const lrt_ray *, lrt_hit *, size_t, uint32_t);
static const struct {
    const char *name;
    paths_fn trace;
    int needs_avx2;
} g_paths[] = {{"scalar", paths_trace_scalar, 0},
               {"SSE2 alone", paths_trace_sse2, 0},
               {"AVX2 compiled in", paths_trace_avx2, 1},
               PATHS_BUILDS(PATHS_ROW)};
#define PATHS ((int)(sizeof g_paths / sizeof g_paths[0]))

static int g_have_avx2;
static size_t g_rays;

#if defined(__SSE2__) || defined(_M_X64)
#include <xmmintrin.h>
/* A GPU that flushes subnormal floats (an NVIDIA H200 did, and cannot keep
   them) runs the kernels' arithmetic as x86 does with MXCSR's flush-to-zero
   and denormals-are-zero bits set: docs/MODEL.md reads subnormal inputs as 0
   so that such a device answers as the CPU does. Build and trace under
   those bits, the own copy (AVX2 where the CPU has it) and the scalar one,
   whose steps the kernels follow. */
static int trace_flushed(paths_fn fn, const lrt_depth *depth, const lrt_build_options *opt, const lrt_ray *rays,
                         lrt_hit *hits, size_t n, uint32_t flags)
{
    const unsigned int csr = _mm_getcsr();
    int r;
    _mm_setcsr(csr | 0x8040u); /* FTZ (bit 15) and DAZ (bit 6) */
    r = fn(depth, opt, rays, hits, n, flags);
    _mm_setcsr(csr);
    return r;
}
static int flushed_own(const lrt_depth *depth, const lrt_build_options *opt, const lrt_ray *rays, lrt_hit *hits, size_t n,
                       uint32_t flags)
{
    return trace_flushed(build_and_trace, depth, opt, rays, hits, n, flags);
}
static int flushed_scalar(const lrt_depth *depth, const lrt_build_options *opt, const lrt_ray *rays, lrt_hit *hits, size_t n,
                          uint32_t flags)
{
    return trace_flushed(paths_trace_scalar, depth, opt, rays, hits, n, flags);
}
#define FLUSHING_PATHS 2
static const struct {
    const char *name;
    paths_fn trace;
} g_flushing[FLUSHING_PATHS] = {{"own copy, subnormals flushed", flushed_own}, {"scalar, subnormals flushed", flushed_scalar}};
#else
#define FLUSHING_PATHS 0
#endif

/* The rays of one map through every path; the first differing ray of each
   path is printed. */
static void compare(const char *what, const test_map *m, uint32_t node_bits, const lrt_ray *rays, size_t n, uint32_t flags)
{
    lrt_hit *own = (lrt_hit *)calloc(n ? n : 1, sizeof(lrt_hit)), *other = (lrt_hit *)calloc(n ? n : 1, sizeof(lrt_hit));
    const lrt_depth *depth = test_map_depth(m);
    lrt_bvh bvh = {0};
    lrt_build_options opt = m->model;
    int p;
    opt.node_bits = node_bits;
    CHECK(own && other, "%s: out of memory", what);
    if (!own || !other || lrt_bvh_build(&bvh, depth, &opt, NULL) != LRT_SUCCESS) {
        CHECK(0, "%s: build failed", what);
        free(own);
        free(other);
        return;
    }
    CHECK(lrt_trace(&bvh, depth, rays, own, n, flags) == LRT_SUCCESS, "%s: own trace", what);
    lrt_bvh_destroy(&bvh);
    for (p = 0; p < PATHS + FLUSHING_PATHS; ++p) {
        const char *name;
        paths_fn trace;
        size_t i, differ = 0;
        int r;
        if (p < PATHS) {
            if (g_paths[p].needs_avx2 && !g_have_avx2) continue;
            name = g_paths[p].name;
            trace = g_paths[p].trace;
        } else {
#if FLUSHING_PATHS
            name = g_flushing[p - PATHS].name;
            trace = g_flushing[p - PATHS].trace;
#else
            continue;
#endif
        }
        memset(other, 0xab, n * sizeof *other);
        r = trace(depth, &opt, rays, other, n, flags);
        CHECK(r == LRT_SUCCESS, "%s: %s trace returned %d", what, name, r);
        for (i = 0; i < n; ++i) {
            if (memcmp(&own[i], &other[i], sizeof own[i]) != 0) {
                if (differ == 0)
                    printf("  %s: ray %zu o=(%.9g %.9g %.9g) v=(%.9g %.9g %.9g): own kind %u t %.9g (%u,%u), %s kind %u t %.9g (%u,%u)\n",
                           what, i, rays[i].origin[0], rays[i].origin[1], rays[i].origin[2], rays[i].dir[0], rays[i].dir[1],
                           rays[i].dir[2], own[i].kind, own[i].t, own[i].x, own[i].y, name, other[i].kind, other[i].t,
                           other[i].x, other[i].y);
                ++differ;
            }
        }
        CHECK(differ == 0, "%s: %zu of %zu rays differ between the own copy and %s", what, differ, n, name);
    }
    g_rays += n;
    free(own);
    free(other);
}

static void map_and_rays(int w, int h, int shape, lrt_format format, int reversed, uint32_t node_bits, size_t n, int padded,
                         int thick)
{
    test_map m;
    lrt_ray *rays = (lrt_ray *)malloc(sizeof(lrt_ray) * n);
    char what[160];
    size_t i;
    make_map(&m, w, h, shape, format, reversed, padded);
    if (thick == LRT_THICKNESS_BACK_MAP) add_back(&m);
    if (thick >= LRT_THICKNESS_CONSTANT) add_model(&m, (uint32_t)thick, (w & 1) ? 0.05f : 1.5f, 0.1f, (h & 1) ? 80.0f : INFINITY);
    snprintf(what, sizeof what, "%dx%d %s fmt=%d%s nodes=%u%s%s", w, h, m.name, (int)format, reversed ? " reversed" : "",
             node_bits, padded ? " strided" : "", model_name(&m));
    if (rays) {
        for (i = 0; i < n; ++i) rays[i] = make_ray(&m, (int)(i % RAY_KIND_COUNT));
        compare(what, &m, node_bits, rays, n, 0);
    } else CHECK(0, "%s: out of memory", what);
    free_map(&m);
    free(rays);
}

/* every size, shape and format, Z direction, node width, strided or not */
static void test_maps(void)
{
    static const int sizes[][2] = {{1, 1}, {1, 23}, {23, 1}, {3, 5}, {7, 9}, {8, 8}, {33, 20}, {100, 37}, {5, 300}, {257, 129}};
    const size_t nsizes = sizeof sizes / sizeof sizes[0];
    size_t s;
    int shape, f;
    for (s = 0; s < nsizes; ++s)
        for (shape = 0; shape < SHAPE_COUNT; ++shape)
            for (f = 1; f <= 3; ++f) {
                if (shape == SHAPE_WILD && f != 3) continue;
                map_and_rays(sizes[s][0], sizes[s][1], shape, (lrt_format)f, (int)(s & 1), (s % 3 == 0) ? 8u : 16u, 3000,
                             (int)(s & 2), (shape == SHAPE_SCENE || shape == SHAPE_POLES) && f == 2);
            }
}

static void test_large(void)
{
    map_and_rays(1024, 1024, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 16, 100000, 0, 0);
    map_and_rays(1024, 1024, SHAPE_POLES, LRT_FORMAT_FLOAT32, 1, 8, 30000, 0, 0);
    map_and_rays(1282, 1110, SHAPE_SCENE, LRT_FORMAT_UNORM16, 1, 8, 30000, 1, 0);
}

static void test_thickness(void)
{
    map_and_rays(1024, 1024, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 16, 50000, 0, 1);
    map_and_rays(513, 257, SHAPE_SCENE, LRT_FORMAT_UNORM16, 1, 8, 20000, 1, 1);
    /* constant and relative thickness: plain float (the AVX2 texel test's own b(d)), then others */
    map_and_rays(1024, 1024, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 16, 50000, 0, LRT_THICKNESS_CONSTANT);
    map_and_rays(1023, 512, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 8, 30000, 0, LRT_THICKNESS_RELATIVE);
    map_and_rays(257, 129, SHAPE_NOISE, LRT_FORMAT_FLOAT32, 0, 16, 20000, 1, LRT_THICKNESS_CONSTANT);
    map_and_rays(257, 130, SHAPE_POLES, LRT_FORMAT_FLOAT32, 1, 16, 20000, 0, LRT_THICKNESS_RELATIVE);
    map_and_rays(100, 37, SHAPE_SCENE, LRT_FORMAT_UNORM16, 1, 8, 20000, 1, LRT_THICKNESS_CONSTANT);
    map_and_rays(101, 37, SHAPE_TERRACES, LRT_FORMAT_UNORM8, 0, 16, 20000, 0, LRT_THICKNESS_RELATIVE);
}

/* A float map of w x h texels (and its back, if any) as a test_map. */
static void map_from_floats(test_map *m, const float *depth, const float *back, int w, int h, const char *name)
{
    const size_t bytes = sizeof(float) * (size_t)w * (size_t)h;
    memset(m, 0, sizeof *m);
    if (!(m->storage = malloc(bytes)) || (back && !(m->back_storage = malloc(bytes)))) exit(2);
    memcpy(m->storage, depth, bytes);
    m->depth.data = m->storage;
    m->depth.width = (uint32_t)w;
    m->depth.height = (uint32_t)h;
    m->depth.format = LRT_FORMAT_FLOAT32;
    m->name = name;
    if (ref_map_from_raw(&m->ref, m->storage, w, h, 0, REF_FORMAT_FLOAT32, 0) != 0) exit(2);
    if (back) {
        memcpy(m->back_storage, back, bytes);
        m->pair[0] = m->depth;
        m->pair[0].back = &m->pair[1];
        m->pair[1] = m->depth;
        m->pair[1].data = m->back_storage;
        m->model.thickness = LRT_THICKNESS_BACK_MAP;
        if (ref_map_set_back_from_raw(&m->ref, m->back_storage, 0, REF_FORMAT_FLOAT32, 0) != 0) exit(2);
    }
}

static float bench_rnd01(void) { return rndf(); }

/* The benchmark's five scenes, every thickness model (the yard back's own
   back map; a constant and a relative layer on the others), with no budget
   and each of the benchmark's step budgets, both node widths. */
static void test_bench_scenes(void)
{
    static const uint32_t budgets[] = {0, 4, 8, 16, 32};
    const int w = 320, h = 200;
    const size_t n = 6000;
    float *depth = (float *)malloc(sizeof(float) * (size_t)w * (size_t)h);
    float *back = (float *)malloc(sizeof(float) * (size_t)w * (size_t)h);
    lrt_ray *rays = (lrt_ray *)malloc(sizeof(lrt_ray) * n);
    int kind, model;
    size_t b, i;
    if (!depth || !back || !rays) exit(2);
    for (kind = 0; kind < BENCH_SCENE_COUNT; ++kind) {
        bench_scene_depth(kind, (uint32_t)w, (uint32_t)h, depth, back, bench_rnd01);
        for (model = 0; model < (kind == 4 ? 1 : 3); ++model) {
            test_map m;
            map_from_floats(&m, depth, kind == 4 ? back : NULL, w, h, bench_scene_names[kind]);
            if (model == 1) add_model(&m, LRT_THICKNESS_CONSTANT, 0.3f, 0.1f, 100.0f);
            if (model == 2) add_model(&m, LRT_THICKNESS_RELATIVE, 0.05f, 0.1f, INFINITY);
            for (i = 0; i < n; ++i) rays[i] = make_ray(&m, (int)(i % RAY_KIND_COUNT));
            for (b = 0; b < sizeof budgets / sizeof budgets[0]; ++b) {
                char what[160];
                uint32_t bits;
                for (bits = 8; bits <= 16; bits += 8) {
                    snprintf(what, sizeof what, "bench scene %s%s, budget %u, nodes %u", m.name, model_name(&m),
                             (unsigned)budgets[b], (unsigned)bits);
                    compare(what, &m, bits, rays, n, LRT_TRACE_BUDGET(budgets[b]));
                }
            }
            free_map(&m);
        }
    }
    free(depth);
    free(back);
    free(rays);
}

/* linear_rt.h's C twin of the GPU's cell walk (lrt__walk_cells): on every
   ray its ordinary pass takes, the same answer as lrt_trace's (hit or not,
   the same texel), as test_vulkan holds the kernels' own. And a budget
   counts its steps: lrt_trace with the steps the walk took gives the exact
   answer, with one fewer a budget miss */
static size_t g_cell_rays, g_cell_budgets;
static void cells_match(const char *what, const test_map *m, uint32_t node_bits, const lrt_ray *rays, size_t n)
{
    const lrt_depth *depth = test_map_depth(m);
    lrt_build_options opt = m->model;
    lrt_bvh bvh = {0};
    size_t i, differ = 0, texels = 0, budget_differ = 0;
    opt.node_bits = node_bits;
    if (lrt_bvh_build(&bvh, depth, &opt, NULL) != LRT_SUCCESS) {
        CHECK(0, "%s: build failed", what);
        return;
    }
    for (i = 0; i < n; ++i) {
        uint32_t steps = 0, hx = 0, hy = 0;
        int hit = 0;
        lrt_hit h;
        if (!lrt__walk_cells_ray(&bvh, depth, &rays[i], &steps, &texels, &hit, &hx, &hy)) continue;
        if (lrt_trace(&bvh, depth, &rays[i], &h, 1, 0) != LRT_SUCCESS) h.kind = 0xffffu;
        if ((h.kind == LRT_HIT) != hit || (hit && (h.x != hx || h.y != hy))) {
            if (!differ)
                printf("  %s: ray %zu: lrt_trace kind %u (%u,%u), the cell walk %s (%u,%u)\n", what, i, h.kind, h.x, h.y,
                       hit ? "a hit" : "no hit", hx, hy);
            ++differ;
        }
        ++g_cell_rays;
        if (opt.thickness == LRT_THICKNESS_INFINITE && steps <= LRT_TRACE_BUDGET_MAX) {
            lrt_hit b = h;
            int ok = lrt_trace(&bvh, depth, &rays[i], &b, 1, LRT_TRACE_BUDGET(steps)) == LRT_SUCCESS &&
                     memcmp(&b, &h, sizeof b) == 0;
            if (ok && steps > 1)
                ok = lrt_trace(&bvh, depth, &rays[i], &b, 1, LRT_TRACE_BUDGET(steps - 1)) == LRT_SUCCESS &&
                     b.kind == LRT_MISS_BUDGET;
            budget_differ += !ok;
            ++g_cell_budgets;
        }
    }
    CHECK(differ == 0, "%s: the cell walk differs from lrt_trace on %zu rays", what, differ);
    CHECK(budget_differ == 0, "%s: a budget of the cell walk's steps (or one fewer) answers otherwise on %zu rays", what,
          budget_differ);
    lrt_bvh_destroy(&bvh);
}

static void test_cell_walk(void)
{
    static const int sizes[][2] = {{1, 1}, {3, 5}, {8, 8}, {33, 20}, {257, 129}, {640, 360}};
    size_t s, i;
    int shape, f;
    for (s = 0; s < sizeof sizes / sizeof sizes[0]; ++s)
        for (shape = 0; shape < SHAPE_COUNT; ++shape)
            for (f = 1; f <= 3; ++f) {
                test_map m;
                const size_t n = 4000;
                lrt_ray *rays = (lrt_ray *)malloc(sizeof(lrt_ray) * n);
                char what[128];
                if (shape == SHAPE_WILD && f != 3) continue;
                make_map(&m, sizes[s][0], sizes[s][1], shape, (lrt_format)f, (int)(s & 1), (int)(s & 2));
                if (!rays) exit(2);
                for (i = 0; i < n; ++i) rays[i] = make_ray(&m, (int)(i % RAY_KIND_COUNT));
                snprintf(what, sizeof what, "cell walk %dx%d %s fmt=%d", sizes[s][0], sizes[s][1], m.name, f);
                cells_match(what, &m, (s % 2) ? 8u : 16u, rays, n);
                free_map(&m);
                free(rays);
            }
    printf("%zu rays through the cell walk, each lrt_trace's answer; %zu traced with a budget of its steps\n", g_cell_rays,
           g_cell_budgets);
    CHECK(g_cell_rays > 100000, "only %zu rays took the cell walk", g_cell_rays);
    CHECK(g_cell_budgets > 100000, "only %zu rays traced with a budget of the cell walk's steps", g_cell_budgets);
}

/* the fuzzer's rays, the rare set-up among them */
static void test_found_cases(void)
{
    test_map m;
    lrt_ray r;
    int k;
    for (k = 0; found_case(k, &m, &r); ++k) {
        char what[64];
        snprintf(what, sizeof what, "found case %d", k);
        compare(what, &m, 0, &r, 1, 0);
        free_map(&m);
    }
}

int main(int argc, char **argv)
{
    check_select(argc, argv);
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
    __builtin_cpu_init();
    g_have_avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#endif
    printf("this copy's walk: %s\n", lrt_cpu_path());
    if (!g_have_avx2) printf("note: this CPU has no AVX2: the AVX2 copy is compiled, not run\n");
    RUN_TEST(test_maps);
    RUN_TEST(test_large);
    RUN_TEST(test_thickness);
    RUN_TEST(test_bench_scenes);
    RUN_TEST(test_cell_walk);
    RUN_TEST(test_found_cases);
    printf("%zu rays compared across the paths\n", g_rays);
    return check_summary();
}
