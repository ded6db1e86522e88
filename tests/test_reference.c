/* tests/test_reference.c - self-test of the exact reference tracer
   (tests/support/reference.h) on hand-made cases with known answers, plus a
   cross-check against an all-texel scan and against dense sampling.

   gcc -std=c99 -O2 -Wall -Wextra -Wpedantic -Werror tests/test_reference.c -o /tmp/test_reference -lm
   g++ -x c++ -std=c++11 -O2 -Wall -Wextra -Werror tests/test_reference.c -o /tmp/test_reference_cpp -lm
*/
#include "support/reference.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"

/* ------------------------------------------------------------ helpers -- */

static ref_map map_const(int w, int h, double d)
{
    ref_map m;
    int k;
    m.w = w;
    m.h = h;
    m.d = (double *)malloc((size_t)w * (size_t)h * sizeof(double));
    m.b = NULL; /* infinite thickness */
    for (k = 0; k < w * h; k++) m.d[k] = d;
    return m;
}

/* the same back depth (as float32 raw input) for every texel of m */
static void set_back_const(ref_map *m, float back)
{
    float *f = (float *)malloc((size_t)m->w * (size_t)m->h * sizeof(float));
    int k;
    for (k = 0; k < m->w * m->h; k++) f[k] = back;
    CHECK(ref_map_set_back_from_raw(m, f, 0, REF_FORMAT_FLOAT32, 0) == 0, "set_back %g", (double)back);
    free(f);
}

static void set_d(ref_map *m, int i, int j, double d) { m->d[j * m->w + i] = d; }

static ref_ray mkray(double ox, double oy, double oz, double vx, double vy, double vz,
                     double tmin, double tmax)
{
    ref_ray r;
    r.o[0] = (float)ox; r.o[1] = (float)oy; r.o[2] = (float)oz;
    r.v[0] = (float)vx; r.v[1] = (float)vy; r.v[2] = (float)vz;
    r.tmin = (float)tmin; r.tmax = (float)tmax;
    return r;
}

static ref_result tr(const ref_map *m, ref_ray r) { return ref_trace_ray(m, &r); }

static int near_t(double got, double want)
{
    return fabs(got - want) <= 1e-12 * (1 + fabs(want));
}

#define EXPECT_HIT(res, tt, xx, yy)                                                     \
    CHECK((res).kind == REF_HIT && near_t((res).t, (tt)) && (res).x == (xx) &&          \
              (res).y == (yy),                                                          \
          "expected hit t=%.17g (%d,%d), got kind %d t=%.17g (%d,%d)", (double)(tt),    \
          (xx), (yy), (res).kind, (res).t, (res).x, (res).y)

#define EXPECT_KIND(res, k)                                                             \
    CHECK((res).kind == (k), "expected kind %d, got kind %d t=%.17g (%d,%d)", (k),      \
          (res).kind, (res).t, (res).x, (res).y)

static ref_answer ans(int kind, double t, int x, int y)
{
    ref_answer a;
    a.kind = kind; a.t = (float)t; a.x = x; a.y = y; a.face = REF_FACE_ANY;
    return a;
}

/* ----------------------------------------------------------- the cases -- */

static void test_one_texel(void)
{
    ref_map m = map_const(1, 1, 0.5);
    ref_result r;
    r = tr(&m, mkray(0.5, 0.5, 0, 0, 0, 1, 0, 1));
    EXPECT_HIT(r, 0.5, 0, 0);
    r = tr(&m, mkray(0.5, 0.5, 0, 0, 0, 1, 0, 0.25));
    EXPECT_KIND(r, REF_MISS_TMAX);
    /* the whole interval off the screen */
    r = tr(&m, mkray(2, 2, 0, 1, 0, 0, 0, 1));
    EXPECT_KIND(r, REF_MISS_OFF_SCREEN);
    /* on the screen edge x = 1 (closed): still in the footprint */
    r = tr(&m, mkray(1, 0.5, 0, 0, 0, 1, 0, 1));
    EXPECT_HIT(r, 0.5, 0, 0);
    /* corner of the screen */
    r = tr(&m, mkray(0, 1, 0, 0, 0, 1, 0, 1));
    EXPECT_HIT(r, 0.5, 0, 0);
    /* tmin == tmax, point in the solid */
    r = tr(&m, mkray(0.5, 0.5, 0, 0, 0, 1, 0.75, 0.75));
    EXPECT_HIT(r, 0.75, 0, 0);
    ref_map_free(&m);
}

static void test_floor_primary(void)
{
    int w = 13, h = 7, i, j;
    ref_map m = map_const(w, h, 0);
    for (j = 0; j < h; j++)
        for (i = 0; i < w; i++) set_d(&m, i, j, (double)((i * 7 + j * 3) % 17) / 16.0);
    set_d(&m, 3, 2, 1.0);
    set_d(&m, 4, 2, 0.0);
    for (j = 0; j < h; j++)
        for (i = 0; i < w; i++) {
            ref_result r = tr(&m, mkray(i + 0.5, j + 0.5, 0, 0, 0, 1, 0, 1));
            EXPECT_HIT(r, m.d[j * w + i], i, j);
        }
    /* 8-bit depths (not dyadic): t = d exactly as the double */
    {
        unsigned char px[6] = { 0, 1, 77, 128, 254, 255 };
        ref_map m8;
        CHECK(ref_map_from_raw(&m8, px, 3, 2, 0, REF_FORMAT_UNORM8, 0) == 0, "from_raw 8");
        for (j = 0; j < 2; j++)
            for (i = 0; i < 3; i++) {
                ref_result r = tr(&m8, mkray(i + 0.5, j + 0.5, 0, 0, 0, 1, 0, 1));
                EXPECT_HIT(r, px[j * 3 + i] / 255.0, i, j);
            }
        ref_map_free(&m8);
    }
    ref_map_free(&m);
}

static void test_inside_and_surface(void)
{
    ref_map m = map_const(4, 4, 0.5);
    ref_result r;
    /* starts inside the solid */
    r = tr(&m, mkray(1.5, 1.5, 0.8, 1, 0.25, -1, 0, 10));
    EXPECT_HIT(r, 0, 1, 1);
    r = tr(&m, mkray(1.5, 1.5, 0.8, 1, 0.25, -1, 0.125, 10));
    EXPECT_HIT(r, 0.125, 1, 1); /* at t=0.125: (1.625, 1.53, 0.675) */
    /* starts on its own surface, going deeper or going up: closed box */
    r = tr(&m, mkray(1.5, 1.5, 0.5, 1, 0, 0.1, 0, 10));
    EXPECT_HIT(r, 0, 1, 1);
    r = tr(&m, mkray(1.5, 1.5, 0.5, 1, 0, -0.1, 0, 10));
    EXPECT_HIT(r, 0, 1, 1);
    /* starts on the surface going up, tmin past the texel: flat floor,
       leaves the screen above it */
    r = tr(&m, mkray(1.5, 1.5, 0.5, 1, 0, -0.1, 1, 10));
    EXPECT_KIND(r, REF_MISS_OFF_SCREEN);
    /* starts above, comes down onto the floor */
    r = tr(&m, mkray(0.5, 0.5, 0.25, 1, 1, 0.125, 0, 10));
    EXPECT_HIT(r, 2, 2, 2);
    ref_map_free(&m);
}

static void test_miss_kinds(void)
{
    ref_map m = map_const(4, 4, 1.0);
    ref_result r;
    /* z stays 0.25: no hit */
    r = tr(&m, mkray(0.5, 0.5, 0.25, 1, 0, 0, 0, 2));
    EXPECT_KIND(r, REF_MISS_TMAX);
    r = tr(&m, mkray(0.5, 0.5, 0.25, 1, 0, 0, 0, 3.5)); /* ends on x = 4 exactly */
    EXPECT_KIND(r, REF_MISS_TMAX);
    r = tr(&m, mkray(0.5, 0.5, 0.25, 1, 0, 0, 0, 3.5000002));
    EXPECT_KIND(r, REF_MISS_OFF_SCREEN);
    r = tr(&m, mkray(0.5, 0.5, 0.25, 1, 0, 0, 0, 10));
    EXPECT_KIND(r, REF_MISS_OFF_SCREEN);
    r = tr(&m, mkray(0.5, 0.5, 0.25, 1, 0, 0, 0, FLT_MAX));
    EXPECT_KIND(r, REF_MISS_OFF_SCREEN);
    /* whole interval off the screen, starting on screen earlier: tmin past */
    r = tr(&m, mkray(0.5, 0.5, 0.25, 1, 0, 0, 5, 6));
    EXPECT_KIND(r, REF_MISS_OFF_SCREEN);
    /* comes from off the screen, ends on it */
    r = tr(&m, mkray(-3, 0.5, 0.25, 1, 0, 0, 0, 4));
    EXPECT_KIND(r, REF_MISS_TMAX);
    /* behind the far plane and staying on the screen: z plays no part */
    r = tr(&m, mkray(0.5, 0.5, 1.5, 1, 0, 0.5, 0, 2));
    EXPECT_KIND(r, REF_MISS_TMAX);
    /* in front of the near plane */
    r = tr(&m, mkray(0.5, 0.5, -1, 1, 1, -0.5, 0, 2));
    EXPECT_KIND(r, REF_MISS_TMAX);
    ref_map_free(&m);
}

static void test_zero_direction(void)
{
    ref_map m = map_const(2, 1, 0.9);
    ref_result r;
    set_d(&m, 1, 0, 0.3);
    r = tr(&m, mkray(0.5, 0.5, 0.95, 0, 0, 0, 0.25, 7));
    EXPECT_HIT(r, 0.25, 0, 0);
    r = tr(&m, mkray(0.5, 0.5, 0.5, 0, 0, 0, 0.25, 7));
    EXPECT_KIND(r, REF_MISS_TMAX);
    r = tr(&m, mkray(5, 0.5, 0.95, 0, 0, 0, 0, 1));
    EXPECT_KIND(r, REF_MISS_OFF_SCREEN);
    r = tr(&m, mkray(0.5, 0.5, 1.5, 0, 0, 0, 0, 1)); /* behind the far plane */
    EXPECT_KIND(r, REF_MISS_TMAX);
    /* on the edge x = 1 between d = 0.9 and d = 0.3: only texel 1 holds z=0.5 */
    r = tr(&m, mkray(1, 0.5, 0.5, 0, 0, 0, 2, 3));
    EXPECT_HIT(r, 2, 1, 0);
    /* on the far-plane face of the screen, on the screen corner */
    r = tr(&m, mkray(2, 1, 1, 0, 0, 0, 0, 0));
    EXPECT_HIT(r, 0, 1, 0);
    ref_map_free(&m);
}

static void test_invalid(void)
{
    ref_map m = map_const(2, 2, 0.5);
    double nan = strtod("nan", NULL), inf = HUGE_VAL;
    ref_result r;
    int c;
    for (c = 0; c < 8; c++) {
        double vals[8] = { 0.5, 0.5, 0, 0, 0, 1, 0, 1 };
        vals[c] = nan;
        r = tr(&m, mkray(vals[0], vals[1], vals[2], vals[3], vals[4], vals[5], vals[6], vals[7]));
        EXPECT_KIND(r, REF_MISS_INVALID);
        vals[c] = inf;
        r = tr(&m, mkray(vals[0], vals[1], vals[2], vals[3], vals[4], vals[5], vals[6], vals[7]));
        EXPECT_KIND(r, REF_MISS_INVALID);
        vals[c] = -inf;
        r = tr(&m, mkray(vals[0], vals[1], vals[2], vals[3], vals[4], vals[5], vals[6], vals[7]));
        EXPECT_KIND(r, REF_MISS_INVALID);
    }
    r = tr(&m, mkray(0.5, 0.5, 0, 0, 0, 1, -1e-30, 1));
    EXPECT_KIND(r, REF_MISS_INVALID);
    r = tr(&m, mkray(0.5, 0.5, 0, 0, 0, 1, 0.6, 0.5));
    EXPECT_KIND(r, REF_MISS_INVALID);
    r = tr(&m, mkray(0.5, 0.5, 0, 0, 0, 1, -0.0, 1)); /* -0 is not < 0 */
    EXPECT_HIT(r, 0.5, 0, 0);
    ref_map_free(&m);
}

static void test_edges_and_corners(void)
{
    ref_result r;
    {
        /* columns: x in [0,1] near (0.3), x in [1,2] far (0.8) */
        ref_map m = map_const(2, 2, 0.8);
        set_d(&m, 0, 0, 0.3);
        set_d(&m, 0, 1, 0.3);
        r = tr(&m, mkray(1, 0.5, 0, 0, 0, 1, 0, 1));
        EXPECT_HIT(r, 0.3, 0, 0);
        r = tr(&m, mkray(1, 0.125, 0, 0, 0.5, 1, 0, 1)); /* along the edge x = 1 */
        EXPECT_HIT(r, 0.3, 0, 0);
        r = tr(&m, mkray(1, 1.875, 0, 0, -0.5, 1, 0, 1));
        EXPECT_HIT(r, 0.3, 0, 1);
        ref_map_free(&m);
    }
    {
        /* along the edge y = 1 between rows 0 and 1 */
        ref_map m = map_const(4, 2, 1.0);
        set_d(&m, 2, 0, 0.4);
        r = tr(&m, mkray(0.5, 1, 0.5, 1, 0, 0, 0, 10));
        EXPECT_HIT(r, 1.5, 2, 0);
        r = tr(&m, mkray(3.5, 1, 0.5, -1, 0, 0, 0, 10));
        EXPECT_HIT(r, 0.5, 2, 0);
        r = tr(&m, mkray(0.5, 1.0000001, 0.5, 1, 0, 0, 0, 10)); /* just above: misses */
        EXPECT_KIND(r, REF_MISS_OFF_SCREEN);
        ref_map_free(&m);
    }
    {
        /* 2x2, only (1,0) near: the diagonal y = x touches it at the corner */
        ref_map m = map_const(2, 2, 1.0);
        set_d(&m, 1, 0, 0.2);
        r = tr(&m, mkray(0.5, 0.5, 0.5, 1, 1, 0, 0, 10));
        EXPECT_HIT(r, 0.5, 1, 0);
        r = tr(&m, mkray(1.5, 1.5, 0.5, -1, -1, 0, 0, 10));
        EXPECT_HIT(r, 0.5, 1, 0);
        /* one ulp off the corner on the other side: misses */
        r = tr(&m, mkray(0.5, nextafterf(0.5f, 1.0f), 0.5, 1, 1, 0, 0, 10));
        EXPECT_KIND(r, REF_MISS_OFF_SCREEN);
        /* one ulp below: enters the near texel through its left side at t = 0.5 */
        r = tr(&m, mkray(0.5, nextafterf(0.5f, 0.0f), 0.5, 1, 1, 0, 0, 10));
        EXPECT_HIT(r, 0.5, 1, 0);
        /* one ulp right: enters it a little before the corner */
        r = tr(&m, mkray(nextafterf(0.5f, 1.0f), 0.5, 0.5, 1, 1, 0, 0, 10));
        CHECK(r.kind == REF_HIT && r.x == 1 && r.y == 0 && r.t < 0.5 && r.t > 0.4999999,
              "ulp below corner: kind %d t %.17g (%d,%d)", r.kind, r.t, r.x, r.y);
        /* the other diagonal through the same corner: from (0,1) to (1,0) */
        r = tr(&m, mkray(0.5, 1.5, 0.5, 1, -1, 0, 0, 10));
        EXPECT_HIT(r, 0.5, 1, 0);
        ref_map_free(&m);
    }
    {
        /* a corner touched by a ray crossing the other diagonal: (0,1) -> (1,0)
           touches (0,0) only at the corner (1,1) */
        ref_map m = map_const(2, 2, 1.0);
        set_d(&m, 0, 0, 0.2);
        r = tr(&m, mkray(0.5, 1.5, 0.5, 1, -1, 0, 0, 10));
        EXPECT_HIT(r, 0.5, 0, 0);
        /* and a shallow ray (walk along x) through the same corner:
           (0, 1.5) + 0.5 * (2, -1) = (1, 1) */
        r = tr(&m, mkray(0, 1.5, 0.5, 2, -1, 0, 0, 10));
        EXPECT_HIT(r, 0.5, 0, 0);
        /* and a steep one (walk along y): (0.75, 2) + 0.25 * (1, -4) = (1, 1) */
        r = tr(&m, mkray(0.75, 2, 0.5, 1, -4, 0, 0, 10));
        EXPECT_HIT(r, 0.25, 0, 0);
        ref_map_free(&m);
    }
    {
        /* corner with a steep ray (walk along y) */
        ref_map m = map_const(3, 3, 1.0);
        set_d(&m, 2, 0, 0.1);
        /* steep ray (walk along y) entering (2,0) through its corner (2,1):
           (1, 3) + 1 * (1, -2) = (2, 1) */
        r = tr(&m, mkray(1, 3, 0.5, 1, -2, 0, 0, 10));
        EXPECT_HIT(r, 1, 2, 0);
        ref_map_free(&m);
    }
}

static void test_far_plane(void)
{
    ref_map m = map_const(3, 3, 1.0);
    ref_result r;
    r = tr(&m, mkray(0.5, 0.5, 0, 0, 0, 2, 0, 1));
    EXPECT_HIT(r, 0.5, 0, 0);
    r = tr(&m, mkray(0.5, 0.5, 0, 0, 0, 2, 0, 0.4));
    EXPECT_KIND(r, REF_MISS_TMAX);
    r = tr(&m, mkray(0.5, 0.5, 0, 1, 1, 0.5, 0, 10)); /* z = 1 at t = 2: (2.5, 2.5) */
    EXPECT_HIT(r, 2, 2, 2);
    r = tr(&m, mkray(0.5, 0.5, 0, 1, 1, 0.25, 0, 10)); /* z = 1 at t = 4: off screen */
    EXPECT_KIND(r, REF_MISS_OFF_SCREEN);
    ref_map_free(&m);
}

static void test_huge(void)
{
    ref_map m = map_const(8, 8, 1.0);
    ref_result r;
    float big = 1e30f;
    set_d(&m, 5, 3, 0.25);
    r = tr(&m, mkray(big, 3.5, 0.5, -big, 0, 0, 0, 2));
    EXPECT_HIT(r, (6.0 - (double)big) / (-(double)big), 5, 3);
    r = tr(&m, mkray(-big, 3.5, 0.5, big, 0, 0, 0, 2));
    EXPECT_HIT(r, 1.0, 5, 3);
    r = tr(&m, mkray(FLT_MAX, 3.5, 0.5, -FLT_MAX, 0, 0, 0, 2));
    EXPECT_HIT(r, 1.0, 5, 3);
    r = tr(&m, mkray(FLT_MAX, 3.5, 0.5, -FLT_MAX, 0, 0, 0, FLT_MAX));
    EXPECT_HIT(r, 1.0, 5, 3);
    /* y = x diagonal through the texel corners, huge: misses (5,3) */
    r = tr(&m, mkray(big, big, 0.5, -big, -big, 0, 0, 2));
    EXPECT_KIND(r, REF_MISS_OFF_SCREEN);
    r = tr(&m, mkray(big, big, 0.5, -big, -big, 0, 0, 1));
    EXPECT_KIND(r, REF_MISS_TMAX); /* ends at (0,0) exactly */
    set_d(&m, 4, 4, 0.25);
    r = tr(&m, mkray(big, big, 0.5, -big, -big, 0, 0, 2));
    EXPECT_HIT(r, 1.0, 4, 4);
    /* huge and almost along the edge y = 3: y = 3 + 0.5 x / 1e30 runs above
       row 2 and touches it only at x = 0 (t = 1); double arithmetic on
       t = (plane - o) / v cannot tell these apart, exact predicates can */
    {
        ref_map m2 = map_const(8, 8, 1.0);
        set_d(&m2, 5, 2, 0.25);
        r = tr(&m2, mkray(big, 3.5, 0.5, -big, -0.5, 0, 0, 2));
        EXPECT_KIND(r, REF_MISS_OFF_SCREEN);
        set_d(&m2, 0, 2, 0.25);
        r = tr(&m2, mkray(big, 3.5, 0.5, -big, -0.5, 0, 0, 2));
        EXPECT_HIT(r, 1.0, 0, 2);
        set_d(&m2, 6, 3, 0.25); /* row 3 is crossed at x in [6,7] */
        r = tr(&m2, mkray(big, 3.5, 0.5, -big, -0.5, 0, 0, 2));
        EXPECT_HIT(r, 1.0, 6, 3);
        ref_map_free(&m2);
    }
    /* off the screen, huge */
    r = tr(&m, mkray(big, big, 0, big, 0, 0, 0, FLT_MAX));
    EXPECT_KIND(r, REF_MISS_OFF_SCREEN);
    r = tr(&m, mkray(-big, -big, -big, -big, -big, -big, 0, FLT_MAX));
    EXPECT_KIND(r, REF_MISS_OFF_SCREEN);
    /* coming in through the near plane from huge negative z */
    r = tr(&m, mkray(4.5, 4.5, -big, 0, 0, big, 0, 2));
    EXPECT_HIT(r, 1.0, 4, 4);
    /* tiny direction, huge t; a subnormal one reads as 0 (docs/MODEL.md) */
    {
        ref_map m1 = map_const(1, 1, 1e-7);
        float tiny = FLT_MIN, sub = nextafterf(0.0f, 1.0f);
        r = tr(&m1, mkray(0.5, 0.5, 0, tiny, 0, tiny, 0, FLT_MAX));
        EXPECT_HIT(r, 1e-7 / (double)tiny, 0, 0);
        r = tr(&m1, mkray(0.5, 0.5, 0, tiny, 0, tiny, 0, 1e30));
        EXPECT_KIND(r, REF_MISS_TMAX);
        r = tr(&m1, mkray(0.5, 0.5, 0, sub, 0, sub, 0, FLT_MAX));
        EXPECT_KIND(r, REF_MISS_TMAX);
        r = tr(&m1, mkray(0.5, 0.5, 0.5, sub, 0, -sub, 0, FLT_MAX));
        EXPECT_HIT(r, 0.0, 0, 0);
        ref_map_free(&m1);
    }
    ref_map_free(&m);
}

/* float texels the model clamps: in range, NaN, above 1, below 0, inf, -inf, -0 */
static void float_cases(float f[8])
{
    f[0] = 0.25f;
    f[1] = (float)strtod("nan", NULL);
    f[2] = 2.0f;
    f[3] = -1.0f;
    f[4] = 0.1f;
    f[5] = (float)HUGE_VAL;
    f[6] = -(float)HUGE_VAL;
    f[7] = -0.0f;
}

static void test_from_raw(void)
{
    ref_map m;
    {
        unsigned char px[4] = { 0, 255, 128, 51 };
        CHECK(ref_map_from_raw(&m, px, 2, 2, 0, REF_FORMAT_UNORM8, 0) == 0, "8-bit");
        CHECK(m.w == 2 && m.h == 2 && m.d[0] == 0 && m.d[1] == 1 && m.d[2] == 128.0 / 255.0 &&
                  m.d[3] == 51.0 / 255.0, "8-bit values");
        ref_map_free(&m);
        CHECK(ref_map_from_raw(&m, px, 2, 2, 0, REF_FORMAT_UNORM8, 1) == 0, "8-bit rev");
        CHECK(m.d[0] == 1 && m.d[1] == 0 && m.d[2] == 127.0 / 255.0 && m.d[3] == 204.0 / 255.0,
              "8-bit reversed values %.17g %.17g %.17g %.17g", m.d[0], m.d[1], m.d[2], m.d[3]);
        ref_map_free(&m);
    }
    {
        /* 16-bit, padded rows, unaligned start */
        unsigned char buf[1 + 2 * 8];
        unsigned short vals[4] = { 0, 65535, 1, 40000 };
        memset(buf, 0xAB, sizeof buf);
        memcpy(buf + 1, &vals[0], 2);
        memcpy(buf + 3, &vals[1], 2);
        memcpy(buf + 1 + 8, &vals[2], 2);
        memcpy(buf + 3 + 8, &vals[3], 2);
        CHECK(ref_map_from_raw(&m, buf + 1, 2, 2, 8, REF_FORMAT_UNORM16, 0) == 0, "16-bit");
        CHECK(m.d[0] == 0 && m.d[1] == 1 && m.d[2] == 1.0 / 65535.0 &&
                  m.d[3] == 40000.0 / 65535.0, "16-bit values");
        ref_map_free(&m);
        CHECK(ref_map_from_raw(&m, buf + 1, 2, 2, 8, REF_FORMAT_UNORM16, 1) == 0, "16-bit rev");
        CHECK(m.d[0] == 1 && m.d[1] == 0 && m.d[2] == 65534.0 / 65535.0 &&
                  m.d[3] == 25535.0 / 65535.0, "16-bit reversed values");
        ref_map_free(&m);
    }
    {
        float f[8];
        unsigned char buf[1 + sizeof f];
        float one_minus = 1.0f - 0.1f; /* float32 arithmetic */
        float_cases(f);
        memcpy(buf + 1, f, sizeof f);
        CHECK(ref_map_from_raw(&m, buf + 1, 4, 2, 0, REF_FORMAT_FLOAT32, 0) == 0, "float");
        CHECK(m.d[0] == 0.25 && m.d[1] == 1 && m.d[2] == 1 && m.d[3] == 0 &&
                  m.d[4] == (double)0.1f && m.d[5] == 1 && m.d[6] == 0 && m.d[7] == 0 &&
                  !signbit(m.d[7]),
              "float values");
        ref_map_free(&m);
        CHECK(ref_map_from_raw(&m, buf + 1, 4, 2, 0, REF_FORMAT_FLOAT32, 1) == 0, "float rev");
        CHECK(m.d[0] == 0.75 && m.d[1] == 1 /* NaN is far also reversed */ &&
                  m.d[2] == 0 /* 1-2 = -1 */ && m.d[3] == 1 /* 1+1 = 2 */ &&
                  m.d[4] == (double)one_minus && m.d[4] != 1.0 - (double)0.1f &&
                  m.d[5] == 0 && m.d[6] == 1 && m.d[7] == 1,
              "float reversed values %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g", m.d[0],
              m.d[1], m.d[2], m.d[3], m.d[4], m.d[5], m.d[6], m.d[7]);
        ref_map_free(&m);
        /* a texel converted from NaN is a far-plane texel */
        CHECK(ref_map_from_raw(&m, buf + 1, 4, 2, 0, REF_FORMAT_FLOAT32, 0) == 0, "float");
        {
            ref_result r = tr(&m, mkray(1.5, 0.5, 0, 0, 0, 1, 0, 2));
            EXPECT_HIT(r, 1.0, 1, 0);
        }
        ref_map_free(&m);
    }
    {
        unsigned char px[4] = { 0, 0, 0, 0 };
        CHECK(ref_map_from_raw(&m, px, 0, 2, 0, REF_FORMAT_UNORM8, 0) != 0, "w = 0 refused");
        CHECK(ref_map_from_raw(&m, px, 2, 2, 1, REF_FORMAT_UNORM8, 0) != 0, "short stride");
        CHECK(ref_map_from_raw(&m, px, 2, 2, 0, 7, 0) != 0, "bad format refused");
        CHECK(m.d == NULL, "d NULL on failure");
    }
}

static void test_check(void)
{
    char why[512];
    ref_answer a;
    ref_ray ray;
    {
        ref_map m = map_const(6, 5, 0.5);
        set_d(&m, 2, 3, 0.625);
        ray = mkray(2.5, 3.5, 0, 0, 0, 1, 0, 1);
        a = ans(REF_HIT, 0.625, 2, 3);
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "exact answer refused: %s", why);
        a = ans(REF_HIT, 0.625 + 1e-6, 2, 3);
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "t within tolerance refused: %s",
              why);
        a = ans(REF_HIT, 0.626, 2, 3);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "t off by 1e-3 accepted");
        CHECK(strlen(why) > 0, "no reason given");
        a = ans(REF_HIT, 0.625, 3, 3);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "wrong texel accepted");
        a = ans(REF_HIT, 0.625, 2, 4);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "wrong texel accepted");
        a = ans(REF_HIT, 0.625, 7, 3);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "texel off the map accepted");
        a = ans(REF_MISS_TMAX, 0, -1, -1);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "miss for a hit accepted");
        a = ans(REF_MISS_INVALID, 0, -1, -1);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "invalid for a hit accepted");
        /* misses: kind matters */
        ray = mkray(0.5, 0.5, 0.25, 1, 0, 0, 0, 10);
        a = ans(REF_MISS_OFF_SCREEN, 0, -1, -1);
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "off-screen miss refused: %s", why);
        a = ans(REF_MISS_TMAX, 0, -1, -1);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "wrong miss kind accepted");
        a = ans(REF_HIT, 3, 3, 0);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "hit for a miss accepted");
        /* invalid rays */
        ray = mkray(0.5, 0.5, 0, 0, 0, 1, 0, 1);
        ray.v[1] = (float)strtod("nan", NULL);
        a = ans(REF_MISS_INVALID, 0, -1, -1);
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "invalid refused: %s", why);
        a = ans(REF_MISS_TMAX, 0, -1, -1);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "miss for invalid accepted");
        ref_map_free(&m);
    }
    {
        /* the corner case: the diagonal touches (1,0) only at its corner */
        ref_map m = map_const(2, 2, 1.0);
        set_d(&m, 1, 0, 0.2);
        ray = mkray(0.5, 0.5, 0.5, 1, 1, 0, 0, 10);
        a = ans(REF_HIT, 0.5, 1, 0);
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "corner hit refused: %s", why);
        /* a float tracer that saw the ray one ulp above the corner: a miss */
        a = ans(REF_MISS_OFF_SCREEN, 0, -1, -1);
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "corner ulp miss refused: %s", why);
        a = ans(REF_MISS_TMAX, 0, -1, -1);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "tmax miss accepted at corner");
        /* (0,0) contains the corner point in x,y but is far (d = 1 > 0.5) */
        a = ans(REF_HIT, 0.5, 0, 0);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "far texel at corner accepted");
        a = ans(REF_HIT, 0.5, 1, 1);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "far texel at corner accepted");
        ref_map_free(&m);
    }
    {
        /* only a 1-ulp perturbation explains it: the hit point is off by
           more than the tolerance of an 8-ulp move, but the kind changes only
           within 1 ulp. Build a grazing ray whose exact answer is a hit at
           t = 1 on a texel top, and a tracer answer that misses: every
           perturbation moves the ray off the top edge, so the miss is right. */
        ref_map m = map_const(3, 1, 1.0);
        set_d(&m, 1, 0, 0.5);
        ray = mkray(0.5, 0.5, 0.5, 1, 0, 0, 0, 10); /* slides along the top of (1,0) */
        a = ans(REF_HIT, 0.5, 1, 0);
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "grazing hit refused: %s", why);
        a = ans(REF_MISS_OFF_SCREEN, 0, -1, -1);
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "grazing miss refused: %s", why);
        a = ans(REF_HIT, 1.5, 1, 0); /* a later point on the top: not the first */
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "late grazing hit accepted");
        CHECK(ref_check(&m, &ray, &a, 1, why, sizeof why), "any-hit grazing refused: %s", why);
        ref_map_free(&m);
    }
    {
        /* any-hit: two hits along the ray */
        ref_map m = map_const(4, 1, 1.0);
        set_d(&m, 1, 0, 0.5);
        set_d(&m, 3, 0, 0.3);
        ray = mkray(0.5, 0.5, 0.9, 1, 0, 0, 0, 10);
        a = ans(REF_HIT, 0.5, 1, 0);
        CHECK(ref_check(&m, &ray, &a, 1, why, sizeof why), "any-hit closest refused: %s", why);
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "closest refused: %s", why);
        a = ans(REF_HIT, 2.7, 3, 0);
        CHECK(ref_check(&m, &ray, &a, 1, why, sizeof why), "any-hit later refused: %s", why);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "later hit accepted as closest");
        a = ans(REF_HIT, 1.7, 2, 0); /* (2.2, 0.5, 0.9): above the far texel 2 */
        CHECK(!ref_check(&m, &ray, &a, 1, why, sizeof why), "any-hit non-solid accepted");
        a = ans(REF_HIT, 2.7, 2, 0); /* point in texel 3, texel 2 reported */
        CHECK(!ref_check(&m, &ray, &a, 1, why, sizeof why), "any-hit wrong texel accepted");
        a = ans(REF_HIT, 12, 3, 0);
        CHECK(!ref_check(&m, &ray, &a, 1, why, sizeof why), "any-hit t > tmax accepted");
        a = ans(REF_MISS_OFF_SCREEN, 0, -1, -1);
        CHECK(!ref_check(&m, &ray, &a, 1, why, sizeof why), "any-hit miss accepted");
        ray = mkray(0.5, 0.5, 0.2, 1, 0, 0, 0, 10);
        CHECK(ref_check(&m, &ray, &a, 1, why, sizeof why), "any-hit miss refused: %s", why);
        a = ans(REF_MISS_TMAX, 0, -1, -1);
        CHECK(!ref_check(&m, &ray, &a, 1, why, sizeof why), "any-hit wrong miss accepted");
        ref_map_free(&m);
    }
    {
        /* huge ray: tolerance is relative to |o|, the exact texel still
           decides nothing, the kind does */
        ref_map m = map_const(8, 8, 1.0);
        set_d(&m, 5, 3, 0.25);
        ray = mkray(1e30, 3.5, 0.5, -1e30, 0, 0, 0, 2);
        a = ans(REF_HIT, 1.0, 5, 3);
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "huge exact refused: %s", why);
        a = ans(REF_MISS_OFF_SCREEN, 0, -1, -1);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "huge miss accepted");
        ref_map_free(&m);
    }
}

/* ------------------------------------------ cross-checks on random rays -- */

static unsigned long long g_rng = 0x9E3779B97F4A7C15ull;
static double rnd(void) /* [0, 1) */
{
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 7;
    g_rng ^= g_rng << 17;
    return (double)(g_rng >> 11) / 9007199254740992.0;
}
static double rnd_coord(double lo, double hi, int quantised)
{
    double x = lo + (hi - lo) * rnd();
    if (quantised) x = floor(x * 4) / 4;
    return x;
}

/* brute force: every texel of the map, exact box test (shares the box test
   with the reference, not the walk) */
static ref_result brute(const ref_map *m, const ref_ray *ray, ref__ev *best_out)
{
    double o[3], v[3];
    ref__ev t0 = ref__ev_scalar(ray->tmin), t1 = ref__ev_scalar(ray->tmax), best = t0;
    int found = 0, bx = -1, by = -1, bface = REF_FACE_NONE, i, j, c;
    ref_result r;
    for (c = 0; c < 3; c++) { o[c] = ray->o[c]; v[c] = ray->v[c]; }
    for (j = 0; j < m->h; j++)
        for (i = 0; i < m->w; i++) ref__consider(m, i, j, o, v, &t0, &t1, &found, &best, &bx, &by, &bface);
    r.t = 0; r.x = -1; r.y = -1; r.face = REF_FACE_NONE;
    if (found) {
        r.kind = REF_HIT; r.t = best.a; r.x = bx; r.y = by; r.face = bface;
    } else {
        double x = o[0] + (double)ray->tmax * v[0], y = o[1] + (double)ray->tmax * v[1];
        r.kind = (x >= 0 && x <= m->w && y >= 0 && y <= m->h) ? REF_MISS_TMAX
                                                               : REF_MISS_OFF_SCREEN;
    }
    *best_out = best;
    return r;
}

/* the lower face of texel (i, j)'s box: 1 without a back map */
static double back_of(const ref_map *m, int i, int j) { return m->b ? m->b[j * m->w + i] : 1.0; }

/* independent: is the point strictly inside the solid (by margin eps)? */
static int in_solid(const ref_map *m, double x, double y, double z, double eps)
{
    int i, j;
    if (x < 0 || y < 0 || x > m->w || y > m->h || z > 1 - eps) return 0;
    i = (int)floor(x);
    j = (int)floor(y);
    if (i >= m->w || j >= m->h) return 0;
    if (x - i < eps || i + 1 - x < eps || y - j < eps || j + 1 - y < eps) return 0;
    return z >= m->d[j * m->w + i] + eps && z <= back_of(m, i, j) - eps;
}

/* loosely: is the point in the closed solid, within eps? */
static int on_solid(const ref_map *m, double x, double y, double z, double eps)
{
    int i, j;
    for (j = (int)floor(y - eps); j <= (int)floor(y + eps); j++)
        for (i = (int)floor(x - eps); i <= (int)floor(x + eps); i++) {
            if (i < 0 || j < 0 || i >= m->w || j >= m->h) continue;
            if (x >= i - eps && x <= i + 1 + eps && y >= j - eps && y <= j + 1 + eps &&
                z >= m->d[j * m->w + i] - eps && z <= back_of(m, i, j) + eps)
                return 1;
        }
    return 0;
}

/* The face a hit enters by, and the checker's rule for it: the exact face,
   or any face the hit point lies on (an edge), inside only at tmin. */
static void test_faces(void)
{
    ref_map m = map_const(6, 5, 0.5);
    ref_ray ray;
    ref_result r;
    ref_answer a;
    char why[256];
    set_d(&m, 3, 2, 0.25); /* a raised texel */
    ray = mkray(3.5, 2.5, 0, 0, 0, 1, 0, 1); /* straight down onto it */
    r = ref_trace_ray(&m, &ray);
    CHECK(r.kind == REF_HIT && r.face == REF_FACE_TOP, "top: kind %d face %d", r.kind, r.face);
    ray = mkray(0.5, 2.5, 0.4, 1, 0, 0, 0, 10); /* level, into the raised texel's side at x = 3 */
    r = ref_trace_ray(&m, &ray);
    CHECK(r.kind == REF_HIT && r.x == 3 && r.face == REF_FACE_SIDE, "side: kind %d (%d,%d) face %d", r.kind, r.x, r.y,
          r.face);
    ray = mkray(1.5, 1.5, 1.5, 0, 0, -1, 0, 2); /* from behind the far plane */
    r = ref_trace_ray(&m, &ray);
    CHECK(r.kind == REF_HIT && r.t == 0.5 && r.face == REF_FACE_BACK, "back: kind %d t %g face %d", r.kind, r.t, r.face);
    ray = mkray(1.5, 1.5, 0.75, 1, 0, 0, 0.25, 2); /* the origin inside the solid */
    r = ref_trace_ray(&m, &ray);
    CHECK(r.kind == REF_HIT && r.t == 0.25 && r.face == REF_FACE_INSIDE, "inside: kind %d t %g face %d", r.kind, r.t,
          r.face);
    ray = mkray(1.5, 1.5, 0.5, 1, 0, 0.5, 0, 2); /* starts on the top: on a face, not inside */
    r = ref_trace_ray(&m, &ray);
    CHECK(r.kind == REF_HIT && r.t == 0 && r.face == REF_FACE_TOP, "on the top at tmin: face %d", r.face);
    ray = mkray(1.5, 1.5, 0.5, 1, 0, 0, 0, 2); /* level along the top: on it throughout */
    r = ref_trace_ray(&m, &ray);
    CHECK(r.kind == REF_HIT && r.face == REF_FACE_TOP, "along the top: face %d", r.face);

    /* the checker: the exact face passes, a wrong one fails, an edge takes either */
    ray = mkray(0.5, 2.5, 0.4, 1, 0, 0, 0, 10);
    a = ans(REF_HIT, 2.5, 3, 2);
    a.face = REF_FACE_SIDE;
    CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "the exact face refused: %s", why);
    a.face = REF_FACE_TOP;
    CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why) && strstr(why, "face"), "a side hit told as the top accepted");
    a.face = REF_FACE_INSIDE;
    CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "a hit past tmin told as inside accepted");
    a.face = REF_FACE_NONE;
    CHECK(!ref_check(&m, &ray, &a, 1, why, sizeof why), "any-hit: a hit with no face accepted");
    ray = mkray(0.5, 2.5, 0.25, 1, 0, 0, 0, 10); /* level with the raised top: meets its top edge */
    a = ans(REF_HIT, 2.5, 3, 2);
    a.face = REF_FACE_TOP;
    CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "the top on an edge refused: %s", why);
    a.face = REF_FACE_SIDE;
    CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "the side on an edge refused: %s", why);
    ray = mkray(3.5, 2.5, 0, 0, 0, 1, 0, 0.2f); /* a miss has no face */
    a = ans(REF_MISS_TMAX, 0, 0, 0);
    a.face = REF_FACE_TOP;
    CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "a miss with a face accepted");
    ref_map_free(&m);
}

#define EXPECT_FACE(res, f)                                                             \
    CHECK((res).kind == REF_HIT && (res).face == (f),                                   \
          "expected a hit by face %d, got kind %d face %d t=%.17g (%d,%d)", (f),        \
          (res).kind, (res).face, (res).t, (res).x, (res).y)

/* Finite thickness: each box is [d, b], b from a back map (docs/MODEL.md,
   "Thickness (optional) and the face of a hit"). */
static void test_thickness(void)
{
    ref_result r;
    ref_ray ray;
    ref_answer a;
    char why[512];
    int k;
    {
        /* (a) a thin floating slab [0.5, 0.55]: a level ray at z = 0.7 passes under it */
        ref_map m = map_const(4, 1, 0.5);
        ref_ray under = mkray(-1, 0.5, 0.7, 1, 0, 0, 0, 4); /* ends at x = 3, on the screen */
        ref_ray from_in = mkray(0.5, 0.5, 0.7, 1, 0, 0, 0, 3);
        r = ref_trace_ray(&m, &under); /* infinite thickness: the first texel's side */
        EXPECT_HIT(r, 1, 0, 0);
        EXPECT_FACE(r, REF_FACE_SIDE);
        r = ref_trace_ray(&m, &from_in);
        EXPECT_HIT(r, 0, 0, 0);
        EXPECT_FACE(r, REF_FACE_INSIDE);
        set_back_const(&m, 0.55f);
        CHECK(m.b != NULL && m.b[0] == (double)0.55f && m.b[3] == (double)0.55f, "slab back depth");
        r = ref_trace_ray(&m, &under);
        EXPECT_KIND(r, REF_MISS_TMAX);
        r = ref_trace_ray(&m, &from_in);
        EXPECT_KIND(r, REF_MISS_TMAX);
        /* level with the back plane: the closed box is grazed at its edge */
        r = tr(&m, mkray(-1, 0.5, 0.55f, 1, 0, 0, 0, 4));
        EXPECT_HIT(r, 1, 0, 0);
        r = tr(&m, mkray(-1, 0.5, nextafterf(0.55f, 1.0f), 1, 0, 0, 0, 4));
        EXPECT_KIND(r, REF_MISS_TMAX);
        /* within the slab: inside at tmin */
        r = tr(&m, mkray(0.5, 0.5, 0.53, 1, 0, 0, 0, 3));
        EXPECT_HIT(r, 0, 0, 0);
        EXPECT_FACE(r, REF_FACE_INSIDE);
        /* going down under the slab and up again past its far end: a
           rising ray whose column z range is all deeper than b (pruned)
           reaches a texel that is thick again */
        set_d(&m, 3, 0, 0.75);
        m.b[3] = 1.0;
        r = tr(&m, mkray(0.5, 0.5, 0.9, 1, 0, -0.03125, 0, 10)); /* z = 0.821875 at x = 3 */
        EXPECT_HIT(r, 2.5, 3, 0);
        EXPECT_FACE(r, REF_FACE_SIDE);
        ref_map_free(&m);
        CHECK(m.b == NULL && m.d == NULL, "ref_map_free clears b");
    }
    {
        /* (b) from below: o.z = 0.8 under the slab [0.5, 0.6], v.z < 0 */
        ref_map m = map_const(4, 4, 0.5);
        double t;
        ray = mkray(1.5, 1.5, 0.8, 0.25, 0, -1, 0, 10);
        r = ref_trace_ray(&m, &ray); /* infinite thickness: already inside */
        EXPECT_HIT(r, 0, 1, 1);
        EXPECT_FACE(r, REF_FACE_INSIDE);
        set_back_const(&m, 0.6f);
        t = (double)0.8f - (double)0.6f; /* exact (Sterbenz) */
        r = ref_trace_ray(&m, &ray);
        EXPECT_HIT(r, t, 1, 1);
        EXPECT_FACE(r, REF_FACE_BACK);
        CHECK(r.kind == REF_HIT && fabs((double)ray.o[2] + r.t * (double)ray.v[2] - 0.6) < 1e-7,
              "back hit at z = %.17g", (double)ray.o[2] + r.t * (double)ray.v[2]);
        /* straight up, and up with tmax short of the back */
        r = tr(&m, mkray(2.5, 0.5, 0.75, 0, 0, -1, 0, 1));
        EXPECT_HIT(r, (double)0.75f - (double)0.6f, 2, 0);
        EXPECT_FACE(r, REF_FACE_BACK);
        r = tr(&m, mkray(2.5, 0.5, 0.75, 0, 0, -1, 0, 0.125));
        EXPECT_KIND(r, REF_MISS_TMAX);
        ref_map_free(&m);
    }
    {
        /* (c) a back in front of the surface is clamped to d: the flat plate z = d */
        ref_map m = map_const(3, 1, 0.5);
        set_back_const(&m, 0.3f);
        CHECK(m.b != NULL && m.b[0] == 0.5 && m.b[1] == 0.5 && m.b[2] == 0.5, "back clamped to d: %.17g",
              m.b ? m.b[1] : -1.0);
        r = tr(&m, mkray(1.5, 0.5, 0, 0, 0, 1, 0, 1));
        EXPECT_HIT(r, 0.5, 1, 0);
        EXPECT_FACE(r, REF_FACE_TOP);
        r = tr(&m, mkray(-1, 0.5, 0.5 + 1.0 / 1024, 1, 0, 0, 0, 3)); /* just behind the plate */
        EXPECT_KIND(r, REF_MISS_TMAX);
        r = tr(&m, mkray(-1, 0.5, 0.5, 1, 0, 0, 0, 3)); /* in its plane: meets its edge */
        EXPECT_HIT(r, 1, 0, 0);
        /* from behind: the plate's back is its top, either face is right */
        ray = mkray(1.5, 0.5, 0.75, 0, 0, -1, 0, 1);
        r = ref_trace_ray(&m, &ray);
        CHECK(r.kind == REF_HIT && r.t == 0.25 && r.x == 1 && (r.face == REF_FACE_BACK || r.face == REF_FACE_TOP),
              "plate from behind: kind %d t %.17g face %d", r.kind, r.t, r.face);
        a = ans(REF_HIT, 0.25, 1, 0);
        a.face = REF_FACE_TOP;
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "plate from behind, top refused: %s", why);
        a.face = REF_FACE_BACK;
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "plate from behind, back refused: %s", why);
        ref_map_free(&m);
    }
    {
        /* per texel: b = max(d, back); a far texel stays the face z = 1 */
        ref_map m = map_const(3, 1, 0.5);
        float bk[3] = { 0.75f, 0.25f, 0.5f };
        set_d(&m, 1, 0, 0.7);
        set_d(&m, 2, 0, 1.0);
        CHECK(ref_map_set_back_from_raw(&m, bk, 0, REF_FORMAT_FLOAT32, 0) == 0, "set_back per texel");
        CHECK(m.b[0] == 0.75 && m.b[1] == 0.7 && m.b[2] == 1.0, "max(d, back): %.17g %.17g %.17g", m.b[0],
              m.b[1], m.b[2]);
        CHECK(m.d[0] == 0.5 && m.d[1] == 0.7 && m.d[2] == 1.0, "set_back changed d");
        r = tr(&m, mkray(2.5, 0.5, 0, 0, 0, 1, 0, 2));
        EXPECT_HIT(r, 1, 2, 0);
        ref_map_free(&m);
    }
    {
        /* (d) conversions, as for depth: float (NaN and > 1 are 1), reversed too */
        float f[8];
        ref_map m = map_const(4, 2, 0.0), md;
        float one_minus = 1.0f - 0.1f; /* float32 arithmetic */
        float_cases(f);
        CHECK(ref_map_set_back_from_raw(&m, f, 0, REF_FORMAT_FLOAT32, 0) == 0, "float back");
        CHECK(m.b[0] == 0.25 && m.b[1] == 1 && m.b[2] == 1 && m.b[3] == 0 && m.b[4] == (double)0.1f &&
                  m.b[5] == 1 && m.b[6] == 0 && m.b[7] == 0 && !signbit(m.b[7]),
              "float back values");
        CHECK(ref_map_from_raw(&md, f, 4, 2, 0, REF_FORMAT_FLOAT32, 0) == 0, "float depth");
        for (k = 0; k < 8; k++) CHECK(m.b[k] == md.d[k], "back %d converts unlike depth", k);
        ref_map_free(&md);
        /* a NaN back reaches the far plane, a back of 0.25 lets z = 0.9 pass */
        r = tr(&m, mkray(-1, 0.5, 0.9, 1, 0, 0, 0, 10));
        EXPECT_HIT(r, 2, 1, 0);
        CHECK(ref_map_set_back_from_raw(&m, f, 0, REF_FORMAT_FLOAT32, 1) == 0, "float back rev");
        CHECK(m.b[0] == 0.75 && m.b[1] == 1 && m.b[2] == 0 && m.b[3] == 1 && m.b[4] == (double)one_minus &&
                  m.b[5] == 0 && m.b[6] == 1 && m.b[7] == 1,
              "float back reversed values %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g", m.b[0], m.b[1],
              m.b[2], m.b[3], m.b[4], m.b[5], m.b[6], m.b[7]);
        ref_map_free(&m);
    }
    {
        unsigned char px[4] = { 0, 255, 128, 51 };
        ref_map m = map_const(2, 2, 0.0);
        CHECK(ref_map_set_back_from_raw(&m, px, 0, REF_FORMAT_UNORM8, 0) == 0, "8-bit back");
        CHECK(m.b[0] == 0 && m.b[1] == 1 && m.b[2] == 128.0 / 255.0 && m.b[3] == 51.0 / 255.0,
              "8-bit back values");
        CHECK(ref_map_set_back_from_raw(&m, px, 0, REF_FORMAT_UNORM8, 1) == 0, "8-bit back rev");
        CHECK(m.b[0] == 1 && m.b[1] == 0 && m.b[2] == 127.0 / 255.0 && m.b[3] == 204.0 / 255.0,
              "8-bit back reversed values");
        ref_map_free(&m);
        m = map_const(2, 2, 0.4); /* backs in front of d = 0.4 become 0.4 */
        CHECK(ref_map_set_back_from_raw(&m, px, 0, REF_FORMAT_UNORM8, 0) == 0, "8-bit back over 0.4");
        CHECK(m.b[0] == 0.4 && m.b[1] == 1 && m.b[2] == 128.0 / 255.0 && m.b[3] == 0.4,
              "8-bit back max(d, back)");
        ref_map_free(&m);
    }
    {
        /* 16-bit, padded rows, unaligned start */
        unsigned char buf[1 + 2 * 8];
        unsigned short vals[4] = { 0, 65535, 1, 40000 };
        ref_map m = map_const(2, 2, 0.0);
        memset(buf, 0xAB, sizeof buf);
        memcpy(buf + 1, &vals[0], 2);
        memcpy(buf + 3, &vals[1], 2);
        memcpy(buf + 1 + 8, &vals[2], 2);
        memcpy(buf + 3 + 8, &vals[3], 2);
        CHECK(ref_map_set_back_from_raw(&m, buf + 1, 8, REF_FORMAT_UNORM16, 0) == 0, "16-bit back");
        CHECK(m.b[0] == 0 && m.b[1] == 1 && m.b[2] == 1.0 / 65535.0 && m.b[3] == 40000.0 / 65535.0,
              "16-bit back values");
        CHECK(ref_map_set_back_from_raw(&m, buf + 1, 8, REF_FORMAT_UNORM16, 1) == 0, "16-bit back rev");
        CHECK(m.b[0] == 1 && m.b[1] == 0 && m.b[2] == 65534.0 / 65535.0 && m.b[3] == 25535.0 / 65535.0,
              "16-bit back reversed values");
        ref_map_free(&m);
    }
    {
        /* (e) the checker. Texels 0..2 are slabs [0.5, 0.55], texel 3 is solid
           to the far plane: a level ray at z = 0.7 passes under three and
           hits the fourth's side at x = 3. */
        ref_map m = map_const(4, 1, 0.5);
        float bk[4] = { 0.55f, 0.55f, 0.55f, 1.0f };
        CHECK(ref_map_set_back_from_raw(&m, bk, 0, REF_FORMAT_FLOAT32, 0) == 0, "set_back (e)");
        ray = mkray(0.5, 0.5, 0.7, 1, 0, 0, 0, 10);
        r = ref_trace_ray(&m, &ray);
        EXPECT_HIT(r, 2.5, 3, 0);
        EXPECT_FACE(r, REF_FACE_SIDE);
        a = ans(REF_HIT, 2.5, 3, 0);
        a.face = REF_FACE_SIDE;
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "side past slabs refused: %s", why);
        CHECK(ref_check(&m, &ray, &a, 1, why, sizeof why), "any-hit side past slabs refused: %s", why);
        /* the right point, but told on texel 2, which the ray passes under */
        a = ans(REF_HIT, 2.5, 2, 0);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "hit on a texel passed under accepted");
        CHECK(!ref_check(&m, &ray, &a, 1, why, sizeof why), "any-hit on a texel passed under accepted");
        /* a point under texel 1, told as a hit on it */
        a = ans(REF_HIT, 1.0, 1, 0);
        CHECK(!ref_check(&m, &ray, &a, 1, why, sizeof why) && strstr(why, "box"),
              "any-hit: a point behind a slab's back accepted (%s)", why);
        /* the same point with infinite thickness is a hit on texel 1 */
        free(m.b);
        m.b = NULL;
        CHECK(ref_check(&m, &ray, &a, 1, why, sizeof why), "any-hit, infinite thickness, refused: %s", why);
        ref_map_free(&m);
    }
    {
        /* BACK faces in the checker: the slab [0.5, 0.6] */
        ref_map m = map_const(4, 4, 0.5);
        set_back_const(&m, 0.6f);
        ray = mkray(1.5, 1.5, 0.8, 0.25, 0, -1, 0, 10); /* from below, as in (b) */
        a = ans(REF_HIT, (double)0.8f - (double)0.6f, 1, 1);
        a.face = REF_FACE_BACK;
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "back at the back refused: %s", why);
        /* any-hit knows no exact face: the point must lie on z = b */
        CHECK(ref_check(&m, &ray, &a, 1, why, sizeof why), "any-hit back at the back refused: %s", why);
        a.face = REF_FACE_TOP;
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "top claimed for a back hit accepted");
        a.face = REF_FACE_INSIDE;
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "inside claimed for a back hit accepted");
        ray = mkray(1.5, 1.5, 0, 0, 0, 1, 0, 1); /* down onto the top */
        a = ans(REF_HIT, 0.5, 1, 1);
        a.face = REF_FACE_TOP;
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "top refused: %s", why);
        a.face = REF_FACE_BACK;
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why) && strstr(why, "face"),
              "back claimed for a top hit accepted");
        CHECK(!ref_check(&m, &ray, &a, 1, why, sizeof why), "any-hit: back claimed for a top hit accepted");
        ref_map_free(&m);
    }
    {
        /* a ray rising into a slab's lower edge (x = 1, z = b): the exact face
           is the side, and the back is right too, the top is not */
        ref_map m = map_const(3, 1, 1.0);
        float bk[3] = { 1.0f, 0.625f, 1.0f };
        set_d(&m, 1, 0, 0.5);
        CHECK(ref_map_set_back_from_raw(&m, bk, 0, REF_FORMAT_FLOAT32, 0) == 0, "set_back edge");
        ray = mkray(0.5, 0.5, 0.875, 1, 0, -0.5, 0, 10);
        r = ref_trace_ray(&m, &ray);
        EXPECT_HIT(r, 0.5, 1, 0);
        a = ans(REF_HIT, 0.5, 1, 0);
        a.face = r.face == REF_FACE_BACK ? REF_FACE_SIDE : REF_FACE_BACK; /* the one not reported */
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "the back edge, other face (%d) refused: %s", a.face,
              why);
        a.face = REF_FACE_TOP;
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "top at the back edge accepted");
        ref_map_free(&m);
    }
    {
        /* (f) bad arguments: -1, and the map left as it was */
        ref_map m = map_const(2, 2, 0.5);
        float f[4] = { 0.75f, 0.75f, 0.75f, 0.75f };
        double *d0 = m.d, *b0;
        CHECK(ref_map_set_back_from_raw(&m, NULL, 0, REF_FORMAT_FLOAT32, 0) == -1, "NULL data accepted");
        CHECK(m.b == NULL && m.d == d0 && m.w == 2 && m.h == 2 && m.d[0] == 0.5, "NULL data changed the map");
        CHECK(ref_map_set_back_from_raw(NULL, f, 0, REF_FORMAT_FLOAT32, 0) == -1, "NULL map accepted");
        CHECK(ref_map_set_back_from_raw(&m, f, 4, REF_FORMAT_FLOAT32, 0) == -1, "short stride accepted");
        CHECK(ref_map_set_back_from_raw(&m, f, 0, 7, 0) == -1, "bad format accepted");
        CHECK(m.b == NULL, "b set on failure");
        CHECK(ref_map_set_back_from_raw(&m, f, 0, REF_FORMAT_FLOAT32, 0) == 0, "set_back");
        b0 = m.b;
        CHECK(ref_map_set_back_from_raw(&m, NULL, 0, REF_FORMAT_FLOAT32, 0) == -1 && m.b == b0 &&
                  m.b[0] == (double)0.75f,
              "a failed set_back changed the back map");
        ref_map_free(&m);
        CHECK(ref_map_set_back_from_raw(&m, f, 0, REF_FORMAT_FLOAT32, 0) == -1, "a freed map accepted");
        CHECK(ref_map_from_raw(&m, f, 2, 2, 0, REF_FORMAT_FLOAT32, 0) == 0 && m.b == NULL, "from_raw: b not NULL");
        ref_map_free(&m);
    }
}

/* The depth of view distance z under the perspective of the thickness
   models, literally as docs/MODEL.md defines it (n > 0, f > n or +INFINITY,
   depth 0 near .. 1 far): independent of reference.h's factored form. */
static double persp_depth(double z, double n, double f)
{
    if (z >= f) return 1.0;
    return f > DBL_MAX ? 1.0 - n / z : f * (z - n) / (z * (f - n));
}

/* The spacing of float32 values at x's magnitude (x >= 0): 2^(e-24) for x
   in (2^(e-1), 2^e], the finer spacing at a power of two (the ulp below
   1 is 2^-24), 2^-149 among the subnormals. */
static double ulp_f32(double x)
{
    int e;
    double fr = frexp(fabs(x), &e);
    if (x == 0) return ldexp(1.0, -149);
    if (fr == 0.5) e--;
    return e - 24 < -149 ? ldexp(1.0, -149) : ldexp(1.0, e - 24);
}

/* the recipe's b (a float32, reference.h) against a value worked out by
   hand: a float, within 2 float ulps */
static int near_f(double got, double want)
{
    return (double)(float)got == got && fabs(got - want) <= 2 * ulp_f32(want);
}

/* x rounded to float32 for certain: GCC 12.2 at -O2 was seen to vectorize
   two (float) casts into a ray's o[] and then hand ref_trace_ray (inlined)
   the unrounded doubles while brute() read the floats, so the two traced
   different rays. A volatile float cannot be skipped. */
static float to_f32(double x)
{
    volatile float f = (float)x;
    return f;
}

/* m is 4 x 1 with the depths d[0..3] */
static void set_row4(ref_map *m, double d0, double d1, double d2, double d3)
{
    set_d(m, 0, 0, d0); set_d(m, 1, 0, d1); set_d(m, 2, 0, d2); set_d(m, 3, 0, d3);
}

/* The perspective thickness models (docs/MODEL.md, "Thickness (optional) and
   the face of a hit"): ref_map_set_back_constant (view-space T) and
   ref_map_set_back_relative (T = k * z_view(d)). */
/* A hit on a flat plate (b == d) that only a real-valued move of the ray
   explains (reference.h, ref__plate_match; found by fuzz_core,
   tests/fuzz/crashes-found/core-constant-plate-restart-rounds-onto-plate):
   docs/MODEL.md's "moved by at most 8 float32 ulps" is not only the discrete
   moves {-8,0,+8}, {-1,0,+1} the checker tries. */
static void test_plate_check(void)
{
    const double vz = ldexp(1, -30), ulp_up = ldexp(1, -24); /* float spacing above 0.5 */
    ref_ray ray;
    ref_answer a;
    ref_result r;
    double o[3], v[3];
    char why[512];
    int k;
    {
        /* (a) 1x1 plate d = b = 0.5; the ray enters the texel at t = 0.5 at
           z = 0.5 + 2^-31, just behind it: off screen. A hit at t = 0.5 on
           the plate is exact for o.z moved by -2^-31 (under an ulp) */
        ref_map m = map_const(1, 1, 0.5);
        set_back_const(&m, 0.5f);
        CHECK(m.b != NULL && m.b[0] == 0.5, "plate back");
        ray = mkray(0.25, -512, 0.5, 0, 1024, vz, 0, 8);
        r = ref_trace_ray(&m, &ray);
        EXPECT_KIND(r, REF_MISS_OFF_SCREEN);
        for (k = 0; k < 3; k++) { o[k] = ray.o[k]; v[k] = ray.v[k]; }
        a = ans(REF_HIT, 0.5, 0, 0);
        a.face = REF_FACE_TOP;
        CHECK(!ref__perturbed_match(&m, &ray, o, v, &a, 0), "a discrete perturbation hits the plate");
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "plate hit of a moved ray refused: %s", why);
        a.face = REF_FACE_BACK;
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "plate hit by its back refused: %s", why);
        a.face = REF_FACE_SIDE; /* y = 0: on the footprint's edge */
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "plate hit on its edge refused: %s", why);
        a.face = REF_FACE_ANY;
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "plate hit without a face refused: %s", why);
        a.face = REF_FACE_INSIDE;
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "plate hit told as inside accepted");
        a = ans(REF_HIT, 0.5 + 0.5 / 1024, 0, 0); /* y = 0.5: not on an edge */
        a.face = REF_FACE_SIDE;
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "plate hit off its edge told as side accepted");
        a.face = REF_FACE_TOP; /* a later point of the plate: still within 8 ulps */
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "plate hit inside the footprint refused: %s", why);
        a = ans(REF_HIT, 0.5 + 2.0 / 1024, 0, 0); /* y = 2: off the footprint */
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "plate hit off its footprint accepted");
        a = ans(REF_HIT, 0.5, 0, 0);
        ray.tmax = 0.25; /* t past tmax */
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "plate hit past tmax accepted");
        /* 7 ulps (2^-24 each) behind the plate: no discrete move, a real one */
        ray = mkray(0.25, -512, 0.5 + 7 * ulp_up, 0, 1024, vz, 0, 8);
        for (k = 0; k < 3; k++) { o[k] = ray.o[k]; v[k] = ray.v[k]; }
        CHECK(!ref__perturbed_match(&m, &ray, o, v, &a, 0), "a discrete perturbation hits the plate (7 ulps)");
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "plate 7 ulps away refused: %s", why);
        /* (c) 9 ulps behind: farther than 8 ulps of o.z reach (t v.z adds
           2^-31, 8 ulps of v.z at t = 0.5 far less) */
        ray = mkray(0.25, -512, 0.5 + 9 * ulp_up, 0, 1024, vz, 0, 8);
        EXPECT_KIND(ref_trace_ray(&m, &ray), REF_MISS_OFF_SCREEN);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "plate 9 ulps away accepted");
        /* in front of the plate, 5 ulps of 2^-25 below it: moved up, it hits */
        ray = mkray(0.25, -512, 0.5 - 5 * ulp_up / 2, 0, 1024, vz, 0, 8);
        EXPECT_KIND(ref_trace_ray(&m, &ray), REF_MISS_OFF_SCREEN);
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "plate 5 ulps in front refused: %s", why);
        /* 9 ulps (2^-25) in front: the up reach of 0.5 - 9 * 2^-25 is 8 of them */
        ray = mkray(0.25, -512, 0.5 - 9 * ulp_up / 2, 0, 1024, vz, 0, 8);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "plate 9 ulps in front accepted");
        /* (c) a level ray (v.z = 0) 2^-18 behind the plate: within the hit
           point's tolerance (1e-5), but 64 ulps from the plate all along */
        ray = mkray(0.25, -512, 0.5 + ldexp(1, -18), 0, 1024, 0, 0, 8);
        EXPECT_KIND(ref_trace_ray(&m, &ray), REF_MISS_OFF_SCREEN);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "level ray 64 ulps behind a plate accepted");
        /* on the plate's plane exactly: the exact answer, by the old path */
        ray = mkray(0.25, -512, 0.5, 0, 1024, 0, 0, 8);
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "level ray on the plate refused: %s", why);
        ref_map_free(&m);
    }
    {
        /* (a) the same on a far texel, d = b = 1 (no back map) */
        ref_map m = map_const(1, 1, 1.0);
        ray = mkray(0.25, -512, 1.0, 0, 1024, vz, 0, 8);
        EXPECT_KIND(ref_trace_ray(&m, &ray), REF_MISS_OFF_SCREEN);
        a = ans(REF_HIT, 0.5, 0, 0);
        a.face = REF_FACE_TOP;
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "far-plane plate hit refused: %s", why);
        ref_map_free(&m);
    }
    {
        /* (b) the same hit on a texel that is not a plate: the box [0.25, 0.5]
           (back 0.5), the ray 2^-20 (16 ulps) behind its back: refused. At
           2^-31 behind, a discrete move (o.z by -1 ulp) explains it */
        ref_map m = map_const(1, 1, 0.25);
        set_back_const(&m, 0.5f);
        CHECK(m.b != NULL && m.b[0] == 0.5 && m.d[0] == 0.25, "slab [0.25, 0.5]");
        ray = mkray(0.25, -512, 0.5 + ldexp(1, -20), 0, 1024, vz, 0, 8);
        EXPECT_KIND(ref_trace_ray(&m, &ray), REF_MISS_OFF_SCREEN);
        a = ans(REF_HIT, 0.5, 0, 0);
        a.face = REF_FACE_BACK;
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "slab hit 16 ulps behind accepted");
        a.face = REF_FACE_SIDE;
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "slab hit 16 ulps behind accepted (side)");
        ray = mkray(0.25, -512, 0.5, 0, 1024, vz, 0, 8);
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "slab hit 2^-31 behind refused: %s", why);
        /* and a texel with depth behind which the ray passes within 8 ulps is
           not taken for a plate: its top is not where the ray is */
        ray = mkray(0.25, -512, 0.5 + 7 * ulp_up, 0, 1024, vz, 0, 8);
        a.face = REF_FACE_TOP;
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "slab hit by its top at z = b accepted");
        ref_map_free(&m);
    }
    {
        /* (d) the exact ray hits something first: row 0 is solid [0.25, 1],
           row 1 the plate [0.5, 0.5]; the ray hits row 0's side at t = 0.5,
           and a hit on the plate at y = 1 is not the closest */
        ref_map m = map_const(1, 2, 0.25);
        m.b = (double *)malloc(2 * sizeof(double));
        m.b[0] = 1.0;
        set_d(&m, 0, 1, 0.5);
        m.b[1] = 0.5;
        ray = mkray(0.25, -512, 0.5, 0, 1024, vz, 0, 8);
        r = ref_trace_ray(&m, &ray);
        EXPECT_HIT(r, 0.5, 0, 0);
        a = ans(REF_HIT, 0.5 + 1.0 / 1024, 0, 1);
        a.face = REF_FACE_TOP;
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "plate hit behind an earlier hit accepted");
        /* with row 0 far (d = b = 1) nothing is earlier: the plate hit stands */
        set_d(&m, 0, 0, 1.0);
        EXPECT_KIND(ref_trace_ray(&m, &ray), REF_MISS_OFF_SCREEN);
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "plate hit with nothing earlier refused: %s", why);
        /* the exact ray hits later (row 1 solid to 1, row 0 the plate) */
        set_d(&m, 0, 0, 0.5);
        m.b[0] = 0.5;
        m.b[1] = 1.0;
        r = ref_trace_ray(&m, &ray);
        EXPECT_HIT(r, 0.5 + 1.0 / 1024, 0, 1);
        a = ans(REF_HIT, 0.5, 0, 0);
        a.face = REF_FACE_TOP;
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "plate hit before a later exact hit refused: %s", why);
        ref_map_free(&m);
    }
    {
        /* (d) a box thinner than a whole-ulp move of z (fuzz_core,
           tests/fuzz/crashes-found/core-relative-thin-box-between-ulps):
           [0.5 + 2^-28, 0.5 + 2^-27]. The ray enters at z = 0.5 + 2^-31, in
           front; o.z moved up by one ulp (2^-24) passes behind it, unmoved in
           front: no discrete move hits it, a real one (2^-28 up) does */
        ref_map m = map_const(1, 1, 0.5);
        set_back_const(&m, 0.5f);
        m.d[0] = 0.5 + ldexp(1, -28);
        m.b[0] = 0.5 + ldexp(1, -27);
        ray = mkray(0.25, -512, 0.5, 0, 1024, vz, 0, 8);
        EXPECT_KIND(ref_trace_ray(&m, &ray), REF_MISS_OFF_SCREEN);
        for (k = 0; k < 3; k++) { o[k] = ray.o[k]; v[k] = ray.v[k]; }
        a = ans(REF_HIT, 0.5, 0, 0);
        a.face = REF_FACE_SIDE; /* it enters through y = 0 with z inside the box */
        CHECK(!ref__perturbed_match(&m, &ray, o, v, &a, 0), "a discrete perturbation hits the thin box");
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "thin-box hit of a moved ray refused: %s", why);
        /* 9 ulps (2^-25 each) in front of it: out of reach */
        ray = mkray(0.25, -512, 0.5 - 9 * ulp_up / 2, 0, 1024, vz, 0, 8);
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "thin box 9 ulps in front accepted");
        /* a box as deep as an ulp's move is left to the discrete moves: a
           ray 9 ulps in front of [0.5, 0.5 + 2^-24] is refused too */
        m.d[0] = 0.5;
        m.b[0] = 0.5 + ulp_up;
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "deep box 9 ulps in front accepted");
        ref_map_free(&m);
    }
}

static void test_thickness_models(void)
{
    const double inf = HUGE_VAL;
    ref_result r;
    ref_ray ray;
    ref_answer a;
    char why[512];
    int k;
    {
        /* (a) analytic values. The maps hold b by the float32 recipe at the
           top of reference.h: within 2 float ulps of these exact values,
           and bit-exact where worked out below (c0 = s = f / (f - n),
           c1 = T / n; relative: c0 = k s, c1 = 1 + k) */
        ref_map m = map_const(4, 1, 0.0);
        /* constant, n = 1, f = inf (d = 1 - 1/z, z_view = 1/(1 - d)), T = 1:
           d = 0 -> z = 1 -> z' = 2 -> b = 1/2; d = 0.5 -> z = 2 -> z' = 3
           -> b = 2/3; d = 0.75 -> z = 4 -> z' = 5 -> b = 4/5; d = 1 -> 1 */
        set_row4(&m, 0, 0.5, 0.75, 1);
        CHECK(ref_map_set_back_constant(&m, 1, 1, inf) == 0, "constant n=1 f=inf T=1");
        CHECK(m.b && m.b[0] == 0.5 && near_f(m.b[1], 2.0 / 3) && near_f(m.b[2], 0.8) && m.b[3] == 1,
              "constant f=inf: %.17g %.17g %.17g %.17g", m.b[0], m.b[1], m.b[2], m.b[3]);
        /* bit-exact, c0 = c1 = 1 (worked by hand, each step rounded to
           float32; the same bits from a throwaway C program of the recipe's
           volatile float steps): d = 0.5: u = 0.5, q = 2, q + c1 = 3,
           3 / u = 6, e = 1/6 rounds to 11184811 * 2^-26 (1/6 = 11184810.67
           units of 2^-26), d + e = 44739243 * 2^-26 = 11184810.75 units of
           2^-24 (the spacing in [1/2, 1)): 11184811 * 2^-24 = (float)(2/3),
           the float nearest the exact b. d = 0.75: u = 0.25, q = 4, 5 / u =
           20, e = 1/20 = 13421773 * 2^-28 (13421772.8 units), d + e =
           214748365 * 2^-28 = 13421772.81 units of 2^-24: 13421773 * 2^-24
           = 0.8f. */
        CHECK(m.b[1] == ldexp(11184811.0, -24) && m.b[1] == (double)(2.0f / 3) && m.b[2] == (double)0.8f,
              "constant f=inf, bits: %a %a", m.b[1], m.b[2]);
        CHECK(m.d[0] == 0 && m.d[1] == 0.5 && m.d[2] == 0.75 && m.d[3] == 1, "set_back_constant changed d");
        /* constant, n = 1, f = 3: d(z) = 3 (z - 1) / (2 z), so
           z_view(d) = 3 / (3 - 2 d); T = 1:
           d = 0    -> z = 1   -> z' = 2   -> b = 3 * 1 / 4     = 0.75
           d = 0.5  -> z = 1.5 -> z' = 2.5 -> b = 3 * 1.5 / 5   = 0.9
           d = 0.6  -> z = 5/3 -> z' = 8/3 -> b = 3 * 5/3 / (16/3) = 15/16
           d = 0.75 -> z = 2   -> z' = 3 = f: the far plane, b = 1 */
        set_row4(&m, 0, 0.5, 0.6, 0.75);
        CHECK(ref_map_set_back_constant(&m, 1, 1, 3) == 0, "constant n=1 f=3 T=1");
        CHECK(near_f(m.b[0], 0.75) && near_f(m.b[1], 0.9) && near_f(m.b[2], 15.0 / 16) && near_f(m.b[3], 1),
              "constant f=3: %.17g %.17g %.17g %.17g", m.b[0], m.b[1], m.b[2], m.b[3]);
        /* bit-exact, c0 = 1.5, c1 = 1 (by hand, checked the same way):
           d = 0: u = 1.5, q = 1, 2 / u = 4/3 rounds to 11184811 * 2^-23,
           e = 1 / that = 0.75 (1 - 3.0e-8), 0.375 ulp below 0.75: e = 0.75,
           b = 0.75. d = 0.5: u = 1, q = 1.5, 2.5 / u = 2.5, e = 0.4f =
           13421773 * 2^-25, d + e = 30198989 * 2^-25, a tie between floats
           (spacing 2^-24): the even 15099494 * 2^-24 = 0.9f, 0.4 ulp below
           0.9. d = 0.75: u = 0.75, q = 2, 3 / u = 4, e = 0.25, b = 1
           exactly, the exact b (z' = f). */
        CHECK(m.b[0] == 0.75 && m.b[1] == ldexp(15099494.0, -24) && m.b[1] == (double)0.9f && m.b[3] == 1,
              "constant f=3, bits: %a %a %a", m.b[0], m.b[1], m.b[3]);
        /* relative, n = 1, f = inf, k = 1: d = 0 -> z = 1 -> z' = 2 -> b = 0.5;
           d = 0.5 -> z = 2 -> z' = 4 -> b = 0.75; d = 0.75 -> z = 4 -> z' = 8
           -> b = 0.875; d = 1 -> 1 */
        set_row4(&m, 0, 0.5, 0.75, 1);
        CHECK(ref_map_set_back_relative(&m, 1, 1, inf) == 0, "relative n=1 f=inf k=1");
        CHECK(m.b[0] == 0.5 && m.b[1] == 0.75 && m.b[2] == 0.875 && m.b[3] == 1,
              "relative f=inf: %.17g %.17g %.17g %.17g", m.b[0], m.b[1], m.b[2], m.b[3]);
        /* relative, n = 1, f = 3, k = 0.5: d = 0 -> z = 1 -> z' = 1.5
           -> b = 3 * 0.5 / 3 = 0.5; d = 0.5 -> z = 1.5 -> z' = 2.25
           -> b = 3 * 1.25 / 4.5 = 5/6; d = 0.75 -> z = 2 -> z' = 3 = f -> 1 */
        set_row4(&m, 0, 0.5, 0.75, 1);
        CHECK(ref_map_set_back_relative(&m, 0.5, 1, 3) == 0, "relative n=1 f=3 k=0.5");
        CHECK(near_f(m.b[0], 0.5) && near_f(m.b[1], 5.0 / 6) && near_f(m.b[2], 1) && m.b[3] == 1,
              "relative f=3: %.17g %.17g %.17g %.17g", m.b[0], m.b[1], m.b[2], m.b[3]);
        /* bit-exact: c0 = 0.5 * 1.5 = 0.75, c1 = 1.5: (0 + 0.75) / 1.5 = 0.5;
           (0.75 + 0.75) / 1.5 = 1 */
        CHECK(m.b[0] == 0.5 && m.b[2] == 1, "relative f=3, bits: %a %a", m.b[0], m.b[2]);
        ref_map_free(&m);
    }
    {
        /* (b) clamped to 1 when z_view(d) + T reaches past the far plane:
           n = 1, f = 3, T = 1, d = 0.8 -> z = 3/1.4 = 2.14 -> z' = 3.14 > f;
           relative k = 0.5, d = 0.9 -> z = 2.5 -> z' = 3.75 > f; f = inf
           with a huge T rounds to 1; an overflowing z' (T = DBL_MAX,
           k * z = inf) is 1 too. d = 1 keeps b = 1 in every model. */
        ref_map m = map_const(4, 1, 0.0);
        set_row4(&m, 0.8, 0.9, 0.99, 1);
        CHECK(ref_map_set_back_constant(&m, 1, 1, 3) == 0 && m.b[0] == 1 && m.b[1] == 1 && m.b[2] == 1 &&
                  m.b[3] == 1,
              "constant past far: %.17g %.17g %.17g %.17g", m.b[0], m.b[1], m.b[2], m.b[3]);
        CHECK(ref_map_set_back_relative(&m, 0.5, 1, 3) == 0 && near_f(m.b[0], persp_depth(1.5 * 3 / 1.4, 1, 3)) &&
                  m.b[1] == 1 && m.b[2] == 1 && m.b[3] == 1,
              "relative past far: %.17g %.17g %.17g %.17g", m.b[0], m.b[1], m.b[2], m.b[3]);
        CHECK(ref_map_set_back_constant(&m, 1e300, 1, inf) == 0 && m.b[0] == 1 && m.b[3] == 1,
              "huge T, infinite far: %.17g", m.b[0]);
        CHECK(ref_map_set_back_constant(&m, DBL_MAX, 1e10, inf) == 0 && m.b[2] == 1 && m.b[3] == 1,
              "overflowing z + T: %.17g", m.b[2]);
        CHECK(ref_map_set_back_relative(&m, 1e308, 1, 1e300) == 0 && m.b[0] == 1 && m.b[3] == 1,
              "overflowing k * z: %.17g", m.b[0]);
        set_row4(&m, 1, 1, 1, 1); /* a far map: every model keeps b = 1 */
        CHECK(ref_map_set_back_constant(&m, 1e-6, 1, 3) == 0 && m.b[0] == 1 && m.b[3] == 1, "d = 1, constant");
        CHECK(ref_map_set_back_relative(&m, 1e-6, 1, inf) == 0 && m.b[0] == 1 && m.b[3] == 1, "d = 1, relative");
        ref_map_free(&m);
    }
    {
        /* (c) d <= b <= 1 for every d and many projections and thicknesses
           (tiny ones lost in z + T give b = d), and the double definition
           (ref_back_*_exact) against the literal one: d = depth(z),
           b = depth(z + T). The recipe against the definition: (i). */
        static const double nf[][2] = { { 1, HUGE_VAL }, { 1, 3 }, { 0.1, 1000 }, { 1e-300, HUGE_VAL },
                                        { 1, 1.0000000000000002 }, { 1, DBL_MAX }, { 1e300, HUGE_VAL } };
        static const double th[] = { 1e-300, 1e-12, 0.01, 0.5, 1, 7, 1e6, 1e300 };
        ref_map m = map_const(67, 1, 0.0);
        int p, q, bad = 0, bad_lit = 0;
        for (k = 0; k <= 64; k++) m.d[k] = k / 64.0;
        m.d[65] = nextafter(1.0, 0.0);
        m.d[66] = 1e-300;
        for (p = 0; p < (int)(sizeof nf / sizeof nf[0]); p++)
            for (q = 0; q < (int)(sizeof th / sizeof th[0]); q++) {
                int rel;
                for (rel = 0; rel < 2; rel++) {
                    int ok = rel ? ref_map_set_back_relative(&m, th[q], nf[p][0], nf[p][1])
                                 : ref_map_set_back_constant(&m, th[q], nf[p][0], nf[p][1]);
                    if (ok != 0) { bad++; continue; }
                    for (k = 0; k < m.w; k++)
                        if (!(m.b[k] >= m.d[k] && m.b[k] <= 1) && bad++ < 5)
                            printf("b out of [d, 1]: n %g f %g %s %g d %.17g b %.17g\n", nf[p][0], nf[p][1],
                                   rel ? "k" : "T", th[q], m.d[k], m.b[k]);
                }
            }
        CHECK(bad == 0, "%d back depths out of [d, 1]", bad);
        /* round trip: view distances z -> d = depth(z) -> b ~ depth(z + T).
           These d are doubles, not floats (a hand-made map): the map's
           recipe reads each as the nearest float and keeps b >= d; it must
           equal the per-depth ref_back_*_recipe. */
        for (p = 0; p < 3; p++) {
            double n = nf[p][0], f = nf[p][1], T = p == 2 ? 0.5 : 2;
            for (k = 0; k < m.w; k++) m.d[k] = persp_depth(n * pow(1.1, k), n, f);
            for (q = 0; q < 2; q++) {
                CHECK((q ? ref_map_set_back_relative(&m, 0.25, n, f) : ref_map_set_back_constant(&m, T, n, f)) == 0,
                      "round trip set");
                for (k = 0; k < m.w; k++) {
                    double z = n * pow(1.1, k), want = m.d[k] >= 1 ? 1 : persp_depth(z + (q ? 0.25 * z : T), n, f);
                    double ex = q ? ref_back_relative_exact(m.d[k], 0.25, n, f) : ref_back_constant_exact(m.d[k], T, n, f);
                    double rc = q ? ref_back_relative_recipe(m.d[k], 0.25, n, f)
                                  : ref_back_constant_recipe(m.d[k], T, n, f);
                    if (!(fabs(ex - want) <= 1e-12) && bad_lit++ < 5)
                        printf("round trip: n %g f %g %s z %.17g d %.17g b %.17g want %.17g\n", n, f,
                               q ? "relative" : "constant", z, m.d[k], ex, want);
                    if (!(m.b[k] == rc && m.b[k] >= m.d[k]) && bad_lit++ < 5)
                        printf("map vs recipe: n %g f %g %s d %.17g map b %.17g recipe %.17g\n", n, f,
                               q ? "relative" : "constant", m.d[k], m.b[k], rc);
                }
            }
        }
        CHECK(bad_lit == 0, "%d back depths differ from the definition or the recipe", bad_lit);
        ref_map_free(&m);
    }
    {
        /* (d) a reversed-Z map is forward depth once read: the same backs */
        float fwd[4] = { 0.0f, 0.5f, 0.75f, 1.0f }, rev[4] = { 1.0f, 0.5f, 0.25f, 0.0f };
        ref_map mf, mr;
        CHECK(ref_map_from_raw(&mf, fwd, 4, 1, 0, REF_FORMAT_FLOAT32, 0) == 0 &&
                  ref_map_from_raw(&mr, rev, 4, 1, 0, REF_FORMAT_FLOAT32, 1) == 0,
              "from_raw fwd/rev");
        CHECK(ref_map_set_back_constant(&mf, 1, 1, inf) == 0 && ref_map_set_back_constant(&mr, 1, 1, inf) == 0,
              "set_back_constant fwd/rev");
        for (k = 0; k < 4; k++) CHECK(mf.b[k] == mr.b[k], "reversed back %d: %.17g vs %.17g", k, mr.b[k], mf.b[k]);
        CHECK(mr.b[0] == 0.5 && mr.b[3] == 1, "reversed: near texel %.17g, far texel %.17g", mr.b[0], mr.b[3]);
        ref_map_free(&mf);
        ref_map_free(&mr);
    }
    {
        /* (e) bad parameters: -1, and the map (and an earlier back map) unchanged */
        const double nan = strtod("nan", NULL);
        static const double bad_amount[] = { 0, -0.0, -1, HUGE_VAL, -HUGE_VAL, 0 /* NaN below */ };
        ref_map m = map_const(2, 2, 0.5);
        double *d0 = m.d, *b0;
        int rel, failed = 0;
        for (rel = 0; rel < 2; rel++) {
            int (*set)(ref_map *, double, double, double) = rel ? ref_map_set_back_relative
                                                                : ref_map_set_back_constant;
            for (k = 0; k < (int)(sizeof bad_amount / sizeof bad_amount[0]); k++) {
                double t = k == 5 ? nan : bad_amount[k];
                if (set(&m, t, 1, inf) != -1 && failed++ < 5) printf("amount %g accepted\n", t);
            }
            /* near: zero, negative, infinite, NaN */
            if (set(&m, 1, 0, inf) != -1) failed++;
            if (set(&m, 1, -0.0, inf) != -1) failed++;
            if (set(&m, 1, -1, 3) != -1) failed++;
            if (set(&m, 1, inf, inf) != -1) failed++;
            if (set(&m, 1, nan, 3) != -1) failed++;
            /* far: equal to near, before it, -inf, NaN */
            if (set(&m, 1, 1, 1) != -1) failed++;
            if (set(&m, 1, 2, 1) != -1) failed++;
            if (set(&m, 1, 1, -inf) != -1) failed++;
            if (set(&m, 1, 1, nan) != -1) failed++;
            if (set(NULL, 1, 1, inf) != -1) failed++;
        }
        CHECK(failed == 0, "%d bad parameter sets accepted", failed);
        CHECK(m.b == NULL && m.d == d0 && m.w == 2 && m.h == 2 && m.d[0] == 0.5, "bad parameters changed the map");
        /* an earlier back map is replaced on success, kept on failure */
        set_back_const(&m, 0.75f);
        CHECK(ref_map_set_back_constant(&m, 0.5, 1, inf) == 0 && near_f(m.b[0], 0.6) && m.b[3] == m.b[0],
              "constant replaces a raw back map: %.17g", m.b[0]);
        b0 = m.b;
        CHECK(ref_map_set_back_relative(&m, -1, 1, inf) == -1 && m.b == b0 && near_f(m.b[0], 0.6),
              "a failed set_back_relative changed the back map");
        CHECK(ref_map_set_back_relative(&m, 1, 1, inf) == 0 && m.b[0] == 0.75, "relative replaces constant");
        ref_map_free(&m);
        CHECK(ref_map_set_back_constant(&m, 1, 1, inf) == -1 && ref_map_set_back_relative(&m, 1, 1, inf) == -1,
              "a freed map accepted");
    }
    {
        /* (f) traced: a thin layer d = 0.5 (z_view = 2 at n = 1, f = inf)
           with a thicker texel 3 (d = 0.65, z_view = 1/0.35 = 2.857).
           T = 0.5: b = 1 - 1/2.5 = 0.6 for texels 0..2 and 1 - 1/3.357 = 0.702
           for texel 3; relative k = 0.25: z' = 2.5, b = 0.6 again, and
           1 - 1/3.571 = 0.72 for texel 3. A level ray at z = 0.7 passes under
           the layer and hits texel 3's side at x = 3; with infinite
           thickness it hits the first texel's side at x = 0. */
        ref_map m = map_const(4, 1, 0.5);
        ref_ray under = mkray(-1, 0.5, 0.7, 1, 0, 0, 0, 5);
        ref_ray deep = mkray(-1, 0.5, 0.75, 1, 0, 0, 0, 5); /* under every texel's back */
        set_d(&m, 3, 0, 0.65);
        r = ref_trace_ray(&m, &under);
        EXPECT_HIT(r, 1, 0, 0);
        EXPECT_FACE(r, REF_FACE_SIDE);
        for (k = 0; k < 2; k++) {
            CHECK((k ? ref_map_set_back_relative(&m, 0.25, 1, inf) : ref_map_set_back_constant(&m, 0.5, 1, inf)) == 0,
                  "layer set %d", k);
            CHECK(near_f(m.b[0], 0.6) && m.b[3] > 0.7 && m.b[3] < 0.73, "layer backs %.17g %.17g", m.b[0], m.b[3]);
            r = ref_trace_ray(&m, &under);
            EXPECT_HIT(r, 4, 3, 0);
            EXPECT_FACE(r, REF_FACE_SIDE);
            a = ans(REF_HIT, 4, 3, 0);
            a.face = REF_FACE_SIDE;
            CHECK(ref_check(&m, &under, &a, 0, why, sizeof why), "past the layer refused (%d): %s", k, why);
            a = ans(REF_HIT, 1, 0, 0); /* the infinite-thickness answer */
            CHECK(!ref_check(&m, &under, &a, 0, why, sizeof why), "a hit on the layer's shadow accepted (%d)", k);
            r = ref_trace_ray(&m, &deep);
            EXPECT_KIND(r, REF_MISS_TMAX);
            r = tr(&m, mkray(-1, 0.5, 0.55, 1, 0, 0, 0, 5)); /* within the layer: its side */
            EXPECT_HIT(r, 1, 0, 0);
        }
        free(m.b);
        m.b = NULL;
        r = ref_trace_ray(&m, &deep);
        EXPECT_HIT(r, 1, 0, 0);
        set_d(&m, 3, 0, 0.5);
        /* finite far: n = 1, f = 3, T = 1, d = 0.5 -> b = 0.9 (see (a));
           z = 0.95 passes under, z = 0.85 meets the side; d = 0.8 is
           clamped to 1 and stops z = 0.95 like infinite thickness */
        CHECK(ref_map_set_back_constant(&m, 1, 1, 3) == 0, "layer f=3");
        r = tr(&m, mkray(-1, 0.5, 0.95, 1, 0, 0, 0, 5));
        EXPECT_KIND(r, REF_MISS_TMAX);
        r = tr(&m, mkray(-1, 0.5, 0.85, 1, 0, 0, 0, 5));
        EXPECT_HIT(r, 1, 0, 0);
        set_d(&m, 2, 0, 0.8);
        CHECK(ref_map_set_back_constant(&m, 1, 1, 3) == 0 && m.b[2] == 1, "clamped texel");
        r = tr(&m, mkray(-1, 0.5, 0.95, 1, 0, 0, 0, 5));
        EXPECT_HIT(r, 3, 2, 0);
        EXPECT_FACE(r, REF_FACE_SIDE);
        ref_map_free(&m);
    }
    {
        /* (g) the back face from behind, constant model: d = 0.5, n = 1,
           f = inf, T = 0.5 -> b = 0.6; a ray from z = 0.8 rising
           (v.z = -1) meets z = b at t = 0.8 - b. Infinite thickness: the
           origin is inside. */
        ref_map m = map_const(4, 4, 0.5);
        double t;
        ray = mkray(1.5, 1.5, 0.8, 0.25, 0, -1, 0, 10);
        r = ref_trace_ray(&m, &ray);
        EXPECT_HIT(r, 0, 1, 1);
        EXPECT_FACE(r, REF_FACE_INSIDE);
        CHECK(ref_map_set_back_constant(&m, 0.5, 1, inf) == 0 && near_f(m.b[5], 0.6), "back 0.6: %.17g", m.b[5]);
        t = (double)0.8f - m.b[5];
        r = ref_trace_ray(&m, &ray);
        EXPECT_HIT(r, t, 1, 1);
        EXPECT_FACE(r, REF_FACE_BACK);
        a = ans(REF_HIT, t, 1, 1);
        a.face = REF_FACE_BACK;
        CHECK(ref_check(&m, &ray, &a, 0, why, sizeof why), "back face (constant) refused: %s", why);
        a.face = REF_FACE_TOP;
        CHECK(!ref_check(&m, &ray, &a, 0, why, sizeof why), "top claimed for a back hit (constant) accepted");
        /* finite far, n = 1, f = 3, T = 1: b = 0.9; straight up from 0.95 */
        CHECK(ref_map_set_back_constant(&m, 1, 1, 3) == 0, "back f=3");
        r = tr(&m, mkray(2.5, 0.5, 0.95, 0, 0, -1, 0, 1));
        EXPECT_HIT(r, (double)0.95f - m.b[2], 2, 0);
        EXPECT_FACE(r, REF_FACE_BACK);
        /* tmax short of the back: a miss */
        r = tr(&m, mkray(2.5, 0.5, 0.95, 0, 0, -1, 0, 0.03125));
        EXPECT_KIND(r, REF_MISS_TMAX);
        ref_map_free(&m);
    }
    {
        /* (h) walk vs all-texel scan on random maps with both models (the
           generator's state restored: test_random keeps its rays) */
        unsigned long long saved = g_rng;
        int n, q, bad = 0, count = 0;
        for (n = 0; n < 60; n++) {
            int w = 1 + (int)(rnd() * 8), h = 1 + (int)(rnd() * 8);
            ref_map m = map_const(w, h, 1);
            double nz = 0.05 + rnd(), fz = n % 3 == 0 ? inf : nz * (2 + 100 * rnd());
            for (k = 0; k < w * h; k++) m.d[k] = rnd() < 0.1 ? 1.0 : rnd();
            if ((n % 2 ? ref_map_set_back_relative(&m, 0.02 + rnd(), nz, fz)
                       : ref_map_set_back_constant(&m, nz * (0.02 + 2 * rnd()), nz, fz)) != 0)
                bad++;
            for (q = 0; q < 60; q++) {
                ref_result rr, bb;
                ref__ev be;
                int c, ok;
                ray.o[0] = to_f32(rnd_coord(-2, w + 2, 0));
                ray.o[1] = to_f32(rnd_coord(-2, h + 2, 0));
                ray.o[2] = to_f32(rnd_coord(-0.5, 1.5, 0));
                for (c = 0; c < 3; c++) ray.v[c] = to_f32(rnd_coord(-3, 3, 0));
                ray.tmin = 0;
                ray.tmax = to_f32(rnd_coord(0, 6, 0));
                count++;
                rr = ref_trace_ray(&m, &ray);
                bb = brute(&m, &ray, &be);
                ok = rr.kind == bb.kind;
                if (ok && rr.kind == REF_HIT) {
                    /* the same exact t (a tie between texels may name another texel, by another face) */
                    double o[3], v[3];
                    ref__ev t0 = ref__ev_scalar(ray.tmin), t1 = ref__ev_scalar(ray.tmax), e;
                    int face;
                    for (c = 0; c < 3; c++) { o[c] = ray.o[c]; v[c] = ray.v[c]; }
                    ok = ref__texel(&m, rr.x, rr.y, o, v, &t0, &t1, &e, &face) && ref__cmp(&e, &be) == 0 &&
                         face == rr.face && (rr.x != bb.x || rr.y != bb.y || (rr.t == bb.t && rr.face == bb.face));
                }
                if (!ok && bad++ < 5)
                    printf("models vs brute: kind %d/%d t %.17g/%.17g face %d/%d map %dx%d\n", rr.kind, bb.kind,
                           rr.t, bb.t, rr.face, bb.face, w, h);
                a.kind = rr.kind; a.t = (float)rr.t; a.x = rr.x; a.y = rr.y; a.face = rr.face;
                if (!ref_check(&m, &ray, &a, 0, why, sizeof why) && bad++ < 5)
                    printf("models: check refuses the reference: %s\n", why);
            }
            ref_map_free(&m);
        }
        g_rng = saved;
        CHECK(bad == 0, "%d of %d rays on perspective-thickness maps disagree", bad, count);
    }
}

/* The float32 recipe of the constant and relative models (the top of
   reference.h: what ref_map_set_back_constant and ref_map_set_back_relative
   store, and what the library computes) against their double definition
   (ref_back_constant_exact, ref_back_relative_exact), over projections
   (near 0.01 .. 10, far / near 1.01 .. 1e6 and infinite), thicknesses
   (1e-7 .. 1e7; relative k likewise) and depths from float32, unorm8 and
   unorm16 maps read by ref_map_from_raw (dense in [0, 1], with values
   near 0 and within a few ulps of 1). The error, in float32 ulps at b's
   magnitude and absolute, is a few ulps everywhere in both models:
   - relative model: b = (d + k s) / (1 + k) adds positive terms;
   - constant model: b = d + e, e = c1 / ((q + c1) / u), in reals
     (s - d) T / (z_view + T) >= 0: a chain of divisions of positive values (and
     one difference u = s - d of a constant and the depth), each rounded
     once, and the depth d added last: small b (d near 0 with T small
     next to n) and far close to near (s up to 101) included. (The
     earlier recipe b = (1 - n / z') s lost up to 2.2e7 ulps, 1.68e-5
     absolute, there.)
   The tracer and the reference agree bit for bit either way; this bounds
   how far both are from docs/MODEL.md's b. */
/* The recipe once more, transcribed from its text for a float32 depth d
   (a second copy, to catch an edit of reference.h that lets a step skip
   its rounding, e.g. a contraction under -march=native): every step a
   volatile float. */
static double recipe_again(float d, int rel, double amt, double n, double f)
{
    double s = f > DBL_MAX ? 1.0 : f / (f - n);
    volatile float c0 = to_f32(rel ? amt * s : s), c1 = to_f32(rel ? 1.0 + amt : amt / n);
    volatile float t1, t2, t3, t4, t5, b;
    if (rel) {
        t1 = d + c0;
        b = t1 / c1;
    } else {
        t1 = c0 - d;  /* u */
        t2 = c0 / t1; /* q */
        t3 = t2 + c1;
        t4 = t3 / t1;
        t5 = c1 / t4; /* e */
        b = d + t5;
    }
    if (!(b <= 1.0f)) b = 1.0f;
    if (b < d) b = d;
    return b;
}

static void test_thickness_recipe(void)
{
    static const double nears[] = { 0.01, 0.1, 1, 10 };
    static const double ratios[] = { 0 /* infinite far */, 1.01, 1.5, 2, 10, 100, 1e3, 1e4, 1e5, 1e6 };
    static const double amounts[] = { 1e-7, 1e-5, 1e-3, 0.01, 0.1, 0.5, 1, 3, 10, 100, 1e3, 1e5, 1e7 };
    float *fd = (float *)malloc(4096 * sizeof(float));
    unsigned char u8[256];
    unsigned short *u16 = (unsigned short *)malloc(4096 * sizeof(unsigned short));
    ref_map mf, m8, m16, m;
    int nf = 0, n16 = 0, k, i, bad = 0, bad_unorm = 0, bad_again = 0;
    double rel_ulps = 0, rel_abs = 0, con_ulps = 0, con_abs = 0;
    /* float32 depths: a grid, 0 and 1, values near 0, and near 1 */
    for (i = 0; i < 2048; i++) fd[nf++] = (float)((i + 0.5) / 2048);
    fd[nf++] = 0.0f;
    fd[nf++] = 1.0f;
    for (i = 1; i <= 149; i += 2) fd[nf++] = (float)ldexp(1.0, -i);
    for (i = 1; i <= 64; i++) fd[nf++] = (float)ldexp(i, -30);
    for (i = 1; i <= 128; i++) fd[nf++] = (float)(1.0 - ldexp(i, -24));
    for (i = 1; i <= 64; i++) fd[nf++] = (float)(1.0 - ldexp(i, -18));
    /* unorm8: every value; unorm16: both ends and every 31st */
    for (i = 0; i < 256; i++) u8[i] = (unsigned char)i;
    for (i = 0; i < 65536; i++)
        if (i < 128 || i >= 65408 || i % 31 == 0) u16[n16++] = (unsigned short)i;
    CHECK(ref_map_from_raw(&mf, fd, nf, 1, 0, REF_FORMAT_FLOAT32, 0) == 0 &&
              ref_map_from_raw(&m8, u8, 256, 1, 0, REF_FORMAT_UNORM8, 0) == 0 &&
              ref_map_from_raw(&m16, u16, n16, 1, 0, REF_FORMAT_UNORM16, 0) == 0,
          "recipe sweep maps");
    m = map_const(nf + 256 + n16, 1, 0.0);
    memcpy(m.d, mf.d, (size_t)nf * sizeof(double));
    memcpy(m.d + nf, m8.d, 256 * sizeof(double));
    memcpy(m.d + nf + 256, m16.d, (size_t)n16 * sizeof(double));
    ref_map_free(&mf);
    ref_map_free(&m8);
    ref_map_free(&m16);
    free(fd);
    free(u16);

    /* a unorm depth d = v / max (double) is read by the recipe as the
       float32 division (float)v / (float)max, which is also (float)d */
    for (i = 0; i < 65536; i++) {
        int mx;
        for (mx = 0; mx < 2; mx++) {
            double max = mx ? 65535.0 : 255.0, dd = i / max;
            volatile float fv = (float)i, fm = (float)max, q;
            if (i > max) continue;
            q = fv / fm;
            if (!(ref__depth_f32(dd) == q && (float)dd == q) && bad_unorm++ < 5)
                printf("unorm depth %d/%g: recipe d %.9g, float division %.9g\n", i, max,
                       (double)ref__depth_f32(dd), (double)q);
        }
    }
    CHECK(bad_unorm == 0, "%d unorm depths read unlike (float)v / (float)max", bad_unorm);

    for (i = 0; i < 2 * 4 * 10 * 13; i++) {
        int rel = i % 2, a = i / 2 % 13, r = i / 26 % 10, p = i / 260;
        double n = to_f32(nears[p]), f = ratios[r] == 0 ? HUGE_VAL : to_f32(nears[p] * ratios[r]);
        double amt = to_f32(amounts[a]);
        if ((rel ? ref_map_set_back_relative(&m, amt, n, f) : ref_map_set_back_constant(&m, amt, n, f)) != 0) {
            bad++;
            continue;
        }
        for (k = 0; k < m.w; k++) {
            double d = m.d[k], b = m.b[k];
            double x = rel ? ref_back_relative_exact(d, amt, n, f) : ref_back_constant_exact(d, amt, n, f);
            double err = fabs(b - x), ulps = err / ulp_f32(x), again;
            /* constants past FLT_MAX do not occur here: to_f32 is a plain cast */
            again = recipe_again((float)d, rel, amt, n, f);
            if (again < d) again = d;
            if (b != again && bad_again++ < 5)
                printf("recipe: map b %a, transcribed %a: d %.17g n %g f %g %s %g\n", b, again, d, n, f,
                       rel ? "k" : "T", amt);
            /* a float in [d, 1] (or d itself: a unorm d is not a float); d = 1 keeps 1 */
            if (!(b >= d && b <= 1 && ((double)(float)b == b || b == d) && (d < 1 || b == 1)) && bad++ < 5)
                printf("recipe: b %.17g out of [d, 1] or not a float: d %.17g n %g f %g %s %g\n", b, d, n, f,
                       rel ? "k" : "T", amt);
            if (rel) {
                if (ulps > rel_ulps) rel_ulps = ulps;
                if (err > rel_abs) rel_abs = err;
            } else {
                if (ulps > con_ulps) con_ulps = ulps;
                if (err > con_abs) con_abs = err;
            }
        }
    }
    ref_map_free(&m);
    CHECK(bad == 0, "%d recipe back depths out of [d, 1], not floats, or refused", bad);
    CHECK(bad_again == 0, "%d recipe back depths differ from the transcription", bad_again);
    printf("recipe vs definition, everywhere: relative model %.2f ulps, %.3g abs; constant model %.2f ulps, "
           "%.3g abs\n",
           rel_ulps, rel_abs, con_ulps, con_abs);
    /* This sweep measures 2.27 ulps, 1.35e-07 abs (relative) and 4.18
       ulps, 2.05e-07 abs (constant). A random search of 1.26e9 samples of
       the constant model (a throwaway program, 110 s of CPU; log-uniform
       near 0.01 .. 10, far / near 1.01 .. 1e6 or infinite, T 1e-7 .. 1e7,
       each rounded to float32; float depths uniform, over all bit
       patterns, near 0 and near 1, unorm8 and unorm16 ones) found more:
       6.21 ulps (d = 0x1.443cacp-10, n = 0x1.2f79d8p+2,
       f = 0x1.2a38a8p+10, T = 0x1.45c682p-1: b = 0.1197) and 2.99e-07 abs
       (d = 0x1.27058p-18, n = 0x1.f4115p+1, f = 0x1.09f482p+2,
       T = 0x1.f697fcp-3: b = 0.987, s = 16.7), both confirmed in exact
       rational arithmetic; an earlier search of 3e8 samples found 3.26
       ulps for the relative model. The bounds are a margin over the
       largest of these: 4 ulps for the relative model (about what its
       four roundings of at most 2^-24 relative each, and the unorm d's,
       can reach), 6.5 ulps and 3.2e-7 abs for the constant one (eight
       roundings: c0, c1 and six steps). */
    CHECK(rel_ulps <= 4, "relative model: recipe %.3g ulps from the definition", rel_ulps);
    CHECK(con_ulps <= 6.5, "constant model: recipe %.3g ulps from the definition", con_ulps);
    CHECK(con_abs <= 3.2e-7, "constant model: recipe %.3g abs from the definition", con_abs);
}

static void test_random(void)
{
    static const double levels[6] = { 0, 0.25, 0.5, 0.75, 1, 0.3 };
    int n, bad_brute = 0, bad_sample = 0, bad_check = 0, count = 0;
    for (n = 0; n < 400; n++) {
        int w = 1 + (int)(rnd() * 9), h = 1 + (int)(rnd() * 9), k, q;
        ref_map m = map_const(w, h, 1);
        for (k = 0; k < w * h; k++) m.d[k] = n % 2 ? levels[(int)(rnd() * 6)] : rnd();
        if (n % 4 >= 2) {
            /* finite thickness: backs behind the surface (on the quarter
               grid for the level maps, so quantised rays graze them), in
               front of it (clamped to d), NaN (the far plane) */
            float *bk = (float *)malloc((size_t)w * (size_t)h * sizeof(float));
            for (k = 0; k < w * h; k++) {
                double u = rnd();
                if (u < 0.15) bk[k] = (float)(m.d[k] * rnd());
                else if (u < 0.25) bk[k] = (float)strtod("nan", NULL);
                else if (n % 2) bk[k] = (float)(m.d[k] + 0.25 * (int)(rnd() * 3));
                else bk[k] = (float)(m.d[k] + 0.5 * rnd());
            }
            if (ref_map_set_back_from_raw(&m, bk, 0, REF_FORMAT_FLOAT32, 0) != 0) bad_brute++;
            free(bk);
        }
        for (q = 0; q < 100; q++) {
            int quant = (q % 3) != 0, c;
            ref_ray ray;
            ref_result r, b;
            ref__ev be;
            double o[3], v[3];
            ray.o[0] = (float)rnd_coord(-2, w + 2, quant);
            ray.o[1] = (float)rnd_coord(-2, h + 2, quant);
            ray.o[2] = (float)rnd_coord(-0.5, 1.5, quant);
            for (c = 0; c < 3; c++) {
                double s = rnd();
                ray.v[c] = s < 0.15 ? 0.0f : (float)rnd_coord(-3, 3, quant);
            }
            ray.tmin = rnd() < 0.5 ? 0.0f : (float)rnd_coord(0, 1, quant);
            ray.tmax = ray.tmin + (float)rnd_coord(0, 6, quant);
            for (c = 0; c < 3; c++) { o[c] = ray.o[c]; v[c] = ray.v[c]; }
            count++;
            r = ref_trace_ray(&m, &ray);
            b = brute(&m, &ray, &be);
            /* walk vs all-texel scan: same kind, same exact t, and the
               reported texel is entered at that same t */
            if (r.kind != b.kind) {
                if (bad_brute++ < 5)
                    printf("brute kind: ref %d brute %d ray o(%.9g %.9g %.9g) v(%.9g %.9g %.9g) "
                           "[%.9g %.9g] map %dx%d\n", r.kind, b.kind, o[0], o[1], o[2], v[0],
                           v[1], v[2], (double)ray.tmin, (double)ray.tmax, w, h);
            } else if (r.kind == REF_HIT) {
                ref__ev t0 = ref__ev_scalar(ray.tmin), t1 = ref__ev_scalar(ray.tmax), e;
                int face, ok = ref__texel(&m, r.x, r.y, o, v, &t0, &t1, &e, &face) && ref__cmp(&e, &be) == 0;
                /* the same texel entered by the same face (another texel at the same t may be another face) */
                ok = ok && (r.x != b.x || r.y != b.y || (face == r.face && r.face == b.face));
                if (!ok && bad_brute++ < 5)
                    printf("brute t: ref %.17g (%d,%d) brute %.17g (%d,%d)\n", r.t, r.x, r.y,
                           b.t, b.x, b.y);
            }
            /* independent: the hit point is in the solid; no sample before it
               (or at all, for a miss) is strictly inside the solid */
            {
                int s, ok = 1, ns = 400;
                double tend = r.kind == REF_HIT ? r.t : (double)ray.tmax;
                if (r.kind == REF_HIT) {
                    if (!(r.t >= ray.tmin && r.t <= ray.tmax)) ok = 0;
                    if (!on_solid(&m, o[0] + r.t * v[0], o[1] + r.t * v[1], o[2] + r.t * v[2],
                                  1e-9))
                        ok = 0;
                    {
                        double px = o[0] + r.t * v[0], py = o[1] + r.t * v[1],
                               pz = o[2] + r.t * v[2], d = m.d[r.y * w + r.x],
                               bk = back_of(&m, r.x, r.y);
                        if (!(px >= r.x - 1e-9 && px <= r.x + 1 + 1e-9 && py >= r.y - 1e-9 &&
                              py <= r.y + 1 + 1e-9 && pz >= d - 1e-9 && pz <= bk + 1e-9))
                            ok = 0;
                    }
                }
                for (s = 0; s <= ns && ok; s++) {
                    double t = ray.tmin + (tend - ray.tmin) * s / ns;
                    if (t >= tend - 1e-9 * (1 + tend) && r.kind == REF_HIT) break;
                    if (in_solid(&m, o[0] + t * v[0], o[1] + t * v[1], o[2] + t * v[2], 1e-9))
                        ok = 0;
                }
                if (!ok && bad_sample++ < 5)
                    printf("sample: ref kind %d t %.17g (%d,%d) ray o(%.9g %.9g %.9g) "
                           "v(%.9g %.9g %.9g) [%.9g %.9g]\n", r.kind, r.t, r.x, r.y, o[0], o[1],
                           o[2], v[0], v[1], v[2], (double)ray.tmin, (double)ray.tmax);
            }
            /* the comparator accepts the reference's own answer */
            {
                ref_answer a;
                char why[512];
                a.kind = r.kind; a.t = (float)r.t; a.x = r.x; a.y = r.y; a.face = r.face;
                if (!ref_check(&m, &ray, &a, 0, why, sizeof why) && bad_check++ < 5)
                    printf("check refuses the reference: %s\n", why);
            }
        }
        ref_map_free(&m);
    }
    CHECK(bad_brute == 0, "%d of %d random rays differ from the all-texel scan", bad_brute, count);
    CHECK(bad_sample == 0, "%d of %d random rays fail the sampling check", bad_sample, count);
    CHECK(bad_check == 0, "%d of %d random rays: comparator refuses the reference", bad_check,
          count);
}

int main(int argc, char **argv)
{
    check_select(argc, argv);
    RUN_TEST(test_one_texel);
    RUN_TEST(test_floor_primary);
    RUN_TEST(test_inside_and_surface);
    RUN_TEST(test_miss_kinds);
    RUN_TEST(test_zero_direction);
    RUN_TEST(test_invalid);
    RUN_TEST(test_edges_and_corners);
    RUN_TEST(test_far_plane);
    RUN_TEST(test_huge);
    RUN_TEST(test_from_raw);
    RUN_TEST(test_check);
    RUN_TEST(test_faces);
    RUN_TEST(test_thickness);
    RUN_TEST(test_plate_check);
    RUN_TEST(test_thickness_models);
    RUN_TEST(test_thickness_recipe);
    RUN_TEST(test_random);
    return check_summary();
}
