/* bench/march_common.h - what the CPU peers of the benchmark share
   (bench/m_embree.c, bench/march_cpu.c): docs/MODEL.md's ray validation, the
   clip of a ray to the screen box and the rule that tells the two kinds of
   miss apart (the march_* functions of examples/march.h, the classic march
   a user writes, which the benchmark scores as "march64 cpu" and the like),
   and here a parallel-for over a batch of rays on pthreads.

   The marching math itself: the fixed-step march in examples/march.h, DDA
   and Hi-Z in bench/march_cpu.c; their comments state each step in terms a
   shader can follow. Everything here is `static inline` (no unused-function
   warnings), C99. */
#ifndef LINEAR_RT_BENCH_MARCH_COMMON_H
#define LINEAR_RT_BENCH_MARCH_COMMON_H

#include <math.h>
#include <pthread.h>
#include <stddef.h>
#include <string.h>
#include "bench.h"
#include "../examples/march.h"

#define BMC_MAX_THREADS 64

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
