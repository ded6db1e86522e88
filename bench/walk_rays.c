/* bench/walk_rays.c - the CPU walk on the demo's rays, for bench/walk_ab.sh.

   The demo's workload (examples/demo.c): the embedded scene at --size
   (float depth, 16-bit nodes), one primary ray per texel and one random
   segment per texel from the demo's generator, traced with lrt_trace_range
   on --threads threads, --runs times after a warm-up (--only one of the
   two sets: primary or segments). Prints one line per
   set: "<set> <median M rays/s> <hits>". It uses only what every version of
   the header has had (fields set by name), so that walk_ab.sh can build it
   against an older commit's linear_rt.h: -DLRT_HEADER='"path"'. */
#define _POSIX_C_SOURCE 200809L
#ifndef LRT_HEADER
#define LRT_HEADER "../linear_rt.h"
#endif
#define LINEAR_RT_IMPLEMENTATION
#include LRT_HEADER
#include "../examples/scene.h"
#include "../examples/trace_threads.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* one batch on `threads` threads (at most 16), in equal slices; ms */
static double trace(const lrt_bvh *bvh, const lrt_depth *depth, const lrt_ray *rays, lrt_hit *hits, size_t n,
                    int threads)
{
    double t0 = now_ms();
    if (trace_threads(bvh, depth, rays, hits, n, 0, threads) != LRT_SUCCESS) {
        fprintf(stderr, "walk_rays: lrt_trace_range failed\n");
        exit(1);
    }
    return now_ms() - t0;
}

int main(int argc, char **argv)
{
    int size = 512, threads = 2, runs = 5, only = -1, a, r;
    size_t n, i;
    float *depth_f;
    lrt_ray *prim, *seg;
    lrt_hit *hits;
    lrt_depth depth;
    lrt_bvh bvh;
    scene_camera cam = scene_default_camera();
    for (a = 1; a + 1 < argc; a += 2) {
        if (!strcmp(argv[a], "--size")) size = atoi(argv[a + 1]);
        else if (!strcmp(argv[a], "--threads")) threads = atoi(argv[a + 1]);
        else if (!strcmp(argv[a], "--runs")) runs = atoi(argv[a + 1]);
        else if (!strcmp(argv[a], "--only")) only = !strcmp(argv[a + 1], "segments") ? 1 : !strcmp(argv[a + 1], "primary") ? 0 : 2;
        else break;
    }
    if (a < argc || only == 2 || size < 8 || size > 4096 || threads < 1 || threads > 16 || runs < 1 || runs > 99) {
        fprintf(stderr, "usage: walk_rays [--size N] [--threads T] [--runs R] [--only primary|segments]\n");
        return 2;
    }
    n = (size_t)size * (size_t)size;
    depth_f = (float *)malloc(n * sizeof *depth_f);
    prim = (lrt_ray *)malloc(n * sizeof *prim);
    seg = (lrt_ray *)malloc(n * sizeof *seg);
    hits = (lrt_hit *)malloc(n * sizeof *hits);
    if (!depth_f || !prim || !seg || !hits) return 1;
    memset(hits, 0, n * sizeof *hits);
    scene_render(size, size, &cam, depth_f, NULL);
    memset(&depth, 0, sizeof depth);
    depth.data = depth_f;
    depth.width = depth.height = (uint32_t)size;
    depth.format = LRT_FORMAT_FLOAT32;
    { /* the demo's rays, draw for draw (examples/scene.h) */
        uint64_t rng = SCENE_DEMO_SEED;
        scene_demo_rays(size, depth_f, prim, seg, n, &rng);
    }
    memset(&bvh, 0, sizeof bvh);
    if (lrt_bvh_build(&bvh, &depth, NULL, NULL) != LRT_SUCCESS) return 1;
    for (a = 0; a < 2; ++a) {
        const lrt_ray *rays = a ? seg : prim;
        double ms[99];
        size_t hit_count = 0;
        if (only >= 0 && a != only) continue;
        trace(&bvh, &depth, rays, hits, n, threads); /* warm-up */
        for (r = 0; r < runs; ++r) ms[r] = trace(&bvh, &depth, rays, hits, n, threads);
        qsort(ms, (size_t)runs, sizeof ms[0], cmp_double);
        for (i = 0; i < n; ++i) hit_count += hits[i].kind == LRT_HIT;
        printf("%s %.3f %lu\n", a ? "segments" : "primary", (double)n / ms[runs / 2] / 1e3, (unsigned long)hit_count);
    }
    lrt_bvh_destroy(&bvh);
    free(depth_f);
    free(prim);
    free(seg);
    free(hits);
    return 0;
}
