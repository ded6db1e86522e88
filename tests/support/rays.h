/* tests/support/rays.h - what the tests trace: depth maps of many shapes in every
   format, each with its exact reference twin (tests/support/reference.h), and rays
   of every kind docs/MODEL.md names, from one deterministic random sequence.
   Shared by tests/test_core.c (the CPU path) and tests/test_vulkan.c (the
   kernels). Include after linear_rt.h, reference.h and examples/scene.h;
   everything is static, for one test file. */
#ifndef LINEAR_RT_TESTS_RAYS_H
#define LINEAR_RT_TESTS_RAYS_H

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* not every test that includes this file uses all of it */
#if defined(__GNUC__) || defined(__clang__)
#define RAYS_MAYBE_UNUSED __attribute__((unused))
#else
#define RAYS_MAYBE_UNUSED
#endif

/* ---- deterministic random numbers ---------------------------------------- */
static uint64_t g_rng = 0x9e3779b97f4a7c15ull;
static uint32_t rnd(void)
{
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 7;
    g_rng ^= g_rng << 17;
    return (uint32_t)(g_rng >> 16);
}
static float rndf(void) { return (float)(rnd() & 0xffffff) / 16777216.0f; } /* [0,1) */
static int rndi(int n) { return (int)(rnd() % (uint32_t)n); }

/* ---- a depth map in any format, with its reference twin ------------------ */
typedef struct test_map {
    lrt_depth depth;
    void *storage;
    ref_map ref;
    const char *name;
    /* with a back map (add_back): pair[0] is depth with its back at pair[1],
       the back map, for LRT_THICKNESS_BACK_MAP trees (the struct must not move) */
    lrt_depth pair[2];
    void *back_storage;
    /* the tree's thickness model and its parameters (add_back, add_model) */
    lrt_build_options model;
} test_map;

enum { SHAPE_NOISE, SHAPE_TERRACES, SHAPE_SCENE, SHAPE_POLES, SHAPE_FAR, SHAPE_WILD, SHAPE_COUNT };
static const char *shape_names[SHAPE_COUNT] = {"noise", "terraces", "scene", "poles", "far", "wild"};

/* depth value in [0,1] of texel (i,j) for a shape (float model units) */
static float shape_depth(int shape, int i, int j, int w, int h, const float *scene)
{
    switch (shape) {
    case SHAPE_NOISE: return rndf();
    case SHAPE_TERRACES: { /* flat camera-facing steps of 8-bit depth */
        float d = 0.3f + 0.5f * (float)(i / 5 + j / 7) / (float)(w / 5 + h / 7 + 1);
        return floorf(d * 255.0f) / 255.0f;
    }
    case SHAPE_SCENE: return scene[(size_t)j * (size_t)w + (size_t)i];
    case SHAPE_POLES: return ((i % 13) == 5 || (j % 11 == 3 && i % 3 == 0)) ? 0.2f + 0.01f * (float)(i % 7) : 0.95f;
    case SHAPE_FAR: return 1.0f;
    default: return rndf();
    }
}

/* depth d (0..1 for unorm formats) as a texel of the format: unorm rounded, float as it is */
static void put_texel(unsigned char *p, lrt_format format, float d)
{
    if (format == LRT_FORMAT_UNORM8) {
        p[0] = (unsigned char)(d * 255.0f + 0.5f);
    } else if (format == LRT_FORMAT_UNORM16) {
        uint16_t v = (uint16_t)(d * 65535.0f + 0.5f);
        memcpy(p, &v, 2);
    } else {
        memcpy(p, &d, 4);
    }
}

static void make_map(test_map *m, int w, int h, int shape, lrt_format format, int reversed, int padded)
{
    uint32_t bpp = format == LRT_FORMAT_UNORM8 ? 1 : format == LRT_FORMAT_UNORM16 ? 2 : 4;
    size_t stride = (size_t)w * bpp + (padded ? 3 : 0); /* odd stride: unaligned rows */
    unsigned char *bytes;
    float *scene = NULL;
    int i, j;
    memset(m, 0, sizeof *m);
    if (shape == SHAPE_SCENE) {
        scene_camera cam = scene_default_camera();
        scene = (float *)malloc(sizeof(float) * (size_t)w * (size_t)h);
        scene_render(w, h, &cam, scene, NULL);
    }
    bytes = (unsigned char *)malloc(stride * (size_t)h + 1);
    for (j = 0; j < h; ++j) {
        for (i = 0; i < w; ++i) {
            float d = shape_depth(shape, i, j, w, h, scene);
            unsigned char *p = bytes + 1 + stride * (size_t)j + (size_t)i * bpp; /* +1: unaligned data */
            if (reversed) d = 1.0f - d;
            if (format == LRT_FORMAT_FLOAT32 && shape == SHAPE_WILD) { /* values the model clamps */
                int r = rndi(10);
                if (r == 0) d = NAN;
                else if (r == 1) d = 1.5f;
                else if (r == 2) d = -0.25f;
                else if (r == 3) d = INFINITY;
            }
            put_texel(p, format, d);
        }
    }
    free(scene);
    m->storage = bytes;
    m->depth.data = bytes + 1;
    m->depth.width = (uint32_t)w;
    m->depth.height = (uint32_t)h;
    m->depth.row_stride = padded ? stride : 0;
    m->depth.format = format;
    m->depth.flags = reversed ? LRT_DEPTH_REVERSED_Z : 0u;
    m->name = shape_names[shape];
    if (ref_map_from_raw(&m->ref, m->depth.data, w, h, stride, (int)format, reversed) != 0) {
        printf("reference could not convert the map\n");
        exit(2);
    }
}

static void free_map(test_map *m)
{
    free(m->storage);
    free(m->back_storage);
    ref_map_free(&m->ref);
}

/* A back map for m, in m's format, stride and Z direction: each texel's
   depth plus a thickness of 0 to 0.2 (thin slabs and thick ones), with
   some backs in front of the depth (the model clamps them) and, in float,
   some NaN and above-1 values. Sets m->pair and the reference's back. */
RAYS_MAYBE_UNUSED static void add_back(test_map *m)
{
    const lrt_format format = m->depth.format;
    const int w = (int)m->depth.width, h = (int)m->depth.height, reversed = (m->depth.flags & LRT_DEPTH_REVERSED_Z) != 0;
    const uint32_t bpp = format == LRT_FORMAT_UNORM8 ? 1 : format == LRT_FORMAT_UNORM16 ? 2 : 4;
    const size_t stride = m->depth.row_stride ? m->depth.row_stride + 2 : (size_t)w * bpp; /* a stride of its own */
    unsigned char *bytes = (unsigned char *)malloc(stride * (size_t)h);
    int i, j;
    for (j = 0; j < h; ++j) {
        for (i = 0; i < w; ++i) {
            const double d = m->ref.d[(size_t)j * (size_t)w + (size_t)i];
            const int r = rndi(16);
            float b = (float)(d + (r < 2 ? -0.05 : r < 8 ? 0.004 * rndf() : 0.2 * rndf()));
            unsigned char *p = bytes + stride * (size_t)j + (size_t)i * bpp;
            if (b < 0.0f) b = 0.0f;
            if (b > 1.0f) b = 1.0f;
            if (reversed) b = 1.0f - b;
            if (format == LRT_FORMAT_FLOAT32 && r == 15) b = rndi(2) ? NAN : 1.5f;
            put_texel(p, format, b);
        }
    }
    m->back_storage = bytes;
    m->pair[0] = m->depth;
    m->pair[0].back = &m->pair[1];
    m->pair[1] = m->depth;
    m->pair[1].data = bytes;
    m->pair[1].row_stride = m->depth.row_stride ? stride : 0;
    m->model.thickness = LRT_THICKNESS_BACK_MAP;
    if (ref_map_set_back_from_raw(&m->ref, bytes, stride, (int)format, reversed) != 0) {
        printf("reference could not convert the back map\n");
        exit(2);
    }
}

/* A constant (thickness LRT_THICKNESS_CONSTANT) or relative thickness
   model for m, under a perspective projection with planes near_z, far_z:
   the tree is built with it (test_map_options) and the reference computes
   its own back depths from docs/MODEL.md's definition. */
RAYS_MAYBE_UNUSED static void add_model(test_map *m, uint32_t thickness, float value, float near_z, float far_z)
{
    int r;
    m->model.thickness = thickness;
    m->model.thickness_value = value;
    m->model.near_z = near_z;
    m->model.far_z = far_z;
    r = thickness == LRT_THICKNESS_CONSTANT ? ref_map_set_back_constant(&m->ref, value, near_z, far_z)
                                            : ref_map_set_back_relative(&m->ref, value, near_z, far_z);
    if (r != 0) {
        printf("reference could not make the thickness model\n");
        exit(2);
    }
}

/* The model's name, for messages. */
RAYS_MAYBE_UNUSED static const char *model_name(const test_map *m)
{
    static const char *names[4] = {"", " back map", " constant thickness", " relative thickness"};
    return m->model.thickness < 4 ? names[m->model.thickness] : " ?";
}

/* The maps to build, update and trace m with: the pair with a back map. */
/* An lrt_depth over data: w x h texels of `format`, packed rows, standard
   Z, no back map; a test sets what else it needs. */
RAYS_MAYBE_UNUSED static lrt_depth packed_depth(const void *data, uint32_t w, uint32_t h, lrt_format format)
{
    lrt_depth d = {0}; /* row_stride 0: packed; flags 0: standard Z; no back */
    d.data = data;
    d.width = w;
    d.height = h;
    d.format = format;
    return d;
}

RAYS_MAYBE_UNUSED static const lrt_depth *test_map_depth(const test_map *m)
{
    return m->back_storage ? m->pair : &m->depth;
}

/* ---- rays the fuzzer found wrong once (tests/fuzz/crashes-found/README.md) ---- */
/* Case k's map and ray; 0 past the last case. The answer is the reference's.
   Not every test that includes this file runs them. */
RAYS_MAYBE_UNUSED static int found_case(int k, test_map *m, lrt_ray *r)
{
    static const struct {
        int w, h, format;
        float fill;                     /* every texel, as a float depth or a unorm v */
        int sx[2], sy[2];               /* up to two other texels (-1: none) */
        float sv[2];
        float o[3], v[3], tmin, tmax;
    } c[] = {
        /* a ray through two texel corners: the first, (6,7) at t = 3.2, was skipped */
        {16, 16, 3, 1.0f, {6, 9}, {7, 11}, {0.168f, 0.2f}, {0, 0, 0}, {1.875f, 2.5f, 0.05859375f}, 0, 12},
        /* unorm depth and an origin far in front of the near plane: o.z * 65535 overflowed */
        {1, 1, 2, 1000, {-1, -1}, {-1, -1}, {0, 0}, {0.5f, 0.5f, -1e34f}, {0, 0, 0}, 0, 1},
        {1, 1, 1, 100, {-1, -1}, {-1, -1}, {0, 0}, {0.5f, 0.5f, -1e37f}, {0, 0, 0}, 0, 1},
        /* ... and through the restart of a far-away ray */
        {1, 1, 1, 100, {-1, -1}, {-1, -1}, {0, 0}, {1.25f, 1.25f, -1577}, {-7.5f, -7.5f, -1e38f}, 0, 1},
        {1, 1, 2, 1000, {-1, -1}, {-1, -1}, {0, 0}, {1.25f, 1.25f, -1577}, {-7.5f, -7.5f, -1e38f}, 0, 1},
        /* directions below 2^-128 were rescaled by an infinite t_scale: a hit with t = NaN, or at tmax */
        {1, 1, 3, 0.5f, {-1, -1}, {-1, -1}, {0, 0}, {0.5f, 0.5f, 0.6f}, {1e-39f, 0, 0}, 0, FLT_MAX},
        {1, 1, 3, 0.5f, {-1, -1}, {-1, -1}, {0, 0}, {0.5f, 0.5f, 0.0f}, {0, 0, 2e-39f}, 0, FLT_MAX},
        /* tmax = FLT_MAX: the widened exit must not overflow into a hit never met */
        {1, 1, 3, 0.5f, {-1, -1}, {-1, -1}, {0, 0}, {0.5f, 0.5f, 0.0f}, {0, 0, 0}, 0, FLT_MAX},
        {62, 16, 1, 200, {-1, -1}, {-1, -1}, {0, 0}, {15.25f, 3.75f, 0.0f}, {0, 0, 0}, 0, FLT_MAX},
        {8, 8, 3, 0.5f, {-1, -1}, {-1, -1}, {0, 0}, {0.5f, 0.5f, 0.0f}, {1, 1, 0}, 0, FLT_MAX},
        /* the restart of a far-away ray dropped a coordinate 2^120 times smaller (y 4.4e-30 above the edge) */
        {64, 1, 3, 1.0f, {59, -1}, {0, -1}, {0.002f, 0}, {3.97868e31f, 4.36341e-30f, 0.0629892f},
         {-4.31355e36f, -2.17651e-38f, -0.304688f}, 0, 11.25f},
        /* ... and a direction component 2^120 times smaller than the largest (y enters the screen at 1e-43) */
        {64, 1, 3, 1.0f, {59, -1}, {0, -1}, {0.002f, 0}, {3.97868e31f, -1e-43f, 0.0629892f},
         {-4.31355e36f, 2.17651e-38f, -0.304688f}, 0, 11.25f},
        /* the restart of a ray from far left on the far plane, going up by 8e-17: rounded onto the far plane, it hit (0,0) */
        {18, 1, 1, 255, {7, -1}, {0, -1}, {0, 0}, {-378.72f, 0.5f, 1.0f}, {4.125f, 0, -8.67361738e-19f}, 0, 200},
        /* a tiny direction rescaled: tmin = tmax = 2.4e-38 became [0, 0], on the far plane (a hit; exact: behind it) */
        {1, 1, 3, 1.0f, {-1, -1}, {-1, -1}, {0, 0}, {1.4387588e-33f, 4.83930017e-38f, 1.0f},
         {2.36942783e-38f, 2.36942783e-38f, 2.36942783e-38f}, 2.36942783e-38f, 2.36942783e-38f},
        /* a subnormal v.z beside a normal v.x: 1/v.z = inf, the far plane's (1 - 1) * inf = NaN was dropped (a hit) */
        {18, 18, 3, 1.0f, {-1, -1}, {-1, -1}, {0, 0}, {6.5f, 0.25f, 1.0f}, {1.875f, -2.9891144e-20f, 5.3809861e-42f},
         0.234375f, 0.234375f},
        /* ... the same kind of v.y next to an origin 2^-130 above the screen's edge: it leaves the screen at t = 32, after
           (10,0) and before (40,0) (an inverse of +-FLT_MAX would leave at once, one of inf never) */
        {64, 1, 3, 1.0f, {10, -1}, {0, -1}, {0, 0}, {0.5f, 7.34683969e-40f, 0.5f}, {1, -2.2958874e-41f, 0}, 0, 100},
        {64, 1, 3, 1.0f, {40, -1}, {0, -1}, {0, 0}, {0.5f, 7.34683969e-40f, 0.5f}, {1, -2.2958874e-41f, 0}, 0, 100},
        /* ... and a v.z of 2^-140 from z = 0 over depths of 2^-130: met at t = 1024, not at once nor never */
        {2048, 1, 3, 7.34683969e-40f, {-1, -1}, {-1, -1}, {0, 0}, {0.5f, 0.5f, 0}, {1, 0, 7.17464814e-43f}, 0, 4000},
        /* crossings below 2^-149 rounded to 0: off the screen by 1e-38 at t = 0 (a tmax miss), in front of a texel top
           by 1e-38 at t = 0 (a hit), leaving the screen at t = -2e-46 (a hit at t = 0), a depth of 2^-140 met at
           t = 2^-150 from z = 0 (a hit at t = 0) */
        {35, 1, 1, 0, {-1, -1}, {-1, -1}, {0, 0}, {5, -1.18010406e-38f, -1.18010406e-38f}, {-16, 2.26832694e+23f, 0}, 0, 0},
        {192, 164, 3, 0.0f, {-1, -1}, {-1, -1}, {0, 0}, {147.5f, 82, -1.18010406e-38f}, {-16, -16, 2.47903617e+38f}, 0, 0},
        {5, 5, 3, 1.0f, {-1, -1}, {-1, -1}, {0, 0}, {-3.64337601e-44f, 6.39020126e-41f, 1.0f},
         {-82.7632828f, 4.03814645e-38f, 7.81393798e-37f}, 0, FLT_MAX},
        {1, 1, 3, 7.17464814e-43f, {-1, -1}, {-1, -1}, {0, 0}, {0.5f, 0.5f, 0}, {0, 0, 1024}, 0, 0},
        /* (the soak) a huge ray that touches the screen only at its corner (0,0), at z = 0: the entering planes of x and
           z rounded to the same t, the restart took x and landed 2^20 away, where the exits' widening spans texels (a hit) */
        {258, 1, 3, 0.5f, {-1, -1}, {-1, -1}, {0, 0}, {8.10612714e+16f, 2.95147888e+20f, -2.95147905e+20f},
         {-8.10612714e+16f, -2.95147888e+20f, 2.95147905e+20f}, 0, 2},
        /* (the soak) the same kind of ray, x slow beside y and z: a second restart from 2^23 away rounded y, and x met
           0 at x = 1.5e-5 instead of at the corner, inside texel (0,0) for a t of 0.2 (a hit; exact: off-screen) */
        {489, 270, 1, 1, {-1, -1}, {-1, -1}, {0, 0}, {1.92934496e+26f, -2.5353012e+30f, -2.5353012e+30f},
         {-1.92934496e+26f, 2.5353012e+30f, 2.5353012e+30f}, 0, 2},
        /* (fuzz_core, crashes-found 19) a far-away ray whose restart switched axes three times (z, whose crossing put
           y a float above the screen; y; x) and kept x's crossing as its origin with z's t: a hit in the right texel
           at t = 1.7e-13 for 1.03e-13 */
        {2, 3, 2, 32639, {-1, -1}, {-1, -1}, {0, 0}, {2.25f, 3, -7.31282984e+12f}, {-7.31282984e+12f, -5.5f, 7.0847792e+25f},
         0, 7.0847792e+25f},
        /* (made for devices that flush subnormals) a direction of 2^127, which the rare set-up scales by 2^-127, a
           subnormal factor that FTZ and DAZ read as 0, meeting a raised texel at t = 2.06e-38 (a hit at a normal t) */
        {32, 1, 3, 0.9f, {4, -1}, {0, -1}, {0.1f, 0}, {0.5f, 0.5f, 0.5f}, {1.70141183e+38f, 0, 0}, 0, 5e-38f},
        /* (fuzz_core, crashes-found 21) a rare ray entering the screen box through the near plane onto a texel of
           depth 0: its depth plane's t, rounded, came an ulp before the near plane's, and the hit was told INSIDE */
        {64, 64, 2, 65535, {27, -1}, {27, -1}, {0, 0}, {32, 32, -1.18010406e-38f}, {-16, -16, 4.68780747e-38f}, 0,
         35460327931904.0f},
        /* (fuzz_core, crashes-found 22) a ray from far in front with v.z = 2^85, restarted at the near plane: the
           restart's y, exactly 5.7e-13 below the screen's edge y = 3, rounded twice to an ulp above it, off the
           screen for good; exact: the far plane's flat box of texel (164,2) at t = 1.03e-13 */
        {199, 3, 3, 1.0f, {-1, -1}, {-1, -1}, {0, 0}, {165.25f, 3, -7.31282984e+12f}, {-7.31282984e+12f, -5.5f, 7.0847792e+25f},
         0, 2.08202948e-13f},
    };
    size_t n, i, bpp;
    int q;
    if (k < 0 || k >= (int)(sizeof c / sizeof c[0])) return 0;
    memset(m, 0, sizeof *m);
    bpp = c[k].format == 1 ? 1 : c[k].format == 2 ? 2 : 4;
    n = (size_t)c[k].w * (size_t)c[k].h;
    m->storage = malloc(n * bpp);
    if (!m->storage) exit(2);
    for (i = 0; i < n; ++i) {
        int x = (int)(i % (size_t)c[k].w), y = (int)(i / (size_t)c[k].w);
        float v = c[k].fill;
        for (q = 0; q < 2; ++q)
            if (c[k].sx[q] == x && c[k].sy[q] == y) v = c[k].sv[q];
        if (bpp == 1) ((uint8_t *)m->storage)[i] = (uint8_t)v;
        else if (bpp == 2) ((uint16_t *)m->storage)[i] = (uint16_t)v;
        else ((float *)m->storage)[i] = v;
    }
    m->depth.data = m->storage;
    m->depth.width = (uint32_t)c[k].w;
    m->depth.height = (uint32_t)c[k].h;
    m->depth.format = (lrt_format)c[k].format;
    m->name = "fuzz-found";
    if (ref_map_from_raw(&m->ref, m->storage, c[k].w, c[k].h, 0, c[k].format, 0) != 0) exit(2);
    for (q = 0; q < 3; ++q) {
        r->origin[q] = c[k].o[q];
        r->dir[q] = c[k].v[q];
    }
    r->tmin = c[k].tmin;
    r->tmax = c[k].tmax;
    return 1;
}

/* ---- ray kinds -------------------------------------------------------------- */
enum {
    RAY_PRIMARY, RAY_SEGMENT, RAY_REFLECT, RAY_GRAZING, RAY_EDGE, RAY_CORNER, RAY_INSIDE, RAY_LEAVING,
    RAY_POINT, RAY_ZERO_DIR, RAY_HUGE, RAY_INVALID, RAY_SHORT, RAY_KIND_COUNT
};
RAYS_MAYBE_UNUSED static const char *ray_names[RAY_KIND_COUNT] = {"primary", "segment", "reflect", "grazing", "edge", "corner",
                                                "inside", "leaving", "tmin==tmax", "v=0", "huge", "invalid", "short"};

static float depth_at(const test_map *m, int i, int j) { return (float)m->ref.d[(size_t)j * (size_t)m->ref.w + (size_t)i]; }

static lrt_ray make_ray(const test_map *m, int kind)
{
    const int w = m->ref.w, h = m->ref.h;
    lrt_ray r;
    int i = rndi(w), j = rndi(h);
    float d = depth_at(m, i, j);
    memset(&r, 0, sizeof r);
    r.tmin = 0.0f;
    r.tmax = 1.0f;
    switch (kind) {
    case RAY_PRIMARY:
        r.origin[0] = (float)i + 0.5f; r.origin[1] = (float)j + 0.5f; r.origin[2] = 0.0f;
        r.dir[2] = 1.0f;
        break;
    case RAY_SEGMENT: { /* random segment across the screen ending a little behind the surface */
        int i1 = rndi(w), j1 = rndi(h);
        float z0 = d * rndf(), z1 = depth_at(m, i1, j1) + 0.05f * rndf();
        r.origin[0] = (float)i + rndf(); r.origin[1] = (float)j + rndf(); r.origin[2] = z0;
        r.dir[0] = (float)i1 + rndf() - r.origin[0]; r.dir[1] = (float)j1 + rndf() - r.origin[1]; r.dir[2] = z1 - z0;
        break;
    }
    case RAY_REFLECT: { /* from the surface, towards the camera a little, across the screen */
        float a = 6.2831853f * rndf(), len = 4.0f + rndf() * (float)(w > h ? w : h);
        r.origin[0] = (float)i + 0.5f; r.origin[1] = (float)j + 0.5f; r.origin[2] = d;
        r.dir[0] = cosf(a) * len; r.dir[1] = sinf(a) * len; r.dir[2] = -0.3f * d * rndf();
        r.tmin = 0.75f / len; /* leave the own texel first: the examples' policy */
        break;
    }
    case RAY_GRAZING: /* almost level with a texel top */
        r.origin[0] = (float)i + rndf(); r.origin[1] = (float)j + rndf(); r.origin[2] = d - 1e-6f * rndf();
        r.dir[0] = (rndf() - 0.5f) * (float)w; r.dir[1] = (rndf() - 0.5f) * (float)h;
        r.dir[2] = (rnd() & 1) ? 0.0f : 1e-5f * (rndf() - 0.5f);
        break;
    case RAY_EDGE: /* along a cell edge */
        if (rnd() & 1) {
            r.origin[0] = (float)rndi(w + 1); r.origin[1] = rndf() * (float)h; r.dir[1] = (rndf() - 0.5f) * (float)h;
        } else {
            r.origin[1] = (float)rndi(h + 1); r.origin[0] = rndf() * (float)w; r.dir[0] = (rndf() - 0.5f) * (float)w;
        }
        r.origin[2] = rndf(); r.dir[2] = (rndf() - 0.3f) * 0.5f;
        break;
    case RAY_CORNER: { /* through texel corners: integer origin, diagonal-ish direction */
        int sx = (rnd() & 1) ? 1 : -1, sy = (rnd() & 1) ? 1 : -1, k = 1 + rndi(3);
        r.origin[0] = (float)rndi(w + 1); r.origin[1] = (float)rndi(h + 1); r.origin[2] = rndf() * 0.9f;
        r.dir[0] = (float)(sx * k * 4); r.dir[1] = (float)(sy * 4 * (1 + rndi(2))); r.dir[2] = (rndf() - 0.2f) * 0.2f;
        r.tmax = (float)(1 + rndi(8));
        break;
    }
    case RAY_INSIDE:
        r.origin[0] = (float)i + rndf(); r.origin[1] = (float)j + rndf(); r.origin[2] = d + (1.0f - d) * rndf();
        r.dir[0] = rndf() - 0.5f; r.dir[1] = rndf() - 0.5f; r.dir[2] = rndf() - 0.5f;
        r.tmin = rndf();
        r.tmax = r.tmin + rndf();
        break;
    case RAY_LEAVING: /* over everything, out through an edge of the screen */
        r.origin[0] = (float)i + rndf(); r.origin[1] = (float)j + rndf(); r.origin[2] = 0.0f;
        r.dir[0] = (rndf() - 0.5f) * 4.0f * (float)w; r.dir[1] = (rndf() - 0.5f) * 4.0f * (float)h; r.dir[2] = 1e-4f * rndf();
        r.tmax = 2.0f;
        break;
    case RAY_POINT: /* tmin == tmax */
        r.origin[0] = (float)i + rndf(); r.origin[1] = (float)j + rndf(); r.origin[2] = rndf();
        r.dir[0] = rndf() - 0.5f; r.dir[1] = rndf() - 0.5f; r.dir[2] = rndf() - 0.5f;
        r.tmin = r.tmax = rndf();
        break;
    case RAY_ZERO_DIR:
        r.origin[0] = (rnd() & 3) ? (float)i + rndf() : (float)(rndi(w + 1)); r.origin[1] = (float)j + rndf();
        r.origin[2] = (rnd() & 1) ? d : rndf();
        if ((rnd() & 7) == 0) r.origin[0] = -1.0f - rndf();
        break;
    case RAY_HUGE: {
        float big = ldexpf(1.0f, 20 + rndi(100));
        float a = 6.2831853f * rndf();
        r.origin[0] = (float)i + 0.5f - cosf(a) * big; r.origin[1] = (float)j + 0.5f - sinf(a) * big;
        r.origin[2] = (rnd() & 1) ? -big : 0.0f;
        r.dir[0] = cosf(a) * big; r.dir[1] = sinf(a) * big; r.dir[2] = (r.origin[2] != 0.0f) ? big + rndf() : rndf();
        r.tmin = 0.0f; r.tmax = (rnd() & 1) ? 2.0f : FLT_MAX;
        if (rnd() & 1) { /* huge time instead of huge direction */
            r.origin[0] = (float)i + rndf(); r.origin[1] = (float)j + rndf(); r.origin[2] = 0.0f;
            r.dir[0] = (rndf() - 0.5f) * 1e-30f; r.dir[1] = (rndf() - 0.5f) * 1e-30f; r.dir[2] = 1e-31f;
            r.tmax = 3e38f;
        }
        break;
    }
    case RAY_INVALID: {
        int which = rndi(7);
        r.origin[0] = (float)i; r.origin[1] = (float)j; r.dir[2] = 1.0f;
        if (which == 0) r.origin[rndi(3)] = NAN;
        else if (which == 1) r.dir[rndi(3)] = INFINITY;
        else if (which == 2) r.tmin = -1e-3f;
        else if (which == 3) { r.tmin = 2.0f; r.tmax = 1.0f; }
        else if (which == 4) r.tmax = NAN;
        else if (which == 5) r.tmax = INFINITY;
        else r.dir[rndi(3)] = -NAN;
        break;
    }
    default: /* short AO-like ray */
        r.origin[0] = (float)i + 0.5f; r.origin[1] = (float)j + 0.5f; r.origin[2] = d - 1e-3f;
        r.dir[0] = (rndf() - 0.5f) * 16.0f; r.dir[1] = (rndf() - 0.5f) * 16.0f; r.dir[2] = -rndf() * 0.05f;
        break;
    }
    return r;
}

RAYS_MAYBE_UNUSED static ref_answer to_answer(const lrt_hit *h)
{
    ref_answer a;
    a.kind = (int)h->kind;
    a.t = h->t;
    a.x = (int)h->x;
    a.y = (int)h->y;
    a.face = (int)h->face;
    return a;
}

/* ---- frames for update tests: a floor and a sphere that moves in and out ---- */
RAYS_MAYBE_UNUSED static void paint_frame(float *d, int w, int h, int frame)
{
    int i, j;
    float cx = (float)(w / 4 + (frame * 7) % (w / 2 + 1)), cy = (float)(h / 3 + (frame * 5) % (h / 3 + 1));
    float r = 6.0f + (float)(frame % 5);
    for (j = 0; j < h; ++j)
        for (i = 0; i < w; ++i) {
            float dx = (float)i - cx, dy = (float)j - cy, q = dx * dx + dy * dy;
            float v = 0.7f + 0.2f * (float)j / (float)h; /* a floor */
            if (q < r * r) v = 0.3f + 0.001f * sqrtf(q); /* a sphere that moves in and out */
            d[(size_t)j * (size_t)w + (size_t)i] = v;
        }
}

/* The smallest rectangle holding every texel that differs between two
   frames (empty, at the origin, when none does): the dirty rect an engine
   would pass to an update. */
RAYS_MAYBE_UNUSED static lrt_rect changed_rect(const float *prev, const float *d, int w, int h)
{
    int i, j, x0 = w, y0 = h, x1 = -1, y1 = -1;
    lrt_rect rect;
    for (j = 0; j < h; ++j)
        for (i = 0; i < w; ++i)
            if (d[(size_t)j * w + i] != prev[(size_t)j * w + i]) {
                x0 = i < x0 ? i : x0; x1 = i > x1 ? i : x1;
                y0 = j < y0 ? j : y0; y1 = j > y1 ? j : y1;
            }
    if (x1 < 0) { x0 = y0 = 0; x1 = y1 = -1; }
    rect.x = (uint32_t)x0; rect.y = (uint32_t)y0;
    rect.width = (uint32_t)(x1 - x0 + 1); rect.height = (uint32_t)(y1 - y0 + 1);
    return rect;
}

#endif /* LINEAR_RT_TESTS_RAYS_H */
