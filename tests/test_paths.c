/* tests/test_paths.c - linear_rt.h's traversal paths give the same answers,
   bit for bit. This file's own copy is built as users build it (plain
   x86-64 flags: the walk twice, AVX2 chosen at run time where the CPU has
   it); the others are separate copies of the implementation
   (tests/paths_tu.c): plain C (LINEAR_RT_NO_SIMD), SSE2 alone
   (LINEAR_RT_NO_AVX), AVX2 compiled in (-mavx2 -mfma, run only where the
   CPU has it) and the run-time choice again under -std=gnu99, where gcc
   fuses a * b + c into an fma wherever it may (-ffp-contract=fast); and on
   x86, the own and scalar copies again with subnormals flushed (MXCSR's
   FTZ and DAZ), as a GPU may run the kernels.
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

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int paths_trace_scalar(const lrt_depth *depth, const lrt_build_options *opt, const lrt_ray *rays, lrt_hit *hits, size_t n, uint32_t flags);
int paths_trace_avx2(const lrt_depth *depth, const lrt_build_options *opt, const lrt_ray *rays, lrt_hit *hits, size_t n, uint32_t flags);
int paths_trace_sse2(const lrt_depth *depth, const lrt_build_options *opt, const lrt_ray *rays, lrt_hit *hits, size_t n, uint32_t flags);
int paths_trace_contract(const lrt_depth *depth, const lrt_build_options *opt, const lrt_ray *rays, lrt_hit *hits, size_t n, uint32_t flags);
typedef int (*paths_fn)(const lrt_depth *, const lrt_build_options *, const lrt_ray *, lrt_hit *, size_t, uint32_t);
static const struct {
    const char *name;
    paths_fn trace;
    int needs_avx2;
} g_paths[] = {{"scalar", paths_trace_scalar, 0},
               {"SSE2 alone", paths_trace_sse2, 0},
               {"AVX2 compiled in", paths_trace_avx2, 1},
               {"gnu99 fp-contract=fast", paths_trace_contract, 0}};
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
static void compare(const char *what, const test_map *m, uint32_t node_bits, const lrt_ray *rays, size_t n)
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
    CHECK(lrt_trace(&bvh, depth, rays, own, n, 0) == LRT_SUCCESS, "%s: own trace", what);
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
        r = trace(depth, &opt, rays, other, n, 0);
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
        compare(what, &m, node_bits, rays, n);
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

/* the fuzzer's rays, the rare set-up among them */
static void test_found_cases(void)
{
    test_map m;
    lrt_ray r;
    int k;
    for (k = 0; found_case(k, &m, &r); ++k) {
        char what[64];
        snprintf(what, sizeof what, "found case %d", k);
        compare(what, &m, 0, &r, 1);
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
    RUN_TEST(test_found_cases);
    printf("%zu rays compared across the paths\n", g_rays);
    return check_summary();
}
