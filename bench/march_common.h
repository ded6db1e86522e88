/* bench/march_common.h - what the CPU peers of the benchmark share
   (bench/m_embree.c, bench/march_cpu.c): docs/MODEL.md's ray validation, the
   clip of a ray to the screen box, the rule that tells the two kinds of miss
   apart, and a parallel-for over a batch of rays on pthreads.

   The marching math itself (fixed-step march, DDA, Hi-Z) lives in
   bench/march_cpu.c; its comments state each step in terms a shader can
   follow. Everything here is `static inline` (no unused-function warnings),
   C99, double precision for set-up (no overflow for any finite float ray). */
#ifndef LINEAR_RT_BENCH_MARCH_COMMON_H
#define LINEAR_RT_BENCH_MARCH_COMMON_H

#include <math.h>
#include <pthread.h>
#include <stddef.h>
#include <string.h>
#include "bench.h"

#define BMC_MAX_THREADS 64

static inline int bmc_finite(float x) { return x - x == 0.0f; } /* false for NaN and +-inf */

/* docs/MODEL.md's one repair of input depth: NaN and values above 1 become 1,
   values below 0 become 0 (the harness hands clamped maps; this is cheap
   insurance for a user's map). */
static inline float bmc_depth(float d) { return !(d <= 1.0f) ? 1.0f : d < 0.0f ? 0.0f : d; }

/* docs/MODEL.md: a NaN or infinite component, tmin < 0 or tmin > tmax: invalid. */
static inline int bmc_ray_valid(const lrt_ray *r)
{
    int k;
    for (k = 0; k < 3; ++k)
        if (!bmc_finite(r->origin[k]) || !bmc_finite(r->dir[k])) return 0;
    if (!bmc_finite(r->tmin) || !bmc_finite(r->tmax)) return 0;
    return r->tmin >= 0.0f && r->tmin <= r->tmax;
}

/* A coordinate of the point o + t v for float o, v and a float t: the
   product of two floats is exact in double and the sum is rounded once, so
   comparing the result with any float (an integer texel edge, a depth, W, H)
   gives the exact answer (rounding is monotonic). */
static inline double bmc_at(float o, float v, float t) { return (double)o + (double)t * (double)v; }

/* The kind of a miss by docs/MODEL.md's rule (the reference's): the point at tmax
   on the closed screen rectangle [0,W] x [0,H] (x and y only): reached tmax;
   otherwise the ray left (or never met) the screen. Exact, see bmc_at. */
static inline uint32_t bmc_miss_kind(const lrt_ray *r, uint32_t w, uint32_t h)
{
    double x = bmc_at(r->origin[0], r->dir[0], r->tmax), y = bmc_at(r->origin[1], r->dir[1], r->tmax);
    return (x >= 0.0 && x <= (double)w && y >= 0.0 && y <= (double)h) ? LRT_MISS_TMAX : LRT_MISS_OFF_SCREEN;
}

static inline void bmc_set_miss(lrt_hit *hit, uint32_t kind)
{
    hit->t = 0.0f;
    hit->x = hit->y = 0u;
    hit->kind = (uint16_t)kind;
    hit->face = LRT_FACE_NONE;
}

/* Clips [tmin, tmax] of a valid ray to the screen box [0,W] x [0,H] x [0,1]
   (every texel box lies inside it); double precision, no overflow for finite
   floats. Returns 0 when nothing is left, else the interval in *t0, *t1. */
static inline int bmc_clip(const lrt_ray *r, uint32_t w, uint32_t h, double *t0, double *t1)
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
static inline int bmc_begin(const lrt_ray *r, uint32_t w, uint32_t h, lrt_hit *hit, double *t0, double *t1)
{
    if (!bmc_ray_valid(r)) {
        bmc_set_miss(hit, LRT_MISS_INVALID_RAY);
        return 0;
    }
    if (!bmc_clip(r, w, h, t0, t1)) {
        bmc_set_miss(hit, bmc_miss_kind(r, w, h));
        return 0;
    }
    return 1;
}

/* texel index of a screen coordinate: floor, clamped to [0, n-1] (x == n,
   the screen's far edge, and rounding at the clip land in the last texel);
   truncation is floor for x >= 0, and negative x (or NaN) gives 0 */
static inline uint32_t bmc_texel(double x, uint32_t n)
{
    if (!(x >= 0.0)) return 0u;
    if (x >= (double)n) return n - 1u;
    return (uint32_t)x;
}

/* ---- a batch of rays on `threads` pthreads, contiguous slices --------------------- */
typedef void (*bmc_range_fn)(void *ctx, size_t first, size_t end);

typedef struct bmc_slice {
    bmc_range_fn fn;
    void *ctx;
    size_t first, end;
} bmc_slice;

static inline void *bmc_slice_main(void *p)
{
    bmc_slice *s = (bmc_slice *)p;
    s->fn(s->ctx, s->first, s->end);
    return NULL;
}

/* Runs fn over [0, count) split into `threads` contiguous slices; the calling
   thread takes the first. 0 on success, -1 if a thread could not start (the
   slices that did start are joined; the whole batch is then retraced on the
   calling thread, so the answers are complete either way). */
static inline int bmc_parallel(bmc_range_fn fn, void *ctx, size_t count, int threads)
{
    bmc_slice sl[BMC_MAX_THREADS];
    pthread_t th[BMC_MAX_THREADS];
    int k, started = 1, failed = 0;
    if (threads < 1) threads = 1;
    if (threads > BMC_MAX_THREADS) threads = BMC_MAX_THREADS;
    if ((size_t)threads > count) threads = count > 0 ? (int)count : 1;
    for (k = 0; k < threads; ++k) {
        sl[k].fn = fn;
        sl[k].ctx = ctx;
        sl[k].first = count * (size_t)k / (size_t)threads;
        sl[k].end = count * (size_t)(k + 1) / (size_t)threads;
    }
    for (k = 1; k < threads; ++k) {
        if (pthread_create(&th[k], NULL, bmc_slice_main, &sl[k]) != 0) {
            failed = 1;
            break;
        }
        started = k + 1;
    }
    bmc_slice_main(&sl[0]);
    for (k = 1; k < started; ++k) pthread_join(th[k], NULL);
    if (failed) {
        fn(ctx, 0, count);
        return -1;
    }
    return 0;
}

static inline void bmc_why(char *why, size_t n, const char *msg)
{
    if (why && n > 0) {
        size_t k = strlen(msg);
        if (k >= n) k = n - 1;
        memcpy(why, msg, k);
        why[k] = 0;
    }
}

#endif
