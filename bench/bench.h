/* bench/bench.h - the one interface every method of the benchmark answers to.

   A method (linear_rt on the CPU or on Vulkan, Embree, a ray-query BVH, a
   screen-space march) is a bench_method: it is given a scene (a depth map),
   builds whatever it needs, refits it per frame, and traces batches of
   screen-space rays (docs/MODEL.md's rays: lrt_ray, answers as lrt_hit), timing
   each step itself (CPU: CLOCK_MONOTONIC; Vulkan: GPU timestamps). The
   harness (bench/main.c) owns the scenes, the ray sets, the reference, the
   scoring, the tables and the chart; methods own nothing but themselves.

   A method that cannot run here (a package, a device or an extension is
   missing) says why in `why` and is listed as skipped, never silently left
   out. */
#ifndef LINEAR_RT_BENCH_H
#define LINEAR_RT_BENCH_H

#include <stddef.h>
#include <stdint.h>
#include "../linear_rt.h"

typedef struct bench_scene {
    const char *name;
    uint32_t width, height;
    const float *depth;      /* width*height floats, row 0 first: 0 near, 1 far (already standard Z) */
    lrt_depth lrt;           /* the same map as linear_rt takes it (LRT_FORMAT_FLOAT32, packed) */
    /* thickness (docs/MODEL.md): NULL, or each texel's back depth (a back-face
       pass; texel (i,j)'s box is [depth, max(depth, back)]); a method runs
       such a scene under that model, or says in build() why it cannot */
    const float *back;
    lrt_depth pair[2];       /* with back: lrt with its back pointing at pair[1], the back map */
} bench_scene;

/* What linear_rt takes of a scene: its depth (with the back map after it, for
   a thickness scene) and the thickness model of its tree. */
static inline const lrt_depth *bench_lrt_depth(const bench_scene *sc) { return sc->back ? sc->pair : &sc->lrt; }
static inline uint32_t bench_lrt_thickness(const bench_scene *sc)
{
    return sc->back ? LRT_THICKNESS_BACK_MAP : LRT_THICKNESS_INFINITE;
}

enum { BENCH_ANY_HIT = 1u }; /* bench_rays.flags: occlusion; any hit will do */
/* the finish the benchmark's linear_rt budgets take (budgeted 2): 16 steps, as march16 */
#define BENCH_FINISH LRT_TRACE_FINISH(4)

typedef struct bench_rays {
    const char *name;        /* "primary", "reflection", "ao", "shadow", "segments", ... */
    const lrt_ray *rays;
    size_t count;
    uint32_t flags;          /* BENCH_ANY_HIT */
} bench_rays;

typedef struct bench_method bench_method;
struct bench_method {
    const char *name;        /* short, unique, for tables and the chart: "linear_rt cpu 16", "embree", "march64 cpu" */
    const char *device;      /* "cpu" or "vulkan" */
    int exact;               /* 1: must agree with the reference on every ray (docs/MODEL.md); 0: scored */
    int budgeted;            /* linear_rt with a step budget: 1 scored by docs/MODEL.md's rule, a budget miss wrong;
                                2 with a finish: an estimate and a budget miss (read as the miss the ray's point at
                                tmax tells) scored as the marches' answers are, the rest by that rule */
    void *impl;              /* the method's own state */

    /* Makes the method ready (pipelines, devices), once; width and height
       are the benchmark's size, a hint: build() may later get scenes of any
       size (the stability suite has 3x2 and 2048x2048 maps) and must redo
       whatever depends on the size. 0 on success, else a one-line reason in
       why (the method is then skipped). */
    int (*open)(bench_method *m, uint32_t width, uint32_t height, int threads, char *why, size_t why_size);
    /* Builds its structure for a scene: ms of the build (0 if it has none). */
    int (*build)(bench_method *m, const bench_scene *scene, double *ms, char *why, size_t why_size);
    /* The per-frame step after the depth changed (refit, rebuild, mip chain):
       ms; the scene has the same size as at build. */
    int (*update)(bench_method *m, const bench_scene *scene, double *ms, char *why, size_t why_size);
    /* Traces rays into hits (one lrt_hit per ray: kind, texel, t), on
       `threads` CPU threads where that applies: ms of the trace alone. */
    int (*trace)(bench_method *m, const bench_scene *scene, const bench_rays *rays, lrt_hit *hits, double *ms,
                 char *why, size_t why_size);
    /* Bytes of its acceleration structure for the built scene (0: none). */
    size_t (*memory_bytes)(bench_method *m);
    void (*close)(bench_method *m);
};

/* Sets a method's six functions, which its file names PREFIX_open,
   PREFIX_build, PREFIX_update, PREFIX_trace, PREFIX_memory, PREFIX_close. */
#define BENCH_METHOD_FUNCTIONS(m, prefix)                                                                \
    ((m).open = prefix##_open, (m).build = prefix##_build, (m).update = prefix##_update,             \
     (m).trace = prefix##_trace, (m).memory_bytes = prefix##_memory, (m).close = prefix##_close)

/* The methods, each in its own file; a file whose package is missing still
   defines its adder, and its open() says why it cannot run. Each adds zero
   or more methods to the list and returns how many. */
int bench_add_linear_rt_cpu(bench_method *out, int max);
int bench_add_linear_rt_cpu_native(bench_method *out, int max); /* BENCH_WITH_NATIVE_TWIN builds only */
int bench_add_linear_rt_vulkan(bench_method *out, int max);
int bench_add_embree(bench_method *out, int max);
int bench_add_march_cpu(bench_method *out, int max);
int bench_add_vulkan_peers(bench_method *out, int max); /* ray-query AABB / triangle BVHs, marches on Vulkan */

double bench_now_ms(void);   /* CLOCK_MONOTONIC in ms (bench/clock.c) */

/* GPU traces are timed as batches of back-to-back dispatches of the same
   rays in one submission, about BENCH_GPU_BATCH_MS of GPU time a batch
   (its mean is the trace's time), so that the GPU works in stretches
   rather than in single short dispatches with host work between: under
   those an NVIDIA H200's SM clock stood at its idle 345 MHz of 1980
   (docs/PERFORMANCE.md, the H200; whether batches
   raise it is still to be seen on such a device). A dispatch of one of
   lavapipe's whole sets mostly lasts a batch on its own. */
#define BENCH_GPU_BATCH_MS 10.0
#define BENCH_GPU_BATCH_MAX 64u
typedef struct bench_gpu_batch {
    const void *rays; /* the set the size was chosen for */
    size_t count;
    uint32_t size;    /* dispatches in the next batch */
} bench_gpu_batch;

/* The batch size for `rays` (count of them): 1 for a set not seen last */
static inline uint32_t bench_gpu_batch_size(bench_gpu_batch *b, const void *rays, size_t count)
{
    if (b->rays != rays || b->count != count || !b->size) {
        b->rays = rays;
        b->count = count;
        b->size = 1;
    }
    return b->size;
}

/* After a batch whose dispatches took ms each: enough for the next batch
   to last BENCH_GPU_BATCH_MS, at most BENCH_GPU_BATCH_MAX */
static inline void bench_gpu_batch_timed(bench_gpu_batch *b, double ms)
{
    double n = ms > 0.0 ? BENCH_GPU_BATCH_MS / ms : (double)BENCH_GPU_BATCH_MAX;
    b->size = n >= (double)BENCH_GPU_BATCH_MAX ? BENCH_GPU_BATCH_MAX : n > 1.0 ? (uint32_t)n + 1u : 1u;
}

/* What linear_rt's walk costs per ray on a set (bench/visits.c): node
   tests per ray at level 0 (the one texel of a ray that needs no walk),
   level 1 (a level-1 node's texels) and above (a node's children), and the
   exact tests of texels the level-1 codes let through (as in the kernels),
   by a copy of the library that counts them, on one thread. 0 on success. */
int bench_visits(const bench_scene *scene, const bench_rays *rays, uint32_t node_bits, double per_ray[4]);

/* What thickness costs a scene with a back map (16-bit nodes, one ray at a
   time): each ray traced with the back-map tree and with the infinite tree
   of the same depth, its node tests counted in both. out: [0] % of rays
   answered alike (the same kind, and for a hit the same texel); their node
   tests per ray, [1] thick and [2] infinite; the other rays' [3] thick and
   [4] infinite; [5] the rays answered alike whose two counts differ (0 by
   design: docs/PERFORMANCE.md, "What limits the walk"). 0 on success. */
int bench_visits_thickness(const bench_scene *scene, const bench_rays *rays, double out[6]);

/* What a wave pays (bench/visits.c, bench/wave.c): the steps of each ray
   of a set as the GPU kernels take them, counted on one thread into
   steps[] (rs->count of them). bench_wave_linear_rt: the node tests (any
   level) of a copy of the library that walks as the kernels do (always
   from the origin's level-1 node), and in *texels the exact texel tests of
   the set. bench_wave_march: which 0 the 64-step march (its samples and
   bisection steps), 1 the DDA of stride 1 (its columns), 2 the Hi-Z walk
   capped at 64 (its iterations), as the Vulkan peers run them. 0 on
   success. bench_wave_stats: the mean of steps and the mean over groups of
   `wave` consecutive rays of the group's most. */
int bench_wave_linear_rt(const bench_scene *scene, const bench_rays *rays, uint32_t node_bits, uint32_t *steps, double *texels);
/* bench_wave_cells: the exact ordinary pass's cell walk (one cell or texel
   a step), each hit checked against lrt_trace's (1 where one differs) */
int bench_wave_cells(const bench_scene *scene, const bench_rays *rays, uint32_t node_bits, uint32_t *steps, double *texels);
/* bench_finish_samples: each ray's samples in the finish of a step budget
   (LRT_TRACE_BUDGET(budget) | BENCH_FINISH), 0 where the budget did not stop it */
int bench_finish_samples(const bench_scene *scene, const bench_rays *rays, uint32_t budget, uint32_t *samples);
int bench_wave_march(const bench_scene *scene, const bench_rays *rays, int which, uint32_t *steps);
void bench_wave_stats(const uint32_t *steps, size_t n, uint32_t wave, double *mean, double *wave_mean);
/* bench_wave_march_blocks: of the 64-step march's steps (bench_wave_march,
   which 0, and the rays' answers), the mean over groups of `wave` rays of
   the group's loop trips (samples, bisections aside) and of the number of
   distinct trips in which some lane of the group hit and refined: a wave
   runs the kernel's refinement block once for each of those. */
void bench_wave_march_blocks(const uint32_t *steps, size_t n, uint32_t wave, double *trips, double *refine_trips);
/* bench_wave_exits: for a loop whose lanes leave it from inside (storing
   their answer) at their last step unless they reach the cap, the mean over
   groups of `wave` rays of the group's most steps and of the number of
   distinct steps at which some lane of the group left: a wave runs the
   kernel's exit blocks once for each. */
void bench_wave_exits(const uint32_t *steps, size_t n, uint32_t wave, uint32_t cap, double *trips, double *exit_trips);

#endif
