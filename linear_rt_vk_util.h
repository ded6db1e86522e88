/* linear_rt_vk_util.h - a companion of linear_rt.h, as sokol keeps util
   headers beside its own: the little Vulkan that tools, tests, examples and
   the benchmark need around linear_rt's recording functions, and that an
   engine has of its own. Host-visible buffers, sampled depth images
   uploaded through a staging buffer, one command buffer submitted and
   waited for, memory barriers (the form of every row of linear_rt.h's
   BARRIERS), timestamps. Every function pointer comes from the
   lrt_vk_device of linear_rt.h's device helper: nothing links against
   Vulkan, it builds with VK_NO_PROTOTYPES. Include after linear_rt.h (with
   LINEAR_RT_VULKAN and LINEAR_RT_VULKAN_DEVICE_HELPER); every function is
   static, for one file. Errors print a line to stderr and return nonzero.

   LICENCE: MIT, as linear_rt.h. */
#ifndef LINEAR_RT_VK_UTIL_H
#define LINEAR_RT_VK_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__) || defined(__clang__)
#define LRT_VKU_FN static __attribute__((unused)) /* a file uses only some */
#else
#define LRT_VKU_FN static
#endif

#define LRT_VKU_TIMESTAMPS 3 /* queries in lrt_vku.queries */

#define LRT_VKU_INSTANCE_FUNCS(X)                                                                                     \
    X(vkGetPhysicalDeviceMemoryProperties) X(vkGetPhysicalDeviceFormatProperties)
#define LRT_VKU_DEVICE_FUNCS(X)                                                                                       \
    X(vkCreateBuffer) X(vkDestroyBuffer) X(vkGetBufferMemoryRequirements) X(vkAllocateMemory) X(vkFreeMemory)    \
    X(vkBindBufferMemory) X(vkMapMemory) X(vkUnmapMemory) X(vkCreateImage) X(vkDestroyImage)                     \
    X(vkGetImageMemoryRequirements) X(vkBindImageMemory) X(vkCreateImageView) X(vkDestroyImageView)             \
    X(vkCreateCommandPool) X(vkDestroyCommandPool) X(vkAllocateCommandBuffers) X(vkBeginCommandBuffer)           \
    X(vkEndCommandBuffer) X(vkResetCommandBuffer) X(vkCmdPipelineBarrier) X(vkCmdCopyBufferToImage)              \
    X(vkCmdCopyBuffer) X(vkCmdFillBuffer) X(vkQueueSubmit) X(vkCreateFence) X(vkDestroyFence) X(vkWaitForFences) \
    X(vkResetFences) X(vkCreateQueryPool) X(vkDestroyQueryPool) X(vkCmdResetQueryPool) X(vkCmdWriteTimestamp)    \
    X(vkGetQueryPoolResults) X(vkDeviceWaitIdle)

typedef struct lrt_vku {
    const lrt_vk_device *dev;
    VkDevice device;
    VkPhysicalDeviceMemoryProperties memory;
    VkCommandPool pool;
    VkCommandBuffer cmd; /* one, reused: lrt_vku_begin .. lrt_vku_submit */
    VkFence fence;
    VkQueryPool queries; /* LRT_VKU_TIMESTAMPS timestamps; VK_NULL_HANDLE: the queue has none */
#define LRT_VKU_MEMBER(name) PFN_##name name;
    LRT_VKU_INSTANCE_FUNCS(LRT_VKU_MEMBER)
    LRT_VKU_DEVICE_FUNCS(LRT_VKU_MEMBER)
#undef LRT_VKU_MEMBER
} lrt_vku;

typedef struct lrt_vku_buffer {
    VkBuffer buffer;
    VkDeviceMemory memory;
    void *map; /* host-visible, coherent, mapped for its lifetime */
    VkDeviceSize size;
} lrt_vku_buffer;

typedef struct lrt_vku_image {
    VkImage image;
    VkDeviceMemory memory;
    VkImageView view;
    VkFormat format;
    uint32_t width, height, bpp;
} lrt_vku_image;

/* floats in [0,1] -> the bytes of a depth format (unorm: rounded) */
LRT_VKU_FN void lrt_vku_encode_depth(const float *f, void *out, size_t n, lrt_format format)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        if (format == LRT_FORMAT_UNORM8) ((uint8_t *)out)[i] = (uint8_t)(f[i] * 255.0f + 0.5f);
        else if (format == LRT_FORMAT_UNORM16) {
            uint16_t v = (uint16_t)(f[i] * 65535.0f + 0.5f);
            memcpy((unsigned char *)out + 2 * i, &v, 2);
        } else memcpy((unsigned char *)out + 4 * i, &f[i], 4);
    }
}

LRT_VKU_FN int lrt_vku_fail(const char *what, VkResult r)
{
    fprintf(stderr, "linear_rt_vk_util: %s failed: VkResult %d\n", what, (int)r);
    return 1;
}

/* Loads the functions, makes the command pool and buffer, the fence and
   (where the queue has timestamps) the query pool. lrt_vku_free undoes it,
   also after a failure half-way. */
LRT_VKU_FN int lrt_vku_init(lrt_vku *t, const lrt_vk_device *dev)
{
    const lrt_vk_context_desc *d = &dev->desc;
    VkCommandPoolCreateInfo pi;
    VkCommandBufferAllocateInfo ai;
    VkFenceCreateInfo fi;
    VkResult r;
    memset(t, 0, sizeof *t);
    t->dev = dev;
    t->device = d->device;
#define LRT_VKU_LOAD_I(name)                                                                                          \
    t->name = (PFN_##name)d->get_instance_proc_addr(d->instance, #name);                                          \
    if (!t->name) return lrt_vku_fail("loading " #name, VK_ERROR_INITIALIZATION_FAILED);
#define LRT_VKU_LOAD_D(name)                                                                                          \
    t->name = (PFN_##name)d->get_device_proc_addr(d->device, #name);                                              \
    if (!t->name) return lrt_vku_fail("loading " #name, VK_ERROR_INITIALIZATION_FAILED);
    LRT_VKU_INSTANCE_FUNCS(LRT_VKU_LOAD_I)
    LRT_VKU_DEVICE_FUNCS(LRT_VKU_LOAD_D)
#undef LRT_VKU_LOAD_I
#undef LRT_VKU_LOAD_D
    t->vkGetPhysicalDeviceMemoryProperties(d->physical_device, &t->memory);
    memset(&pi, 0, sizeof pi);
    pi.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pi.queueFamilyIndex = dev->queue_family;
    if ((r = t->vkCreateCommandPool(t->device, &pi, NULL, &t->pool)) != VK_SUCCESS) return lrt_vku_fail("vkCreateCommandPool", r);
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    ai.commandPool = t->pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    if ((r = t->vkAllocateCommandBuffers(t->device, &ai, &t->cmd)) != VK_SUCCESS) return lrt_vku_fail("vkAllocateCommandBuffers", r);
    memset(&fi, 0, sizeof fi);
    fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    if ((r = t->vkCreateFence(t->device, &fi, NULL, &t->fence)) != VK_SUCCESS) return lrt_vku_fail("vkCreateFence", r);
    if (dev->timestamp_valid_bits) {
        VkQueryPoolCreateInfo qi;
        memset(&qi, 0, sizeof qi);
        qi.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
        qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
        qi.queryCount = LRT_VKU_TIMESTAMPS;
        if (t->vkCreateQueryPool(t->device, &qi, NULL, &t->queries) != VK_SUCCESS) t->queries = VK_NULL_HANDLE;
    }
    return 0;
}

LRT_VKU_FN void lrt_vku_free(lrt_vku *t)
{
    if (!t->device) return;
    t->vkDeviceWaitIdle(t->device);
    if (t->queries) t->vkDestroyQueryPool(t->device, t->queries, NULL);
    if (t->fence) t->vkDestroyFence(t->device, t->fence, NULL);
    if (t->pool) t->vkDestroyCommandPool(t->device, t->pool, NULL);
    memset(t, 0, sizeof *t);
}

LRT_VKU_FN int lrt_vku_memory_type(const lrt_vku *t, uint32_t allowed, VkMemoryPropertyFlags want)
{
    uint32_t i;
    for (i = 0; i < t->memory.memoryTypeCount; ++i)
        if (((allowed >> i) & 1u) && (t->memory.memoryTypes[i].propertyFlags & want) == want) return (int)i;
    return -1;
}

LRT_VKU_FN int lrt_vku_allocate(lrt_vku *t, VkMemoryRequirements *mr, VkMemoryPropertyFlags want, VkDeviceMemory *out)
{
    VkMemoryAllocateInfo ai;
    VkResult r;
    int type = lrt_vku_memory_type(t, mr->memoryTypeBits, want);
    if (type < 0) return lrt_vku_fail("finding a memory type", VK_ERROR_FEATURE_NOT_PRESENT);
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    ai.allocationSize = mr->size;
    ai.memoryTypeIndex = (uint32_t)type;
    if ((r = t->vkAllocateMemory(t->device, &ai, NULL, out)) != VK_SUCCESS) return lrt_vku_fail("vkAllocateMemory", r);
    return 0;
}

/* A host-visible, coherent, mapped buffer of size bytes (usage: storage,
   uniform texel (a tree's nodes), indirect (a compacted trace's scratch),
   transfer source and destination); prefer_device: DEVICE_LOCAL as well
   where there is such memory (integrated GPUs, resizable BAR, lavapipe). */
LRT_VKU_FN int lrt_vku_buffer_create_in(lrt_vku *t, VkDeviceSize size, int prefer_device, lrt_vku_buffer *b)
{
    const VkMemoryPropertyFlags hv = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    VkBufferCreateInfo bi;
    VkMemoryRequirements mr;
    VkResult r;
    memset(b, 0, sizeof *b);
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bi.size = size ? size : 4;
    bi.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT |
               VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    if ((r = t->vkCreateBuffer(t->device, &bi, NULL, &b->buffer)) != VK_SUCCESS) return lrt_vku_fail("vkCreateBuffer", r);
    t->vkGetBufferMemoryRequirements(t->device, b->buffer, &mr);
    if (prefer_device && lrt_vku_memory_type(t, mr.memoryTypeBits, hv | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT) >= 0) {
        if (lrt_vku_allocate(t, &mr, hv | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, &b->memory)) return 1;
    } else if (lrt_vku_allocate(t, &mr, hv, &b->memory)) {
        return 1;
    }
    if ((r = t->vkBindBufferMemory(t->device, b->buffer, b->memory, 0)) != VK_SUCCESS) return lrt_vku_fail("vkBindBufferMemory", r);
    if ((r = t->vkMapMemory(t->device, b->memory, 0, VK_WHOLE_SIZE, 0, &b->map)) != VK_SUCCESS) return lrt_vku_fail("vkMapMemory", r);
    b->size = bi.size;
    return 0;
}

LRT_VKU_FN int lrt_vku_buffer_create(lrt_vku *t, VkDeviceSize size, lrt_vku_buffer *b) { return lrt_vku_buffer_create_in(t, size, 0, b); }

LRT_VKU_FN void lrt_vku_buffer_destroy(lrt_vku *t, lrt_vku_buffer *b)
{
    if (b->memory) {
        if (b->map) t->vkUnmapMemory(t->device, b->memory);
        t->vkFreeMemory(t->device, b->memory, NULL);
    }
    if (b->buffer) t->vkDestroyBuffer(t->device, b->buffer, NULL);
    memset(b, 0, sizeof *b);
}

LRT_VKU_FN int lrt_vku_begin(lrt_vku *t)
{
    VkCommandBufferBeginInfo bi;
    VkResult r;
    if ((r = t->vkResetCommandBuffer(t->cmd, 0)) != VK_SUCCESS) return lrt_vku_fail("vkResetCommandBuffer", r);
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    if ((r = t->vkBeginCommandBuffer(t->cmd, &bi)) != VK_SUCCESS) return lrt_vku_fail("vkBeginCommandBuffer", r);
    return 0;
}

/* Ends, submits and waits for the command buffer. */
LRT_VKU_FN int lrt_vku_submit(lrt_vku *t)
{
    VkSubmitInfo si;
    VkResult r;
    if ((r = t->vkEndCommandBuffer(t->cmd)) != VK_SUCCESS) return lrt_vku_fail("vkEndCommandBuffer", r);
    memset(&si, 0, sizeof si);
    si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &t->cmd;
    if ((r = t->vkQueueSubmit(t->dev->queue, 1, &si, t->fence)) != VK_SUCCESS) return lrt_vku_fail("vkQueueSubmit", r);
    if ((r = t->vkWaitForFences(t->device, 1, &t->fence, VK_TRUE, UINT64_MAX)) != VK_SUCCESS)
        return lrt_vku_fail("vkWaitForFences", r);
    if ((r = t->vkResetFences(t->device, 1, &t->fence)) != VK_SUCCESS) return lrt_vku_fail("vkResetFences", r);
    return 0;
}

/* A global memory barrier: what linear_rt.h's BARRIERS asks of its callers. */
LRT_VKU_FN void lrt_vku_barrier(lrt_vku *t, VkPipelineStageFlags src_stage, VkAccessFlags src_access, VkPipelineStageFlags dst_stage,
                        VkAccessFlags dst_access)
{
    VkMemoryBarrier b;
    memset(&b, 0, sizeof b);
    b.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    b.srcAccessMask = src_access;
    b.dstAccessMask = dst_access;
    t->vkCmdPipelineBarrier(t->cmd, src_stage, dst_stage, 0, 1, &b, 0, NULL, 0, NULL);
}

/* compute writes (a build, update or trace) -> the next linear_rt command
   (a build's counter fill included) */
LRT_VKU_FN void lrt_vku_compute_barrier(lrt_vku *t)
{
    lrt_vku_barrier(t, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
}

/* compute writes -> mapped reads on the host after the fence */
LRT_VKU_FN void lrt_vku_host_barrier(lrt_vku *t)
{
    lrt_vku_barrier(t, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                VK_ACCESS_HOST_READ_BIT);
}

/* Timestamp i once the commands before it have passed stage; index 0
   resets the pool first. Nothing without t->queries. */
LRT_VKU_FN void lrt_vku_timestamp(lrt_vku *t, VkPipelineStageFlagBits stage, uint32_t i)
{
    if (!t->queries) return;
    if (i == 0) t->vkCmdResetQueryPool(t->cmd, t->queries, 0, LRT_VKU_TIMESTAMPS);
    t->vkCmdWriteTimestamp(t->cmd, stage, t->queries, i);
}

/* After lrt_vku_submit: ms[i] = timestamp i+1 - timestamp i, in milliseconds. */
LRT_VKU_FN int lrt_vku_timestamps_ms(lrt_vku *t, double ms[LRT_VKU_TIMESTAMPS - 1])
{
    uint64_t ts[LRT_VKU_TIMESTAMPS];
    const double period = (double)t->dev->properties.limits.timestampPeriod * 1e-6; /* ns a tick -> ms */
    VkResult r = t->vkGetQueryPoolResults(t->device, t->queries, 0, LRT_VKU_TIMESTAMPS, sizeof ts, ts, sizeof ts[0],
                                          VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
    int i;
    if (r != VK_SUCCESS) return lrt_vku_fail("vkGetQueryPoolResults", r);
    for (i = 0; i + 1 < LRT_VKU_TIMESTAMPS; ++i) ms[i] = (double)(ts[i + 1] - ts[i]) * period;
    return 0;
}

LRT_VKU_FN int lrt_vku_format_sampled(lrt_vku *t, VkFormat format)
{
    VkFormatProperties p;
    t->vkGetPhysicalDeviceFormatProperties(t->dev->desc.physical_device, format, &p);
    return (p.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT) != 0;
}

LRT_VKU_FN int lrt_vku_is_depth_format(VkFormat f) { return f == VK_FORMAT_D32_SFLOAT || f == VK_FORMAT_D16_UNORM; }

LRT_VKU_FN void lrt_vku_image_barrier(lrt_vku *t, const lrt_vku_image *im, VkImageLayout from, VkImageLayout to,
                              VkPipelineStageFlags src_stage, VkAccessFlags src_access, VkPipelineStageFlags dst_stage,
                              VkAccessFlags dst_access)
{
    VkImageMemoryBarrier b;
    memset(&b, 0, sizeof b);
    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    b.srcAccessMask = src_access;
    b.dstAccessMask = dst_access;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = im->image;
    b.subresourceRange.aspectMask = lrt_vku_is_depth_format(im->format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
    b.subresourceRange.levelCount = 1;
    b.subresourceRange.layerCount = 1;
    t->vkCmdPipelineBarrier(t->cmd, src_stage, dst_stage, 0, 0, NULL, 0, NULL, 1, &b);
}

/* Uploads packed texels (width*bpp bytes a row) into the image through a
   staging buffer, leaving it SHADER_READ_ONLY_OPTIMAL. first: the image was
   never written (UNDEFINED), else it is SHADER_READ_ONLY_OPTIMAL now. */
LRT_VKU_FN int lrt_vku_image_upload(lrt_vku *t, lrt_vku_image *im, const void *texels, int first)
{
    lrt_vku_buffer staging;
    VkBufferImageCopy c;
    const VkDeviceSize bytes = (VkDeviceSize)im->width * im->height * im->bpp;
    int err;
    if (lrt_vku_buffer_create(t, bytes, &staging)) return 1;
    memcpy(staging.map, texels, (size_t)bytes);
    if (lrt_vku_begin(t)) return 1;
    lrt_vku_image_barrier(t, im, first ? VK_IMAGE_LAYOUT_UNDEFINED : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                      VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0,
                      VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
    memset(&c, 0, sizeof c);
    c.imageSubresource.aspectMask = lrt_vku_is_depth_format(im->format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
    c.imageSubresource.layerCount = 1;
    c.imageExtent.width = im->width;
    c.imageExtent.height = im->height;
    c.imageExtent.depth = 1;
    t->vkCmdCopyBufferToImage(t->cmd, staging.buffer, im->image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &c);
    /* the depth writes -> the kernels' reads: BARRIERS' first rule */
    lrt_vku_image_barrier(t, im, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                      VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      VK_ACCESS_SHADER_READ_BIT);
    err = lrt_vku_submit(t);
    lrt_vku_buffer_destroy(t, &staging);
    return err;
}

/* A sampled 2D image of one level (optimal tiling, device-local if there
   is such memory) with a view; its texels come from lrt_vku_image_upload. */
LRT_VKU_FN int lrt_vku_image_create(lrt_vku *t, VkFormat format, uint32_t width, uint32_t height, lrt_vku_image *im)
{
    VkImageCreateInfo ii;
    VkImageViewCreateInfo vi;
    VkMemoryRequirements mr;
    VkResult r;
    memset(im, 0, sizeof *im);
    im->format = format;
    im->width = width;
    im->height = height;
    im->bpp = format == VK_FORMAT_R8_UNORM ? 1u : (format == VK_FORMAT_D16_UNORM || format == VK_FORMAT_R16_UNORM) ? 2u : 4u;
    memset(&ii, 0, sizeof ii);
    ii.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    ii.imageType = VK_IMAGE_TYPE_2D;
    ii.format = format;
    ii.extent.width = width;
    ii.extent.height = height;
    ii.extent.depth = 1;
    ii.mipLevels = 1;
    ii.arrayLayers = 1;
    ii.samples = VK_SAMPLE_COUNT_1_BIT;
    ii.tiling = VK_IMAGE_TILING_OPTIMAL;
    ii.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    ii.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    ii.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    if ((r = t->vkCreateImage(t->device, &ii, NULL, &im->image)) != VK_SUCCESS) return lrt_vku_fail("vkCreateImage", r);
    t->vkGetImageMemoryRequirements(t->device, im->image, &mr);
    if (lrt_vku_memory_type(t, mr.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT) >= 0) {
        if (lrt_vku_allocate(t, &mr, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, &im->memory)) return 1;
    } else if (lrt_vku_allocate(t, &mr, 0, &im->memory)) {
        return 1;
    }
    if ((r = t->vkBindImageMemory(t->device, im->image, im->memory, 0)) != VK_SUCCESS) return lrt_vku_fail("vkBindImageMemory", r);
    memset(&vi, 0, sizeof vi);
    vi.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    vi.image = im->image;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = format;
    vi.subresourceRange.aspectMask = lrt_vku_is_depth_format(format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
    vi.subresourceRange.levelCount = 1;
    vi.subresourceRange.layerCount = 1;
    if ((r = t->vkCreateImageView(t->device, &vi, NULL, &im->view)) != VK_SUCCESS) return lrt_vku_fail("vkCreateImageView", r);
    return 0;
}

LRT_VKU_FN void lrt_vku_image_destroy(lrt_vku *t, lrt_vku_image *im)
{
    if (im->view) t->vkDestroyImageView(t->device, im->view, NULL);
    if (im->image) t->vkDestroyImage(t->device, im->image, NULL);
    if (im->memory) t->vkFreeMemory(t->device, im->memory, NULL);
    memset(im, 0, sizeof *im);
}

#endif /* LINEAR_RT_VK_UTIL_H */
