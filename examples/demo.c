/* examples/demo.c - the design's headline workload on the CPU path of
   linear_rt.h, timed, and its answers checked: on 1 and 2 threads alike,
   and on the GPU the CPU's bit for bit.

   On the embedded scene (examples/scene.h, float32 depth, default 1024x1024):
   - BVH build, whole-map update and memory, with 16-bit and 8-bit nodes;
   - primary rays (one per texel, straight into the depth) on 1 and 2
     threads, and update + trace, the design's headline figure;
   - reflection-like random segments (one per texel) on 1 and 2 threads;
   - with --dump FILE, the map, both sets of rays and the CPU's hits into
     FILE, for a judge: make test-demo holds every primary ray and a fixed
     sample of the segments to the tests' exact reference tracer
     (docs/MODEL.md's "Right, and how right").
   - built with LINEAR_RT_VULKAN (make demo does where <vulkan/vulkan.h> is
     installed): the same map on the first Vulkan device (lavapipe on a
     machine with no GPU): build once, then update + primary trace, GPU
     timestamps of the two dispatches side by side with the CPU's, and the
     GPU hits held to the CPU hits bit for bit (t, texel, kind and face);
     also the segments. No device:
     the demo says why and shows the CPU table alone.
   Then the pictures, into out/ (examples/ssr.c, ao.c and shadows.c, and the
   classic 64-step linear march of examples/march.h): the scene's
   colour and depth, reflections traced with linear_rt and the same rays
   marched in 64 steps, side by side, ambient occlusion and contact shadows;
   each with its time, and the share of reflection rays on which the march
   agrees with linear_rt (same hit texel, or both miss).
   Exits 0 if every check passes (and --dump wrote its file), 1 otherwise
   (2: bad arguments or file).

   make demo              (builds build/demo with -O3 and runs it)
   build/demo --size 128  (a smaller map)
   build/demo --no-gpu    (the CPU path alone)
   build/demo --depth FILE [--color FILE] [--fov DEG --near N --far F] [--reversed-z]
                          (the pictures from your own frame; the timings stay on the scene)
   build/demo --out DIR   (where the pictures go; default out/)
   build/demo --dump FILE (also the map, rays and CPU hits into FILE) */
#define _POSIX_C_SOURCE 200809L

#include "example.h" /* linear_rt.h's implementation, the frame, PNG out */
#include "scene.h"
#include "march.h" /* the classic march, for the side-by-side picture */
#define EXAMPLE_NO_MAIN
#include "ssr.c"
#include "ao.c"
#include "shadows.c"
#include "trace_threads.h" /* the timed traces: 1 or 2 threads, each a half of the batch */
#ifdef LINEAR_RT_VULKAN
#include "../linear_rt_vk_util.h" /* the device, buffers, one command buffer, submit and wait, barriers, timestamps */
#endif

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef DEMO_CFLAGS
#define DEMO_CFLAGS "(not given: build with make demo)"
#endif

#define BUILD_RUNS 5   /* timed runs after one warm-up */
#define UPDATE_RUNS 9
#define TRACE_RUNS 5

/* ---- timing (example_now_ms: CLOCK_MONOTONIC) --------------------------------- */
static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y ? 1 : 0;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return (n & 1) ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static void must(lrt_result r, const char *what)
{
    if (r != LRT_SUCCESS) {
        fprintf(stderr, "%s: %s\n", what, lrt_result_string(r));
        exit(1);
    }
}

/* Median ms of TRACE_RUNS traces after a warm-up; with_update: each timed run
   is a whole-map update followed by the trace. */
static double time_trace(lrt_bvh *bvh, const lrt_depth *depth, const lrt_ray *rays,
                         lrt_hit *hits, size_t count, int threads, int with_update)
{
    double ms[TRACE_RUNS];
    int k;
    if (with_update) must(lrt_bvh_update(bvh, depth, NULL), "lrt_bvh_update");
    must(trace_threads(bvh, depth, rays, hits, count, 0, threads), "lrt_trace_range");
    for (k = 0; k < TRACE_RUNS; ++k) {
        double t0 = example_now_ms();
        if (with_update) must(lrt_bvh_update(bvh, depth, NULL), "lrt_bvh_update");
        must(trace_threads(bvh, depth, rays, hits, count, 0, threads), "lrt_trace_range");
        ms[k] = example_now_ms() - t0;
    }
    return median(ms, TRACE_RUNS);
}

typedef struct bvh_stats { double build_ms, update_ms, bytes_per_texel; } bvh_stats;

static bvh_stats measure_bvh(const lrt_depth *depth, uint32_t node_bits, lrt_bvh *keep)
{
    bvh_stats s;
    lrt_build_options opt;
    lrt_bvh bvh = {0};
    double ms[UPDATE_RUNS];
    int k;
    memset(&opt, 0, sizeof opt);
    opt.node_bits = node_bits;
    for (k = -1; k < BUILD_RUNS; ++k) { /* k = -1: warm-up */
        double t0 = example_now_ms();
        must(lrt_bvh_build(&bvh, depth, &opt, NULL), "lrt_bvh_build");
        if (k >= 0) ms[k] = example_now_ms() - t0;
        lrt_bvh_destroy(&bvh);
    }
    s.build_ms = median(ms, BUILD_RUNS);
    must(lrt_bvh_build(&bvh, depth, &opt, NULL), "lrt_bvh_build");
    must(lrt_bvh_update(&bvh, depth, NULL), "lrt_bvh_update"); /* warm-up */
    for (k = 0; k < UPDATE_RUNS; ++k) {
        double t0 = example_now_ms();
        must(lrt_bvh_update(&bvh, depth, NULL), "lrt_bvh_update");
        ms[k] = example_now_ms() - t0;
    }
    s.update_ms = median(ms, UPDATE_RUNS);
    s.bytes_per_texel = (double)bvh.layout.bytes / ((double)depth->width * (double)depth->height);
    if (keep) *keep = bvh;
    else lrt_bvh_destroy(&bvh);
    return s;
}

/* ---- the answers, for a judge (--dump) ------------------------------------------ */
/* FILE: the 8 bytes "LRTDEMO1"; uint32 width, height, sizeof(lrt_ray) and
   sizeof(lrt_hit), in this machine's byte order; the depth (width * height
   floats, row 0 first); the primary rays, then their CPU hits; the
   segments, then their CPU hits (width * height of each). 0 on success. */
static int dump_answers(const char *path, const lrt_depth *depth, const lrt_ray *prim, const lrt_hit *prim_hits,
                        const lrt_ray *seg, const lrt_hit *seg_hits)
{
    const uint32_t head[4] = {depth->width, depth->height, (uint32_t)sizeof(lrt_ray), (uint32_t)sizeof(lrt_hit)};
    const size_t n = (size_t)depth->width * depth->height;
    FILE *f = fopen(path, "wb");
    int bad;
    if (!f) {
        fprintf(stderr, "--dump: cannot write %s\n", path);
        return 1;
    }
    bad = fwrite("LRTDEMO1", 1, 8, f) != 8 || fwrite(head, sizeof head, 1, f) != 1 ||
          fwrite(depth->data, sizeof(float), n, f) != n || fwrite(prim, sizeof *prim, n, f) != n ||
          fwrite(prim_hits, sizeof *prim_hits, n, f) != n || fwrite(seg, sizeof *seg, n, f) != n ||
          fwrite(seg_hits, sizeof *seg_hits, n, f) != n;
    if (fclose(f) != 0) bad = 1;
    if (bad) fprintf(stderr, "--dump: writing %s failed\n", path);
    else printf("answers: the map, %lu primary rays and %lu segments with the CPU's hits, into %s\n", (unsigned long)n,
                (unsigned long)n, path);
    return bad;
}

static size_t count_hits(const lrt_hit *hits, size_t count)
{
    size_t k, n = 0;
    for (k = 0; k < count; ++k) n += hits[k].kind == LRT_HIT;
    return n;
}

/* ---- the same workload on Vulkan ---------------------------------------------- */
#define GPU_RUNS 9 /* timed runs after one warm-up */
typedef struct gpu_run {
    int ran;                    /* 0: not run, why says why */
    char why[200];
    char device[320];           /* the device's name (VK_MAX_PHYSICAL_DEVICE_NAME_SIZE: 256) and version */
    double update_ms, prim_ms, seg_ms; /* GPU timestamps: medians */
    int timed;
    size_t prim_same, seg_same; /* equal to the CPU's, bit for bit */
} gpu_run;

#ifdef LINEAR_RT_VULKAN

/* The same answer, bit for bit: t, texel, kind and face (the kernels follow
   the CPU step by step in float). */
static int same_hit(const lrt_hit *a, const lrt_hit *b)
{
    return memcmp(&a->t, &b->t, sizeof a->t) == 0 && a->x == b->x && a->y == b->y && a->kind == b->kind &&
           a->face == b->face;
}

/* Counts the GPU hits equal to the CPU's, and shows the first few that are not. */
static size_t count_same(const lrt_hit *gpu, const lrt_hit *cpu, size_t n, const char *what)
{
    size_t i, same = 0;
    for (i = 0; i < n; ++i) {
        if (same_hit(&gpu[i], &cpu[i])) {
            ++same;
        } else if (i - same < 3) {
            printf("  DIFFER %s ray %lu: GPU t %.9g (%u, %u) kind %u face %u, CPU t %.9g (%u, %u) kind %u face %u\n",
                   what, (unsigned long)i, (double)gpu[i].t, gpu[i].x, gpu[i].y, gpu[i].kind, gpu[i].face,
                   (double)cpu[i].t, cpu[i].x, cpu[i].y, cpu[i].kind, cpu[i].face);
        }
    }
    return same;
}

/* compute writes (a build, update or trace) -> the next linear_rt command,
   a build's counter fill included (linear_rt.h's BARRIERS) */
static void compute_barrier(lrt_vku *t)
{
    lrt_vku_barrier(t, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
}

/* One submission: [update] + trace, timestamps around each; the
   dispatches' milliseconds where the queue has timestamps. */
static int gpu_frame(lrt_vku *t, lrt_vk_context *ctx, lrt_vk_bvh *bvh, const lrt_vk_depth *depth,
                     const lrt_vku_buffer *rays, const lrt_vku_buffer *hits, uint32_t n, int with_update,
                     double *update_ms, double *trace_ms)
{
    double ms[LRT_VKU_TIMESTAMPS - 1];
    if (lrt_vku_begin(t)) return 1;
    compute_barrier(t); /* the previous submission's build, update or trace -> this one */
    lrt_vku_timestamp(t, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, 0);
    if (with_update) {
        must(lrt_vk_cmd_update(ctx, t->cmd, bvh, depth, NULL), "lrt_vk_cmd_update");
        compute_barrier(t); /* update -> trace on the tree */
    }
    lrt_vku_timestamp(t, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 1);
    must(lrt_vk_cmd_trace(ctx, t->cmd, bvh, depth, rays->buffer, 0, hits->buffer, 0, n, 0), "lrt_vk_cmd_trace");
    lrt_vku_timestamp(t, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 2);
    /* trace -> the hits read on the host */
    lrt_vku_barrier(t, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                VK_ACCESS_HOST_READ_BIT);
    if (lrt_vku_submit(t)) return 1;
    if (t->queries) {
        if (lrt_vku_timestamps_ms(t, ms)) return 1;
        *update_ms = ms[0];
        *trace_ms = ms[1];
    }
    return 0;
}

static void run_vulkan(gpu_run *g, const lrt_depth *depth, const lrt_ray *prim, const lrt_hit *prim_cpu,
                       const lrt_ray *seg, const lrt_hit *seg_cpu, size_t n)
{
    static lrt_vku_device dev; /* stays put while it lives */
    lrt_vk_context *ctx = NULL;
    lrt_vk_bvh bvh = {0};
    lrt_vk_bvh_desc bd;
    lrt_vk_depth vd;
    lrt_vku t;
    lrt_vku_buffer db, rb, hb, sb, shb;
    const size_t depth_bytes = (size_t)depth->width * depth->height * 4u;
    double upd[GPU_RUNS], tr[GPU_RUNS], sg[GPU_RUNS];
    lrt_result r;
    int k;
    memset(g, 0, sizeof *g);
    memset(&t, 0, sizeof t);
    memset(&bvh, 0, sizeof bvh);
    memset(&db, 0, sizeof db); /* what was never made is not destroyed */
    rb = hb = sb = shb = db;
    r = lrt_vku_device_create(&dev, 0);
    if (r != LRT_SUCCESS) {
        snprintf(g->why, sizeof g->why, "lrt_vku_device_create: %s", lrt_result_string(r));
        return;
    }
    snprintf(g->device, sizeof g->device, "%s, Vulkan %u.%u.%u", dev.properties.deviceName,
             VK_API_VERSION_MAJOR(dev.properties.apiVersion), VK_API_VERSION_MINOR(dev.properties.apiVersion),
             VK_API_VERSION_PATCH(dev.properties.apiVersion));
    if ((r = lrt_vk_context_create(&dev.desc, &ctx)) != LRT_SUCCESS || lrt_vku_init(&t, &dev)) {
        snprintf(g->why, sizeof g->why, "Vulkan set-up failed: %s", lrt_result_string(r));
        lrt_vku_free(&t);
        lrt_vk_context_destroy(ctx);
        lrt_vku_device_destroy(&dev);
        return;
    }
    if (n > 0xffffffffu || lrt_vku_buffer_create_in(&t, depth_bytes, 1, &db) || lrt_vku_buffer_create_in(&t, n * sizeof *prim, 1, &rb) ||
        lrt_vku_buffer_create_in(&t, n * sizeof *seg, 1, &sb) || lrt_vku_buffer_create_in(&t, n * sizeof(lrt_hit), 1, &hb) ||
        lrt_vku_buffer_create_in(&t, n * sizeof(lrt_hit), 1, &shb)) {
        snprintf(g->why, sizeof g->why, "Vulkan buffers could not be made");
        goto done;
    }
    memcpy(db.map, depth->data, depth_bytes);
    memcpy(rb.map, prim, n * sizeof *prim);
    memcpy(sb.map, seg, n * sizeof *seg);
    memset(&vd, 0, sizeof vd);
    vd.format = depth->format;
    vd.width = depth->width;
    vd.height = depth->height;
    vd.buffer = db.buffer;
    memset(&bd, 0, sizeof bd);
    bd.width = depth->width;
    bd.height = depth->height;
    bd.format = depth->format;
    bd.depth_flags = depth->flags;
    if ((r = lrt_vk_bvh_create(ctx, &bd, &bvh)) != LRT_SUCCESS) {
        snprintf(g->why, sizeof g->why, "lrt_vk_bvh_create: %s", lrt_result_string(r));
        goto done;
    }
    g->timed = t.queries != VK_NULL_HANDLE;
    /* build once (the host wrote the depth before the submission) */
    if (lrt_vku_begin(&t)) goto done;
    must(lrt_vk_cmd_build(ctx, t.cmd, &bvh, &vd), "lrt_vk_cmd_build");
    compute_barrier(&t);
    if (lrt_vku_submit(&t)) goto done;
    for (k = -1; k < GPU_RUNS; ++k) { /* k = -1: warm-up */
        double u = 0, p = 0, s_ = 0, dummy = 0;
        if (gpu_frame(&t, ctx, &bvh, &vd, &rb, &hb, (uint32_t)n, 1, &u, &p) ||
            gpu_frame(&t, ctx, &bvh, &vd, &sb, &shb, (uint32_t)n, 0, &dummy, &s_))
            goto done;
        if (k >= 0) {
            upd[k] = u;
            tr[k] = p;
            sg[k] = s_;
        }
    }
    g->update_ms = median(upd, GPU_RUNS);
    g->prim_ms = median(tr, GPU_RUNS);
    g->seg_ms = median(sg, GPU_RUNS);
    g->prim_same = count_same((const lrt_hit *)hb.map, prim_cpu, n, "primary");
    g->seg_same = count_same((const lrt_hit *)shb.map, seg_cpu, n, "segment");
    g->ran = 1;
done:
    lrt_vk_bvh_destroy(ctx, &bvh);
    if (t.device) {
        lrt_vku_buffer_destroy(&t, &db);
        lrt_vku_buffer_destroy(&t, &rb);
        lrt_vku_buffer_destroy(&t, &sb);
        lrt_vku_buffer_destroy(&t, &hb);
        lrt_vku_buffer_destroy(&t, &shb);
    }
    lrt_vku_free(&t);
    lrt_vk_context_destroy(ctx);
    lrt_vku_device_destroy(&dev);
    if (!g->ran && !g->why[0]) snprintf(g->why, sizeof g->why, "a Vulkan call failed (see above)");
}
#endif

static void usage(const char *argv0)
{
    fprintf(stderr, "usage: %s [--no-gpu] [--no-pictures] [--dump FILE] %s\n   (N in 1..%u, default 1024)\n", argv0,
            example_options_usage(), (unsigned)LINEAR_RT_MAX_DIM);
}

/* The classic 64-step march (march.h) on the same rays, row by row: what an
   engine would write instead. It reads the depth alone (no thickness). */
#define DEMO_MARCH_STEPS 64
typedef struct march_rows {
    march_map map;
    const lrt_ray *rays;
    lrt_hit *hits;
} march_rows;

static void march_row(void *ctx, uint32_t j)
{
    const march_rows *q = (const march_rows *)ctx;
    size_t k, first = (size_t)j * q->map.w;
    for (k = first; k < first + q->map.w; ++k) march_linear(&q->map, DEMO_MARCH_STEPS, &q->rays[k], &q->hits[k]);
}

static void march64_trace(const example_frame *f, const lrt_ray *rays, lrt_hit *hits, int threads, double *ms)
{
    march_rows q;
    double t0;
    q.map.depth = f->depth;
    q.map.back = NULL;
    q.map.w = f->w;
    q.map.h = f->h;
    q.rays = rays;
    q.hits = hits;
    t0 = example_now_ms();
    example_parallel_rows(f->h, threads, "reflections, 64-step march", march_row, &q);
    *ms = example_now_ms() - t0;
}

/* The pictures of the frame (the scene, or the user's files) into o->out_dir. */
static int pictures(const example_options *o)
{
    example_frame f;
    size_t n, k, agree = 0, traced = 0;
    lrt_ray *rays = NULL, *ao_rays = NULL;
    lrt_hit *hits = NULL, *march_hits = NULL, *ao_hits = NULL;
    uint8_t *img = NULL, *img2 = NULL, *both = NULL;
    float *occ = NULL;
    double t0, ms_ssr, ms_march = 0.0, ms_ao, ms_sh;
    int rc, bad = 0;
    uint32_t j;
    t0 = example_now_ms();
    if ((rc = example_frame_load(&f, o)) != EXAMPLE_EXIT_OK) return rc;
    printf("pictures: %s %ux%u, into %s/ (%d threads; frame set-up and BVH build %.1f ms)\n",
           o->depth_file ? o->depth_file : "the embedded scene", f.w, f.h, o->out_dir, o->threads,
           example_now_ms() - t0);
    n = (size_t)f.w * f.h;
    rays = (lrt_ray *)malloc(n * sizeof *rays);
    hits = (lrt_hit *)malloc(n * sizeof *hits);
    march_hits = (lrt_hit *)malloc(n * sizeof *march_hits);
    ao_rays = (lrt_ray *)malloc(n * AO_RAYS * sizeof *ao_rays);
    ao_hits = (lrt_hit *)malloc(n * AO_RAYS * sizeof *ao_hits);
    img = (uint8_t *)malloc(n * 3);
    img2 = (uint8_t *)malloc(n * 3);
    both = (uint8_t *)malloc(n * 6);
    occ = (float *)malloc(n * sizeof *occ);
    if (!rays || !hits || !march_hits || !ao_rays || !ao_hits || !img || !img2 || !both || !occ) {
        fprintf(stderr, "out of memory for the pictures\n");
        rc = EXAMPLE_EXIT_FAILED;
        goto done;
    }
    bad |= example_write_png(o->out_dir, "color.png", f.w, f.h, 3, f.rgb);
    example_depth_picture(&f, img);
    bad |= example_write_png(o->out_dir, "depth.png", f.w, f.h, 1, img);

    /* reflections: linear_rt, then the same rays marched */
    ssr_make_rays(&f, rays, o->threads);
    t0 = example_now_ms();
    example_trace(&f, rays, hits, f.w, 0, o->threads, "reflections, linear_rt");
    ms_ssr = example_now_ms() - t0;
    ssr_shade(&f, hits, img);
    bad |= example_write_png(o->out_dir, "ssr.png", f.w, f.h, 3, img);
    march64_trace(&f, rays, march_hits, o->threads, &ms_march);
    ssr_shade(&f, march_hits, img2);
    bad |= example_write_png(o->out_dir, "ssr_march64.png", f.w, f.h, 3, img2);
    for (j = 0; j < f.h; ++j) { /* linear_rt left, march right */
        memcpy(&both[(size_t)j * f.w * 6], &img[(size_t)j * f.w * 3], (size_t)f.w * 3);
        memcpy(&both[(size_t)j * f.w * 6 + (size_t)f.w * 3], &img2[(size_t)j * f.w * 3], (size_t)f.w * 3);
    }
    bad |= example_write_png(o->out_dir, "ssr_side_by_side.png", 2 * f.w, f.h, 3, both);
    for (k = 0; k < n; ++k) { /* where the march answers otherwise: white on the colour, darkened */
        int hit_a = hits[k].kind == LRT_HIT, hit_b = march_hits[k].kind == LRT_HIT, same;
        same = hit_a == hit_b && (!hit_a || (hits[k].x == march_hits[k].x && hits[k].y == march_hits[k].y));
        img2[3 * k] = img2[3 * k + 1] = img2[3 * k + 2] = 255;
        if (same || hits[k].kind == LRT_MISS_INVALID_RAY) {
            for (j = 0; j < 3; ++j) img2[3 * k + j] = (uint8_t)(f.rgb[3 * k + j] / 4);
        }
        if (hits[k].kind == LRT_MISS_INVALID_RAY) continue;
        ++traced;
        agree += (size_t)same;
    }
    bad |= example_write_png(o->out_dir, "ssr_difference.png", f.w, f.h, 3, img2);

    ao_make_rays(&f, ao_rays, AO_RADIUS, o->threads);
    t0 = example_now_ms();
    example_trace(&f, ao_rays, ao_hits, (size_t)f.w * AO_RAYS, 0, o->threads, "ambient occlusion");
    ms_ao = example_now_ms() - t0;
    ao_occlusion(&f, ao_hits, occ);
    ao_picture(&f, occ, img);
    bad |= example_write_png(o->out_dir, "ao.png", f.w, f.h, 1, img);

    shadows_make_rays(&f, rays, SHADOW_LENGTH, o->threads);
    t0 = example_now_ms();
    example_trace(&f, rays, hits, f.w, 0, o->threads, "contact shadows");
    ms_sh = example_now_ms() - t0;
    shadows_shade(&f, hits, img);
    bad |= example_write_png(o->out_dir, "shadows.png", f.w, f.h, 3, img);

    printf("  %-36s %10s %12s\n", "traced on the CPU", "ms", "M rays/s");
    printf("  %-36s %10.1f %12.2f\n", "reflections, linear_rt (exact)", ms_ssr, (double)traced / ms_ssr / 1e3);
    printf("  %-36s %10.1f %12.2f\n", "reflections, 64-step march", ms_march, (double)traced / ms_march / 1e3);
    printf("  %-36s %10.1f %12.2f\n", "ambient occlusion, 16 rays/texel", ms_ao, (double)n * AO_RAYS / ms_ao / 1e3);
    printf("  %-36s %10.1f %12.2f\n", "contact shadows", ms_sh, (double)n / ms_sh / 1e3);
    printf("  the march agrees with linear_rt on %.1f%% of the %lu reflection rays (same texel, or both miss)%s\n\n",
           traced ? 100.0 * (double)agree / (double)traced : 0.0, (unsigned long)traced,
           f.bvh.layout.thickness != LRT_THICKNESS_INFINITE ? "; the march has no thickness: linear_rt's rays pass behind objects, the march's stop" : "");
    rc = bad ? EXAMPLE_EXIT_FAILED : EXAMPLE_EXIT_OK;
done:
    free(rays);
    free(hits);
    free(march_hits);
    free(ao_rays);
    free(ao_hits);
    free(img);
    free(img2);
    free(both);
    free(occ);
    example_frame_free(&f);
    return rc;
}

int main(int argc, char **argv)
{
    int size, a, use_gpu = 1, draw = 1, dumped = 0;
    const char *dump_path = NULL;
    example_options opt;
    gpu_run gpu;
    size_t n;
    float *depth_f;
    lrt_depth depth;
    lrt_bvh bvh = {0};
    lrt_ray *prim, *seg;
    lrt_hit *hits1, *hits2, *seg_hits1, *seg_hits2;
    bvh_stats s16, s8;
    double prim_ms[2], upd_trace_ms[2], seg_ms[2];
    int same_prim, same_seg;
    scene_camera cam = scene_default_camera();

    example_default_options(&opt);
    for (a = 1; a < argc; ++a) {
        int p;
        if (strcmp(argv[a], "--no-gpu") == 0) {
            use_gpu = 0;
        } else if (strcmp(argv[a], "--no-pictures") == 0) {
            draw = 0;
        } else if (strcmp(argv[a], "--dump") == 0 && a + 1 < argc) {
            dump_path = argv[++a];
        } else if ((p = example_parse_option(&opt, argc, argv, &a)) != 1) {
            if (p == 0) usage(argv[0]);
            return 2;
        }
    }
    size = (int)opt.size;
    if (draw) { /* first, so that a bad file fails at once */
        int rc = pictures(&opt);
        if (rc != EXAMPLE_EXIT_OK) return rc;
    }
    n = (size_t)size * (size_t)size;

    depth_f = (float *)malloc(n * sizeof *depth_f);
    prim = (lrt_ray *)malloc(n * sizeof *prim);
    seg = (lrt_ray *)malloc(n * sizeof *seg);
    hits1 = (lrt_hit *)malloc(n * sizeof *hits1);
    hits2 = (lrt_hit *)malloc(n * sizeof *hits2);
    seg_hits1 = (lrt_hit *)malloc(n * sizeof *seg_hits1);
    seg_hits2 = (lrt_hit *)malloc(n * sizeof *seg_hits2);
    if (!depth_f || !prim || !seg || !hits1 || !hits2 || !seg_hits1 || !seg_hits2) {
        fprintf(stderr, "out of memory\n");
        return 1;
    }
    /* pre-touch every output array so that page faults stay out of the timings */
    memset(hits1, 0, n * sizeof *hits1);
    memset(hits2, 0, n * sizeof *hits2);
    memset(seg_hits1, 0, n * sizeof *seg_hits1);
    memset(seg_hits2, 0, n * sizeof *seg_hits2);

    scene_render(size, size, &cam, depth_f, NULL);
    memset(&depth, 0, sizeof depth);
    depth.data = depth_f;
    depth.width = depth.height = (uint32_t)size;
    depth.format = LRT_FORMAT_FLOAT32;

    /* rays: primary, then one random segment per texel (examples/scene.h) */
    {
        uint64_t rng = SCENE_DEMO_SEED;
        scene_demo_rays(size, depth_f, prim, seg, n, &rng);
    }

    /* BVH: 8-bit nodes first (measured, then freed), then the float default
       of 16-bit nodes, kept for tracing */
    s8 = measure_bvh(&depth, 8, NULL);
    s16 = measure_bvh(&depth, LRT_NODE_BITS_AUTO, &bvh);

    for (a = 0; a < 2; ++a) {
        prim_ms[a] = time_trace(&bvh, &depth, prim, a ? hits2 : hits1, n, a + 1, 0);
        upd_trace_ms[a] = time_trace(&bvh, &depth, prim, a ? hits2 : hits1, n, a + 1, 1);
        seg_ms[a] = time_trace(&bvh, &depth, seg, a ? seg_hits2 : seg_hits1, n, a + 1, 0);
    }
    same_prim = memcmp(hits1, hits2, n * sizeof *hits1) == 0;
    same_seg = memcmp(seg_hits1, seg_hits2, n * sizeof *seg_hits1) == 0;

    memset(&gpu, 0, sizeof gpu);
#ifdef LINEAR_RT_VULKAN
    if (use_gpu) run_vulkan(&gpu, &depth, prim, hits1, seg, seg_hits1, n);
    else snprintf(gpu.why, sizeof gpu.why, "--no-gpu");
#else
    (void)use_gpu;
    snprintf(gpu.why, sizeof gpu.why, "built without LINEAR_RT_VULKAN (no <vulkan/vulkan.h> at build time)");
#endif

    printf("linear_rt demo: embedded scene %dx%d, float32 depth, CPU path\n", size, size);
#if defined(__clang__)
    printf("compiler: clang %s\n", __clang_version__);
#elif defined(__GNUC__)
    printf("compiler: gcc %s\n", __VERSION__);
#endif
    printf("flags:    %s\n", DEMO_CFLAGS);
    printf("CPU walk: %s\n", lrt_cpu_path());
    printf("timings:  CLOCK_MONOTONIC, medians after a warm-up (build %d, update %d, trace %d runs)\n\n",
           BUILD_RUNS, UPDATE_RUNS, TRACE_RUNS);

    printf("%-34s %14s %14s\n", "BVH", "16-bit nodes", "8-bit nodes");
    printf("%-34s %14.3f %14.3f\n", "  build ms (lrt_bvh_build)", s16.build_ms, s8.build_ms);
    printf("%-34s %14.3f %14.3f\n", "  update ms (whole map)", s16.update_ms, s8.update_ms);
    printf("%-34s %14.3f %14.3f\n\n", "  bytes per texel", s16.bytes_per_texel, s8.bytes_per_texel);

    printf("%-34s %14s %14s\n", "rays (16-bit nodes, float default)", "1 thread", "2 threads");
    printf("%-34s %14.3f %14.3f\n", "  primary: trace ms", prim_ms[0], prim_ms[1]);
    printf("%-34s %14.2f %14.2f\n", "  primary: M rays/s", (double)n / prim_ms[0] / 1e3,
           (double)n / prim_ms[1] / 1e3);
    printf("%-34s %14.3f %14.3f\n", "  update + primary trace ms *", upd_trace_ms[0], upd_trace_ms[1]);
    printf("%-34s %14.3f %14.3f\n", "  segments: trace ms", seg_ms[0], seg_ms[1]);
    printf("%-34s %14.2f %14.2f\n", "  segments: M rays/s", (double)n / seg_ms[0] / 1e3,
           (double)n / seg_ms[1] / 1e3);
    printf("  * the design's headline figure (~1.4 ms quoted for a phone GPU at 1024x1024)\n");
    printf("  (%lu rays of each kind; %.1f%% of the segments hit; 2-thread hits %s)\n\n",
           (unsigned long)n, 100.0 * (double)count_hits(seg_hits1, n) / (double)n,
           same_prim && same_seg ? "identical to 1-thread hits" : "DIFFER from 1-thread hits");

    if (!gpu.ran) {
        printf("Vulkan: not run: %s\n\n", gpu.why);
    } else {
        printf("Vulkan: %s; build once, then per run update + primary trace, and the segments\n", gpu.device);
        if (gpu.timed) {
            printf("timings: GPU timestamps of the dispatches (vkCmdWriteTimestamp), medians of %d runs after a warm-up\n",
                   GPU_RUNS);
            printf("%-34s %14s %14s %14s\n", "16-bit nodes, float depth", "CPU 1 thread", "CPU 2 threads", "Vulkan");
            printf("%-34s %14.3f %14s %14.3f\n", "  update ms (whole map)", s16.update_ms, "-", gpu.update_ms);
            printf("%-34s %14.3f %14.3f %14.3f\n", "  primary: trace ms", prim_ms[0], prim_ms[1], gpu.prim_ms);
            printf("%-34s %14.3f %14.3f %14.3f\n", "  update + primary trace ms *", upd_trace_ms[0], upd_trace_ms[1],
                   gpu.update_ms + gpu.prim_ms);
            printf("%-34s %14.3f %14.3f %14.3f\n", "  segments: trace ms", seg_ms[0], seg_ms[1], gpu.seg_ms);
            printf("%-34s %14.2f %14.2f %14.2f\n", "  segments: M rays/s", (double)n / seg_ms[0] / 1e3,
                   (double)n / seg_ms[1] / 1e3, (double)n / gpu.seg_ms / 1e3);
        } else {
            printf("  (this queue has no timestamps: no GPU timings)\n");
        }
        printf("  GPU hits == CPU hits, bit for bit (t, texel, kind, face): primary %lu / %lu, segments %lu / %lu\n\n",
               (unsigned long)gpu.prim_same, (unsigned long)n, (unsigned long)gpu.seg_same, (unsigned long)n);
    }
    if (dump_path) dumped = dump_answers(dump_path, &depth, prim, hits1, seg, seg_hits1) == 0;
    else printf("(make test-demo judges these CPU answers by an exact reference tracer: build/demo --dump FILE)\n");

    lrt_bvh_destroy(&bvh);
    free(depth_f);
    free(prim);
    free(seg);
    free(hits1);
    free(hits2);
    free(seg_hits1);
    free(seg_hits2);
    return same_prim && same_seg && (!gpu.ran || (gpu.prim_same == n && gpu.seg_same == n)) && (!dump_path || dumped)
               ? 0
               : 1;
}
