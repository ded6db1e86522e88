/* march.h - the classic screen-space march: what an engine programmer writes
   today instead of linear_rt, on the same rays (lrt_ray in, lrt_hit out).
   Approximate: it samples the ray at fixed steps, so whatever lies between
   two samples is unseen (thin things are stepped over, grazing hits come
   late). The demo draws its 64-step reflections beside linear_rt's (the
   side-by-side picture) and counts where the two agree; the benchmark
   (bench/march_cpu.c) scores it, and builds its DDA and Hi-Z marches on the
   rules here.

   The rules every march here keeps (docs/MODEL.md's, as linear_rt keeps
   them): an invalid ray (a NaN or infinite component, tmin < 0 or tmin >
   tmax) is flagged and not traced; [tmin, tmax] is first clipped to the
   screen box [0,W] x [0,H] x [0,1]; a miss is told apart by the point at
   tmax: on the closed screen rectangle, LRT_MISS_TMAX, else
   LRT_MISS_OFF_SCREEN. The texel "under" a point is (floor x, floor y),
   clamped to the map. The rays are straight in screen space, so depth is
   linear along them (no 1/w interpolation). Arithmetic is double (it costs
   nothing here; the errors of a march are its sampling, not its rounding):
   no overflow for any finite float ray.

   Header-only, all static inline, C99; needs only linear_rt.h's types. */
#ifndef EXAMPLE_MARCH_H
#define EXAMPLE_MARCH_H

#include <stddef.h>
#include <stdint.h>
#include "../linear_rt.h"

/* A profiling hook: called once per sample the march reads (the fixed-step
   march's samples and bisection steps; bench/march_cpu.c's DDA steps and
   Hi-Z iterations); a counting copy (bench/wave.c) defines it, the timed
   code pays nothing. */
#ifndef MARCH_COUNT_STEP
#define MARCH_COUNT_STEP() ((void)0)
#endif

/* the fixed-step march refines its first step behind the surface by this
   many bisection steps */
#define MARCH_BISECTIONS 8

/* What a march reads: the depth map (w * h floats, row 0 first, 0 near, 1
   far), and for a thickness model each texel's back depth (texel k is solid
   over [depth, max(depth, back)]), or back = NULL: everything behind the
   visible surface is solid (linear_rt's default, infinite thickness). */
typedef struct march_map {
    const float *depth;
    const float *back;
    uint32_t w, h;
} march_map;

static inline int march_finite(float x) { return x - x == 0.0f; } /* false for NaN and +-inf */

/* docs/MODEL.md's one repair of input depth: NaN and values above 1 become 1,
   values below 0 become 0. */
static inline float march_depth(float d) { return !(d <= 1.0f) ? 1.0f : d < 0.0f ? 0.0f : d; }

/* docs/MODEL.md: a NaN or infinite component, tmin < 0 or tmin > tmax: invalid. */
static inline int march_ray_valid(const lrt_ray *r)
{
    int k;
    for (k = 0; k < 3; ++k)
        if (!march_finite(r->origin[k]) || !march_finite(r->dir[k])) return 0;
    if (!march_finite(r->tmin) || !march_finite(r->tmax)) return 0;
    return r->tmin >= 0.0f && r->tmin <= r->tmax;
}

/* A coordinate of the point o + t v for float o, v and a float t: the
   product of two floats is exact in double and the sum is rounded once, so
   comparing the result with any float (an integer texel edge, a depth, W, H)
   gives the exact answer (rounding is monotonic). */
static inline double march_at(float o, float v, float t) { return (double)o + (double)t * (double)v; }

/* The kind of a miss by docs/MODEL.md's rule: the point at tmax on the
   closed screen rectangle [0,W] x [0,H] (x and y only): reached tmax;
   otherwise the ray left (or never met) the screen. Exact, see march_at. */
static inline uint32_t march_miss_kind(const lrt_ray *r, uint32_t w, uint32_t h)
{
    double x = march_at(r->origin[0], r->dir[0], r->tmax), y = march_at(r->origin[1], r->dir[1], r->tmax);
    return (x >= 0.0 && x <= (double)w && y >= 0.0 && y <= (double)h) ? LRT_MISS_TMAX : LRT_MISS_OFF_SCREEN;
}

static inline void march_set_miss(lrt_hit *hit, uint32_t kind)
{
    hit->t = 0.0f;
    hit->x = hit->y = 0u;
    hit->kind = (uint16_t)kind;
    hit->face = LRT_FACE_NONE;
}

/* A hit at t (kept within [tmin, tmax] after rounding to float) on texel (i, j). */
static inline void march_set_hit(const lrt_ray *r, double t, uint32_t i, uint32_t j, lrt_hit *hit)
{
    float tf = (float)t;
    hit->t = tf < r->tmin ? r->tmin : tf > r->tmax ? r->tmax : tf;
    hit->x = i;
    hit->y = j;
    hit->kind = LRT_HIT;
    hit->face = LRT_FACE_NONE; /* a march does not know which face it met */
}

/* Clips [tmin, tmax] of a valid ray to the screen box [0,W] x [0,H] x [0,1]
   (every texel box lies inside it). Returns 0 when nothing is left, else
   the interval in *t0, *t1. */
static inline int march_clip(const lrt_ray *r, uint32_t w, uint32_t h, double *t0, double *t1)
{
    const double hi[3] = {(double)w, (double)h, 1.0};
    double lo = r->tmin, up = r->tmax;
    int k;
    for (k = 0; k < 3; ++k) {
        double o = r->origin[k], v = r->dir[k], a, b;
        if (v == 0.0) {
            if (o < 0.0 || o > hi[k]) return 0;
            continue;
        }
        a = (0.0 - o) / v;
        b = (hi[k] - o) / v;
        if (a > b) {
            double x = a;
            a = b;
            b = x;
        }
        if (a > lo) lo = a;
        if (b < up) up = b;
        if (lo > up) return 0;
    }
    *t0 = lo;
    *t1 = up;
    return 1;
}

/* The start every march shares: an invalid ray or one with nothing on
   screen is answered into hit (returns 0); else [t0, t1] is its clipped
   interval (returns 1). */
static inline int march_begin(const lrt_ray *r, uint32_t w, uint32_t h, lrt_hit *hit, double *t0, double *t1)
{
    if (!march_ray_valid(r)) {
        march_set_miss(hit, LRT_MISS_INVALID_RAY);
        return 0;
    }
    if (!march_clip(r, w, h, t0, t1)) {
        march_set_miss(hit, march_miss_kind(r, w, h));
        return 0;
    }
    return 1;
}

/* texel index of a screen coordinate: floor, clamped to [0, n-1] (x == n,
   the screen's far edge, and rounding at the clip land in the last texel);
   truncation is floor for x >= 0, and negative x (or NaN) gives 0 */
static inline uint32_t march_texel(double x, uint32_t n)
{
    if (!(x >= 0.0)) return 0u;
    if (x >= (double)n) return n - 1u;
    return (uint32_t)x;
}

/* texel k's back depth: max(depth, back), or 1 without a back map (infinite) */
static inline double march_back(const march_map *m, size_t k)
{
    double d = (double)march_depth(m->depth[k]), b;
    if (!m->back) return 1.0;
    b = (double)march_depth(m->back[k]);
    return b > d ? b : d;
}

/* Is the point at t inside its texel's solid [depth, back]? Its texel in *i, *j. */
static inline int march_behind(const march_map *m, const double o[3], const double v[3], double t, uint32_t *i,
                               uint32_t *j)
{
    double x = o[0] + t * v[0], y = o[1] + t * v[1], z = o[2] + t * v[2];
    size_t k;
    MARCH_COUNT_STEP();
    *i = march_texel(x, m->w);
    *j = march_texel(y, m->h);
    k = (size_t)*j * m->w + *i;
    return z >= (double)march_depth(m->depth[k]) && z <= march_back(m, k);
}

/* ---- the fixed-step linear march with binary refinement ----------------------------
   The clipped segment [t0, t1] is cut into `steps` equal steps; the samples
   at t0 + k (t1 - t0) / steps, k = 0..steps, read the depth of the texel
   under the point. The first sample inside its texel's solid (behind the
   visible surface, and in front of the back depth where there is one) ends
   the march: sample 0 is a hit at t0 (the ray starts inside); otherwise
   MARCH_BISECTIONS bisection steps between the previous sample (in front)
   and this one (inside) keep the sample that is inside, and its texel and t
   are reported. No sample inside: a miss, its kind by the rule above. */
static inline void march_linear(const march_map *m, int steps, const lrt_ray *r, lrt_hit *hit)
{
    double o[3], v[3], t0, t1, prev;
    uint32_t i, j;
    int k, b;
    if (!march_begin(r, m->w, m->h, hit, &t0, &t1)) return;
    for (k = 0; k < 3; ++k) {
        o[k] = r->origin[k];
        v[k] = r->dir[k];
    }
    prev = t0;
    for (k = 0; k <= steps; ++k) {
        double t = k == steps ? t1 : t0 + (t1 - t0) * (double)k / (double)steps;
        if (march_behind(m, o, v, t, &i, &j)) {
            double lo = prev, hi = t;
            if (k > 0)
                for (b = 0; b < MARCH_BISECTIONS; ++b) {
                    double mid = 0.5 * (lo + hi);
                    uint32_t mi, mj;
                    if (march_behind(m, o, v, mid, &mi, &mj)) {
                        hi = mid;
                        i = mi;
                        j = mj;
                    } else {
                        lo = mid;
                    }
                }
            march_set_hit(r, hi, i, j, hit);
            return;
        }
        prev = t;
    }
    march_set_miss(hit, march_miss_kind(r, m->w, m->h));
}

#endif
