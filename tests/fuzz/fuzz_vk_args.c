/* tests/fuzz/fuzz_vk_args.c - libFuzzer harness of the argument checks of
   linear_rt.h's Vulkan API, with no device and no loader.

   The library gets every Vulkan function from the vkGetInstanceProcAddr of
   lrt_vk_context_desc, so this harness hands it a mock: a table of small
   functions that make fake handles, count live objects, fail where the
   input says, report limits, features and memory types from the input, and
   record what the recording functions record. Nothing reaches a driver.

   From the input: the context's desc (NULL fields, allocation callbacks,
   a missing function, a missing feature, a Vulkan call that fails, an
   allocation that fails), the device's limits, then a sequence of calls
   (lrt_vk_bvh_buffer_sizes, lrt_vk_bvh_create, lrt_vk_cmd_build / update /
   trace) with garbage descs: sizes, formats, node bits, flags, buffers and
   views, offsets and strides, image layouts, dirty rects, ray counts.
   Checked: every result is one the header documents for the arguments
   given (success when none applies); an error records nothing and leaves
   nothing created; what is recorded stays inside the device's limits and
   binds what the arguments name; every object and allocation is freed. */
#define VK_NO_PROTOTYPES
#define LINEAR_RT_VULKAN
#define LINEAR_RT_IMPLEMENTATION
#include "../../linear_rt.h"
#include "fuzz_common.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct input { const uint8_t *p; size_t n, at; } input;
static uint8_t u8(input *in) { return in->at < in->n ? in->p[in->at++] : 0; }
static uint16_t u16(input *in) { uint16_t a = u8(in); return (uint16_t)(a | (uint16_t)u8(in) << 8); }
static uint32_t u32(input *in) { uint32_t a = u16(in); return a | (uint32_t)u16(in) << 16; }
static uint64_t u64(input *in) { uint64_t a = u32(in); return a | (uint64_t)u32(in) << 32; }

#define FAIL(...) (fprintf(stderr, "fuzz_vk_args: " __VA_ARGS__), fputc('\n', stderr), abort())

/* ---- result codes: the documented errors of one call ------------------------
   must: errors the arguments certainly have (any one may be returned);
   may: what a call may also answer (a policy the header leaves open). */
typedef uint32_t codes;
#define CODE(c) ((codes)1u << (c))

static void expect(const char *what, lrt_result got, codes must, codes may)
{
    if (got == LRT_SUCCESS && must == 0) return;
    if ((unsigned)got < 32 && ((must | may) & CODE(got))) return;
    FAIL("%s returned %d (%s); documented for these arguments: 0x%x (or 0x%x)", what, (int)got,
         lrt_result_string(got), (unsigned)must, (unsigned)may);
}

/* ---- the mock device -------------------------------------------------------------- */
static void injected(uint32_t calls0, uint32_t allocs0, codes *must);
typedef struct mock {
    /* from the input */
    uint32_t api_version, missing_fn, fail_call, enumerate_mode, no_feature;
    uint32_t mem_type_count, mem_flags[4], mem_type_bits, fail_alloc;
    VkPhysicalDeviceLimits limits;
    /* counters */
    uint32_t lookups, calls, allocs;
    int live_objects, live_allocs, alloc_failed, live_pipelines;
    VkResult last_error; /* of the last mock call that failed */
    uintptr_t next_handle;
    /* what was recorded */
    uint32_t commands;
    uint32_t gx, gy, gz;
    lrt__vk_push pc;
    uint32_t writes;
    VkDescriptorBufferInfo buf[10]; /* by binding */
    VkBufferView view;             /* binding 8, the nodes' texels */
    int has[10];
    VkDeviceSize fill_offset, fill_size;
} mock;
static mock g;

#define FAKE(type) ((type)(g.next_handle += 16))

/* every create may fail where the input says (the n-th call of the device) */
static VkResult next_call(void)
{
    if (++g.calls == g.fail_call) return g.last_error = VK_ERROR_OUT_OF_DEVICE_MEMORY;
    return VK_SUCCESS;
}

#define CREATE(name, Info, Handle)                                                                                \
    static VKAPI_ATTR VkResult VKAPI_CALL name(VkDevice d, const Info *info, const VkAllocationCallbacks *cb,     \
                                               Handle *out)                                                     \
    {                                                                                                             \
        VkResult r = next_call();                                                                                 \
        (void)d, (void)info, (void)cb;                                                                            \
        if (r != VK_SUCCESS) return r;                                                                            \
        *out = FAKE(Handle);                                                                                      \
        ++g.live_objects;                                                                                         \
        return VK_SUCCESS;                                                                                        \
    }
#define DESTROY(name, Handle)                                                                                     \
    static VKAPI_ATTR void VKAPI_CALL name(VkDevice d, Handle h, const VkAllocationCallbacks *cb)                 \
    {                                                                                                             \
        (void)d, (void)cb;                                                                                        \
        if (h == VK_NULL_HANDLE) FAIL(#name " of VK_NULL_HANDLE");                                               \
        --g.live_objects;                                                                                         \
    }
CREATE(m_CreateShaderModule, VkShaderModuleCreateInfo, VkShaderModule)
CREATE(m_CreateDescriptorSetLayout, VkDescriptorSetLayoutCreateInfo, VkDescriptorSetLayout)
CREATE(m_CreatePipelineLayout, VkPipelineLayoutCreateInfo, VkPipelineLayout)
CREATE(m_CreateSampler, VkSamplerCreateInfo, VkSampler)
CREATE(m_CreateBuffer, VkBufferCreateInfo, VkBuffer)
CREATE(m_CreateBufferView, VkBufferViewCreateInfo, VkBufferView)
DESTROY(m_DestroyShaderModule, VkShaderModule)
DESTROY(m_DestroyDescriptorSetLayout, VkDescriptorSetLayout)
DESTROY(m_DestroyPipelineLayout, VkPipelineLayout)
DESTROY(m_DestroySampler, VkSampler)
DESTROY(m_DestroyBuffer, VkBuffer)
DESTROY(m_DestroyBufferView, VkBufferView)
DESTROY(m_DestroyPipelineObject, VkPipeline)
static VKAPI_ATTR void VKAPI_CALL m_DestroyPipeline(VkDevice d, VkPipeline h, const VkAllocationCallbacks *cb)
{
    m_DestroyPipelineObject(d, h, cb);
    --g.live_pipelines;
}
DESTROY(m_FreeMemory, VkDeviceMemory)

static VKAPI_ATTR VkResult VKAPI_CALL m_CreateComputePipelines(VkDevice d, VkPipelineCache c, uint32_t n,
                                                               const VkComputePipelineCreateInfo *info,
                                                               const VkAllocationCallbacks *cb, VkPipeline *out)
{
    VkResult r = next_call();
    uint32_t k;
    (void)d, (void)c, (void)info, (void)cb;
    for (k = 0; k < n; ++k) out[k] = VK_NULL_HANDLE;
    if (r != VK_SUCCESS) return r;
    for (k = 0; k < n; ++k, ++g.live_objects, ++g.live_pipelines) out[k] = FAKE(VkPipeline);
    return VK_SUCCESS;
}

static VKAPI_ATTR VkResult VKAPI_CALL m_AllocateMemory(VkDevice d, const VkMemoryAllocateInfo *info,
                                                       const VkAllocationCallbacks *cb, VkDeviceMemory *out)
{
    VkResult r = next_call();
    (void)d, (void)cb;
    if (info->memoryTypeIndex >= g.mem_type_count) FAIL("allocation from memory type %u of %u", info->memoryTypeIndex,
                                                        g.mem_type_count);
    if (r != VK_SUCCESS) return r;
    *out = FAKE(VkDeviceMemory);
    ++g.live_objects;
    return VK_SUCCESS;
}

static VKAPI_ATTR VkResult VKAPI_CALL m_BindBufferMemory(VkDevice d, VkBuffer b, VkDeviceMemory m, VkDeviceSize o)
{
    (void)d, (void)b, (void)m, (void)o;
    return next_call();
}

static unsigned char g_mapped[16];
static VKAPI_ATTR VkResult VKAPI_CALL m_MapMemory(VkDevice d, VkDeviceMemory m, VkDeviceSize o, VkDeviceSize s,
                                                  VkMemoryMapFlags f, void **out)
{
    VkResult r = next_call();
    (void)d, (void)m, (void)o, (void)s, (void)f;
    if (r == VK_SUCCESS) *out = g_mapped;
    return r;
}

static VKAPI_ATTR void VKAPI_CALL m_UnmapMemory(VkDevice d, VkDeviceMemory m) { (void)d, (void)m; }

static VKAPI_ATTR void VKAPI_CALL m_GetBufferMemoryRequirements(VkDevice d, VkBuffer b, VkMemoryRequirements *out)
{
    (void)d, (void)b;
    out->size = 1u << 20;
    out->alignment = 256;
    out->memoryTypeBits = g.mem_type_bits;
}

/* physical device queries */
static VKAPI_ATTR void VKAPI_CALL m_GetPhysicalDeviceProperties(VkPhysicalDevice p, VkPhysicalDeviceProperties *out)
{
    (void)p;
    memset(out, 0, sizeof *out);
    out->apiVersion = g.api_version;
    out->limits = g.limits;
}

static VKAPI_ATTR void VKAPI_CALL m_GetPhysicalDeviceProperties2(VkPhysicalDevice p, VkPhysicalDeviceProperties2 *out)
{
    VkBaseOutStructure *s;
    m_GetPhysicalDeviceProperties(p, &out->properties);
    for (s = (VkBaseOutStructure *)out->pNext; s; s = s->pNext)
        if (s->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES) {
            VkPhysicalDeviceVulkan11Properties *p11 = (VkPhysicalDeviceVulkan11Properties *)s;
            p11->subgroupSupportedStages = g.no_feature == 11 ? VK_SHADER_STAGE_FRAGMENT_BIT : VK_SHADER_STAGE_ALL;
            p11->subgroupSupportedOperations = g.no_feature == 12 ? VK_SUBGROUP_FEATURE_BASIC_BIT : 0xffu;
        }
}

/* every feature, but the one the input turns off (0: none; 1..10 the ones
   lrt_vk_requirements lists; 11, 12 the subgroup properties) */
static VKAPI_ATTR void VKAPI_CALL m_GetPhysicalDeviceFeatures2(VkPhysicalDevice p, VkPhysicalDeviceFeatures2 *out)
{
    VkBaseOutStructure *s;
    VkBool32 *f[11] = {NULL};
    uint32_t k;
    (void)p;
    f[1] = &out->features.shaderFloat64;
    f[2] = &out->features.shaderInt64;
    f[3] = &out->features.shaderInt16;
    for (s = (VkBaseOutStructure *)out->pNext; s; s = s->pNext) {
        if (s->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES) {
            VkPhysicalDeviceVulkan11Features *f11 = (VkPhysicalDeviceVulkan11Features *)s;
            f11->storageBuffer16BitAccess = VK_TRUE;
            f[4] = &f11->storageBuffer16BitAccess;
        } else if (s->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES) {
            VkPhysicalDeviceVulkan12Features *f12 = (VkPhysicalDeviceVulkan12Features *)s;
            f[5] = &f12->shaderInt8;
            f[6] = &f12->shaderFloat16;
            f[7] = &f12->storageBuffer8BitAccess;
            f[8] = &f12->shaderBufferInt64Atomics;
            f[9] = &f12->vulkanMemoryModel;
            f[10] = &f12->vulkanMemoryModelDeviceScope;
        }
    }
    for (k = 1; k < 11; ++k)
        if (f[k]) *f[k] = VK_TRUE;
    if (g.no_feature >= 1 && g.no_feature <= 10 && f[g.no_feature]) *f[g.no_feature] = VK_FALSE;
}

/* does turning off feature k make the kernels unusable? */
static int feature_needed(uint32_t k)
{
    lrt_vk_requirements q;
    lrt_vk_get_requirements(&q);
    switch (k) {
    case 1: return q.shader_float64;
    case 2: return q.shader_int64;
    case 3: return q.shader_int16;
    case 4: return q.storage_buffer_16bit_access;
    case 5: return q.shader_int8;
    case 6: return q.shader_float16;
    case 7: return q.storage_buffer_8bit_access;
    case 8: return q.shader_buffer_int64_atomics;
    case 9: return q.vulkan_memory_model;
    case 10: return q.vulkan_memory_model_device_scope;
    case 11: return q.subgroup_operations != 0;
    case 12: return (q.subgroup_operations & ~(VkSubgroupFeatureFlags)VK_SUBGROUP_FEATURE_BASIC_BIT) != 0;
    default: return 0;
    }
}

static VKAPI_ATTR void VKAPI_CALL m_GetPhysicalDeviceMemoryProperties(VkPhysicalDevice p,
                                                                      VkPhysicalDeviceMemoryProperties *out)
{
    uint32_t k;
    (void)p;
    memset(out, 0, sizeof *out);
    out->memoryTypeCount = g.mem_type_count;
    out->memoryHeapCount = 1;
    for (k = 0; k < g.mem_type_count; ++k) out->memoryTypes[k].propertyFlags = g.mem_flags[k];
}

/* enumerate_mode: 0 the extension is there, 1 it is not, 2 the first call
   fails, 3 the second call fails, 4 the second call finds one more (INCOMPLETE) */
static VKAPI_ATTR VkResult VKAPI_CALL m_EnumerateDeviceExtensionProperties(VkPhysicalDevice p, const char *layer,
                                                                            uint32_t *n, VkExtensionProperties *out)
{
    static const char *names[3] = {"VK_KHR_maintenance4", VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME, "VK_EXT_foo"};
    uint32_t have = g.enumerate_mode == 1 ? 1u : 3u, k;
    (void)p, (void)layer;
    if (!out) {
        if (g.enumerate_mode == 2) return g.last_error = VK_ERROR_INITIALIZATION_FAILED;
        *n = g.enumerate_mode == 4 ? have - 1 : have;
        return VK_SUCCESS;
    }
    if (g.enumerate_mode == 3) return g.last_error = VK_ERROR_OUT_OF_HOST_MEMORY;
    for (k = 0; k < *n && k < have; ++k) {
        memset(&out[k], 0, sizeof out[k]);
        snprintf(out[k].extensionName, sizeof out[k].extensionName, "%s", names[g.enumerate_mode == 1 ? 0 : k]);
    }
    if (*n < have) return VK_INCOMPLETE;
    *n = have;
    return VK_SUCCESS;
}

/* recording */
static VKAPI_ATTR void VKAPI_CALL m_CmdBindPipeline(VkCommandBuffer c, VkPipelineBindPoint b, VkPipeline p)
{
    (void)c, (void)b;
    if (p == VK_NULL_HANDLE) FAIL("bound VK_NULL_HANDLE");
    ++g.commands;
}

static VKAPI_ATTR void VKAPI_CALL m_CmdPushDescriptorSetKHR(VkCommandBuffer c, VkPipelineBindPoint b,
                                                            VkPipelineLayout l, uint32_t set, uint32_t n,
                                                            const VkWriteDescriptorSet *w)
{
    uint32_t k;
    (void)c, (void)b, (void)l, (void)set;
    ++g.commands;
    memset(g.has, 0, sizeof g.has);
    g.writes = n;
    for (k = 0; k < n; ++k) {
        uint32_t b = w[k].dstBinding;
        if (b >= 10 || w[k].descriptorCount != 1) FAIL("descriptor write to binding %u, count %u", b, w[k].descriptorCount);
        if (g.has[b]) FAIL("binding %u written twice", b);
        g.has[b] = 1;
        if (b == 1 || b == 7) { /* the depth image, the back map's image */
            if (w[k].descriptorType != VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER || !w[k].pImageInfo)
                FAIL("binding %u is no image", b);
        } else if (b == 8) { /* the nodes' texels */
            if (w[k].descriptorType != VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER || !w[k].pTexelBufferView ||
                *w[k].pTexelBufferView == VK_NULL_HANDLE)
                FAIL("binding 8 is no texel buffer view");
            g.view = *w[k].pTexelBufferView;
        } else {
            if (w[k].descriptorType != VK_DESCRIPTOR_TYPE_STORAGE_BUFFER || !w[k].pBufferInfo)
                FAIL("binding %u is no storage buffer", b);
            g.buf[b] = *w[k].pBufferInfo;
        }
    }
}

static VKAPI_ATTR void VKAPI_CALL m_CmdPushConstants(VkCommandBuffer c, VkPipelineLayout l, VkShaderStageFlags s,
                                                     uint32_t off, uint32_t size, const void *v)
{
    (void)c, (void)l, (void)s;
    if (off != 0 || size != sizeof g.pc) FAIL("push constants at %u, %u bytes", off, size);
    memcpy(&g.pc, v, sizeof g.pc);
    ++g.commands;
}

static VKAPI_ATTR void VKAPI_CALL m_CmdDispatch(VkCommandBuffer c, uint32_t x, uint32_t y, uint32_t z)
{
    (void)c;
    g.gx = x, g.gy = y, g.gz = z;
    ++g.commands;
}

static VKAPI_ATTR void VKAPI_CALL m_CmdDispatchIndirect(VkCommandBuffer c, VkBuffer b, VkDeviceSize off)
{
    (void)c, (void)b, (void)off;
    ++g.commands;
}

static VKAPI_ATTR void VKAPI_CALL m_CmdUpdateBuffer(VkCommandBuffer c, VkBuffer b, VkDeviceSize off, VkDeviceSize size,
                                                    const void *data)
{
    (void)c, (void)b, (void)data;
    if (off % 4u || size % 4u || size == 0 || size > 65536u) FAIL("vkCmdUpdateBuffer at %llu, %llu bytes",
                                                                  (unsigned long long)off, (unsigned long long)size);
    ++g.commands;
}

static VKAPI_ATTR void VKAPI_CALL m_CmdFillBuffer(VkCommandBuffer c, VkBuffer b, VkDeviceSize off, VkDeviceSize size,
                                                  uint32_t data)
{
    (void)c, (void)b, (void)data;
    g.fill_offset = off;
    g.fill_size = size;
    ++g.commands;
}

static VKAPI_ATTR void VKAPI_CALL m_CmdPipelineBarrier(VkCommandBuffer c, VkPipelineStageFlags s, VkPipelineStageFlags d,
                                                       VkDependencyFlags f, uint32_t n0, const VkMemoryBarrier *b0,
                                                       uint32_t n1, const VkBufferMemoryBarrier *b1, uint32_t n2,
                                                       const VkImageMemoryBarrier *b2)
{
    (void)c, (void)s, (void)d, (void)f, (void)n0, (void)b0, (void)n1, (void)b1, (void)n2, (void)b2;
    ++g.commands;
}

static PFN_vkVoidFunction lookup(const char *name);
static VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL m_GetDeviceProcAddr(VkDevice d, const char *name)
{
    (void)d;
    return lookup(name);
}
static VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL m_GetInstanceProcAddr(VkInstance i, const char *name)
{
    (void)i;
    return lookup(name);
}

/* The n-th name asked for is missing when the input says so. */
static PFN_vkVoidFunction lookup(const char *name)
{
    static const struct { const char *name; PFN_vkVoidFunction fn; } table[] = {
#define FN(n) {"vk" #n, (PFN_vkVoidFunction)m_##n}
        FN(GetPhysicalDeviceProperties), FN(GetPhysicalDeviceProperties2), FN(GetPhysicalDeviceFeatures2),
        FN(GetPhysicalDeviceMemoryProperties), FN(EnumerateDeviceExtensionProperties), FN(CreateShaderModule),
        FN(DestroyShaderModule), FN(CreateDescriptorSetLayout), FN(DestroyDescriptorSetLayout), FN(CreatePipelineLayout),
        FN(DestroyPipelineLayout), FN(CreateComputePipelines), FN(DestroyPipeline), FN(CreateSampler), FN(DestroySampler),
        FN(CreateBuffer), FN(DestroyBuffer), FN(CreateBufferView), FN(DestroyBufferView), FN(GetBufferMemoryRequirements), FN(AllocateMemory), FN(FreeMemory),
        FN(BindBufferMemory), FN(MapMemory), FN(UnmapMemory), FN(CmdBindPipeline), FN(CmdPushDescriptorSetKHR),
        FN(CmdPushConstants), FN(CmdDispatch), FN(CmdFillBuffer), FN(CmdPipelineBarrier), FN(GetDeviceProcAddr),
        FN(CmdDispatchIndirect), FN(CmdUpdateBuffer),
#undef FN
    };
    size_t k;
    if (++g.lookups == g.missing_fn) return NULL;
    for (k = 0; k < sizeof table / sizeof table[0]; ++k)
        if (strcmp(name, table[k].name) == 0) return table[k].fn;
    return NULL;
}

/* host allocation callbacks: counted, and the n-th fails when the input says */
static VKAPI_ATTR void *VKAPI_CALL a_alloc(void *user, size_t size, size_t align, VkSystemAllocationScope scope)
{
    void *p;
    (void)user, (void)align, (void)scope;
    if (++g.allocs == g.fail_alloc) {
        g.alloc_failed = 1;
        return NULL;
    }
    p = malloc(size);
    if (p) ++g.live_allocs;
    return p;
}
static VKAPI_ATTR void *VKAPI_CALL a_realloc(void *user, void *old, size_t size, size_t align, VkSystemAllocationScope s)
{
    (void)user, (void)old, (void)size, (void)align, (void)s;
    FAIL("reallocation was not expected");
    return NULL;
}
static VKAPI_ATTR void VKAPI_CALL a_free(void *user, void *p)
{
    (void)user;
    if (p) --g.live_allocs, free(p);
}

/* ---- the device's limits, from the input ------------------------------------------ */
static void read_device(input *in)
{
    static const uint32_t ranges[8] = {1u << 27, 0x7fffffffu, 0xffffffffu, 1u << 16, 1000, 65536 * 4, 4, 0};
    static const uint32_t counts[4] = {65535, 1, 100, 0xffffffffu};
    uint8_t a = u8(in), b = u8(in), c = u8(in), k;
    memset(&g, 0, sizeof g);
    g.next_handle = 0x1000;
    g.api_version = (a & 7) == 7 ? VK_API_VERSION_1_1 : (a & 7) == 6 ? VK_API_VERSION_1_3 : VK_API_VERSION_1_2;
    g.missing_fn = (a & 0x18) == 0x18 ? 1u + u8(in) % 40u : 0u;
    g.fail_call = (a & 0x60) == 0x60 ? 1u + u8(in) % 16u : 0u;
    g.enumerate_mode = (a & 0x80) ? u8(in) % 5u : 0u;
    g.no_feature = (b & 7) == 7 ? u8(in) % 13u : 0u;
    g.limits.minStorageBufferOffsetAlignment = 1u << ((b >> 3) % 9u); /* 1..256 */
    g.limits.maxStorageBufferRange = (b & 0xc0) == 0xc0 ? u32(in) : ranges[(b >> 6) == 0 ? 1 : c & 7];
    g.limits.maxComputeWorkGroupCount[0] = (c & 0x18) ? 65535u : counts[u8(in) & 3];
    g.limits.maxComputeWorkGroupCount[1] = (c & 0x60) ? 65535u : counts[u8(in) & 3];
    g.limits.maxComputeWorkGroupCount[2] = 65535u;
    g.limits.maxImageDimension2D = (a & 0x60) == 0x40 ? 1u << (u8(in) % 16u) : 16384u;
    k = u8(in); /* texel buffers: 2^27, 65536 (the Vulkan minimum), 256 or 0 elements; alignment 0..256 */
    g.limits.maxTexelBufferElements = (k & 3) == 0 ? 1u << 27 : (k & 3) == 1 ? 65536u : (k & 3) == 2 ? 256u : 0u;
    g.limits.minTexelBufferOffsetAlignment = (k >> 2) % 10u ? 1u << ((k >> 2) % 10u - 1u) : 0u;
    g.mem_type_count = (c >> 7) ? 1u + u8(in) % 4u : 1u;
    for (k = 0; k < g.mem_type_count; ++k)
        g.mem_flags[k] = k == 0 && !(c >> 7) ? VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                                   VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
                                             : u8(in) & 0x1fu;
    g.mem_type_bits = (c >> 7) ? u8(in) & 0xfu : 1u;
}

/* ---- descs from the input ----------------------------------------------------------- */
static uint32_t dim(input *in)
{
    uint8_t b = u8(in);
    return b < 0xf0 ? 1u + b % 70u : b == 0xf0 ? 0u : b == 0xf1 ? 16384u : b == 0xf2 ? 16385u : 1u + u16(in);
}

static lrt_format format(input *in)
{
    uint8_t b = u8(in);
    return (lrt_format)(b < 0xf0 ? 1u + b % 3u : b == 0xf0 ? 0u : b == 0xf1 ? 4u : u32(in));
}

static uint32_t bpp_of(lrt_format f) { return f == LRT_FORMAT_UNORM8 ? 1u : f == LRT_FORMAT_UNORM16 ? 2u : f == LRT_FORMAT_FLOAT32 ? 4u : 0u; }

static int size_ok(uint32_t w, uint32_t h) { return w >= 1 && h >= 1 && w <= LINEAR_RT_MAX_DIM && h <= LINEAR_RT_MAX_DIM; }

/* an offset: aligned, a texel off, or anything */
static VkDeviceSize offset(input *in)
{
    uint8_t b = u8(in);
    return b < 0x80 ? (VkDeviceSize)(b & 7) * 256u : b < 0xc0 ? (VkDeviceSize)(b & 63) * 4u : b < 0xf0 ? (b & 0x3f) : u64(in);
}

static VkDeviceSize align_of(void)
{
    VkDeviceSize a = g.limits.minStorageBufferOffsetAlignment;
    return a < 4 ? 4 : a; /* offsets are multiples of it and of 4 (lrt_vk_bvh_desc) */
}

/* a caller's node buffer's offset: a multiple of minTexelBufferOffsetAlignment too (0 read as 1) */
static VkDeviceSize texel_align_of(void)
{
    VkDeviceSize a = g.limits.minTexelBufferOffsetAlignment;
    return a < 1 ? 1 : a;
}

/* A command call makes the pipelines it needs on first use (linear_rt.h's
   LRT__VK_LAZY), before it records anything: a failure the mock injected
   during the call (a create call's, an allocation's) is then its error. */
static void injected(uint32_t calls0, uint32_t allocs0, codes *must)
{
    if (g.fail_call > calls0 && g.fail_call <= g.calls) *must |= CODE(LRT_ERROR_VULKAN);
    if (g.fail_alloc > allocs0 && g.fail_alloc <= g.allocs) *must |= CODE(LRT_ERROR_OUT_OF_MEMORY);
}

/* ---- checks of what was recorded ---------------------------------------------------- */
static void check_binding(const char *what, uint32_t b)
{
    if (!g.has[b]) FAIL("%s: binding %u not written", what, b);
    if (g.buf[b].buffer == VK_NULL_HANDLE) FAIL("%s: binding %u is VK_NULL_HANDLE", what, b);
    if (g.buf[b].offset % align_of()) FAIL("%s: binding %u at misaligned offset %llu", what, b,
                                           (unsigned long long)g.buf[b].offset);
    if (g.buf[b].range == 0 || g.buf[b].range > g.limits.maxStorageBufferRange)
        FAIL("%s: binding %u range %llu (limit %u)", what, b, (unsigned long long)g.buf[b].range,
             g.limits.maxStorageBufferRange);
}

static void check_dispatch(const char *what, uint64_t invocations)
{
    if (g.gz != 1 || g.gx == 0 || g.gy == 0 || g.gx > g.limits.maxComputeWorkGroupCount[0] ||
        g.gy > g.limits.maxComputeWorkGroupCount[1] || (uint64_t)g.gx * g.gy * 64u < invocations)
        FAIL("%s: dispatch %ux%ux%u for %llu invocations (limits %u x %u)", what, g.gx, g.gy, g.gz,
             (unsigned long long)invocations, g.limits.maxComputeWorkGroupCount[0], g.limits.maxComputeWorkGroupCount[1]);
}

/* may a dispatch of this many invocations be refused? must it? */
static codes dispatch_limit(uint64_t invocations, codes *may)
{
    uint64_t groups = (invocations + 63) / 64, x = g.limits.maxComputeWorkGroupCount[0], y = g.limits.maxComputeWorkGroupCount[1];
    if (groups > x * y) return CODE(LRT_ERROR_LIMIT_EXCEEDED);
    /* the library's policy, 1D up to 65535 groups and then rows, can refuse a little more */
    if (groups > (x < 65535 ? x : 65535) * y) *may |= CODE(LRT_ERROR_LIMIT_EXCEEDED);
    return 0;
}

/* the documented errors of a depth source, against a BVH */
static codes depth_errors(const lrt_vk_depth *d, const lrt_vk_bvh *bvh, VkDeviceSize *stride_out)
{
    codes e = 0;
    uint32_t bpp = bpp_of(d->format);
    if (!size_ok(d->width, d->height)) e |= CODE(LRT_ERROR_INVALID_SIZE);
    if (!bpp) e |= CODE(LRT_ERROR_INVALID_FORMAT);
    if (d->flags & ~(uint32_t)LRT_DEPTH_REVERSED_Z) e |= CODE(LRT_ERROR_INVALID_OPTION);
    /* this harness makes infinite-thickness trees only: a back map (read_depth
       points one at a struct of garbage now and then) is a mismatch, refused unread */
    if (d->back && bvh->created && !bvh->layout.back_codes) e |= CODE(LRT_ERROR_THICKNESS_MISMATCH);
    if (bvh->created && (d->width != bvh->layout.width || d->height != bvh->layout.height))
        e |= CODE(LRT_ERROR_SIZE_MISMATCH);
    /* the format and Z direction the tree was created for (lrt_vk_bvh_desc) */
    if (bvh->created && (d->format != bvh->format || d->flags != bvh->depth_flags)) e |= CODE(LRT_ERROR_DEPTH_MISMATCH);
    if (d->buffer == VK_NULL_HANDLE && d->view == VK_NULL_HANDLE) e |= CODE(LRT_ERROR_NULL_POINTER);
    if (d->buffer != VK_NULL_HANDLE && d->view != VK_NULL_HANDLE) e |= CODE(LRT_ERROR_INVALID_OPTION);
    if (d->buffer != VK_NULL_HANDLE && bpp && size_ok(d->width, d->height)) {
        /* one row spans row_bytes, whatever its stride (never used then) */
        VkDeviceSize row = (VkDeviceSize)d->width * bpp, stride = d->row_stride && d->height > 1 ? d->row_stride : row;
        *stride_out = stride;
        if (stride < row) e |= CODE(LRT_ERROR_INVALID_STRIDE);
        if (d->offset % bpp || stride % bpp) e |= CODE(LRT_ERROR_MISALIGNED);
        /* the bound range: from the aligned offset below, to the word past the last texel */
        if (stride > g.limits.maxStorageBufferRange || /* first: the span below could wrap */
            (d->offset % align_of() + stride * (d->height - 1) + row + 3) / 4 * 4 > g.limits.maxStorageBufferRange)
            e |= CODE(LRT_ERROR_LIMIT_EXCEEDED);
    }
    if (d->buffer == VK_NULL_HANDLE && d->view != VK_NULL_HANDLE) {
        VkImageLayout l = d->layout;
        if (l != VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL && l != VK_IMAGE_LAYOUT_GENERAL &&
            l != VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL && l != VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL &&
            l != VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL)
            e |= CODE(LRT_ERROR_INVALID_OPTION);
        if (d->width > g.limits.maxImageDimension2D || d->height > g.limits.maxImageDimension2D)
            e |= CODE(LRT_ERROR_LIMIT_EXCEEDED); /* no such image on this device */
    }
    return e;
}

static void read_depth(input *in, const lrt_vk_bvh *bvh, lrt_vk_depth *d)
{
    static const VkImageLayout layouts[8] = {
        VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL,
        VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_UNDEFINED,
        VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
    uint8_t sel = u8(in);
    memset(d, 0, sizeof *d);
    d->format = format(in);
    d->flags = (sel & 0x40) ? u32(in) : (sel & 1u);
    if (sel & 0x80) { d->width = dim(in); d->height = dim(in); }
    else { d->width = bvh->layout.width; d->height = bvh->layout.height; }
    switch ((sel >> 1) & 7) {
    case 0: case 1: case 2: /* a buffer */
        d->buffer = (VkBuffer)(uintptr_t)0xb0;
        d->offset = offset(in);
        d->row_stride = (sel & 0x20) ? offset(in) : 0;
        break;
    case 3: case 4: /* an image */
        d->view = (VkImageView)(uintptr_t)0xc0;
        d->layout = (sel & 0x20) ? (VkImageLayout)u32(in) : layouts[u8(in) & 7];
        break;
    case 5: break; /* neither */
    default: /* both */
        d->buffer = (VkBuffer)(uintptr_t)0xb0;
        d->view = (VkImageView)(uintptr_t)0xc0;
        break;
    }
    /* now and then a back map, of garbage: never read, for no tree here has a back-map model */
    if ((sel & 0x1e) == 0x10) { /* a buffer depth */
        static lrt_vk_depth garbage;
        memset(&garbage, 0x5a, sizeof garbage);
        d->back = &garbage;
    }
}

/* what the calls answered, printed when a run ends */
static unsigned long g_ok[8], g_err[8], g_contexts;
static void fuzz_print_counts(void)
{
    static const char *names[8] = {"buffer_sizes", "bvh_create", "bvh_create", "cmd_build", "cmd_update",
                                   "cmd_update", "cmd_trace", "cmd_trace"};
    int k;
    fprintf(stderr, "fuzz_vk_args: %lu contexts made;", g_contexts);
    for (k = 0; k < 8; ++k)
        if (k != 2 && k != 5 && k != 7)
            fprintf(stderr, " %s %lu ok %lu refused;", names[k], g_ok[k] + g_ok[k + (k == 1 || k == 4 || k == 6)],
                    g_err[k] + g_err[k + (k == 1 || k == 4 || k == 6)]);
    fputc('\n', stderr);
}

/* ---- one input ------------------------------------------------------------------------ */
enum { BVHS = 3 };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    input in = {data, size, 0};
    VkAllocationCallbacks cb;
    lrt_vk_context_desc cd;
    lrt_vk_context *ctx = NULL, *const sentinel = (lrt_vk_context *)(uintptr_t)0x5a5a;
    lrt_vk_bvh bvh[BVHS] = {{0}};
    int built[BVHS] = {0};
    VkResult vr = VK_SUCCESS;
    codes must = 0, may = 0;
    uint8_t cs;
    int ops, k, base_objects;
    uint32_t calls0, allocs0;
    lrt_result r;

    read_device(&in);
    cs = u8(&in);
    memset(bvh, 0, sizeof bvh);

    /* the context's desc */
    memset(&cd, 0, sizeof cd);
    cd.instance = (VkInstance)(uintptr_t)0x10;
    cd.physical_device = (VkPhysicalDevice)(uintptr_t)0x20;
    cd.device = (VkDevice)(uintptr_t)0x30;
    cd.get_instance_proc_addr = m_GetInstanceProcAddr;
    cd.get_device_proc_addr = (cs & 1) ? m_GetDeviceProcAddr : NULL;
    cd.vk_result = (cs & 2) ? &vr : NULL;
    if ((cs & 0x1c) == 0x1c) { /* a NULL required member */
        uint8_t which = u8(&in) % 4;
        if (which == 0) cd.instance = VK_NULL_HANDLE;
        if (which == 1) cd.physical_device = VK_NULL_HANDLE;
        if (which == 2) cd.device = VK_NULL_HANDLE;
        if (which == 3) cd.get_instance_proc_addr = NULL;
        must |= CODE(LRT_ERROR_NULL_POINTER);
    }
    if (cs & 0x20) { /* our allocation callbacks, maybe incomplete, maybe failing */
        uint8_t b = u8(&in);
        cb.pUserData = NULL;
        cb.pfnAllocation = a_alloc;
        cb.pfnReallocation = a_realloc;
        cb.pfnFree = a_free;
        cb.pfnInternalAllocation = NULL;
        cb.pfnInternalFree = NULL;
        if ((b & 7) == 1) cb.pfnAllocation = NULL;
        if ((b & 7) == 2) cb.pfnFree = NULL;
        if ((b & 7) == 3) cb.pfnReallocation = NULL;
        if ((b & 7) >= 1 && (b & 7) <= 3) must |= CODE(LRT_ERROR_NULL_POINTER);
        g.fail_alloc = (b & 0x18) == 0x18 ? 1u + (b >> 5) : 0u;
        cd.allocation_callbacks = &cb;
    }

    /* create: the documented errors of what the mock was told to be, and
       of what happened in it (a lookup that found nothing, a Vulkan call or
       an allocation that failed) */
    if (g.api_version < VK_API_VERSION_1_2 || feature_needed(g.no_feature) || g.enumerate_mode == 1)
        must |= CODE(LRT_ERROR_MISSING_VULKAN_FEATURE);
    if ((cs & 0xc0) == 0xc0) must |= CODE(LRT_ERROR_NULL_POINTER); /* desc or out NULL */
    ctx = sentinel;
    r = lrt_vk_context_create((cs & 0xd0) == 0xc0 ? NULL : &cd, (cs & 0xd0) == 0xd0 ? NULL : &ctx);
    if (g.missing_fn && g.lookups >= g.missing_fn) must |= CODE(LRT_ERROR_MISSING_VULKAN_FEATURE);
    if (g.last_error != VK_SUCCESS) must |= CODE(LRT_ERROR_VULKAN);
    if (g.alloc_failed) must |= CODE(LRT_ERROR_OUT_OF_MEMORY);
    expect("lrt_vk_context_create", r, must, may);
    if (r == LRT_ERROR_VULKAN && cd.vk_result && vr != g.last_error)
        FAIL("context create: vk_result %d, the failing call gave %d", (int)vr, (int)g.last_error);
    if (r != LRT_SUCCESS) {
        if (ctx != sentinel) FAIL("context create wrote *out on an error");
        if (g.live_objects || g.live_allocs)
            FAIL("context create left %d objects, %d allocations on an error", g.live_objects, g.live_allocs);
        ctx = NULL;
    } else {
        ++g_contexts;
    }
    base_objects = g.live_objects - g.live_pipelines;

    /* then calls with garbage arguments, against what the header documents */
    for (ops = 0; ops < 24 && in.at < in.n; ++ops) {
        uint8_t op = u8(&in);
        lrt_vk_bvh *b = &bvh[(op >> 4) % BVHS];
        int *b_built = &built[(op >> 4) % BVHS]; /* a build of it recorded since its create (update and trace need one) */
        uint32_t before = g.commands;
        VkCommandBuffer cmd = (op & 0x80) && (op & 0x40) ? NULL : (VkCommandBuffer)(uintptr_t)0x40;
        codes cmust = 0, cmay = 0;
        switch (op & 7) {
        case 0: { /* buffer sizes, and the CPU agrees */
            uint32_t w = dim(&in), h = dim(&in);
            lrt_format f = format(&in);
            lrt_build_options o;
            VkDeviceSize nb = 0, cnt = 0;
            size_t cpu = 0;
            memset(&o, 0, sizeof o);
            k = u8(&in) & 3;
            o.node_bits = k == 3 ? u32(&in) : 8u * (uint32_t)k;
            if (!size_ok(w, h)) cmust |= CODE(LRT_ERROR_INVALID_SIZE);
            if (!bpp_of(f)) cmust |= CODE(LRT_ERROR_INVALID_FORMAT);
            if (o.node_bits != 0 && o.node_bits != 8 && o.node_bits != 16) cmust |= CODE(LRT_ERROR_INVALID_OPTION);
            r = lrt_vk_bvh_buffer_sizes(w, h, f, &o, &nb, (op & 8) ? NULL : &cnt);
            expect("lrt_vk_bvh_buffer_sizes", r, cmust | ((op & 8) ? CODE(LRT_ERROR_NULL_POINTER) : 0), 0);
            ++*(r == LRT_SUCCESS ? &g_ok[op & 7] : &g_err[op & 7]);
            if (r == LRT_SUCCESS) {
                lrt_layout L;
                expect("lrt_bvh_memory_size", lrt_bvh_memory_size(w, h, f, &o, &cpu), 0, 0);
                expect("lrt_layout_compute", lrt_layout_compute(w, h, o.node_bits ? o.node_bits : (f == 1 ? 8u : 16u), &L), 0, 0);
                if (nb != L.bytes || cpu != L.bytes + 15 || cnt != (VkDeviceSize)L.node_count * 4u)
                    FAIL("buffer sizes %llu + %llu, CPU %zu, layout %zu nodes %zu bytes", (unsigned long long)nb,
                         (unsigned long long)cnt, cpu, L.node_count, L.bytes);
            }
            break;
        }
        case 1: case 2: { /* create a BVH (over the one there, destroyed first) */
            lrt_vk_bvh_desc bd, *pbd = &bd;
            lrt_vk_bvh out = {0};
            uint8_t s = u8(&in);
            int objects = g.live_objects;
            memset(&bd, 0, sizeof bd);
            bd.width = dim(&in);
            bd.height = dim(&in);
            bd.format = format(&in);
            bd.options.node_bits = (s & 3) == 3 ? u32(&in) : 8u * (s & 3);
            bd.flags = (s & 4) ? ((s & 8) ? u32(&in) : LRT_VK_BVH_HOST_VISIBLE) : 0u;
            bd.depth_flags = (s & 0xc0) == 0x40 ? (uint32_t)LRT_DEPTH_REVERSED_Z : 0u; /* (both bits: no desc) */
            if (s & 0x10) bd.nodes = (VkBuffer)(uintptr_t)0xa0, bd.nodes_offset = offset(&in);
            if (s & 0x20) bd.counters = (VkBuffer)(uintptr_t)0xa8, bd.counters_offset = offset(&in);
            lrt_vk_bvh_destroy(ctx, b);
            *b_built = 0;
            objects = g.live_objects;
            if (!ctx) cmust |= CODE(LRT_ERROR_NULL_POINTER);
            if (s & 0x40 && s & 0x80) pbd = NULL, cmust |= CODE(LRT_ERROR_NULL_POINTER);
            if (!size_ok(bd.width, bd.height)) cmust |= CODE(LRT_ERROR_INVALID_SIZE);
            if (!bpp_of(bd.format)) cmust |= CODE(LRT_ERROR_INVALID_FORMAT);
            if (bd.options.node_bits != 0 && bd.options.node_bits != 8 && bd.options.node_bits != 16)
                cmust |= CODE(LRT_ERROR_INVALID_OPTION);
            if (bd.flags & ~(uint32_t)LRT_VK_BVH_HOST_VISIBLE) cmust |= CODE(LRT_ERROR_INVALID_OPTION);
            if ((bd.nodes == VK_NULL_HANDLE) != (bd.counters == VK_NULL_HANDLE)) cmust |= CODE(LRT_ERROR_NULL_POINTER);
            if (cmust == 0) {
                VkDeviceSize nb, cnt;
                expect("lrt_vk_bvh_buffer_sizes", lrt_vk_bvh_buffer_sizes(bd.width, bd.height, bd.format, &bd.options, &nb, &cnt), 0, 0);
                if (nb > g.limits.maxStorageBufferRange || cnt > g.limits.maxStorageBufferRange)
                    cmust |= CODE(LRT_ERROR_LIMIT_EXCEEDED);
                if (bd.nodes != VK_NULL_HANDLE) {
                    if (bd.flags & LRT_VK_BVH_HOST_VISIBLE) cmust |= CODE(LRT_ERROR_INVALID_OPTION);
                    if (bd.nodes_offset % align_of() || bd.counters_offset % align_of() ||
                        bd.nodes_offset % texel_align_of())
                        cmust |= CODE(LRT_ERROR_MISALIGNED);
                } else { /* library memory: a fitting type, and Vulkan calls that may fail */
                    uint32_t t, ok = 0;
                    VkMemoryPropertyFlags want = (bd.flags & LRT_VK_BVH_HOST_VISIBLE)
                                                     ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
                                                     : 0u;
                    for (t = 0; t < g.mem_type_count; ++t)
                        if ((g.mem_type_bits >> t & 1) && (g.mem_flags[t] & want) == want) ok = 1;
                    if (!ok) cmust |= CODE(LRT_ERROR_MISSING_VULKAN_FEATURE);
                }
            }
            memset(&out, 0x5a, sizeof out);
            g.last_error = VK_SUCCESS;
            r = lrt_vk_bvh_create(ctx, pbd, (op & 8) && (op & 0x40) ? NULL : &out);
            if ((op & 8) && (op & 0x40)) cmust |= CODE(LRT_ERROR_NULL_POINTER);
            if (g.last_error != VK_SUCCESS) cmust |= CODE(LRT_ERROR_VULKAN);
            if (r == LRT_ERROR_VULKAN && lrt_vk_context_vk_result(ctx) != g.last_error)
                FAIL("lrt_vk_context_vk_result %d, the failing call gave %d", (int)lrt_vk_context_vk_result(ctx),
                     (int)g.last_error);
            expect("lrt_vk_bvh_create", r, cmust, cmay);
            ++*(r == LRT_SUCCESS ? &g_ok[op & 7] : &g_err[op & 7]);
            if (r != LRT_SUCCESS) {
                if (g.live_objects != objects) FAIL("lrt_vk_bvh_create left objects on an error");
                if (!((op & 8) && (op & 0x40))) {
                    lrt_vk_bvh sent = {0};
                    memset(&sent, 0x5a, sizeof sent);
                    if (memcmp(&out, &sent, sizeof out) != 0) FAIL("lrt_vk_bvh_create wrote *out on an error");
                }
                break;
            }
            {
                lrt_layout L;
                expect("lrt_layout_compute", lrt_layout_compute(bd.width, bd.height, bd.options.node_bits ? bd.options.node_bits : (bd.format == 1 ? 8u : 16u), &L), 0, 0);
                if (memcmp(&L, &out.layout, sizeof L) != 0) FAIL("the GPU layout is not the CPU's");
                if (out.node_texels == VK_NULL_HANDLE) FAIL("lrt_vk_bvh_create made no texel view of the nodes");
                if (!out.created || out.nodes == VK_NULL_HANDLE || out.counters == VK_NULL_HANDLE ||
                    out.nodes_offset % align_of() || out.counters_offset % align_of() ||
                    out.counters_bytes != (VkDeviceSize)L.node_count * 4u)
                    FAIL("lrt_vk_bvh_create made a bvh with nodes at %llu, counters at %llu (%llu bytes)",
                         (unsigned long long)out.nodes_offset, (unsigned long long)out.counters_offset,
                         (unsigned long long)out.counters_bytes);
                if (out.nodes == out.counters && out.counters_offset < out.nodes_offset + L.bytes)
                    FAIL("counters overlap the nodes");
                if ((bd.flags & LRT_VK_BVH_HOST_VISIBLE) && !out.mapped) FAIL("host-visible BVH without mapped nodes");
                *b = out;
            }
            break;
        }
        case 3: case 4: case 5: { /* build, update */
            lrt_vk_depth d;
            lrt_rect rect, *pr = NULL;
            VkDeviceSize stride = 0;
            uint32_t x0 = 0, y0 = 0, x1, y1;
            const char *what = (op & 7) == 3 ? "lrt_vk_cmd_build" : "lrt_vk_cmd_update";
            int empty = 0;
            read_depth(&in, b, &d);
            if (!ctx || !cmd) cmust |= CODE(LRT_ERROR_NULL_POINTER);
            if (!b->created || ((op & 7) != 3 && !*b_built)) cmust |= CODE(LRT_ERROR_INVALID_BVH);
            cmust |= depth_errors(&d, b, &stride);
            x1 = d.width - 1u;
            y1 = d.height - 1u;
            if ((op & 7) == 5) { /* a dirty rect */
                uint8_t s = u8(&in);
                pr = &rect;
                if (s & 1) { rect.x = u32(&in); rect.y = u32(&in); rect.width = u32(&in); rect.height = u32(&in); }
                else { rect.x = u8(&in); rect.y = u8(&in); rect.width = u8(&in); rect.height = u8(&in); }
                if ((uint64_t)rect.x + rect.width > d.width || (uint64_t)rect.y + rect.height > d.height)
                    cmust |= CODE(LRT_ERROR_INVALID_RECT);
                empty = rect.width == 0 || rect.height == 0;
                x0 = rect.x, y0 = rect.y, x1 = rect.x + rect.width - 1u, y1 = rect.y + rect.height - 1u;
            }
            if (cmust == 0 && !empty) {
                /* one invocation per level-2 node (8x8 texels) above the rect */
                uint64_t n = (uint64_t)((x1 >> 3) - (x0 >> 3) + 1u) * ((y1 >> 3) - (y0 >> 3) + 1u);
                cmust |= dispatch_limit(n, &cmay);
            }
            calls0 = g.calls, allocs0 = g.allocs;
            r = (op & 7) == 3 ? lrt_vk_cmd_build(ctx, cmd, (op & 8) && (op & 0x40) ? NULL : b, (op & 8) && (op & 0x80) ? NULL : &d)
                              : lrt_vk_cmd_update(ctx, cmd, (op & 8) && (op & 0x40) ? NULL : b, (op & 8) && (op & 0x80) ? NULL : &d, pr);
            if ((op & 8) && (op & 0xc0)) cmust |= CODE(LRT_ERROR_NULL_POINTER);
            injected(calls0, allocs0, &cmust);
            expect(what, r, cmust, cmay);
            if ((op & 7) == 3 && r == LRT_SUCCESS) *b_built = 1;
            ++*(r == LRT_SUCCESS ? &g_ok[op & 7] : &g_err[op & 7]);
            if (r != LRT_SUCCESS || empty) {
                if (g.commands != before) FAIL("%s recorded %u commands, with %s", what, g.commands - before,
                                               r != LRT_SUCCESS ? "an error" : "an empty rect");
                break;
            }
            {
                uint64_t n = (uint64_t)((x1 >> 3) - (x0 >> 3) + 1u) * ((y1 >> 3) - (y0 >> 3) + 1u);
                check_dispatch(what, n);
            }
            if (g.pc.width != d.width || g.pc.height != d.height || g.pc.format != (uint32_t)d.format ||
                g.pc.flags != d.flags || g.pc.node_bits != b->layout.node_bits ||
                g.pc.level_count != b->layout.level_count || g.pc.rect_x0 != x0 || g.pc.rect_y0 != y0 ||
                g.pc.rect_x1 != x1 || g.pc.rect_y1 != y1 || g.pc.build != ((op & 7) == 3))
                FAIL("%s: push constants do not match the arguments", what);
            check_binding(what, 2);
            check_binding(what, 3);
            if (g.buf[2].range != b->layout.bytes || g.buf[3].range != b->counters_bytes ||
                g.buf[2].offset != b->nodes_offset || g.buf[3].offset != b->counters_offset)
                FAIL("%s: nodes or counters bound at other ranges than the bvh's", what);
            if ((op & 7) == 3 && (g.fill_offset != b->counters_offset || g.fill_size != b->counters_bytes))
                FAIL("%s: the fill is not the counters", what);
            if (d.buffer != VK_NULL_HANDLE) {
                check_binding(what, 0);
                check_binding(what, 6); /* no back map: the depth again, so the binding is never empty */
                if (g.buf[6].buffer != g.buf[0].buffer || g.buf[6].offset != g.buf[0].offset || g.buf[6].range != g.buf[0].range)
                    FAIL("%s: binding 6 is not the depth", what);
                if (g.buf[0].offset + g.pc.depth_offset != d.offset || g.pc.row_stride != stride ||
                    g.buf[0].range < g.pc.depth_offset + stride * (d.height - 1u) + (VkDeviceSize)d.width * bpp_of(d.format))
                    FAIL("%s: depth bound at %llu + %u, %llu bytes, stride %u: not the map at %llu", what,
                         (unsigned long long)g.buf[0].offset, g.pc.depth_offset, (unsigned long long)g.buf[0].range,
                         g.pc.row_stride, (unsigned long long)d.offset);
            } else if (!g.has[1] || !g.has[7]) {
                FAIL("%s: no image bound (depth and back map)", what);
            }
            break;
        }
        default: { /* trace */
            lrt_vk_depth d;
            VkDeviceSize stride = 0, ro, ho, a = align_of(), first;
            uint32_t count, flags;
            uint8_t s;
            VkBuffer rays = (VkBuffer)(uintptr_t)0xd0, hits = (VkBuffer)(uintptr_t)0xe0;
            read_depth(&in, b, &d);
            s = u8(&in);
            /* offsets: the same ray index away from aligned ones, or anything */
            first = u8(&in) % 8u;
            ro = (s & 1) ? offset(&in) : (VkDeviceSize)(u8(&in) & 3) * 256u + first * sizeof(lrt_ray);
            ho = (s & 2) ? offset(&in) : (VkDeviceSize)(u8(&in) & 3) * 256u + first * sizeof(lrt_hit);
            count = (s & 4) ? u32(&in) : u8(&in);
            flags = (s & 8) ? u32(&in) : (s >> 4) & 1u;
            if (s & 0x20) rays = VK_NULL_HANDLE;
            if (s & 0x40) hits = VK_NULL_HANDLE;
            if (!ctx || !cmd) cmust |= CODE(LRT_ERROR_NULL_POINTER);
            if (!b->created || !*b_built) cmust |= CODE(LRT_ERROR_INVALID_BVH);
            cmust |= depth_errors(&d, b, &stride);
            if (fuzz_trace_flags_bad(flags)) cmust |= CODE(LRT_ERROR_INVALID_OPTION);
            if (count > LINEAR_RT_MAX_RAYS_PER_CALL) cmust |= CODE(LRT_ERROR_TOO_MANY_RAYS);
            if (count && (rays == VK_NULL_HANDLE || hits == VK_NULL_HANDLE)) cmust |= CODE(LRT_ERROR_NULL_POINTER);
            if (count && cmust == 0) {
                /* documented: aligned offsets, or the same ray index k away from aligned ones */
                VkDeviceSize k2, found = a;
                for (k2 = 0; k2 < a && found == a; ++k2)
                    if (k2 * sizeof(lrt_ray) <= ro && k2 * sizeof(lrt_hit) <= ho &&
                        (ro - k2 * sizeof(lrt_ray)) % a == 0 && (ho - k2 * sizeof(lrt_hit)) % a == 0)
                        found = k2;
                if (found == a) cmust |= CODE(LRT_ERROR_MISALIGNED);
                else if ((found + count) * sizeof(lrt_ray) > g.limits.maxStorageBufferRange)
                    cmust |= CODE(LRT_ERROR_LIMIT_EXCEEDED);
                else cmust |= dispatch_limit(count, &cmay);
            }
            calls0 = g.calls, allocs0 = g.allocs;
            if (s & 0x80) { /* compacted: a scratch of the input's making, checked after the trace's arguments */
                lrt_vk_scratch sc;
                const uint8_t t = u8(&in);
                sc.buffer = (t & 1) ? VK_NULL_HANDLE : (VkBuffer)(uintptr_t)0xf0;
                sc.offset = (t & 2) ? offset(&in) : (VkDeviceSize)(u8(&in) & 3) * 256u;
                sc.size = (t & 4) ? offset(&in) : lrt_vk_trace_scratch_size(count);
                if (count && cmust == 0 && !((op & 8) && (op & 0x40))) {
                    if (sc.buffer == VK_NULL_HANDLE) cmust |= CODE(LRT_ERROR_NULL_POINTER);
                    else if (sc.offset % a) cmust |= CODE(LRT_ERROR_MISALIGNED);
                    else if (sc.size < lrt_vk_trace_scratch_size(count)) cmust |= CODE(LRT_ERROR_BUFFER_TOO_SMALL);
                }
                r = lrt_vk_cmd_trace_compacted(ctx, cmd, (op & 8) && (op & 0x40) ? NULL : b, &d, rays, ro, hits, ho, count,
                                               flags, (t & 8) ? NULL : &sc);
                if ((t & 8) && count && cmust == 0 && !((op & 8) && (op & 0x40))) cmust |= CODE(LRT_ERROR_NULL_POINTER);
            } else {
                r = lrt_vk_cmd_trace(ctx, cmd, (op & 8) && (op & 0x40) ? NULL : b, &d, rays, ro, hits, ho, count, flags);
            }
            if ((op & 8) && (op & 0x40)) cmust |= CODE(LRT_ERROR_NULL_POINTER);
            injected(calls0, allocs0, &cmust);
            expect("lrt_vk_cmd_trace", r, cmust, cmay);
            ++*(r == LRT_SUCCESS ? &g_ok[op & 7] : &g_err[op & 7]);
            if (r != LRT_SUCCESS || count == 0) {
                if (g.commands != before) FAIL("lrt_vk_cmd_trace recorded %u commands with %s", g.commands - before,
                                               r != LRT_SUCCESS ? "an error" : "no rays");
                break;
            }
            check_dispatch("lrt_vk_cmd_trace", count);
            check_binding("lrt_vk_cmd_trace", 4);
            check_binding("lrt_vk_cmd_trace", 5);
            check_binding("lrt_vk_cmd_trace", 9); /* the scratch, or the hits where a pass has none */
            if (!g.has[8] || g.view != b->node_texels) FAIL("lrt_vk_cmd_trace: the nodes' texel view is not bound");
            if (g.pc.ray_count != count || g.pc.trace_flags != flags ||
                g.buf[4].offset + g.pc.ray_first * sizeof(lrt_ray) != ro ||
                g.buf[5].offset + g.pc.ray_first * sizeof(lrt_hit) != ho ||
                g.buf[4].range < ((VkDeviceSize)g.pc.ray_first + count) * sizeof(lrt_ray) ||
                g.buf[5].range < ((VkDeviceSize)g.pc.ray_first + count) * sizeof(lrt_hit))
                FAIL("lrt_vk_cmd_trace: rays at %llu and hits at %llu bound as %llu+%llu, %llu+%llu, first %u",
                     (unsigned long long)ro, (unsigned long long)ho, (unsigned long long)g.buf[4].offset,
                     (unsigned long long)g.buf[4].range, (unsigned long long)g.buf[5].offset,
                     (unsigned long long)g.buf[5].range, g.pc.ray_first);
            break;
        }
        }
    }

    for (k = 0; k < BVHS; ++k) lrt_vk_bvh_destroy(ctx, &bvh[k]);
    /* the pipelines made on first use live with the context */
    if (g.live_objects - g.live_pipelines != base_objects)
        FAIL("%d objects of BVHs left after destroy", g.live_objects - g.live_pipelines - base_objects);
    lrt_vk_context_destroy(ctx);
    if (g.live_objects || g.live_allocs) FAIL("%d objects, %d allocations left after destroy", g.live_objects, g.live_allocs);
    return 0;
}
