/* tests/test_vulkan.c - the Vulkan path of linear_rt.h (the kernels of
   shaders/, embedded in shaders_spv.h) against the CPU path and docs/MODEL.md.

   On the first device lrt_vku_device_create finds (lavapipe on the project's
   machines), with the Khronos validation layer on, synchronization
   validation too (the barriers linear_rt.h documents, and its own): any
   validation message fails the test.
   (a) GPU build == CPU build byte for byte: many sizes, the three formats,
       reversed Z, 8- and 16-bit nodes, depth from buffers (packed, or at an
       unaligned offset with a padded stride) and from sampled images
       (D32_SFLOAT, R32_SFLOAT, D16_UNORM, R16_UNORM, R8_UNORM);
   (b) update with a dirty rect and with NULL over moving frames == the CPU's
       update, byte for byte;
   (c) trace: rays of every kind of tests/support/rays.h on GPU and CPU: same kind and
       texel, t within 1e-5 * (1 + |t|); where they differ, the GPU answer
       must still be right by tests/support/reference.h's ref_check (counted);
       any-hit on a slice at an offset; 2D dispatches of trace and refit;
   (d) every bad argument's result code, without a device and with one, and
       that an erroring call records nothing;
   (e) device limits (maxStorageBufferRange, maxComputeWorkGroupCount,
       maxImageDimension2D) on contexts that see lowered ones: past them
       LRT_ERROR_LIMIT_EXCEEDED and nothing recorded, within them the CPU's
       trees and answers (test_device_limits).
   With --flushing-device first (x86 only), the device is made while the
   process flushes subnormal floats (MXCSR's FTZ and DAZ), so lavapipe's
   threads, which inherit that state, run the kernels as a GPU that
   flushes them does (an NVIDIA H200: this mode gave its very answers),
   while the CPU path and the reference run as usual.
   No Vulkan loader or device: prints why and exits 0 (skipped), or 1 when
   the environment variable CI is "true". Ends with "N passed, M failed".
   LRT_TEST_SEED (a number) draws other rays of the same kinds: a longer
   soak of the GPU walks against the CPU's, one seed a run.
   Built with TEST_HLSL (test_vulkan_hlsl), the trace kernels (buffer and
   image depth) are tests/hlsl/lrt_trace.hlsl, compiled by glslang's HLSL
   front end: the same tests but one trace of (e), in rows of a lowered
   maxComputeWorkGroupCount (HLSL has no gl_NumWorkGroups: the kernel works
   out a 2D dispatch's row for the usual limit). */
#ifndef LINEAR_RT_VULKAN
#define LINEAR_RT_VULKAN
#endif
#ifdef TEST_HLSL /* test_vulkan_hlsl: the trace kernels compiled from HLSL (tests/hlsl/lrt_trace.hlsl) */
#include "test_vulkan_hlsl_spv.h"
#define LRT__VK_TRACE_BUFFER_SPV lrt_hlsl_trace_buffer
#define LRT__VK_TRACE_BUFFER_SPV_SIZE lrt_hlsl_trace_buffer_SIZE
#define LRT__VK_TRACE_IMAGE_SPV lrt_hlsl_trace_image
#define LRT__VK_TRACE_IMAGE_SPV_SIZE lrt_hlsl_trace_image_SIZE
#endif
#define LINEAR_RT_IMPLEMENTATION
#include "../linear_rt.h"
#include "support/reference.h"
#include "../examples/scene.h"
#include "support/rays.h"
#include "support/check.h"
#include "../linear_rt_vk_util.h"

#include <stdio.h>
#if defined(__SSE2__) || defined(_M_X64)
#include <xmmintrin.h>
#define HAVE_MXCSR 1
#endif
#include <stdlib.h>
#include <string.h>
#include <math.h>


static lrt_vku_device g_dev;  /* stays put: the validation callback counts into it */
static lrt_vku g_t;
static lrt_vk_context *g_ctx;
static VkPhysicalDeviceLimits g_limits;

static uint32_t bytes_of(lrt_format f) { return f == LRT_FORMAT_UNORM8 ? 1u : f == LRT_FORMAT_UNORM16 ? 2u : 4u; }

/* ---- depth on the GPU --------------------------------------------------------- */
enum { SRC_PACKED, SRC_OFFSET, SRC_IMAGE };
static const char *src_names[] = {"buffer", "buffer+offset", "image"};

typedef struct gpu_depth {
    lrt_vk_depth depth;
    lrt_vku_buffer buffer;
    lrt_vku_image image;
    int source;
    /* a back-map tree's maps: pair[0] the depth (its back: &pair[1]), pair[1] its back map */
    int thick;
    lrt_vk_depth pair[2];
    lrt_build_options model; /* the tree's thickness model (test_map.model) */
} gpu_depth;

/* the lrt_vk_depth the calls take: the depth, or the pair */
static const lrt_vk_depth *gpu_maps(const gpu_depth *g) { return g->thick ? g->pair : &g->depth; }

/* Texels of a CPU depth map (any stride) as rows of dst_stride bytes. */
static void copy_rows(const lrt_depth *d, unsigned char *dst, size_t dst_stride)
{
    const size_t row = (size_t)d->width * bytes_of(d->format);
    const size_t stride = d->row_stride ? d->row_stride : row;
    uint32_t y;
    for (y = 0; y < d->height; ++y) memcpy(dst + dst_stride * y, (const unsigned char *)d->data + stride * y, row);
}

/* Writes the texels of d into g (buffer: mapped; image: staging upload). */
static int gpu_depth_write(gpu_depth *g, const lrt_depth *d, int first)
{
    if (g->source == SRC_IMAGE) {
        size_t row = (size_t)d->width * bytes_of(d->format);
        unsigned char *packed = (unsigned char *)malloc(row * d->height);
        int err;
        copy_rows(d, packed, row);
        err = lrt_vku_image_upload(&g_t, &g->image, packed, first);
        free(packed);
        return err;
    }
    /* host writes before the submission are visible to it: no barrier */
    copy_rows(d, (unsigned char *)g->buffer.map + g->depth.offset, (size_t)g->depth.row_stride);
    return 0;
}

static VkFormat default_image_format(lrt_format f, int in_range)
{
    if (f == LRT_FORMAT_UNORM8) return VK_FORMAT_R8_UNORM;
    if (f == LRT_FORMAT_UNORM16) return in_range ? VK_FORMAT_D16_UNORM : VK_FORMAT_R16_UNORM;
    return in_range ? VK_FORMAT_D32_SFLOAT : VK_FORMAT_R32_SFLOAT; /* D32 holds [0,1] only */
}

static int gpu_depth_create(const lrt_depth *d, int source, VkFormat image_format, gpu_depth *g)
{
    const uint32_t bpp = bytes_of(d->format);
    memset(g, 0, sizeof *g);
    g->source = source;
    g->depth.format = d->format;
    g->depth.flags = d->flags;
    g->depth.width = d->width;
    g->depth.height = d->height;
    if (source == SRC_IMAGE) {
        if (lrt_vku_image_create(&g_t, image_format, d->width, d->height, &g->image)) return 1;
        g->depth.view = g->image.view;
        g->depth.layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    } else {
        /* at an offset that is no multiple of the storage alignment, rows
           padded by 3 texels: the kernels get the rest of the offset */
        VkDeviceSize offset = source == SRC_OFFSET ? 52u : 0u;
        VkDeviceSize stride = (VkDeviceSize)d->width * bpp + (source == SRC_OFFSET ? 3u * bpp : 0u);
        VkDeviceSize size = offset + stride * (d->height - 1u) + (VkDeviceSize)d->width * bpp;
        if (lrt_vku_buffer_create(&g_t, (size + 3u) / 4u * 4u, &g->buffer)) return 1;
        memset(g->buffer.map, 0xee, (size_t)g->buffer.size); /* poison around the texels */
        g->depth.buffer = g->buffer.buffer;
        g->depth.offset = offset;
        g->depth.row_stride = source == SRC_OFFSET ? stride : 0u;
    }
    if (source != SRC_IMAGE) g->depth.row_stride = g->depth.row_stride ? g->depth.row_stride : (VkDeviceSize)d->width * bpp;
    return gpu_depth_write(g, d, 1);
}

static void gpu_depth_destroy(gpu_depth *g)
{
    lrt_vku_buffer_destroy(&g_t, &g->buffer);
    lrt_vku_image_destroy(&g_t, &g->image);
}

/* ---- GPU BVHs ---------------------------------------------------------------------- */

/* Creates a host-visible GPU BVH and builds it from g; 0 on success. */
static int gpu_build(const lrt_depth *d, uint32_t node_bits, gpu_depth *g, lrt_vk_bvh *bvh, const char *what)
{
    lrt_vk_bvh_desc bd;
    lrt_result r;
    memset(&bd, 0, sizeof bd);
    bd.width = d->width;
    bd.height = d->height;
    bd.format = d->format;
    bd.depth_flags = d->flags;
    bd.options = g->model;
    bd.options.node_bits = node_bits;
    bd.flags = LRT_VK_BVH_HOST_VISIBLE;
    r = lrt_vk_bvh_create(g_ctx, &bd, bvh);
    CHECK(r == LRT_SUCCESS && bvh->mapped, "%s: lrt_vk_bvh_create: %s", what, lrt_result_string(r));
    if (r != LRT_SUCCESS) return 1;
    memset(bvh->mapped, 0xa5, bvh->layout.bytes); /* the build must write every byte */
    if (lrt_vku_begin(&g_t)) return 1;
    r = lrt_vk_cmd_build(g_ctx, g_t.cmd, bvh, gpu_maps(g));
    CHECK(r == LRT_SUCCESS, "%s: lrt_vk_cmd_build: %s", what, lrt_result_string(r));
    lrt_vku_host_barrier(&g_t);
    return lrt_vku_submit(&g_t);
}

/* GPU nodes == CPU nodes, byte for byte; prints the first difference. */
static int same_nodes(const lrt_vk_bvh *gpu, const lrt_bvh *cpu, const char *what)
{
    const unsigned char *a = (const unsigned char *)gpu->mapped, *b = (const unsigned char *)cpu->nodes;
    size_t i, n = cpu->layout.bytes, diffs = 0, first = 0;
    if (gpu->layout.bytes != n) {
        printf("  %s: %zu GPU node bytes, %zu CPU\n", what, (size_t)gpu->layout.bytes, n);
        return 0;
    }
    for (i = 0; i < n; ++i)
        if (a[i] != b[i] && diffs++ == 0) first = i;
    if (diffs) {
        const lrt_layout *L = &cpu->layout;
        const size_t heights = L->back_codes ? n / 2u : n, at = first % heights; /* the back codes repeat the layout */
        uint32_t lv = 1;
        if (at >= L->levels[1].count * L->level1_node_bytes) { /* above level 1: 16-byte nodes */
            const size_t node = L->levels[1].count + (at - L->levels[1].count * L->level1_node_bytes) / 16u;
            while (lv < L->level_count && node >= L->levels[lv].offset + L->levels[lv].count) ++lv;
        }
        printf("  %s: %zu of %zu node bytes differ; the first at byte %zu (level %u): GPU 0x%02x CPU 0x%02x\n", what,
               diffs, n, first, lv, a[first], b[first]);
    }
    return diffs == 0;
}

/* ---- (c) tracing ----------------------------------------------------------------- */
typedef struct trace_stats {
    size_t rays, differ, wrong, bit_identical, kind_rays[RAY_KIND_COUNT], kind_differ[RAY_KIND_COUNT];
} trace_stats;
static trace_stats g_trace_total;
static int g_flushing;  /* --flushing-device */
static int g_compacted; /* --compacted: gpu_trace records lrt_vk_cmd_trace_compacted */
static size_t g_listed[LRT_K_VK_TRACE_ROUNDS - 1u]; /* rays each round left for the next */
static size_t g_budget_rays, g_budget_stopped, g_budget_estimates; /* budget_case's rays, its budget misses and estimates */
static int g_ran_budget_cases;                  /* test_build_and_trace ran: its budget cases must stop some rays */

static int same_answer(const lrt_hit *a, const lrt_hit *b)
{
    if (a->kind != b->kind || a->face != b->face) return 0;
    if (a->kind != LRT_HIT) return a->t == b->t && a->x == b->x && a->y == b->y;
    return a->x == b->x && a->y == b->y && fabsf(a->t - b->t) <= 1e-5f * (1.0f + fabsf(b->t));
}

/* Traces rays[0..n) on the GPU at ray index `first` of the buffers (so at
   offsets first*32 and first*16) into gpu_hits. */
static int gpu_trace(const lrt_vk_bvh *bvh, const gpu_depth *g, const lrt_ray *rays, lrt_hit *gpu_hits, size_t n,
                     size_t first, uint32_t flags, const char *what)
{
    lrt_vku_buffer rb, hb, sb;
    lrt_vk_scratch scratch;
    lrt_result r;
    int err;
    memset(&sb, 0, sizeof sb);
    if (lrt_vku_buffer_create(&g_t, (first + n) * sizeof(lrt_ray), &rb) ||
        lrt_vku_buffer_create(&g_t, (first + n) * sizeof(lrt_hit), &hb) ||
        (g_compacted && lrt_vku_buffer_create(&g_t, lrt_vk_trace_scratch_size((uint32_t)n), &sb)))
        return 1;
    memcpy((lrt_ray *)rb.map + first, rays, n * sizeof(lrt_ray));
    memset(hb.map, 0xff, (size_t)hb.size);
    if (sb.map) memset(sb.map, 0xee, (size_t)sb.size); /* the trace sets what it reads */
    scratch.buffer = sb.buffer;
    scratch.offset = 0;
    scratch.size = sb.size;
    if (lrt_vku_begin(&g_t)) return 1;
    lrt_vku_compute_barrier(&g_t); /* the build of an earlier submission -> this trace */
    if (g_compacted)
        r = lrt_vk_cmd_trace_compacted(g_ctx, g_t.cmd, bvh, gpu_maps(g), rb.buffer, first * sizeof(lrt_ray), hb.buffer,
                                       first * sizeof(lrt_hit), (uint32_t)n, flags, &scratch);
    else
        r = lrt_vk_cmd_trace(g_ctx, g_t.cmd, bvh, gpu_maps(g), rb.buffer, first * sizeof(lrt_ray), hb.buffer,
                             first * sizeof(lrt_hit), (uint32_t)n, flags);
    CHECK(r == LRT_SUCCESS, "%s: lrt_vk_cmd_trace%s: %s", what, g_compacted ? "_compacted" : "", lrt_result_string(r));
    lrt_vku_host_barrier(&g_t);
    err = lrt_vku_submit(&g_t);
    memcpy(gpu_hits, (const lrt_hit *)hb.map + first, n * sizeof(lrt_hit));
    if (sb.map && !bvh->layout.back_codes) { /* what each round listed (the count, a header's 4th word) */
        size_t k;
        for (k = 0; k < LRT_K_VK_TRACE_ROUNDS - 1u; ++k) g_listed[k] += ((const uint32_t *)sb.map)[4 * k + 3];
    }
    if (sb.buffer) lrt_vku_buffer_destroy(&g_t, &sb);
    {   /* nothing written outside the slice */
        size_t i, outside = 0;
        const unsigned char *h = (const unsigned char *)hb.map;
        for (i = 0; i < first * sizeof(lrt_hit); ++i) outside += h[i] != 0xff;
        CHECK(outside == 0, "%s: %zu bytes written before the slice", what, outside);
    }
    lrt_vku_buffer_destroy(&g_t, &rb);
    lrt_vku_buffer_destroy(&g_t, &hb);
    return err;
}

/* GPU answers against the CPU's; differences judged by the reference. */
static void judge(const char *what, const test_map *m, const lrt_ray *rays, const int *kinds, const lrt_hit *gpu,
                  const lrt_hit *cpu, size_t n, int any_hit)
{
    size_t i, differ = 0, wrong = 0;
    for (i = 0; i < n; ++i) {
        ref_ray q;
        ref_answer a;
        char why[256];
        g_trace_total.kind_rays[kinds[i]] += !any_hit;
        g_trace_total.bit_identical += !any_hit && memcmp(&gpu[i], &cpu[i], sizeof gpu[i]) == 0;
        if (!any_hit && same_answer(&gpu[i], &cpu[i])) continue;
        g_trace_total.kind_differ[kinds[i]] += !any_hit;
        ++differ;
        q = ref_ray_of(&rays[i]);
        a = to_answer(&gpu[i]);
        if (!ref_check(&m->ref, &q, &a, any_hit, why, sizeof why)) {
            if (wrong < 5)
                printf("FAIL %s ray %zu (%s) o=(%.9g %.9g %.9g) v=(%.9g %.9g %.9g) t=[%.9g %.9g]: GPU kind %u t %.9g "
                       "(%u,%u), CPU kind %u t %.9g (%u,%u): %s\n",
                       what, i, ray_names[kinds[i]], q.o[0], q.o[1], q.o[2], q.v[0], q.v[1], q.v[2], q.tmin, q.tmax,
                       gpu[i].kind, (double)gpu[i].t, gpu[i].x, gpu[i].y, cpu[i].kind, (double)cpu[i].t, cpu[i].x,
                       cpu[i].y, why);
            ++wrong;
        }
    }
    if (any_hit) differ = 0; /* any-hit answers are judged, not compared */
    CHECK(wrong == 0, "%s: %zu of %zu GPU answers are wrong by the reference", what, wrong, n);
    g_trace_total.rays += n;
    g_trace_total.differ += differ;
    g_trace_total.wrong += wrong;
    if (wrong) printf("  %s: %zu of %zu rays differ from the CPU, %zu of them wrong by the reference\n", what, differ, n, wrong);
}

/* A step budget (LRT_TRACE_BUDGET), one of a ladder from case to case, and
   every other case a finish (LRT_TRACE_FINISH, 2^0, 2^3 or 2^5 steps): the
   GPU's answers are the CPU's bit for bit (the same steps counted, the same
   samples), every answer but a budget miss or an estimate is the exact one,
   and a budget miss's t lies in [tmin, tmax] and not after the exact hit,
   an estimate's in [tmin, tmax]. */
static void budget_case(const test_map *m, const lrt_bvh *cpu, const lrt_vk_bvh *gpu, const gpu_depth *g,
                        const lrt_ray *rays, const lrt_hit *exact, size_t n, const char *what)
{
    static const uint32_t ladder[] = {1, 2, 3, 5, 8, 13, 21}, finishes[] = {0, LRT_TRACE_FINISH(0), 0, LRT_TRACE_FINISH(3),
                                                                              0, LRT_TRACE_FINISH(5)};
    static size_t next;
    const uint32_t budget = ladder[next % (sizeof ladder / sizeof ladder[0])];
    const uint32_t flags = LRT_TRACE_BUDGET(budget) | finishes[next % (sizeof finishes / sizeof finishes[0])];
    lrt_hit *cpu_hits = (lrt_hit *)malloc(sizeof(lrt_hit) * n), *gpu_hits = (lrt_hit *)malloc(sizeof(lrt_hit) * n);
    size_t i, differ = 0, not_exact = 0, bad_t = 0, stopped = 0;
    char name[300];
    ++next;
    snprintf(name, sizeof name, "%s budget %u flags %#x", what, budget, flags);
    CHECK(lrt_trace(cpu, test_map_depth(m), rays, cpu_hits, n, flags) == LRT_SUCCESS, "%s: CPU trace", name);
    if (gpu_trace(gpu, g, rays, gpu_hits, n, 0, flags, name) == 0) {
        for (i = 0; i < n; ++i) {
            differ += memcmp(&gpu_hits[i], &cpu_hits[i], sizeof cpu_hits[i]) != 0;
            if (cpu_hits[i].kind == LRT_HIT_ESTIMATE) {
                ++g_budget_estimates;
                bad_t += !(cpu_hits[i].t >= rays[i].tmin && cpu_hits[i].t <= rays[i].tmax);
            } else if (cpu_hits[i].kind == LRT_MISS_BUDGET) {
                ++stopped;
                bad_t += !(cpu_hits[i].t >= rays[i].tmin && cpu_hits[i].t <= rays[i].tmax) ||
                         (exact[i].kind == LRT_HIT && cpu_hits[i].t > exact[i].t);
            } else {
                not_exact += memcmp(&cpu_hits[i], &exact[i], sizeof exact[i]) != 0;
            }
        }
        CHECK(differ == 0, "%s: %zu of %zu GPU answers not bit-identical to the CPU's", name, differ, n);
        CHECK(not_exact == 0, "%s: %zu answers that are not budget misses differ from the exact walk's", name, not_exact);
        CHECK(bad_t == 0, "%s: %zu budget misses claim a t past the exact hit or outside [tmin, tmax], or estimates outside it",
              name, bad_t);
        g_budget_stopped += stopped;
        g_budget_rays += n;
    } else {
        CHECK(0, "%s: GPU trace failed", name);
    }
    free(cpu_hits);
    free(gpu_hits);
}

static void trace_case(const test_map *m, const lrt_bvh *cpu, const lrt_vk_bvh *gpu, const gpu_depth *g, size_t n,
                       const char *what)
{
    lrt_ray *rays = (lrt_ray *)malloc(sizeof(lrt_ray) * n);
    lrt_hit *cpu_hits = (lrt_hit *)malloc(sizeof(lrt_hit) * n), *gpu_hits = (lrt_hit *)malloc(sizeof(lrt_hit) * n);
    int *kinds = (int *)malloc(sizeof(int) * n);
    char name[256];
    size_t i;
    for (i = 0; i < n; ++i) {
        kinds[i] = (int)(i % RAY_KIND_COUNT);
        rays[i] = make_ray(m, kinds[i]);
    }
    CHECK(lrt_trace(cpu, test_map_depth(m), rays, cpu_hits, n, 0) == LRT_SUCCESS, "%s: CPU trace", what);
    if (gpu_trace(gpu, g, rays, gpu_hits, n, 0, 0, what) == 0) judge(what, m, rays, kinds, gpu_hits, cpu_hits, n, 0);
    else CHECK(0, "%s: GPU trace failed", what);
    budget_case(m, cpu, gpu, g, rays, cpu_hits, n, what);
    if (n >= 300) { /* a slice at an offset: ray_first */
        snprintf(name, sizeof name, "%s slice", what);
        if (gpu_trace(gpu, g, rays + 5, gpu_hits, 200, 5, 0, name) == 0)
            judge(name, m, rays + 5, kinds + 5, gpu_hits, cpu_hits + 5, 200, 0);
        else CHECK(0, "%s: GPU trace failed", name);
    }
    free(rays);
    free(cpu_hits);
    free(gpu_hits);
    free(kinds);
}

/* ---- (a) build, then (c) trace on the same map ------------------------------------- */
static void build_case(int w, int h, int shape, lrt_format format, int reversed, uint32_t node_bits, int source,
                       VkFormat image_format, size_t nrays, int thick)
{
    test_map m;
    lrt_bvh cpu = {0};
    lrt_vk_bvh gpu = {0};
    lrt_build_options opt;
    gpu_depth g, gb;
    char what[200];
    make_map(&m, w, h, shape, format, reversed, (w + h) & 1);
    if (thick == LRT_THICKNESS_BACK_MAP) add_back(&m);
    if (thick >= LRT_THICKNESS_CONSTANT) /* thin or thick layers, far planes finite or not */
        add_model(&m, (uint32_t)thick, (w & 1) ? 0.05f : 1.5f, (h & 1) ? 0.1f : 1.0f, (w & 2) ? 100.0f : INFINITY);
    opt = m.model;
    opt.node_bits = node_bits;
    CHECK(lrt_bvh_build(&cpu, test_map_depth(&m), &opt, NULL) == LRT_SUCCESS, "CPU build");
    snprintf(what, sizeof what, "%dx%d %s fmt=%d%s nodes=%u %s%s", w, h, m.name, (int)format, reversed ? " reversed" : "",
             cpu.layout.node_bits, src_names[source], model_name(&m));
    memset(&gb, 0, sizeof gb);
    if (source == SRC_IMAGE) {
        size_t len = strlen(what);
        snprintf(what + len, sizeof what - len, " (VkFormat %d)", (int)image_format);
        if (!lrt_vku_format_sampled(&g_t, image_format)) {
            printf("  note: %s: the device cannot sample this format: skipped\n", what);
            lrt_bvh_destroy(&cpu);
            free_map(&m);
            return;
        }
    }
    memset(&gpu, 0, sizeof gpu);
    if (gpu_depth_create(&m.depth, source, image_format, &g) == 0 && (g.model = m.model, 1) &&
        (!m.back_storage || gpu_depth_create(&m.pair[1], source, image_format, &gb) == 0) &&
        (!m.back_storage || (g.thick = 1, g.pair[0] = g.depth, g.pair[0].back = &g.pair[1], g.pair[1] = gb.depth, 1)) &&
        gpu_build(&m.depth, node_bits, &g, &gpu, what) == 0) {
        CHECK(gpu.layout.node_bits == cpu.layout.node_bits && gpu.layout.level_count == cpu.layout.level_count,
              "%s: layouts differ", what);
        CHECK(same_nodes(&gpu, &cpu, what), "%s: GPU build differs from the CPU build", what);
        if (nrays) trace_case(&m, &cpu, &gpu, &g, nrays, what);
    } else {
        CHECK(0, "%s: GPU set-up failed", what);
    }
    lrt_vk_bvh_destroy(g_ctx, &gpu);
    gpu_depth_destroy(&g);
    gpu_depth_destroy(&gb);
    lrt_bvh_destroy(&cpu);
    free_map(&m);
}

/* the rays the fuzzer found wrong once, on the GPU: the CPU's answers */
static void test_found_cases(void)
{
    test_map m;
    lrt_ray r;
    int k;
    for (k = 0; found_case(k, &m, &r); ++k) {
        lrt_bvh cpu = {0};
        lrt_vk_bvh gpu = {0};
        gpu_depth g;
        lrt_hit ch, gh;
        int kind = RAY_CORNER;
        char what[64];
        snprintf(what, sizeof what, "found case %d", k);
        memset(&gpu, 0, sizeof gpu);
        CHECK(lrt_bvh_build(&cpu, &m.depth, NULL, NULL) == LRT_SUCCESS, "%s: CPU build", what);
        CHECK(lrt_trace(&cpu, &m.depth, &r, &ch, 1, 0) == LRT_SUCCESS, "%s: CPU trace", what);
        if (gpu_depth_create(&m.depth, 0, VK_FORMAT_UNDEFINED, &g) == 0 && gpu_build(&m.depth, 0, &g, &gpu, what) == 0 &&
            gpu_trace(&gpu, &g, &r, &gh, 1, 0, 0, what) == 0) {
            CHECK(memcmp(&gh, &ch, sizeof gh) == 0, "%s: GPU kind %u t %g (%u,%u), CPU kind %u t %g (%u,%u)", what,
                  gh.kind, (double)gh.t, gh.x, gh.y, ch.kind, (double)ch.t, ch.x, ch.y);
            judge(what, &m, &r, &kind, &gh, &ch, 1, 0);
            lrt_vk_bvh_destroy(g_ctx, &gpu);
            gpu_depth_destroy(&g);
        } else {
            CHECK(0, "%s: GPU set-up failed", what);
        }
        lrt_bvh_destroy(&cpu);
        free_map(&m);
    }
}

static void test_build_and_trace(void)
{
    static const int sizes[][2] = {{1, 1}, {3, 5}, {7, 9}, {33, 20}, {64, 64}, {100, 37}, {5, 300}, {300, 200}};
    const size_t nsizes = sizeof sizes / sizeof sizes[0];
    size_t s;
    int f;
    g_ran_budget_cases = 1;
    for (s = 0; s < nsizes; ++s) {
        const int w = sizes[s][0], h = sizes[s][1];
        for (f = 1; f <= 3; ++f) {
            const lrt_format fmt = (lrt_format)f;
            const int shape = (int)((s + (size_t)f) % 4); /* noise, terraces, scene, poles */
            const size_t nrays = w * h >= 1000 ? 2600 : 1300;
            /* auto node bits; the other precision with reversed Z at an offset; an image */
            build_case(w, h, shape, fmt, 0, 0, SRC_PACKED, VK_FORMAT_UNDEFINED, nrays, 0);
            build_case(w, h, shape, fmt, 1, fmt == LRT_FORMAT_UNORM8 ? 16u : 8u, SRC_OFFSET, VK_FORMAT_UNDEFINED, nrays, 0);
            build_case(w, h, shape, fmt, (int)(s & 1), (s & 2) ? 8u : 16u, SRC_IMAGE, default_image_format(fmt, 1), nrays, 0);
        }
        /* float values the model clamps (NaN, inf, out of [0,1]) */
        build_case(w, h, SHAPE_WILD, LRT_FORMAT_FLOAT32, (int)(s & 1), 0, SRC_OFFSET, VK_FORMAT_UNDEFINED, 1300, 0);
        build_case(w, h, SHAPE_WILD, LRT_FORMAT_FLOAT32, 0, 8, SRC_IMAGE, VK_FORMAT_R32_SFLOAT, 1300, 0);
        build_case(w, h, SHAPE_FAR, LRT_FORMAT_UNORM16, 0, 0, SRC_IMAGE, VK_FORMAT_R16_UNORM, 0, 0);
    }
    /* the large sizes of the issue */
    build_case(1282, 1110, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 0, SRC_PACKED, VK_FORMAT_UNDEFINED, 30000, 0);
    build_case(1282, 1110, SHAPE_SCENE, LRT_FORMAT_UNORM16, 1, 8, SRC_IMAGE, VK_FORMAT_D16_UNORM, 5000, 0);
    build_case(1024, 1024, SHAPE_SCENE, LRT_FORMAT_UNORM8, 0, 0, SRC_OFFSET, VK_FORMAT_UNDEFINED, 5000, 0);
    build_case(1024, 1024, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 1, 16, SRC_IMAGE, VK_FORMAT_D32_SFLOAT, 30000, 0);
    /* back-map trees (thickness): a buffer at an offset with padded rows, an image, each format and node width */
    for (f = 1; f <= 3; ++f) {
        const lrt_format fmt = (lrt_format)f;
        build_case(100, 37, SHAPE_SCENE, fmt, 0, 0, SRC_OFFSET, VK_FORMAT_UNDEFINED, 2600, 1);
        build_case(33, 20, SHAPE_POLES, fmt, 1, fmt == LRT_FORMAT_UNORM8 ? 16u : 8u, SRC_IMAGE, default_image_format(fmt, 1), 1300, 1);
    }
    build_case(300, 200, SHAPE_WILD, LRT_FORMAT_FLOAT32, 0, 16, SRC_PACKED, VK_FORMAT_UNDEFINED, 2600, 1);
    build_case(1, 1, SHAPE_NOISE, LRT_FORMAT_FLOAT32, 0, 8, SRC_PACKED, VK_FORMAT_UNDEFINED, 300, 1);
    build_case(1024, 1024, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 16, SRC_IMAGE, VK_FORMAT_D32_SFLOAT, 20000, 1);
    /* constant and relative thickness: b(d) in the kernels, the CPU's floats */
    for (f = 1; f <= 3; ++f) {
        const lrt_format fmt = (lrt_format)f;
        int model;
        for (model = LRT_THICKNESS_CONSTANT; model <= LRT_THICKNESS_RELATIVE; ++model) {
            build_case(100, 37, SHAPE_SCENE, fmt, f == 2, 0, SRC_OFFSET, VK_FORMAT_UNDEFINED, 2600, model);
            build_case(34, 21, SHAPE_POLES, fmt, 1, fmt == LRT_FORMAT_UNORM8 ? 16u : 8u, SRC_IMAGE, default_image_format(fmt, 1), 1300, model);
            build_case(39, 20, SHAPE_NOISE, fmt, 0, 16, SRC_PACKED, VK_FORMAT_UNDEFINED, 1300, model);
        }
    }
    build_case(300, 201, SHAPE_WILD, LRT_FORMAT_FLOAT32, 0, 16, SRC_PACKED, VK_FORMAT_UNDEFINED, 2600, LRT_THICKNESS_CONSTANT);
    build_case(512, 512, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 16, SRC_IMAGE, VK_FORMAT_D32_SFLOAT, 20000, LRT_THICKNESS_CONSTANT);
    build_case(514, 513, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 1, 16, SRC_PACKED, VK_FORMAT_UNDEFINED, 20000, LRT_THICKNESS_RELATIVE);
}

/* A quick loop's Vulkan test (make check): one build and trace of a
   buffer depth and of a constant-thickness tree on an image, the CPU's
   nodes and answers bit for bit, validation on. */
static void test_smoke(void)
{
    build_case(100, 37, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 0, SRC_OFFSET, VK_FORMAT_UNDEFINED, 2600, 0);
    build_case(64, 64, SHAPE_POLES, LRT_FORMAT_UNORM16, 1, 8, SRC_IMAGE, default_image_format(LRT_FORMAT_UNORM16, 1), 1300,
               LRT_THICKNESS_CONSTANT);
}

/* ---- (b) update == the CPU's update ---------------------------------------------------- */

/* thick: 0, or the constant or relative thickness model (b(d) refit in the kernels) */
static void update_case(lrt_format format, uint32_t bits, int source, uint32_t thick)
{
    const int w = 203, h = 131, frames = 12;
    float *d = (float *)malloc(sizeof(float) * w * h), *prev = (float *)malloc(sizeof(float) * w * h);
    void *bytes = malloc(sizeof(float) * w * h);
    lrt_depth dm;
    lrt_bvh live = {0};
    lrt_vk_bvh gpu = {0};
    lrt_build_options opt;
    gpu_depth g;
    char what[160];
    int frame, same_rect = 1, same_full = 1;
    dm = packed_depth(bytes, (uint32_t)w, (uint32_t)h, format);
    memset(&opt, 0, sizeof opt);
    opt.node_bits = bits;
    opt.thickness = thick;
    opt.thickness_value = thick == LRT_THICKNESS_CONSTANT ? 0.4f : 0.1f;
    opt.near_z = 0.1f;
    opt.far_z = 60.0f;
    snprintf(what, sizeof what, "update %dx%d fmt=%d nodes=%u %s%s", w, h, (int)format, bits, src_names[source],
             thick == LRT_THICKNESS_CONSTANT ? " constant thickness" : thick ? " relative thickness" : "");
    paint_frame(d, w, h, 0);
    lrt_vku_encode_depth(d, bytes, (size_t)w * h, format);
    CHECK(lrt_bvh_build(&live, &dm, &opt, NULL) == LRT_SUCCESS, "%s: CPU build", what);
    memset(&gpu, 0, sizeof gpu);
    if (gpu_depth_create(&dm, source, default_image_format(format, 1), &g) || (g.model = opt, 0) ||
        gpu_build(&dm, bits, &g, &gpu, what)) {
        CHECK(0, "%s: GPU set-up failed", what);
    } else {
        CHECK(same_nodes(&gpu, &live, what), "%s: GPU build of frame 0 differs", what);
        for (frame = 1; frame <= frames; ++frame) {
            lrt_rect rect;
            lrt_result r;
            memcpy(prev, d, sizeof(float) * w * h);
            paint_frame(d, w, h, frame);
            rect = changed_rect(prev, d, w, h);
            lrt_vku_encode_depth(d, bytes, (size_t)w * h, format);
            CHECK(lrt_bvh_update(&live, &dm, (frame & 1) ? NULL : &rect) == LRT_SUCCESS, "%s: CPU update", what);
            if (gpu_depth_write(&g, &dm, 0) || lrt_vku_begin(&g_t)) break;
            lrt_vku_compute_barrier(&g_t); /* the previous frame's refit -> this one */
            r = lrt_vk_cmd_update(g_ctx, g_t.cmd, &gpu, &g.depth, (frame & 1) ? NULL : &rect);
            CHECK(r == LRT_SUCCESS, "%s frame %d: lrt_vk_cmd_update: %s", what, frame, lrt_result_string(r));
            lrt_vku_host_barrier(&g_t);
            if (lrt_vku_submit(&g_t)) break;
            if (!same_nodes(&gpu, &live, what)) {
                if (frame & 1) same_full = 0;
                else same_rect = 0;
            }
        }
        CHECK(frame > frames, "%s: Vulkan failed at frame %d", what, frame);
        CHECK(same_full, "%s: update of the whole map differs from the CPU's", what);
        CHECK(same_rect, "%s: update of the dirty rect differs from the CPU's", what);
        { /* a rect that misses the change leaves the tree stale: the comparison can fail */
            lrt_rect elsewhere = {0, 0, 4, 4};
            lrt_bvh fresh = {0};
            paint_frame(d, w, h, 3);
            lrt_vku_encode_depth(d, bytes, (size_t)w * h, format);
            CHECK(lrt_bvh_build(&fresh, &dm, &opt, NULL) == LRT_SUCCESS, "CPU build");
            if (gpu_depth_write(&g, &dm, 0) == 0 && lrt_vku_begin(&g_t) == 0) {
                lrt_vku_compute_barrier(&g_t);
                lrt_vk_cmd_update(g_ctx, g_t.cmd, &gpu, &g.depth, &elsewhere);
                lrt_vku_host_barrier(&g_t);
                if (lrt_vku_submit(&g_t) == 0)
                    CHECK(memcmp(gpu.mapped, fresh.nodes, fresh.layout.bytes) != 0, "%s: a stale update went unnoticed", what);
            }
            lrt_bvh_destroy(&fresh);
        }
    }
    lrt_vk_bvh_destroy(g_ctx, &gpu);
    gpu_depth_destroy(&g);
    lrt_bvh_destroy(&live);
    free(d);
    free(prev);
    free(bytes);
}

static void test_update(void)
{
    update_case(LRT_FORMAT_FLOAT32, 16, SRC_OFFSET, 0);
    update_case(LRT_FORMAT_FLOAT32, 8, SRC_PACKED, 0);
    update_case(LRT_FORMAT_FLOAT32, 16, SRC_IMAGE, 0);
    update_case(LRT_FORMAT_UNORM16, 0, SRC_IMAGE, 0);
    update_case(LRT_FORMAT_UNORM8, 0, SRC_OFFSET, 0);
    update_case(LRT_FORMAT_FLOAT32, 16, SRC_OFFSET, LRT_THICKNESS_CONSTANT);
    update_case(LRT_FORMAT_UNORM16, 8, SRC_IMAGE, LRT_THICKNESS_RELATIVE);
    update_case(LRT_FORMAT_UNORM8, 0, SRC_PACKED, LRT_THICKNESS_CONSTANT);
}

/* ---- 2D dispatches: more than 65535 groups of 64 ------------------------------------- */
static void test_2d_dispatch(void)
{
    const uint64_t need = 65535ull * 64u + 1u; /* one invocation past a 1D dispatch */
    if (g_limits.maxComputeWorkGroupCount[0] > 65535u)
        printf("  note: maxComputeWorkGroupCount[0] = %u: the library still goes 2D past 65535 groups\n",
               g_limits.maxComputeWorkGroupCount[0]);
    { /* trace: primary rays over a 1024x1024 map, each texel 4 times */
        test_map m;
        lrt_bvh cpu = {0};
        lrt_vk_bvh gpu = {0};
        gpu_depth g;
        size_t n = (size_t)need, i, bad = 0;
        if (n * sizeof(lrt_ray) > g_limits.maxStorageBufferRange) {
            printf("  note: maxStorageBufferRange %u is too small for a 2D trace: skipped\n", g_limits.maxStorageBufferRange);
        } else {
            lrt_ray *rays = (lrt_ray *)malloc(sizeof(lrt_ray) * n);
            lrt_hit *cpu_hits = (lrt_hit *)malloc(sizeof(lrt_hit) * n), *gpu_hits = (lrt_hit *)malloc(sizeof(lrt_hit) * n);
            make_map(&m, 1024, 1024, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 0);
            lrt_bvh_build(&cpu, &m.depth, NULL, NULL);
            for (i = 0; i < n; ++i) {
                size_t texel = i % (1024u * 1024u);
                lrt_ray *r = &rays[i];
                memset(r, 0, sizeof *r);
                r->origin[0] = (float)(texel % 1024u) + 0.5f;
                r->origin[1] = (float)(texel / 1024u) + 0.5f;
                r->dir[2] = 1.0f;
                r->tmax = 1.0f;
            }
            lrt_trace(&cpu, &m.depth, rays, cpu_hits, n, 0);
            if (gpu_depth_create(&m.depth, SRC_PACKED, VK_FORMAT_UNDEFINED, &g) == 0 &&
                gpu_build(&m.depth, 0, &g, &gpu, "2D trace") == 0 &&
                gpu_trace(&gpu, &g, rays, gpu_hits, n, 0, 0, "2D trace") == 0) {
                for (i = 0; i < n; ++i) bad += memcmp(&gpu_hits[i], &cpu_hits[i], sizeof(lrt_hit)) != 0;
                CHECK(bad == 0, "2D trace of %zu primary rays: %zu differ from the CPU", n, bad);
            } else {
                CHECK(0, "2D trace: Vulkan failed");
            }
            lrt_vk_bvh_destroy(g_ctx, &gpu);
            gpu_depth_destroy(&g);
            lrt_bvh_destroy(&cpu);
            free_map(&m);
            free(rays);
            free(cpu_hits);
            free(gpu_hits);
        }
    }
    { /* refit: 8192x4096 texels have 2048x2048 level-1 nodes */
        const int w = 8192, h = 4096;
        VkDeviceSize nodes_bytes, counters_bytes;
        lrt_build_options opt;
        memset(&opt, 0, sizeof opt);
        opt.node_bits = 8;
        lrt_vk_bvh_buffer_sizes((uint32_t)w, (uint32_t)h, LRT_FORMAT_UNORM8, &opt, &nodes_bytes, &counters_bytes);
        if (nodes_bytes > g_limits.maxStorageBufferRange || counters_bytes > g_limits.maxStorageBufferRange ||
            (VkDeviceSize)w * h > g_limits.maxStorageBufferRange) {
            printf("  note: maxStorageBufferRange %u is too small for a 2D refit: skipped\n", g_limits.maxStorageBufferRange);
        } else {
            uint8_t *bytes = (uint8_t *)malloc((size_t)w * h);
            lrt_depth dm;
            lrt_bvh cpu = {0};
            lrt_vk_bvh gpu = {0};
            gpu_depth g;
            size_t i;
            for (i = 0; i < (size_t)w * h; ++i) bytes[i] = (uint8_t)(rnd() & 0xff);
            dm = packed_depth(bytes, (uint32_t)w, (uint32_t)h, LRT_FORMAT_UNORM8);
            lrt_bvh_build(&cpu, &dm, &opt, NULL);
            memset(&gpu, 0, sizeof gpu);
            if (gpu_depth_create(&dm, SRC_PACKED, VK_FORMAT_UNDEFINED, &g) == 0 && gpu_build(&dm, 8, &g, &gpu, "2D refit") == 0)
                CHECK(same_nodes(&gpu, &cpu, "2D refit 8192x4096"), "2D refit (8192x4096, 8-bit) differs from the CPU build");
            else
                CHECK(0, "2D refit: Vulkan failed");
            lrt_vk_bvh_destroy(g_ctx, &gpu);
            gpu_depth_destroy(&g);
            lrt_bvh_destroy(&cpu);
            free(bytes);
        }
    }
}

/* ---- (d) bad arguments ---------------------------------------------------------------- */
static VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL null_gipa(VkInstance instance, const char *name)
{
    (void)instance;
    (void)name;
    return NULL;
}

/* Those that need no device: checked before any Vulkan call. */
static void test_bad_arguments_no_device(void)
{
    lrt_vk_context_desc cd;
    lrt_vk_context *ctx = (lrt_vk_context *)&cd; /* a sentinel: must stay */
    lrt_vk_bvh_desc bd;
    lrt_vk_bvh bvh = {0};
    lrt_vk_depth depth;
    lrt_vku_device dev;
    lrt_vk_requirements req;
    VkDeviceSize a, b;
    lrt_rect rect = {0, 0, 1, 1};
    int fake;
    memset(&cd, 0, sizeof cd);
    memset(&bd, 0, sizeof bd);
    memset(&bvh, 0, sizeof bvh);
    memset(&depth, 0, sizeof depth);
    CHECK(lrt_vk_get_requirements(NULL) == LRT_ERROR_NULL_POINTER, "requirements to NULL");
    CHECK(lrt_vk_get_requirements(&req) == LRT_SUCCESS && req.api_version >= VK_API_VERSION_1_2 &&
              req.extension_count == 1 && strcmp(req.extensions[0], "VK_KHR_push_descriptor") == 0,
          "requirements");
    CHECK(lrt_vk_context_create(NULL, &ctx) == LRT_ERROR_NULL_POINTER, "context: null desc");
    CHECK(lrt_vk_context_create(&cd, NULL) == LRT_ERROR_NULL_POINTER, "context: null out");
    CHECK(lrt_vk_context_create(&cd, &ctx) == LRT_ERROR_NULL_POINTER, "context: empty desc");
    /* handles that look set but no getter; then a getter that finds nothing */
    cd.instance = (VkInstance)(void *)&fake;
    cd.physical_device = (VkPhysicalDevice)(void *)&fake;
    cd.device = (VkDevice)(void *)&fake;
    CHECK(lrt_vk_context_create(&cd, &ctx) == LRT_ERROR_NULL_POINTER, "context: no vkGetInstanceProcAddr");
    cd.get_instance_proc_addr = null_gipa;
    cd.flags = 4u;
    CHECK(lrt_vk_context_create(&cd, &ctx) == LRT_ERROR_INVALID_OPTION, "context: unknown flag");
    cd.flags = LRT_VK_TRACE_TWO_PASSES | LRT_VK_TRACE_ONE_PASS;
    CHECK(lrt_vk_context_create(&cd, &ctx) == LRT_ERROR_INVALID_OPTION, "context: one pass and two");
    cd.flags = 0;
    CHECK(lrt_vk_context_create(&cd, &ctx) == LRT_ERROR_MISSING_VULKAN_FEATURE, "context: functions not found");
    CHECK(ctx == (lrt_vk_context *)&cd, "context: *out written on error");
    lrt_vk_context_destroy(NULL);
    CHECK(lrt_vk_context_vk_result(NULL) == VK_SUCCESS, "vk_result of NULL");

    CHECK(lrt_vk_bvh_buffer_sizes(3, 2, LRT_FORMAT_FLOAT32, NULL, &a, &b) == LRT_SUCCESS && a == 16 && b == 4,
          "buffer sizes of 3x2 float (one node): %u %u", (unsigned)a, (unsigned)b);
    CHECK(lrt_vk_bvh_buffer_sizes(3, 2, LRT_FORMAT_UNORM8, NULL, &a, &b) == LRT_SUCCESS && a == 16 && b == 4,
          "buffer sizes of 3x2 unorm8 (one node, 16-bit codes: no parent for a compact one): %u %u", (unsigned)a,
          (unsigned)b);
    CHECK(lrt_vk_bvh_buffer_sizes(5, 2, LRT_FORMAT_UNORM8, NULL, &a, &b) == LRT_SUCCESS && a == 8 * 6 + 16 && b == 36,
          "buffer sizes of 5x2 unorm8 (8 compact level-1 slots and a root): %u %u", (unsigned)a, (unsigned)b);
    CHECK(lrt_vk_bvh_buffer_sizes(0, 2, LRT_FORMAT_FLOAT32, NULL, &a, &b) == LRT_ERROR_INVALID_SIZE, "buffer sizes: 0 wide");
    CHECK(lrt_vk_bvh_buffer_sizes(3, 2, (lrt_format)0, NULL, &a, &b) == LRT_ERROR_INVALID_FORMAT, "buffer sizes: format 0");
    { /* a back-map tree: a second code per slot */
        lrt_build_options thick;
        memset(&thick, 0, sizeof thick);
        thick.thickness = LRT_THICKNESS_BACK_MAP;
        CHECK(lrt_vk_bvh_buffer_sizes(3, 2, LRT_FORMAT_FLOAT32, &thick, &a, &b) == LRT_SUCCESS && a == 32 && b == 4,
              "buffer sizes: a back-map tree holds twice the nodes: %lu", (unsigned long)a);
    }
    CHECK(lrt_vk_bvh_buffer_sizes(3, 2, LRT_FORMAT_FLOAT32, NULL, NULL, &b) == LRT_ERROR_NULL_POINTER, "buffer sizes: NULL");
    CHECK(lrt_vk_bvh_create(NULL, &bd, &bvh) == LRT_ERROR_NULL_POINTER, "bvh: null context");
    lrt_vk_bvh_destroy(NULL, NULL);
    lrt_vk_bvh_destroy(NULL, &bvh);
    CHECK(lrt_vk_cmd_build(NULL, NULL, &bvh, &depth) == LRT_ERROR_NULL_POINTER, "build: null context");
    CHECK(lrt_vk_cmd_update(NULL, NULL, &bvh, &depth, &rect) == LRT_ERROR_NULL_POINTER, "update: null context");
    CHECK(lrt_vk_cmd_trace(NULL, NULL, &bvh, &depth, VK_NULL_HANDLE, 0, VK_NULL_HANDLE, 0, 1, 0) == LRT_ERROR_NULL_POINTER,
          "trace: null context");
    CHECK(lrt_vku_device_create(NULL, 0) == LRT_ERROR_NULL_POINTER, "device: null out");
    memset(&dev, 0x5a, sizeof dev);
    CHECK(lrt_vku_device_create(&dev, 0x80) == LRT_ERROR_INVALID_OPTION, "device: unknown flag");
    CHECK(lrt_vku_device_create(&dev, 4) == LRT_ERROR_INVALID_OPTION, "device: flag 4");
    CHECK(((unsigned char *)&dev)[0] == 0x5a, "device: written on a bad argument");
    lrt_vku_device_destroy(NULL);
    memset(&dev, 0, sizeof dev);
    lrt_vku_device_destroy(&dev); /* a zeroed one */
    CHECK(strcmp(lrt_result_string(LRT_ERROR_MISALIGNED), "unknown result code") != 0 &&
              strcmp(lrt_result_string(LRT_ERROR_VULKAN), "unknown result code") != 0,
          "result strings of the Vulkan codes");
}

static void test_bad_arguments(void)
{
    lrt_vk_bvh_desc bd, bad_bd;
    lrt_vk_bvh bvh = {0}, untouched = {0}, unbuilt = {0};
    lrt_vk_depth bad;
    gpu_depth g;
    lrt_vku_buffer rb, hb, own;
    lrt_rect rect;
    unsigned char sentinel[sizeof(lrt_vk_bvh)];
    float texels[6] = {0.5f, 0.5f, 0.5f, 0.5f, 0.25f, 0.5f};
    lrt_depth dm;
    const VkDeviceSize align = g_limits.minStorageBufferOffsetAlignment < 4 ? 4 : g_limits.minStorageBufferOffsetAlignment;
    VkCommandBuffer cmd;
    int k;
    dm = packed_depth(texels, 3, 2, LRT_FORMAT_FLOAT32);
    memset(&bd, 0, sizeof bd);
    bd.width = 3;
    bd.height = 2;
    bd.format = LRT_FORMAT_FLOAT32;
    bd.flags = LRT_VK_BVH_HOST_VISIBLE;
    memset(&untouched, 0xab, sizeof untouched);
    memcpy(sentinel, &untouched, sizeof sentinel);

#define EXPECT_CREATE(desc_ptr, code, what)                                                                   \
    do {                                                                                                      \
        lrt_result r_ = lrt_vk_bvh_create(g_ctx, desc_ptr, &untouched);                                       \
        CHECK(r_ == code, "bvh create, %s: got %s", what, lrt_result_string(r_));                             \
        CHECK(memcmp(&untouched, sentinel, sizeof sentinel) == 0, "%s: the lrt_vk_bvh was written", what);    \
    } while (0)
    EXPECT_CREATE(NULL, LRT_ERROR_NULL_POINTER, "null desc");
    CHECK(lrt_vk_bvh_create(g_ctx, &bd, NULL) == LRT_ERROR_NULL_POINTER, "bvh create: null out");
    bad_bd = bd; bad_bd.width = 0;
    EXPECT_CREATE(&bad_bd, LRT_ERROR_INVALID_SIZE, "zero width");
    bad_bd = bd; bad_bd.height = LINEAR_RT_MAX_DIM + 1;
    EXPECT_CREATE(&bad_bd, LRT_ERROR_INVALID_SIZE, "oversized height");
    bad_bd = bd; bad_bd.format = (lrt_format)4;
    EXPECT_CREATE(&bad_bd, LRT_ERROR_INVALID_FORMAT, "unknown format");
    bad_bd = bd; bad_bd.options.node_bits = 12;
    EXPECT_CREATE(&bad_bd, LRT_ERROR_INVALID_OPTION, "node bits 12");
    bad_bd = bd; bad_bd.flags = 0x10;
    EXPECT_CREATE(&bad_bd, LRT_ERROR_INVALID_OPTION, "unknown flag");
    bad_bd = bd; bad_bd.depth_flags = 2;
    EXPECT_CREATE(&bad_bd, LRT_ERROR_INVALID_OPTION, "unknown depth flag");
    if (lrt_vku_buffer_create(&g_t, 4096, &own)) return;
    bad_bd = bd; bad_bd.flags = 0; bad_bd.nodes = own.buffer;
    EXPECT_CREATE(&bad_bd, LRT_ERROR_NULL_POINTER, "nodes buffer without a counter buffer");
    bad_bd.counters = own.buffer; bad_bd.counters_offset = align + 2;
    EXPECT_CREATE(&bad_bd, LRT_ERROR_MISALIGNED, "misaligned counters");
    bad_bd.counters_offset = 2 * align; bad_bd.flags = LRT_VK_BVH_HOST_VISIBLE;
    EXPECT_CREATE(&bad_bd, LRT_ERROR_INVALID_OPTION, "host-visible flag with the caller's buffers");
    bad_bd = bd; bad_bd.width = bad_bd.height = 16384; bad_bd.flags = 0;
    {
        VkDeviceSize nb, cb;
        lrt_vk_bvh_buffer_sizes(16384, 16384, LRT_FORMAT_FLOAT32, NULL, &nb, &cb);
        if (nb > g_limits.maxStorageBufferRange) EXPECT_CREATE(&bad_bd, LRT_ERROR_LIMIT_EXCEEDED, "16384^2 past maxStorageBufferRange");
    }
#undef EXPECT_CREATE

    /* the caller's buffers: nodes and counters in one buffer at aligned offsets */
    bad_bd = bd; bad_bd.flags = 0;
    bad_bd.nodes = own.buffer; bad_bd.nodes_offset = align;
    bad_bd.counters = own.buffer; bad_bd.counters_offset = 4 * align;
    CHECK(lrt_vk_bvh_create(g_ctx, &bad_bd, &bvh) == LRT_SUCCESS && !bvh.mapped && bvh.memory == VK_NULL_HANDLE,
          "bvh in the caller's buffers");
    if (gpu_depth_create(&dm, SRC_PACKED, VK_FORMAT_UNDEFINED, &g)) return;
    if (lrt_vku_begin(&g_t)) return;
    memset(own.map, 0x77, (size_t)own.size);
    CHECK(lrt_vk_cmd_build(g_ctx, g_t.cmd, &bvh, &g.depth) == LRT_SUCCESS, "build in the caller's buffers");
    lrt_vku_host_barrier(&g_t);
    if (lrt_vku_submit(&g_t)) return;
    {
        lrt_bvh cpu = {0};
        const unsigned char *o = (const unsigned char *)own.map;
        lrt_bvh_build(&cpu, &dm, NULL, NULL);
        CHECK(memcmp(o + align, cpu.nodes, cpu.layout.bytes) == 0, "build in the caller's buffers == CPU build");
        CHECK(o[align - 1] == 0x77 && o[align + cpu.layout.bytes] == 0x77, "build wrote outside the node range");
        for (k = 0; k < (int)(cpu.layout.node_count * 4); ++k)
            if (o[4 * align + (size_t)k] != 0) break;
        CHECK(k == (int)(cpu.layout.node_count * 4), "counters are not 0 after a build");
        lrt_bvh_destroy(&cpu);
    }
    lrt_vk_bvh_destroy(g_ctx, &bvh);

    /* recording: every error records nothing (checked below by poisoning
       the nodes and submitting everything), the result codes are right */
    if (gpu_build(&dm, 0, &g, &bvh, "bad arguments")) return;
    if (lrt_vku_buffer_create(&g_t, 64 * sizeof(lrt_ray), &rb) || lrt_vku_buffer_create(&g_t, 64 * sizeof(lrt_hit), &hb)) return;
    memset(bvh.mapped, 0x3c, bvh.layout.bytes);
    memset(hb.map, 0x3c, (size_t)hb.size);
    memset(&unbuilt, 0, sizeof unbuilt);
    if (lrt_vku_begin(&g_t)) return;
    cmd = g_t.cmd;
#define EXPECT(call, code, what)                                                                               \
    do {                                                                                                       \
        lrt_result r_ = (call);                                                                                \
        CHECK(r_ == code, "%s: got %s, expected %s", what, lrt_result_string(r_), lrt_result_string(code));    \
    } while (0)
    EXPECT(lrt_vk_cmd_build(g_ctx, NULL, &bvh, &g.depth), LRT_ERROR_NULL_POINTER, "build: null command buffer");
    EXPECT(lrt_vk_cmd_build(g_ctx, cmd, NULL, &g.depth), LRT_ERROR_NULL_POINTER, "build: null bvh");
    EXPECT(lrt_vk_cmd_build(g_ctx, cmd, &bvh, NULL), LRT_ERROR_NULL_POINTER, "build: null depth");
    EXPECT(lrt_vk_cmd_build(g_ctx, cmd, &unbuilt, &g.depth), LRT_ERROR_INVALID_BVH, "build: bvh not created");
    EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &unbuilt, &g.depth, NULL), LRT_ERROR_INVALID_BVH, "update: bvh not created");
    bad = g.depth; bad.width = 4; bad.row_stride = 16;
    EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &bvh, &bad, NULL), LRT_ERROR_SIZE_MISMATCH, "update: another size");
    bad = g.depth; bad.height = 0;
    EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &bvh, &bad, NULL), LRT_ERROR_INVALID_SIZE, "update: zero height");
    bad = g.depth; bad.format = (lrt_format)9;
    EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &bvh, &bad, NULL), LRT_ERROR_INVALID_FORMAT, "update: unknown format");
    bad = g.depth; bad.flags = 6;
    EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &bvh, &bad, NULL), LRT_ERROR_INVALID_OPTION, "update: unknown depth flag");
    /* the format and Z direction the tree was created for: another map is refused, not misread */
    bad = g.depth; bad.format = LRT_FORMAT_UNORM16;
    EXPECT(lrt_vk_cmd_build(g_ctx, cmd, &bvh, &bad), LRT_ERROR_DEPTH_MISMATCH, "build: a 16-bit map on a float tree");
    EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &bvh, &bad, NULL), LRT_ERROR_DEPTH_MISMATCH, "update: a 16-bit map on a float tree");
    EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &bvh, &bad, rb.buffer, 0, hb.buffer, 0, 1, 0), LRT_ERROR_DEPTH_MISMATCH,
           "trace: a 16-bit map on a float tree");
    bad = g.depth; bad.format = LRT_FORMAT_UNORM8;
    EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &bvh, &bad, rb.buffer, 0, hb.buffer, 0, 1, 0), LRT_ERROR_DEPTH_MISMATCH,
           "trace: an 8-bit map on a float tree");
    bad = g.depth; bad.flags = LRT_DEPTH_REVERSED_Z;
    EXPECT(lrt_vk_cmd_build(g_ctx, cmd, &bvh, &bad), LRT_ERROR_DEPTH_MISMATCH, "build: the other Z direction");
    EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &bvh, &bad, rb.buffer, 0, hb.buffer, 0, 1, 0), LRT_ERROR_DEPTH_MISMATCH,
           "trace: the other Z direction");
    { /* create over a created tree is refused, the tree intact; garbage is no tree */
        lrt_vk_bvh before = bvh, junk;
        EXPECT(lrt_vk_bvh_create(g_ctx, &bd, &bvh), LRT_ERROR_ALREADY_BUILT, "create over a created tree");
        CHECK(memcmp(&before, &bvh, sizeof bvh) == 0, "a refused create left the tree as it was");
        memset(&junk, 0x5a, sizeof junk);
        EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &junk, &g.depth, rb.buffer, 0, hb.buffer, 0, 1, 0), LRT_ERROR_INVALID_BVH,
               "trace: a tree of garbage bytes");
        lrt_vk_bvh_destroy(g_ctx, &junk); /* destroys nothing it did not make */
    }
    { /* a tree created but never built: update and trace refuse it (its nodes are garbage until a build runs) */
        lrt_vk_bvh fresh;
        lrt_rect rect = {0, 0, 2, 2};
        memset(&fresh, 0, sizeof fresh);
        CHECK(lrt_vk_bvh_create(g_ctx, &bd, &fresh) == LRT_SUCCESS, "a second tree");
        EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &fresh, &g.depth, rb.buffer, 0, hb.buffer, 0, 1, 0), LRT_ERROR_INVALID_BVH,
               "trace: a tree never built");
        EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &fresh, &g.depth, rb.buffer, 0, hb.buffer, 0, 1, LRT_TRACE_BUDGET(8)),
               LRT_ERROR_INVALID_BVH, "trace with a budget: a tree never built");
        EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &fresh, &g.depth, NULL), LRT_ERROR_INVALID_BVH, "update: a tree never built");
        EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &fresh, &g.depth, &rect), LRT_ERROR_INVALID_BVH,
               "update of a rect: a tree never built");
        lrt_vk_bvh_destroy(g_ctx, &fresh);
    }
    { /* a tree of another VkDevice: refused before anything is recorded, both ways; destroy with the wrong
         context frees nothing, the right one frees it (the validation layer of both devices watches) */
        static lrt_vku_device other; /* stays put: its validation callback counts into it */
        lrt_vk_context *other_ctx = NULL;
        lrt_vk_bvh theirs, before;
        memset(&theirs, 0, sizeof theirs);
        CHECK(lrt_vku_device_create(&other, LRT_VKU_DEVICE_VALIDATION) == LRT_SUCCESS &&
                  lrt_vk_context_create(&other.desc, &other_ctx) == LRT_SUCCESS &&
                  lrt_vk_bvh_create(other_ctx, &bd, &theirs) == LRT_SUCCESS,
              "a second device, its context and a tree on it");
        if (other_ctx && theirs.created) {
            EXPECT(lrt_vk_cmd_build(g_ctx, cmd, &theirs, &g.depth), LRT_ERROR_CONTEXT_MISMATCH,
                   "build: a tree of another device");
            EXPECT(lrt_vk_cmd_trace(other_ctx, cmd, &bvh, &g.depth, rb.buffer, 0, hb.buffer, 0, 1, 0),
                   LRT_ERROR_CONTEXT_MISMATCH, "trace: a context of another device");
            EXPECT(lrt_vk_cmd_update(other_ctx, cmd, &bvh, &g.depth, NULL), LRT_ERROR_CONTEXT_MISMATCH,
                   "update: a context of another device");
            before = theirs;
            lrt_vk_bvh_destroy(g_ctx, &theirs);
            CHECK(memcmp(&before, &theirs, sizeof theirs) == 0, "destroy with another device's context left the tree");
            lrt_vk_bvh_destroy(other_ctx, &theirs);
            CHECK(theirs.created == 0, "destroy with its own context");
        }
        lrt_vk_context_destroy(other_ctx);
        lrt_vku_device_destroy(&other);
        CHECK(other.message_count == 0, "%u validation messages of the second device", other.message_count);
    }
    bad = g.depth; bad.buffer = VK_NULL_HANDLE;
    EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &bvh, &bad, NULL), LRT_ERROR_NULL_POINTER, "update: neither buffer nor view");
    bad = g.depth; /* any non-null view handle: rejected before use */
    memcpy(&bad.view, &g.depth.buffer, sizeof bad.view < sizeof g.depth.buffer ? sizeof bad.view : sizeof g.depth.buffer);
    EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &bvh, &bad, NULL), LRT_ERROR_INVALID_OPTION, "update: both buffer and view");
    bad = g.depth; bad.row_stride = 8;
    EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &bvh, &bad, NULL), LRT_ERROR_INVALID_STRIDE, "update: stride below a row");
    bad = g.depth; bad.row_stride = 14;
    EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &bvh, &bad, NULL), LRT_ERROR_MISALIGNED, "update: stride not a texel multiple");
    bad = g.depth; bad.offset = 2;
    EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &bvh, &bad, NULL), LRT_ERROR_MISALIGNED, "update: offset not a texel multiple");
    bad = g.depth; /* a whole number of texels past the limit (NVIDIA's limit is 2^32 - 1, not a texel multiple) */
    bad.row_stride = ((VkDeviceSize)g_limits.maxStorageBufferRange / 4u + 1u) * 4u;
    EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &bvh, &bad, NULL), LRT_ERROR_LIMIT_EXCEEDED, "update: span past the range limit");
    { /* thickness: the back map (a second lrt_vk_depth) exactly with a back-map tree, described as the depth is */
        lrt_vk_depth pair[2];
        lrt_vk_bvh_desc tbd = bd;
        lrt_vk_bvh thick = {0};
        pair[0] = g.depth;
        pair[0].back = &pair[1];
        pair[1] = g.depth;
        EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &bvh, pair, NULL), LRT_ERROR_THICKNESS_MISMATCH, "update: a back map, an infinite tree");
        tbd.options.thickness = LRT_THICKNESS_BACK_MAP;
        CHECK(lrt_vk_bvh_create(g_ctx, &tbd, &thick) == LRT_SUCCESS && thick.layout.bytes == 2 * bvh.layout.bytes,
              "a back-map tree on the GPU: twice the bytes");
        EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &thick, &g.depth, NULL), LRT_ERROR_THICKNESS_MISMATCH,
               "update: a back-map tree without its back map");
        EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &thick, &g.depth, rb.buffer, 0, hb.buffer, 0, 1, 0), LRT_ERROR_THICKNESS_MISMATCH,
               "trace: a back-map tree without its back map");
        pair[1].format = LRT_FORMAT_UNORM16;
        EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &thick, pair, NULL), LRT_ERROR_DEPTH_MISMATCH, "update: a back map of another format");
        pair[1] = g.depth; pair[1].width = 2;
        EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &thick, pair, NULL), LRT_ERROR_SIZE_MISMATCH, "update: a back map of another size");
        pair[1] = g.depth; pair[1].flags = LRT_DEPTH_REVERSED_Z;
        EXPECT(lrt_vk_cmd_build(g_ctx, cmd, &thick, pair), LRT_ERROR_DEPTH_MISMATCH, "build: a back map of the other Z direction");
        pair[1] = g.depth; pair[1].row_stride = 8;
        EXPECT(lrt_vk_cmd_build(g_ctx, cmd, &thick, pair), LRT_ERROR_INVALID_STRIDE, "build: a back map stride below a row");
        pair[1] = g.depth; pair[1].buffer = VK_NULL_HANDLE;
        memcpy(&pair[1].view, &g.depth.buffer, sizeof pair[1].view < sizeof g.depth.buffer ? sizeof pair[1].view : sizeof g.depth.buffer);
        pair[1].layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL; /* an image back map for a buffer depth: rejected before use */
        EXPECT(lrt_vk_cmd_build(g_ctx, cmd, &thick, pair), LRT_ERROR_INVALID_OPTION, "build: a buffer depth with an image back map");
        lrt_vk_bvh_destroy(g_ctx, &thick);
        /* constant thickness: no back map, and numbers it can use */
        tbd.options.thickness = LRT_THICKNESS_CONSTANT;
        tbd.options.thickness_value = 0.5f;
        tbd.options.near_z = 0.1f;
        tbd.options.far_z = 0.1f;
        EXPECT(lrt_vk_bvh_create(g_ctx, &tbd, &thick), LRT_ERROR_INVALID_THICKNESS, "create: far plane on the near plane");
        tbd.options.far_z = INFINITY;
        tbd.options.thickness_value = NAN;
        EXPECT(lrt_vk_bvh_create(g_ctx, &tbd, &thick), LRT_ERROR_INVALID_THICKNESS, "create: a NaN thickness");
        tbd.options.thickness_value = 0.5f;
        CHECK(lrt_vk_bvh_create(g_ctx, &tbd, &thick) == LRT_SUCCESS && thick.layout.bytes == 2 * bvh.layout.bytes,
              "a constant-thickness tree on the GPU: twice the bytes");
        pair[1] = g.depth;
        EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &thick, pair, NULL), LRT_ERROR_THICKNESS_MISMATCH,
               "update: a constant-thickness tree with a back map");
        EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &thick, pair, rb.buffer, 0, hb.buffer, 0, 1, 0), LRT_ERROR_THICKNESS_MISMATCH,
               "trace: a constant-thickness tree with a back map");
        lrt_vk_bvh_destroy(g_ctx, &thick);
    }
    rect.x = 2; rect.y = 0; rect.width = 2; rect.height = 1;
    EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &bvh, &g.depth, &rect), LRT_ERROR_INVALID_RECT, "update: rect past the edge");
    rect.x = 0; rect.y = 1; rect.width = 1; rect.height = 0xffffffffu;
    EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &bvh, &g.depth, &rect), LRT_ERROR_INVALID_RECT, "update: rect wrapping around");
    rect.x = 3; rect.y = 2; rect.width = 0; rect.height = 0;
    EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &bvh, &g.depth, &rect), LRT_SUCCESS, "update: empty rect (records nothing)");
    rect.x = 1; rect.y = 1; rect.width = 0; rect.height = 1;
    EXPECT(lrt_vk_cmd_update(g_ctx, cmd, &bvh, &g.depth, &rect), LRT_SUCCESS, "update: zero-width rect (records nothing)");
    EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 0, hb.buffer, 0, 1, 0x10000), LRT_ERROR_INVALID_OPTION,
           "trace: unknown flag");
    EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 0, hb.buffer, 0, 1, LRT_TRACE_BUDGET(LRT_TRACE_BUDGET_MAX + 1u)),
           LRT_ERROR_INVALID_OPTION, "trace: a budget past LRT_TRACE_BUDGET_MAX");
    EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 0, hb.buffer, 0, 1, LRT_TRACE_FINISH(2)),
           LRT_ERROR_INVALID_OPTION, "trace: a finish without a budget");
    EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 0, hb.buffer, 0, 1, LRT_TRACE_BUDGET(3) | LRT_TRACE_FINISH(8)),
           LRT_ERROR_INVALID_OPTION, "trace: a finish of 2^8 samples");
    EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 0, hb.buffer, 0, LINEAR_RT_MAX_RAYS_PER_CALL + 1u, 0),
           LRT_ERROR_TOO_MANY_RAYS, "trace: too many rays");
    EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &bvh, &g.depth, VK_NULL_HANDLE, 0, hb.buffer, 0, 1, 0), LRT_ERROR_NULL_POINTER,
           "trace: null ray buffer");
    EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 0, VK_NULL_HANDLE, 0, 1, 0), LRT_ERROR_NULL_POINTER,
           "trace: null hit buffer");
    EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 0, hb.buffer, 0, 0, 0), LRT_SUCCESS,
           "trace: no rays (records nothing)");
    if (align >= 64) /* no ray index f makes both 32 - 32f and 48 - 16f multiples of the alignment */
        EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 32, hb.buffer, 48, 1, 0), LRT_ERROR_MISALIGNED,
               "trace: ray 1 into hit 3");
    if (align > 4) {
        EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 4, hb.buffer, 0, 1, 0), LRT_ERROR_MISALIGNED,
               "trace: ray offset 4");
        EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 0, hb.buffer, 8, 1, 0), LRT_ERROR_MISALIGNED,
               "trace: hit offset 8");
    }
    if ((VkDeviceSize)(g_limits.maxStorageBufferRange / sizeof(lrt_ray)) < LINEAR_RT_MAX_RAYS_PER_CALL)
        EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 0, hb.buffer, 0,
                                g_limits.maxStorageBufferRange / (uint32_t)sizeof(lrt_ray) + 1u, 0),
               LRT_ERROR_LIMIT_EXCEEDED, "trace: rays past maxStorageBufferRange");
    { /* a compacted trace's scratch: each misuse returns before anything is recorded */
        lrt_vk_scratch sc;
        sc.buffer = hb.buffer;
        sc.offset = 0;
        sc.size = lrt_vk_trace_scratch_size(2);
        EXPECT(lrt_vk_cmd_trace_compacted(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 0, hb.buffer, 0, 2, 0, NULL),
               LRT_ERROR_NULL_POINTER, "compacted trace: no scratch");
        sc.buffer = VK_NULL_HANDLE;
        EXPECT(lrt_vk_cmd_trace_compacted(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 0, hb.buffer, 0, 2, 0, &sc),
               LRT_ERROR_NULL_POINTER, "compacted trace: a null scratch buffer");
        sc.buffer = hb.buffer;
        sc.size -= 16;
        EXPECT(lrt_vk_cmd_trace_compacted(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 0, hb.buffer, 0, 2, 0, &sc),
               LRT_ERROR_BUFFER_TOO_SMALL, "compacted trace: scratch 16 bytes short");
        sc.size += 16;
        if (align > 4) {
            sc.offset = 4;
            EXPECT(lrt_vk_cmd_trace_compacted(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 0, hb.buffer, 0, 2, 0, &sc),
                   LRT_ERROR_MISALIGNED, "compacted trace: scratch offset 4");
            sc.offset = 0;
        }
        EXPECT(lrt_vk_cmd_trace_compacted(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 0, hb.buffer, 0, 2, 0x10000, &sc),
               LRT_ERROR_INVALID_OPTION, "compacted trace: unknown flag");
        EXPECT(lrt_vk_cmd_trace_compacted(g_ctx, cmd, &bvh, &g.depth, rb.buffer, 0, hb.buffer, 0, 0, 0, NULL), LRT_SUCCESS,
               "compacted trace: no rays (records nothing, needs no scratch)");
    }
    bad = g.depth; bad.buffer = VK_NULL_HANDLE;
    memcpy(&bad.view, &g.depth.buffer, sizeof bad.view < sizeof g.depth.buffer ? sizeof bad.view : sizeof g.depth.buffer);
    bad.layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    EXPECT(lrt_vk_cmd_trace(g_ctx, cmd, &bvh, &bad, rb.buffer, 0, hb.buffer, 0, 1, 0), LRT_ERROR_INVALID_OPTION,
           "trace: an image in a layout the kernels cannot read");
#undef EXPECT
    lrt_vku_host_barrier(&g_t);
    if (lrt_vku_submit(&g_t)) return;
    {
        const unsigned char *n = (const unsigned char *)bvh.mapped, *h = (const unsigned char *)hb.map;
        size_t i, touched = 0;
        for (i = 0; i < bvh.layout.bytes; ++i) touched += n[i] != 0x3c;
        for (i = 0; i < hb.size; ++i) touched += h[i] != 0x3c;
        CHECK(touched == 0, "erroring or empty calls recorded work: %zu bytes changed", touched);
    }
    lrt_vku_buffer_destroy(&g_t, &rb);
    lrt_vku_buffer_destroy(&g_t, &hb);
    lrt_vku_buffer_destroy(&g_t, &own);
    lrt_vk_bvh_destroy(g_ctx, &bvh);
    CHECK(bvh.created == 0 && bvh.memory == VK_NULL_HANDLE, "destroy zeroes the lrt_vk_bvh");
    lrt_vk_bvh_destroy(g_ctx, &bvh); /* twice is harmless */
    gpu_depth_destroy(&g);
}

/* ---- device limits, on contexts that see smaller ones ---------------------------------
   lavapipe's own limits (maxStorageBufferRange 128 MiB, maxComputeWorkGroupCount
   65535, maxImageDimension2D 16384) are reached here only by the range, in
   test_bad_arguments (16384^2 nodes, rays past 128 MiB). A context reads the
   limits once, at create, through the vkGetPhysicalDeviceProperties its
   vkGetInstanceProcAddr gives: a getter that gives a wrapper lowering them
   makes a small device out of the real one, with the public API alone (no
   test hook in linear_rt.h). Past a lowered limit every call must return
   LRT_ERROR_LIMIT_EXCEEDED and record nothing; within them the answers must
   still be the CPU's (a 2D dispatch of 4x2 groups, say), and the validation
   layer, which knows the real limits, sees every command recorded. */
static PFN_vkGetInstanceProcAddr g_real_gipa;
static PFN_vkGetPhysicalDeviceProperties g_real_properties;
static uint32_t g_low_range, g_low_groups_x, g_low_groups_y, g_low_image, g_low_texels; /* 0: the real limit */
static VkDeviceSize g_high_texel_align; /* 0: the real minTexelBufferOffsetAlignment */

static VKAPI_ATTR void VKAPI_CALL low_properties(VkPhysicalDevice pd, VkPhysicalDeviceProperties *p)
{
    g_real_properties(pd, p);
    if (g_low_range) p->limits.maxStorageBufferRange = g_low_range;
    if (g_low_groups_x) p->limits.maxComputeWorkGroupCount[0] = g_low_groups_x;
    if (g_low_groups_y) p->limits.maxComputeWorkGroupCount[1] = g_low_groups_y;
    if (g_low_image) p->limits.maxImageDimension2D = g_low_image;
    if (g_low_texels) p->limits.maxTexelBufferElements = g_low_texels;
    if (g_high_texel_align) p->limits.minTexelBufferOffsetAlignment = g_high_texel_align;
}

static VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL low_gipa(VkInstance instance, const char *name)
{
    if (strcmp(name, "vkGetPhysicalDeviceProperties") == 0) return (PFN_vkVoidFunction)low_properties;
    return g_real_gipa(instance, name);
}

/* A context on g_dev's device whose limits read as these (0: the real one). */
static lrt_vk_context *low_context(uint32_t range, uint32_t groups_x, uint32_t groups_y, uint32_t image,
                                   uint32_t texels)
{
    lrt_vk_context_desc cd = g_dev.desc;
    lrt_vk_context *ctx = NULL;
    lrt_result r;
    g_real_gipa = g_dev.desc.get_instance_proc_addr;
    g_real_properties =
        (PFN_vkGetPhysicalDeviceProperties)g_real_gipa(g_dev.desc.instance, "vkGetPhysicalDeviceProperties");
    g_low_range = range;
    g_low_groups_x = groups_x;
    g_low_groups_y = groups_y;
    g_low_image = image;
    g_low_texels = texels;
    cd.get_instance_proc_addr = low_gipa;
    r = g_real_properties ? lrt_vk_context_create(&cd, &ctx) : LRT_ERROR_MISSING_VULKAN_FEATURE;
    CHECK(r == LRT_SUCCESS, "context with lowered limits (range %u, groups %ux%u, image %u, texels %u): %s", range,
          groups_x, groups_y, image, texels, lrt_result_string(r));
    return r == LRT_SUCCESS ? ctx : NULL;
}

/* Traces rays[0..n) from rb into hb with ctx (after a barrier for earlier
   submissions) and compares hb with the CPU's hits. */
static void limits_trace(lrt_vk_context *ctx, const lrt_vk_bvh *bvh, const lrt_vk_depth *depth, lrt_vku_buffer *rb,
                         lrt_vku_buffer *hb, const lrt_hit *cpu_hits, uint32_t n, const char *what)
{
    const lrt_hit *gpu = (const lrt_hit *)hb->map;
    lrt_result r;
    uint32_t i, differ = 0;
    memset(hb->map, 0xff, (size_t)hb->size);
    if (lrt_vku_begin(&g_t)) return;
    lrt_vku_compute_barrier(&g_t);
    r = lrt_vk_cmd_trace(ctx, g_t.cmd, bvh, depth, rb->buffer, 0, hb->buffer, 0, n, 0);
    CHECK(r == LRT_SUCCESS, "%s: %s", what, lrt_result_string(r));
    lrt_vku_host_barrier(&g_t);
    if (lrt_vku_submit(&g_t)) return;
    for (i = 0; i < n; ++i) differ += !same_answer(&gpu[i], &cpu_hits[i]);
    CHECK(differ == 0, "%s: %u of %u answers differ from the CPU's", what, differ, n);
}

/* Records build (dirty == NULL) or update of dirty with ctx, submits, and
   compares the nodes with the CPU's. */
static void limits_refit(lrt_vk_context *ctx, lrt_vk_bvh *bvh, const lrt_vk_depth *depth, const lrt_rect *dirty,
                         const lrt_bvh *cpu, const char *what)
{
    lrt_result r;
    if (lrt_vku_begin(&g_t)) return;
    lrt_vku_compute_barrier(&g_t);
    r = dirty ? lrt_vk_cmd_update(ctx, g_t.cmd, bvh, depth, dirty) : lrt_vk_cmd_build(ctx, g_t.cmd, bvh, depth);
    CHECK(r == LRT_SUCCESS, "%s: %s", what, lrt_result_string(r));
    lrt_vku_host_barrier(&g_t);
    if (lrt_vku_submit(&g_t)) return;
    CHECK(same_nodes(bvh, cpu, what), "%s: nodes differ from the CPU build", what);
}

static void test_device_limits(void)
{
    enum { NRAYS = 600 };
    test_map m, wide;
    lrt_bvh cpu = {0}, cpu_wide = {0};
    lrt_vk_bvh bvh = {0}, bvh_wide = {0}, untouched = {0}, fits = {0};
    lrt_vk_bvh_desc bd;
    gpu_depth buf, img, wbuf;
    lrt_vku_buffer rb, hb;
    lrt_hit cpu_hits[NRAYS];
    lrt_ray *rays;
    VkDeviceSize nodes_bytes, counters_bytes, texel_align;
    lrt_vku_buffer own;
    lrt_vk_context *range_ctx, *span_ctx, *group_ctx, *image_ctx, *texel_ctx;
    unsigned char sentinel[sizeof(lrt_vk_bvh)];
    const VkFormat image_format = default_image_format(LRT_FORMAT_FLOAT32, 1);
    lrt_rect rect;
    uint32_t i, span_rays;
    VkCommandBuffer cmd;

    make_map(&m, 64, 64, SHAPE_SCENE, LRT_FORMAT_FLOAT32, 0, 0);
    make_map(&wide, 520, 64, SHAPE_TERRACES, LRT_FORMAT_FLOAT32, 0, 0);
    lrt_bvh_build(&cpu, &m.depth, NULL, NULL);
    lrt_bvh_build(&cpu_wide, &wide.depth, NULL, NULL);
    lrt_vk_bvh_buffer_sizes(64, 64, LRT_FORMAT_FLOAT32, NULL, &nodes_bytes, &counters_bytes);
    /* 64x64 float: 9360 node bytes, 2340 counter bytes, 16384 depth bytes */
    CHECK(nodes_bytes > counters_bytes && nodes_bytes < 64u * 64u * 4u, "64x64: %u node bytes, %u counter bytes",
          (unsigned)nodes_bytes, (unsigned)counters_bytes);
    span_rays = (uint32_t)(nodes_bytes / sizeof(lrt_ray)); /* the most rays a range of nodes_bytes holds */
    memset(&bvh, 0, sizeof bvh);
    memset(&bvh_wide, 0, sizeof bvh_wide);
    memset(&buf, 0, sizeof buf);
    memset(&img, 0, sizeof img);
    memset(&wbuf, 0, sizeof wbuf);
    memset(&rb, 0, sizeof rb);
    memset(&hb, 0, sizeof hb);
    memset(&own, 0, sizeof own);
    rays = (lrt_ray *)malloc(sizeof(lrt_ray) * NRAYS);
    range_ctx = low_context((uint32_t)nodes_bytes - 16u, 0, 0, 0, 0); /* the 64x64 float tree does not fit */
    span_ctx = low_context((uint32_t)nodes_bytes, 0, 0, 0, 0);         /* the tree fits, its float depth does not */
    group_ctx = low_context(0, 4, 2, 0, 0);                            /* 8 groups of 64: 512 rays or level-1 nodes */
    image_ctx = low_context(0, 0, 0, 32, 0);                           /* no 64x64 image */
    /* 256 texel-buffer elements: the 64x64 tree's 585 nodes do not fit; and
       texel views at multiples of 4 storage alignments */
    texel_align = 4u * g_limits.minStorageBufferOffsetAlignment;
    if (texel_align < 64u) texel_align = 64u;
    if (texel_align < g_limits.minTexelBufferOffsetAlignment) texel_align = g_limits.minTexelBufferOffsetAlignment;
    g_high_texel_align = texel_align;
    texel_ctx = low_context(0, 0, 0, 0, 256);
    g_high_texel_align = 0;
    if (!rays || !range_ctx || !span_ctx || !group_ctx || !image_ctx || !texel_ctx ||
        !lrt_vku_format_sampled(&g_t, image_format) ||
        gpu_depth_create(&m.depth, SRC_PACKED, VK_FORMAT_UNDEFINED, &buf) ||
        gpu_depth_create(&m.depth, SRC_IMAGE, image_format, &img) ||
        gpu_depth_create(&wide.depth, SRC_PACKED, VK_FORMAT_UNDEFINED, &wbuf) ||
        gpu_build(&m.depth, 0, &buf, &bvh, "limits 64x64") || gpu_build(&wide.depth, 0, &wbuf, &bvh_wide, "limits 520x64") ||
        lrt_vku_buffer_create(&g_t, NRAYS * sizeof(lrt_ray), &rb) || lrt_vku_buffer_create(&g_t, NRAYS * sizeof(lrt_hit), &hb)) {
        CHECK(0, "device limits: set-up failed");
        goto done;
    }
    for (i = 0; i < NRAYS; ++i) rays[i] = make_ray(&m, (int)(i % RAY_KIND_COUNT));
    memcpy(rb.map, rays, NRAYS * sizeof(lrt_ray));
    lrt_trace(&cpu, &m.depth, rays, cpu_hits, NRAYS, 0);

    /* creating: a tree past the range is refused, a smaller one fits */
    memset(&bd, 0, sizeof bd);
    bd.width = 64;
    bd.height = 64;
    bd.format = LRT_FORMAT_FLOAT32;
    memset(&untouched, 0xab, sizeof untouched);
    memcpy(sentinel, &untouched, sizeof sentinel);
    CHECK(lrt_vk_bvh_create(range_ctx, &bd, &untouched) == LRT_ERROR_LIMIT_EXCEEDED, "create: nodes past the range");
    CHECK(memcmp(&untouched, sentinel, sizeof sentinel) == 0, "create past the range: the lrt_vk_bvh was written");
    bd.format = LRT_FORMAT_UNORM8; /* 8-bit nodes: about a third of the bytes */
    CHECK(lrt_vk_bvh_create(range_ctx, &bd, &fits) == LRT_SUCCESS, "create: 8-bit nodes within the range");
    lrt_vk_bvh_destroy(range_ctx, &fits);

    /* recording past a limit: the result code, and nothing recorded (the
       trees and hits are poisoned and must stay so after the submission) */
    memset(bvh.mapped, 0x3c, bvh.layout.bytes);
    memset(bvh_wide.mapped, 0x3c, bvh_wide.layout.bytes);
    memset(hb.map, 0x3c, (size_t)hb.size);
    if (lrt_vku_begin(&g_t)) goto done;
    cmd = g_t.cmd;
    rect.x = 0; rect.y = 0; rect.width = 8; rect.height = 8;
#define EXPECT_LIMIT(call, what)                                                                                \
    do {                                                                                                        \
        lrt_result r_ = (call);                                                                                 \
        CHECK(r_ == LRT_ERROR_LIMIT_EXCEEDED, "%s: got %s", what, lrt_result_string(r_));                       \
    } while (0)
    EXPECT_LIMIT(lrt_vk_cmd_build(range_ctx, cmd, &bvh, &buf.depth), "build: nodes past the range");
    EXPECT_LIMIT(lrt_vk_cmd_update(range_ctx, cmd, &bvh, &img.depth, NULL), "update: nodes past the range");
    EXPECT_LIMIT(lrt_vk_cmd_trace(range_ctx, cmd, &bvh, &img.depth, rb.buffer, 0, hb.buffer, 0, 1, 0),
                 "trace: nodes past the range");
    EXPECT_LIMIT(lrt_vk_cmd_build(span_ctx, cmd, &bvh, &buf.depth), "build: depth buffer past the range");
    EXPECT_LIMIT(lrt_vk_cmd_update(span_ctx, cmd, &bvh, &buf.depth, &rect), "update: depth buffer past the range");
    EXPECT_LIMIT(lrt_vk_cmd_trace(span_ctx, cmd, &bvh, &buf.depth, rb.buffer, 0, hb.buffer, 0, 1, 0),
                 "trace: depth buffer past the range");
    EXPECT_LIMIT(lrt_vk_cmd_trace(span_ctx, cmd, &bvh, &img.depth, rb.buffer, 0, hb.buffer, 0, span_rays + 1u, 0),
                 "trace: rays past the range");
    EXPECT_LIMIT(lrt_vk_cmd_trace(group_ctx, cmd, &bvh, &buf.depth, rb.buffer, 0, hb.buffer, 0, 8u * 64u + 1u, 0),
                 "trace: 513 rays, 9 groups past 4x2");
    EXPECT_LIMIT(lrt_vk_cmd_build(group_ctx, cmd, &bvh_wide, &wbuf.depth), "build: 520x64, 9 groups past 4x2");
    EXPECT_LIMIT(lrt_vk_cmd_update(group_ctx, cmd, &bvh_wide, &wbuf.depth, NULL), "update: 520x64, 9 groups past 4x2");
    EXPECT_LIMIT(lrt_vk_cmd_build(image_ctx, cmd, &bvh, &img.depth), "build: 64x64 image past 32");
    EXPECT_LIMIT(lrt_vk_cmd_update(image_ctx, cmd, &bvh, &img.depth, &rect), "update: 64x64 image past 32");
    EXPECT_LIMIT(lrt_vk_cmd_trace(image_ctx, cmd, &bvh, &img.depth, rb.buffer, 0, hb.buffer, 0, 1, 0),
                 "trace: 64x64 image past 32");
#undef EXPECT_LIMIT
    lrt_vku_host_barrier(&g_t);
    if (lrt_vku_submit(&g_t)) goto done;
    {
        const unsigned char *a = (const unsigned char *)bvh.mapped, *b = (const unsigned char *)bvh_wide.mapped,
                            *h = (const unsigned char *)hb.map;
        size_t k, touched = 0;
        for (k = 0; k < bvh.layout.bytes; ++k) touched += a[k] != 0x3c;
        for (k = 0; k < bvh_wide.layout.bytes; ++k) touched += b[k] != 0x3c;
        for (k = 0; k < hb.size; ++k) touched += h[k] != 0x3c;
        CHECK(touched == 0, "calls past a limit recorded work: %zu bytes changed", touched);
    }

    /* within the lowered limits: the CPU's trees and answers */
    limits_refit(span_ctx, &bvh, &img.depth, NULL, &cpu, "build from an image, range = the nodes");
    limits_trace(span_ctx, &bvh, &img.depth, &rb, &hb, cpu_hits, span_rays, "trace of as many rays as the range holds");
    limits_refit(group_ctx, &bvh, &buf.depth, NULL, &cpu, "build in 4x2 groups");
#ifndef TEST_HLSL /* the HLSL kernel works out rows of 65535 groups, not rows of a lowered limit */
    limits_trace(group_ctx, &bvh, &buf.depth, &rb, &hb, cpu_hits, 8u * 64u, "trace of 512 rays in 4x2 groups");
#endif
    limits_refit(g_ctx, &bvh_wide, &wbuf.depth, NULL, &cpu_wide, "build 520x64");
    rect.x = 8; rect.y = 0; rect.width = 512; rect.height = 64; /* 512 level-2 nodes (8x8 texels each): 4x2 groups */
    limits_refit(group_ctx, &bvh_wide, &wbuf.depth, &rect, &cpu_wide, "update of 64x64 texels in 4x2 groups");
    limits_refit(image_ctx, &bvh, &buf.depth, NULL, &cpu, "build from a buffer, images up to 32");
    limits_trace(image_ctx, &bvh, &buf.depth, &rb, &hb, cpu_hits, NRAYS, "trace from a buffer, images up to 32");
    /* texel buffers too small for the largest tree: the trace reads the
       nodes' storage buffer, through a tree made in that context (its texel
       view clipped to 256 nodes) and one made in g_ctx */
    bd.format = LRT_FORMAT_FLOAT32;
    if (lrt_vku_buffer_create(&g_t, 8u * (nodes_bytes + texel_align), &own)) goto done;
    bd.nodes = bd.counters = own.buffer;
    bd.counters_offset = ((2u * texel_align + nodes_bytes) / texel_align + 1u) * texel_align;
    bd.nodes_offset = g_limits.minStorageBufferOffsetAlignment < 16u ? 16u : g_limits.minStorageBufferOffsetAlignment;
    CHECK(lrt_vk_bvh_create(texel_ctx, &bd, &untouched) == LRT_ERROR_MISALIGNED,
          "create: nodes at a storage alignment but not a texel one");
    CHECK(memcmp(&untouched, sentinel, sizeof sentinel) == 0, "create, misaligned: the lrt_vk_bvh was written");
    bd.nodes_offset = 2u * texel_align;
    CHECK(lrt_vk_bvh_create(texel_ctx, &bd, &fits) == LRT_SUCCESS, "create: nodes at a texel alignment");
    lrt_vk_bvh_destroy(texel_ctx, &fits);
    bd.nodes = bd.counters = VK_NULL_HANDLE;
    bd.nodes_offset = bd.counters_offset = 0;
    bd.flags = LRT_VK_BVH_HOST_VISIBLE;
    CHECK(lrt_vk_bvh_create(texel_ctx, &bd, &fits) == LRT_SUCCESS, "create: 585 nodes, 256 texel-buffer elements");
    limits_refit(texel_ctx, &fits, &img.depth, NULL, &cpu, "build, 256 texel-buffer elements");
    limits_trace(texel_ctx, &fits, &img.depth, &rb, &hb, cpu_hits, NRAYS, "trace, 256 texel-buffer elements");
    limits_trace(texel_ctx, &bvh, &buf.depth, &rb, &hb, cpu_hits, NRAYS,
                 "trace of g_ctx's tree, 256 texel-buffer elements");
    lrt_vk_bvh_destroy(texel_ctx, &fits);

done:
    lrt_vku_buffer_destroy(&g_t, &rb);
    lrt_vku_buffer_destroy(&g_t, &hb);
    lrt_vku_buffer_destroy(&g_t, &own);
    lrt_vk_bvh_destroy(g_ctx, &bvh);
    lrt_vk_bvh_destroy(g_ctx, &bvh_wide);
    gpu_depth_destroy(&buf);
    gpu_depth_destroy(&img);
    gpu_depth_destroy(&wbuf);
    lrt_vk_context_destroy(range_ctx);
    lrt_vk_context_destroy(span_ctx);
    lrt_vk_context_destroy(group_ctx);
    lrt_vk_context_destroy(image_ctx);
    lrt_vk_context_destroy(texel_ctx);
    lrt_bvh_destroy(&cpu);
    lrt_bvh_destroy(&cpu_wide);
    free_map(&m);
    free_map(&wide);
    free(rays);
}

/* ---- a context with VkAllocationCallbacks and no vkGetDeviceProcAddr ------------------- */
static int g_host_allocs, g_host_frees;
typedef struct host_header { void *raw; size_t size; } host_header; /* 16 bytes, just before the block */

static void *host_block(size_t size, size_t align)
{
    const size_t a = align < sizeof(host_header) ? sizeof(host_header) : align; /* powers of two */
    unsigned char *raw = (unsigned char *)malloc(size + a + sizeof(host_header));
    uintptr_t p;
    host_header *h;
    if (!raw) return NULL;
    p = ((uintptr_t)raw + sizeof(host_header) + a - 1) & ~(uintptr_t)(a - 1);
    h = (host_header *)p - 1;
    h->raw = raw;
    h->size = size;
    ++g_host_allocs;
    return (void *)p;
}

static void host_release(void *p)
{
    if (!p) return;
    ++g_host_frees;
    free(((host_header *)p - 1)->raw);
}

static VKAPI_ATTR void *VKAPI_CALL host_alloc(void *user, size_t size, size_t align, VkSystemAllocationScope scope)
{
    (void)user;
    (void)scope;
    return host_block(size, align);
}

static VKAPI_ATTR void *VKAPI_CALL host_realloc(void *user, void *p, size_t size, size_t align, VkSystemAllocationScope scope)
{
    void *q;
    (void)user;
    (void)scope;
    if (!p) return host_block(size, align);
    if (size == 0) {
        host_release(p);
        return NULL;
    }
    q = host_block(size, align);
    if (!q) return NULL;
    memcpy(q, p, ((host_header *)p - 1)->size < size ? ((host_header *)p - 1)->size : size);
    host_release(p);
    return q;
}

static VKAPI_ATTR void VKAPI_CALL host_free(void *user, void *p)
{
    (void)user;
    host_release(p);
}

static void test_context_options(void)
{
    lrt_vk_context_desc cd = g_dev.desc;
    VkAllocationCallbacks cb;
    lrt_vk_context *ctx = NULL;
    VkResult vr = VK_SUCCESS;
    lrt_result r;
    memset(&cb, 0, sizeof cb);
    cb.pfnAllocation = host_alloc;
    cb.pfnReallocation = host_realloc;
    cb.pfnFree = host_free;
    cd.allocation_callbacks = &cb;
    cd.get_device_proc_addr = NULL; /* from vkGetInstanceProcAddr */
    cd.vk_result = &vr;
    r = lrt_vk_context_create(&cd, &ctx);
    CHECK(r == LRT_SUCCESS && g_host_allocs > 0, "context with allocation callbacks: %s, %d allocations",
          lrt_result_string(r), g_host_allocs);
    if (r == LRT_SUCCESS) {
        lrt_vk_bvh bvh = {0};
        lrt_vk_bvh_desc bd;
        memset(&bd, 0, sizeof bd);
        bd.width = 100;
        bd.height = 50;
        bd.format = LRT_FORMAT_UNORM16;
        CHECK(lrt_vk_bvh_create(ctx, &bd, &bvh) == LRT_SUCCESS, "bvh with allocation callbacks");
        lrt_vk_bvh_destroy(ctx, &bvh);
        lrt_vk_context_destroy(ctx);
        CHECK(g_host_allocs == g_host_frees, "allocation callbacks: %d allocations, %d frees", g_host_allocs, g_host_frees);
    }
}

/* where GPU and CPU answers differ (a texel corner or edge, t rounding),
   both are right by the reference unless counted as wrong */
/* a device of ours without VK_KHR_push_descriptor: the context refuses it */
static void test_device_without_extension(void)
{
    const lrt_vk_context_desc *d = &g_dev.desc;
    PFN_vkCreateDevice create = (PFN_vkCreateDevice)d->get_instance_proc_addr(d->instance, "vkCreateDevice");
    PFN_vkDestroyDevice destroy;
    lrt_vk_context_desc cd = *d;
    lrt_vk_context *ctx = NULL;
    VkDevice bare;
    if (!create || lrt_vku_create_vk_device(create, d->physical_device, g_dev.queue_family, NULL, NULL, 0, &bare) != VK_SUCCESS) {
        CHECK(0, "could not create a second device");
        return;
    }
    cd.device = bare;
    CHECK(lrt_vk_context_create(&cd, &ctx) == LRT_ERROR_MISSING_VULKAN_FEATURE && ctx == NULL,
          "context on a device without VK_KHR_push_descriptor enabled");
    destroy = (PFN_vkDestroyDevice)d->get_device_proc_addr(bare, "vkDestroyDevice");
    if (destroy) destroy(bare, NULL);
}

static void print_trace_summary(void)
{
    int k;
    printf("trace: %zu GPU answers judged; of the closest-hit ones %zu differ from the CPU's (kind, texel, or t "
           "past 1e-5*(1+|t|)), and %zu answers are wrong by the reference\n",
           g_trace_total.rays, g_trace_total.differ, g_trace_total.wrong);
    printf("  differ by ray kind:");
    for (k = 0; k < RAY_KIND_COUNT; ++k)
        printf(" %s %zu/%zu%s", ray_names[k], g_trace_total.kind_differ[k], g_trace_total.kind_rays[k],
               k + 1 < RAY_KIND_COUNT ? "," : "\n");
    {
        size_t closest = 0;
        for (k = 0; k < RAY_KIND_COUNT; ++k) closest += g_trace_total.kind_rays[k];
        printf("  bit-identical to the CPU's lrt_hit: %zu of %zu closest-hit answers\n", g_trace_total.bit_identical,
               closest);
        /* bit for bit, -0 against +0 too (a kernel's t + 0 folded to t once gave -0) */
        CHECK(g_trace_total.bit_identical == closest, "%zu closest-hit GPU answers not bit-identical to the CPU's",
              closest - g_trace_total.bit_identical);
    }
    /* a budget case that stopped no ray would not test the stop */
    printf("  with a step budget: %zu rays, %zu of them budget misses, %zu estimates of a finish, every answer the CPU's bit "
           "for bit\n", g_budget_rays, g_budget_stopped, g_budget_estimates);
    CHECK(!g_ran_budget_cases || (g_budget_stopped > 0 && g_budget_stopped < g_budget_rays && g_budget_estimates > 0),
          "budget cases: %zu of %zu rays stopped, %zu estimates", g_budget_stopped, g_budget_rays, g_budget_estimates);
    if (g_compacted) { /* the rounds resumed rays, and some rays reached the last slices */
        printf("  compacted: rays each round left for the next:");
        for (k = 0; k < (int)LRT_K_VK_TRACE_ROUNDS - 1; ++k) printf(" %zu", g_listed[k]);
        printf("\n");
        CHECK(!g_ran_budget_cases || (g_listed[0] > 0 && g_listed[2] > 0),
              "compacted: round 0 listed %zu rays, round 2 %zu", g_listed[0], g_listed[2]);
    }
    /* The kernels compute the CPU's floats step by step: the same kind and
       texel on every ray, t within rounding (the "identical"). */
    CHECK(g_trace_total.differ == 0, "%zu closest-hit GPU answers differ from the CPU's", g_trace_total.differ);
}

int main(int argc, char **argv)
{
    const char *ci = getenv("CI");
    const int in_ci = ci && strcmp(ci, "true") == 0;
    lrt_result r;
#ifdef HAVE_MXCSR
    const unsigned int mxcsr = _mm_getcsr();
#endif
    const char *seed = getenv("LRT_TEST_SEED");
    g_flushing = argc > 1 && strcmp(argv[1], "--flushing-device") == 0;
    g_compacted = argc > 1 && strcmp(argv[1], "--compacted") == 0;
    check_select(argc - g_flushing - g_compacted, argv + g_flushing + g_compacted);
    if (seed) { /* rays.h's generator; never 0, where xorshift stays */
        g_rng = (strtoull(seed, NULL, 0) * 0x9e3779b97f4a7c15ull) | 1u;
        printf("rays from LRT_TEST_SEED=%s\n", seed);
    }
    if (g_flushing) {
#ifdef HAVE_MXCSR
        _mm_setcsr(mxcsr | 0x8040u); /* FTZ (bit 15), DAZ (bit 6): inherited by the threads made from here */
#else
        printf("test-vulkan --flushing-device: skipped: no MXCSR on this CPU\n0 passed, 0 failed\n");
        return 0;
#endif
    }
    RUN_TEST(test_bad_arguments_no_device);
    r = lrt_vku_device_create(&g_dev, LRT_VKU_DEVICE_VALIDATION | LRT_VKU_DEVICE_SYNC_VALIDATION);
    if (r == LRT_ERROR_NO_VULKAN_LOADER || r == LRT_ERROR_NO_VULKAN_DEVICE || r == LRT_ERROR_MISSING_VULKAN_FEATURE) {
        printf("test-vulkan: %s: %s (%s)\n", in_ci ? "FAIL under CI=true" : "skipped", lrt_result_string(r),
               r == LRT_ERROR_MISSING_VULKAN_FEATURE ? "the validation layer VK_LAYER_KHRONOS_validation is not installed"
                                                     : "no Vulkan driver here: tools/install-deps.sh installs lavapipe");
        printf("%d passed, %d failed\n", g_pass, g_fail + in_ci);
        return in_ci || g_fail ? 1 : 0;
    }
    CHECK(r == LRT_SUCCESS, "lrt_vku_device_create: %s (VkResult %d)", lrt_result_string(r), (int)g_dev.vk_result);
    if (r != LRT_SUCCESS) {
        printf("%d passed, %d failed\n", g_pass, g_fail);
        return 1;
    }
    printf("device: %s, Vulkan %u.%u.%u, validation and synchronization validation on\n", g_dev.properties.deviceName,
           VK_API_VERSION_MAJOR(g_dev.properties.apiVersion), VK_API_VERSION_MINOR(g_dev.properties.apiVersion),
           VK_API_VERSION_PATCH(g_dev.properties.apiVersion));
    g_limits = g_dev.properties.limits;
    /* the trace's two passes, as on a GPU; --flushing-device: the device's choice (one pass on lavapipe) */
    if (!g_flushing) g_dev.desc.flags = LRT_VK_TRACE_TWO_PASSES;
    r = lrt_vk_context_create(&g_dev.desc, &g_ctx);
#ifdef HAVE_MXCSR
    _mm_setcsr(mxcsr); /* the CPU path and the reference as usual */
#endif
    if (g_flushing) printf("the device's threads flush subnormal floats (x86 FTZ and DAZ), as some GPUs do\n");
    printf("lrt_vk_cmd_trace%s in %s\n", g_compacted ? "_compacted" : "",
           g_flushing ? "the device's passes (lavapipe: one)" : "two passes (LRT_VK_TRACE_TWO_PASSES)");
    CHECK(r == LRT_SUCCESS, "lrt_vk_context_create: %s", lrt_result_string(r));
    if (r == LRT_SUCCESS && lrt_vku_init(&g_t, &g_dev) == 0) {
        RUN_TEST(test_smoke);
        RUN_TEST(test_context_options);
        RUN_TEST(test_device_without_extension);
        RUN_TEST(test_bad_arguments);
        RUN_TEST(test_device_limits);
        RUN_TEST(test_build_and_trace);
        RUN_TEST(test_found_cases);
        RUN_TEST(test_update);
        RUN_TEST(test_2d_dispatch);
        print_trace_summary();
    } else {
        CHECK(0, "Vulkan set-up failed");
    }
    lrt_vku_free(&g_t);
    lrt_vk_context_destroy(g_ctx);
    lrt_vku_device_destroy(&g_dev);
    CHECK(g_dev.message_count == 0, "%u validation messages (printed above)", g_dev.message_count);
    return check_summary();
}
