/* tests/test_threads.c - linear_rt.h's promise that threads may trace
   disjoint slices of one batch at once (lrt_trace_range: the tree and the
   depth are only read while tracing), run by `make test-threads-tsan` under
   ThreadSanitizer (clang -fsanitize=thread: any report fails the target).
   (a) slices: 4 threads trace uneven slices (some empty, some in chunks of
       calls) of one batch while the main thread waits in pthread_join; maps
       of many sizes, odd ones too, the three formats, reversed Z and padded
       rows, 8- and 16-bit nodes; nothing
       orders the threads but their creation and join, so TSan sees any
       write the library would make to memory they share (measured: a
       static counter injected into lrt_trace_range is reported here);
   (b) frames: the documented rule, the tree updated between frames
       (lrt_bvh_update with the changed rectangle, or the whole map) while
       no thread traces: threads joined every frame, or a pool of 4 parked
       on a condition variable (slices, or a shared queue of chunks); each
       update equals a rebuild byte for byte;
   (c) at once: two threads build an 8- and a 16-bit tree from one depth
       map, then 4 threads trace the whole batch at once, each tree with
       each flag, each thread into its own hits.
   Every threaded result equals a single-threaded lrt_trace of the same rays
   byte for byte, and a sample agrees with the reference (ref_check).
   --break-rule (TSan builds only): a self-check of the harness, one thread
   updates the tree while two trace it, against the rule; ThreadSanitizer
   must report it (the make target expects its exit code 66).
   Ends with "N passed, M failed". */
#define _POSIX_C_SOURCE 200809L /* pthreads under -std=c99 */
#define LINEAR_RT_IMPLEMENTATION
#include "../linear_rt.h"
#include "support/reference.h"
#include "../examples/scene.h"
#include "../examples/trace_threads.h"
#include "support/rays.h"
#include "support/check.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__SANITIZE_THREAD__)
#define TSAN_BUILD 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define TSAN_BUILD 1
#endif
#endif
#ifndef TSAN_BUILD
#define TSAN_BUILD 0
#endif

enum { THREADS = 4, SAMPLE_STEP = 37 /* every 37th ray is judged by the reference */ };

enum { FLAG_SETS = 1 }; /* lrt_trace has no flags yet */
static const uint32_t g_flag_sets[FLAG_SETS] = {0u};
static const char *flag_name(uint32_t f) { return f ? "flags?" : "closest"; }

/* ---- work of one thread: a slice of a batch ------------------------------------- */
/* Workers only write their own job (and their slice of hits): CHECK and
   the random numbers of rays.h belong to the main thread. */
typedef struct job {
    trace_slice s;     /* examples/trace_threads.h: the slice and its result */
    size_t chunk;      /* 0: the slice in one call, else calls of this many rays */
} job;

static void run_job(job *j)
{
    trace_slice *s = &j->s;
    size_t a = s->first;
    if (!j->chunk) {
        trace_slice_run(s);
        return;
    }
    s->result = LRT_SUCCESS;
    while (a < s->end && s->result == LRT_SUCCESS) {
        size_t b = s->end - a > j->chunk ? a + j->chunk : s->end;
        s->result = lrt_trace_range(s->bvh, s->depth, s->rays, s->hits, a, b, s->flags);
        a = b;
    }
}

static void *job_thread(void *arg)
{
    run_job((job *)arg);
    return NULL;
}

/* Runs n jobs on n threads of their own; the caller waits in pthread_join. */
static int run_joined(job *jobs, int n)
{
    pthread_t t[THREADS];
    int i, started = 0;
    for (i = 0; i < n; ++i) {
        if (pthread_create(&t[i], NULL, job_thread, &jobs[i]) != 0) break;
        ++started;
    }
    for (i = 0; i < started; ++i) pthread_join(t[i], NULL);
    return started == n;
}

/* ---- a pool of workers parked between frames, as an engine's job system ----------- */
typedef struct pool pool;
typedef struct worker { pool *p; int index; } worker;
struct pool {
    pthread_t threads[THREADS];
    worker workers[THREADS];
    int count;
    pthread_mutex_t lock;
    pthread_cond_t wake, idle;
    unsigned long frame; /* bumped by pool_run: every worker takes part once per frame */
    int busy;            /* workers not yet done with this frame */
    int quit;
    job *jobs;           /* per worker: jobs[index] (index < njobs) ... */
    int njobs;
    job *queue;          /* ... or one batch handed out in chunks under the lock */
    size_t next;
    lrt_result queue_result;
    size_t taken[THREADS]; /* chunks each worker took (queue mode) */
};

static void *pool_worker(void *arg)
{
    worker *w = (worker *)arg;
    pool *p = w->p;
    unsigned long seen = 0;
    pthread_mutex_lock(&p->lock);
    for (;;) {
        while (p->frame == seen && !p->quit) pthread_cond_wait(&p->wake, &p->lock);
        if (p->quit) break;
        seen = p->frame;
        if (p->queue) {
            job *q = p->queue;
            while (p->next < q->s.end) {
                size_t a = p->next, b = q->s.end - a > q->chunk ? a + q->chunk : q->s.end;
                lrt_result r;
                p->next = b;
                ++p->taken[w->index];
                pthread_mutex_unlock(&p->lock);
                r = lrt_trace_range(q->s.bvh, q->s.depth, q->s.rays, q->s.hits, a, b, q->s.flags);
                pthread_mutex_lock(&p->lock);
                if (r != LRT_SUCCESS) p->queue_result = r;
            }
        } else if (w->index < p->njobs) {
            job *j = &p->jobs[w->index];
            pthread_mutex_unlock(&p->lock);
            run_job(j);
            pthread_mutex_lock(&p->lock);
        }
        if (--p->busy == 0) pthread_cond_signal(&p->idle);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

static int pool_start(pool *p)
{
    int i;
    memset(p, 0, sizeof *p);
    pthread_mutex_init(&p->lock, NULL);
    pthread_cond_init(&p->wake, NULL);
    pthread_cond_init(&p->idle, NULL);
    for (i = 0; i < THREADS; ++i) {
        p->workers[i].p = p;
        p->workers[i].index = i;
        if (pthread_create(&p->threads[i], NULL, pool_worker, &p->workers[i]) != 0) break;
        ++p->count;
    }
    return p->count == THREADS;
}

/* One frame: each worker runs jobs[its index], or they share *queue in
   chunks; returns when every worker is parked again. */
static void pool_run(pool *p, job *jobs, int njobs, job *queue)
{
    pthread_mutex_lock(&p->lock);
    p->jobs = jobs;
    p->njobs = njobs;
    p->queue = queue;
    p->next = queue ? queue->s.first : 0;
    p->queue_result = LRT_SUCCESS;
    p->busy = p->count;
    ++p->frame;
    pthread_cond_broadcast(&p->wake);
    while (p->busy) pthread_cond_wait(&p->idle, &p->lock);
    pthread_mutex_unlock(&p->lock);
}

static void pool_stop(pool *p)
{
    int i;
    pthread_mutex_lock(&p->lock);
    p->quit = 1;
    pthread_cond_broadcast(&p->wake);
    pthread_mutex_unlock(&p->lock);
    for (i = 0; i < p->count; ++i) pthread_join(p->threads[i], NULL);
    pthread_cond_destroy(&p->wake);
    pthread_cond_destroy(&p->idle);
    pthread_mutex_destroy(&p->lock);
}

/* ---- checks (main thread) ----------------------------------------------------------- */
/* n cut points into [0, n): random, sorted, equal ones give empty slices */
static void split(size_t n, int parts, size_t *cuts)
{
    int i, k;
    cuts[0] = 0;
    cuts[parts] = n;
    for (i = 1; i < parts; ++i) cuts[i] = (rnd() & 7) == 0 ? cuts[i - 1] : (size_t)rnd() % (n + 1);
    for (i = 1; i < parts; ++i) /* insertion sort of cuts[1..parts-1] */
        for (k = i; k > 1 && cuts[k - 1] > cuts[k]; --k) {
            size_t t = cuts[k];
            cuts[k] = cuts[k - 1];
            cuts[k - 1] = t;
        }
}

/* THREADS jobs on random slices of rays[0, n) (split), each in one call
   until the caller sets its chunk */
static void make_jobs(job *jobs, const lrt_bvh *bvh, const lrt_depth *depth, const lrt_ray *rays, lrt_hit *hits,
                      size_t n, uint32_t flags)
{
    size_t cuts[THREADS + 1];
    int k;
    split(n, THREADS, cuts);
    for (k = 0; k < THREADS; ++k) {
        jobs[k].s.bvh = bvh;
        jobs[k].s.depth = depth;
        jobs[k].s.rays = rays;
        jobs[k].s.hits = hits;
        jobs[k].s.first = cuts[k];
        jobs[k].s.end = cuts[k + 1];
        jobs[k].chunk = 0;
        jobs[k].s.flags = flags;
        jobs[k].s.result = LRT_ERROR_INVALID_BVH;
    }
}

/* Threaded hits == single-threaded hits, byte for byte; 1 when they are. */
static int same_hits(const lrt_hit *got, const lrt_hit *expect, size_t n, const job *jobs, int njobs, const char *what)
{
    size_t i, differ = 0, first = 0;
    int k;
    for (i = 0; i < n; ++i)
        if (memcmp(&got[i], &expect[i], sizeof got[i]) != 0 && differ++ == 0) first = i;
    if (differ) {
        int owner = -1;
        for (k = 0; k < njobs; ++k)
            if (first >= jobs[k].s.first && first < jobs[k].s.end) owner = k;
        printf("  %s: %zu of %zu hits differ from one thread's; the first, ray %zu (thread %d): kind %u t %.9g (%u,%u), "
               "single-threaded kind %u t %.9g (%u,%u)\n",
               what, differ, n, first, owner, got[first].kind, (double)got[first].t, got[first].x, got[first].y,
               expect[first].kind, (double)expect[first].t, expect[first].x, expect[first].y);
    }
    return differ == 0;
}

/* Every SAMPLE_STEP-th answer against the reference; returns the wrong ones. */
static size_t judge_sample(const ref_map *ref, const lrt_ray *rays, const lrt_hit *hits, size_t n, uint32_t flags,
                           size_t offset, const char *what)
{
    size_t i, wrong = 0;
    for (i = offset % SAMPLE_STEP; i < n; i += SAMPLE_STEP) {
        ref_ray q = ref_ray_of(&rays[i]);
        ref_answer a = to_answer(&hits[i]);
        char why[256];
        if (!ref_check(ref, &q, &a, flags != 0, why, sizeof why)) {
            if (wrong < 3)
                printf("  %s: ray %zu o=(%.9g %.9g %.9g) v=(%.9g %.9g %.9g) t=[%.9g %.9g]: %s\n", what, i, q.o[0],
                       q.o[1], q.o[2], q.v[0], q.v[1], q.v[2], q.tmin, q.tmax, why);
            ++wrong;
        }
    }
    return wrong;
}

static lrt_ray *make_rays(const test_map *m, size_t n)
{
    lrt_ray *rays = (lrt_ray *)malloc(sizeof(lrt_ray) * n);
    size_t i;
    if (!rays) exit(2);
    for (i = 0; i < n; ++i) rays[i] = make_ray(m, (int)(i % RAY_KIND_COUNT));
    return rays;
}

/* ---- (a) slices of one batch, the main thread waiting --------------------------------- */
static void slices_case(int w, int h, int shape, lrt_format format, int reversed, int padded, size_t n)
{
    test_map m;
    lrt_ray *rays;
    lrt_hit *expect = (lrt_hit *)malloc(sizeof(lrt_hit) * n), *hits = (lrt_hit *)malloc(sizeof(lrt_hit) * n);
    uint32_t bits;
    int f, k;
    make_map(&m, w, h, shape, format, reversed, padded);
    rays = make_rays(&m, n);
    for (bits = 8; bits <= 16; bits += 8) {
        lrt_bvh bvh = {0};
        lrt_build_options opt;
        memset(&opt, 0, sizeof opt);
        opt.node_bits = bits;
        CHECK(lrt_bvh_build(&bvh, &m.depth, &opt, NULL) == LRT_SUCCESS, "%dx%d: build", w, h);
        for (f = 0; f < FLAG_SETS; ++f) {
            const uint32_t flags = g_flag_sets[f];
            job jobs[THREADS];
            char what[160];
            int ok = 1;
            snprintf(what, sizeof what, "slices %dx%d %s fmt=%d%s%s nodes=%u %s", w, h, m.name, (int)format,
                     reversed ? " reversed" : "", padded ? " strided" : "", bits, flag_name(flags));
            CHECK(lrt_trace(&bvh, &m.depth, rays, expect, n, flags) == LRT_SUCCESS, "%s: single-threaded trace", what);
            memset(hits, 0xff, sizeof(lrt_hit) * n);
            make_jobs(jobs, &bvh, &m.depth, rays, hits, n, flags);
            for (k = 0; k < THREADS; ++k)
                jobs[k].chunk = (size_t)(k & 1) * (1 + (size_t)rndi(100)); /* odd threads: many small calls */
            CHECK(run_joined(jobs, THREADS), "%s: pthread_create failed", what);
            for (k = 0; k < THREADS; ++k) ok &= jobs[k].s.result == LRT_SUCCESS;
            CHECK(ok, "%s: a thread's lrt_trace_range failed", what);
            CHECK(same_hits(hits, expect, n, jobs, THREADS, what), "%s: threads differ from one thread", what);
            CHECK(judge_sample(&m.ref, rays, hits, n, flags, (size_t)f, what) == 0, "%s: wrong by the reference", what);
        }
        lrt_bvh_destroy(&bvh);
    }
    free(rays);
    free(expect);
    free(hits);
    free_map(&m);
}

static void test_slices(void)
{
    slices_case(1, 1, SHAPE_NOISE, LRT_FORMAT_FLOAT32, 0, 0, 1000);
    slices_case(7, 9, SHAPE_TERRACES, LRT_FORMAT_UNORM8, 1, 1, 6000);
    slices_case(33, 20, SHAPE_POLES, LRT_FORMAT_UNORM16, 0, 0, 6000);
    slices_case(203, 131, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 1, 12000);
    slices_case(701, 3, SHAPE_NOISE, LRT_FORMAT_UNORM16, 1, 0, 6000);
    slices_case(5, 517, SHAPE_WILD, LRT_FORMAT_FLOAT32, 0, 0, 6000);
    slices_case(640, 361, SHAPE_SCENE, LRT_FORMAT_UNORM8, 0, 0, 12000);
    slices_case(1282, 1110, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 1, 0, 20000);
}

/* ---- (b) frames: update between them, no thread tracing --------------------------------- */
enum { SYNC_JOIN, SYNC_POOL, SYNC_QUEUE };
static const char *sync_names[] = {"joined threads", "pool, a slice each", "pool, a queue of chunks"};

static void frames_case(int sync, uint32_t bits, pool *p)
{
    const int w = 227, h = 139, frames = 16;
    const size_t n = 5000;
    float *d = (float *)malloc(sizeof(float) * w * h), *prev = (float *)malloc(sizeof(float) * w * h);
    lrt_hit *expect = (lrt_hit *)malloc(sizeof(lrt_hit) * n), *hits = (lrt_hit *)malloc(sizeof(lrt_hit) * n);
    test_map m;
    lrt_bvh live = {0};
    lrt_build_options opt;
    size_t stale = 0, differ = 0, wrong = 0, failed = 0;
    int frame, k;
    char what[160];
    snprintf(what, sizeof what, "frames %dx%d nodes=%u, %s", w, h, bits, sync_names[sync]);
    memset(&m, 0, sizeof m);
    m.depth.data = d;
    m.depth.width = (uint32_t)w;
    m.depth.height = (uint32_t)h;
    m.depth.format = LRT_FORMAT_FLOAT32;
    memset(&opt, 0, sizeof opt);
    opt.node_bits = bits;
    paint_frame(d, w, h, 0);
    CHECK(lrt_bvh_build(&live, &m.depth, &opt, NULL) == LRT_SUCCESS, "%s: build", what);
    for (frame = 1; frame <= frames; ++frame) {
        const uint32_t flags = g_flag_sets[frame % FLAG_SETS];
        lrt_rect rect;
        lrt_bvh fresh = {0};
        lrt_ray *rays;
        job jobs[THREADS], queue;
        /* every thread is joined or parked: the tree may change */
        memcpy(prev, d, sizeof(float) * w * h);
        paint_frame(d, w, h, frame);
        rect = changed_rect(prev, d, w, h);
        failed += lrt_bvh_update(&live, &m.depth, frame % 3 ? &rect : NULL) != LRT_SUCCESS;
        failed += lrt_bvh_build(&fresh, &m.depth, &opt, NULL) != LRT_SUCCESS;
        stale += memcmp(live.nodes, fresh.nodes, live.layout.bytes) != 0;
        lrt_bvh_destroy(&fresh);
        if (ref_map_from_raw(&m.ref, d, w, h, 0, REF_FORMAT_FLOAT32, 0) != 0) exit(2);
        rays = make_rays(&m, n);
        failed += lrt_trace(&live, &m.depth, rays, expect, n, flags) != LRT_SUCCESS;
        memset(hits, 0xff, sizeof(lrt_hit) * n);
        make_jobs(jobs, &live, &m.depth, rays, hits, n, flags);
        for (k = 0; k < THREADS; ++k) jobs[k].chunk = (size_t)(frame & 1) * 50;
        queue = jobs[0];
        queue.s.first = 0;
        queue.s.end = n;
        queue.chunk = 64 + (size_t)rndi(64);
        if (sync == SYNC_JOIN) {
            failed += !run_joined(jobs, THREADS);
        } else if (sync == SYNC_POOL) {
            pool_run(p, jobs, THREADS, NULL);
        } else {
            for (k = 0; k < THREADS; ++k) jobs[k].s.result = LRT_SUCCESS; /* unused: one queue */
            pool_run(p, NULL, 0, &queue);
            failed += p->queue_result != LRT_SUCCESS; /* the workers are parked: no lock needed */
        }
        for (k = 0; k < THREADS; ++k) failed += jobs[k].s.result != LRT_SUCCESS;
        differ += !same_hits(hits, expect, n, jobs, sync == SYNC_QUEUE ? 0 : THREADS, what);
        wrong += judge_sample(&m.ref, rays, hits, n, flags, (size_t)frame, what);
        free(rays);
        ref_map_free(&m.ref);
    }
    CHECK(failed == 0, "%s: %zu calls failed", what, failed);
    CHECK(stale == 0, "%s: %zu of %d updates differ from a rebuild", what, stale, frames);
    CHECK(differ == 0, "%s: %zu of %d frames' threaded hits differ from one thread's", what, differ, frames);
    CHECK(wrong == 0, "%s: %zu sampled answers wrong by the reference", what, wrong);
    lrt_bvh_destroy(&live);
    free(d);
    free(prev);
    free(expect);
    free(hits);
}

static void test_frames(void)
{
    pool p;
    uint32_t bits;
    int k;
    size_t chunks = 0;
    if (!pool_start(&p)) {
        CHECK(0, "the pool's threads could not be started");
        pool_stop(&p);
        return;
    }
    for (bits = 8; bits <= 16; bits += 8) {
        frames_case(SYNC_JOIN, bits, &p);
        frames_case(SYNC_POOL, bits, &p);
        frames_case(SYNC_QUEUE, bits, &p);
    }
    for (k = 0; k < THREADS; ++k) chunks += p.taken[k];
    pool_stop(&p);
    CHECK(chunks > 0, "the queue handed out no chunk");
}

/* ---- (c) two trees, every flag, at once ------------------------------------------------- */
typedef struct build_job {
    lrt_bvh *bvh;
    const lrt_depth *depth;
    uint32_t bits;
    lrt_result result;
} build_job;

static void *build_thread(void *arg)
{
    build_job *b = (build_job *)arg;
    lrt_build_options opt;
    memset(&opt, 0, sizeof opt);
    opt.node_bits = b->bits;
    b->result = lrt_bvh_build(b->bvh, b->depth, &opt, NULL);
    return NULL;
}

static void test_at_once(void)
{
    const size_t n = 10000;
    test_map m;
    lrt_bvh trees[2], check = {0};
    memset(trees, 0, sizeof trees);
    build_job builds[2];
    pthread_t t[2];
    lrt_ray *rays;
    lrt_hit *expect[THREADS], *hits[THREADS];
    job jobs[THREADS];
    int k, started = 0;
    make_map(&m, 311, 177, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 1);
    /* two trees of one depth map built at once: build only reads the depth */
    for (k = 0; k < 2; ++k) {
        builds[k].bvh = &trees[k];
        builds[k].depth = &m.depth;
        builds[k].bits = 8u << k;
        builds[k].result = LRT_ERROR_INVALID_BVH;
        if (pthread_create(&t[k], NULL, build_thread, &builds[k]) == 0) ++started;
    }
    for (k = 0; k < started; ++k) pthread_join(t[k], NULL);
    if (started != 2 || builds[0].result != LRT_SUCCESS || builds[1].result != LRT_SUCCESS) {
        CHECK(0, "at once: the two builds failed");
        for (k = 0; k < started; ++k)
            if (builds[k].result == LRT_SUCCESS) lrt_bvh_destroy(&trees[k]);
        free_map(&m);
        return;
    }
    for (k = 0; k < 2; ++k) {
        lrt_build_options opt;
        memset(&opt, 0, sizeof opt);
        opt.node_bits = 8u << k;
        CHECK(lrt_bvh_build(&check, &m.depth, &opt, NULL) == LRT_SUCCESS &&
                  memcmp(check.nodes, trees[k].nodes, check.layout.bytes) == 0,
              "at once: the %u-bit tree built beside another differs from a lone build", 8u << k);
        lrt_bvh_destroy(&check);
    }
    rays = make_rays(&m, n);
    for (k = 0; k < THREADS; ++k) { /* thread k: tree k & 1 with flags k >> 1, the whole batch */
        expect[k] = (lrt_hit *)malloc(sizeof(lrt_hit) * n);
        hits[k] = (lrt_hit *)malloc(sizeof(lrt_hit) * n);
        memset(hits[k], 0xff, sizeof(lrt_hit) * n);
        lrt_trace(&trees[k & 1], &m.depth, rays, expect[k], n, g_flag_sets[k >> 1]);
        jobs[k].s.bvh = &trees[k & 1];
        jobs[k].s.depth = &m.depth;
        jobs[k].s.rays = rays;
        jobs[k].s.hits = hits[k];
        jobs[k].s.first = 0;
        jobs[k].s.end = n;
        jobs[k].chunk = (size_t)k * 33;
        jobs[k].s.flags = g_flag_sets[k >> 1];
        jobs[k].s.result = LRT_ERROR_INVALID_BVH;
    }
    CHECK(run_joined(jobs, THREADS), "at once: pthread_create failed");
    for (k = 0; k < THREADS; ++k) {
        char what[96];
        snprintf(what, sizeof what, "at once: thread %d, %u-bit tree, %s", k, 8u << (k & 1), flag_name(g_flag_sets[k >> 1]));
        CHECK(jobs[k].s.result == LRT_SUCCESS, "%s: lrt_trace_range failed", what);
        CHECK(same_hits(hits[k], expect[k], n, jobs + k, 1, what), "%s: differs from one thread", what);
        CHECK(judge_sample(&m.ref, rays, hits[k], n, g_flag_sets[k >> 1], (size_t)k, what) == 0, "%s: wrong by the reference",
              what);
        free(expect[k]);
        free(hits[k]);
    }
    free(rays);
    lrt_bvh_destroy(&trees[0]);
    lrt_bvh_destroy(&trees[1]);
    free_map(&m);
}

/* ---- --break-rule: the harness sees a race -------------------------------------------- */
typedef struct update_job {
    lrt_bvh *bvh;
    const lrt_depth *depth;
} update_job;

static void *update_thread(void *arg)
{
    update_job *u = (update_job *)arg;
    lrt_bvh_update(u->bvh, u->depth, NULL);
    return NULL;
}

/* Against the documented rule: the tree is refitted while two threads
   trace it. Under TSan (halt_on_error) this never returns. */
static int break_rule(void)
{
    const size_t n = 20000;
    test_map m;
    lrt_bvh bvh = {0};
    lrt_ray *rays;
    lrt_hit *hits = (lrt_hit *)malloc(sizeof(lrt_hit) * n * 2);
    job jobs[2];
    update_job u;
    pthread_t t[3];
    int k;
    if (!TSAN_BUILD) {
        printf("--break-rule: only for a -fsanitize=thread build (it races on purpose)\n");
        return 2;
    }
    make_map(&m, 256, 256, SHAPE_NOISE, LRT_FORMAT_FLOAT32, 0, 0);
    lrt_bvh_build(&bvh, &m.depth, NULL, NULL);
    rays = make_rays(&m, n);
    /* a new frame's depth (all near): the refit must write the nodes */
    memset((unsigned char *)m.storage + 1, 0, sizeof(float) * m.depth.width * m.depth.height);
    u.bvh = &bvh;
    u.depth = &m.depth;
    for (k = 0; k < 2; ++k) {
        jobs[k].s.bvh = &bvh;
        jobs[k].s.depth = &m.depth;
        jobs[k].s.rays = rays;
        jobs[k].s.hits = hits + n * (size_t)k;
        jobs[k].s.first = 0;
        jobs[k].s.end = n;
        jobs[k].chunk = 0;
        jobs[k].s.flags = 0;
        pthread_create(&t[k], NULL, job_thread, &jobs[k]);
    }
    pthread_create(&t[2], NULL, update_thread, &u);
    for (k = 0; k < 3; ++k) pthread_join(t[k], NULL);
    printf("--break-rule: FAIL: ThreadSanitizer reported nothing while the tree was updated during a trace\n");
    lrt_bvh_destroy(&bvh);
    free(rays);
    free(hits);
    free_map(&m);
    return 1;
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "--break-rule") == 0) return break_rule();
    if (argc > 2 || (argc > 1 && argv[1][0] == '-')) {
        printf("usage: %s [--break-rule | TEST]\n", argv[0]);
        return 2;
    }
    check_select(argc, argv);
    printf("threads: %d%s\n", THREADS, TSAN_BUILD ? ", under ThreadSanitizer" : "");
    RUN_TEST(test_slices);
    RUN_TEST(test_frames);
    RUN_TEST(test_at_once);
    return check_summary();
}
