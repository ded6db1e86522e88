/* examples/vk_small.h - the little Vulkan the demo needs around linear_rt's
   recording functions (vulkan_trace.c too), and vulkan_inline/main.c around its own pipeline:
   host-visible buffers, one command buffer submitted and waited for, a
   memory barrier, timestamps. Every function pointer comes from the
   lrt_vk_device of linear_rt.h's device helper, so it builds with
   VK_NO_PROTOTYPES and nothing links against Vulkan. Include after
   linear_rt.h (with LINEAR_RT_VULKAN and LINEAR_RT_VULKAN_DEVICE_HELPER).
   Errors print a line to stderr and return nonzero. */
#ifndef VK_SMALL_H
#define VK_SMALL_H

#include <stdio.h>
#include <string.h>

#define VKS_TIMESTAMPS 3 /* queries in vks.queries */

#define VKS_DEVICE_FUNCS(X)                                                                                       \
    X(vkCreateBuffer) X(vkDestroyBuffer) X(vkGetBufferMemoryRequirements) X(vkAllocateMemory) X(vkFreeMemory)    \
    X(vkBindBufferMemory) X(vkMapMemory) X(vkUnmapMemory) X(vkCreateCommandPool) X(vkDestroyCommandPool)         \
    X(vkAllocateCommandBuffers) X(vkResetCommandBuffer) X(vkBeginCommandBuffer) X(vkEndCommandBuffer)            \
    X(vkCmdPipelineBarrier) X(vkQueueSubmit) X(vkCreateFence) X(vkDestroyFence) X(vkWaitForFences)               \
    X(vkResetFences) X(vkCreateQueryPool) X(vkDestroyQueryPool) X(vkCmdResetQueryPool) X(vkCmdWriteTimestamp)    \
    X(vkGetQueryPoolResults) X(vkDeviceWaitIdle)

typedef struct vks {
    const lrt_vk_device *dev;
    VkDevice device;
    VkCommandPool pool;
    VkCommandBuffer cmd;  /* one, reused: vks_begin .. vks_submit */
    VkFence fence;
    VkQueryPool queries;  /* VKS_TIMESTAMPS timestamps; VK_NULL_HANDLE: the queue has none */
    VkPhysicalDeviceMemoryProperties memory;
#define VKS_MEMBER(name) PFN_##name name;
    VKS_DEVICE_FUNCS(VKS_MEMBER)
#undef VKS_MEMBER
} vks;

typedef struct vks_buffer {
    VkBuffer buffer;
    VkDeviceMemory memory;
    void *map; /* host-visible and coherent, mapped for its lifetime */
    VkDeviceSize size;
} vks_buffer;

static inline int vks_fail(const char *what, VkResult r)
{
    fprintf(stderr, "vk_small: %s failed: VkResult %d\n", what, (int)r);
    return 1;
}

/* Loads the functions, makes the command pool and buffer, the fence and
   (where the queue has timestamps) the query pool. vks_free undoes it, also
   after a failure half-way. */
static inline int vks_init(vks *t, const lrt_vk_device *dev)
{
    const lrt_vk_context_desc *d = &dev->desc;
    PFN_vkGetPhysicalDeviceMemoryProperties get_memory;
    VkCommandPoolCreateInfo pi;
    VkCommandBufferAllocateInfo ai;
    VkFenceCreateInfo fi;
    VkResult r;
    memset(t, 0, sizeof *t);
#define VKS_LOAD(name)                                                                                            \
    t->name = (PFN_##name)d->get_device_proc_addr(d->device, #name);                                              \
    if (!t->name) return vks_fail("loading " #name, VK_ERROR_INITIALIZATION_FAILED);
    VKS_DEVICE_FUNCS(VKS_LOAD)
#undef VKS_LOAD
    get_memory = (PFN_vkGetPhysicalDeviceMemoryProperties)d->get_instance_proc_addr(
        d->instance, "vkGetPhysicalDeviceMemoryProperties");
    if (!get_memory) return vks_fail("loading vkGetPhysicalDeviceMemoryProperties", VK_ERROR_INITIALIZATION_FAILED);
    get_memory(d->physical_device, &t->memory);
    t->dev = dev;
    t->device = d->device; /* from here on vks_free cleans up */

    memset(&pi, 0, sizeof pi);
    pi.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pi.queueFamilyIndex = dev->queue_family;
    if ((r = t->vkCreateCommandPool(t->device, &pi, NULL, &t->pool)) != VK_SUCCESS)
        return vks_fail("vkCreateCommandPool", r);
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    ai.commandPool = t->pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    if ((r = t->vkAllocateCommandBuffers(t->device, &ai, &t->cmd)) != VK_SUCCESS)
        return vks_fail("vkAllocateCommandBuffers", r);
    memset(&fi, 0, sizeof fi);
    fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    if ((r = t->vkCreateFence(t->device, &fi, NULL, &t->fence)) != VK_SUCCESS) return vks_fail("vkCreateFence", r);
    if (dev->timestamp_valid_bits) {
        VkQueryPoolCreateInfo qi;
        memset(&qi, 0, sizeof qi);
        qi.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
        qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
        qi.queryCount = VKS_TIMESTAMPS;
        if (t->vkCreateQueryPool(t->device, &qi, NULL, &t->queries) != VK_SUCCESS) t->queries = VK_NULL_HANDLE;
    }
    return 0;
}

static inline void vks_free(vks *t)
{
    if (!t->device) return;
    t->vkDeviceWaitIdle(t->device);
    if (t->queries) t->vkDestroyQueryPool(t->device, t->queries, NULL);
    if (t->fence) t->vkDestroyFence(t->device, t->fence, NULL);
    if (t->pool) t->vkDestroyCommandPool(t->device, t->pool, NULL); /* frees the command buffer */
    memset(t, 0, sizeof *t);
}

/* The first memory type among `allowed` with every flag of want, or
   memoryTypeCount where there is none. */
static inline uint32_t vks_memory_type(const vks *t, uint32_t allowed, VkMemoryPropertyFlags want)
{
    uint32_t type;
    for (type = 0; type < t->memory.memoryTypeCount; ++type)
        if (((allowed >> type) & 1u) && (t->memory.memoryTypes[type].propertyFlags & want) == want) break;
    return type;
}

/* A storage buffer of size bytes in host-visible, coherent memory, mapped;
   device-local as well where there is such memory (integrated GPUs,
   resizable BAR, lavapipe), so that the kernels do not read it across the
   bus. */
static inline int vks_buffer_create(vks *t, VkDeviceSize size, vks_buffer *b)
{
    const VkMemoryPropertyFlags want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    VkBufferCreateInfo bi;
    VkMemoryRequirements mr;
    VkMemoryAllocateInfo ai;
    VkResult r;
    uint32_t type;
    memset(b, 0, sizeof *b);
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bi.size = size;
    bi.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    if ((r = t->vkCreateBuffer(t->device, &bi, NULL, &b->buffer)) != VK_SUCCESS) return vks_fail("vkCreateBuffer", r);
    t->vkGetBufferMemoryRequirements(t->device, b->buffer, &mr);
    type = vks_memory_type(t, mr.memoryTypeBits, want | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (type == t->memory.memoryTypeCount) type = vks_memory_type(t, mr.memoryTypeBits, want);
    if (type == t->memory.memoryTypeCount) return vks_fail("finding host-visible memory", VK_ERROR_FEATURE_NOT_PRESENT);
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    ai.allocationSize = mr.size;
    ai.memoryTypeIndex = type;
    if ((r = t->vkAllocateMemory(t->device, &ai, NULL, &b->memory)) != VK_SUCCESS) return vks_fail("vkAllocateMemory", r);
    if ((r = t->vkBindBufferMemory(t->device, b->buffer, b->memory, 0)) != VK_SUCCESS)
        return vks_fail("vkBindBufferMemory", r);
    if ((r = t->vkMapMemory(t->device, b->memory, 0, VK_WHOLE_SIZE, 0, &b->map)) != VK_SUCCESS)
        return vks_fail("vkMapMemory", r);
    b->size = size;
    return 0;
}

static inline void vks_buffer_destroy(vks *t, vks_buffer *b)
{
    if (b->map) t->vkUnmapMemory(t->device, b->memory);
    if (b->memory) t->vkFreeMemory(t->device, b->memory, NULL);
    if (b->buffer) t->vkDestroyBuffer(t->device, b->buffer, NULL);
    memset(b, 0, sizeof *b);
}

/* Starts recording into t->cmd (again). */
static inline int vks_begin(vks *t)
{
    VkCommandBufferBeginInfo bi;
    VkResult r;
    if ((r = t->vkResetCommandBuffer(t->cmd, 0)) != VK_SUCCESS) return vks_fail("vkResetCommandBuffer", r);
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    if ((r = t->vkBeginCommandBuffer(t->cmd, &bi)) != VK_SUCCESS) return vks_fail("vkBeginCommandBuffer", r);
    return 0;
}

/* Ends t->cmd, submits it to the device's queue and waits for it. */
static inline int vks_submit(vks *t)
{
    VkSubmitInfo si;
    VkResult r;
    if ((r = t->vkEndCommandBuffer(t->cmd)) != VK_SUCCESS) return vks_fail("vkEndCommandBuffer", r);
    memset(&si, 0, sizeof si);
    si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &t->cmd;
    if ((r = t->vkQueueSubmit(t->dev->queue, 1, &si, t->fence)) != VK_SUCCESS) return vks_fail("vkQueueSubmit", r);
    if ((r = t->vkWaitForFences(t->device, 1, &t->fence, VK_TRUE, UINT64_MAX)) != VK_SUCCESS)
        return vks_fail("vkWaitForFences", r);
    if ((r = t->vkResetFences(t->device, 1, &t->fence)) != VK_SUCCESS) return vks_fail("vkResetFences", r);
    return 0;
}

/* One global memory barrier, src (stage, access) -> dst (stage, access):
   the form of every row of linear_rt.h's BARRIERS. */
static inline void vks_barrier(vks *t, VkPipelineStageFlags src_stage, VkAccessFlags src_access, VkPipelineStageFlags dst_stage,
                        VkAccessFlags dst_access)
{
    VkMemoryBarrier b;
    memset(&b, 0, sizeof b);
    b.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    b.srcAccessMask = src_access;
    b.dstAccessMask = dst_access;
    t->vkCmdPipelineBarrier(t->cmd, src_stage, dst_stage, 0, 1, &b, 0, NULL, 0, NULL);
}

/* Timestamp i once the commands before it have passed stage; index 0
   resets the pool first. Nothing without t->queries. */
static inline void vks_timestamp(vks *t, VkPipelineStageFlagBits stage, uint32_t i)
{
    if (!t->queries) return;
    if (i == 0) t->vkCmdResetQueryPool(t->cmd, t->queries, 0, VKS_TIMESTAMPS);
    t->vkCmdWriteTimestamp(t->cmd, stage, t->queries, i);
}

/* After vks_submit: ms[i] = timestamp i+1 - timestamp i, in milliseconds. */
static inline int vks_timestamps_ms(vks *t, double ms[VKS_TIMESTAMPS - 1])
{
    uint64_t ts[VKS_TIMESTAMPS];
    const double period = (double)t->dev->properties.limits.timestampPeriod * 1e-6; /* ns a tick -> ms */
    VkResult r = t->vkGetQueryPoolResults(t->device, t->queries, 0, VKS_TIMESTAMPS, sizeof ts, ts, sizeof ts[0],
                                          VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
    int i;
    if (r != VK_SUCCESS) return vks_fail("vkGetQueryPoolResults", r);
    for (i = 0; i + 1 < VKS_TIMESTAMPS; ++i) ms[i] = (double)(ts[i + 1] - ts[i]) * period;
    return 0;
}

#endif /* VK_SMALL_H */
