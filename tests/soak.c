/* tests/soak.c - linear_rt.h run the way an engine runs it, for a while:
   `make soak` (SOAK_SECONDS, default 60; not part of `make test`).

   A frame loop. Now and then (and at the start) a new map: a random size
   (1..700 a side, odd ones included, sometimes up to 2048x1200), shape,
   format, reversed Z, row padding and node bits (8, 16 or auto): the tree
   is destroyed and built again. Every other frame changes the depth inside
   a random rectangle only (noise, a plane, a bump, near or far, NaN and
   out-of-range floats) and refits the tree with that rectangle (or, one
   frame in 8, the whole map); the refit must equal a fresh build byte for
   byte. Then a batch of rays of every kind of tests/support/rays.h is traced by a
   pool of 4 threads, 2 to 4 of them taking a slice (lrt_trace_range) while
   the main thread waits. The
   threads' hits
   must equal a single-threaded lrt_trace byte for byte, and a sample of
   each frame's hits must agree with the exact reference (ref_check).

   Prints a progress line every 10 s and at the end the frames, rays and
   mismatches; exits 1 on any mismatch. Usage: soak [seconds]; the
   environment variable SOAK_SEED replays a run (the seed is printed). */
#define _POSIX_C_SOURCE 200809L /* pthreads and clock_gettime under -std=c99 */
#define LINEAR_RT_IMPLEMENTATION
#include "../linear_rt.h"
#include "support/reference.h"
#include "../examples/scene.h"
#include "support/rays.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { THREADS = 4, MAX_RAYS = 24000, REF_SAMPLE = 48, MAX_REPORTS = 10 };

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- the thread pool: workers parked between frames ------------------------------ */
typedef struct slice {
    size_t first, end;
    lrt_result result;
} slice;

typedef struct pool {
    pthread_t threads[THREADS];
    int index[THREADS];
    int count;
    pthread_mutex_t lock;
    pthread_cond_t wake, idle;
    unsigned long frame; /* bumped by pool_run */
    int busy, quit;
    /* this frame's batch: worker i traces slices[i] when i < active */
    const lrt_bvh *bvh;
    const lrt_depth *depth;
    const lrt_ray *rays;
    lrt_hit *hits;
    uint32_t flags;
    int active;
    slice slices[THREADS];
} pool;

static pool g_pool;

static void *pool_worker(void *arg)
{
    const int me = *(const int *)arg;
    pool *p = &g_pool;
    unsigned long seen = 0;
    pthread_mutex_lock(&p->lock);
    for (;;) {
        while (p->frame == seen && !p->quit) pthread_cond_wait(&p->wake, &p->lock);
        if (p->quit) break;
        seen = p->frame;
        if (me < p->active) {
            slice *s = &p->slices[me];
            pthread_mutex_unlock(&p->lock);
            s->result = lrt_trace_range(p->bvh, p->depth, p->rays, p->hits, s->first, s->end, p->flags);
            pthread_mutex_lock(&p->lock);
        }
        if (--p->busy == 0) pthread_cond_signal(&p->idle);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

static int pool_start(void)
{
    pool *p = &g_pool;
    int i;
    pthread_mutex_init(&p->lock, NULL);
    pthread_cond_init(&p->wake, NULL);
    pthread_cond_init(&p->idle, NULL);
    for (i = 0; i < THREADS; ++i) {
        p->index[i] = i;
        if (pthread_create(&p->threads[i], NULL, pool_worker, &p->index[i]) != 0) break;
        ++p->count;
    }
    return p->count == THREADS;
}

/* The frame's batch (set in g_pool by the caller) on `active` workers;
   returns when all are parked again. */
static void pool_run(int active)
{
    pool *p = &g_pool;
    pthread_mutex_lock(&p->lock);
    p->active = active;
    p->busy = p->count;
    ++p->frame;
    pthread_cond_broadcast(&p->wake);
    while (p->busy) pthread_cond_wait(&p->idle, &p->lock);
    pthread_mutex_unlock(&p->lock);
}

static void pool_stop(void)
{
    pool *p = &g_pool;
    int i;
    pthread_mutex_lock(&p->lock);
    p->quit = 1;
    pthread_cond_broadcast(&p->wake);
    pthread_mutex_unlock(&p->lock);
    for (i = 0; i < p->count; ++i) pthread_join(p->threads[i], NULL);
}

/* ---- the soak's state ----------------------------------------------------------------- */
typedef struct stats {
    unsigned long frames, maps, updates, rect_updates, empty_rects, rays, ref_checked;
    unsigned long update_mismatch, thread_mismatch, ref_mismatch, call_failed;
    uint32_t largest_w, largest_h;
} stats;

static stats g_s;
static int g_reports;
static unsigned long long g_seed;

static unsigned long mismatches(void)
{
    return g_s.update_mismatch + g_s.thread_mismatch + g_s.ref_mismatch + g_s.call_failed;
}

static void report(const char *fmt, const char *a, unsigned long frame, const test_map *m, const lrt_bvh *bvh)
{
    if (g_reports++ >= MAX_REPORTS) return;
    printf("MISMATCH frame %lu (SOAK_SEED=%llu): %dx%d %s fmt=%d%s nodes=%u: ", frame, g_seed, m->ref.w, m->ref.h,
           m->name, (int)m->depth.format, m->depth.flags ? " reversed" : "", bvh->layout.node_bits);
    printf(fmt, a);
    printf("\n");
}

static uint32_t bytes_of(lrt_format f) { return f == LRT_FORMAT_UNORM8 ? 1u : f == LRT_FORMAT_UNORM16 ? 2u : 4u; }

/* a random size: mostly small and odd, now and then large */
static void pick_size(int *w, int *h)
{
    int r = rndi(100);
    if (r < 8) { /* large */
        *w = 1024 + rndi(1025);
        *h = 600 + rndi(601);
    } else if (r < 20) { /* thin or tiny */
        *w = 1 + rndi(rnd() & 1 ? 8 : 700);
        *h = 1 + rndi(8);
        if (rnd() & 1) {
            int t = *w;
            *w = *h;
            *h = t;
        }
    } else {
        *w = 1 + rndi(700);
        *h = 1 + rndi(700);
    }
}

/* Writes depth value v (model units; any float for float maps) at texel (i, j). */
static void put(test_map *m, int i, int j, float v)
{
    const uint32_t bpp = bytes_of(m->depth.format);
    const size_t stride = m->depth.row_stride ? m->depth.row_stride : (size_t)m->depth.width * bpp;
    unsigned char *p = (unsigned char *)m->storage + 1 + stride * (size_t)j + (size_t)i * bpp; /* make_map's +1 */
    if (m->depth.format == LRT_FORMAT_FLOAT32) {
        memcpy(p, &v, 4);
        return;
    }
    v = v != v ? 1.0f : v < 0.0f ? 0.0f : v > 1.0f ? 1.0f : v;
    if (m->depth.format == LRT_FORMAT_UNORM8) {
        p[0] = (unsigned char)(v * 255.0f + 0.5f);
    } else {
        uint16_t u = (uint16_t)(v * 65535.0f + 0.5f);
        memcpy(p, &u, 2);
    }
}

/* New depth inside rect only: the change a frame makes. */
static void paint_rect(test_map *m, const lrt_rect *rect)
{
    const int kind = rndi(7);
    const float base = rndf(), slope_x = (rndf() - 0.5f) * 0.02f, slope_y = (rndf() - 0.5f) * 0.02f;
    const float cx = (float)rect->x + rndf() * (float)rect->width, cy = (float)rect->y + rndf() * (float)rect->height;
    const float radius = 1.0f + rndf() * (float)(rect->width > rect->height ? rect->width : rect->height);
    uint32_t i, j;
    for (j = rect->y; j < rect->y + rect->height; ++j)
        for (i = rect->x; i < rect->x + rect->width; ++i) {
            float v, dx = (float)i + 0.5f - cx, dy = (float)j + 0.5f - cy;
            switch (kind) {
            case 0: v = rndf(); break;                                         /* noise */
            case 1: v = base + slope_x * (float)(i - rect->x) + slope_y * (float)(j - rect->y); break; /* a plane */
            case 2: v = dx * dx + dy * dy < radius * radius ? 0.2f + 0.3f * sqrtf(dx * dx + dy * dy) / radius : base;
                break;                                                         /* a bump */
            case 3: v = 1.0f; break;                                           /* far: sky */
            case 4: v = 0.0f; break;                                           /* on the near plane */
            case 5: v = floorf(base * 8.0f + (float)((i / 3 + j / 5) & 3)) / 12.0f; break; /* terraces */
            default: { /* values the model clamps (floats), else noise */
                int r = rndi(8);
                v = r == 0 ? NAN : r == 1 ? 1.5f : r == 2 ? -0.25f : r == 3 ? INFINITY : rndf();
                break;
            }
            }
            put(m, (int)i, (int)j, v);
        }
}

static lrt_rect pick_rect(int w, int h)
{
    lrt_rect r;
    int k = rndi(20);
    if (k == 0) { /* empty: no width or no height, anywhere up to the far edges */
        r.x = (uint32_t)rndi(w + 1);
        r.y = (uint32_t)rndi(h + 1);
        r.width = rnd() & 1 ? 0u : (uint32_t)rndi(w - (int)r.x + 1);
        r.height = r.width ? 0u : (uint32_t)rndi(h - (int)r.y + 1);
        return r;
    }
    if (k == 1) { /* everything */
        r.x = r.y = 0;
        r.width = (uint32_t)w;
        r.height = (uint32_t)h;
        return r;
    }
    if (k < 5) { /* a single texel or a thin line */
        r.x = (uint32_t)rndi(w);
        r.y = (uint32_t)rndi(h);
        r.width = 1 + (uint32_t)(k == 3 ? rndi(w - (int)r.x) : 0);
        r.height = 1 + (uint32_t)(k == 4 ? rndi(h - (int)r.y) : 0);
        return r;
    }
    r.width = 1 + (uint32_t)rndi(w < 200 ? w : 1 + rndi(w));
    r.height = 1 + (uint32_t)rndi(h < 200 ? h : 1 + rndi(h));
    if (r.width > (uint32_t)w) r.width = (uint32_t)w;
    if (r.height > (uint32_t)h) r.height = (uint32_t)h;
    r.x = (uint32_t)rndi(w - (int)r.width + 1);
    r.y = (uint32_t)rndi(h - (int)r.height + 1);
    return r;
}

/* ---- one frame ------------------------------------------------------------------------ */
typedef struct world {
    test_map m;
    lrt_bvh live, fresh; /* zeroed with the whole world in main (lrt_bvh_build needs a zeroed tree) */
    lrt_build_options opt;
    int have_map;
    lrt_ray *rays;
    lrt_hit *hits, *expect;
} world;

static void new_map(world *wd)
{
    static const lrt_format formats[3] = {LRT_FORMAT_UNORM8, LRT_FORMAT_UNORM16, LRT_FORMAT_FLOAT32};
    static const uint32_t bits[3] = {8u, 16u, LRT_NODE_BITS_AUTO};
    int w, h, shape;
    lrt_format format;
    if (wd->have_map) {
        lrt_bvh_destroy(&wd->live);
        free_map(&wd->m);
    }
    pick_size(&w, &h);
    format = formats[rndi(3)];
    shape = rndi(SHAPE_COUNT);
    if (shape == SHAPE_WILD && format != LRT_FORMAT_FLOAT32) shape = SHAPE_NOISE;
    make_map(&wd->m, w, h, shape, format, (int)(rnd() & 1), (int)((rnd() & 3) == 0));
    memset(&wd->opt, 0, sizeof wd->opt);
    wd->opt.node_bits = bits[rndi(3)];
    if (lrt_bvh_build(&wd->live, &wd->m.depth, &wd->opt, NULL) != LRT_SUCCESS) {
        printf("soak: build of a %dx%d map failed\n", w, h);
        exit(2);
    }
    wd->have_map = 1;
    ++g_s.maps;
    if ((uint64_t)w * (uint64_t)h > (uint64_t)g_s.largest_w * g_s.largest_h) {
        g_s.largest_w = (uint32_t)w;
        g_s.largest_h = (uint32_t)h;
    }
}

static void frame(world *wd, unsigned long f)
{
    test_map *m = &wd->m;
    const int w = (int)m->depth.width, h = (int)m->depth.height;
    const uint32_t flags = 0u; /* lrt_trace has no flags yet */
    size_t n, i, cuts[THREADS + 1];
    int active, k;
    lrt_result r;

    if (!wd->have_map || rndi(40) == 0) {
        new_map(wd);
    } else if (f & 1) { /* a change inside a rectangle, and its refit */
        lrt_rect rect = pick_rect(w, h);
        const int whole = rndi(8) == 0;
        if (rect.width && rect.height) paint_rect(m, &rect);
        else ++g_s.empty_rects;
        r = lrt_bvh_update(&wd->live, &m->depth, whole ? NULL : &rect);
        if (r != LRT_SUCCESS) {
            ++g_s.call_failed;
            report("lrt_bvh_update: %s", lrt_result_string(r), f, m, &wd->live);
        }
        ++g_s.updates;
        g_s.rect_updates += !whole;
        ref_map_free(&m->ref);
        if (ref_map_from_raw(&m->ref, m->depth.data, w, h, m->depth.row_stride, (int)m->depth.format,
                             m->depth.flags != 0) != 0)
            exit(2);
        /* the refit == a fresh build of the same depth, byte for byte */
        r = lrt_bvh_build(&wd->fresh, &m->depth, &wd->opt, NULL);
        if (r != LRT_SUCCESS || wd->fresh.layout.bytes != wd->live.layout.bytes ||
            memcmp(wd->fresh.nodes, wd->live.nodes, wd->live.layout.bytes) != 0) {
            char what[96];
            ++g_s.update_mismatch;
            snprintf(what, sizeof what, "rect (%u,%u) %ux%u%s", rect.x, rect.y, rect.width, rect.height,
                     whole ? ", updated as the whole map" : "");
            report("the refit after a change in %s differs from a fresh build", what, f, m, &wd->live);
        }
        lrt_bvh_destroy(&wd->fresh);
    }

    /* the batch: all ray kinds, some frames mostly reflections */
    n = rndi(10) == 0 ? (size_t)rndi(64) : 1 + (size_t)rndi(MAX_RAYS);
    for (i = 0; i < n; ++i) wd->rays[i] = make_ray(m, (rnd() & 1) ? RAY_REFLECT : rndi(RAY_KIND_COUNT));
    memset(wd->hits, 0xff, sizeof(lrt_hit) * (n ? n : 1));

    /* 2 to 4 threads trace slices while this thread waits */
    active = 2 + rndi(THREADS - 1);
    cuts[0] = 0;
    cuts[active] = n;
    for (k = 1; k < active; ++k) cuts[k] = (rnd() & 7) == 0 ? cuts[k - 1] : (size_t)rnd() % (n + 1); /* some empty */
    for (k = 2; k < active; ++k) { /* sorted */
        int j;
        for (j = k; j > 1 && cuts[j - 1] > cuts[j]; --j) {
            size_t t = cuts[j];
            cuts[j] = cuts[j - 1];
            cuts[j - 1] = t;
        }
    }
    g_pool.bvh = &wd->live;
    g_pool.depth = &m->depth;
    g_pool.rays = wd->rays;
    g_pool.hits = wd->hits;
    g_pool.flags = flags;
    for (k = 0; k < active; ++k) {
        g_pool.slices[k].first = cuts[k];
        g_pool.slices[k].end = cuts[k + 1];
        g_pool.slices[k].result = LRT_ERROR_INVALID_BVH;
    }
    pool_run(active);
    for (k = 0; k < active; ++k)
        if (g_pool.slices[k].result != LRT_SUCCESS) {
            ++g_s.call_failed;
            report("lrt_trace_range: %s", lrt_result_string(g_pool.slices[k].result), f, m, &wd->live);
        }

    /* == one thread's lrt_trace, byte for byte */
    r = lrt_trace(&wd->live, &m->depth, wd->rays, wd->expect, n, flags);
    if (r != LRT_SUCCESS) {
        ++g_s.call_failed;
        report("lrt_trace: %s", lrt_result_string(r), f, m, &wd->live);
    } else if (n && memcmp(wd->hits, wd->expect, sizeof(lrt_hit) * n) != 0) {
        for (i = 0; i < n && !memcmp(&wd->hits[i], &wd->expect[i], sizeof(lrt_hit)); ++i) continue;
        ++g_s.thread_mismatch;
        {
            char what[160];
            snprintf(what, sizeof what, "ray %zu of %zu: threads kind %u t %.9g (%u,%u), one thread kind %u t %.9g (%u,%u)",
                     i, n, wd->hits[i].kind, (double)wd->hits[i].t, wd->hits[i].x, wd->hits[i].y, wd->expect[i].kind,
                     (double)wd->expect[i].t, wd->expect[i].x, wd->expect[i].y);
            report("threaded hits differ from one thread's: %s", what, f, m, &wd->live);
        }
    }

    /* a sample against the exact reference */
    for (k = 0; k < REF_SAMPLE && n; ++k) {
        const size_t q = (size_t)rnd() % n;
        ref_ray rr = ref_ray_of(&wd->rays[q]);
        ref_answer a = to_answer(&wd->hits[q]);
        char why[256], what[420];
        if (!ref_check(&m->ref, &rr, &a, 0 /* closest hit */, why, sizeof why)) {
            ++g_s.ref_mismatch;
            snprintf(what, sizeof what, "flags %u, ray o=(%.9g %.9g %.9g) v=(%.9g %.9g %.9g) t=[%.9g %.9g]: %.250s",
                     flags, rr.o[0], rr.o[1], rr.o[2], rr.v[0], rr.v[1], rr.v[2], rr.tmin, rr.tmax, why);
            report("wrong by the reference: %s", what, f, m, &wd->live);
        }
        ++g_s.ref_checked;
    }
    g_s.rays += n;
    ++g_s.frames;
}

int main(int argc, char **argv)
{
    const double seconds = argc > 1 ? atof(argv[1]) : 60.0;
    const char *seed_env = getenv("SOAK_SEED");
    double start, next_progress;
    world wd;
    if (argc > 2 || !(seconds >= 0.0)) {
        printf("usage: %s [seconds]   (SOAK_SEED=n replays a run)\n", argv[0]);
        return 2;
    }
    g_seed = seed_env && *seed_env ? strtoull(seed_env, NULL, 10) : (unsigned long long)time(NULL);
    g_rng = 0x9e3779b97f4a7c15ull ^ (g_seed * 0x2545f4914f6cdd1dull);
    if (!g_rng) g_rng = 1;
    memset(&wd, 0, sizeof wd);
    wd.rays = (lrt_ray *)malloc(sizeof(lrt_ray) * MAX_RAYS);
    wd.hits = (lrt_hit *)malloc(sizeof(lrt_hit) * MAX_RAYS);
    wd.expect = (lrt_hit *)malloc(sizeof(lrt_hit) * MAX_RAYS);
    if (!wd.rays || !wd.hits || !wd.expect || !pool_start()) {
        printf("soak: set-up failed\n");
        return 2;
    }
    printf("soak: %.0f s, SOAK_SEED=%llu, %d pool threads\n", seconds, g_seed, THREADS);
    fflush(stdout);
    start = now();
    next_progress = start + 10.0;
    while (now() - start < seconds) {
        frame(&wd, g_s.frames);
        if (now() >= next_progress) {
            printf("soak: %3.0f s: %lu frames, %lu maps, %lu rays, %lu mismatches\n", now() - start, g_s.frames,
                   g_s.maps, g_s.rays, mismatches());
            fflush(stdout);
            next_progress += 10.0;
        }
    }
    pool_stop();
    printf("soak: %.1f s, SOAK_SEED=%llu: %lu frames, %lu maps "
           "(largest %ux%u), %lu updates (%lu with a rect, %lu of them empty) each == a rebuild, %lu rays traced on "
           "2-4 threads == one thread, %lu checked against the reference\n",
           now() - start, g_seed, g_s.frames, g_s.maps, g_s.largest_w, g_s.largest_h, g_s.updates, g_s.rect_updates, g_s.empty_rects,
           g_s.rays, g_s.ref_checked);
    printf("soak: mismatches %lu (refit != rebuild %lu, threads != one thread %lu, wrong by the reference %lu, "
           "failed calls %lu)\n",
           mismatches(), g_s.update_mismatch, g_s.thread_mismatch, g_s.ref_mismatch, g_s.call_failed);
    if (wd.have_map) {
        lrt_bvh_destroy(&wd.live);
        free_map(&wd.m);
    }
    free(wd.rays);
    free(wd.hits);
    free(wd.expect);
    return mismatches() ? 1 : 0;
}
