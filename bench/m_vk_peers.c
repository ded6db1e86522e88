/* bench/m_vk_peers.c - the Vulkan peers of linear_rt: what an engine
   programmer would run on the GPU instead.

     "rq aabb vulkan"       a generic ray-query BVH (VK_KHR_acceleration_structure,
                            VK_KHR_ray_query): one procedural AABB per texel box,
                            the exact box test in the shader (exact)
     "rq triangles vulkan"  the same solid as opaque triangles: texel tops, the
                            walls between neighbours of different depth and on the
                            screen border (exact)
     "march64 vulkan"       fixed-step linear march, 64 steps + 8 bisection steps
     "dda vulkan"           per-pixel DDA, stride 1, thickness 0.02
     "hiz64 vulkan"         min-depth Hi-Z traversal, at most 64 iterations
   The marches are scored, not exact: the algorithms of bench/march_cpu.c
   ("march64 cpu": examples/march.h's march_linear; "dda cpu", "hiz64 cpu"),
   in float. Kernels:
   bench/shaders/vkp_*.comp (each says exactly what it computes).

   The BVHs. Both take the texels in Z (Morton) order: lavapipe's builder
   splits primitives at the middle of their submission order and does not
   sort, so that order is what makes its tree (row-major order would give
   long row strips). One TLAS instance over one BLAS.
   - AABBs: build = a compute dispatch writing every texel's AABB from the
     depth buffer, the BLAS and the TLAS built (ALLOW_UPDATE,
     PREFER_FAST_TRACE); update = the same dispatch, then the BLAS and the
     TLAS refitted in place (mode UPDATE: same primitives, new heights).
   - triangles: build and update alike = the triangles generated on the host
     (tops, walls where neighbours differ, border walls; their count follows
     the depth) and the BLAS and TLAS built anew (PREFER_FAST_TRACE; a refit
     cannot add or drop walls).
   memory_bytes: the structures' sizes (vkGetAccelerationStructureBuildSizesKHR)
   plus their build input (AABBs 24 bytes a texel, vertices 36 bytes a
   triangle) and the primitive -> texel table (4 bytes a primitive), which a
   refit or rebuild needs; the scratch is not counted. Hi-Z: its levels above
   the depth map. The marches: 0. Depth, rays and hits are never counted.

   Each method makes its own instance and device: the Vulkan loader is opened
   at run time (dlopen of libvulkan.so.1: no link-time Vulkan symbol, link
   with -ldl on old glibc), and the first physical device with Vulkan 1.2, a
   compute queue with timestamps and (ray-query methods) the extensions
   VK_KHR_acceleration_structure, VK_KHR_ray_query,
   VK_KHR_deferred_host_operations and the features bufferDeviceAddress,
   accelerationStructure, rayQuery is used: on a machine with lavapipe only,
   the same device as linear_rt's own Vulkan methods. A missing piece makes
   open() fail with one line saying which.

   Memory: depth, rays, hits, the primitive tables and the triangle vertices
   are host-visible, coherent buffers written and read through a mapping
   (DEVICE_LOCAL as well where the device has such memory: all of lavapipe's
   is); the acceleration structures and the scratch prefer DEVICE_LOCAL. On
   a discrete GPU the rays and hits would want device-local copies.

   Timing: every ms is the difference of two GPU timestamps
   (vkCmdWriteTimestamp around the work, timestampPeriod), but for the
   triangle BVH's build and update, which add the host time of generating
   the triangles (CLOCK_MONOTONIC). lavapipe builds acceleration structures
   on the CPU while it executes the command buffer, between the two
   timestamps, so they time the build itself (measured: the host wall time of
   the whole submission, submit to fence, is within about 1% of them); that
   wall time is kept in vkp.wall_ms for comparison and is not reported. A
   kernel's first dispatch, where lavapipe compiles it, is run once untimed
   before the first timed build; warming the trace up is the harness's job.
   A trace is timed as a batch of back-to-back dispatches of the same rays
   (bench/bench.h: bench_gpu_batch), as linear_rt's Vulkan methods
   are: an H200 kept its idle clock under single short dispatches.
   The `threads` argument is not used: lavapipe's threads are LP_NUM_THREADS.

   Built when the Makefile passes BENCH_HAVE_VULKAN (<vulkan/vulkan.h> is
   there) and BENCH_HAVE_VK_PEERS_SPV (it compiled the kernels into
   bench_vk_spv.h on the include path); otherwise the methods are still
   listed and open() says what is missing.

   LRT_BENCH_VK_VALIDATION=1 in the environment turns on the Khronos
   validation layer for these devices (=sync: with synchronization
   validation): each warning or error is printed to stderr and counted in
   vkp_validation_messages. */
#include "bench.h"
#include "march_common.h" /* march_depth: the model's clamp */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { VKP_RQ_AABB, VKP_RQ_TRI, VKP_MARCH64, VKP_DDA, VKP_HIZ, VKP_KINDS };
static const char *const vkp_names[VKP_KINDS] = {"rq aabb vulkan", "rq triangles vulkan", "march64 vulkan",
                                                 "dda vulkan", "hiz64 vulkan"};

#if defined(BENCH_HAVE_VULKAN) && defined(BENCH_HAVE_VK_PEERS_SPV)

#ifndef VK_NO_PROTOTYPES
#define VK_NO_PROTOTYPES
#endif
#define LINEAR_RT_VULKAN /* linear_rt.h again, with its Vulkan declarations: linear_rt_vk_util.h needs them */
#include "../linear_rt.h"
#include "../linear_rt_vk_util.h" /* the loader, a device with one queue */

#include "bench_vk_spv.h" /* vkp_spv_<kernel>[]: bench/shaders/vkp_<kernel>.comp, compiled by make bench */

unsigned vkp_validation_messages; /* validation warnings and errors seen (LRT_BENCH_VK_VALIDATION) */

#define VKP_GROUP 64u           /* local_size_x of every kernel */
#define VKP_MAX_GROUPS 65535u   /* groups per dispatch; more are split by ray_first */
#define VKP_MAX_LEVELS 16u

/* the push constants of every kernel (vkp_common.glsl's VkpPush) */
typedef struct vkp_push {
    uint32_t width, height, ray_first, ray_count, flags, level_count, level, pad;
    uint32_t offsets[VKP_MAX_LEVELS];
} vkp_push;

#define VKP_GLOBAL_FUNCS(X) X(vkCreateInstance) X(vkEnumerateInstanceLayerProperties)
#define VKP_INSTANCE_FUNCS(X)                                                                                      \
    X(vkDestroyInstance) X(vkEnumeratePhysicalDevices) X(vkGetPhysicalDeviceProperties)                          \
    X(vkGetPhysicalDeviceProperties2) X(vkGetPhysicalDeviceFeatures2) X(vkGetPhysicalDeviceQueueFamilyProperties) \
    X(vkGetPhysicalDeviceMemoryProperties) X(vkEnumerateDeviceExtensionProperties) X(vkCreateDevice)             \
    X(vkGetDeviceProcAddr)
#define VKP_DEVICE_FUNCS(X)                                                                                        \
    X(vkDestroyDevice) X(vkGetDeviceQueue) X(vkDeviceWaitIdle) X(vkCreateBuffer) X(vkDestroyBuffer)              \
    X(vkGetBufferMemoryRequirements) X(vkAllocateMemory) X(vkFreeMemory) X(vkBindBufferMemory) X(vkMapMemory)   \
    X(vkCreateCommandPool) X(vkDestroyCommandPool) X(vkAllocateCommandBuffers) X(vkBeginCommandBuffer)           \
    X(vkEndCommandBuffer) X(vkResetCommandBuffer) X(vkQueueSubmit) X(vkCreateFence) X(vkDestroyFence)            \
    X(vkWaitForFences) X(vkResetFences) X(vkCreateQueryPool) X(vkDestroyQueryPool) X(vkCmdResetQueryPool)        \
    X(vkCmdWriteTimestamp) X(vkGetQueryPoolResults) X(vkCreateShaderModule) X(vkDestroyShaderModule)             \
    X(vkCreateDescriptorSetLayout) X(vkDestroyDescriptorSetLayout) X(vkCreatePipelineLayout)                     \
    X(vkDestroyPipelineLayout) X(vkCreateComputePipelines) X(vkDestroyPipeline) X(vkCreateDescriptorPool)        \
    X(vkDestroyDescriptorPool) X(vkAllocateDescriptorSets) X(vkUpdateDescriptorSets) X(vkCmdBindPipeline)        \
    X(vkCmdBindDescriptorSets) X(vkCmdPushConstants) X(vkCmdDispatch) X(vkCmdPipelineBarrier)
#define VKP_RT_FUNCS(X)                                                                                            \
    X(vkGetBufferDeviceAddress) X(vkCreateAccelerationStructureKHR) X(vkDestroyAccelerationStructureKHR)         \
    X(vkGetAccelerationStructureBuildSizesKHR) X(vkGetAccelerationStructureDeviceAddressKHR)                     \
    X(vkCmdBuildAccelerationStructuresKHR)

typedef struct vkp_buf {
    VkBuffer buf;
    VkDeviceMemory mem;
    void *map;             /* host-visible buffers: mapped for their lifetime */
    VkDeviceSize size;
    VkDeviceAddress addr;  /* buffers with SHADER_DEVICE_ADDRESS usage */
} vkp_buf;

typedef struct vkp_as {
    vkp_buf store;
    VkAccelerationStructureKHR as;
    VkDeviceSize capacity; /* size it was created with */
    VkDeviceAddress addr;
} vkp_as;

typedef struct vkp {
    int kind;
    /* device */
    void *lib;
    PFN_vkGetInstanceProcAddr gipa;
    VkInstance inst;
    VkDebugUtilsMessengerEXT messenger;
    PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger;
    VkPhysicalDevice pd;
    VkDevice dev;
    VkQueue queue;
    uint32_t family;
    VkPhysicalDeviceMemoryProperties memory;
    char device_name[VK_MAX_PHYSICAL_DEVICE_NAME_SIZE];
    double ns_per_tick;
    uint64_t tick_mask;
    VkDeviceSize scratch_align;
    VkCommandPool pool;
    VkCommandBuffer cmd;
    VkFence fence;
    VkQueryPool queries;
    VkDescriptorSetLayout dsl;
    VkPipelineLayout layout;
    VkDescriptorPool dpool;
    VkDescriptorSet set;
    VkPipeline trace_pipe, prep_pipe; /* prep: AABBs from depth, or one Hi-Z level */
#define VKP_MEMBER(name) PFN_##name name;
    VKP_GLOBAL_FUNCS(VKP_MEMBER)
    VKP_INSTANCE_FUNCS(VKP_MEMBER)
    VKP_DEVICE_FUNCS(VKP_MEMBER)
    VKP_RT_FUNCS(VKP_MEMBER)
#undef VKP_MEMBER
    /* the scene's size and what hangs on it */
    uint32_t w, h;
    int has_back; /* the scene has a thickness: back depths follow the depth (vkp_common.glsl) */
    vkp_buf depth, rays, hits, table, aux, verts, scratch, instances;
    size_t ray_cap;
    vkp_as blas, tlas;
    uint32_t prims;            /* primitives in the BLAS: texels, or triangles */
    VkDeviceSize blas_bytes, tlas_bytes; /* build sizes of the current structures */
    uint32_t levels;           /* Hi-Z levels, level 0 the depth map */
    uint32_t offsets[VKP_MAX_LEVELS];
    VkDeviceSize aux_bytes;    /* Hi-Z: bytes of the levels above level 0 */
    int built;
    int warm;                  /* the prep kernel has run once (lavapipe compiles a kernel on its first dispatch) */
    /* the last command: GPU timestamps, and host wall time of submit to fence */
    double gpu_ms, wall_ms, host_ms;
    bench_gpu_batch batch;     /* dispatches a trace's submission repeats */
} vkp;

/* ---- small things ------------------------------------------------------------ */
static int vkp_fail(char *why, size_t n, const char *what, VkResult r)
{
    snprintf(why, n, "%s failed (VkResult %d)", what, (int)r);
    return 1;
}

static int vkp_is_rt(const vkp *p) { return p->kind == VKP_RQ_AABB || p->kind == VKP_RQ_TRI; }

static VKAPI_ATTR VkBool32 VKAPI_CALL vkp_on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                     VkDebugUtilsMessageTypeFlagsEXT types,
                                                     const VkDebugUtilsMessengerCallbackDataEXT *data, void *user)
{
    (void)types;
    (void)user;
    ++vkp_validation_messages;
    fprintf(stderr, "vk peers: validation %s: %s\n",
            severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning",
            data && data->pMessage ? data->pMessage : "(no message)");
    return VK_FALSE;
}

/* 0: no validation; 1: the layer; 2: the layer with synchronization
   validation (LRT_BENCH_VK_VALIDATION=sync) */
static int vkp_validation_wanted(void)
{
    const char *e = getenv("LRT_BENCH_VK_VALIDATION");
    if (!e || !e[0] || strcmp(e, "0") == 0) return 0;
    return strcmp(e, "sync") == 0 ? 2 : 1;
}

static int vkp_has_ext(const VkExtensionProperties *e, uint32_t n, const char *name)
{
    uint32_t i;
    for (i = 0; i < n; ++i)
        if (strcmp(e[i].extensionName, name) == 0) return 1;
    return 0;
}

/* ---- buffers ------------------------------------------------------------------ */
static int vkp_memory_type(const vkp *p, uint32_t allowed, VkMemoryPropertyFlags want)
{
    uint32_t i;
    for (i = 0; i < p->memory.memoryTypeCount; ++i)
        if (((allowed >> i) & 1u) && (p->memory.memoryTypes[i].propertyFlags & want) == want) return (int)i;
    return -1;
}

static void vkp_buf_destroy(vkp *p, vkp_buf *b)
{
    if (b->buf) p->vkDestroyBuffer(p->dev, b->buf, NULL);
    if (b->mem) p->vkFreeMemory(p->dev, b->mem, NULL);
    memset(b, 0, sizeof *b);
}

/* host: HOST_VISIBLE | HOST_COHERENT, mapped (DEVICE_LOCAL too where there is
   such memory); else DEVICE_LOCAL preferred. */
static int vkp_buf_create(vkp *p, VkDeviceSize size, VkBufferUsageFlags usage, int host, vkp_buf *b, char *why,
                          size_t n)
{
    const VkMemoryPropertyFlags hv = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    VkBufferCreateInfo bi;
    VkMemoryRequirements mr;
    VkMemoryAllocateInfo ai;
    VkMemoryAllocateFlagsInfo fi;
    VkResult r;
    int type;
    memset(b, 0, sizeof *b);
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bi.size = size ? size : 16;
    bi.usage = usage;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    if ((r = p->vkCreateBuffer(p->dev, &bi, NULL, &b->buf)) != VK_SUCCESS) return vkp_fail(why, n, "vkCreateBuffer", r);
    p->vkGetBufferMemoryRequirements(p->dev, b->buf, &mr);
    if (host) {
        type = vkp_memory_type(p, mr.memoryTypeBits, hv | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        if (type < 0) type = vkp_memory_type(p, mr.memoryTypeBits, hv);
    } else {
        type = vkp_memory_type(p, mr.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        if (type < 0) type = vkp_memory_type(p, mr.memoryTypeBits, 0);
    }
    if (type < 0) {
        vkp_buf_destroy(p, b);
        snprintf(why, n, "no memory type for a %s buffer", host ? "host-visible" : "device");
        return 1;
    }
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    ai.allocationSize = mr.size;
    ai.memoryTypeIndex = (uint32_t)type;
    memset(&fi, 0, sizeof fi);
    fi.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO;
    fi.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    if (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) ai.pNext = &fi;
    if ((r = p->vkAllocateMemory(p->dev, &ai, NULL, &b->mem)) != VK_SUCCESS) {
        vkp_buf_destroy(p, b);
        return vkp_fail(why, n, "vkAllocateMemory", r);
    }
    if ((r = p->vkBindBufferMemory(p->dev, b->buf, b->mem, 0)) != VK_SUCCESS ||
        (host && (r = p->vkMapMemory(p->dev, b->mem, 0, VK_WHOLE_SIZE, 0, &b->map)) != VK_SUCCESS)) {
        vkp_buf_destroy(p, b);
        return vkp_fail(why, n, host ? "binding or mapping memory" : "vkBindBufferMemory", r);
    }
    b->size = bi.size;
    if (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) {
        VkBufferDeviceAddressInfo di;
        memset(&di, 0, sizeof di);
        di.sType = VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO;
        di.buffer = b->buf;
        b->addr = p->vkGetBufferDeviceAddress(p->dev, &di);
    }
    return 0;
}

/* b holds at least size bytes (contents not kept) */
static int vkp_buf_reserve(vkp *p, VkDeviceSize size, VkBufferUsageFlags usage, int host, vkp_buf *b, char *why,
                           size_t n)
{
    if (b->buf && b->size >= size) return 0;
    vkp_buf_destroy(p, b);
    return vkp_buf_create(p, size, usage, host, b, why, n);
}

/* ---- device ------------------------------------------------------------------- */
static void vkp_release(vkp *p)
{
    int kind = p->kind;
    if (p->dev) {
        p->vkDeviceWaitIdle(p->dev);
        if (p->blas.as) p->vkDestroyAccelerationStructureKHR(p->dev, p->blas.as, NULL);
        if (p->tlas.as) p->vkDestroyAccelerationStructureKHR(p->dev, p->tlas.as, NULL);
        vkp_buf_destroy(p, &p->blas.store);
        vkp_buf_destroy(p, &p->tlas.store);
        vkp_buf_destroy(p, &p->depth);
        vkp_buf_destroy(p, &p->rays);
        vkp_buf_destroy(p, &p->hits);
        vkp_buf_destroy(p, &p->table);
        vkp_buf_destroy(p, &p->aux);
        vkp_buf_destroy(p, &p->verts);
        vkp_buf_destroy(p, &p->scratch);
        vkp_buf_destroy(p, &p->instances);
        if (p->trace_pipe) p->vkDestroyPipeline(p->dev, p->trace_pipe, NULL);
        if (p->prep_pipe) p->vkDestroyPipeline(p->dev, p->prep_pipe, NULL);
        if (p->dpool) p->vkDestroyDescriptorPool(p->dev, p->dpool, NULL);
        if (p->layout) p->vkDestroyPipelineLayout(p->dev, p->layout, NULL);
        if (p->dsl) p->vkDestroyDescriptorSetLayout(p->dev, p->dsl, NULL);
        if (p->queries) p->vkDestroyQueryPool(p->dev, p->queries, NULL);
        if (p->fence) p->vkDestroyFence(p->dev, p->fence, NULL);
        if (p->pool) p->vkDestroyCommandPool(p->dev, p->pool, NULL);
        p->vkDestroyDevice(p->dev, NULL);
    }
    if (p->messenger && p->destroy_messenger) p->destroy_messenger(p->inst, p->messenger, NULL);
    if (p->inst) p->vkDestroyInstance(p->inst, NULL);
    lrt_vku_close_loader(p->lib);
    memset(p, 0, sizeof *p);
    p->kind = kind;
}

/* The features the ray-query peers need, as one pNext chain: features 2
   -> 1.2 (bufferDeviceAddress) -> acceleration structure -> ray query. */
typedef struct vkp_rt_chain {
    VkPhysicalDeviceFeatures2 f2;
    VkPhysicalDeviceVulkan12Features f12;
    VkPhysicalDeviceAccelerationStructureFeaturesKHR fas;
    VkPhysicalDeviceRayQueryFeaturesKHR frq;
} vkp_rt_chain;

/* every feature off, the chain linked */
static void vkp_rt_chain_init(vkp_rt_chain *c)
{
    memset(c, 0, sizeof *c);
    c->f2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    c->f2.pNext = &c->f12;
    c->f12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
    c->f12.pNext = &c->fas;
    c->fas.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR;
    c->fas.pNext = &c->frq;
    c->frq.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR;
}

/* Is this physical device fit? 0 if so, else 1 with the reason in why. */
static int vkp_device_fit(vkp *p, VkPhysicalDevice pd, uint32_t *family, char *why, size_t n)
{
    static const char *const rt_exts[3] = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                                           VK_KHR_RAY_QUERY_EXTENSION_NAME,
                                           VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};
    VkPhysicalDeviceProperties props;
    VkQueueFamilyProperties fams[32];
    uint32_t nf = 32, f, i;
    p->vkGetPhysicalDeviceProperties(pd, &props);
    if (props.apiVersion < VK_API_VERSION_1_2) {
        snprintf(why, n, "%.128s: Vulkan 1.2 is needed", props.deviceName);
        return 1;
    }
    p->vkGetPhysicalDeviceQueueFamilyProperties(pd, &nf, fams);
    for (f = 0; f < nf; ++f)
        if ((fams[f].queueFlags & VK_QUEUE_COMPUTE_BIT) && fams[f].timestampValidBits > 0) break;
    if (f == nf) {
        snprintf(why, n, "%.128s: no compute queue with timestamps", props.deviceName);
        return 1;
    }
    *family = f;
    if (vkp_is_rt(p)) {
        VkExtensionProperties *exts;
        vkp_rt_chain c;
        uint32_t ne = 0;
        if (p->vkEnumerateDeviceExtensionProperties(pd, NULL, &ne, NULL) != VK_SUCCESS) ne = 0;
        exts = (VkExtensionProperties *)calloc(ne ? ne : 1, sizeof *exts);
        if (!exts) {
            snprintf(why, n, "out of memory");
            return 1;
        }
        if (p->vkEnumerateDeviceExtensionProperties(pd, NULL, &ne, exts) < VK_SUCCESS) ne = 0;
        for (i = 0; i < 3; ++i) {
            if (!vkp_has_ext(exts, ne, rt_exts[i])) {
                snprintf(why, n, "%.128s has no %s", props.deviceName, rt_exts[i]);
                free(exts);
                return 1;
            }
        }
        free(exts);
        vkp_rt_chain_init(&c);
        p->vkGetPhysicalDeviceFeatures2(pd, &c.f2);
        if (!c.f12.bufferDeviceAddress || !c.fas.accelerationStructure || !c.frq.rayQuery) {
            snprintf(why, n, "%.128s lacks %s", props.deviceName,
                     !c.f12.bufferDeviceAddress ? "bufferDeviceAddress"
                     : !c.fas.accelerationStructure ? "the accelerationStructure feature"
                                                  : "the rayQuery feature");
            return 1;
        }
    }
    return 0;
}

static int vkp_create_device(vkp *p, char *why, size_t n)
{
    static const char *const layer = "VK_LAYER_KHRONOS_validation";
    static const char *const validation_exts[2] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME,
                                                   VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
    const VkValidationFeatureEnableEXT sync = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    VkValidationFeaturesEXT vf;
    static const char *const rt_exts[3] = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                                           VK_KHR_RAY_QUERY_EXTENSION_NAME,
                                           VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};
    const int validate = vkp_validation_wanted();
    VkApplicationInfo app;
    VkInstanceCreateInfo ii;
    VkDebugUtilsMessengerCreateInfoEXT mi;
    VkPhysicalDevice devices[16];
    uint32_t nd = 16, i;
    vkp_rt_chain c;
    VkPhysicalDeviceProperties props;
    VkQueueFamilyProperties fams[32];
    uint32_t nf = 32;
    char reason[256];
    VkResult r;

    if (!(p->lib = lrt_vku_open_loader(&p->gipa))) {
        snprintf(why, n, "no Vulkan loader (libvulkan.so.1)");
        return 1;
    }
#define VKP_LOAD_G(name)                                                                                           \
    if (!(p->name = (PFN_##name)p->gipa(VK_NULL_HANDLE, #name))) return vkp_fail(why, n, "loading " #name, VK_SUCCESS);
    VKP_GLOBAL_FUNCS(VKP_LOAD_G)
#undef VKP_LOAD_G
    if (validate) {
        VkLayerProperties layers[64];
        uint32_t nl = 64;
        int found = 0;
        if (p->vkEnumerateInstanceLayerProperties(&nl, layers) >= VK_SUCCESS)
            for (i = 0; i < nl; ++i) found |= strcmp(layers[i].layerName, layer) == 0;
        if (!found) {
            snprintf(why, n, "LRT_BENCH_VK_VALIDATION is set but %s is not installed", layer);
            return 1;
        }
    }
    memset(&app, 0, sizeof app);
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "linear_rt bench";
    app.apiVersion = VK_API_VERSION_1_2;
    lrt_vku_messenger_info(&mi, vkp_on_message, NULL);
    memset(&ii, 0, sizeof ii);
    ii.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ii.pApplicationInfo = &app;
    memset(&vf, 0, sizeof vf);
    vf.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
    vf.pNext = &mi;
    vf.enabledValidationFeatureCount = 1;
    vf.pEnabledValidationFeatures = &sync;
    if (validate) { /* messages of instance creation too */
        ii.pNext = validate == 2 ? (const void *)&vf : (const void *)&mi;
        ii.enabledLayerCount = 1;
        ii.ppEnabledLayerNames = &layer;
        ii.enabledExtensionCount = validate == 2 ? 2u : 1u;
        ii.ppEnabledExtensionNames = validation_exts;
    }
    if ((r = p->vkCreateInstance(&ii, NULL, &p->inst)) != VK_SUCCESS) {
        p->inst = VK_NULL_HANDLE;
        if (r == VK_ERROR_INCOMPATIBLE_DRIVER) {
            snprintf(why, n, "no Vulkan driver");
            return 1;
        }
        return vkp_fail(why, n, "vkCreateInstance", r);
    }
#define VKP_LOAD_I(name)                                                                                           \
    if (!(p->name = (PFN_##name)p->gipa(p->inst, #name))) return vkp_fail(why, n, "loading " #name, VK_SUCCESS);
    VKP_INSTANCE_FUNCS(VKP_LOAD_I)
#undef VKP_LOAD_I
    if (validate) {
        PFN_vkCreateDebugUtilsMessengerEXT create =
            (PFN_vkCreateDebugUtilsMessengerEXT)p->gipa(p->inst, "vkCreateDebugUtilsMessengerEXT");
        p->destroy_messenger = (PFN_vkDestroyDebugUtilsMessengerEXT)p->gipa(p->inst, "vkDestroyDebugUtilsMessengerEXT");
        if (!create || !p->destroy_messenger || (r = create(p->inst, &mi, NULL, &p->messenger)) != VK_SUCCESS) {
            p->messenger = VK_NULL_HANDLE;
            snprintf(why, n, "no debug messenger for the validation layer");
            return 1;
        }
    }
    if ((r = p->vkEnumeratePhysicalDevices(p->inst, &nd, devices)) < VK_SUCCESS) {
        snprintf(why, n, "no Vulkan device (vkEnumeratePhysicalDevices: VkResult %d)", (int)r);
        return 1;
    }
    snprintf(reason, sizeof reason, "no Vulkan device");
    for (i = 0; i < nd; ++i) {
        uint32_t fam;
        char r1[256];
        if (vkp_device_fit(p, devices[i], &fam, r1, sizeof r1) == 0) {
            p->pd = devices[i];
            p->family = fam;
            break;
        }
        if (i == 0) snprintf(reason, sizeof reason, "%s", r1); /* the first device's reason */
    }
    if (!p->pd) {
        snprintf(why, n, "%s", reason);
        return 1;
    }
    p->vkGetPhysicalDeviceProperties(p->pd, &props);
    p->vkGetPhysicalDeviceMemoryProperties(p->pd, &p->memory);
    p->vkGetPhysicalDeviceQueueFamilyProperties(p->pd, &nf, fams);
    snprintf(p->device_name, sizeof p->device_name, "%s", props.deviceName);
    p->ns_per_tick = (double)props.limits.timestampPeriod;
    p->tick_mask = fams[p->family].timestampValidBits >= 64 ? ~0ull : (1ull << fams[p->family].timestampValidBits) - 1ull;
    p->scratch_align = 256;

    vkp_rt_chain_init(&c);
    if (vkp_is_rt(p)) {
        VkPhysicalDeviceProperties2 pp;
        VkPhysicalDeviceAccelerationStructurePropertiesKHR asp;
        c.f12.bufferDeviceAddress = VK_TRUE;
        c.fas.accelerationStructure = VK_TRUE;
        c.frq.rayQuery = VK_TRUE;
        memset(&pp, 0, sizeof pp);
        memset(&asp, 0, sizeof asp);
        pp.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
        asp.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR;
        pp.pNext = &asp;
        p->vkGetPhysicalDeviceProperties2(p->pd, &pp);
        if (asp.minAccelerationStructureScratchOffsetAlignment > p->scratch_align)
            p->scratch_align = asp.minAccelerationStructureScratchOffsetAlignment;
    }
    r = vkp_is_rt(p) ? lrt_vku_create_vk_device(p->vkCreateDevice, p->pd, p->family, &c.f2, rt_exts, 3, &p->dev)
                     : lrt_vku_create_vk_device(p->vkCreateDevice, p->pd, p->family, NULL, NULL, 0, &p->dev);
    if (r != VK_SUCCESS) {
        p->dev = VK_NULL_HANDLE;
        return vkp_fail(why, n, "vkCreateDevice", r);
    }
#define VKP_LOAD_D(name)                                                                                           \
    if (!(p->name = (PFN_##name)p->vkGetDeviceProcAddr(p->dev, #name))) return vkp_fail(why, n, "loading " #name, VK_SUCCESS);
    VKP_DEVICE_FUNCS(VKP_LOAD_D)
    if (vkp_is_rt(p)) {
        VKP_RT_FUNCS(VKP_LOAD_D)
    }
#undef VKP_LOAD_D
    p->vkGetDeviceQueue(p->dev, p->family, 0, &p->queue);
    return 0;
}

/* command pool, buffer, fence, 2 timestamps */
static int vkp_create_commands(vkp *p, char *why, size_t n)
{
    VkCommandPoolCreateInfo pi;
    VkCommandBufferAllocateInfo ai;
    VkFenceCreateInfo fi;
    VkQueryPoolCreateInfo qi;
    VkResult r;
    memset(&pi, 0, sizeof pi);
    pi.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pi.queueFamilyIndex = p->family;
    if ((r = p->vkCreateCommandPool(p->dev, &pi, NULL, &p->pool)) != VK_SUCCESS)
        return vkp_fail(why, n, "vkCreateCommandPool", r);
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    ai.commandPool = p->pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    if ((r = p->vkAllocateCommandBuffers(p->dev, &ai, &p->cmd)) != VK_SUCCESS)
        return vkp_fail(why, n, "vkAllocateCommandBuffers", r);
    memset(&fi, 0, sizeof fi);
    fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    if ((r = p->vkCreateFence(p->dev, &fi, NULL, &p->fence)) != VK_SUCCESS) return vkp_fail(why, n, "vkCreateFence", r);
    memset(&qi, 0, sizeof qi);
    qi.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
    qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qi.queryCount = 2;
    if ((r = p->vkCreateQueryPool(p->dev, &qi, NULL, &p->queries)) != VK_SUCCESS)
        return vkp_fail(why, n, "vkCreateQueryPool", r);
    return 0;
}

/* The descriptor bindings of a kind: 0 depth, 1 rays, 2 hits, 3 table,
   4 aux (AABBs or Hi-Z levels), 5 TLAS (vkp_common.glsl). */
static uint32_t vkp_bindings(const vkp *p)
{
    switch (p->kind) {
    case VKP_RQ_AABB: return 0x3fu;
    case VKP_RQ_TRI: return 0x2fu;
    case VKP_HIZ: return 0x17u;
    default: return 0x07u;
    }
}

static int vkp_pipeline(vkp *p, const uint32_t *code, size_t size, VkPipeline *out, char *why, size_t n)
{
    VkShaderModuleCreateInfo mi;
    VkComputePipelineCreateInfo ci;
    VkShaderModule module;
    VkResult r;
    memset(&mi, 0, sizeof mi);
    mi.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    mi.codeSize = size;
    mi.pCode = code;
    if ((r = p->vkCreateShaderModule(p->dev, &mi, NULL, &module)) != VK_SUCCESS)
        return vkp_fail(why, n, "vkCreateShaderModule", r);
    memset(&ci, 0, sizeof ci);
    ci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = module;
    ci.stage.pName = "main";
    ci.layout = p->layout;
    r = p->vkCreateComputePipelines(p->dev, VK_NULL_HANDLE, 1, &ci, NULL, out);
    p->vkDestroyShaderModule(p->dev, module, NULL);
    if (r != VK_SUCCESS) {
        *out = VK_NULL_HANDLE;
        return vkp_fail(why, n, "vkCreateComputePipelines", r);
    }
    return 0;
}

/* bench/gpu_stats.c makes these layouts again (gs_peer_row), a program of
   its own that weighs the kernels on RADV: the copy there must stay in step
   with this one. */
static int vkp_create_pipelines(vkp *p, char *why, size_t n)
{
    VkDescriptorSetLayoutBinding b[6];
    VkDescriptorSetLayoutCreateInfo li;
    VkPushConstantRange pr;
    VkPipelineLayoutCreateInfo pli;
    VkDescriptorPoolSize ps[2];
    VkDescriptorPoolCreateInfo dpi;
    VkDescriptorSetAllocateInfo dai;
    uint32_t mask = vkp_bindings(p), nb = 0, k;
    VkResult r;
    int e = 0;
    memset(b, 0, sizeof b);
    for (k = 0; k < 6; ++k) {
        if (!((mask >> k) & 1u)) continue;
        b[nb].binding = k;
        b[nb].descriptorType = k == 5 ? VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        b[nb].descriptorCount = 1;
        b[nb].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
        ++nb;
    }
    memset(&li, 0, sizeof li);
    li.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    li.bindingCount = nb;
    li.pBindings = b;
    if ((r = p->vkCreateDescriptorSetLayout(p->dev, &li, NULL, &p->dsl)) != VK_SUCCESS)
        return vkp_fail(why, n, "vkCreateDescriptorSetLayout", r);
    memset(&pr, 0, sizeof pr);
    pr.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    pr.size = sizeof(vkp_push);
    memset(&pli, 0, sizeof pli);
    pli.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    pli.setLayoutCount = 1;
    pli.pSetLayouts = &p->dsl;
    pli.pushConstantRangeCount = 1;
    pli.pPushConstantRanges = &pr;
    if ((r = p->vkCreatePipelineLayout(p->dev, &pli, NULL, &p->layout)) != VK_SUCCESS)
        return vkp_fail(why, n, "vkCreatePipelineLayout", r);
    memset(ps, 0, sizeof ps);
    ps[0].type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    ps[0].descriptorCount = 5;
    ps[1].type = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
    ps[1].descriptorCount = 1;
    memset(&dpi, 0, sizeof dpi);
    dpi.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    dpi.maxSets = 1;
    dpi.poolSizeCount = vkp_is_rt(p) ? 2u : 1u;
    dpi.pPoolSizes = ps;
    if ((r = p->vkCreateDescriptorPool(p->dev, &dpi, NULL, &p->dpool)) != VK_SUCCESS)
        return vkp_fail(why, n, "vkCreateDescriptorPool", r);
    memset(&dai, 0, sizeof dai);
    dai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    dai.descriptorPool = p->dpool;
    dai.descriptorSetCount = 1;
    dai.pSetLayouts = &p->dsl;
    if ((r = p->vkAllocateDescriptorSets(p->dev, &dai, &p->set)) != VK_SUCCESS)
        return vkp_fail(why, n, "vkAllocateDescriptorSets", r);
    switch (p->kind) {
    case VKP_RQ_AABB:
        e = vkp_pipeline(p, vkp_spv_rq_aabb, vkp_spv_rq_aabb_SIZE, &p->trace_pipe, why, n) ||
            vkp_pipeline(p, vkp_spv_aabb_gen, vkp_spv_aabb_gen_SIZE, &p->prep_pipe, why, n);
        break;
    case VKP_RQ_TRI: e = vkp_pipeline(p, vkp_spv_rq_tri, vkp_spv_rq_tri_SIZE, &p->trace_pipe, why, n); break;
    case VKP_MARCH64: e = vkp_pipeline(p, vkp_spv_march64, vkp_spv_march64_SIZE, &p->trace_pipe, why, n); break;
    case VKP_DDA: e = vkp_pipeline(p, vkp_spv_dda, vkp_spv_dda_SIZE, &p->trace_pipe, why, n); break;
    default:
        e = vkp_pipeline(p, vkp_spv_hiz, vkp_spv_hiz_SIZE, &p->trace_pipe, why, n) ||
            vkp_pipeline(p, vkp_spv_hiz_mip, vkp_spv_hiz_mip_SIZE, &p->prep_pipe, why, n);
        break;
    }
    return e;
}

/* points every binding of the kind at the current buffers */
static void vkp_write_set(vkp *p)
{
    VkDescriptorBufferInfo bi[5];
    VkWriteDescriptorSet wr[6];
    VkWriteDescriptorSetAccelerationStructureKHR wa;
    const vkp_buf *bufs[5];
    uint32_t mask = vkp_bindings(p), nw = 0, k;
    bufs[0] = &p->depth;
    bufs[1] = &p->rays;
    bufs[2] = &p->hits;
    bufs[3] = &p->table;
    bufs[4] = &p->aux;
    memset(wr, 0, sizeof wr);
    for (k = 0; k < 6; ++k) {
        if (!((mask >> k) & 1u)) continue;
        wr[nw].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        wr[nw].dstSet = p->set;
        wr[nw].dstBinding = k;
        wr[nw].descriptorCount = 1;
        if (k == 5) {
            memset(&wa, 0, sizeof wa);
            wa.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR;
            wa.accelerationStructureCount = 1;
            wa.pAccelerationStructures = &p->tlas.as;
            wr[nw].pNext = &wa;
            wr[nw].descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
        } else {
            bi[k].buffer = bufs[k]->buf;
            bi[k].offset = 0;
            bi[k].range = VK_WHOLE_SIZE;
            wr[nw].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            wr[nw].pBufferInfo = &bi[k];
        }
        ++nw;
    }
    p->vkUpdateDescriptorSets(p->dev, nw, wr, 0, NULL);
}

/* ---- recording and submitting ------------------------------------------------------ */
static void vkp_barrier(vkp *p, VkPipelineStageFlags src, VkAccessFlags src_access, VkPipelineStageFlags dst,
                        VkAccessFlags dst_access)
{
    lrt_vku_memory_barrier(p->vkCmdPipelineBarrier, p->cmd, src, src_access, dst, dst_access);
}

/* Begins the command buffer: the last submission's writes -> everything
   here (a fence orders the host, not the next submission), then the first
   timestamp. */
static int vkp_begin(vkp *p, char *why, size_t n)
{
    VkCommandBufferBeginInfo bi;
    VkResult r;
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    if ((r = p->vkResetCommandBuffer(p->cmd, 0)) != VK_SUCCESS || (r = p->vkBeginCommandBuffer(p->cmd, &bi)) != VK_SUCCESS)
        return vkp_fail(why, n, "vkBeginCommandBuffer", r);
    vkp_barrier(p, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
    p->vkCmdResetQueryPool(p->cmd, p->queries, 0, 2);
    p->vkCmdWriteTimestamp(p->cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, p->queries, 0);
    return 0;
}

/* The second timestamp, the writes -> the host, submit, wait: gpu_ms from
   the timestamps, wall_ms from the host clock. */
static int vkp_end_submit(vkp *p, char *why, size_t n)
{
    VkSubmitInfo si;
    uint64_t ts[2];
    double t0;
    VkResult r;
    p->vkCmdWriteTimestamp(p->cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, p->queries, 1);
    vkp_barrier(p, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                VK_ACCESS_HOST_READ_BIT);
    if ((r = p->vkEndCommandBuffer(p->cmd)) != VK_SUCCESS) return vkp_fail(why, n, "vkEndCommandBuffer", r);
    memset(&si, 0, sizeof si);
    si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &p->cmd;
    t0 = bench_now_ms();
    if ((r = p->vkResetFences(p->dev, 1, &p->fence)) != VK_SUCCESS || (r = p->vkQueueSubmit(p->queue, 1, &si, p->fence)) != VK_SUCCESS)
        return vkp_fail(why, n, "vkQueueSubmit", r);
    if ((r = p->vkWaitForFences(p->dev, 1, &p->fence, VK_TRUE, UINT64_MAX)) != VK_SUCCESS)
        return vkp_fail(why, n, "vkWaitForFences", r);
    p->wall_ms = bench_now_ms() - t0;
    if ((r = p->vkGetQueryPoolResults(p->dev, p->queries, 0, 2, sizeof ts, ts, sizeof ts[0],
                                      VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT)) != VK_SUCCESS)
        return vkp_fail(why, n, "vkGetQueryPoolResults", r);
    p->gpu_ms = (double)((ts[1] - ts[0]) & p->tick_mask) * p->ns_per_tick * 1e-6;
    return 0;
}

/* count invocations of the bound pipeline, split into dispatches of at most
   VKP_MAX_GROUPS groups (push: ray_first, ray_count of each) */
static void vkp_dispatch(vkp *p, vkp_push *push, uint64_t count)
{
    const uint64_t per = (uint64_t)VKP_MAX_GROUPS * VKP_GROUP;
    uint64_t first;
    for (first = 0; first < count; first += per) {
        uint64_t c = count - first < per ? count - first : per;
        push->ray_first = (uint32_t)first;
        push->ray_count = (uint32_t)c;
        p->vkCmdPushConstants(p->cmd, p->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof *push, push);
        p->vkCmdDispatch(p->cmd, (uint32_t)((c + VKP_GROUP - 1) / VKP_GROUP), 1, 1);
    }
}

static void vkp_push_init(const vkp *p, vkp_push *push)
{
    memset(push, 0, sizeof *push);
    push->width = p->w;
    push->height = p->h;
    push->level_count = p->levels;
    push->flags = p->has_back ? 2u : 0u; /* vkp_common.glsl's VKP_FLAG_BACK */
    memcpy(push->offsets, p->offsets, sizeof push->offsets);
}

/* ---- scene ------------------------------------------------------------------------- */
/* Writes the scene's depth into the depth buffer, clamped as docs/MODEL.md says
   (the harness's maps are already clamped; this keeps NaN out of an AABB),
   then with a thickness each texel's back b = max(depth, back), read and
   clamped the same way. */
static void vkp_upload_depth(vkp *p, const bench_scene *sc)
{
    float *d = (float *)p->depth.map;
    size_t i, count = (size_t)p->w * p->h;
    for (i = 0; i < count; ++i) d[i] = march_depth(sc->depth[i]);
    p->has_back = sc->back != NULL;
    for (i = 0; p->has_back && i < count; ++i) {
        const float b = march_depth(sc->back[i]);
        d[count + i] = b > d[i] ? b : d[i];
    }
}

/* the texels of a w x h map in Z (Morton) order: quadrants (x0,y0),
   (x0+s,y0), (x0,y0+s), (x0+s,y0+s) recursively, texels off the map skipped */
static void vkp_zorder(uint32_t *out, size_t *k, uint32_t w, uint32_t h, uint32_t x0, uint32_t y0, uint32_t size)
{
    uint32_t s = size / 2;
    if (x0 >= w || y0 >= h) return;
    if (size == 1) {
        out[(*k)++] = y0 * w + x0;
        return;
    }
    vkp_zorder(out, k, w, h, x0, y0, s);
    vkp_zorder(out, k, w, h, x0 + s, y0, s);
    vkp_zorder(out, k, w, h, x0, y0 + s, s);
    vkp_zorder(out, k, w, h, x0 + s, y0 + s, s);
}

static void vkp_zorder_all(uint32_t *out, uint32_t w, uint32_t h)
{
    uint32_t size = 1;
    size_t k = 0;
    while (size < w || size < h) size *= 2;
    vkp_zorder(out, &k, w, h, 0, 0, size);
}

/* Buffers of the scene's size that every kind has: depth, rays and hits
   (a first 64K rays; trace grows them). */
static int vkp_size_common(vkp *p, const bench_scene *sc, char *why, size_t n)
{
    const VkBufferUsageFlags st = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    size_t texels = (size_t)sc->width * sc->height;
    if (p->depth.buf && p->w == sc->width && p->h == sc->height) return 0;
    p->w = sc->width;
    p->h = sc->height;
    p->built = 0;
    vkp_buf_destroy(p, &p->depth);
    if (vkp_buf_create(p, 2 * texels * sizeof(float), st, 1, &p->depth, why, n)) return 1; /* depth, back */
    if (!p->rays.buf) {
        p->ray_cap = 65536;
        if (vkp_buf_create(p, p->ray_cap * sizeof(lrt_ray), st, 1, &p->rays, why, n) ||
            vkp_buf_create(p, p->ray_cap * sizeof(lrt_hit), st, 1, &p->hits, why, n))
            return 1;
    }
    return 0;
}

/* ---- acceleration structures ------------------------------------------------------- */
static VkDeviceAddress vkp_as_address(vkp *p, VkAccelerationStructureKHR as)
{
    VkAccelerationStructureDeviceAddressInfoKHR ai;
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR;
    ai.accelerationStructure = as;
    return p->vkGetAccelerationStructureDeviceAddressKHR(p->dev, &ai);
}

static void vkp_as_destroy(vkp *p, vkp_as *a)
{
    if (a->as) p->vkDestroyAccelerationStructureKHR(p->dev, a->as, NULL);
    vkp_buf_destroy(p, &a->store);
    memset(a, 0, sizeof *a);
}

/* a holds a structure of type with at least size bytes; *fresh = 1 if it
   was (re)created */
static int vkp_as_reserve(vkp *p, vkp_as *a, VkAccelerationStructureTypeKHR type, VkDeviceSize size, int *fresh,
                          char *why, size_t n)
{
    VkAccelerationStructureCreateInfoKHR ci;
    VkResult r;
    *fresh = 0;
    if (a->as && a->capacity >= size) return 0;
    vkp_as_destroy(p, a);
    *fresh = 1;
    if (vkp_buf_create(p, size,
                       VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                       0, &a->store, why, n))
        return 1;
    memset(&ci, 0, sizeof ci);
    ci.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR;
    ci.buffer = a->store.buf;
    ci.size = size;
    ci.type = type;
    if ((r = p->vkCreateAccelerationStructureKHR(p->dev, &ci, NULL, &a->as)) != VK_SUCCESS) {
        a->as = VK_NULL_HANDLE;
        return vkp_fail(why, n, "vkCreateAccelerationStructureKHR", r);
    }
    a->capacity = size;
    a->addr = vkp_as_address(p, a->as);
    return 0;
}

/* The build description of the BLAS (AABBs or triangles over p->aux /
   p->verts, p->prims primitives) or of the TLAS (one instance). */
static void vkp_geometry(const vkp *p, int top, VkAccelerationStructureGeometryKHR *g,
                         VkAccelerationStructureBuildGeometryInfoKHR *bi)
{
    memset(g, 0, sizeof *g);
    memset(bi, 0, sizeof *bi);
    g->sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
    if (top) {
        g->geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
        g->geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
        g->geometry.instances.data.deviceAddress = p->instances.addr;
    } else if (p->kind == VKP_RQ_AABB) {
        g->geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
        g->geometry.aabbs.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
        g->geometry.aabbs.data.deviceAddress = p->aux.addr;
        g->geometry.aabbs.stride = sizeof(VkAabbPositionsKHR);
    } else {
        g->geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
        g->flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
        g->geometry.triangles.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
        g->geometry.triangles.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
        g->geometry.triangles.vertexData.deviceAddress = p->verts.addr;
        g->geometry.triangles.vertexStride = 3 * sizeof(float);
        g->geometry.triangles.maxVertex = p->prims * 3u - 1u;
        g->geometry.triangles.indexType = VK_INDEX_TYPE_NONE_KHR;
    }
    bi->sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR;
    bi->type = top ? VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR : VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    /* AABBs: refitted by update (same primitives, new heights); triangles:
       rebuilt (the walls come and go with the depth) */
    bi->flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    if (p->kind == VKP_RQ_AABB) bi->flags |= VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
    bi->mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    bi->geometryCount = 1;
    bi->pGeometries = g;
}

/* Sizes both structures for p->prims primitives, (re)creates what is too
   small, the scratch and the instance; *fresh if the structures are new
   (then only a BUILD, not an UPDATE, may follow). */
static int vkp_as_prepare(vkp *p, int *fresh, char *why, size_t n)
{
    VkAccelerationStructureGeometryKHR g;
    VkAccelerationStructureBuildGeometryInfoKHR bi;
    VkAccelerationStructureBuildSizesInfoKHR bs, ts;
    const uint32_t one = 1;
    VkDeviceSize scratch;
    int fb = 0, ft = 0;
    memset(&bs, 0, sizeof bs);
    memset(&ts, 0, sizeof ts);
    bs.sType = ts.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR;
    vkp_geometry(p, 0, &g, &bi);
    p->vkGetAccelerationStructureBuildSizesKHR(p->dev, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &bi, &p->prims, &bs);
    vkp_geometry(p, 1, &g, &bi);
    p->vkGetAccelerationStructureBuildSizesKHR(p->dev, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &bi, &one, &ts);
    p->blas_bytes = bs.accelerationStructureSize;
    p->tlas_bytes = ts.accelerationStructureSize;
    if (vkp_as_reserve(p, &p->blas, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, bs.accelerationStructureSize, &fb,
                       why, n) ||
        vkp_as_reserve(p, &p->tlas, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, ts.accelerationStructureSize, &ft, why,
                       n))
        return 1;
    scratch = bs.buildScratchSize;
    if (bs.updateScratchSize > scratch) scratch = bs.updateScratchSize;
    if (ts.buildScratchSize > scratch) scratch = ts.buildScratchSize;
    if (ts.updateScratchSize > scratch) scratch = ts.updateScratchSize;
    if (vkp_buf_reserve(p, scratch + p->scratch_align,
                        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT, 0, &p->scratch,
                        why, n))
        return 1;
    if (!p->instances.buf &&
        vkp_buf_create(p, 64,
                       VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                           VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                       1, &p->instances, why, n))
        return 1;
    if (fb || ft) {
        /* VkAccelerationStructureInstanceKHR, written field by field: identity
           transform, custom index 0, mask 0xff, SBT offset 0, flags (culling
           off), the BLAS */
        static const float identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
        unsigned char *inst = (unsigned char *)p->instances.map;
        uint32_t word = 0xffu << 24;
        uint64_t ref = p->blas.addr;
        memcpy(inst, identity, sizeof identity);
        memcpy(inst + 48, &word, 4);
        word = (uint32_t)VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR << 24;
        memcpy(inst + 52, &word, 4);
        memcpy(inst + 56, &ref, 8);
        vkp_write_set(p); /* a new TLAS handle */
    }
    *fresh = fb || ft;
    return 0;
}

/* records the build (mode BUILD) or refit (mode UPDATE, in place) of the
   BLAS and then the TLAS; the AS writes -> the ray queries of later commands */
static void vkp_record_as(vkp *p, int update)
{
    VkAccelerationStructureGeometryKHR g;
    VkAccelerationStructureBuildGeometryInfoKHR bi;
    VkAccelerationStructureBuildRangeInfoKHR range;
    const VkAccelerationStructureBuildRangeInfoKHR *ranges = &range;
    const VkDeviceAddress scratch = (p->scratch.addr + p->scratch_align - 1) & ~(VkDeviceAddress)(p->scratch_align - 1);
    int top;
    for (top = 0; top < 2; ++top) {
        vkp_geometry(p, top, &g, &bi);
        if (update) {
            bi.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
            bi.srcAccelerationStructure = top ? p->tlas.as : p->blas.as;
        }
        bi.dstAccelerationStructure = top ? p->tlas.as : p->blas.as;
        bi.scratchData.deviceAddress = scratch;
        memset(&range, 0, sizeof range);
        range.primitiveCount = top ? 1u : p->prims;
        p->vkCmdBuildAccelerationStructuresKHR(p->cmd, 1, &bi, &ranges);
        /* BLAS -> TLAS (and the shared scratch); TLAS -> the queries */
        vkp_barrier(p, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                    VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR | VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR,
                    top ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT : VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                    VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR |
                        (top ? 0u : (VkAccessFlags)VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR));
    }
}

/* ---- the AABB BVH ------------------------------------------------------------------ */
static int aabb_build(vkp *p, const bench_scene *sc, int update, double *ms, char *why, size_t n)
{
    const VkBufferUsageFlags st = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    size_t texels = (size_t)sc->width * sc->height;
    vkp_push push;
    int fresh = 0;
    if (vkp_size_common(p, sc, why, n)) return 1;
    if (!p->built) {
        if (texels > 0x7fffffffu / 6u) {
            snprintf(why, n, "map too large for one AABB per texel");
            return 1;
        }
        p->prims = (uint32_t)texels;
        if (vkp_buf_reserve(p, texels * 4u, st, 1, &p->table, why, n) ||
            vkp_buf_reserve(p, texels * sizeof(VkAabbPositionsKHR),
                            st | VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                                VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                            0, &p->aux, why, n))
            return 1;
        vkp_zorder_all((uint32_t *)p->table.map, p->w, p->h);
        if (vkp_as_prepare(p, &fresh, why, n)) return 1;
        vkp_write_set(p);
        update = 0;
    }
    vkp_upload_depth(p, sc);
    vkp_push_init(p, &push);
    if (!p->warm) { /* untimed: the kernel's first run, where lavapipe compiles it */
        if (vkp_begin(p, why, n)) return 1;
        p->vkCmdBindPipeline(p->cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p->prep_pipe);
        p->vkCmdBindDescriptorSets(p->cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p->layout, 0, 1, &p->set, 0, NULL);
        vkp_dispatch(p, &push, p->prims);
        if (vkp_end_submit(p, why, n)) return 1;
        p->warm = 1;
    }
    /* timed: the AABBs from depth (one dispatch), the BLAS and the TLAS */
    if (vkp_begin(p, why, n)) return 1;
    p->vkCmdBindPipeline(p->cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p->prep_pipe);
    p->vkCmdBindDescriptorSets(p->cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p->layout, 0, 1, &p->set, 0, NULL);
    vkp_dispatch(p, &push, p->prims);
    vkp_barrier(p, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_ACCESS_SHADER_READ_BIT);
    vkp_record_as(p, update);
    if (vkp_end_submit(p, why, n)) return 1;
    p->built = 1;
    p->host_ms = 0;
    *ms = p->gpu_ms;
    return 0;
}

/* ---- the triangle BVH ---------------------------------------------------------------- */
/* a quad a b c d (in order around it) as triangles a b c and a c d of texel t */
static void tri_quad(float **v, uint32_t **owner, const float a[3], const float b[3], const float c[3],
                     const float d[3], uint32_t t)
{
    float *o = *v;
    memcpy(o, a, 12);
    memcpy(o + 3, b, 12);
    memcpy(o + 6, c, 12);
    memcpy(o + 9, a, 12);
    memcpy(o + 12, c, 12);
    memcpy(o + 15, d, 12);
    *v = o + 18;
    (*owner)[0] = (*owner)[1] = t;
    *owner += 2;
}

/* The triangles of texel (i, j), in this order: its top, the walls towards
   its right and lower neighbours where the depths differ (owned by the
   nearer texel), and its walls on the screen border. Counts them when v is
   NULL. Returns the number of triangles. */
static uint32_t tri_texel(const float *dm, uint32_t w, uint32_t h, uint32_t i, uint32_t j, float **v,
                          uint32_t **owner)
{
    const uint32_t t = j * w + i;
    const float d = dm[t], x0 = (float)i, x1 = (float)(i + 1), y0 = (float)j, y1 = (float)(j + 1);
    uint32_t count = 2;
    if (v) {
        float a[3] = {x0, y0, d}, b[3] = {x1, y0, d}, c[3] = {x1, y1, d}, e[3] = {x0, y1, d};
        tri_quad(v, owner, a, b, c, e, t);
    }
    if (i + 1 < w && dm[t + 1] != d) { /* wall on x = i+1 */
        float lo = d < dm[t + 1] ? d : dm[t + 1], hi = d < dm[t + 1] ? dm[t + 1] : d;
        count += 2;
        if (v) {
            float a[3] = {x1, y0, lo}, b[3] = {x1, y1, lo}, c[3] = {x1, y1, hi}, e[3] = {x1, y0, hi};
            tri_quad(v, owner, a, b, c, e, d < dm[t + 1] ? t : t + 1);
        }
    }
    if (j + 1 < h && dm[t + w] != d) { /* wall on y = j+1 */
        float lo = d < dm[t + w] ? d : dm[t + w], hi = d < dm[t + w] ? dm[t + w] : d;
        count += 2;
        if (v) {
            float a[3] = {x0, y1, lo}, b[3] = {x1, y1, lo}, c[3] = {x1, y1, hi}, e[3] = {x0, y1, hi};
            tri_quad(v, owner, a, b, c, e, d < dm[t + w] ? t : t + w);
        }
    }
    if (d < 1.0f) { /* the border: from the top down to the far plane */
        int side;
        for (side = 0; side < 4; ++side) {
            int on = side == 0 ? i == 0 : side == 1 ? i + 1 == w : side == 2 ? j == 0 : j + 1 == h;
            if (!on) continue;
            count += 2;
            if (v) {
                float x = side == 1 ? x1 : x0, y = side == 3 ? y1 : y0;
                float a[3], b[3], c[3], e[3];
                if (side < 2) { /* x = x, y from y0 to y1 */
                    a[0] = b[0] = c[0] = e[0] = x;
                    a[1] = e[1] = y0;
                    b[1] = c[1] = y1;
                } else {
                    a[1] = b[1] = c[1] = e[1] = y;
                    a[0] = e[0] = x0;
                    b[0] = c[0] = x1;
                }
                a[2] = b[2] = d;
                c[2] = e[2] = 1.0f;
                tri_quad(v, owner, a, b, c, e, t);
            }
        }
    }
    return count;
}

static int tri_build(vkp *p, const bench_scene *sc, double *ms, char *why, size_t n)
{
    const VkBufferUsageFlags st = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    size_t texels = (size_t)sc->width * sc->height, k;
    uint64_t count = 0;
    uint32_t *order;
    float *v;
    uint32_t *owner;
    double t0;
    int fresh = 0;
    if (vkp_size_common(p, sc, why, n)) return 1;
    vkp_upload_depth(p, sc);
    order = (uint32_t *)malloc(texels * sizeof *order);
    if (!order) {
        snprintf(why, n, "out of memory");
        return 1;
    }
    /* timed on the host: the triangles from depth, in Z order of texels */
    t0 = bench_now_ms();
    vkp_zorder_all(order, p->w, p->h);
    {
        const float *dm = (const float *)p->depth.map;
        for (k = 0; k < texels; ++k) count += tri_texel(dm, p->w, p->h, order[k] % p->w, order[k] / p->w, NULL, NULL);
        if (count > 0x7fffffffu / 9u) {
            free(order);
            snprintf(why, n, "map too large for its triangles");
            return 1;
        }
        p->prims = (uint32_t)count;
        if (vkp_buf_reserve(p, count * 4u, st, 1, &p->table, why, n) ||
            vkp_buf_reserve(p, count * 36u,
                            st | VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                                VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                            1, &p->verts, why, n)) {
            free(order);
            return 1;
        }
        v = (float *)p->verts.map;
        owner = (uint32_t *)p->table.map;
        for (k = 0; k < texels; ++k) tri_texel(dm, p->w, p->h, order[k] % p->w, order[k] / p->w, &v, &owner);
    }
    p->host_ms = bench_now_ms() - t0;
    free(order);
    if (vkp_as_prepare(p, &fresh, why, n)) return 1;
    vkp_write_set(p); /* the table may be new */
    /* timed on the GPU: the BLAS and the TLAS, built anew */
    if (vkp_begin(p, why, n)) return 1;
    vkp_record_as(p, 0);
    if (vkp_end_submit(p, why, n)) return 1;
    p->built = 1;
    *ms = p->host_ms + p->gpu_ms;
    return 0;
}

/* ---- the marches -------------------------------------------------------------------- */
static int march_build(vkp *p, const bench_scene *sc, double *ms, char *why, size_t n)
{
    vkp_push push;
    uint32_t k;
    int pass;
    *ms = 0;
    p->gpu_ms = p->wall_ms = p->host_ms = 0;
    if (vkp_size_common(p, sc, why, n)) return 1;
    if (!p->built && p->kind == VKP_HIZ) { /* the levels: ceil(W / 2^k) x ceil(H / 2^k) down to 1 x 1 */
        uint64_t total = 0;
        uint32_t lw = p->w, lh = p->h;
        p->levels = 1;
        memset(p->offsets, 0, sizeof p->offsets);
        while ((lw > 1 || lh > 1) && p->levels < VKP_MAX_LEVELS) {
            lw = (lw + 1) / 2;
            lh = (lh + 1) / 2;
            p->offsets[p->levels++] = (uint32_t)total;
            total += (uint64_t)lw * lh;
        }
        p->aux_bytes = total * sizeof(float);
        if (vkp_buf_reserve(p, p->aux_bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 0, &p->aux, why, n)) return 1;
    }
    if (!p->built) {
        vkp_write_set(p);
        p->built = 1;
    }
    vkp_upload_depth(p, sc);
    if (p->kind != VKP_HIZ) return 0; /* a march has nothing to build */
    /* timed: one dispatch per level, each reading the one before (untimed
       once before: the kernel's first run, where lavapipe compiles it) */
    for (pass = p->warm; pass < 2; ++pass) {
        if (vkp_begin(p, why, n)) return 1;
        vkp_push_init(p, &push);
        p->vkCmdBindPipeline(p->cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p->prep_pipe);
        p->vkCmdBindDescriptorSets(p->cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p->layout, 0, 1, &p->set, 0, NULL);
        for (k = 1; k < p->levels; ++k) {
            uint64_t lw = (p->w + (1u << k) - 1) >> k, lh = (p->h + (1u << k) - 1) >> k;
            push.level = k;
            vkp_dispatch(p, &push, lw * lh);
            vkp_barrier(p, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
        }
        if (vkp_end_submit(p, why, n)) return 1;
    }
    p->warm = 1;
    *ms = p->gpu_ms;
    return 0;
}

/* ---- the methods --------------------------------------------------------------------- */
static int vkp_open(bench_method *m, uint32_t width, uint32_t height, int threads, char *why, size_t n)
{
    vkp *p = (vkp *)m->impl;
    (void)width;
    (void)height;
    (void)threads; /* lavapipe's threads: LP_NUM_THREADS */
    if (p->dev) return 0;
    if (vkp_create_device(p, why, n) || vkp_create_commands(p, why, n) || vkp_create_pipelines(p, why, n)) {
        vkp_release(p);
        return 1;
    }
    return 0;
}

static int vkp_build(bench_method *m, const bench_scene *sc, double *ms, char *why, size_t n)
{
    vkp *p = (vkp *)m->impl;
    *ms = 0;
    if (sc->back && p->kind == VKP_RQ_TRI) { /* its walls model the infinite layer: it would answer another model */
        snprintf(why, n, "triangle walls model the infinite layer only");
        return 1;
    }
    if (!p->dev) {
        snprintf(why, n, "not open");
        return 1;
    }
    if (p->kind == VKP_RQ_AABB) {
        p->built = p->built && p->w == sc->width && p->h == sc->height;
        return aabb_build(p, sc, 0, ms, why, n);
    }
    if (p->kind == VKP_RQ_TRI) return tri_build(p, sc, ms, why, n);
    return march_build(p, sc, ms, why, n);
}

/* AABBs: a refit (mode UPDATE, the BLAS and TLAS in place, after the AABBs
   are written from the new depth); triangles: a new build (the walls depend
   on the depth); Hi-Z: the levels again; the marches: nothing. */
static int vkp_update(bench_method *m, const bench_scene *sc, double *ms, char *why, size_t n)
{
    vkp *p = (vkp *)m->impl;
    *ms = 0;
    if (!p->dev || !p->built || p->w != sc->width || p->h != sc->height) {
        snprintf(why, n, "update before build, or of another size");
        return 1;
    }
    if (p->kind == VKP_RQ_AABB) return aabb_build(p, sc, 1, ms, why, n);
    if (p->kind == VKP_RQ_TRI) return tri_build(p, sc, ms, why, n);
    return march_build(p, sc, ms, why, n);
}

static int vkp_trace(bench_method *m, const bench_scene *sc, const bench_rays *rs, lrt_hit *hits, double *ms,
                     char *why, size_t n)
{
    vkp *p = (vkp *)m->impl;
    vkp_push push;
    uint32_t batch, i;
    *ms = 0;
    if (!p->dev || !p->built || p->w != sc->width || p->h != sc->height) {
        snprintf(why, n, "trace before build, or of another size");
        return 1;
    }
    if (rs->count == 0) return 0;
    if (rs->count > 0xffffffffu) {
        snprintf(why, n, "too many rays for one trace");
        return 1;
    }
    if (rs->count > p->ray_cap) {
        vkp_buf_destroy(p, &p->rays);
        vkp_buf_destroy(p, &p->hits);
        p->ray_cap = 0;
        if (vkp_buf_create(p, rs->count * sizeof(lrt_ray), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 1, &p->rays, why, n) ||
            vkp_buf_create(p, rs->count * sizeof(lrt_hit), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 1, &p->hits, why, n))
            return 1;
        p->ray_cap = rs->count;
        vkp_write_set(p);
    }
    memcpy(p->rays.map, rs->rays, rs->count * sizeof(lrt_ray));
    batch = bench_gpu_batch_size(&p->batch, rs->rays, rs->count);
    if (vkp_begin(p, why, n)) return 1;
    vkp_push_init(p, &push);
    push.flags |= (rs->flags & BENCH_ANY_HIT) ? 1u : 0u;
    p->vkCmdBindPipeline(p->cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p->trace_pipe);
    p->vkCmdBindDescriptorSets(p->cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p->layout, 0, 1, &p->set, 0, NULL);
    for (i = 0; i < batch; ++i) { /* back to back (bench_gpu_batch) */
        if (i) /* the same hits written again */
            vkp_barrier(p, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                        VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
        vkp_dispatch(p, &push, rs->count);
    }
    if (vkp_end_submit(p, why, n)) return 1;
    memcpy(hits, p->hits.map, rs->count * sizeof(lrt_hit));
    *ms = p->gpu_ms / batch;
    bench_gpu_batch_timed(&p->batch, *ms);
    return 0;
}

/* The structure a method keeps between frames: ray-query BVHs, the BLAS and
   TLAS (vkGetAccelerationStructureBuildSizesKHR's accelerationStructureSize)
   plus their build input (AABBs: 24 bytes a texel; triangles: 36 bytes a
   triangle) and the primitive -> texel table (4 bytes a primitive), scratch
   not counted; Hi-Z, its levels above the depth map; the marches, none. */
static size_t vkp_memory(bench_method *m)
{
    vkp *p = (vkp *)m->impl;
    if (!p->built) return 0;
    switch (p->kind) {
    case VKP_RQ_AABB:
        return (size_t)(p->blas_bytes + p->tlas_bytes) + (size_t)p->prims * (sizeof(VkAabbPositionsKHR) + 4u);
    case VKP_RQ_TRI: return (size_t)(p->blas_bytes + p->tlas_bytes) + (size_t)p->prims * (36u + 4u);
    case VKP_HIZ: return (size_t)p->aux_bytes;
    default: return 0;
    }
}

static void vkp_close(bench_method *m)
{
    vkp *p = (vkp *)m->impl;
    if (!p) return;
    vkp_release(p);
    free(p);
    m->impl = NULL;
}

int bench_add_vulkan_peers(bench_method *out, int max)
{
    int i;
    for (i = 0; i < VKP_KINDS && i < max; ++i) {
        vkp *p = (vkp *)calloc(1, sizeof *p);
        memset(&out[i], 0, sizeof out[i]);
        if (!p) return i;
        p->kind = i;
        out[i].name = vkp_names[i];
        out[i].device = "vulkan";
        out[i].exact = vkp_is_rt(p);
        out[i].impl = p;
        BENCH_METHOD_FUNCTIONS(out[i], vkp);
    }
    return i;
}

#else /* no Vulkan header, or the kernels were not compiled */

static int vkp_open_missing(bench_method *m, uint32_t width, uint32_t height, int threads, char *why, size_t n)
{
    (void)m;
    (void)width;
    (void)height;
    (void)threads;
#ifndef BENCH_HAVE_VULKAN
    snprintf(why, n, "built without <vulkan/vulkan.h> (Debian: libvulkan-dev)");
#else
    snprintf(why, n, "built without its kernels: glslangValidator was missing (Debian: glslang-tools)");
#endif
    return 1;
}

static void vkp_close_missing(bench_method *m) { (void)m; }

int bench_add_vulkan_peers(bench_method *out, int max)
{
    int i;
    for (i = 0; i < VKP_KINDS && i < max; ++i) {
        memset(&out[i], 0, sizeof out[i]);
        out[i].name = vkp_names[i];
        out[i].device = "vulkan";
        out[i].exact = i == VKP_RQ_AABB || i == VKP_RQ_TRI;
        out[i].open = vkp_open_missing;
        out[i].close = vkp_close_missing;
    }
    return i;
}
#endif
