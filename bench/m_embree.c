/* bench/m_embree.c - Embree 3 on the CPU as a benchmark peer: the generic
   BVH a user would pick instead of linear_rt, over the very solid of docs/MODEL.md
   as triangles, on the same threads. Method "embree" (exact = 1).

   Built with Embree when the Makefile defines BENCH_HAVE_EMBREE (Debian:
   libembree-dev, <embree3/rtcore.h>, -lembree3); without it the method is
   still listed and its open() says why it cannot run.

   The solid as triangles (docs/MODEL.md: texel (i, j) with depth d is the closed
   box [i, i+1] x [j, j+1] x [d, 1]); its boundary, as a ray from outside
   meets it:
   - each texel's top, z = d, two triangles (kept at d = 1 too: a far-plane
     texel is the face z = 1);
   - the walls between horizontally and vertically adjacent texels whose
     depths differ, from the nearer depth down to the farther (none where
     they are equal);
   - the walls at the screen border x = 0, x = W, y = 0, y = H, from the
     texel's depth to 1 (none for d = 1);
   - the back face z = 1 over the whole screen (two triangles), met only by
     rays coming from behind the far plane.
   Every vertex is exact in float (integer x, y; z a float depth or 1). The
   walls reuse the tops' corner vertices, and each wall's vertical edges also
   carry the depths of the other texels at that corner (the tops' corners
   there), so that walls meeting on a corner line share whole edges: without
   that, a ray through a texel corner slips through the T-junction between
   two coplanar walls of different heights (seen in testing).
   Each triangle stores the texel whose box holds it: a top its own texel, a
   wall the nearer of its two texels (the side that is solid behind it), a
   border wall its texel; the back face none (the texel under the hit point).

   Making Embree answer by the model:
   - invalid rays (NaN/inf component, tmin < 0, tmin > tmax) are flagged
     without calling Embree;
   - a ray whose point at tmin lies in the solid hits at tmin (checked
     exactly: the point is computed with one rounding per component and
     compared with texel edges and depths, which are floats);
   - a miss is told apart by the point at tmax: on the closed rectangle
     [0,W] x [0,H], LRT_MISS_TMAX, else LRT_MISS_OFF_SCREEN (docs/MODEL.md);
   - tfar is tmax moved up by one float ulp, so that a hit exactly at tmax
     (a primary ray on a far-plane texel: t = d = 1 = tmax) is found whatever
     Embree's comparison at tfar; such a hit is reported at tmax;
   - Embree's robust triangle test is conservative: it accepts points about
     1e-7 of a triangle's size outside the triangle, so no ray slips between
     neighbours. A filter function (intersection and occlusion) therefore
     keeps a hit only if its point lies in the closed box of the triangle's
     texel, within the rounding of Embree's t (emb_on_box); without it a ray
     grazing 1.5 ulp above a wall's top edge was reported as hitting it;
   - Embree's box tests take a zero direction component as +1e-18: a ray
     lying exactly in the plane x = W, y = H or z = 1 saw nothing. There the
     component is made a tiny negative number, and the filter judges the ray
     on the same side of the edge (emb_one);
   - a ray far from unit size (|o| > 2^20, max |v| > 2^40 or < 2^-20) is
     restarted next to the screen with its direction scaled by a power of
     two (Embree rejects |o|, |v| above 1.8e18 with an assertion, treats
     components below 1e-18 as 1e-18, and works in float relative to the
     origin). The restart point comes from exact products of floats, so even
     o = -v = 1e18 rays come out right.
   Otherwise rays go to Embree as given (origin, direction, tnear = tmin).
   Known limit: a ray that touches the solid only tangentially at a convex
   vertical corner of a box (e.g. passing exactly through the corner of a
   one-texel pole, or a ray exactly along the diagonal of a checkerboard
   corner) can be missed: there Embree's edge functions round either way and
   both walls at the corner may reject the ray; the model counts the touch.
   Measured: about 1 in 25,000 of the tests' "corner" rays (integer origins,
   directions through lattice points) on noise maps; none on the benchmark's
   workloads and stability cases.

   Closest hit: rtcIntersect1. Any hit (BENCH_ANY_HIT): rtcOccluded1, the
   filter recording the first hit it accepts (primitive and t: the harness
   checks that a reported any-hit is a real hit point), or rtcIntersect1
   when this Embree has no filter functions.

   Build: RTC_SCENE_FLAG_ROBUST, RTC_BUILD_QUALITY_HIGH for the scene and the
   geometry, the device's thread count = the benchmark's ("threads=N").
   update() is a fresh build from the new depths (the set of walls changes
   with the depths, so a refit of the old triangles is not the same solid);
   its time includes making the triangles.
   Memory: Embree 3 has no query for a BVH's size; the bytes are measured
   with rtcSetDeviceMemoryMonitorFunction (Embree reports every allocation
   and free it makes: BVH nodes, primitive blocks, and the vertex and index
   buffers, which it allocates here), net after the commit, plus this file's
   per-triangle texel table (4 bytes a triangle). Checked against the
   process's RSS growth around a build: within 2% (1024x1024 yard: 377 MB). */
#include "bench.h"
#include "march_common.h"

#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef BENCH_HAVE_EMBREE

/* says why the method is skipped: the harness calls nothing else of it */
static int emb_open(bench_method *m, uint32_t w, uint32_t h, int threads, char *why, size_t n)
{
    (void)m;
    (void)w;
    (void)h;
    (void)threads;
    bmc_why(why, n, "Embree 3 is not installed (Debian: libembree-dev)");
    return 1;
}

#else /* BENCH_HAVE_EMBREE */

#include <embree3/rtcore.h>

#define EMB_NO_TEXEL 0xffffffffu /* the back face: the texel under the hit point */

typedef struct emb {
    int threads;
    RTCDevice device;
    RTCScene scene;
    int filter_ok;         /* filter functions are supported (emb_filter) */
    uint32_t *prim_texel;  /* per triangle: the texel (i, j) it bounds, as j << 16 | i */
    size_t prims, prim_cap;
    uint32_t w, h;         /* of the built scene */
    pthread_mutex_t lock;  /* the memory monitor is called from Embree's build threads */
    long long mem_now;     /* bytes Embree holds, net */
    char error[160];       /* Embree's last error message */
} emb;

static void emb_on_error(void *user, enum RTCError code, const char *str)
{
    emb *e = (emb *)user;
    snprintf(e->error, sizeof e->error, "Embree error %d: %s", (int)code, str ? str : "");
}

static void emb_filter(const struct RTCFilterFunctionNArguments *a);

static bool emb_on_memory(void *user, ssize_t bytes, bool post)
{
    emb *e = (emb *)user;
    (void)post;
    pthread_mutex_lock(&e->lock);
    e->mem_now += (long long)bytes;
    pthread_mutex_unlock(&e->lock);
    return true;
}

static int emb_open(bench_method *m, uint32_t w, uint32_t h, int threads, char *why, size_t n)
{
    emb *e = (emb *)m->impl;
    char config[64];
    (void)w;
    (void)h;
    if (e->device) return 0;
    e->threads = threads < 1 ? 1 : threads > BMC_MAX_THREADS ? BMC_MAX_THREADS : threads;
    snprintf(config, sizeof config, "threads=%d", e->threads);
    e->device = rtcNewDevice(config);
    if (!e->device) {
        snprintf(why, n, "rtcNewDevice(\"%s\") failed: %s", config, rtcGetDeviceError(NULL) == RTC_ERROR_UNSUPPORTED_CPU
                                                                        ? "unsupported CPU"
                                                                        : "no device");
        return 1;
    }
    rtcSetDeviceErrorFunction(e->device, emb_on_error, e);
    rtcSetDeviceMemoryMonitorFunction(e->device, emb_on_memory, e);
    e->filter_ok = rtcGetDeviceProperty(e->device, RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED) != 0;
    if (!rtcGetDeviceProperty(e->device, RTC_DEVICE_PROPERTY_TRIANGLE_GEOMETRY_SUPPORTED)) {
        bmc_why(why, n, "this Embree was built without triangles");
        return 1;
    }
    return 0;
}

/* The triangles of the solid's boundary, counted (idx == NULL) or written. */
typedef struct emb_geo {
    const float *D;
    uint32_t W, H;
    unsigned int tb, bb, lb, rb; /* first vertex of the border rows/columns at z = 1 */
    unsigned int *idx;           /* NULL: count only */
    uint32_t *texel;
    size_t nt;
} emb_geo;

static float emb_d(const emb_geo *g, uint32_t i, uint32_t j) { return march_depth(g->D[(size_t)j * g->W + i]); }

/* the vertex of texel (i, j)'s top at its corner (k, m), k in {i, i+1}, m in {j, j+1} */
static unsigned int emb_cv(const emb_geo *g, uint32_t i, uint32_t j, uint32_t k, uint32_t m)
{
    return 4u * (j * g->W + i) + (k - i) + 2u * (m - j);
}

static void emb_tri(emb_geo *g, unsigned int a, unsigned int b, unsigned int c, uint32_t owner)
{
    unsigned int *p = g->idx + 3 * g->nt;
    p[0] = a;
    p[1] = b;
    p[2] = c;
    g->texel[g->nt++] = owner;
}

/* The vertices on the vertical line at the corner (k, m) strictly between
   zlo and zhi: the tops' corners of the (up to 4) texels around it, one per
   depth, ascending. Returns how many (at most 3). */
static int emb_between(const emb_geo *g, uint32_t k, uint32_t m, float zlo, float zhi, unsigned int *v, float *z)
{
    uint32_t i, j;
    int n = 0, q;
    for (j = m > 0 ? m - 1u : 0u; j <= m && j < g->H; ++j)
        for (i = k > 0 ? k - 1u : 0u; i <= k && i < g->W; ++i) {
            const float d = emb_d(g, i, j);
            int dup = 0;
            if (!(d > zlo && d < zhi)) continue;
            for (q = 0; q < n; ++q) dup |= z[q] == d;
            if (dup) continue;
            for (q = n; q > 0 && z[q - 1] > d; --q) {
                z[q] = z[q - 1];
                v[q] = v[q - 1];
            }
            z[q] = d;
            v[q] = emb_cv(g, i, j, k, m);
            ++n;
        }
    return n;
}

/* A wall between the vertical edges at the corners P = (pk, pm) and Q = (qk,
   qm), from zlo (vertices lp, lq) to zhi (hp, hq). Its vertical edges carry
   every corner depth in between (the tops' corners of the other texels
   there), so that neighbouring walls share whole edges and no ray slips
   through a T-junction; triangulated as a ladder between the two edges. */
static void emb_wall(emb_geo *g, uint32_t pk, uint32_t pm, uint32_t qk, uint32_t qm, float zlo, float zhi,
                     unsigned int lp, unsigned int lq, unsigned int hp, unsigned int hq, uint32_t owner)
{
    unsigned int L[5], R[5];
    float zL[5], zR[5];
    int nl, nr, a = 0, b = 0;
    L[0] = lp;
    zL[0] = zlo;
    nl = 1 + emb_between(g, pk, pm, zlo, zhi, L + 1, zL + 1);
    L[nl] = hp;
    zL[nl] = zhi;
    R[0] = lq;
    zR[0] = zlo;
    nr = 1 + emb_between(g, qk, qm, zlo, zhi, R + 1, zR + 1);
    R[nr] = hq;
    zR[nr] = zhi;
    if (!g->idx) {
        g->nt += (size_t)(nl + nr);
        return;
    }
    while (a < nl || b < nr) {
        if (b == nr || (a < nl && zL[a + 1] <= zR[b + 1])) {
            emb_tri(g, L[a], R[b], L[a + 1], owner);
            ++a;
        } else {
            emb_tri(g, L[a], R[b], R[b + 1], owner);
            ++b;
        }
    }
}

/* every triangle: the tops, the walls between texels, the border walls and
   the back face */
static void emb_triangles(emb_geo *g)
{
    const uint32_t W = g->W, H = g->H;
    uint32_t i, j;
    for (j = 0; j < H; ++j)
        for (i = 0; i < W; ++i) {
            const uint32_t t = j << 16 | i; /* the owner code of this texel */
            const float d = emb_d(g, i, j);
            if (g->idx) {
                const unsigned int v = 4u * (j * W + i); /* v+0 (i,j) v+1 (i+1,j) v+2 (i,j+1) v+3 (i+1,j+1), at z = d */
                emb_tri(g, v, v + 1u, v + 3u, t);
                emb_tri(g, v, v + 3u, v + 2u, t);
            } else {
                g->nt += 2;
            }
            if (i + 1 < W) { /* the wall at x = i+1 against (i+1, j), owned by the nearer */
                const float d2 = emb_d(g, i + 1, j);
                const uint32_t a = d < d2 ? i : i + 1u, b = d < d2 ? i + 1u : i;
                if (d != d2)
                    emb_wall(g, i + 1u, j, i + 1u, j + 1u, d < d2 ? d : d2, d < d2 ? d2 : d, emb_cv(g, a, j, i + 1u, j),
                             emb_cv(g, a, j, i + 1u, j + 1u), emb_cv(g, b, j, i + 1u, j), emb_cv(g, b, j, i + 1u, j + 1u),
                             j << 16 | a);
            }
            if (j + 1 < H) { /* the wall at y = j+1 against (i, j+1) */
                const float d2 = emb_d(g, i, j + 1);
                const uint32_t a = d < d2 ? j : j + 1u, b = d < d2 ? j + 1u : j;
                if (d != d2)
                    emb_wall(g, i, j + 1u, i + 1u, j + 1u, d < d2 ? d : d2, d < d2 ? d2 : d, emb_cv(g, i, a, i, j + 1u),
                             emb_cv(g, i, a, i + 1u, j + 1u), emb_cv(g, i, b, i, j + 1u), emb_cv(g, i, b, i + 1u, j + 1u),
                             a << 16 | i);
            }
            if (d < 1.0f) { /* the screen border, from d to 1 */
                if (i == 0)
                    emb_wall(g, 0, j, 0, j + 1u, d, 1.0f, emb_cv(g, i, j, 0, j), emb_cv(g, i, j, 0, j + 1u), g->lb + j,
                             g->lb + j + 1u, t);
                if (i + 1 == W)
                    emb_wall(g, W, j, W, j + 1u, d, 1.0f, emb_cv(g, i, j, W, j), emb_cv(g, i, j, W, j + 1u), g->rb + j,
                             g->rb + j + 1u, t);
                if (j == 0)
                    emb_wall(g, i, 0, i + 1u, 0, d, 1.0f, emb_cv(g, i, j, i, 0), emb_cv(g, i, j, i + 1u, 0), g->tb + i,
                             g->tb + i + 1u, t);
                if (j + 1 == H)
                    emb_wall(g, i, H, i + 1u, H, d, 1.0f, emb_cv(g, i, j, i, H), emb_cv(g, i, j, i + 1u, H), g->bb + i,
                             g->bb + i + 1u, t);
            }
        }
    if (g->idx) { /* the back face z = 1 */
        emb_tri(g, g->tb, g->tb + W, g->bb + W, EMB_NO_TEXEL);
        emb_tri(g, g->tb, g->bb + W, g->bb, EMB_NO_TEXEL);
    } else {
        g->nt += 2;
    }
}

static void emb_release_scene(emb *e)
{
    if (e->scene) rtcReleaseScene(e->scene);
    e->scene = NULL;
}

static int emb_build(bench_method *m, const bench_scene *sc, double *ms, char *why, size_t n)
{
    emb *e = (emb *)m->impl;
    const uint32_t W = sc->width, H = sc->height;
    const float *D = sc->depth;
    if (sc->back) { /* its geometry is the infinite layer's: it would answer another model */
        bmc_why(why, n, "no thickness model: its heightfield geometry reaches the far plane");
        return 1;
    }
    double t0 = bench_now_ms();
    size_t nv, nt;
    uint32_t i, j;
    float *vtx;
    emb_geo geo;
    RTCGeometry g;

    emb_release_scene(e);
    e->error[0] = 0;
    if ((size_t)W * H > (size_t)0x3fffffffu / 4u || W > 65535u || H > 65535u) {
        bmc_why(why, n, "map too large for 32-bit Embree indices");
        return 1;
    }
    memset(&geo, 0, sizeof geo);
    geo.D = D;
    geo.W = W;
    geo.H = H;
    geo.tb = (unsigned int)(4u * (size_t)W * H); /* (i, 0, 1), i = 0..W */
    geo.bb = geo.tb + W + 1u;                    /* (i, H, 1) */
    geo.lb = geo.bb + W + 1u;                    /* (0, j, 1), j = 0..H */
    geo.rb = geo.lb + H + 1u;                    /* (W, j, 1) */
    nv = (size_t)geo.rb + H + 1u;
    emb_triangles(&geo); /* count */
    nt = geo.nt;
    if (nt > e->prim_cap) {
        free(e->prim_texel);
        e->prim_texel = (uint32_t *)malloc(sizeof(uint32_t) * nt);
        e->prim_cap = e->prim_texel ? nt : 0;
        if (!e->prim_texel) {
            bmc_why(why, n, "out of memory");
            return 1;
        }
    }

    g = rtcNewGeometry(e->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!g) {
        snprintf(why, n, "rtcNewGeometry failed (%s)", e->error);
        return 1;
    }
    rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
    vtx = (float *)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv);
    geo.idx = (unsigned int *)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                      3 * sizeof(unsigned int), nt);
    if (!vtx || !geo.idx) {
        rtcReleaseGeometry(g);
        snprintf(why, n, "rtcSetNewGeometryBuffer failed (%s)", e->error);
        return 1;
    }

    /* vertices: 4 per texel (its top's corners), then the border at z = 1 */
    for (j = 0; j < H; ++j)
        for (i = 0; i < W; ++i) {
            const float d = march_depth(D[(size_t)j * W + i]);
            float *p = vtx + 12u * ((size_t)j * W + i);
            p[0] = (float)i;       p[1] = (float)j;       p[2] = d;
            p[3] = (float)(i + 1); p[4] = (float)j;       p[5] = d;
            p[6] = (float)i;       p[7] = (float)(j + 1); p[8] = d;
            p[9] = (float)(i + 1); p[10] = (float)(j + 1); p[11] = d;
        }
    for (i = 0; i <= W; ++i) {
        float *p = vtx + 3u * (geo.tb + i), *q = vtx + 3u * (geo.bb + i);
        p[0] = (float)i; p[1] = 0.0f;     p[2] = 1.0f;
        q[0] = (float)i; q[1] = (float)H; q[2] = 1.0f;
    }
    for (j = 0; j <= H; ++j) {
        float *p = vtx + 3u * (geo.lb + j), *q = vtx + 3u * (geo.rb + j);
        p[0] = 0.0f;     p[1] = (float)j; p[2] = 1.0f;
        q[0] = (float)W; q[1] = (float)j; q[2] = 1.0f;
    }

    /* triangles */
    geo.texel = e->prim_texel;
    geo.nt = 0;
    emb_triangles(&geo);
    e->prims = geo.nt;
    e->w = W;
    e->h = H;

    if (e->filter_ok) {
        rtcSetGeometryIntersectFilterFunction(g, emb_filter);
        rtcSetGeometryOccludedFilterFunction(g, emb_filter);
    }
    rtcCommitGeometry(g);
    e->scene = rtcNewScene(e->device);
    if (!e->scene) {
        rtcReleaseGeometry(g);
        snprintf(why, n, "rtcNewScene failed (%s)", e->error);
        return 1;
    }
    rtcSetSceneFlags(e->scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(e->scene, RTC_BUILD_QUALITY_HIGH);
    rtcAttachGeometry(e->scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(e->scene);
    *ms = bench_now_ms() - t0;
    if (geo.nt != nt || rtcGetDeviceError(e->device) != RTC_ERROR_NONE || e->error[0]) {
        snprintf(why, n, "Embree build failed: %s", e->error[0] ? e->error : "triangle count");
        emb_release_scene(e);
        return 1;
    }
    return 0;
}

static int emb_update(bench_method *m, const bench_scene *sc, double *ms, char *why, size_t n)
{
    return emb_build(m, sc, ms, why, n); /* a fresh build: see the top of the file */
}

typedef struct emb_job {
    const emb *e;
    const float *depth;
    const lrt_ray *rays;
    lrt_hit *hits;
    int any;
} emb_job;

/* The ray as Embree is given it, and what the filter needs to judge a hit. */
typedef struct emb_context {
    struct RTCIntersectContext ctx; /* first: Embree hands this pointer back to the filter */
    const emb_job *jb;
    double o[3], v[3];              /* origin and direction given to Embree */
    int side[3];                    /* an axis the ray does not move along: +1 it counts as just above o, -1 just below; else 0 */
    unsigned int prim;              /* any hit: the first hit accepted */
    float t;
    int found;
} emb_context;

/* The texel of an edge coordinate o of a ray that does not move along this
   axis: the cell [i, i+1) holding o + 0 (side +1) or (i, i+1] holding o - 0
   (side -1), clamped to the map. */
static uint32_t emb_cell(double o, int side, uint32_t n)
{
    double f = side < 0 ? ceil(o) - 1.0 : floor(o);
    return f < 0.0 ? 0u : f >= (double)n ? n - 1u : (uint32_t)f;
}

/* Is Embree's hit at t on triangle prim a point of the texel box that the
   triangle bounds? Embree's robust triangle test is conservative (it accepts
   points about 1e-7 of a triangle's size outside its edges, so that no ray
   slips between neighbours); this test is the model's: the hit point p = o +
   t v (one rounding per component, from Embree's float t) must lie in the
   closed box, within 2^-20 |t v_c| for the rounding of t. Along an axis the
   ray does not move, the cell is half-open on the side Embree's traversal
   takes it to be (a zero direction counts as +0 or -0 there: see emb_one),
   so a ray exactly on a texel edge sees one column or row, consistently. */
static int emb_on_box(const emb_context *c, unsigned int prim, float t, uint32_t *ti, uint32_t *tj)
{
    const emb *e = c->jb->e;
    const uint32_t n[2] = {e->w, e->h};
    uint32_t cell[2], tx;
    double lo_z;
    int k;
    if (prim >= e->prims) return 0;
    tx = e->prim_texel[prim];
    if (tx == EMB_NO_TEXEL) { /* the back face z = 1: the texel under the point */
        for (k = 0; k < 2; ++k)
            cell[k] = c->side[k] ? emb_cell(c->o[k], c->side[k], n[k]) : march_texel(c->o[k] + (double)t * c->v[k], n[k]);
        lo_z = 0.0;
    } else {
        cell[0] = tx & 0xffffu;
        cell[1] = tx >> 16;
        lo_z = (double)march_depth(c->jb->depth[(size_t)cell[1] * e->w + cell[0]]);
    }
    for (k = 0; k < 3; ++k) {
        const double tv = (double)t * c->v[k], p = c->o[k] + tv;
        const double lo = k < 2 ? (double)cell[k] : lo_z, hi = k < 2 ? (double)cell[k] + 1.0 : 1.0;
        if (c->side[k] && k < 2) {
            if (c->side[k] < 0 ? !(p > lo && p <= hi) : !(p >= lo && p < hi)) {
                /* the far edge of the map belongs to its last cell */
                if (!(c->side[k] > 0 && p == hi && cell[k] + 1u == n[k])) return 0;
            }
        } else {
            const double tol = fabs(tv) * 0x1p-20 + fabs(c->o[k]) * 0x1p-50;
            if (!(p >= lo - tol && p <= hi + tol)) return 0;
        }
    }
    *ti = cell[0];
    *tj = cell[1];
    return 1;
}

/* Embree's filter for both queries: keep only hits on the model's boxes */
static void emb_filter(const struct RTCFilterFunctionNArguments *a)
{
    emb_context *c = (emb_context *)a->context;
    unsigned int i, prim;
    float t;
    uint32_t ti, tj;
    for (i = 0; i < a->N; ++i) {
        if (!a->valid[i]) continue;
        /* the SOA layouts of RTCHitN and RTCRayN (rtcore_ray.h; its accessors
           are C++ only): primID is hit field 5, tfar is ray field 8 and holds
           the hit distance while the filter runs */
        memcpy(&prim, (const unsigned char *)a->hit + sizeof(unsigned int) * (5u * a->N + i), sizeof prim);
        memcpy(&t, (const unsigned char *)a->ray + sizeof(float) * (8u * a->N + i), sizeof t);
        if (!emb_on_box(c, prim, t, &ti, &tj)) {
            a->valid[i] = 0;
            continue;
        }
        if (!c->found) {
            c->prim = prim;
            c->t = t;
            c->found = 1;
        }
    }
}

/* docs/MODEL.md: is the point o + tmin v inside the solid? (closed boxes: on an
   edge or a corner every texel around it is tried) */
static int emb_inside(const emb_job *jb, const lrt_ray *r, uint32_t *ti, uint32_t *tj)
{
    const uint32_t W = jb->e->w, H = jb->e->h;
    const double x = march_at(r->origin[0], r->dir[0], r->tmin), y = march_at(r->origin[1], r->dir[1], r->tmin),
                 z = march_at(r->origin[2], r->dir[2], r->tmin);
    double fx, fy;
    uint32_t i0, i1, j0, j1, i, j;
    if (!(x >= 0.0 && x <= (double)W && y >= 0.0 && y <= (double)H && z <= 1.0)) return 0;
    fx = floor(x);
    fy = floor(y);
    i1 = fx >= (double)W ? W - 1u : (uint32_t)fx;
    j1 = fy >= (double)H ? H - 1u : (uint32_t)fy;
    i0 = (x == fx && fx > 0.0) ? (uint32_t)fx - 1u : i1;
    j0 = (y == fy && fy > 0.0) ? (uint32_t)fy - 1u : j1;
    for (j = j0; j <= j1; ++j)
        for (i = i0; i <= i1; ++i)
            if (z >= (double)march_depth(jb->depth[(size_t)j * W + i])) {
                *ti = i;
                *tj = j;
                return 1;
            }
    return 0;
}

/* Embree takes |origin|, |direction| up to about 1.8e18 (larger ones fail its
   ray.valid() assertion), treats direction components below 1e-18 as +1e-18
   in its box tests, and works relative to the origin in float: a ray from
   far off the screen, or with a direction far from unit size, is restarted
   next to the screen with its direction scaled by a power of two. */
static int emb_restart(const lrt_ray *r)
{
    float vmax = 0.0f;
    int k;
    for (k = 0; k < 3; ++k) {
        if (fabsf(r->origin[k]) > 1048576.0f) return 1;
        if (fabsf(r->dir[k]) > vmax) vmax = fabsf(r->dir[k]);
    }
    return vmax > 1099511627776.0f || vmax < 1.0f / 1048576.0f; /* 2^40, 2^-20 */
}

static void emb_one(const emb_job *jb, const lrt_ray *r, lrt_hit *hit)
{
    const emb *e = jb->e;
    const uint32_t n[3] = {e->w, e->h, 1u};
    float org[3], dir[3], tnear, tfar, vmax = 0.0f;
    double t_base = 0.0, t_scale = 1.0, t;
    emb_context c;
    uint32_t ti, tj;
    int k;
    if (!march_ray_valid(r)) {
        march_set_miss(hit, LRT_MISS_INVALID_RAY);
        return;
    }
    if (emb_inside(jb, r, &ti, &tj)) {
        hit->t = r->tmin;
        hit->x = ti;
        hit->y = tj;
        hit->kind = LRT_HIT;
        hit->face = LRT_FACE_NONE; /* not reported by this peer */
        return;
    }
    if (r->tmin == r->tmax || (r->dir[0] == 0.0f && r->dir[1] == 0.0f && r->dir[2] == 0.0f)) {
        march_set_miss(hit, march_miss_kind(r, e->w, e->h)); /* the ray is its point at tmin: not in the solid */
        return;
    }
    if (emb_restart(r)) {
        /* restart one unit before the screen box on the axis a the ray moves
           fastest along, at the plane x_a = P: the other coordinates are
           (o_b v_a - o_a v_b + P v_b) / v_a, from products of floats (exact
           in double), so they come out right to a few ulps even when o and
           v are huge and cancel; or at tmin if that is later. The direction
           is scaled by a power of two to [0.5, 1). */
        double t0, t1, vm = 0.0, ts, te, plane, tp;
        int ex, ax = 0;
        if (!march_clip(r, e->w, e->h, &t0, &t1)) {
            march_set_miss(hit, march_miss_kind(r, e->w, e->h));
            return;
        }
        for (k = 0; k < 3; ++k)
            if (fabs((double)r->dir[k]) > vm) {
                vm = fabs((double)r->dir[k]);
                ax = k;
            }
        (void)frexp(vm, &ex);
        plane = r->dir[ax] > 0.0f ? -1.0 : (double)n[ax] + 1.0;
        tp = (plane - (double)r->origin[ax]) / (double)r->dir[ax];
        if (tp > (double)r->tmin) {
            const double va = r->dir[ax], oa = r->origin[ax];
            ts = tp;
            for (k = 0; k < 3; ++k)
                org[k] = k == ax ? (float)plane
                                 : (float)(((double)r->origin[k] * va - oa * (double)r->dir[k] + plane * (double)r->dir[k]) / va);
        } else {
            ts = r->tmin;
            for (k = 0; k < 3; ++k) org[k] = (float)march_at(r->origin[k], r->dir[k], r->tmin);
        }
        for (k = 0; k < 3; ++k) dir[k] = (float)ldexp((double)r->dir[k], -ex);
        /* the end: the restarted ray's own exit from the screen box, one unit
           on (t - ts would cancel where t is huge), or tmax if sooner */
        {
            lrt_ray q;
            double q0, q1;
            memcpy(q.origin, org, sizeof q.origin);
            memcpy(q.dir, dir, sizeof q.dir);
            q.tmin = 0.0f;
            q.tmax = FLT_MAX;
            te = ldexp((double)r->tmax - ts, ex);
            if (!march_clip(&q, e->w, e->h, &q0, &q1) || te < 0.0) {
                march_set_miss(hit, march_miss_kind(r, e->w, e->h));
                return;
            }
            if (q1 + 2.0 < te) te = q1 + 2.0; /* |dir| >= 0.5 on the axis a: one unit or more */
        }
        t_base = ts;
        t_scale = ldexp(1.0, -ex);
        tnear = 0.0f;
        tfar = nextafterf((float)te, INFINITY);
    } else {
        for (k = 0; k < 3; ++k) {
            org[k] = r->origin[k];
            dir[k] = r->dir[k];
        }
        tnear = r->tmin;
        tfar = nextafterf(r->tmax, INFINITY);
    }
    /* An axis the ray does not move along: Embree's box tests take a zero
       component as +1e-18, so the ray counts as lying just above its
       coordinate there, and a ray exactly on a node's far plane (the border
       x = W, y = H, z = 1 of the whole scene) would see nothing. There the
       component is made a tiny negative number instead (it moves the ray by
       far less than an ulp over its length); emb_on_box takes the same side. */
    for (k = 0; k < 3; ++k)
        if (fabsf(dir[k]) > vmax) vmax = fabsf(dir[k]);
    rtcInitIntersectContext(&c.ctx);
    c.jb = jb;
    c.found = 0;
    c.prim = 0;
    c.t = 0.0f;
    for (k = 0; k < 3; ++k) {
        c.side[k] = 0;
        if (dir[k] == 0.0f) {
            c.side[k] = org[k] >= (float)n[k] ? -1 : 1;
            dir[k] = 0.0f;
            if (c.side[k] < 0) {
                float tiny = ldexpf(vmax, -40);
                dir[k] = -(tiny > 2e-18f ? tiny : 2e-18f);
            }
        }
        c.o[k] = org[k];
        c.v[k] = c.side[k] ? 0.0 : (double)dir[k];
    }
    if (jb->any && e->filter_ok) {
        struct RTCRay ray;
        ray.org_x = org[0];
        ray.org_y = org[1];
        ray.org_z = org[2];
        ray.tnear = tnear;
        ray.dir_x = dir[0];
        ray.dir_y = dir[1];
        ray.dir_z = dir[2];
        ray.time = 0.0f;
        ray.tfar = tfar;
        ray.mask = 0xffffffffu;
        ray.id = 0;
        ray.flags = 0;
        rtcOccluded1(e->scene, &c.ctx, &ray);
        if (!c.found) {
            march_set_miss(hit, march_miss_kind(r, e->w, e->h));
            return;
        }
    } else {
        struct RTCRayHit rh;
        rh.ray.org_x = org[0];
        rh.ray.org_y = org[1];
        rh.ray.org_z = org[2];
        rh.ray.tnear = tnear;
        rh.ray.dir_x = dir[0];
        rh.ray.dir_y = dir[1];
        rh.ray.dir_z = dir[2];
        rh.ray.time = 0.0f;
        rh.ray.tfar = tfar;
        rh.ray.mask = 0xffffffffu;
        rh.ray.id = 0;
        rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(e->scene, &c.ctx, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
            march_set_miss(hit, march_miss_kind(r, e->w, e->h));
            return;
        }
        c.prim = rh.hit.primID;
        c.t = rh.ray.tfar;
    }
    if (!emb_on_box(&c, c.prim, c.t, &ti, &tj)) { /* only without filter functions */
        ti = march_texel(c.o[0] + (double)c.t * c.v[0], e->w);
        tj = march_texel(c.o[1] + (double)c.t * c.v[1], e->h);
    }
    t = t_base + (double)c.t * t_scale;
    hit->t = (float)t;
    if (!(hit->t <= r->tmax)) hit->t = r->tmax; /* found within the one ulp above tmax */
    if (hit->t < r->tmin) hit->t = r->tmin;
    hit->x = ti;
    hit->y = tj;
    hit->kind = LRT_HIT;
    hit->face = LRT_FACE_NONE; /* not reported by this peer */
}

static void emb_range(void *ctx, size_t first, size_t end)
{
    const emb_job *jb = (const emb_job *)ctx;
    size_t q;
    for (q = first; q < end; ++q) emb_one(jb, &jb->rays[q], &jb->hits[q]);
}

static int emb_trace(bench_method *m, const bench_scene *sc, const bench_rays *rs, lrt_hit *hits, double *ms,
                     char *why, size_t n)
{
    emb *e = (emb *)m->impl;
    emb_job jb;
    double t0;
    if (!e->scene || e->w != sc->width || e->h != sc->height) {
        bmc_why(why, n, "Embree: trace before build, or the scene changed size");
        return 1;
    }
    jb.e = e;
    jb.depth = sc->depth;
    jb.rays = rs->rays;
    jb.hits = hits;
    jb.any = (rs->flags & BENCH_ANY_HIT) != 0;
    t0 = bench_now_ms();
    (void)bmc_parallel(emb_range, &jb, rs->count, e->threads);
    *ms = bench_now_ms() - t0;
    return 0;
}

static size_t emb_memory(bench_method *m)
{
    emb *e = (emb *)m->impl;
    long long b;
    pthread_mutex_lock(&e->lock);
    b = e->mem_now;
    pthread_mutex_unlock(&e->lock);
    return (b > 0 ? (size_t)b : 0u) + e->prims * sizeof(uint32_t);
}

static void emb_close(bench_method *m)
{
    emb *e = (emb *)m->impl;
    if (!e) return;
    emb_release_scene(e);
    if (e->device) rtcReleaseDevice(e->device);
    free(e->prim_texel);
    pthread_mutex_destroy(&e->lock);
    free(e);
    m->impl = NULL;
}

#endif /* BENCH_HAVE_EMBREE */

int bench_add_embree(bench_method *out, int max)
{
    if (max < 1) return 0;
    memset(&out[0], 0, sizeof out[0]);
    out[0].name = "embree";
    out[0].device = "cpu";
    out[0].exact = 1;
#ifdef BENCH_HAVE_EMBREE
    {
        emb *e = (emb *)calloc(1, sizeof *e);
        if (!e) return 0;
        if (pthread_mutex_init(&e->lock, NULL) != 0) {
            free(e);
            return 0;
        }
        e->threads = 1;
        out[0].impl = e;
    }
    BENCH_METHOD_FUNCTIONS(out[0], emb);
#else
    out[0].open = emb_open;
#endif
    return 1;
}
