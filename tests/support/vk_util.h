/* tests/support/vk_util.h - the little Vulkan a test or the benchmark needs around
   linear_rt's recording functions: host-visible buffers, sampled depth
   images uploaded through a staging buffer, one command buffer submitted
   and waited for, timestamps. Every function pointer comes from the
   lrt_vk_device of linear_rt.h's device helper: nothing links against
   Vulkan. Include after linear_rt.h (with LINEAR_RT_VULKAN and
   LINEAR_RT_VULKAN_DEVICE_HELPER); everything is static, for one file.
   Errors print a line to stderr and return nonzero. */
#ifndef LINEAR_RT_TESTS_VK_UTIL_H
#define LINEAR_RT_TESTS_VK_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__) || defined(__clang__)
#define VKT_FN static __attribute__((unused)) /* a file uses only some */
#else
#define VKT_FN static
#endif

#define VKT_INSTANCE_FUNCS(X)                                                                                     \
    X(vkGetPhysicalDeviceMemoryProperties) X(vkGetPhysicalDeviceFormatProperties)
#define VKT_DEVICE_FUNCS(X)                                                                                       \
    X(vkCreateBuffer) X(vkDestroyBuffer) X(vkGetBufferMemoryRequirements) X(vkAllocateMemory) X(vkFreeMemory)    \
    X(vkBindBufferMemory) X(vkMapMemory) X(vkUnmapMemory) X(vkCreateImage) X(vkDestroyImage)                     \
    X(vkGetImageMemoryRequirements) X(vkBindImageMemory) X(vkCreateImageView) X(vkDestroyImageView)             \
    X(vkCreateCommandPool) X(vkDestroyCommandPool) X(vkAllocateCommandBuffers) X(vkBeginCommandBuffer)           \
    X(vkEndCommandBuffer) X(vkResetCommandBuffer) X(vkCmdPipelineBarrier) X(vkCmdCopyBufferToImage)              \
    X(vkCmdCopyBuffer) X(vkCmdFillBuffer) X(vkQueueSubmit) X(vkCreateFence) X(vkDestroyFence) X(vkWaitForFences) \
    X(vkResetFences) X(vkCreateQueryPool) X(vkDestroyQueryPool) X(vkCmdResetQueryPool) X(vkCmdWriteTimestamp)    \
    X(vkGetQueryPoolResults) X(vkDeviceWaitIdle)

typedef struct vkt {
    lrt_vk_device *dev;
    VkDevice device;
    VkPhysicalDeviceMemoryProperties memory;
    VkCommandPool pool;
    VkCommandBuffer cmd; /* one, reused: vkt_begin .. vkt_submit */
    VkFence fence;
#define VKT_MEMBER(name) PFN_##name name;
    VKT_INSTANCE_FUNCS(VKT_MEMBER)
    VKT_DEVICE_FUNCS(VKT_MEMBER)
#undef VKT_MEMBER
} vkt;

typedef struct vkt_buffer {
    VkBuffer buffer;
    VkDeviceMemory memory;
    void *map; /* host-visible, coherent, mapped for its lifetime */
    VkDeviceSize size;
} vkt_buffer;

typedef struct vkt_image {
    VkImage image;
    VkDeviceMemory memory;
    VkImageView view;
    VkFormat format;
    uint32_t width, height, bpp;
} vkt_image;

/* floats in [0,1] -> the bytes of a depth format (unorm: rounded) */
VKT_FN void vkt_encode_depth(const float *f, void *out, size_t n, lrt_format format)
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

VKT_FN int vkt_fail(const char *what, VkResult r)
{
    fprintf(stderr, "vk_util: %s failed: VkResult %d\n", what, (int)r);
    return 1;
}

VKT_FN int vkt_init(vkt *t, lrt_vk_device *dev)
{
    const lrt_vk_context_desc *d = &dev->desc;
    VkCommandPoolCreateInfo pi;
    VkCommandBufferAllocateInfo ai;
    VkFenceCreateInfo fi;
    VkResult r;
    memset(t, 0, sizeof *t);
    t->dev = dev;
    t->device = d->device;
#define VKT_LOAD_I(name)                                                                                          \
    t->name = (PFN_##name)d->get_instance_proc_addr(d->instance, #name);                                          \
    if (!t->name) return vkt_fail("loading " #name, VK_ERROR_INITIALIZATION_FAILED);
#define VKT_LOAD_D(name)                                                                                          \
    t->name = (PFN_##name)d->get_device_proc_addr(d->device, #name);                                              \
    if (!t->name) return vkt_fail("loading " #name, VK_ERROR_INITIALIZATION_FAILED);
    VKT_INSTANCE_FUNCS(VKT_LOAD_I)
    VKT_DEVICE_FUNCS(VKT_LOAD_D)
#undef VKT_LOAD_I
#undef VKT_LOAD_D
    t->vkGetPhysicalDeviceMemoryProperties(d->physical_device, &t->memory);
    memset(&pi, 0, sizeof pi);
    pi.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pi.queueFamilyIndex = dev->queue_family;
    if ((r = t->vkCreateCommandPool(t->device, &pi, NULL, &t->pool)) != VK_SUCCESS) return vkt_fail("vkCreateCommandPool", r);
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    ai.commandPool = t->pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    if ((r = t->vkAllocateCommandBuffers(t->device, &ai, &t->cmd)) != VK_SUCCESS) return vkt_fail("vkAllocateCommandBuffers", r);
    memset(&fi, 0, sizeof fi);
    fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    if ((r = t->vkCreateFence(t->device, &fi, NULL, &t->fence)) != VK_SUCCESS) return vkt_fail("vkCreateFence", r);
    return 0;
}

VKT_FN void vkt_free(vkt *t)
{
    if (!t->device) return;
    t->vkDeviceWaitIdle(t->device);
    if (t->fence) t->vkDestroyFence(t->device, t->fence, NULL);
    if (t->pool) t->vkDestroyCommandPool(t->device, t->pool, NULL);
    memset(t, 0, sizeof *t);
}

VKT_FN int vkt_memory_type(const vkt *t, uint32_t allowed, VkMemoryPropertyFlags want)
{
    uint32_t i;
    for (i = 0; i < t->memory.memoryTypeCount; ++i)
        if (((allowed >> i) & 1u) && (t->memory.memoryTypes[i].propertyFlags & want) == want) return (int)i;
    return -1;
}

VKT_FN int vkt_allocate(vkt *t, VkMemoryRequirements *mr, VkMemoryPropertyFlags want, VkDeviceMemory *out)
{
    VkMemoryAllocateInfo ai;
    VkResult r;
    int type = vkt_memory_type(t, mr->memoryTypeBits, want);
    if (type < 0) return vkt_fail("finding a memory type", VK_ERROR_FEATURE_NOT_PRESENT);
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    ai.allocationSize = mr->size;
    ai.memoryTypeIndex = (uint32_t)type;
    if ((r = t->vkAllocateMemory(t->device, &ai, NULL, out)) != VK_SUCCESS) return vkt_fail("vkAllocateMemory", r);
    return 0;
}

/* A host-visible, coherent, mapped buffer of size bytes (usage: storage,
   uniform texel (a tree's nodes), transfer source and destination); prefer_device: DEVICE_LOCAL as well
   where there is such memory (integrated GPUs, resizable BAR, lavapipe). */
VKT_FN int vkt_buffer_create_in(vkt *t, VkDeviceSize size, int prefer_device, vkt_buffer *b)
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
               VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    if ((r = t->vkCreateBuffer(t->device, &bi, NULL, &b->buffer)) != VK_SUCCESS) return vkt_fail("vkCreateBuffer", r);
    t->vkGetBufferMemoryRequirements(t->device, b->buffer, &mr);
    if (prefer_device && vkt_memory_type(t, mr.memoryTypeBits, hv | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT) >= 0) {
        if (vkt_allocate(t, &mr, hv | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, &b->memory)) return 1;
    } else if (vkt_allocate(t, &mr, hv, &b->memory)) {
        return 1;
    }
    if ((r = t->vkBindBufferMemory(t->device, b->buffer, b->memory, 0)) != VK_SUCCESS) return vkt_fail("vkBindBufferMemory", r);
    if ((r = t->vkMapMemory(t->device, b->memory, 0, VK_WHOLE_SIZE, 0, &b->map)) != VK_SUCCESS) return vkt_fail("vkMapMemory", r);
    b->size = bi.size;
    return 0;
}

VKT_FN int vkt_buffer_create(vkt *t, VkDeviceSize size, vkt_buffer *b) { return vkt_buffer_create_in(t, size, 0, b); }

VKT_FN void vkt_buffer_destroy(vkt *t, vkt_buffer *b)
{
    if (b->memory) {
        if (b->map) t->vkUnmapMemory(t->device, b->memory);
        t->vkFreeMemory(t->device, b->memory, NULL);
    }
    if (b->buffer) t->vkDestroyBuffer(t->device, b->buffer, NULL);
    memset(b, 0, sizeof *b);
}

VKT_FN int vkt_begin(vkt *t)
{
    VkCommandBufferBeginInfo bi;
    VkResult r;
    if ((r = t->vkResetCommandBuffer(t->cmd, 0)) != VK_SUCCESS) return vkt_fail("vkResetCommandBuffer", r);
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    if ((r = t->vkBeginCommandBuffer(t->cmd, &bi)) != VK_SUCCESS) return vkt_fail("vkBeginCommandBuffer", r);
    return 0;
}

/* Ends, submits and waits for the command buffer. */
VKT_FN int vkt_submit(vkt *t)
{
    VkSubmitInfo si;
    VkResult r;
    if ((r = t->vkEndCommandBuffer(t->cmd)) != VK_SUCCESS) return vkt_fail("vkEndCommandBuffer", r);
    memset(&si, 0, sizeof si);
    si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &t->cmd;
    if ((r = t->vkQueueSubmit(t->dev->queue, 1, &si, t->fence)) != VK_SUCCESS) return vkt_fail("vkQueueSubmit", r);
    if ((r = t->vkWaitForFences(t->device, 1, &t->fence, VK_TRUE, UINT64_MAX)) != VK_SUCCESS)
        return vkt_fail("vkWaitForFences", r);
    if ((r = t->vkResetFences(t->device, 1, &t->fence)) != VK_SUCCESS) return vkt_fail("vkResetFences", r);
    return 0;
}

/* A global memory barrier: what linear_rt.h's BARRIERS asks of its callers. */
VKT_FN void vkt_barrier(vkt *t, VkPipelineStageFlags src_stage, VkAccessFlags src_access, VkPipelineStageFlags dst_stage,
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
VKT_FN void vkt_compute_barrier(vkt *t)
{
    vkt_barrier(t, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
}

/* compute writes -> mapped reads on the host after the fence */
VKT_FN void vkt_host_barrier(vkt *t)
{
    vkt_barrier(t, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                VK_ACCESS_HOST_READ_BIT);
}

VKT_FN int vkt_format_sampled(vkt *t, VkFormat format)
{
    VkFormatProperties p;
    t->vkGetPhysicalDeviceFormatProperties(t->dev->desc.physical_device, format, &p);
    return (p.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT) != 0;
}

VKT_FN int vkt_is_depth_format(VkFormat f) { return f == VK_FORMAT_D32_SFLOAT || f == VK_FORMAT_D16_UNORM; }

VKT_FN void vkt_image_barrier(vkt *t, const vkt_image *im, VkImageLayout from, VkImageLayout to,
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
    b.subresourceRange.aspectMask = vkt_is_depth_format(im->format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
    b.subresourceRange.levelCount = 1;
    b.subresourceRange.layerCount = 1;
    t->vkCmdPipelineBarrier(t->cmd, src_stage, dst_stage, 0, 0, NULL, 0, NULL, 1, &b);
}

/* Uploads packed texels (width*bpp bytes a row) into the image through a
   staging buffer, leaving it SHADER_READ_ONLY_OPTIMAL. first: the image was
   never written (UNDEFINED), else it is SHADER_READ_ONLY_OPTIMAL now. */
VKT_FN int vkt_image_upload(vkt *t, vkt_image *im, const void *texels, int first)
{
    vkt_buffer staging;
    VkBufferImageCopy c;
    const VkDeviceSize bytes = (VkDeviceSize)im->width * im->height * im->bpp;
    int err;
    if (vkt_buffer_create(t, bytes, &staging)) return 1;
    memcpy(staging.map, texels, (size_t)bytes);
    if (vkt_begin(t)) return 1;
    vkt_image_barrier(t, im, first ? VK_IMAGE_LAYOUT_UNDEFINED : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                      VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0,
                      VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
    memset(&c, 0, sizeof c);
    c.imageSubresource.aspectMask = vkt_is_depth_format(im->format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
    c.imageSubresource.layerCount = 1;
    c.imageExtent.width = im->width;
    c.imageExtent.height = im->height;
    c.imageExtent.depth = 1;
    t->vkCmdCopyBufferToImage(t->cmd, staging.buffer, im->image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &c);
    /* the depth writes -> the kernels' reads: BARRIERS' first rule */
    vkt_image_barrier(t, im, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                      VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      VK_ACCESS_SHADER_READ_BIT);
    err = vkt_submit(t);
    vkt_buffer_destroy(t, &staging);
    return err;
}

/* A sampled 2D image of one level (optimal tiling, device-local if there
   is such memory) with a view; its texels come from vkt_image_upload. */
VKT_FN int vkt_image_create(vkt *t, VkFormat format, uint32_t width, uint32_t height, vkt_image *im)
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
    if ((r = t->vkCreateImage(t->device, &ii, NULL, &im->image)) != VK_SUCCESS) return vkt_fail("vkCreateImage", r);
    t->vkGetImageMemoryRequirements(t->device, im->image, &mr);
    if (vkt_memory_type(t, mr.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT) >= 0) {
        if (vkt_allocate(t, &mr, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, &im->memory)) return 1;
    } else if (vkt_allocate(t, &mr, 0, &im->memory)) {
        return 1;
    }
    if ((r = t->vkBindImageMemory(t->device, im->image, im->memory, 0)) != VK_SUCCESS) return vkt_fail("vkBindImageMemory", r);
    memset(&vi, 0, sizeof vi);
    vi.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    vi.image = im->image;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = format;
    vi.subresourceRange.aspectMask = vkt_is_depth_format(format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
    vi.subresourceRange.levelCount = 1;
    vi.subresourceRange.layerCount = 1;
    if ((r = t->vkCreateImageView(t->device, &vi, NULL, &im->view)) != VK_SUCCESS) return vkt_fail("vkCreateImageView", r);
    return 0;
}

VKT_FN void vkt_image_destroy(vkt *t, vkt_image *im)
{
    if (im->view) t->vkDestroyImageView(t->device, im->view, NULL);
    if (im->image) t->vkDestroyImage(t->device, im->image, NULL);
    if (im->memory) t->vkFreeMemory(t->device, im->memory, NULL);
    memset(im, 0, sizeof *im);
}

#endif /* LINEAR_RT_TESTS_VK_UTIL_H */
