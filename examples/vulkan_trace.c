/* examples/vulkan_trace.c - the plain GPU trace, as a user writes it: a
   device (linear_rt_vk_util.h's) with the validation layer and its
   synchronization validation, which checks the barriers; the library's
   context; a depth map in a VkBuffer, lrt_vk_cmd_build, then
   lrt_vk_cmd_trace of a few thousand rays with the barriers of the header's
   BARRIERS section; one submit, one fence. The same rays traced on the CPU
   (lrt_trace) must give the same hits, bit for bit.
     build/vulkan_trace        (make examples; make test-vulkan-trace runs it)
   Exit: 0 GPU == CPU; 1 a difference, a validation message or an error;
   77 no Vulkan loader or device (1 under CI=true). */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#define LINEAR_RT_IMPLEMENTATION
#ifndef LINEAR_RT_VULKAN /* the Makefile defines these two; cc vulkan_trace.c -lm -ldl needs neither */
#define LINEAR_RT_VULKAN
#endif
#ifndef VK_NO_PROTOTYPES /* our vk* calls go through function pointers (linear_rt_vk_util.h), not the loader's symbols */
#define VK_NO_PROTOTYPES
#endif
#include "../linear_rt.h" /* includes <vulkan/vulkan.h> and, beside itself, shaders_spv.h */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../linear_rt_vk_util.h" /* the device, host-visible buffers, one command buffer submitted and waited for, a barrier */

enum { W = 256, H = 256, RAYS = 4096 };

/* The scene (depth 0 near, 1 far): a floor that recedes up the screen, a box
   and a ball standing on it. */
static float scene_depth(int x, int y)
{
    float d = 0.95f - 0.6f * (float)y / H, dx = (float)(x - 180) / 50.0f, dy = (float)(y - 140) / 50.0f;
    if (x >= 40 && x < 110 && y >= 120 && y < 200) d = 0.45f;
    if (dx * dx + dy * dy < 1.0f) d = 0.55f - 0.2f * sqrtf(1.0f - dx * dx - dy * dy);
    return d;
}

static uint32_t seed = 1u;
static float rnd(void) /* [0, 1) */
{
    seed = seed * 1664525u + 1013904223u;
    return (float)(seed >> 8) / 16777216.0f;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

#define CHECK_VK(call) do { if (call) goto done; } while (0) /* linear_rt_vk_util.h printed why */
#define CHECK_LRT(call) do { lrt_result r_ = (call); if (r_ != LRT_SUCCESS) { \
    fprintf(stderr, "vulkan_trace: %s: %s\n", #call, lrt_result_string(r_)); goto done; } } while (0)

int main(void)
{
    static lrt_vku_device dev; /* stays put: the validation callback counts into it */
    const char *ci = getenv("CI");
    lrt_vk_context *ctx = NULL;
    /* every library struct by field name: fields added later stay 0 */
    lrt_vk_bvh_desc bd = {.width = W, .height = H, .format = LRT_FORMAT_FLOAT32}; /* infinite thickness */
    lrt_vk_depth vd = {.format = LRT_FORMAT_FLOAT32, .width = W, .height = H};    /* standard Z, packed rows */
    lrt_depth cd = {.width = W, .height = H, .format = LRT_FORMAT_FLOAT32};
    lrt_vk_bvh bvh = {0};
    lrt_bvh cpu = {0};
    lrt_vku vk = {0};
    lrt_vku_buffer depth = {0}, rays = {0}, hits = {0};
    float *map;
    lrt_hit cpu_hits[RAYS];
    const lrt_hit *gpu_hits;
    char name[VK_MAX_PHYSICAL_DEVICE_NAME_SIZE];
    double t0, context_ms = 0, record_ms = 0;
    int x, y, k, hit_count = 0, equal = 0, done_ok = 0;
    lrt_result r = lrt_vku_device_create(&dev, LRT_VKU_DEVICE_VALIDATION | LRT_VKU_DEVICE_SYNC_VALIDATION);

    if (r == LRT_ERROR_NO_VULKAN_LOADER || r == LRT_ERROR_NO_VULKAN_DEVICE || r == LRT_ERROR_MISSING_VULKAN_FEATURE) {
        printf("vulkan_trace: %s: %s\n", ci && !strcmp(ci, "true") ? "FAIL under CI=true" : "skipped",
               lrt_result_string(r));
        return ci && !strcmp(ci, "true") ? 1 : 77;
    }
    CHECK_LRT(r);
    memcpy(name, dev.properties.deviceName, sizeof name); /* destroy zeroes dev but its message count */
    CHECK_VK(lrt_vku_init(&vk, &dev));

    t0 = now_ms(); /* layouts, a sampler: the pipelines are made by the first commands */
    CHECK_LRT(lrt_vk_context_create(&dev.desc, &ctx));
    context_ms = now_ms() - t0;

    /* the depth map, written straight into its buffer; the rays: random segments from in front of it */
    CHECK_VK(lrt_vku_buffer_create_in(&vk, (VkDeviceSize)W * H * sizeof(float), 1, &depth));
    CHECK_VK(lrt_vku_buffer_create_in(&vk, RAYS * sizeof(lrt_ray), 1, &rays));
    CHECK_VK(lrt_vku_buffer_create_in(&vk, RAYS * sizeof(lrt_hit), 1, &hits));
    map = (float *)depth.map;
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x) map[y * W + x] = scene_depth(x, y);
    for (k = 0; k < RAYS; ++k) {
        float ox = rnd() * W, oy = rnd() * H, oz = rnd() * scene_depth((int)ox, (int)oy);
        float dx = (rnd() - 0.5f) * W, dy = (rnd() - 0.5f) * H, dz = rnd() - 0.3f;
        ((lrt_ray *)rays.map)[k] = (lrt_ray){.origin = {ox, oy, oz}, .dir = {dx, dy, dz}, .tmin = 0, .tmax = 1};
    }

    /* the tree on the GPU, in memory the library makes */
    CHECK_LRT(lrt_vk_bvh_create(ctx, &bd, &bvh));
    vd.buffer = depth.buffer;

    /* one command buffer: build, trace, with the barriers of BARRIERS */
    CHECK_VK(lrt_vku_begin(&vk));
    /* the depth and rays we wrote -> the kernels (the submit orders host writes already) */
    lrt_vku_barrier(&vk, VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                VK_ACCESS_SHADER_READ_BIT);
    t0 = now_ms();
    CHECK_LRT(lrt_vk_cmd_build(ctx, vk.cmd, &bvh, &vd));
    /* the built tree -> the trace */
    lrt_vku_barrier(&vk, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    CHECK_LRT(lrt_vk_cmd_trace(ctx, vk.cmd, &bvh, &vd, rays.buffer, 0, hits.buffer, 0, RAYS, 0));
    record_ms = now_ms() - t0; /* their pipelines made (refit; trace: one pass on a CPU device, else two) */
    /* its hits -> our mapped read after the fence */
    lrt_vku_barrier(&vk, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                VK_ACCESS_HOST_READ_BIT);
    CHECK_VK(lrt_vku_submit(&vk));

    /* the same rays on the CPU, on a tree of the same map; every field must match bit for bit */
    cd.data = depth.map;
    CHECK_LRT(lrt_bvh_build(&cpu, &cd, NULL, NULL));
    CHECK_LRT(lrt_trace(&cpu, &cd, (const lrt_ray *)rays.map, cpu_hits, RAYS, 0));
    gpu_hits = (const lrt_hit *)hits.map;
    for (k = 0; k < RAYS; ++k) {
        const lrt_hit *g = &gpu_hits[k], *c = &cpu_hits[k];
        if (memcmp(&g->t, &c->t, sizeof g->t) == 0 && g->x == c->x && g->y == c->y && g->kind == c->kind &&
            g->face == c->face)
            ++equal;
        else if (k - equal < 5) /* the first few differences */
            fprintf(stderr, "vulkan_trace: ray %d: GPU t %.9g (%u, %u) kind %u face %u, CPU t %.9g (%u, %u) kind %u "
                    "face %u\n", k, g->t, g->x, g->y, g->kind, g->face, c->t, c->x, c->y, c->kind, c->face);
        hit_count += c->kind == LRT_HIT;
    }
    done_ok = 1;
done:
    lrt_bvh_destroy(&cpu);
    if (vk.device) {
        lrt_vku_buffer_destroy(&vk, &hits);
        lrt_vku_buffer_destroy(&vk, &rays);
        lrt_vku_buffer_destroy(&vk, &depth);
    }
    lrt_vku_free(&vk);
    lrt_vk_bvh_destroy(ctx, &bvh);
    lrt_vk_context_destroy(ctx);
    lrt_vku_device_destroy(&dev); /* the layer's last messages (leaks) are counted too */
    if (!done_ok) return 1;
    printf("vulkan_trace: %s: %d rays, %d hits, %d equal (GPU == CPU: %s), %u validation messages; "
           "lrt_vk_context_create %.0f ms, the first build and trace recorded in %.0f ms\n", name, RAYS, hit_count,
           equal, equal == RAYS ? "yes" : "NO", dev.message_count, context_ms, record_ms);
    return equal == RAYS && dev.message_count == 0 ? 0 : 1;
}
