/* examples/vulkan_inline/main.c - the host side of contact_shadows.comp, a
   compute shader of the user's own that includes shaders/linear_rt.glsl and
   traces the BVH inline.

   linear_rt builds the tree on the GPU (lrt_vk_cmd_build) in buffers the
   library makes; everything after that is ours: a descriptor set layout, a
   pipeline layout with our push constants, our pipeline, one dispatch of one
   invocation per texel. Then the same shadow rays on the CPU (lrt_bvh_build
   and lrt_trace on the same depth) must give the same hit or miss on every
   texel: the kernels answer what the CPU answers, bit for bit.

   build/vulkan_inline [--size N] [--validation] [--out DIR]
   (build/hlsl_inline: the same, with examples/hlsl_inline/contact_shadows.hlsl)
     --size N      the embedded scene at N x N texels (default 256)
     --validation  the Khronos validation layer on, synchronization validation
                   too (the barriers); any message is a failure
     --out DIR     where vulkan_inline.png goes (default out)
   Exit: 0 GPU == CPU, 1 a disagreement or a failure, 2 bad arguments,
   77 no Vulkan loader or device (skipped; 1 when CI=true). */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#define LINEAR_RT_IMPLEMENTATION
#include "../../linear_rt.h" /* with -DLINEAR_RT_VULKAN */
#include "../scene.h"
#include "../../linear_rt_vk_util.h" /* the device, buffers, one command buffer, submit and wait, barriers, timestamps */
#ifdef HLSL_INLINE /* build/hlsl_inline: the same host, the shader in HLSL (examples/hlsl_inline) */
#include "hlsl_inline_spv.h" /* contact_shadows_spv[]: contact_shadows.hlsl, compiled by make */
#define EXAMPLE "hlsl_inline"
#else
#include "vulkan_inline_spv.h" /* contact_shadows_spv[]: contact_shadows.comp, compiled by make */
#define EXAMPLE "vulkan_inline"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

enum { EXIT_OK = 0, EXIT_FAILED = 1, EXIT_BAD_INPUT = 2, EXIT_SKIPPED = 77 };
enum { OUT_LIT = 0, OUT_SHADOWED = 1, OUT_SKY = 2 };
#define RUNS 5 /* timed dispatches; the median is printed */

/* The shadow ray for t in [0, 1], as fractions of the width in x and y (to
   the right and up: the sun of examples/shadows.c), and its climb towards
   the eye in depth per unit of (1 - depth); the origin's extra lift. */
#define LIGHT_X 0.03f
#define LIGHT_Y (-0.02f)
#define LIGHT_Z (-3.0f)
#define BIAS 1e-6f

/* contact_shadows.comp's push constants: LrtParams' 8 fields, then ours
   (std430: vec3 at byte 32, float at 44) */
typedef struct shadow_push {
    uint32_t width, height, format, flags, node_bits, level_count, depth_offset, row_stride;
    float light[3];
    float bias;
} shadow_push;

/* The Vulkan functions of our own pipeline (linear_rt_vk_util.h has the rest). */
#define OWN_FUNCS(X)                                                                                              \
    X(vkCreateDescriptorSetLayout) X(vkDestroyDescriptorSetLayout) X(vkCreatePipelineLayout)                     \
    X(vkDestroyPipelineLayout) X(vkCreateShaderModule) X(vkDestroyShaderModule) X(vkCreateComputePipelines)      \
    X(vkDestroyPipeline) X(vkCmdBindPipeline) X(vkCmdPushDescriptorSetKHR) X(vkCmdPushConstants) X(vkCmdDispatch)

typedef struct own {
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
    VkPipeline pipeline;
#define OWN_MEMBER(name) PFN_##name name;
    OWN_FUNCS(OWN_MEMBER)
#undef OWN_MEMBER
} own;

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static double median(double *v, int n)
{
    int i, j;
    for (i = 1; i < n; ++i)
        for (j = i; j > 0 && v[j - 1] > v[j]; --j) {
            double x = v[j];
            v[j] = v[j - 1];
            v[j - 1] = x;
        }
    return v[n / 2];
}

/* ---- our pipeline -------------------------------------------------------------- */
/* Written out on purpose, as an engine's own code is: this is the side the
   example shows. linear_rt.h makes its pipelines with the same calls
   (lrt__vk_create_objects) and so do the benchmark's peers
   (bench/m_vk_peers.c), which `duplicates` lists as pairs. */
static int own_create(own *o, const lrt_vku_device *dev)
{
    const VkDevice device = dev->desc.device;
    VkDescriptorSetLayoutBinding b[3];
    VkDescriptorSetLayoutCreateInfo si;
    VkPushConstantRange pc;
    VkPipelineLayoutCreateInfo li;
    VkShaderModuleCreateInfo mi;
    VkComputePipelineCreateInfo ci;
    VkShaderModule module;
    VkResult r;
    int i;
    memset(o, 0, sizeof *o);
#define OWN_LOAD(name)                                                                                            \
    o->name = (PFN_##name)dev->desc.get_device_proc_addr(device, #name);                                          \
    if (!o->name) return lrt_vku_fail("loading " #name, VK_ERROR_INITIALIZATION_FAILED);
    OWN_FUNCS(OWN_LOAD)
#undef OWN_LOAD
    /* depth and nodes at the library's bindings (linear_rt.h's >>contract), our output at 3;
       push descriptors: the device has VK_KHR_push_descriptor (linear_rt needs it) */
    memset(b, 0, sizeof b);
    for (i = 0; i < 3; ++i) {
        b[i].binding = i == 0 ? LRT_K_VK_BINDING_DEPTH_BUFFER : i == 1 ? LRT_K_VK_BINDING_NODES : 3u;
        b[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        b[i].descriptorCount = 1;
        b[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    memset(&si, 0, sizeof si);
    si.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    si.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
    si.bindingCount = 3;
    si.pBindings = b;
    if ((r = o->vkCreateDescriptorSetLayout(device, &si, NULL, &o->set_layout)) != VK_SUCCESS)
        return lrt_vku_fail("vkCreateDescriptorSetLayout", r);
    memset(&pc, 0, sizeof pc);
    pc.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    pc.size = sizeof(shadow_push);
    memset(&li, 0, sizeof li);
    li.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    li.setLayoutCount = 1;
    li.pSetLayouts = &o->set_layout;
    li.pushConstantRangeCount = 1;
    li.pPushConstantRanges = &pc;
    if ((r = o->vkCreatePipelineLayout(device, &li, NULL, &o->layout)) != VK_SUCCESS)
        return lrt_vku_fail("vkCreatePipelineLayout", r);
    memset(&mi, 0, sizeof mi);
    mi.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    mi.codeSize = contact_shadows_spv_SIZE;
    mi.pCode = contact_shadows_spv;
    if ((r = o->vkCreateShaderModule(device, &mi, NULL, &module)) != VK_SUCCESS)
        return lrt_vku_fail("vkCreateShaderModule", r);
    memset(&ci, 0, sizeof ci);
    ci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = module;
    ci.stage.pName = "main";
    ci.layout = o->layout;
    r = o->vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, NULL, &o->pipeline);
    o->vkDestroyShaderModule(device, module, NULL);
    return r == VK_SUCCESS ? 0 : lrt_vku_fail("vkCreateComputePipelines", r);
}

static void own_destroy(own *o, VkDevice device)
{
    if (o->pipeline) o->vkDestroyPipeline(device, o->pipeline, NULL);
    if (o->layout) o->vkDestroyPipelineLayout(device, o->layout, NULL);
    if (o->set_layout) o->vkDestroyDescriptorSetLayout(device, o->set_layout, NULL);
    memset(o, 0, sizeof *o);
}

/* Records our dispatch: the tree and depth of linear_rt, our output. */
static void own_record(const own *o, VkCommandBuffer cmd, const lrt_vk_bvh *bvh, const lrt_vku_buffer *depth,
                       const lrt_vku_buffer *out, const shadow_push *push)
{
    VkDescriptorBufferInfo bi[3];
    VkWriteDescriptorSet w[3];
    int i;
    bi[0].buffer = depth->buffer;
    bi[0].offset = 0;
    bi[0].range = depth->size;
    bi[1].buffer = bvh->nodes; /* the node range only (the counters follow it) */
    bi[1].offset = bvh->nodes_offset;
    bi[1].range = bvh->layout.bytes;
    bi[2].buffer = out->buffer;
    bi[2].offset = 0;
    bi[2].range = out->size;
    memset(w, 0, sizeof w);
    for (i = 0; i < 3; ++i) {
        w[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        w[i].dstBinding = i == 0 ? LRT_K_VK_BINDING_DEPTH_BUFFER : i == 1 ? LRT_K_VK_BINDING_NODES : 3u;
        w[i].descriptorCount = 1;
        w[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        w[i].pBufferInfo = &bi[i];
    }
    o->vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, o->pipeline);
    o->vkCmdPushDescriptorSetKHR(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, o->layout, 0, 3, w);
    o->vkCmdPushConstants(cmd, o->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof *push, push);
    o->vkCmdDispatch(cmd, (push->width + 7u) / 8u, (push->height + 7u) / 8u, 1);
}

/* ---- the same rays on the CPU -------------------------------------------------- */
/* Each step as contact_shadows.comp writes it (every operation rounds once
   in both: IEEE float here, `precise` there), so the rays are the same
   floats; the answers must then agree. */
static float cpu_depth_at(const float *d, int w, int h, int x, int y)
{
    float v;
    x = x < 0 ? 0 : x > w - 1 ? w - 1 : x;
    y = y < 0 ? 0 : y > h - 1 ? h - 1 : y;
    v = d[(size_t)y * (size_t)w + (size_t)x];
    return v != v || v > 1.0f ? 1.0f : v < 0.0f ? 0.0f : v; /* docs/MODEL.md's clamp, as lrt_depth_raw */
}

static float cpu_slope(float d, float a, float b)
{
    float sa = fabsf(d - a), sb = fabsf(b - d);
    return sb < sa ? sb : sa; /* GLSL min(sa, sb) */
}

/* 0: sky, no ray; 1: *ray set */
static int cpu_ray(const float *depth, int w, int h, int x, int y, const shadow_push *p, lrt_ray *ray)
{
    float d = cpu_depth_at(depth, w, h, x, y), sx, sy, s, half, lift, far;
    if (d >= 1.0f) return 0;
    sx = cpu_slope(d, cpu_depth_at(depth, w, h, x - 1, y), cpu_depth_at(depth, w, h, x + 1, y));
    sy = cpu_slope(d, cpu_depth_at(depth, w, h, x, y - 1), cpu_depth_at(depth, w, h, x, y + 1));
    s = sx + sy;
    half = 0.5f * s; /* exact: a fused multiply-add would round the same */
    lift = half + p->bias;
    far = 1.0f - d;
    ray->origin[0] = (float)x + 0.5f;
    ray->origin[1] = (float)y + 0.5f;
    ray->origin[2] = d - lift;
    ray->tmin = 0.0f;
    ray->dir[0] = p->light[0];
    ray->dir[1] = p->light[1];
    ray->dir[2] = p->light[2] * far;
    ray->tmax = 1.0f;
    return 1;
}

static int write_png(const char *dir, const uint32_t *out, uint32_t w, uint32_t h)
{
    static const uint8_t grey[3] = {235, 60, 150}; /* lit, shadowed, sky */
    char path[1024];
    size_t k, n = (size_t)w * h;
    uint8_t *px = (uint8_t *)malloc(n);
    int ok;
    if (!px) return 1;
    for (k = 0; k < n; ++k) px[k] = grey[out[k] <= OUT_SKY ? out[k] : OUT_SKY];
    mkdir(dir, 0777); /* fails harmlessly when it exists */
    snprintf(path, sizeof path, "%s/" EXAMPLE ".png", dir);
    ok = stbi_write_png(path, (int)w, (int)h, 1, px, (int)w);
    free(px);
    if (!ok) {
        fprintf(stderr, EXAMPLE ": cannot write %s\n", path);
        return 1;
    }
    printf("  wrote %s (%ux%u)\n", path, w, h);
    return 0;
}

/* ---- main --------------------------------------------------------------------- */
#define CHECK_LRT(call)                                                                                           \
    do {                                                                                                          \
        lrt_result r_ = (call);                                                                                   \
        if (r_ != LRT_SUCCESS) {                                                                                  \
            fprintf(stderr, EXAMPLE ": %s: %s\n", #call, lrt_result_string(r_));                            \
            goto done;                                                                                            \
        }                                                                                                         \
    } while (0)

int main(int argc, char **argv)
{
    static lrt_vku_device dev; /* stays put: the validation callback counts into it */
    const char *ci = getenv("CI"), *out_dir = "out";
    const int in_ci = ci && strcmp(ci, "true") == 0;
    uint32_t size = 256, w, h;
    int validation = 0, a, rc = EXIT_FAILED;
    size_t n, k, shadowed = 0, rays_traced = 0, differ = 0;
    float *depth = NULL;
    lrt_ray *rays = NULL;
    lrt_hit *hits = NULL;
    int *has_ray = NULL;
    lrt_bvh cpu_bvh = {0};
    lrt_depth cpu_depth;
    lrt_vk_context *ctx = NULL;
    lrt_vk_bvh bvh = {0};
    lrt_vk_bvh_desc bd;
    lrt_vk_depth vd;
    lrt_vku t;
    lrt_vku_buffer depth_buf, out_buf;
    own o;
    shadow_push push;
    double build_ms = 0, trace_ms[RUNS], wall_ms[RUNS], cpu_build_ms, cpu_ms, t0, gpu_ms[LRT_VKU_TIMESTAMPS - 1];
    const uint32_t *out;
    lrt_result r;
    scene_camera cam = scene_default_camera();

    memset(&cpu_bvh, 0, sizeof cpu_bvh);
    memset(&bvh, 0, sizeof bvh);
    memset(&t, 0, sizeof t);
    memset(&o, 0, sizeof o);
    memset(&depth_buf, 0, sizeof depth_buf);
    memset(&out_buf, 0, sizeof out_buf);
    for (a = 1; a < argc; ++a) {
        if (!strcmp(argv[a], "--validation")) {
            validation = 1;
        } else if (!strcmp(argv[a], "--size") && a + 1 < argc && atoi(argv[a + 1]) >= 1 &&
                   atoi(argv[a + 1]) <= 8192) {
            size = (uint32_t)atoi(argv[++a]);
        } else if (!strcmp(argv[a], "--out") && a + 1 < argc) {
            out_dir = argv[++a];
        } else {
            fprintf(stderr, "usage: %s [--size N (1..8192)] [--validation] [--out DIR]\n", argv[0]);
            return EXIT_BAD_INPUT;
        }
    }
    w = h = size;
    n = (size_t)w * h;

    /* the device: the validation layer prints each message and counts it */
    r = lrt_vku_device_create(&dev, validation ? LRT_VKU_DEVICE_VALIDATION | LRT_VKU_DEVICE_SYNC_VALIDATION : 0u);
    if (r == LRT_ERROR_NO_VULKAN_LOADER || r == LRT_ERROR_NO_VULKAN_DEVICE || r == LRT_ERROR_MISSING_VULKAN_FEATURE) {
        printf(EXAMPLE ": %s: %s%s\n", in_ci ? "FAIL under CI=true" : "skipped", lrt_result_string(r),
               r == LRT_ERROR_MISSING_VULKAN_FEATURE && validation ? " (is VK_LAYER_KHRONOS_validation installed?)" : "");
        return in_ci ? EXIT_FAILED : EXIT_SKIPPED;
    }
    if (r != LRT_SUCCESS) {
        fprintf(stderr, EXAMPLE ": lrt_vku_device_create: %s (VkResult %d)\n", lrt_result_string(r),
                (int)dev.vk_result);
        return EXIT_FAILED;
    }
    printf(EXAMPLE ": %s, Vulkan %u.%u.%u%s\n", dev.properties.deviceName,
           VK_API_VERSION_MAJOR(dev.properties.apiVersion), VK_API_VERSION_MINOR(dev.properties.apiVersion),
           VK_API_VERSION_PATCH(dev.properties.apiVersion), validation ? ", validation on" : "");
    CHECK_LRT(lrt_vk_context_create(&dev.desc, &ctx));
    if (lrt_vku_init(&t, &dev) || own_create(&o, &dev)) goto done;

    /* the scene's depth, and the CPU's tree of it */
    depth = (float *)malloc(n * sizeof *depth);
    rays = (lrt_ray *)malloc(n * sizeof *rays);
    hits = (lrt_hit *)malloc(n * sizeof *hits);
    has_ray = (int *)malloc(n * sizeof *has_ray);
    if (!depth || !rays || !hits || !has_ray) {
        fprintf(stderr, EXAMPLE ": out of memory\n");
        goto done;
    }
    scene_render((int)w, (int)h, &cam, depth, NULL);
    memset(&cpu_depth, 0, sizeof cpu_depth);
    cpu_depth.data = depth;
    cpu_depth.width = w;
    cpu_depth.height = h;
    cpu_depth.format = LRT_FORMAT_FLOAT32;
    t0 = now_ms();
    CHECK_LRT(lrt_bvh_build(&cpu_bvh, &cpu_depth, NULL, NULL));
    cpu_build_ms = now_ms() - t0;

    /* the depth in a host-visible storage buffer; the GPU's tree */
    if (lrt_vku_buffer_create_in(&t, n * sizeof *depth, 1, &depth_buf) || lrt_vku_buffer_create_in(&t, n * sizeof(uint32_t), 1, &out_buf))
        goto done;
    memcpy(depth_buf.map, depth, n * sizeof *depth); /* host writes before the submission: no barrier */
    memset(&vd, 0, sizeof vd);
    vd.format = LRT_FORMAT_FLOAT32;
    vd.width = w;
    vd.height = h;
    vd.buffer = depth_buf.buffer;
    vd.row_stride = (VkDeviceSize)w * sizeof(float);
    memset(&bd, 0, sizeof bd);
    bd.width = w;
    bd.height = h;
    bd.format = LRT_FORMAT_FLOAT32;
    CHECK_LRT(lrt_vk_bvh_create(ctx, &bd, &bvh));

    /* our push constants: LrtParams from the tree's layout, then the light */
    memset(&push, 0, sizeof push);
    push.width = w;
    push.height = h;
    push.format = (uint32_t)vd.format;
    push.flags = vd.flags;
    push.node_bits = bvh.layout.node_bits;
    push.level_count = bvh.layout.level_count;
    push.depth_offset = (uint32_t)vd.offset;
    push.row_stride = (uint32_t)vd.row_stride;
    push.light[0] = LIGHT_X * (float)w;
    push.light[1] = LIGHT_Y * (float)w;
    push.light[2] = LIGHT_Z;
    push.bias = BIAS;

    /* Run 0 builds the tree and dispatches ours in one command buffer; runs
       1..RUNS dispatch ours alone (timed: the median is printed). Barriers as
       linear_rt.h's BARRIERS has them for a trace (our dispatch reads the tree
       as lrt_vk_cmd_trace does); the depth was written by the host before the
       submission, which needs none. */
    for (a = 0; a <= RUNS; ++a) {
        t0 = now_ms();
        if (lrt_vku_begin(&t)) goto done;
        lrt_vku_timestamp(&t, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, 0);
        if (a == 0) CHECK_LRT(lrt_vk_cmd_build(ctx, t.cmd, &bvh, &vd));
        lrt_vku_timestamp(&t, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 1);
        /* "before update or trace, after the build of the tree": (CS, SHADER_WRITE)
           -> (CS, SHADER_READ); in later runs the same barrier orders the last
           run's writes of our output before this run's (and BARRIERS asks it of
           a build in an earlier submission too) */
        lrt_vku_barrier(&t, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                    VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
        own_record(&o, t.cmd, &bvh, &depth_buf, &out_buf, &push);
        lrt_vku_timestamp(&t, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 2);
        /* "after trace: its hits" -> (HOST, HOST_READ): our output, mapped, read after the fence */
        lrt_vku_barrier(&t, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                    VK_ACCESS_HOST_READ_BIT);
        if (lrt_vku_submit(&t)) goto done;
        if (a > 0) wall_ms[a - 1] = now_ms() - t0;
        if (t.queries) {
            if (lrt_vku_timestamps_ms(&t, gpu_ms)) goto done;
            if (a == 0) build_ms = gpu_ms[0];
            else trace_ms[a - 1] = gpu_ms[1];
        }
    }
    out = (const uint32_t *)out_buf.map;

    /* the same rays on the CPU, any hit */
    t0 = now_ms();
    for (k = 0; k < n; ++k) {
        has_ray[k] = cpu_ray(depth, (int)w, (int)h, (int)(k % w), (int)(k / w), &push, &rays[k]);
        if (!has_ray[k]) lrt_camera_segment(NULL, NULL, NULL, &rays[k]); /* an invalid ray: a miss, not traced */
    }
    CHECK_LRT(lrt_trace(&cpu_bvh, &cpu_depth, rays, hits, n, 0));
    cpu_ms = now_ms() - t0;

    /* texel by texel: sky where there is no ray; else hit == shadowed. The
       kernels answer what lrt_trace answers, bit for bit, and the rays are
       the same floats: any disagreement is a failure. */
    for (k = 0; k < n; ++k) {
        uint32_t want = !has_ray[k] ? OUT_SKY : hits[k].kind == LRT_HIT ? OUT_SHADOWED : OUT_LIT;
        rays_traced += has_ray[k] != 0;
        shadowed += out[k] == OUT_SHADOWED;
        if (out[k] == want) continue;
        if (++differ <= 5)
            printf("  texel (%u,%u): GPU %u, CPU %u: o=(%.9g %.9g %.9g) v=(%.9g %.9g %.9g)\n", (unsigned)(k % w),
                   (unsigned)(k / w), out[k], want, (double)rays[k].origin[0], (double)rays[k].origin[1],
                   (double)rays[k].origin[2], (double)rays[k].dir[0], (double)rays[k].dir[1], (double)rays[k].dir[2]);
    }
    if (differ == 0)
        printf(EXAMPLE ": %zu texels, %zu shadowed, GPU == CPU on all\n", n, shadowed);
    else
        printf(EXAMPLE ": FAIL: %zu texels, %zu shadowed, GPU != CPU on %zu\n", n, shadowed, differ);
    if (t.queries)
        printf("  GPU (timestamps): lrt_vk_cmd_build %.3f ms, our dispatch %.3f ms (median of %d; %.2f ms on the wall "
               "with submit and wait)\n", build_ms, median(trace_ms, RUNS), RUNS, median(wall_ms, RUNS));
    else
        printf("  GPU: no timestamps on this queue; our dispatch %.2f ms on the wall with submit and wait (median of %d)\n",
               median(wall_ms, RUNS), RUNS);
    printf("  CPU (1 thread): lrt_bvh_build %.2f ms, %zu rays made and traced (lrt_trace, any hit) %.2f ms\n",
           cpu_build_ms, rays_traced, cpu_ms);
    if (write_png(out_dir, out, w, h)) goto done;
    rc = differ == 0 ? EXIT_OK : EXIT_FAILED;

done:
    if (t.device) {
        t.vkDeviceWaitIdle(t.device);
        own_destroy(&o, t.device);
        lrt_vku_buffer_destroy(&t, &depth_buf);
        lrt_vku_buffer_destroy(&t, &out_buf);
    }
    lrt_vk_bvh_destroy(ctx, &bvh);
    lrt_vku_free(&t);
    lrt_vk_context_destroy(ctx);
    lrt_vku_device_destroy(&dev);
    lrt_bvh_destroy(&cpu_bvh);
    free(depth);
    free(rays);
    free(hits);
    free(has_ray);
    if (dev.message_count) {
        printf(EXAMPLE ": FAIL: %u validation messages (printed above)\n", dev.message_count);
        rc = EXIT_FAILED;
    }
    return rc;
}
