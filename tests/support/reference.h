/* tests/support/reference.h - the exact reference tracer of the tests, and the
   comparator that judges a tracer's answers by docs/MODEL.md
   ("Right, and how right").

   Header-only, every function `static`; C99 and C++11. It shares no code with
   linear_rt.h and does not include it.

   How it is exact
   ---------------
   The model (docs/MODEL.md): texel (i, j) with depth d and back depth b is the
   closed box [i, i+1] x [j, j+1] x [d, b]; a hit is the smallest t in
   [tmin, tmax] with o + t v inside any box. Without a back map b = 1 (the
   infinite thickness: the box reaches the far plane); with one, rays may
   pass behind surfaces. The back map m->b comes from one of the thickness
   models of docs/MODEL.md ("Thickness (optional) and the face of a hit"):
   - a back-face depth pass, ref_map_set_back_from_raw: b = max(d, back);
   - a constant view-space thickness T, ref_map_set_back_constant, and a
     relative one T = k * z_view(d), ref_map_set_back_relative, under a
     perspective projection with near n > 0 and far f > n (f = +INFINITY:
     an infinite far plane), depth 0 at the near plane and 1 at the far one
     (Vulkan's): d(z) = f (z - n) / (z (f - n)) for the view-space distance
     z in [n, f] (f infinite: d = 1 - n / z), z_view = the inverse of d(z).
     docs/MODEL.md's b = d(z_view(d) + T), at most 1, b = max(d, that); d = 1
     keeps b = 1. Reversed-Z maps need nothing more: ref_map_from_raw
     already turned them into this forward depth.
     The b these two store is NOT that real number but the float32 result
     of the recipe below, which the library computes in exactly the same
     float32 steps (each rounded once, nothing fused). Why: a ray that
     grazes a back face (v.z tiny) moves its hit point along the ray by
     delta_b / v.z for any difference delta_b between the tracer's b and
     the reference's, even one under a float ulp, far past docs/MODEL.md's
     tolerance, and no perturbation of the ray explains it. The real b is
     not a float, so the tracer has to use a float b, and the reference
     judges it against the same float. The recipe, for one texel:
     - d: its depth as a float32, as the tracer reads it: a float32 map's
       clamped float (reversed: 1.0f - f in float, then the clamp); a
       unorm map's forward integer v (reversed: max - v) as
       (float)v / (float)max, max 255 or 65535, a float32 division (ref_map
       holds v / max as a double, from which v = round(d * max) exactly);
     - constants, each computed in double from the caller's values and
       rounded to float32 once: s = far / (far - near), 1 for an infinite
       far plane; constant model c0 = (float)s, c1 = (float)(T / near);
       relative model c0 = (float)(k * s), c1 = (float)(1 + k);
     - constant model, float32 steps: u = c0 - d; q = c0 / u;
       e = c1 / ((q + c1) / u); b = d + e (b = d + u c1 / (q + c1) =
       (1 - 1 / (q + c1)) c0 as q u = c0, written with divisions only so
       that no product feeds a sum and nothing can be contracted; c0 = 1,
       d = 1: u = 0, q = +inf, e = 0, b = 1). Relative model:
       b = (d + c0) / c1;
     - then: if !(b <= 1) b = 1; if (b < d) b = d (d = 1 gives b = 1);
     - the stored b is that float as a double (and at least the stored
       double d: a unorm v / max lies up to half an ulp above its float;
       such a texel is the plate [d, d]).
     The double definition stays as ref_back_constant_exact and
     ref_back_relative_exact (one d), and test_reference.c bounds the
     recipe against it, both models everywhere (small b, d near 0 with T
     small next to near, and far close to near included): relative model
     within 4 float ulps of b (measured 3.26), constant model within 6.5
     ulps and 3.2e-7 absolute (measured 6.21 ulps, 2.99e-7 by a random
     search of 1.26e9 samples). The tracer is exact with respect to the
     stored b.
   Every decision the reference makes (does a box meet the ray inside
   [tmin, tmax], which of two boxes is entered first, is the
   point at tmax on the screen) is a comparison of two numbers of the form
   (p - o_c) / v_c or a scalar t, where p is a box plane (an integer, a depth
   value d, a back depth b, or 1). Such comparisons are made exactly: a cheap
   double-precision test with a proven error bound decides the clear cases,
   and the rest (ties: rays through texel corners, along cell edges, grazing
   texel tops or backs) are decided by the exact sign of a sum of products,
   using error-free transformations (two-sum, fma two-product) and a
   growing floating-point expansion. This is exact for every ray whose
   values are float32 values widened to double (the inputs the tests pass);
   with arbitrary doubles it is exact unless a product overflows or
   underflows.
   The walk that picks the candidate boxes is a plain loop over the columns
   (or rows: the axis along which the ray moves fastest) that the ray's xy
   projection crosses, and over the 2 to 4 cells of the other axis in each;
   it is generous (a margin of 1e-9 texel) because each candidate is tested
   exactly. The reported t is the double nearest the exact hit t (within two
   ulps). Huge finite values work: the ray is clipped to the screen box
   [0,W] x [0,H] x [0,1] first, exactly, and screen positions at the clip
   events are computed from an exact expansion, so a ray with o = 1e30,
   v = -1e30 is walked over the texels it really crosses.

   The depth values are the doubles of ref_map (converted once by
   ref_map_from_raw, the back depths by ref_map_set_back_from_raw,
   ref_map_set_back_constant or ref_map_set_back_relative); the model is
   exact with respect to those doubles.
*/
#ifndef LINEAR_RT_TESTS_REFERENCE_H
#define LINEAR_RT_TESTS_REFERENCE_H

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The error-free transformations need IEEE double arithmetic rounded to
   nearest, without excess precision or reassociation. */
#if defined(__FAST_MATH__)
#error "tests/support/reference.h: do not build the exact reference with -ffast-math"
#endif
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD == 2
#error "tests/support/reference.h: needs double arithmetic without excess precision (use SSE2)"
#endif

#if defined(__GNUC__)
#define REF_FUNC static __attribute__((unused))
#else
#define REF_FUNC static
#endif

/* ---------------------------------------------------------------- API --- */

/* d[j*w+i], depth already converted: 0 near, 1 far, in [0,1].
   b[j*w+i], the back depth, d <= b <= 1; b == NULL: infinite thickness
   (b = 1 everywhere). A map built by hand must set b (NULL or malloc'd:
   ref_map_free frees it). */
typedef struct ref_map { int w, h; double *d; double *b; } ref_map;

enum { REF_HIT = 1, REF_MISS_TMAX = 2, REF_MISS_OFF_SCREEN = 3, REF_MISS_INVALID = 4 };

/* The face of the box a hit enters by (docs/MODEL.md): the top z = d, a side
   (x or y), the back z = b (from behind; the far plane without a back
   map), or inside (the origin at tmin already in the box, on none of its
   faces). REF_FACE_ANY in an answer: not reported, not checked
   (approximate tracers). */
enum { REF_FACE_ANY = -1, REF_FACE_NONE = 0, REF_FACE_TOP = 1, REF_FACE_SIDE = 2, REF_FACE_BACK = 3,
       REF_FACE_INSIDE = 4 };

/* kind as above; for a hit: t, the texel (x, y) and the face. For a miss:
   t = 0, x = y = -1, face REF_FACE_NONE. */
typedef struct ref_result { int kind; double t; int x, y, face; } ref_result;

/* what a tracer returned for a ray: kind as above, t, texel x,y, face */
typedef struct ref_answer { int kind; float t; int x, y, face; } ref_answer;

/* ray as float32 values, as the tracer saw it */
typedef struct ref_ray { float o[3], v[3], tmin, tmax; } ref_ray;

#define REF_FORMAT_UNORM8 1
#define REF_FORMAT_UNORM16 2
#define REF_FORMAT_FLOAT32 3

/* ------------------------------------------------ exact arithmetic ----- */

static int ref__finite(double x)
{
    return x == x && x != HUGE_VAL && x != -HUGE_VAL;
}

/* s + e == a + b exactly (round to nearest, no overflow) */
static void ref__two_sum(double a, double b, double *s, double *e)
{
    double x = a + b;
    double bv = x - a;
    double av = x - bv;
    *s = x;
    *e = (a - av) + (b - bv);
}

/* p + e == a * b exactly (no overflow/underflow) */
static void ref__two_prod(double a, double b, double *p, double *e)
{
    double x = a * b;
    *p = x;
    *e = fma(a, b, -x);
}

/* Sum x[0..n-1] exactly into a nonoverlapping expansion e (increasing
   magnitude, zeros allowed); returns its length (n <= 16). */
static int ref__expand(const double *x, int n, double *e)
{
    int m = 0, i, k;
    for (k = 0; k < n; k++) {
        double q = x[k];
        if (q == 0) continue;
        for (i = 0; i < m; i++) {
            double s, h;
            ref__two_sum(q, e[i], &s, &h);
            e[i] = h;
            q = s;
        }
        e[m++] = q;
    }
    return m;
}

/* exact sign of x[0] + ... + x[n-1] */
static int ref__sign_sum(const double *x, int n)
{
    double e[16];
    int m = ref__expand(x, n, e), i;
    for (i = m - 1; i >= 0; i--)
        if (e[i] != 0) return e[i] > 0 ? 1 : -1;
    return 0;
}

/* x[0] + ... + x[n-1], correct to a few ulps */
static double ref__approx_sum(const double *x, int n)
{
    double e[16], s = 0;
    int m = ref__expand(x, n, e), i;
    for (i = 0; i < m; i++) s += e[i];
    return s;
}

/* An event: the parameter t = (n0 + n1) / d exactly, d != 0;
   a is the double nearest to it within two ulps. */
typedef struct ref__ev { double n0, n1, d, a; } ref__ev;

static ref__ev ref__ev_scalar(double t)
{
    ref__ev e;
    e.n0 = t; e.n1 = 0; e.d = 1; e.a = t;
    return e;
}

/* where o + t v crosses the plane p (v != 0) */
static ref__ev ref__ev_plane(double p, double o, double v)
{
    ref__ev e;
    ref__two_sum(p, -o, &e.n0, &e.n1);
    e.d = v;
    e.a = e.n0 / v;
    return e;
}

/* exact sign of (x - y) */
static int ref__cmp(const ref__ev *x, const ref__ev *y)
{
    double a = x->a, b = y->a, t[8];
    int s;
    if (ref__finite(a) && ref__finite(b)) {
        /* each approximation is within 2.3e-16 relative of its event */
        double bound = 1e-15 * (fabs(a) + fabs(b)) + 1e-300;
        if (b - a > bound) return -1;
        if (a - b > bound) return 1;
        if (x->d == 1 && y->d == 1 && x->n1 == 0 && y->n1 == 0)
            return a < b ? -1 : (a > b ? 1 : 0);
    }
    /* (x.n0 + x.n1) * y.d - (y.n0 + y.n1) * x.d, sign-corrected by x.d*y.d */
    ref__two_prod(x->n0, y->d, &t[0], &t[1]);
    ref__two_prod(x->n1, y->d, &t[2], &t[3]);
    ref__two_prod(-y->n0, x->d, &t[4], &t[5]);
    ref__two_prod(-y->n1, x->d, &t[6], &t[7]);
    s = ref__sign_sum(t, 8);
    if ((x->d < 0) != (y->d < 0)) s = -s;
    return s;
}

/* coordinate o + t v at event e, approximately; *err bounds the error */
static double ref__coord(double o, double v, const ref__ev *e, double *err)
{
    double tv, val, eb, t[6];
    if (v == 0) { *err = 0; return o; }
    tv = v * e->a;
    val = o + tv;
    eb = 4e-16 * fabs(o) + 8e-16 * fabs(tv);
    if (ref__finite(val) && eb < 1e-7) { *err = eb + 1e-300; return val; }
    /* (o * d + v * (n0 + n1)) / d from an exact expansion */
    ref__two_prod(o, e->d, &t[0], &t[1]);
    ref__two_prod(v, e->n0, &t[2], &t[3]);
    ref__two_prod(v, e->n1, &t[4], &t[5]);
    val = ref__approx_sum(t, 6) / e->d;
    *err = 4e-15 * fabs(val) + 1e-300;
    return val;
}

/* exact: lo <= o + t v <= hi */
static int ref__in_slab_at(double o, double v, double t, double lo, double hi)
{
    double x[4];
    x[0] = o;
    ref__two_prod(t, v, &x[1], &x[2]);
    x[3] = -lo;
    if (ref__sign_sum(x, 4) < 0) return 0;
    x[0] = -o; x[1] = -x[1]; x[2] = -x[2]; x[3] = hi;
    return ref__sign_sum(x, 4) >= 0;
}

/* Exact ray/box test: the t-interval where o + t v lies in the closed box
   [lo3, hi3], intersected with [*t0, *t1]. Returns 1 and writes the
   interval's ends when it is not empty. */
static int ref__box(const double o[3], const double v[3], const double lo3[3],
                    const double hi3[3], const ref__ev *t0, const ref__ev *t1,
                    ref__ev *enter_out, ref__ev *exit_out, int *face_out)
{
    ref__ev lo = *t0, hi = *t1;
    int c, face = REF_FACE_INSIDE, along = REF_FACE_INSIDE;
    for (c = 0; c < 3; c++) {
        /* the face of axis c's plane the ray enters by: z's low plane is the top */
        const int plane_face = c < 2 ? REF_FACE_SIDE : v[c] < 0 ? REF_FACE_BACK : REF_FACE_TOP;
        ref__ev e1, e2;
        int k;
        if (v[c] == 0) {
            if (!(lo3[c] <= o[c] && o[c] <= hi3[c])) return 0;
            /* moving along a face: on it, for every t */
            if (o[c] == lo3[c] || o[c] == hi3[c])
                along = c < 2 ? REF_FACE_SIDE : o[c] == lo3[c] ? REF_FACE_TOP : REF_FACE_BACK;
            continue;
        }
        e1 = ref__ev_plane(lo3[c], o[c], v[c]);
        e2 = ref__ev_plane(hi3[c], o[c], v[c]);
        if (v[c] < 0) { ref__ev tmp = e1; e1 = e2; e2 = tmp; }
        k = ref__cmp(&e1, &lo);
        /* a plane crossed at exactly t0 puts the point on that face */
        if (k > 0 || (k == 0 && face == REF_FACE_INSIDE)) { lo = e1; face = plane_face; }
        if (ref__cmp(&e2, &hi) < 0) hi = e2;
        if (ref__cmp(&lo, &hi) > 0) return 0;
    }
    if (enter_out) *enter_out = lo;
    if (exit_out) *exit_out = hi;
    if (face_out) *face_out = face == REF_FACE_INSIDE ? along : face;
    return 1;
}

/* cells k in [0, n-1] whose closed [k, k+1] meets [lo - mg, hi + mg];
   empty when *k0 > *k1 */
static void ref__cells(double lo, double hi, double mg, int n, int *k0, int *k1)
{
    double a, b;
    if (!(lo == lo) || !(hi == hi) || !(mg == mg)) { *k0 = 0; *k1 = n - 1; return; }
    a = ceil(lo - mg) - 1;
    b = floor(hi + mg);
    if (a < 0) a = 0;
    if (a > n) a = n;
    if (b > n - 1) b = n - 1;
    if (b < -1) b = -1;
    *k0 = (int)a;
    *k1 = (int)b;
}

/* ------------------------------------------------------- depth maps --- */

/* One raw texel converted to a depth in [0, 1] (see ref_map_from_raw). */
static double ref__raw_texel(const unsigned char *p, int format, int reversed)
{
    if (format == REF_FORMAT_UNORM8) {
        double v = (double)p[0];
        return reversed ? (255.0 - v) / 255.0 : v / 255.0;
    } else if (format == REF_FORMAT_UNORM16) {
        unsigned short u;
        double v;
        memcpy(&u, p, sizeof u);
        v = (double)u;
        return reversed ? (65535.0 - v) / 65535.0 : v / 65535.0;
    } else {
        float f, g;
        memcpy(&f, p, sizeof f);
        if (reversed) {
            volatile float one_minus = 1.0f - f; /* rounded to float32 */
            g = one_minus;
        } else {
            g = f;
        }
        if (g != g || g > 1.0f) return 1.0;
        if (g < 0.0f) return 0.0;
        if (g == 0.0f) return 0.0; /* -0 -> +0 */
        if (g < 1.17549435e-38f) return 0.0; /* subnormal: read as 0 (a GPU may flush it) */
        return (double)g;
    }
}

/* A w x h raw map converted texel by texel into a new array (row-major,
   w per row), or NULL on bad arguments or out of memory. */
static double *ref__read_raw(const void *data, int w, int h, size_t row_stride, int format,
                             int reversed)
{
    size_t bpp, i, j;
    const unsigned char *base = (const unsigned char *)data;
    double *out;
    if (!data || w < 1 || h < 1) return NULL;
    if (format == REF_FORMAT_UNORM8) bpp = 1;
    else if (format == REF_FORMAT_UNORM16) bpp = 2;
    else if (format == REF_FORMAT_FLOAT32) bpp = 4;
    else return NULL;
    if ((size_t)w > ((size_t)-1) / bpp) return NULL;
    if (row_stride == 0) row_stride = (size_t)w * bpp;
    if (row_stride < (size_t)w * bpp) return NULL;
    if ((size_t)w > ((size_t)-1) / sizeof(double) / (size_t)h) return NULL;
    out = (double *)malloc((size_t)w * (size_t)h * sizeof(double));
    if (!out) return NULL;
    for (j = 0; j < (size_t)h; j++) {
        const unsigned char *row = base + j * row_stride;
        for (i = 0; i < (size_t)w; i++)
            out[j * (size_t)w + i] = ref__raw_texel(row + i * bpp, format, reversed);
    }
    return out;
}

/* Build from raw input. format: 1 = 8-bit unorm (v/255), 2 = 16-bit unorm
   (v/65535), 3 = float32. row_stride in bytes (0 = tightly packed).
   reversed != 0: reversed Z. Integer formats: d = v/max, reversed:
   d = (max - v)/max, in double. float32: f' = reversed ? 1.0f - f (in
   float32) : f; NaN and values > 1 -> 1, values < 0 and subnormal ones -> 0.
   No back map (b = NULL: infinite thickness).
   Returns 0 on success, -1 on bad arguments or out of memory (m->d = NULL). */
REF_FUNC int ref_map_from_raw(ref_map *m, const void *data, int w, int h,
                              size_t row_stride, int format, int reversed)
{
    if (!m) return -1;
    m->w = 0; m->h = 0; m->b = NULL;
    m->d = ref__read_raw(data, w, h, row_stride, format, reversed);
    if (!m->d) return -1;
    m->w = w; m->h = h;
    return 0;
}

/* Give m (built, m->w x m->h) per-texel back depths from a raw back map of
   the same size (a back-face depth pass): read and clamped exactly as
   ref_map_from_raw reads depth, then b = max(d, back), so a back in front
   of the surface makes the texel the flat plate z = d. A previous m->b is
   replaced. Returns 0 on success, -1 on bad arguments or out of memory
   (m unchanged). */
REF_FUNC int ref_map_set_back_from_raw(ref_map *m, const void *data, size_t row_stride,
                                       int format, int reversed)
{
    double *back;
    size_t k, n;
    if (!m || !m->d || m->w < 1 || m->h < 1) return -1;
    back = ref__read_raw(data, m->w, m->h, row_stride, format, reversed);
    if (!back) return -1;
    n = (size_t)m->w * (size_t)m->h;
    for (k = 0; k < n; k++)
        if (back[k] < m->d[k]) back[k] = m->d[k];
    free(m->b);
    m->b = back;
    return 0;
}

/* ------------------------------------- perspective thickness models --- */

/* The perspective depth of the thickness models (see the top of this
   file), through s = f / (f - n) (1 for an infinite far plane):
   d(z) = f (z - n) / (z (f - n)) = s (z - n) / z, and its inverse
   z_view(d) = n / (1 - d / s). The same functions as the definition,
   written with s so that a huge finite f cannot overflow (f (z - n) would
   reach f * f) and f = +INFINITY needs no case of its own. */
static double ref__persp_s(double n, double f)
{
    return f > DBL_MAX ? 1.0 : f / (f - n);
}

/* d(z): the depth of view-space distance z (n <= z < f) */
static double ref__depth_of_z(double z, double n, double s)
{
    return s * ((z - n) / z);
}

/* z_view(d): the view-space distance depth d (0 <= d < 1) stands for */
static double ref__z_of_depth(double d, double n, double s)
{
    return n / (1.0 - d / s);
}

/* The parameters both models accept (written so that a NaN fails each
   test): amount (T or k) finite and > 0, near finite and > 0, far > near
   (+INFINITY allowed). */
static int ref__persp_ok(double amount, double n, double f)
{
    if (!(amount > 0) || !ref__finite(amount)) return 0;
    if (!(n > 0) || !ref__finite(n)) return 0;
    return f > n;
}

/* The DEFINITION, in double (not what the maps hold, see the top of this
   file): b = d(z_view(d) + T), T = amount, or amount * z_view(d) when
   relative; at most 1, at least d; d = 1 (or more) gives 1. Through z_view
   and back, not a closed form in d; within a few double ulps. NaN on bad
   parameters. */
static double ref__back_exact(double d, double amount, int relative, double n, double f)
{
    double s, z, z2, b;
    if (!ref__persp_ok(amount, n, f) || !(d == d)) return strtod("nan", NULL);
    if (!(d < 1)) return 1.0; /* a far texel stays the face z = 1 (z_view(1) = f) */
    s = ref__persp_s(n, f);
    z = ref__z_of_depth(d, n, s);
    z2 = z + (relative ? amount * z : amount);
    /* at or past the far plane (z2 may overflow to +inf): clamped to 1 */
    b = z2 >= f ? 1.0 : ref__depth_of_z(z2, n, s);
    if (b > 1) b = 1;
    /* z2 > z, so b >= d but for rounding (or T lost in z + T) */
    if (!(b >= d)) b = d;
    return b;
}

/* docs/MODEL.md's constant-thickness back depth of one depth d, in double
   (for tests of the recipe; parameters as ref_map_set_back_constant) */
REF_FUNC double ref_back_constant_exact(double d, double thickness, double near_z, double far_z)
{
    return ref__back_exact(d, thickness, 0, near_z, far_z);
}

/* the same for the relative model (parameters as ref_map_set_back_relative) */
REF_FUNC double ref_back_relative_exact(double d, double k, double near_z, double far_z)
{
    return ref__back_exact(d, k, 1, near_z, far_z);
}

/* x rounded once to float32 (to nearest, ties to even), stored through a
   volatile so that no wider value survives. Magnitudes that round past
   FLT_MAX give +-infinity, as an IEEE conversion does; they are written
   out because C leaves the conversion of an out-of-range double undefined.
   2^128 - 2^103 is the midpoint between FLT_MAX and 2^128; the tie goes to
   the even 2^128, infinity. */
static float ref__f32(double x)
{
    volatile float f;
    const double big = (double)FLT_MAX + ldexp(1.0, 103);
    if (x >= big) return (float)HUGE_VAL;
    if (x <= -big) return -(float)HUGE_VAL;
    f = (float)x;
    return f;
}

/* The float32 depth d of the recipe for a texel whose converted depth (in
   ref_map) is dd: the depth the tracer reads. A float32 map's d is a float
   already (clamped, reversed: 1.0f - f in float, as ref__raw_texel reads
   it); a unorm map's dd is the double v / max, max 255 or 65535, from which
   v = round(dd * max) exactly, and the recipe's d is the float32 division
   (float)v / (float)max. (That equals (float)dd for every unorm8 and
   unorm16 value: no double rounding; the tests check it.) A hand-made map
   whose depth is neither: the nearest float. */
static float ref__depth_f32(double dd)
{
    static const double maxes[2] = { 255.0, 65535.0 };
    float f = ref__f32(dd);
    int i;
    if ((double)f == dd) return f;
    for (i = 0; i < 2; i++) {
        double v = floor(dd * maxes[i] + 0.5);
        if (v >= 0 && v <= maxes[i] && v / maxes[i] == dd) {
            volatile float fv = (float)v, fm = (float)maxes[i], q;
            q = fv / fm;
            return q;
        }
    }
    return f;
}

/* The recipe's two constants, each computed in double from the caller's
   values and rounded to float32 once (see the top of this file). */
typedef struct ref__recipe { int relative; float c0, c1; } ref__recipe;

static int ref__recipe_init(ref__recipe *r, double amount, int relative, double n, double f)
{
    double s;
    if (!ref__persp_ok(amount, n, f)) return -1;
    s = ref__persp_s(n, f); /* far / (far - near), or 1 */
    r->relative = relative;
    if (relative) {
        r->c0 = ref__f32(amount * s);
        r->c1 = ref__f32(1.0 + amount);
    } else {
        r->c0 = ref__f32(s);
        r->c1 = ref__f32(amount / n);
    }
    return 0;
}

/* The recipe's back depth of the float32 depth d: each step one float32
   operation, rounded into a volatile float (no excess precision, nothing
   fused or reordered), then clamped to [d, 1] (NaN: 1). */
static float ref__recipe_back(const ref__recipe *r, float d)
{
    volatile float u, q, qc, g, e, num, b;
    float out;
    if (r->relative) {
        num = d + r->c0;          /* d + k s        */
        b = num / r->c1;          /* / (1 + k)      */
    } else {
        u = r->c0 - d;            /* s - d          */
        q = r->c0 / u;            /* s / (s - d) = z_view / n (d = 1, f = inf: +inf) */
        qc = q + r->c1;           /* (z_view + T) / n */
        g = qc / u;               /* (z_view + T) / (n (s - d)) */
        e = r->c1 / g;            /* (s - d) T / (z_view + T) = b - d (q = inf: 0) */
        b = d + e;                /* s (1 - n / z') */
    }
    out = b;
    if (!(out <= 1.0f)) out = 1.0f;
    if (out < d) out = d;
    return out;
}

/* The recipe's back depth of one converted depth dd (as ref_map holds it),
   as double: what ref_map_set_back_constant (relative 0) or _relative (1)
   stores for that texel (NaN on bad parameters). For tests. */
static double ref__recipe_of(double dd, double amount, int relative, double near_z, double far_z)
{
    ref__recipe r;
    double b;
    if (ref__recipe_init(&r, amount, relative, near_z, far_z) != 0 || !(dd == dd)) return strtod("nan", NULL);
    b = (double)ref__recipe_back(&r, ref__depth_f32(dd));
    return b < dd ? dd : b;
}

REF_FUNC double ref_back_constant_recipe(double dd, double thickness, double near_z, double far_z)
{
    return ref__recipe_of(dd, thickness, 0, near_z, far_z);
}

REF_FUNC double ref_back_relative_recipe(double dd, double k, double near_z, double far_z)
{
    return ref__recipe_of(dd, k, 1, near_z, far_z);
}

/* Both models: m->b[k] = the recipe's b of texel k's float32 depth, as a
   double, and at least the stored double d (only a unorm d = v / max, whose
   float is up to half an ulp below it, can need that: the box stays
   [d, d], a plate). */
static int ref__set_back_persp(ref_map *m, double amount, int relative, double n, double f)
{
    ref__recipe r;
    double *back;
    size_t k, cnt;
    if (!m || !m->d || m->w < 1 || m->h < 1) return -1;
    if (ref__recipe_init(&r, amount, relative, n, f) != 0) return -1;
    if ((size_t)m->w > ((size_t)-1) / sizeof(double) / (size_t)m->h) return -1;
    cnt = (size_t)m->w * (size_t)m->h;
    back = (double *)malloc(cnt * sizeof(double));
    if (!back) return -1;
    for (k = 0; k < cnt; k++) {
        double dd = m->d[k], b = (double)ref__recipe_back(&r, ref__depth_f32(dd));
        back[k] = b < dd ? dd : b;
    }
    free(m->b);
    m->b = back;
    return 0;
}

/* Give m (built, m->w x m->h) the back depths of a constant view-space
   thickness `thickness` under a perspective projection with near near_z > 0
   and far far_z > near_z (+INFINITY: an infinite far plane), forward depth
   (reversed maps are already forward in m->d): b = d(z_view(d) + thickness)
   clamped to 1, so a thin object lets rays pass behind it, computed by the
   float32 recipe at the top of this file. A previous m->b is replaced.
   Returns 0 on success, -1 on bad arguments (thickness, near_z not finite
   and > 0, far_z not > near_z, any NaN) or out of memory (m unchanged). */
REF_FUNC int ref_map_set_back_constant(ref_map *m, double thickness, double near_z, double far_z)
{
    return ref__set_back_persp(m, thickness, 0, near_z, far_z);
}

/* The same with a thickness relative to the distance: T = k * z_view(d),
   a thickness that grows with the distance. k finite and > 0; otherwise
   as ref_map_set_back_constant. */
REF_FUNC int ref_map_set_back_relative(ref_map *m, double k, double near_z, double far_z)
{
    return ref__set_back_persp(m, k, 1, near_z, far_z);
}

REF_FUNC void ref_map_free(ref_map *m)
{
    if (!m) return;
    free(m->d);
    free(m->b);
    m->d = NULL;
    m->b = NULL;
    m->w = m->h = 0;
}

/* ---------------------------------------------------------- tracer ---- */

/* the back depth b of texel (i, j): 1 without a back map */
static double ref__back(const ref_map *m, int i, int j)
{
    return m->b ? m->b[(size_t)j * (size_t)m->w + (size_t)i] : 1.0;
}

/* texel (i, j)'s box: [i, i+1] x [j, j+1] x [d, b] */
static void ref__texel_box(const ref_map *m, int i, int j, double lo[3], double hi[3])
{
    lo[0] = i; lo[1] = j; lo[2] = m->d[(size_t)j * (size_t)m->w + (size_t)i];
    hi[0] = i + 1.0; hi[1] = j + 1.0; hi[2] = ref__back(m, i, j);
}

/* exact test of one texel's box [d, b] against the ray, t in [*t0, *t1] */
static int ref__texel(const ref_map *m, int i, int j, const double o[3],
                      const double v[3], const ref__ev *t0, const ref__ev *t1,
                      ref__ev *enter, int *face)
{
    double lo3[3], hi3[3];
    ref__texel_box(m, i, j, lo3, hi3);
    return ref__box(o, v, lo3, hi3, t0, t1, enter, NULL, face);
}

/* Keep the earlier of the current best and texel (i, j). */
static void ref__consider(const ref_map *m, int i, int j, const double o[3],
                          const double v[3], const ref__ev *t0, const ref__ev *t1,
                          int *found, ref__ev *best, int *bx, int *by, int *bface)
{
    ref__ev e;
    int face;
    if (!ref__texel(m, i, j, o, v, t0, t1, &e, &face)) return;
    if (!*found || ref__cmp(&e, best) < 0) {
        *found = 1; *best = e; *bx = i; *by = j; *bface = face;
    }
}

/* The exact answer for the ray o + t v, t in [tmin, tmax] (see docs/MODEL.md). */
REF_FUNC ref_result ref_trace(const ref_map *m, const double o[3], const double v[3],
                              double tmin, double tmax)
{
    ref_result r;
    ref__ev tmin_e, tmax_e, T0, T1, best;
    double slo[3], shi[3];
    int c, found = 0, bx = -1, by = -1, bface = REF_FACE_NONE;

    r.kind = REF_MISS_INVALID; r.t = 0; r.x = -1; r.y = -1; r.face = REF_FACE_NONE;
    if (!m || !m->d || m->w < 1 || m->h < 1) return r;
    for (c = 0; c < 3; c++)
        if (!ref__finite(o[c]) || !ref__finite(v[c])) return r;
    if (!ref__finite(tmin) || !ref__finite(tmax)) return r;
    if (tmin < 0 || tmin > tmax) return r;

    tmin_e = ref__ev_scalar(tmin);
    tmax_e = ref__ev_scalar(tmax);
    best = T0 = T1 = tmin_e;
    slo[0] = 0; slo[1] = 0; slo[2] = 0;
    shi[0] = m->w; shi[1] = m->h; shi[2] = 1;

    /* clip to the screen box (every texel box lies inside it) */
    if (ref__box(o, v, slo, shi, &tmin_e, &tmax_e, &T0, &T1, NULL)) {
        /* a: the axis of the walk (the faster one), b: the other */
        int a = fabs(v[0]) >= fabs(v[1]) ? 0 : 1, b = 1 - a;
        int na = a == 0 ? m->w : m->h, nb = b == 0 ? m->w : m->h;
        if (v[a] == 0) {
            /* v.x = v.y = 0: the (up to 4) texels whose footprint holds o.xy */
            int i0, i1, j0, j1, i, j;
            ref__cells(o[0], o[0], 0, m->w, &i0, &i1);
            ref__cells(o[1], o[1], 0, m->h, &j0, &j1);
            for (j = j0; j <= j1; j++)
                for (i = i0; i <= i1; i++)
                    ref__consider(m, i, j, o, v, &tmin_e, &tmax_e, &found, &best, &bx, &by, &bface);
        } else {
            double e0, e1, A0, A1;
            int k0, k1, k, step = v[a] > 0 ? 1 : -1;
            A0 = ref__coord(o[a], v[a], &T0, &e0);
            A1 = ref__coord(o[a], v[a], &T1, &e1);
            ref__cells(A0 < A1 ? A0 : A1, A0 < A1 ? A1 : A0,
                       (e0 > e1 ? e0 : e1) + 1e-9, na, &k0, &k1);
            /* columns in the order the ray meets them: a hit in column k is
               at t <= (crossing of plane k+1) <= any hit in the next one */
            for (k = step > 0 ? k0 : k1; k >= k0 && k <= k1 && !found; k += step) {
                ref__ev pk = ref__ev_plane((double)k, o[a], v[a]);
                ref__ev pk1 = ref__ev_plane((double)k + 1.0, o[a], v[a]);
                ref__ev en = step > 0 ? pk : pk1, ex = step > 0 ? pk1 : pk;
                double B0, B1, Z0, Z1, eb0, eb1, ez0, ez1, zmax, zmin;
                int j0, j1, j;
                if (ref__cmp(&en, &T0) < 0) en = T0;
                if (ref__cmp(&ex, &T1) > 0) ex = T1;
                if (ref__cmp(&en, &ex) > 0) continue;
                B0 = ref__coord(o[b], v[b], &en, &eb0);
                B1 = ref__coord(o[b], v[b], &ex, &eb1);
                ref__cells(B0 < B1 ? B0 : B1, B0 < B1 ? B1 : B0,
                           (eb0 > eb1 ? eb0 : eb1) + 1e-9, nb, &j0, &j1);
                Z0 = ref__coord(o[2], v[2], &en, &ez0);
                Z1 = ref__coord(o[2], v[2], &ex, &ez1);
                /* z is linear in t: over this column's [en, ex] it lies
                   between Z0 and Z1 (each within its error bound), so a box
                   whose z range [d, b] is wholly deeper than zmax or wholly
                   shallower than zmin holds no point of the ray here */
                zmax = Z0 + ez0 > Z1 + ez1 ? Z0 + ez0 : Z1 + ez1;
                zmax += 1e-9;
                if (!(zmax == zmax)) zmax = 2; /* cannot happen with finite input */
                zmin = Z0 - ez0 < Z1 - ez1 ? Z0 - ez0 : Z1 - ez1;
                zmin -= 1e-9;
                if (!(zmin == zmin)) zmin = -1; /* likewise */
                for (j = j0; j <= j1; j++) {
                    int i = a == 0 ? k : j, jj = a == 0 ? j : k;
                    if (m->d[(size_t)jj * (size_t)m->w + (size_t)i] > zmax) continue;
                    if (ref__back(m, i, jj) < zmin) continue;
                    ref__consider(m, i, jj, o, v, &tmin_e, &tmax_e, &found, &best, &bx, &by, &bface);
                }
            }
        }
    }

    if (found) {
        r.kind = REF_HIT;
        r.t = best.a;
        r.x = bx;
        r.y = by;
        r.face = bface;
        return r;
    }
    /* a miss: on the screen (closed rectangle, x and y only) at tmax? */
    if (ref__in_slab_at(o[0], v[0], tmax, 0, (double)m->w) &&
        ref__in_slab_at(o[1], v[1], tmax, 0, (double)m->h))
        r.kind = REF_MISS_TMAX;
    else
        r.kind = REF_MISS_OFF_SCREEN;
    return r;
}

/* A float32 ray as docs/MODEL.md reads it: a subnormal component (below
   2^-126 in size) is 0 of its sign, as on a GPU that flushes them. */
static ref_ray ref__read_ray(const ref_ray *ray)
{
    ref_ray r = *ray;
    float *f[8];
    int c;
    f[0] = &r.o[0]; f[1] = &r.o[1]; f[2] = &r.o[2]; f[3] = &r.v[0];
    f[4] = &r.v[1]; f[5] = &r.v[2]; f[6] = &r.tmin; f[7] = &r.tmax;
    for (c = 0; c < 8; c++)
        if (*f[c] != 0.0f && fabsf(*f[c]) < 1.17549435e-38f) *f[c] = *f[c] < 0.0f ? -0.0f : 0.0f;
    return r;
}

/* the same for a float32 ray */
REF_FUNC ref_result ref_trace_ray(const ref_map *m, const ref_ray *caller_ray)
{
    const ref_ray read = ref__read_ray(caller_ray), *ray = &read;
    double o[3], v[3];
    int c;
    for (c = 0; c < 3; c++) { o[c] = ray->o[c]; v[c] = ray->v[c]; }
    return ref_trace(m, o, v, ray->tmin, ray->tmax);
}

/* ------------------------------------------------------ comparator ---- */

static const char *ref__kind_name(int kind)
{
    switch (kind) {
    case REF_HIT: return "hit";
    case REF_MISS_TMAX: return "tmax-miss";
    case REF_MISS_OFF_SCREEN: return "off-screen-miss";
    case REF_MISS_INVALID: return "invalid";
    default: return "bad-kind";
    }
}

static void ref__why(char *why, size_t n, const char *msg)
{
    if (why && n > 0) {
        size_t k = strlen(msg);
        if (k >= n) k = n - 1;
        memcpy(why, msg, k);
        why[k] = 0;
    }
}

static const char *ref__face_name(int face)
{
    switch (face) {
    case REF_FACE_NONE: return "none";
    case REF_FACE_TOP: return "top";
    case REF_FACE_SIDE: return "side";
    case REF_FACE_BACK: return "back";
    case REF_FACE_INSIDE: return "inside";
    default: return "bad-face";
    }
}

/* Is a hit's reported face right for its point p = o + t v in texel (x, y)?
   The exact answer's face, or any face p lies on within tol_c per
   component (an edge, or a boundary the rounding of o moves it across);
   inside only at tmin. A miss has no face. */
static int ref__face_fits(const ref_map *m, const double o[3], const double v[3], double tmin,
                          const ref_answer *got, int exact_face)
{
    double t = got->t, p[3], tol[3];
    int c;
    if (got->face == REF_FACE_ANY) return 1;
    if (got->kind != REF_HIT) return got->face == REF_FACE_NONE;
    if (got->face == exact_face) return 1;
    for (c = 0; c < 3; c++) {
        p[c] = o[c] + t * v[c];
        tol[c] = 1e-5 * (1 + fabs(o[c]) + fabs(t * v[c]));
    }
    switch (got->face) {
    case REF_FACE_TOP:
        return fabs(p[2] - m->d[(size_t)got->y * (size_t)m->w + (size_t)got->x]) <= tol[2];
    case REF_FACE_SIDE:
        return fabs(p[0] - got->x) <= tol[0] || fabs(p[0] - (got->x + 1.0)) <= tol[0] ||
               fabs(p[1] - got->y) <= tol[1] || fabs(p[1] - (got->y + 1.0)) <= tol[1];
    case REF_FACE_BACK:
        return fabs(p[2] - ref__back(m, got->x, got->y)) <= tol[2];
    case REF_FACE_INSIDE:
        return fabs(t - tmin) <= 1e-5 * (1 + fabs(tmin));
    default:
        return 0;
    }
}

/* Does `got` match the exact answer E of the ray (po, pv) (the given ray,
   or a perturbed one)? The reported hit point is taken on the given ray
   (o, v). Exact mode only (any-hit is handled by ref_check). */
static int ref__match(const ref_map *m, const double o[3], const double v[3], double tmin,
                      const double po[3], const double pv[3], const ref_result *E,
                      const ref_answer *got, char *msg, size_t n)
{
    double t = got->t, lo[3], hi[3];
    int c;
    if (got->kind != E->kind) {
        if (msg) snprintf(msg, n, "kind: got %s, exact %s", ref__kind_name(got->kind),
                          ref__kind_name(E->kind));
        return 0;
    }
    if (E->kind != REF_HIT) {
        if (got->face == REF_FACE_ANY || got->face == REF_FACE_NONE) return 1;
        if (msg) snprintf(msg, n, "a miss with face %s", ref__face_name(got->face));
        return 0;
    }
    if (!ref__finite(t)) {
        if (msg) snprintf(msg, n, "hit with non-finite t");
        return 0;
    }
    if (got->x < 0 || got->x >= m->w || got->y < 0 || got->y >= m->h) {
        if (msg) snprintf(msg, n, "hit texel (%d,%d) outside the %dx%d map", got->x, got->y,
                          m->w, m->h);
        return 0;
    }
    ref__texel_box(m, got->x, got->y, lo, hi);
    for (c = 0; c < 3; c++) {
        double p = o[c] + t * v[c];
        double e = po[c] + E->t * pv[c];
        double tol = 1e-5 * (1 + fabs(o[c]) + fabs(t * v[c]));
        if (!(fabs(p - e) <= tol)) {
            if (msg) snprintf(msg, n,
                              "hit point: got t=%.9g (%d,%d), exact t=%.17g (%d,%d); "
                              "component %d: got %.17g, exact %.17g, tol %.3g",
                              t, got->x, got->y, E->t, E->x, E->y, c, p, e, tol);
            return 0;
        }
        if (!(e >= lo[c] - tol && e <= hi[c] + tol)) {
            if (msg) snprintf(msg, n,
                              "texel: got (%d,%d) t=%.9g, exact (%d,%d) t=%.17g; "
                              "exact hit point component %d = %.17g not in [%.17g, %.17g] "
                              "+- %.3g",
                              got->x, got->y, t, E->x, E->y, E->t, c, e, lo[c], hi[c], tol);
            return 0;
        }
    }
    if (!ref__face_fits(m, o, v, tmin, got, E->face)) {
        if (msg) snprintf(msg, n, "face: got %s at t=%.9g (%d,%d), exact %s, and the hit point is not on a %s face",
                          ref__face_name(got->face), t, got->x, got->y, ref__face_name(E->face),
                          ref__face_name(got->face));
        return 0;
    }
    return 1;
}

/* x moved by k float32 ulps (nextafterf steps; never to infinity) */
static float ref__ulps(float x, int k)
{
    while (k > 0) { x = nextafterf(x, FLT_MAX); k--; }
    while (k < 0) { x = nextafterf(x, -FLT_MAX); k++; }
    return x;
}

/* The ray with component q (o.x..o.z, v.x..v.z) moved by x ulps (a real
   number; between whole ulps the value is interpolated in double). */
static void ref__moved_ray(const ref_ray *ray, int q, double x, double po[3], double pv[3])
{
    const float f = q < 3 ? ray->o[q] : ray->v[q - 3];
    const int k = (int)floor(fabs(x)), dir = x < 0.0 ? -1 : 1;
    const double lo = ref__ulps(f, dir * k), hi = ref__ulps(f, dir * (k + 1));
    int i;
    for (i = 0; i < 3; i++) {
        po[i] = ray->o[i];
        pv[i] = ray->v[i];
    }
    *(q < 3 ? &po[q] : &pv[q - 3]) = lo + (fabs(x) - (double)k) * (hi - lo);
}

/* the t of a hit, or beyond every t for a miss: along a move of one
   component the first hit comes earlier or later as the ray turns */
static double ref__first_t(const ref_result *E) { return E->kind == REF_HIT ? E->t : HUGE_VAL; }

/* One component alone moved by a real amount up to 8 ulps (docs/MODEL.md):
   where the answers of two neighbouring whole-ulp moves lie on either side
   of got's t, bisect the move between them (the answer moves along the
   ray with it). A ray along a row of texel corners, v.x = v.y: each corner
   is passed at the same distance, and the corner that a real move of
   about 5.5 to 5.97 ulps reaches first lies between those that 5 and 6
   ulps reach (tests/fuzz/crashes-found/README.md, entry 18). */
static int ref__bisected_match(const ref_map *m, const ref_ray *ray, const double o[3], const double v[3],
                               const ref_answer *got)
{
    double po[3], pv[3];
    int q, dir, k, it;
    if (got->kind != REF_HIT) return 0;
    for (q = 0; q < 6; q++) {
        for (dir = -1; dir <= 1; dir += 2) {
            ref_result E0;
            double t0, t1;
            ref__moved_ray(ray, q, 0.0, po, pv);
            E0 = ref_trace(m, po, pv, ray->tmin, ray->tmax);
            t0 = ref__first_t(&E0);
            for (k = 0; k < 8; k++, t0 = t1) {
                double a = k, b = k + 1.0; /* |move| in ulps: the answer at a lies on t0's side of got's t */
                ref_result E;
                ref__moved_ray(ray, q, dir * b, po, pv);
                E = ref_trace(m, po, pv, ray->tmin, ray->tmax);
                t1 = ref__first_t(&E);
                if ((t0 > got->t) == (t1 > got->t)) continue;
                for (it = 0; it < 40; it++) {
                    const double mid = 0.5 * (a + b);
                    ref__moved_ray(ray, q, dir * mid, po, pv);
                    E = ref_trace(m, po, pv, ray->tmin, ray->tmax);
                    if (E.kind == REF_HIT && E.x == got->x && E.y == got->y &&
                        ref__match(m, o, v, ray->tmin, po, pv, &E, got, NULL, 0))
                        return 1;
                    if ((ref__first_t(&E) > got->t) == (t0 > got->t)) a = mid;
                    else b = mid;
                }
            }
        }
    }
    return 0;
}

/* Is there a ray among the given one's perturbations (3^6 combinations of
   {-8,0,+8} ulps on o and v, then of {-1,0,+1}, then one component alone
   moved by 2 to 7 ulps either way, then by a real amount,
   ref__bisected_match) whose exact answer matches `got`? any_hit: only
   the kind has to match. The single moves: a ray along a row of texel
   corners, its answer a corner that v moved by a real 5.6 to 7.9 ulps
   reaches first, while 8 ulps reach an earlier one
   (tests/fuzz/crashes-found/README.md, entry 17). */
static int ref__perturbed_match(const ref_map *m, const ref_ray *ray, const double o[3],
                                const double v[3], const ref_answer *got, int any_hit)
{
    static const int steps[2] = { 8, 1 };
    int s, combo, q;
    for (s = 0; s < 2; s++) {
        for (combo = 0; combo < 729; combo++) {
            double po[3], pv[3];
            ref_result E;
            int code = combo, ok = 1;
            if (combo == 364) continue; /* all digits 1: the ray itself */
            for (q = 0; q < 6; q++) {
                int dig = code % 3 - 1;
                float f = q < 3 ? ray->o[q] : ray->v[q - 3];
                code /= 3;
                f = ref__ulps(f, dig * steps[s]);
                if (!ref__finite(f)) ok = 0;
                if (q < 3) po[q] = f; else pv[q - 3] = f;
            }
            if (!ok) continue;
            E = ref_trace(m, po, pv, ray->tmin, ray->tmax);
            if (any_hit) {
                if (E.kind == got->kind) return 1;
            } else if (ref__match(m, o, v, ray->tmin, po, pv, &E, got, NULL, 0)) {
                return 1;
            }
        }
    }
    for (q = 0; q < 6; q++) {
        int k;
        for (k = -7; k <= 7; k++) {
            double po[3], pv[3];
            ref_result E;
            float f = q < 3 ? ray->o[q] : ray->v[q - 3];
            if (k >= -1 && k <= 1) continue;
            f = ref__ulps(f, k);
            if (!ref__finite(f)) continue;
            for (s = 0; s < 3; s++) {
                po[s] = ray->o[s];
                pv[s] = ray->v[s];
            }
            if (q < 3) po[q] = f; else pv[q - 3] = f;
            E = ref_trace(m, po, pv, ray->tmin, ray->tmax);
            if (any_hit) {
                if (E.kind == got->kind) return 1;
            } else if (ref__match(m, o, v, ray->tmin, po, pv, &E, got, NULL, 0)) {
                return 1;
            }
        }
    }
    return !any_hit && ref__bisected_match(m, ray, o, v, got);
}

/* how far 8 float32 ulps move x, as a double: up (dir > 0), down (dir < 0)
   or the larger of the two (dir == 0; below a power of two the spacing
   halves) */
static double ref__reach8(float x, int dir)
{
    double up = (double)ref__ulps(x, 8) - (double)x, down = (double)x - (double)ref__ulps(x, -8);
    return dir > 0 ? up : dir < 0 ? down : up > down ? up : down;
}

/* A hit on a flat plate, or on a box thinner than one ulp's move of the
   ray's z, that a continuous perturbation of the ray explains.
   Exact mode only; called after ref__match and ref__perturbed_match refuse.

   docs/MODEL.md ("Right, and how right"): an answer is right when it is the exact
   answer "for that ray with each component of o and v moved by at most 8
   float32 ulps": a real-valued move, of which ref__perturbed_match tries
   only the discrete ones ({-8,0,+8}, {-1,0,+1} ulps per component). That
   suffices for a box deeper than the ray's z moves in one ulp's step (a ray
   within 8 ulps of one is moved into it by moving o.z by whole ulps), but
   not for a thinner one, which such steps can jump over (fuzz_core,
   tests/fuzz/crashes-found/core-relative-thin-box-between-ulps: a relative
   thickness of 1.5e-25 left the unorm texel d = 24672/65535 the box [d, d
   + 7.4e-9], a quarter of an ulp of z = 0.376; a far-away ray 2.1e-8 in
   front of it, restarted at the screen's edge with its z rounded, hit it,
   the exact answer for o.z moved up by about 0.7 ulp, while o.z moved by
   0 or 1 ulp passes in front of it or behind), and not for a plate, a box [d, d]
   (b == d: a back map at or in front of the depth, a constant or relative
   thickness lost to float rounding, or a far texel d = b = 1): only a ray
   whose z there is d exactly touches it. Found by fuzz_core
   (tests/fuzz/crashes-found/core-constant-plate-restart-rounds-onto-plate):
   1x1 map d = b = 0.5, o = (0.25, -512, 0.5), v = (0, 1024, 2^-30),
   [0, 8]: the exact ray enters the texel at t = 0.5 at z = 0.5 + 2^-31,
   just behind the plate, and leaves the screen; the library restarts the
   far-away ray at the screen's edge, its z rounded to 0.5, and reports a
   hit at t = 0.5 on the plate. That is the exact answer for o.z moved by
   -2^-31, less than an ulp of o.z (2^-25 below 0.5): right by docs/MODEL.md,
   and no float ray within {-8..8} ulps gives it.

   Accepted here only when all of these hold:
   - got is a hit with a finite t in [tmin, tmax] (within docs/MODEL.md's
     tolerance), on a texel (x, y) of the map whose box is a plate (b == d)
     or a thin box: b - d below an eighth of the 8-ulp reach below;
   - p = o + t v (as ref__match computes hit points) lies in the texel's
     footprint [x, x+1] x [y, y+1] within tol_c = 1e-5 (1 + |o_c| + |t v_c|);
   - the ray's z comes within 8 ulps of the box near p (of d for p.z < d,
     of b for p.z > b; a plate has d = b): |p.z - d| <=
     R(o.z) + min(|t| + s, tmax) R(v.z) + s |v.z|, R(c) the reach of 8
     float32 ulps of the given component c towards d (down when p.z > d, up
     when p.z < d; 2^-25 and 2^-24 per ulp at 0.5), s = min over the c
     with v_c != 0 of (tol_c + R(o_c) + |t| R(v_c)) / |v_c| (R the larger
     side here; s = 0 for v = 0): the moved ray meets z = d at some t'
     whose point is within tol_c of p in each component, so |t' - t| <= s
     (the bound is this plus, in z, what 8 ulps add at t'); a ray that runs
     level behind a plate (v.z = 0) must be within 8 ulps of it, whatever
     the tolerance;
   - the exact answer of the given ray hits nothing before: a miss, or a
     hit at t_E >= t, or at a point within tol_c of p;
   - the face is TOP or BACK (one plane for a plate, and p is on it by the
     test above), SIDE only with p on the footprint's edge within tol_c
     (ref__face_fits's rule), or not reported (REF_FACE_ANY). */
static int ref__plate_match(const ref_map *m, const ref_ray *ray, const double o[3],
                            const double v[3], const ref_result *E, const ref_answer *got)
{
    double t = got->t, p[3], tol[3], d, b, s = 0, tfar, gap;
    int c, dir, have_s = 0;
    if (got->kind != REF_HIT || !ref__finite(t)) return 0;
    if (!(t >= (double)ray->tmin - 1e-5 * (1 + fabs((double)ray->tmin))) ||
        !(t <= (double)ray->tmax + 1e-5 * (1 + fabs((double)ray->tmax))))
        return 0;
    if (got->x < 0 || got->x >= m->w || got->y < 0 || got->y >= m->h) return 0;
    d = m->d[(size_t)got->y * (size_t)m->w + (size_t)got->x];
    b = ref__back(m, got->x, got->y);
    if (!(b >= d)) return 0;
    for (c = 0; c < 3; c++) {
        p[c] = o[c] + t * v[c];
        tol[c] = 1e-5 * (1 + fabs(o[c]) + fabs(t * v[c]));
    }
    if (!(p[0] >= got->x - tol[0] && p[0] <= got->x + 1.0 + tol[0] &&
          p[1] >= got->y - tol[1] && p[1] <= got->y + 1.0 + tol[1]))
        return 0;
    for (c = 0; c < 3; c++) {
        double sc;
        if (v[c] == 0) continue;
        sc = (tol[c] + ref__reach8(ray->o[c], 0) + fabs(t) * ref__reach8(ray->v[c], 0)) / fabs(v[c]);
        if (!have_s || sc < s) s = sc;
        have_s = 1;
    }
    /* |t'| <= |t| + s, and t' lies in [tmin, tmax] */
    tfar = fabs(t) + s < (double)ray->tmax ? fabs(t) + s : (double)ray->tmax;
    if (tfar < fabs(t)) tfar = fabs(t);
    /* z has to move towards the box: down when p is behind it (for t' >= 0
       both o.z and v.z move down), up when in front */
    dir = p[2] > b ? -1 : 1;
    gap = ref__reach8(ray->o[2], dir) + tfar * ref__reach8(ray->v[2], dir) + s * fabs(v[2]);
    if (b != d && !((b - d) * 8.0 < gap)) return 0; /* deeper: whole-ulp moves cannot jump over it */
    if (!(p[2] >= d && p[2] <= b) && !(fabs(p[2] - (dir < 0 ? b : d)) <= gap)) return 0;
    if (E->kind == REF_HIT && E->t < t) {
        for (c = 0; c < 3; c++)
            if (!(fabs(o[c] + E->t * v[c] - p[c]) <= tol[c])) return 0;
    }
    switch (got->face) {
    case REF_FACE_ANY:
    case REF_FACE_TOP:
    case REF_FACE_BACK:
        return 1;
    case REF_FACE_SIDE:
        return fabs(p[0] - got->x) <= tol[0] || fabs(p[0] - (got->x + 1.0)) <= tol[0] ||
               fabs(p[1] - got->y) <= tol[1] || fabs(p[1] - (got->y + 1.0)) <= tol[1];
    default:
        return 0;
    }
}

/* Returns 1 if `got` is right for `ray` by docs/MODEL.md's rule "Right, and how
   right", else 0 and writes a one-line reason into why (may be NULL).

   Exact mode (any_hit == 0): right when it matches the exact answer of the
   ray, or of one of its perturbations (each component of o and v moved by
   {-8,0,+8} ulps, then by {-1,0,+1}, then one alone by 2..7 either way,
   then one alone by a real amount, ref__bisected_match; tmin, tmax
   unchanged). Matching: same
   kind; for a hit, each component c of p = o + t v (double, from the float
   ray and the reported t) within tol_c = 1e-5 * (1 + |o_c| + |t v_c|) of the
   exact hit point, and the reported texel's box containing the exact hit
   point within tol_c per component. Also right: a hit on a flat plate
   (b == d), or on a box thinner than a whole-ulp move of z, that a
   real-valued move of at most 8 ulps explains, which no discrete one can
   (ref__plate_match).

   any_hit != 0: a hit need not be the closest. A reported hit must be a real
   hit point: t in [tmin, tmax] (within 1e-5 * (1 + |tmin|), 1e-5 * (1 + |tmax|))
   and p = o + t v in the reported texel's box within tol_c per component;
   and the exact answer of the ray or of one of its perturbations must be a
   hit. A reported miss must have the exact answer's kind (again for the ray
   or one of its perturbations). */
REF_FUNC int ref_check(const ref_map *m, const ref_ray *caller_ray, const ref_answer *got,
                       int any_hit, char *why, size_t why_size)
{
    const ref_ray read = ref__read_ray(caller_ray), *ray = &read;
    double o[3], v[3];
    ref_result E;
    char msg[512];
    int c;

    if (why && why_size > 0) why[0] = 0;
    for (c = 0; c < 3; c++) { o[c] = ray->o[c]; v[c] = ray->v[c]; }
    E = ref_trace(m, o, v, ray->tmin, ray->tmax);

    if (got->kind < REF_HIT || got->kind > REF_MISS_INVALID) {
        snprintf(msg, sizeof msg, "bad kind %d (exact: %s)", got->kind, ref__kind_name(E.kind));
        ref__why(why, why_size, msg);
        return 0;
    }
    if (E.kind == REF_MISS_INVALID || got->kind == REF_MISS_INVALID) {
        /* validity does not depend on rounding */
        if (E.kind == got->kind) return 1;
        snprintf(msg, sizeof msg, "kind: got %s, exact %s", ref__kind_name(got->kind),
                 ref__kind_name(E.kind));
        ref__why(why, why_size, msg);
        return 0;
    }

    if (any_hit) {
        if (got->kind == REF_HIT) {
            double t = got->t, lo[3], hi[3];
            if (!ref__finite(t) || !(t >= (double)ray->tmin - 1e-5 * (1 + fabs((double)ray->tmin))) ||
                !(t <= (double)ray->tmax + 1e-5 * (1 + fabs((double)ray->tmax)))) {
                snprintf(msg, sizeof msg, "any-hit: t=%.9g outside [tmin, tmax] = [%.9g, %.9g]",
                         t, (double)ray->tmin, (double)ray->tmax);
                ref__why(why, why_size, msg);
                return 0;
            }
            if (got->x < 0 || got->x >= m->w || got->y < 0 || got->y >= m->h) {
                snprintf(msg, sizeof msg, "any-hit: texel (%d,%d) outside the %dx%d map",
                         got->x, got->y, m->w, m->h);
                ref__why(why, why_size, msg);
                return 0;
            }
            ref__texel_box(m, got->x, got->y, lo, hi);
            for (c = 0; c < 3; c++) {
                double p = o[c] + t * v[c];
                double tol = 1e-5 * (1 + fabs(o[c]) + fabs(t * v[c]));
                if (!(p >= lo[c] - tol && p <= hi[c] + tol)) {
                    snprintf(msg, sizeof msg,
                             "any-hit: point at t=%.9g, component %d = %.17g, is not in "
                             "texel (%d,%d)'s box [%.17g, %.17g] +- %.3g",
                             t, c, p, got->x, got->y, lo[c], hi[c], tol);
                    ref__why(why, why_size, msg);
                    return 0;
                }
            }
        }
        if (!ref__face_fits(m, o, v, ray->tmin, got, REF_FACE_ANY - 1)) {
            snprintf(msg, sizeof msg, "any-hit: face %s, and the point at t=%.9g is not on one",
                     ref__face_name(got->face), (double)got->t);
            ref__why(why, why_size, msg);
            return 0;
        }
        if (E.kind == got->kind) return 1;
        if (ref__perturbed_match(m, ray, o, v, got, 1)) return 1;
        snprintf(msg, sizeof msg, "any-hit: got %s, exact %s (t=%.17g texel (%d,%d)), "
                 "also for all perturbed rays", ref__kind_name(got->kind),
                 ref__kind_name(E.kind), E.t, E.x, E.y);
        ref__why(why, why_size, msg);
        return 0;
    }

    if (ref__match(m, o, v, ray->tmin, o, v, &E, got, msg, sizeof msg)) return 1;
    if (ref__perturbed_match(m, ray, o, v, got, 0)) return 1;
    if (ref__plate_match(m, ray, o, v, &E, got)) return 1;
    {
        char full[768];
        snprintf(full, sizeof full, "%s (got %s t=%.9g (%d,%d); exact %s t=%.17g (%d,%d); "
                 "no perturbed ray matches)", msg, ref__kind_name(got->kind), (double)got->t,
                 got->x, got->y, ref__kind_name(E.kind), E.t, E.x, E.y);
        ref__why(why, why_size, full);
    }
    return 0;
}

/* An lrt_ray as the reference takes it, for a file that includes linear_rt.h
   first (the one converter of the tests, the examples' tests and the
   benchmark). */
#if defined(LINEAR_RT_H) && !defined(LINEAR_RT_TESTS_REF_RAY_OF)
#define LINEAR_RT_TESTS_REF_RAY_OF
REF_FUNC ref_ray ref_ray_of(const lrt_ray *r)
{
    ref_ray q;
    memcpy(q.o, r->origin, sizeof q.o);
    memcpy(q.v, r->dir, sizeof q.v);
    q.tmin = r->tmin;
    q.tmax = r->tmax;
    return q;
}
#endif

#endif /* LINEAR_RT_TESTS_REFERENCE_H */
