/* tests/test_misuse.c - the mistakes a newcomer makes with the CPU API, each
   with the result the header documents and never a wrong answer, a read
   past what was given, or a leak. Built twice by `make test-misuse`: plain,
   and with AddressSanitizer (a read past a struct or a map, and
   LeakSanitizer for a tree dropped by a second build).

   - a map of another format or Z direction than the tree was built from:
     LRT_ERROR_DEPTH_MISMATCH on update and trace (it used to trace it as the
     tree's format and answer a wrong hit);
   - a build over a built tree: LRT_ERROR_ALREADY_BUILT, the tree intact,
     one allocation in all; destroy frees it, a rebuild after works;
   - a tree of garbage bytes (never built, not zeroed): LRT_ERROR_INVALID_BVH;
   - a back-map tree given one lrt_depth: LRT_ERROR_THICKNESS_MISMATCH with
     nothing read past it (the back map is a pointer, not "the next struct");
   - every result code has its own message; the messages of the misleading
     cases name the actual problem;
   - lrt_perspective refuses what lrt_camera_init or the thickness models
     would refuse later, lrt_camera_init a perspective of swapped planes;
   - THE LIFT: lrt_surface_lift and lrt_camera_surface_ray are the recipe.

   Prints one line per failure and ends with "N passed, M failed". */
#define LINEAR_RT_IMPLEMENTATION
#include "../linear_rt.h"
#include "support/check.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* an allocator that counts what is live */
static int g_live, g_allocs;
static void *count_alloc(void *user, size_t size)
{
    (void)user;
    ++g_live;
    ++g_allocs;
    return malloc(size);
}
static void count_free(void *user, void *p)
{
    (void)user;
    --g_live;
    free(p);
}

/* A 16x8 float map: a floor at depth 0.8 and a wall at 0.3 in columns 8..11. */
static void paint(float *d)
{
    int x, y;
    for (y = 0; y < 8; ++y)
        for (x = 0; x < 16; ++x) d[y * 16 + x] = x >= 8 && x < 12 ? 0.3f : 0.8f;
}

static lrt_ray down_ray(float x, float y)
{
    lrt_ray r;
    r.origin[0] = x;
    r.origin[1] = y;
    r.origin[2] = 0.0f;
    r.tmin = 0.0f;
    r.dir[0] = 0.0f;
    r.dir[1] = 0.0f;
    r.dir[2] = 1.0f;
    r.tmax = 1.0f;
    return r;
}

static void test_format_mismatch(void)
{
    float d[16 * 8];
    uint8_t d8[16 * 8];
    uint16_t d16[16 * 8];
    lrt_depth map = {d, 16, 8, 0, LRT_FORMAT_FLOAT32, 0, NULL}, as8 = map, as16 = map, reversed = map;
    lrt_bvh bvh = {0};
    lrt_ray ray = down_ray(4.5f, 4.5f);
    lrt_hit hit;
    int k;
    paint(d);
    for (k = 0; k < 16 * 8; ++k) {
        d8[k] = (uint8_t)(d[k] * 255.0f);
        d16[k] = (uint16_t)(d[k] * 65535.0f);
    }
    as8.data = d8;
    as8.format = LRT_FORMAT_UNORM8;
    as16.data = d16;
    as16.format = LRT_FORMAT_UNORM16;
    reversed.flags = LRT_DEPTH_REVERSED_Z;
    CHECK(lrt_bvh_build(&bvh, &map, NULL, NULL) == LRT_SUCCESS, "build");
    CHECK(bvh.format == LRT_FORMAT_FLOAT32 && bvh.depth_flags == 0, "the tree remembers its format and flags");
    CHECK(lrt_trace(&bvh, &map, &ray, &hit, 1, 0) == LRT_SUCCESS && hit.kind == LRT_HIT && fabsf(hit.t - 0.8f) < 1e-6f,
          "the tree's own map: t %g", hit.t);
    memset(&hit, 0x5a, sizeof hit);
    CHECK(lrt_trace(&bvh, &as8, &ray, &hit, 1, 0) == LRT_ERROR_DEPTH_MISMATCH, "trace: an 8-bit map on a float tree");
    CHECK(lrt_trace(&bvh, &as16, &ray, &hit, 1, 0) == LRT_ERROR_DEPTH_MISMATCH, "trace: a 16-bit map on a float tree");
    CHECK(lrt_trace(&bvh, &reversed, &ray, &hit, 1, 0) == LRT_ERROR_DEPTH_MISMATCH, "trace: the other Z direction");
    CHECK(lrt_trace_range(&bvh, &as8, &ray, &hit, 0, 1, 0) == LRT_ERROR_DEPTH_MISMATCH, "trace_range: an 8-bit map");
    CHECK(hit.kind == 0x5a5a, "a refused trace wrote no hit");
    CHECK(lrt_bvh_update(&bvh, &as8, NULL) == LRT_ERROR_DEPTH_MISMATCH, "update: an 8-bit map on a float tree");
    CHECK(lrt_bvh_update(&bvh, &reversed, NULL) == LRT_ERROR_DEPTH_MISMATCH, "update: the other Z direction");
    lrt_bvh_destroy(&bvh);
    /* a reversed-Z tree takes reversed maps only */
    CHECK(lrt_bvh_build(&bvh, &reversed, NULL, NULL) == LRT_SUCCESS && bvh.depth_flags == LRT_DEPTH_REVERSED_Z,
          "build reversed");
    CHECK(lrt_trace(&bvh, &map, &ray, &hit, 1, 0) == LRT_ERROR_DEPTH_MISMATCH, "trace: standard Z on a reversed tree");
    CHECK(lrt_trace(&bvh, &reversed, &ray, &hit, 1, 0) == LRT_SUCCESS, "trace: its own Z direction");
    lrt_bvh_destroy(&bvh);
    /* a narrower format read as a wider one would run past the map: an 8-bit
       tree given a float map's description of 8-bit bytes is refused unread */
    CHECK(lrt_bvh_build(&bvh, &as8, NULL, NULL) == LRT_SUCCESS, "build 8-bit");
    as8.format = LRT_FORMAT_FLOAT32;
    CHECK(lrt_trace(&bvh, &as8, &ray, &hit, 1, 0) == LRT_ERROR_DEPTH_MISMATCH, "trace: 8-bit bytes called float");
    lrt_bvh_destroy(&bvh);
}

static void test_life_cycle(void)
{
    float d[16 * 8];
    lrt_depth map = {d, 16, 8, 0, LRT_FORMAT_FLOAT32, 0, NULL}, small = map;
    lrt_allocator a = {count_alloc, count_free, NULL};
    lrt_bvh bvh = {0}, before, junk;
    lrt_ray ray = down_ray(4.5f, 4.5f);
    lrt_hit hit;
    size_t bytes = 0;
    void *mem;
    paint(d);
    small.width = 8;
    g_live = g_allocs = 0;
    CHECK(lrt_bvh_build(&bvh, &map, NULL, &a) == LRT_SUCCESS && g_live == 1, "build: one allocation");
    before = bvh;
    CHECK(lrt_bvh_build(&bvh, &small, NULL, &a) == LRT_ERROR_ALREADY_BUILT, "a second build (a resize) is refused");
    CHECK(g_live == 1 && g_allocs == 1, "a refused build allocates nothing: %d live, %d made", g_live, g_allocs);
    CHECK(memcmp(&before, &bvh, sizeof bvh) == 0, "a refused build leaves the tree as it was");
    CHECK(lrt_bvh_memory_size(16, 8, LRT_FORMAT_FLOAT32, NULL, &bytes) == LRT_SUCCESS && (mem = malloc(bytes)) != NULL,
          "memory size");
    CHECK(lrt_bvh_build_in(&bvh, &map, NULL, mem, bytes) == LRT_ERROR_ALREADY_BUILT, "build_in over a built tree");
    CHECK(lrt_trace(&bvh, &map, &ray, &hit, 1, 0) == LRT_SUCCESS && hit.kind == LRT_HIT, "the tree still traces");
    lrt_bvh_destroy(&bvh);
    CHECK(g_live == 0, "destroy frees the tree: %d live", g_live);
    CHECK(bvh.built == 0, "destroy clears the magic word");
    CHECK(lrt_trace(&bvh, &map, &ray, &hit, 1, 0) == LRT_ERROR_INVALID_BVH, "a destroyed tree");
    CHECK(lrt_bvh_build(&bvh, &small, NULL, &a) == LRT_SUCCESS && g_live == 1, "destroy, then build at the new size");
    lrt_bvh_destroy(&bvh);
    lrt_bvh_destroy(&bvh); /* twice is fine */
    CHECK(g_live == 0, "nothing live after two destroys");
    CHECK(lrt_bvh_build_in(&bvh, &map, NULL, mem, bytes) == LRT_SUCCESS, "build_in into a destroyed tree");
    lrt_bvh_destroy(&bvh);
    free(mem);
    /* stack garbage: every byte pattern but the magic word's is no tree */
    memset(&junk, 0x5a, sizeof junk);
    CHECK(lrt_trace(&junk, &map, &ray, &hit, 1, 0) == LRT_ERROR_INVALID_BVH, "trace: a tree of garbage bytes");
    CHECK(lrt_bvh_update(&junk, &map, NULL) == LRT_ERROR_INVALID_BVH, "update: a tree of garbage bytes");
    junk.built = 1; /* what "built" was before the magic word */
    junk.nodes = d;
    junk.layout.width = 16;
    junk.layout.height = 8;
    CHECK(lrt_trace(&junk, &map, &ray, &hit, 1, 0) == LRT_ERROR_INVALID_BVH, "trace: garbage that looks half built");
    memset(&junk, 0xff, sizeof junk);
    lrt_bvh_destroy(&junk); /* frees nothing it does not own */
    CHECK(junk.built == 0, "destroy of garbage zeroes it");
}

static void test_back_map_pointer(void)
{
    /* one lrt_depth on the heap, exactly its size: ASan sees a read past it */
    float d[16 * 8], back[16 * 8];
    lrt_depth *one = (lrt_depth *)malloc(sizeof *one), *pair = (lrt_depth *)malloc(2 * sizeof *pair);
    lrt_build_options opt;
    lrt_bvh bvh = {0};
    lrt_ray ray = down_ray(9.5f, 4.5f);
    lrt_hit hit;
    int k;
    if (!one || !pair) {
        CHECK(0, "out of memory");
        free(one);
        free(pair);
        return;
    }
    paint(d);
    for (k = 0; k < 16 * 8; ++k) back[k] = d[k] + 0.1f;
    memset(one, 0, sizeof *one);
    one->data = d;
    one->width = 16;
    one->height = 8;
    one->format = LRT_FORMAT_FLOAT32;
    memset(&opt, 0, sizeof opt);
    opt.thickness = LRT_THICKNESS_BACK_MAP;
    CHECK(lrt_bvh_build(&bvh, one, &opt, NULL) == LRT_ERROR_THICKNESS_MISMATCH, "a back-map tree from one map");
    one->flags = 2; /* the bit that once said "a back map follows": now an unknown flag */
    CHECK(lrt_bvh_build(&bvh, one, &opt, NULL) == LRT_ERROR_INVALID_OPTION, "the old flag bit");
    one->flags = 0;
    pair[0] = *one;
    pair[1] = *one;
    pair[1].data = back;
    pair[0].back = &pair[1];
    CHECK(lrt_bvh_build(&bvh, pair, &opt, NULL) == LRT_SUCCESS, "a back-map tree from its pair");
    CHECK(lrt_trace(&bvh, one, &ray, &hit, 1, 0) == LRT_ERROR_THICKNESS_MISMATCH, "trace without the back map");
    CHECK(lrt_bvh_update(&bvh, one, NULL) == LRT_ERROR_THICKNESS_MISMATCH, "update without the back map");
    pair[1].back = &pair[0];
    CHECK(lrt_trace(&bvh, pair, &ray, &hit, 1, 0) == LRT_ERROR_THICKNESS_MISMATCH, "a back map with a back of its own");
    pair[1].back = NULL;
    pair[1].format = LRT_FORMAT_UNORM16;
    CHECK(lrt_trace(&bvh, pair, &ray, &hit, 1, 0) == LRT_ERROR_DEPTH_MISMATCH, "a back map of another format");
    pair[1].format = LRT_FORMAT_FLOAT32;
    pair[1].flags = LRT_DEPTH_REVERSED_Z;
    CHECK(lrt_trace(&bvh, pair, &ray, &hit, 1, 0) == LRT_ERROR_DEPTH_MISMATCH, "a back map of the other Z direction");
    pair[1].flags = 0;
    /* the wall [0.3, 0.4]: a ray along z at its column meets its top, and
       one from behind it (z 0.5) passes under it to the far plane */
    CHECK(lrt_trace(&bvh, pair, &ray, &hit, 1, 0) == LRT_SUCCESS && hit.kind == LRT_HIT && fabsf(hit.t - 0.3f) < 1e-6f,
          "the wall's top: t %g", hit.t);
    ray.origin[2] = 0.5f;
    ray.tmax = 0.5f;
    CHECK(lrt_trace(&bvh, pair, &ray, &hit, 1, 0) == LRT_SUCCESS && hit.kind == LRT_MISS_TMAX,
          "behind the wall, above the floor: kind %u", hit.kind);
    lrt_bvh_destroy(&bvh);
    CHECK(lrt_bvh_build(&bvh, pair, NULL, NULL) == LRT_ERROR_THICKNESS_MISMATCH, "an infinite tree with a back map");
    free(one);
    free(pair);
}

static void test_messages(void)
{
    const char *seen[LRT_ERROR_CONTEXT_MISMATCH + 1];
    int k, j;
    for (k = 0; k <= LRT_ERROR_CONTEXT_MISMATCH; ++k) {
        seen[k] = lrt_result_string((lrt_result)k);
        CHECK(seen[k] && strcmp(seen[k], "unknown result code") != 0, "code %d has a message", k);
        for (j = 0; j < k; ++j) CHECK(strcmp(seen[j], seen[k]) != 0, "codes %d and %d share a message", j, k);
    }
    CHECK(strcmp(lrt_result_string((lrt_result)(LRT_ERROR_CONTEXT_MISMATCH + 1)), "unknown result code") == 0,
          "the code after the last is unknown");
    /* the cases whose message used to name another problem */
    CHECK(strstr(lrt_result_string(LRT_ERROR_DEPTH_MISMATCH), "format") != NULL &&
              strstr(lrt_result_string(LRT_ERROR_DEPTH_MISMATCH), "back map") != NULL,
          "a back map of another format: %s", lrt_result_string(LRT_ERROR_DEPTH_MISMATCH));
    CHECK(strstr(lrt_result_string(LRT_ERROR_INVALID_THICKNESS), "thickness model") != NULL,
          "thickness model 7: %s", lrt_result_string(LRT_ERROR_INVALID_THICKNESS));
    CHECK(strstr(lrt_result_string(LRT_ERROR_ALREADY_BUILT), "destroy") != NULL, "a rebuild says what to do");
    {
        float d[4] = {0.5f, 0.5f, 0.5f, 0.5f};
        lrt_depth map = {d, 2, 2, 0, LRT_FORMAT_FLOAT32, 0, NULL};
        lrt_build_options opt;
        lrt_bvh bvh = {0};
        memset(&opt, 0, sizeof opt);
        opt.thickness = 7;
        CHECK(lrt_bvh_build(&bvh, &map, &opt, NULL) == LRT_ERROR_INVALID_THICKNESS, "thickness model 7");
    }
}

static void test_perspective(void)
{
    float m[16], before[16];
    lrt_camera cam;
    float n = 0.0f, f = 0.0f;
    const float pi = 3.14159265f;
    int k;
    for (k = 0; k < 16; ++k) before[k] = m[k] = (float)k;
    CHECK(lrt_perspective(m, 0.0f, 1.0f, 0.1f, 100.0f, 0) == LRT_ERROR_INVALID_CAMERA, "fov 0");
    CHECK(lrt_perspective(m, pi, 1.0f, 0.1f, 100.0f, 0) == LRT_ERROR_INVALID_CAMERA, "fov pi");
    CHECK(lrt_perspective(m, 60.0f, 1.0f, 0.1f, 100.0f, 0) == LRT_ERROR_INVALID_CAMERA, "fov 60: degrees, not radians");
    CHECK(lrt_perspective(m, NAN, 1.0f, 0.1f, 100.0f, 0) == LRT_ERROR_INVALID_CAMERA, "fov NaN");
    CHECK(lrt_perspective(m, 1.0f, 0.0f, 0.1f, 100.0f, 0) == LRT_ERROR_INVALID_CAMERA, "aspect 0");
    CHECK(lrt_perspective(m, 1.0f, INFINITY, 0.1f, 100.0f, 0) == LRT_ERROR_INVALID_CAMERA, "aspect infinite");
    CHECK(lrt_perspective(m, 1.0f, 1.0f, 0.0f, 100.0f, 0) == LRT_ERROR_INVALID_CAMERA, "near 0");
    CHECK(lrt_perspective(m, 1.0f, 1.0f, -1.0f, 100.0f, 0) == LRT_ERROR_INVALID_CAMERA, "near < 0");
    CHECK(lrt_perspective(m, 1.0f, 1.0f, 100.0f, 0.1f, 0) == LRT_ERROR_INVALID_CAMERA, "near and far swapped");
    CHECK(lrt_perspective(m, 1.0f, 1.0f, 1.0f, 1.0f, 0) == LRT_ERROR_INVALID_CAMERA, "far on near");
    CHECK(lrt_perspective(m, 1.0f, 1.0f, 0.1f, NAN, 0) == LRT_ERROR_INVALID_CAMERA, "far NaN");
    CHECK(lrt_perspective(m, 1.0f, 1.0f, INFINITY, INFINITY, 0) == LRT_ERROR_INVALID_CAMERA, "near infinite");
    CHECK(lrt_perspective(m, 1.0f, 1.0f, 0.1f, 100.0f, 4) == LRT_ERROR_INVALID_OPTION, "unknown flags");
    CHECK(lrt_perspective(NULL, 1.0f, 1.0f, 0.1f, 100.0f, 0) == LRT_ERROR_NULL_POINTER, "no matrix");
    CHECK(memcmp(m, before, sizeof m) == 0, "a refused projection leaves the matrix alone");
    for (k = 0; k < 2; ++k) {
        const uint32_t flags = k ? (uint32_t)LRT_DEPTH_REVERSED_Z : 0u;
        CHECK(lrt_perspective(m, 1.0f, 1.5f, 0.1f, 100.0f, flags) == LRT_SUCCESS &&
                  lrt_camera_init(&cam, m, 64, 64, flags) == LRT_SUCCESS && lrt_camera_planes(&cam, &n, &f) &&
                  fabsf(n - 0.1f) < 1e-6f && fabsf(f - 100.0f) < 1e-2f,
              "a good projection (flags %u): planes %g %g", flags, n, f);
        CHECK(lrt_perspective(m, 1.0f, 1.5f, 0.1f, INFINITY, flags) == LRT_SUCCESS &&
                  lrt_camera_init(&cam, m, 64, 64, flags) == LRT_SUCCESS && lrt_camera_planes(&cam, &n, &f) &&
                  fabsf(n - 0.1f) < 1e-6f && f == INFINITY,
              "an infinite far plane (flags %u): planes %g %g", flags, n, f);
    }
    /* a perspective matrix of swapped planes, made by hand: refused by camera_init */
    CHECK(lrt_perspective(m, 1.0f, 1.0f, 0.1f, 100.0f, 0) == LRT_SUCCESS, "projection");
    {
        const double nn = 100.0, ff = 0.1; /* swapped */
        m[10] = (float)(ff / (nn - ff));
        m[14] = (float)(nn * ff / (nn - ff));
    }
    CHECK(lrt_camera_init(&cam, m, 64, 64, 0) == LRT_ERROR_INVALID_CAMERA, "camera_init: near and far swapped");
    /* read with the other Z direction it is the reversed projection of
       planes (0.1, 100): valid */
    CHECK(lrt_camera_init(&cam, m, 64, 64, LRT_DEPTH_REVERSED_Z) == LRT_SUCCESS, "camera_init: as reversed Z");
}

static void test_lift(void)
{
    float m[16], from[3] = {0.0f, 0.0f, -5.0f}, to[3] = {1.0f, 0.5f, -6.0f};
    lrt_camera cam;
    lrt_ray plain, lifted;
    const float lift = lrt_surface_lift(0.002f, -0.001f);
    CHECK(lift == 0.5f * (0.002f + 0.001f) * 1.01f + 1e-7f, "the lift is the recipe: %a", lift);
    CHECK(lrt_surface_lift(0.0f, 0.0f) == 1e-7f, "a flat texel's lift");
    CHECK(lrt_perspective(m, 1.0f, 1.0f, 0.1f, 100.0f, 0) == LRT_SUCCESS &&
              lrt_camera_init(&cam, m, 64, 64, 0) == LRT_SUCCESS,
          "camera");
    CHECK(lrt_camera_segment(&cam, from, to, &plain) == 1 &&
              lrt_camera_surface_ray(&cam, from, NULL, to, lift, &lifted) == 1,
          "both rays");
    CHECK(lifted.origin[0] == plain.origin[0] && lifted.origin[1] == plain.origin[1] &&
              lifted.origin[2] == plain.origin[2] - lift && memcmp(lifted.dir, plain.dir, sizeof plain.dir) == 0 &&
              lifted.tmin == 0.0f && lifted.tmax == 1.0f,
          "the surface ray is the segment, lifted");
    { /* a normal facing the eye adds nothing; one turned away (a tangent plane steep on screen) lifts more, at
         most 8 times the lift */
        const float facing[3] = {0.0f, 0.0f, 1.0f}, turned[3] = {0.9950372f, 0.0f, 0.0995037f};
        CHECK(lrt_camera_surface_ray(&cam, from, facing, to, lift, &lifted) == 1 &&
                  lifted.origin[2] == plain.origin[2] - lift,
              "a facing normal: the lift as given");
        const float small = lrt_surface_lift(1e-6f, 0.0f);
        CHECK(lrt_camera_surface_ray(&cam, from, turned, to, small, &lifted) == 1 &&
                  lifted.origin[2] < plain.origin[2] - 2.0f * small &&
                  lifted.origin[2] >= plain.origin[2] - 8.0f * small * 1.0001f,
              "a turned normal: its plane's slope, at most 8 lifts (%g lifts)",
              (plain.origin[2] - lifted.origin[2]) / small);
    }
    from[2] = 5.0f; /* behind the eye, and to it too: no ray */
    to[2] = 6.0f;
    CHECK(lrt_camera_surface_ray(&cam, from, NULL, to, lift, &lifted) == 0 && lifted.origin[0] != lifted.origin[0],
          "no part in front: an invalid ray");
}

int main(int argc, char **argv)
{
    check_select(argc, argv);
    RUN_TEST(test_format_mismatch);
    RUN_TEST(test_life_cycle);
    RUN_TEST(test_back_map_pointer);
    RUN_TEST(test_messages);
    RUN_TEST(test_perspective);
    RUN_TEST(test_lift);
    return check_summary();
}
