/* tests/test_vulkan_threads.c - linear_rt.h's promise that several threads
   may record commands with one lrt_vk_context at once (the recording
   functions only read the context and the tree).

   One device (lavapipe on the project's machines) with the Khronos
   validation layer, synchronization validation and its thread-safety checks
   on (any message fails the test), one lrt_vk_context. 4 threads, each with
   its own command pool, command buffer and fence (linear_rt_vk_util.h), its own
   lrt_vk_bvh, depth (a buffer, or a sampled image it uploads itself), rays
   and hits, and its own map size, format and node bits, run frames: record
   build (frame 0) or update (the changed rectangle, or the whole map) and a
   trace into their command buffer, all 4 in the recording state at once
   (they meet at a gate after their first command), then submit under a
   mutex (one queue: vkQueueSubmit needs external synchronization) and wait
   for their fence. Each frame:
     GPU nodes == the CPU's lrt_bvh_build / lrt_bvh_update, byte for byte;
     GPU hits == lrt_trace(..., flags) on the CPU (same kind and texel, t
     within 1e-5 * (1 + |t|)).
   `make test-vulkan-threads` runs it as built by CC; `make
   test-vulkan-threads-tsan` under ThreadSanitizer, twice: with
   --no-validation first, because the layer's own mutexes around every
   vkCmd* order the recording threads for TSan and would hide a race in
   linear_rt.h (measured: a write to the context injected into
   lrt_vk_cmd_trace is reported without the layer, never with it); then with
   the layer, as above. Neither needs a TSan suppression (Mesa 25 lavapipe,
   Khronos layer 1.3.239).
   No Vulkan loader or device: prints why and exits 0 (skipped), or 1 when
   the environment variable CI is "true". Ends with "N passed, M failed". */
#define _POSIX_C_SOURCE 200809L /* pthreads under -std=c99 */
#ifndef LINEAR_RT_VULKAN
#define LINEAR_RT_VULKAN
#endif
#define LINEAR_RT_IMPLEMENTATION
#include "../linear_rt.h"
#include "support/reference.h"
#include "../examples/scene.h"
#include "support/rays.h"
#include "support/check.h"
#include "../linear_rt_vk_util.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { WORKERS = 4, FRAMES = 9 };

static lrt_vku_device g_dev; /* stays put: the validation callback counts into it */
static lrt_vk_context *g_ctx;
static pthread_mutex_t g_queue_lock = PTHREAD_MUTEX_INITIALIZER;

/* ---- a gate: every worker waits until all have arrived (reusable) ------------ */
static pthread_mutex_t g_gate_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t g_gate_open = PTHREAD_COND_INITIALIZER;
static int g_gate_waiting, g_gate_workers = WORKERS;
static unsigned long g_gate_round;
static int g_recording, g_most_recording; /* command buffers in the recording state */

static void gate(void)
{
    unsigned long round;
    pthread_mutex_lock(&g_gate_lock);
    round = g_gate_round;
    if (++g_gate_waiting == g_gate_workers) {
        g_gate_waiting = 0;
        ++g_gate_round;
        pthread_cond_broadcast(&g_gate_open);
    } else {
        while (round == g_gate_round) pthread_cond_wait(&g_gate_open, &g_gate_lock);
    }
    pthread_mutex_unlock(&g_gate_lock);
}

/* A worker that stops early leaves the gate: the others do not wait for it. */
static void gate_leave(void)
{
    pthread_mutex_lock(&g_gate_lock);
    if (--g_gate_workers == g_gate_waiting && g_gate_waiting > 0) {
        g_gate_waiting = 0;
        ++g_gate_round;
        pthread_cond_broadcast(&g_gate_open);
    }
    pthread_mutex_unlock(&g_gate_lock);
}

static void recording(int delta)
{
    pthread_mutex_lock(&g_gate_lock);
    g_recording += delta;
    if (g_recording > g_most_recording) g_most_recording = g_recording;
    pthread_mutex_unlock(&g_gate_lock);
}

/* ---- one worker's frames ---------------------------------------------------------- */
/* What a frame needs, made by the main thread beforehand (the random
   numbers of rays.h are not thread-safe). */
typedef struct frame_in {
    void *bytes;      /* the depth, packed, in the worker's format */
    lrt_rect rect;    /* the texels changed since the previous frame */
    int whole;        /* update the whole map (NULL rect) instead */
    lrt_ray *rays;
    uint32_t flags;
} frame_in;

typedef struct vk_worker {
    int index;
    uint32_t w, h, bits;
    lrt_format format;
    VkFormat image_format; /* VK_FORMAT_UNDEFINED: the depth is a storage buffer */
    size_t nrays;
    frame_in frames[FRAMES];
    lrt_vku t;               /* its own command pool, command buffer and fence */
    lrt_vku_buffer upload;   /* the depth buffer, or the image's staging buffer */
    lrt_vku_image image;
    lrt_vku_buffer rays, hits;
    lrt_vk_depth depth;
    lrt_vk_bvh gpu;
    /* results, read by the main thread after the join */
    int frames_done, nodes_differ, hits_differ;
    char failure[200];
} vk_worker;

static uint32_t bytes_of(lrt_format f) { return f == LRT_FORMAT_UNORM8 ? 1u : f == LRT_FORMAT_UNORM16 ? 2u : 4u; }

static int same_answer(const lrt_hit *a, const lrt_hit *b)
{
    if (a->kind != b->kind) return 0;
    if (a->kind != LRT_HIT) return a->t == b->t && a->x == b->x && a->y == b->y;
    return a->x == b->x && a->y == b->y && fabsf(a->t - b->t) <= 1e-5f * (1.0f + fabsf(b->t));
}

/* Ends, submits under the queue's lock, waits for this worker's fence. */
static VkResult submit(vk_worker *k)
{
    VkSubmitInfo si;
    VkResult r = k->t.vkEndCommandBuffer(k->t.cmd);
    recording(-1);
    if (r != VK_SUCCESS) return r;
    memset(&si, 0, sizeof si);
    si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &k->t.cmd;
    pthread_mutex_lock(&g_queue_lock);
    r = k->t.vkQueueSubmit(g_dev.queue, 1, &si, k->t.fence);
    pthread_mutex_unlock(&g_queue_lock);
    if (r != VK_SUCCESS) return r;
    r = k->t.vkWaitForFences(k->t.device, 1, &k->t.fence, VK_TRUE, UINT64_MAX);
    if (r != VK_SUCCESS) return r;
    return k->t.vkResetFences(k->t.device, 1, &k->t.fence);
}

static void *worker_main(void *arg)
{
    vk_worker *k = (vk_worker *)arg;
    const size_t bytes = (size_t)k->w * k->h * bytes_of(k->format);
    lrt_hit *cpu_hits = (lrt_hit *)malloc(sizeof(lrt_hit) * k->nrays);
    lrt_depth cd;
    lrt_bvh cpu = {0};
    lrt_build_options opt;
    int f;
    memset(&cpu, 0, sizeof cpu);
    memset(&cd, 0, sizeof cd);
    cd.width = k->w;
    cd.height = k->h;
    cd.format = k->format;
    memset(&opt, 0, sizeof opt);
    opt.node_bits = k->bits;
    for (f = 0; f < FRAMES && cpu_hits; ++f) {
        const frame_in *in = &k->frames[f];
        const lrt_rect *dirty = in->whole ? NULL : &in->rect;
        lrt_result cr, gr;
        VkResult vr;
        size_t i, differ = 0;
        /* the CPU's answer, on this thread too: trees of other threads are traced meanwhile */
        cd.data = in->bytes;
        cr = f == 0 ? lrt_bvh_build(&cpu, &cd, &opt, NULL) : lrt_bvh_update(&cpu, &cd, dirty);
        if (cr == LRT_SUCCESS) cr = lrt_trace(&cpu, &cd, in->rays, cpu_hits, k->nrays, in->flags);
        if (cr != LRT_SUCCESS) {
            snprintf(k->failure, sizeof k->failure, "frame %d: CPU: %s", f, lrt_result_string(cr));
            break;
        }
        /* host writes before the submission are visible to it: no barrier */
        memcpy(k->upload.map, in->bytes, bytes);
        memcpy(k->rays.map, in->rays, sizeof(lrt_ray) * k->nrays);
        memset(k->hits.map, 0xff, sizeof(lrt_hit) * k->nrays);
        if (f == 0) memset(k->gpu.mapped, 0xa5, k->gpu.layout.bytes); /* the build must write every byte */

        gate(); /* start recording together */
        if ((vr = k->t.vkResetCommandBuffer(k->t.cmd, 0)) == VK_SUCCESS) {
            VkCommandBufferBeginInfo bi;
            memset(&bi, 0, sizeof bi);
            bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
            bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
            vr = k->t.vkBeginCommandBuffer(k->t.cmd, &bi);
        }
        if (vr != VK_SUCCESS) {
            snprintf(k->failure, sizeof k->failure, "frame %d: beginning the command buffer: VkResult %d", f, (int)vr);
            break;
        }
        recording(1);
        if (k->image_format != VK_FORMAT_UNDEFINED) { /* the upload: BARRIERS' first rule */
            VkBufferImageCopy c;
            lrt_vku_image_barrier(&k->t, &k->image,
                              f == 0 ? VK_IMAGE_LAYOUT_UNDEFINED : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                              VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0,
                              VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
            memset(&c, 0, sizeof c);
            c.imageSubresource.aspectMask =
                lrt_vku_is_depth_format(k->image_format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
            c.imageSubresource.layerCount = 1;
            c.imageExtent.width = k->w;
            c.imageExtent.height = k->h;
            c.imageExtent.depth = 1;
            k->t.vkCmdCopyBufferToImage(k->t.cmd, k->upload.buffer, k->image.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                        1, &c);
            lrt_vku_image_barrier(&k->t, &k->image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                              VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
                              VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
        }
        if (f == 0) {
            gr = lrt_vk_cmd_build(g_ctx, k->t.cmd, &k->gpu, &k->depth);
        } else {
            lrt_vku_compute_barrier(&k->t); /* the last frame's refit and trace -> this refit */
            gr = lrt_vk_cmd_update(g_ctx, k->t.cmd, &k->gpu, &k->depth, dirty);
        }
        gate(); /* every command buffer is recording now: the rest is recorded side by side */
        if (gr == LRT_SUCCESS) {
            lrt_vku_compute_barrier(&k->t); /* the refit -> the trace */
            gr = lrt_vk_cmd_trace(g_ctx, k->t.cmd, &k->gpu, &k->depth, k->rays.buffer, 0, k->hits.buffer, 0,
                                  (uint32_t)k->nrays, in->flags);
        }
        lrt_vku_host_barrier(&k->t);
        vr = submit(k);
        if (gr != LRT_SUCCESS || vr != VK_SUCCESS) {
            snprintf(k->failure, sizeof k->failure, "frame %d: recording: %s, submission: VkResult %d", f,
                     lrt_result_string(gr), (int)vr);
            break;
        }
        if (memcmp(k->gpu.mapped, cpu.nodes, cpu.layout.bytes) != 0) ++k->nodes_differ;
        for (i = 0; i < k->nrays; ++i) differ += !same_answer((const lrt_hit *)k->hits.map + i, &cpu_hits[i]);
        if (differ && !k->hits_differ)
            snprintf(k->failure, sizeof k->failure, "frame %d (%s): %zu of %zu GPU hits differ from the CPU's", f,
                     in->flags ? "flags?" : "closest", differ,
                     k->nrays);
        k->hits_differ += differ != 0;
        ++k->frames_done;
    }
    if (k->frames_done < FRAMES) gate_leave();
    lrt_bvh_destroy(&cpu);
    free(cpu_hits);
    return NULL;
}

/* ---- set-up by the main thread ---------------------------------------------------- */

/* Frames (a sphere that moves over a floor), their changes and rays. */
static void make_frames(vk_worker *k)
{
    const int w = (int)k->w, h = (int)k->h;
    const size_t texels = (size_t)w * (size_t)h;
    float *d = (float *)malloc(sizeof(float) * texels), *prev = (float *)malloc(sizeof(float) * texels);
    static const uint32_t flags[2] = {0u, 0u}; /* lrt_vk_cmd_trace has no flags yet */
    int f;
    size_t i;
    if (!d || !prev) exit(2);
    for (f = 0; f < FRAMES; ++f) {
        frame_in *in = &k->frames[f];
        test_map m;
        if (f) memcpy(prev, d, sizeof(float) * texels);
        paint_frame(d, w, h, f * 3 + k->index);
        in->bytes = malloc(texels * bytes_of(k->format));
        in->rays = (lrt_ray *)malloc(sizeof(lrt_ray) * k->nrays);
        if (!in->bytes || !in->rays) exit(2);
        lrt_vku_encode_depth(d, in->bytes, texels, k->format);
        if (f) in->rect = changed_rect(prev, d, w, h);
        in->whole = f % 3 == 0;
        in->flags = flags[(f + k->index) % 2];
        /* make_ray reads the depth through the reference's map */
        memset(&m, 0, sizeof m);
        if (ref_map_from_raw(&m.ref, in->bytes, w, h, 0, (int)k->format, 0) != 0) exit(2);
        for (i = 0; i < k->nrays; ++i) in->rays[i] = make_ray(&m, (int)(i % RAY_KIND_COUNT));
        free_map(&m);
    }
    free(d);
    free(prev);
}

static int worker_create(vk_worker *k, int index, uint32_t w, uint32_t h, lrt_format format, uint32_t bits,
                         VkFormat image_format, size_t nrays)
{
    const VkDeviceSize bytes = (VkDeviceSize)w * h * bytes_of(format);
    lrt_vk_bvh_desc bd;
    lrt_result r;
    memset(k, 0, sizeof *k);
    k->index = index;
    k->w = w;
    k->h = h;
    k->format = format;
    k->bits = bits;
    k->nrays = nrays;
    make_frames(k);
    if (lrt_vku_init(&k->t, &g_dev)) return 1;
    if (image_format != VK_FORMAT_UNDEFINED && !lrt_vku_format_sampled(&k->t, image_format)) {
        printf("  note: worker %d: the device cannot sample VkFormat %d: its depth is a buffer\n", index,
               (int)image_format);
        image_format = VK_FORMAT_UNDEFINED;
    }
    k->image_format = image_format;
    /* the kernels read 32-bit words: the depth buffer is rounded up to 4 bytes */
    if (lrt_vku_buffer_create(&k->t, (bytes + 3u) / 4u * 4u, &k->upload) ||
        lrt_vku_buffer_create(&k->t, nrays * sizeof(lrt_ray), &k->rays) ||
        lrt_vku_buffer_create(&k->t, nrays * sizeof(lrt_hit), &k->hits))
        return 1;
    k->depth.format = format;
    k->depth.width = w;
    k->depth.height = h;
    if (image_format != VK_FORMAT_UNDEFINED) {
        if (lrt_vku_image_create(&k->t, image_format, w, h, &k->image)) return 1;
        k->depth.view = k->image.view;
        k->depth.layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    } else {
        k->depth.buffer = k->upload.buffer;
    }
    memset(&bd, 0, sizeof bd);
    bd.width = w;
    bd.height = h;
    bd.format = format;
    bd.options.node_bits = bits;
    bd.flags = LRT_VK_BVH_HOST_VISIBLE;
    r = lrt_vk_bvh_create(g_ctx, &bd, &k->gpu);
    if (r != LRT_SUCCESS || !k->gpu.mapped) {
        printf("  worker %d: lrt_vk_bvh_create: %s\n", index, lrt_result_string(r));
        return 1;
    }
    return 0;
}

static void worker_destroy(vk_worker *k)
{
    int f;
    if (k->t.device) {
        k->t.vkDeviceWaitIdle(k->t.device);
        lrt_vk_bvh_destroy(g_ctx, &k->gpu);
        lrt_vku_image_destroy(&k->t, &k->image);
        lrt_vku_buffer_destroy(&k->t, &k->upload);
        lrt_vku_buffer_destroy(&k->t, &k->rays);
        lrt_vku_buffer_destroy(&k->t, &k->hits);
        lrt_vku_free(&k->t);
    }
    for (f = 0; f < FRAMES; ++f) {
        free(k->frames[f].bytes);
        free(k->frames[f].rays);
    }
}

static void test_threads(void)
{
    /* size, format, node bits, depth source: each worker a different one */
    static const struct {
        uint32_t w, h;
        lrt_format format;
        uint32_t bits;
        VkFormat image;
        size_t nrays;
    } cfg[WORKERS] = {
        {203, 131, LRT_FORMAT_FLOAT32, 16, VK_FORMAT_UNDEFINED, 3000},
        {97, 61, LRT_FORMAT_UNORM16, 8, VK_FORMAT_R16_UNORM, 2000},
        {320, 201, LRT_FORMAT_UNORM8, 16, VK_FORMAT_UNDEFINED, 3000},
        {64, 77, LRT_FORMAT_FLOAT32, 8, VK_FORMAT_D32_SFLOAT, 2000},
    };
    static vk_worker workers[WORKERS];
    pthread_t threads[WORKERS];
    int i, ready = 1, started = 0;
    for (i = 0; i < WORKERS; ++i)
        if (worker_create(&workers[i], i, cfg[i].w, cfg[i].h, cfg[i].format, cfg[i].bits, cfg[i].image, cfg[i].nrays))
            ready = 0;
    CHECK(ready, "set-up of the workers failed");
    if (ready) {
        g_gate_workers = WORKERS;
        for (i = 0; i < WORKERS; ++i) {
            if (pthread_create(&threads[i], NULL, worker_main, &workers[i]) != 0) break;
            ++started;
        }
        if (started < WORKERS) { /* the gate counts on all: those started stop at it otherwise */
            pthread_mutex_lock(&g_gate_lock);
            g_gate_workers = started;
            pthread_mutex_unlock(&g_gate_lock);
        }
        for (i = 0; i < started; ++i) pthread_join(threads[i], NULL);
        CHECK(started == WORKERS, "only %d of %d threads started", started, WORKERS);
        for (i = 0; i < started; ++i) {
            const vk_worker *k = &workers[i];
            const char *src = k->image_format != VK_FORMAT_UNDEFINED ? "image" : "buffer";
            printf("  thread %d: %ux%u fmt=%d nodes=%u %s: %d frames\n", i, k->w, k->h, (int)k->format,
                   k->gpu.layout.node_bits, src, k->frames_done);
            CHECK(k->frames_done == FRAMES, "thread %d: stopped: %s", i, k->failure);
            CHECK(k->nodes_differ == 0, "thread %d: %d of %d frames' GPU trees differ from the CPU's", i, k->nodes_differ,
                  k->frames_done);
            CHECK(k->hits_differ == 0, "thread %d: %d of %d frames' GPU hits differ from the CPU's (%s)", i,
                  k->hits_differ, k->frames_done, k->failure);
        }
        printf("  at most %d command buffers were in the recording state at once\n", g_most_recording);
    }
    for (i = 0; i < WORKERS; ++i) worker_destroy(&workers[i]);
}

int main(int argc, char **argv)
{
    const char *ci = getenv("CI");
    const int in_ci = ci && strcmp(ci, "true") == 0;
    const int validation = !(argc > 1 && strcmp(argv[1], "--no-validation") == 0);
    lrt_result r;
    (void)make_map; /* rays.h's random maps: the frames here are made by make_frames */
    if (argc > 2 || (argc > 1 && validation)) {
        printf("usage: %s [--no-validation]\n", argv[0]);
        return 2;
    }
    r = lrt_vku_device_create(&g_dev, validation ? LRT_VKU_DEVICE_VALIDATION | LRT_VKU_DEVICE_SYNC_VALIDATION : 0u);
    if (r == LRT_ERROR_NO_VULKAN_LOADER || r == LRT_ERROR_NO_VULKAN_DEVICE || r == LRT_ERROR_MISSING_VULKAN_FEATURE) {
        printf("test-vulkan-threads: %s: %s (%s)\n", in_ci ? "FAIL under CI=true" : "skipped", lrt_result_string(r),
               r == LRT_ERROR_MISSING_VULKAN_FEATURE ? "the validation layer VK_LAYER_KHRONOS_validation is not installed"
                                                     : "no Vulkan driver here: tools/install-deps.sh installs lavapipe");
        printf("%d passed, %d failed\n", g_pass, g_fail + in_ci);
        return in_ci ? 1 : 0;
    }
    CHECK(r == LRT_SUCCESS, "lrt_vku_device_create: %s (VkResult %d)", lrt_result_string(r), (int)g_dev.vk_result);
    if (r != LRT_SUCCESS) return check_summary();
    printf("device: %s, %s; %d threads, %d frames each\n", g_dev.properties.deviceName,
           validation ? "validation and synchronization validation on"
                      : "no validation layer (its mutexes would order the threads for ThreadSanitizer)",
           WORKERS, FRAMES);
    r = lrt_vk_context_create(&g_dev.desc, &g_ctx);
    CHECK(r == LRT_SUCCESS, "lrt_vk_context_create: %s", lrt_result_string(r));
    if (r == LRT_SUCCESS) test_threads();
    lrt_vk_context_destroy(g_ctx);
    lrt_vku_device_destroy(&g_dev);
    CHECK(g_dev.message_count == 0, "%u validation messages (printed above)", g_dev.message_count);
    return check_summary();
}
