/* examples/trace_threads.h - one batch of rays traced by lrt_trace_range on
   threads of their own, in equal slices, as an engine without a job system
   would: the demo's timed traces (examples/demo.c), the benchmark's CPU
   methods (bench/m_linear_rt.c) and bench/walk_rays.c; tests/test_threads.c
   builds its uneven slices from the same trace_slice. Include after
   linear_rt.h; POSIX threads. It calls lrt_trace_range alone, which every
   version of linear_rt.h has had, so walk_rays.c still builds against an
   older header (bench/walk_ab.sh). */
#ifndef EXAMPLES_TRACE_THREADS_H
#define EXAMPLES_TRACE_THREADS_H

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>

#if defined(__GNUC__) || defined(__clang__)
#define TRACE_THREADS_FN static __attribute__((unused)) /* a file uses only some */
#else
#define TRACE_THREADS_FN static
#endif

/* one thread's slice [first, end) of a batch, and what lrt_trace_range
   answered for it */
typedef struct trace_slice {
    const lrt_bvh *bvh;
    const lrt_depth *depth;
    const lrt_ray *rays;
    lrt_hit *hits;
    size_t first, end;
    uint32_t flags;
    lrt_result result;
} trace_slice;

#define TRACE_THREADS_MAX 64 /* threads of one trace_threads */

/* a thread's function: traces its slice */
TRACE_THREADS_FN void *trace_slice_run(void *arg)
{
    trace_slice *s = (trace_slice *)arg;
    s->result = lrt_trace_range(s->bvh, s->depth, s->rays, s->hits, s->first, s->end, s->flags);
    return NULL;
}

/* rays[0, count) into hits on `threads` threads (1 to TRACE_THREADS_MAX):
   slice k is [count k / threads, count (k + 1) / threads), and the calling
   thread takes slice 0. The first failing slice's result, else LRT_SUCCESS;
   a thread that cannot be started ends the program (timings would lie). */
TRACE_THREADS_FN lrt_result trace_threads(const lrt_bvh *bvh, const lrt_depth *depth, const lrt_ray *rays,
                                          lrt_hit *hits, size_t count, uint32_t flags, int threads)
{
    trace_slice s[TRACE_THREADS_MAX];
    pthread_t th[TRACE_THREADS_MAX];
    int k;
    threads = threads < 1 ? 1 : threads > TRACE_THREADS_MAX ? TRACE_THREADS_MAX : threads;
    for (k = 0; k < threads; ++k) {
        s[k].bvh = bvh;
        s[k].depth = depth;
        s[k].rays = rays;
        s[k].hits = hits;
        s[k].first = count * (size_t)k / (size_t)threads;
        s[k].end = count * (size_t)(k + 1) / (size_t)threads;
        s[k].flags = flags;
        if (k > 0 && pthread_create(&th[k], NULL, trace_slice_run, &s[k]) != 0) {
            fprintf(stderr, "trace_threads: pthread_create failed\n");
            exit(1);
        }
    }
    trace_slice_run(&s[0]);
    for (k = 1; k < threads; ++k) pthread_join(th[k], NULL);
    for (k = 0; k < threads; ++k)
        if (s[k].result != LRT_SUCCESS) return s[k].result;
    return LRT_SUCCESS;
}

#endif /* EXAMPLES_TRACE_THREADS_H */
