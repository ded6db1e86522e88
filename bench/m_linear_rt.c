/* bench/m_linear_rt.c - linear_rt itself as benchmark methods: the CPU path
   with 8- and 16-bit nodes (threads by lrt_trace_range), and the Vulkan
   kernels with 8- and 16-bit nodes (GPU timestamps). This file holds the
   library's one implementation for the whole benchmark.
   Compiled a second time with -march=native and BENCH_NATIVE_TWIN (make
   bench-plain-vs-native), it adds the same CPU methods under names ending in
   " native", with a static copy of the library built for this CPU alone: the
   plain build's run-time walk and a native build's, side by side in one run
   (this machine's phases move whole runs by 10-40%, more than the effect). */
#ifdef BENCH_NATIVE_TWIN
#define LINEAR_RT_STATIC
#undef BENCH_HAVE_VULKAN
#define BENCH_NAME_SUFFIX " native"
#else
#define BENCH_NAME_SUFFIX ""
#endif
#ifdef BENCH_HAVE_VULKAN
#define LINEAR_RT_VULKAN
#endif
#define LINEAR_RT_IMPLEMENTATION
#include "bench.h"
#include "../examples/trace_threads.h" /* equal slices on c->threads threads */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef BENCH_HAVE_VULKAN
#include "../linear_rt_vk_util.h"
#endif

/* ---- CPU --------------------------------------------------------------------- */
typedef struct lrt_cpu {
    uint32_t node_bits;
    uint32_t flags; /* trace flags: 0 the exact walk, or a step budget and maybe its finish */
    int threads;
    lrt_bvh bvh;
    int built;
} lrt_cpu;

static int cpu_open(bench_method *m, uint32_t w, uint32_t h, int threads, char *why, size_t n)
{
    lrt_cpu *c = (lrt_cpu *)m->impl;
    (void)w;
    (void)h;
    (void)why;
    (void)n;
    c->threads = threads < 1 ? 1 : threads > TRACE_THREADS_MAX ? TRACE_THREADS_MAX : threads;
    return 0;
}

static int cpu_build(bench_method *m, const bench_scene *sc, double *ms, char *why, size_t n)
{
    lrt_cpu *c = (lrt_cpu *)m->impl;
    lrt_build_options o;
    lrt_result r;
    double t0;
    if (c->built) lrt_bvh_destroy(&c->bvh);
    c->built = 0;
    memset(&o, 0, sizeof o);
    o.node_bits = c->node_bits;
    o.thickness = bench_lrt_thickness(sc);
    t0 = bench_now_ms();
    r = lrt_bvh_build(&c->bvh, bench_lrt_depth(sc), &o, NULL);
    *ms = bench_now_ms() - t0;
    if (r != LRT_SUCCESS) {
        snprintf(why, n, "lrt_bvh_build: %s", lrt_result_string(r));
        return 1;
    }
    c->built = 1;
    return 0;
}

static int cpu_update(bench_method *m, const bench_scene *sc, double *ms, char *why, size_t n)
{
    lrt_cpu *c = (lrt_cpu *)m->impl;
    double t0 = bench_now_ms();
    lrt_result r = lrt_bvh_update(&c->bvh, bench_lrt_depth(sc), NULL);
    *ms = bench_now_ms() - t0;
    if (r != LRT_SUCCESS) {
        snprintf(why, n, "lrt_bvh_update: %s", lrt_result_string(r));
        return 1;
    }
    return 0;
}

static int cpu_trace(bench_method *m, const bench_scene *sc, const bench_rays *rs, lrt_hit *hits, double *ms,
                     char *why, size_t n)
{
    lrt_cpu *c = (lrt_cpu *)m->impl;
    double t0 = bench_now_ms(); /* closest hit for every set: the first hit the walk finds is the closest */
    lrt_result r = trace_threads(&c->bvh, bench_lrt_depth(sc), rs->rays, hits, rs->count, c->flags, c->threads);
    *ms = bench_now_ms() - t0;
    if (r != LRT_SUCCESS) {
        snprintf(why, n, "lrt_trace_range: %s", lrt_result_string(r));
        return 1;
    }
    return 0;
}

static size_t cpu_memory(bench_method *m) { return ((lrt_cpu *)m->impl)->bvh.layout.bytes; }

static void cpu_close(bench_method *m)
{
    lrt_cpu *c = (lrt_cpu *)m->impl;
    if (c->built) lrt_bvh_destroy(&c->bvh);
    free(c);
    m->impl = NULL;
}

#ifdef BENCH_NATIVE_TWIN
int bench_add_linear_rt_cpu_native(bench_method *out, int max)
#else
int bench_add_linear_rt_cpu(bench_method *out, int max)
#endif
{
    /* the exact walk with 16- and 8-bit nodes, then 16-bit nodes at a ladder of step budgets, without and with a
       finish of 16 steps (BENCH_FINISH) */
    static const char *names[10] = {
        "linear_rt cpu 16" BENCH_NAME_SUFFIX,           "linear_rt cpu 8" BENCH_NAME_SUFFIX,
        "linear_rt cpu 16 budget 4" BENCH_NAME_SUFFIX,  "linear_rt cpu 16 budget 8" BENCH_NAME_SUFFIX,
        "linear_rt cpu 16 budget 16" BENCH_NAME_SUFFIX, "linear_rt cpu 16 budget 32" BENCH_NAME_SUFFIX,
        "linear_rt cpu 16 budget 4 finish 16" BENCH_NAME_SUFFIX,  "linear_rt cpu 16 budget 8 finish 16" BENCH_NAME_SUFFIX,
        "linear_rt cpu 16 budget 16 finish 16" BENCH_NAME_SUFFIX, "linear_rt cpu 16 budget 32 finish 16" BENCH_NAME_SUFFIX};
    int i;
    for (i = 0; i < 10 && i < max; ++i) {
        lrt_cpu *c = (lrt_cpu *)calloc(1, sizeof *c);
        memset(&out[i], 0, sizeof out[i]);
        if (!c) return i;
        c->node_bits = i == 1 ? 8u : 16u;
        c->flags = i < 2 ? 0u : LRT_TRACE_BUDGET(4u << ((i - 2) % 4)) | (i >= 6 ? BENCH_FINISH : 0u);
        out[i].name = names[i];
        out[i].device = "cpu";
        out[i].exact = i < 2;
        out[i].budgeted = i >= 6 ? 2 : i >= 2;
        out[i].impl = c;
        BENCH_METHOD_FUNCTIONS(out[i], cpu);
    }
    return i;
}

/* ---- Vulkan ------------------------------------------------------------------ */
#ifdef BENCH_HAVE_VULKAN
typedef struct lrt_gpu {
    uint32_t node_bits;
    uint32_t flags; /* trace flags: 0 the exact walk, or a step budget and maybe its finish */
    int compacted;   /* lrt_vk_cmd_trace_compacted, in a context of two passes (a CPU device's too) */
    lrt_vku_device dev;
    lrt_vku t;
    lrt_vk_context *ctx;
    lrt_vk_bvh bvh;
    lrt_vku_buffer depth, rays, hits, scratch;
    VkQueryPool pool;
    double period_ns;
    int has_dev, has_t, has_bvh, has_depth;
    size_t ray_cap;
    bench_gpu_batch batch;
} lrt_gpu;

static void gpu_release(lrt_gpu *g)
{
    if (g->has_t) {
        g->t.vkDeviceWaitIdle(g->t.device);
        if (g->rays.buffer) lrt_vku_buffer_destroy(&g->t, &g->rays);
        if (g->hits.buffer) lrt_vku_buffer_destroy(&g->t, &g->hits);
        if (g->scratch.buffer) lrt_vku_buffer_destroy(&g->t, &g->scratch);
        if (g->has_depth) lrt_vku_buffer_destroy(&g->t, &g->depth);
        if (g->pool) g->t.vkDestroyQueryPool(g->t.device, g->pool, NULL);
    }
    if (g->has_bvh) lrt_vk_bvh_destroy(g->ctx, &g->bvh);
    if (g->ctx) lrt_vk_context_destroy(g->ctx);
    if (g->has_t) lrt_vku_free(&g->t);
    if (g->has_dev) lrt_vku_device_destroy(&g->dev);
    memset(g, 0, sizeof *g);
}

static int gpu_open(bench_method *m, uint32_t w, uint32_t h, int threads, char *why, size_t n)
{
    lrt_gpu *g = (lrt_gpu *)m->impl;
    uint32_t bits = g->node_bits, flags = g->flags;
    int compacted = g->compacted;
    VkQueryPoolCreateInfo qi;
    lrt_result r;
    (void)w;
    (void)h;
    (void)threads;
    if (g->has_dev) return 0;
    gpu_release(g);
    g->node_bits = bits;
    g->flags = flags;
    g->compacted = compacted;
    if ((r = lrt_vku_device_create(&g->dev, 0)) != LRT_SUCCESS) {
        snprintf(why, n, "no Vulkan device: %s", lrt_result_string(r));
        return 1;
    }
    g->has_dev = 1;
    if (compacted) g->dev.desc.flags = LRT_VK_TRACE_TWO_PASSES;
    if ((r = lrt_vk_context_create(&g->dev.desc, &g->ctx)) != LRT_SUCCESS || lrt_vku_init(&g->t, &g->dev)) {
        snprintf(why, n, "linear_rt Vulkan context: %s", lrt_result_string(r));
        return 1;
    }
    g->has_t = 1;
    if (!g->dev.timestamp_valid_bits) {
        snprintf(why, n, "the queue has no timestamps");
        return 1;
    }
    memset(&qi, 0, sizeof qi);
    qi.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
    qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qi.queryCount = 2;
    if (g->t.vkCreateQueryPool(g->t.device, &qi, NULL, &g->pool) != VK_SUCCESS) {
        snprintf(why, n, "vkCreateQueryPool failed");
        return 1;
    }
    g->period_ns = (double)g->dev.properties.limits.timestampPeriod;
    return 0;
}

/* the depth, and with thickness its back map right after it in the same buffer */
static void gpu_depth(const lrt_gpu *g, const bench_scene *sc, lrt_vk_depth d[2])
{
    memset(d, 0, 2 * sizeof *d);
    d[0].format = LRT_FORMAT_FLOAT32;
    d[0].width = sc->width;
    d[0].height = sc->height;
    d[0].buffer = g->depth.buffer;
    if (sc->back) {
        d[1] = d[0];
        d[1].offset = (VkDeviceSize)sc->width * sc->height * 4u;
        d[0].back = &d[1];
    }
}

/* One submission around one recorded command (a trace: `repeat` of them,
   back to back), timed by two timestamps: ms of one. */
typedef enum { GPU_BUILD, GPU_UPDATE, GPU_TRACE } gpu_op;

static int gpu_run(lrt_gpu *g, const bench_scene *sc, gpu_op op, uint32_t count, uint32_t repeat, double *ms,
                   char *why, size_t n)
{
    lrt_vk_depth d[2];
    uint64_t ts[2];
    lrt_result r = LRT_SUCCESS;
    uint32_t i;
    gpu_depth(g, sc, d);
    if (lrt_vku_begin(&g->t)) {
        snprintf(why, n, "vkBeginCommandBuffer failed");
        return 1;
    }
    lrt_vku_compute_barrier(&g->t); /* the last submission's commands -> this one */
    g->t.vkCmdResetQueryPool(g->t.cmd, g->pool, 0, 2);
    g->t.vkCmdWriteTimestamp(g->t.cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, g->pool, 0);
    if (op == GPU_BUILD) r = lrt_vk_cmd_build(g->ctx, g->t.cmd, &g->bvh, d);
    else if (op == GPU_UPDATE) r = lrt_vk_cmd_update(g->ctx, g->t.cmd, &g->bvh, d, NULL);
    else
        for (i = 0; i < repeat && r == LRT_SUCCESS; ++i) {
            if (i) lrt_vku_compute_barrier(&g->t); /* the same hits written again */
            if (g->compacted) {
                lrt_vk_scratch sc;
                sc.buffer = g->scratch.buffer;
                sc.offset = 0;
                sc.size = g->scratch.size;
                r = lrt_vk_cmd_trace_compacted(g->ctx, g->t.cmd, &g->bvh, d, g->rays.buffer, 0, g->hits.buffer, 0,
                                               count, g->flags, &sc);
            } else {
                r = lrt_vk_cmd_trace(g->ctx, g->t.cmd, &g->bvh, d, g->rays.buffer, 0, g->hits.buffer, 0, count, g->flags);
            }
        }
    g->t.vkCmdWriteTimestamp(g->t.cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, g->pool, 1);
    lrt_vku_host_barrier(&g->t);
    if (r != LRT_SUCCESS || lrt_vku_submit(&g->t) ||
        g->t.vkGetQueryPoolResults(g->t.device, g->pool, 0, 2, sizeof ts, ts, sizeof ts[0],
                                   VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT) != VK_SUCCESS) {
        snprintf(why, n, "recording or submitting failed: %s", lrt_result_string(r));
        return 1;
    }
    *ms = (double)(ts[1] - ts[0]) * g->period_ns * 1e-6 / (op == GPU_TRACE ? repeat : 1u);
    return 0;
}

static int gpu_build(bench_method *m, const bench_scene *sc, double *ms, char *why, size_t n)
{
    lrt_gpu *g = (lrt_gpu *)m->impl;
    lrt_vk_bvh_desc bd;
    lrt_result r;
    const size_t map_bytes = (size_t)sc->width * sc->height * 4u, bytes = (sc->back ? 2u : 1u) * map_bytes + 4u;
    if (g->has_bvh) lrt_vk_bvh_destroy(g->ctx, &g->bvh);
    if (g->has_depth) lrt_vku_buffer_destroy(&g->t, &g->depth);
    g->has_bvh = g->has_depth = 0;
    memset(&bd, 0, sizeof bd);
    bd.width = sc->width;
    bd.height = sc->height;
    bd.format = LRT_FORMAT_FLOAT32;
    bd.options.node_bits = g->node_bits;
    bd.options.thickness = bench_lrt_thickness(sc);
    if ((r = lrt_vk_bvh_create(g->ctx, &bd, &g->bvh)) != LRT_SUCCESS) {
        snprintf(why, n, "lrt_vk_bvh_create: %s", lrt_result_string(r));
        return 1;
    }
    g->has_bvh = 1;
    /* device-local where it can also be mapped, as the peers' buffers (m_vk_peers.c):
       a discrete GPU reads host memory over PCIe */
    if (lrt_vku_buffer_create_in(&g->t, bytes, 1, &g->depth)) {
        snprintf(why, n, "depth buffer");
        return 1;
    }
    g->has_depth = 1;
    memcpy(g->depth.map, sc->depth, map_bytes);
    if (sc->back) memcpy((unsigned char *)g->depth.map + map_bytes, sc->back, map_bytes);
    return gpu_run(g, sc, GPU_BUILD, 0, 1, ms, why, n);
}

static int gpu_update(bench_method *m, const bench_scene *sc, double *ms, char *why, size_t n)
{
    lrt_gpu *g = (lrt_gpu *)m->impl;
    const size_t map_bytes = (size_t)sc->width * sc->height * 4u;
    memcpy(g->depth.map, sc->depth, map_bytes);
    if (sc->back) memcpy((unsigned char *)g->depth.map + map_bytes, sc->back, map_bytes);
    return gpu_run(g, sc, GPU_UPDATE, 0, 1, ms, why, n);
}

static int gpu_trace(bench_method *m, const bench_scene *sc, const bench_rays *rs, lrt_hit *hits, double *ms,
                     char *why, size_t n)
{
    lrt_gpu *g = (lrt_gpu *)m->impl;
    if (rs->count > 0xffffffffu) {
        snprintf(why, n, "too many rays for one dispatch");
        return 1;
    }
    if (rs->count > g->ray_cap) {
        if (g->rays.buffer) lrt_vku_buffer_destroy(&g->t, &g->rays);
        if (g->hits.buffer) lrt_vku_buffer_destroy(&g->t, &g->hits);
        if (g->scratch.buffer) lrt_vku_buffer_destroy(&g->t, &g->scratch);
        memset(&g->rays, 0, sizeof g->rays);
        memset(&g->hits, 0, sizeof g->hits);
        memset(&g->scratch, 0, sizeof g->scratch);
        g->ray_cap = 0;
        if (lrt_vku_buffer_create_in(&g->t, rs->count * sizeof(lrt_ray), 1, &g->rays) ||
            lrt_vku_buffer_create_in(&g->t, rs->count * sizeof(lrt_hit), 1, &g->hits) ||
            (g->compacted &&
             lrt_vku_buffer_create_in(&g->t, lrt_vk_trace_scratch_size((uint32_t)rs->count), 1, &g->scratch))) {
            snprintf(why, n, "ray buffers");
            return 1;
        }
        g->ray_cap = rs->count;
    }
    memcpy(g->rays.map, rs->rays, rs->count * sizeof(lrt_ray));
    if (gpu_run(g, sc, GPU_TRACE, (uint32_t)rs->count, bench_gpu_batch_size(&g->batch, rs->rays, rs->count), ms, why, n))
        return 1;
    bench_gpu_batch_timed(&g->batch, *ms);
    memcpy(hits, g->hits.map, rs->count * sizeof(lrt_hit));
    return 0;
}

static size_t gpu_memory(bench_method *m) { return ((lrt_gpu *)m->impl)->bvh.layout.bytes; }

static void gpu_close(bench_method *m)
{
    gpu_release((lrt_gpu *)m->impl);
    free(m->impl);
    m->impl = NULL;
}
#endif

#ifndef BENCH_NATIVE_TWIN
int bench_add_linear_rt_vulkan(bench_method *out, int max)
{
    /* the last: compacted rounds, which a GPU context runs and a CPU device's (lavapipe: one pass)
       does not, run here in a context of two passes to measure them */
    static const char *names[11] = {"linear_rt vulkan 16",
                                    "linear_rt vulkan 8",
                                    "linear_rt vulkan 16 budget 4",
                                    "linear_rt vulkan 16 budget 8",
                                    "linear_rt vulkan 16 budget 16",
                                    "linear_rt vulkan 16 budget 32",
                                    "linear_rt vulkan 16 compacted",
                                    "linear_rt vulkan 16 budget 4 finish 16",
                                    "linear_rt vulkan 16 budget 8 finish 16",
                                    "linear_rt vulkan 16 budget 16 finish 16",
                                    "linear_rt vulkan 16 budget 32 finish 16"};
    int i;
    for (i = 0; i < 11 && i < max; ++i) {
        memset(&out[i], 0, sizeof out[i]);
        out[i].name = names[i];
        out[i].device = "vulkan";
        out[i].exact = i < 2 || i == 6;
        out[i].budgeted = i >= 7 ? 2 : i >= 2 && i < 6;
#ifdef BENCH_HAVE_VULKAN
        {
            lrt_gpu *g = (lrt_gpu *)calloc(1, sizeof *g);
            if (!g) return i;
            g->node_bits = i == 1 ? 8u : 16u;
            g->flags = i < 2 || i == 6 ? 0u : LRT_TRACE_BUDGET(4u << (i >= 7 ? i - 7 : i - 2)) | (i >= 7 ? BENCH_FINISH : 0u);
            g->compacted = i == 6;
            out[i].impl = g;
            BENCH_METHOD_FUNCTIONS(out[i], gpu);
        }
#endif
    }
    return i;
}
#endif /* BENCH_NATIVE_TWIN */
