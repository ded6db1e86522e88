/* linear_rt_vk_util.h - a companion of linear_rt.h, as sokol keeps util
   headers beside its own: the little Vulkan that tools, tests, examples and
   the benchmark need around linear_rt's recording functions, and that an
   engine has of its own, so linear_rt.h carries none of it. A device
   (lrt_vku_device_create: the Vulkan loader opened at run time, an
   instance, a device with what the kernels need and a compute queue,
   optionally the validation layer; its pieces for programs that make
   another device: lrt_vku_open_loader, lrt_vku_messenger_info,
   lrt_vku_create_vk_device), host-visible buffers, sampled depth
   images uploaded through a staging buffer, one command buffer submitted
   and waited for, memory barriers (the form of every row of linear_rt.h's
   BARRIERS), timestamps. Nothing links against Vulkan: every function
   comes from the loader's vkGetInstanceProcAddr, so it builds with
   VK_NO_PROTOTYPES (dlopen: link with -ldl on old glibc).
       #define LINEAR_RT_VULKAN
       #include "linear_rt.h"
       #include "linear_rt_vk_util.h"
   Every function is static (no IMPLEMENTATION switch): a program includes
   it in each file that uses it. lrt_vku_device_create returns an
   lrt_result, lrt_vku_create_vk_device a VkResult, lrt_vku_open_loader
   NULL where there is no loader; the others print a line to stderr and
   return nonzero.

   LICENCE: MIT, as linear_rt.h. */
#ifndef LINEAR_RT_VK_UTIL_H
#define LINEAR_RT_VK_UTIL_H
#ifndef LINEAR_RT_VULKAN_H
#error "linear_rt_vk_util.h: include linear_rt.h with LINEAR_RT_VULKAN defined first"
#endif

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _WIN32
#ifndef WIN32_LEAN_AND_MEAN
#define WIN32_LEAN_AND_MEAN
#endif
#include <windows.h>
#else
#include <dlfcn.h>
#endif

#if defined(__GNUC__) || defined(__clang__)
#define LRT_VKU_FN static __attribute__((unused)) /* a file uses only some */
#else
#define LRT_VKU_FN static
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---- the device: instance, device, queue ---------------------------------------- */
enum {
    /* lrt_vku_device_create flags: the Khronos validation layer and a
       VK_EXT_debug_utils messenger that prints each warning and error to
       stderr and counts it in lrt_vku_device.message_count */
    LRT_VKU_DEVICE_VALIDATION = 1u,
    /* the same with the layer's synchronization validation on (missing or
       wrong barriers; VK_EXT_validation_features) */
    LRT_VKU_DEVICE_SYNC_VALIDATION = 2u
};

typedef struct lrt_vku_device {  /* fields are read-only to callers */
    lrt_vk_context_desc desc;      /* ready for lrt_vk_context_create */
    VkQueue queue;                 /* one queue with compute */
    uint32_t queue_family;
    uint32_t timestamp_valid_bits; /* of that family; 0: no timestamps */
    VkPhysicalDeviceProperties properties;
    uint32_t message_count;        /* validation warnings and errors seen (LRT_VKU_DEVICE_VALIDATION),
                                      those of destroy included: still readable after it */
    VkResult vk_result;            /* the failing call's VkResult when create returned LRT_ERROR_VULKAN */
    /* private */
    void *loader;
    VkDebugUtilsMessengerEXT messenger;
} lrt_vku_device;

/* Opens the Vulkan loader (libvulkan.so.1, vulkan-1.dll, libvulkan.1.dylib:
   nothing is linked) and its vkGetInstanceProcAddr; NULL if there is none.
   lrt_vku_close_loader closes it. */
LRT_VKU_FN void *lrt_vku_open_loader(PFN_vkGetInstanceProcAddr *gipa)
{
    void *lib = NULL, *sym = NULL;
#if defined(_WIN32)
    HMODULE m = LoadLibraryA("vulkan-1.dll");
    FARPROC p = m ? GetProcAddress(m, "vkGetInstanceProcAddr") : NULL;
    lib = (void *)m;
    memcpy(&sym, &p, sizeof sym < sizeof p ? sizeof sym : sizeof p);
#else
    static const char *const names[] = {
#if defined(__APPLE__)
        "libvulkan.1.dylib", "libvulkan.dylib", "libMoltenVK.dylib"
#else
        "libvulkan.so.1", "libvulkan.so"
#endif
    };
    size_t i;
    for (i = 0; i < sizeof names / sizeof names[0] && !lib; ++i) lib = dlopen(names[i], RTLD_NOW | RTLD_LOCAL);
    if (lib) sym = dlsym(lib, "vkGetInstanceProcAddr");
#endif
    if (lib && !sym) {
#if defined(_WIN32)
        FreeLibrary((HMODULE)lib);
#else
        dlclose(lib);
#endif
        lib = NULL;
    }
    /* an object pointer to a function pointer without a cast ISO C forbids */
    if (lib) memcpy(gipa, &sym, sizeof *gipa);
    return lib;
}

LRT_VKU_FN void lrt_vku_close_loader(void *lib)
{
    if (!lib) return;
#if defined(_WIN32)
    FreeLibrary((HMODULE)lib);
#else
    dlclose(lib);
#endif
}

LRT_VKU_FN VKAPI_ATTR VkBool32 VKAPI_CALL lrt_vku__on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                              VkDebugUtilsMessageTypeFlagsEXT types,
                                                              const VkDebugUtilsMessengerCallbackDataEXT *data, void *user)
{
    lrt_vku_device *d = (lrt_vku_device *)user;
    (void)types;
    ++d->message_count;
    (void)fprintf(stderr, "linear_rt: vulkan %s: %s\n",
                  severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning",
                  data && data->pMessage ? data->pMessage : "(no message)");
    return VK_FALSE;
}

/* The chain features 2 -> 1.1 -> 1.2, every feature off. */
LRT_VKU_FN void lrt_vku__feature_chain(VkPhysicalDeviceFeatures2 *f, VkPhysicalDeviceVulkan11Features *f11,
                                       VkPhysicalDeviceVulkan12Features *f12)
{
    memset(f, 0, sizeof *f);
    f->sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    f->pNext = f11;
    memset(f11, 0, sizeof *f11);
    f11->sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES;
    f11->pNext = f12;
    memset(f12, 0, sizeof *f12);
    f12->sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
}

/* A debug messenger's create info: every warning and error of the
   validation layer (general, validation, performance) to fn(..., user). */
LRT_VKU_FN void lrt_vku_messenger_info(VkDebugUtilsMessengerCreateInfoEXT *mi, PFN_vkDebugUtilsMessengerCallbackEXT fn,
                                       void *user)
{
    memset(mi, 0, sizeof *mi);
    mi->sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    mi->messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    mi->messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                      VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    mi->pfnUserCallback = fn;
    mi->pUserData = user;
}

/* Is every feature the kernels need there? Fills the chain on .. on12 to
   enable them. */
LRT_VKU_FN int lrt_vku__device_features(PFN_vkGetPhysicalDeviceFeatures2 get, VkPhysicalDevice pd,
                                        const lrt_vk_requirements *req, VkPhysicalDeviceFeatures2 *on,
                                        VkPhysicalDeviceVulkan11Features *on11, VkPhysicalDeviceVulkan12Features *on12)
{
    VkPhysicalDeviceFeatures2 f;
    VkPhysicalDeviceVulkan11Features f11;
    VkPhysicalDeviceVulkan12Features f12;
    lrt_vku__feature_chain(&f, &f11, &f12);
    get(pd, &f);
    lrt_vku__feature_chain(on, on11, on12);
#define LRT_VKU__WANT(want, have, set)                                                                           \
    if (want) {                                                                                                   \
        if (!(have)) return 0;                                                                                    \
        (set) = VK_TRUE;                                                                                          \
    }
    LRT_VKU__WANT(req->shader_float64, f.features.shaderFloat64, on->features.shaderFloat64)
    LRT_VKU__WANT(req->shader_int64, f.features.shaderInt64, on->features.shaderInt64)
    LRT_VKU__WANT(req->shader_int16, f.features.shaderInt16, on->features.shaderInt16)
    LRT_VKU__WANT(req->storage_buffer_16bit_access, f11.storageBuffer16BitAccess, on11->storageBuffer16BitAccess)
    LRT_VKU__WANT(req->shader_int8, f12.shaderInt8, on12->shaderInt8)
    LRT_VKU__WANT(req->shader_float16, f12.shaderFloat16, on12->shaderFloat16)
    LRT_VKU__WANT(req->storage_buffer_8bit_access, f12.storageBuffer8BitAccess, on12->storageBuffer8BitAccess)
    LRT_VKU__WANT(req->shader_buffer_int64_atomics, f12.shaderBufferInt64Atomics, on12->shaderBufferInt64Atomics)
    LRT_VKU__WANT(req->vulkan_memory_model, f12.vulkanMemoryModel, on12->vulkanMemoryModel)
    LRT_VKU__WANT(req->vulkan_memory_model_device_scope, f12.vulkanMemoryModelDeviceScope,
                  on12->vulkanMemoryModelDeviceScope)
#undef LRT_VKU__WANT
    return 1;
}

/* Destroys whatever of a device exists; leaves it zeroed. */
LRT_VKU_FN void lrt_vku__device_teardown(lrt_vku_device *d, PFN_vkGetInstanceProcAddr gipa)
{
    VkInstance inst = d->desc.instance;
    if (gipa && inst != VK_NULL_HANDLE) {
        if (d->desc.device != VK_NULL_HANDLE) {
            PFN_vkGetDeviceProcAddr gdpa = (PFN_vkGetDeviceProcAddr)gipa(inst, "vkGetDeviceProcAddr");
            PFN_vkDeviceWaitIdle wait = gdpa ? (PFN_vkDeviceWaitIdle)gdpa(d->desc.device, "vkDeviceWaitIdle") : NULL;
            PFN_vkDestroyDevice destroy = gdpa ? (PFN_vkDestroyDevice)gdpa(d->desc.device, "vkDestroyDevice") : NULL;
            if (wait) wait(d->desc.device);
            if (destroy) destroy(d->desc.device, NULL);
        }
        if (d->messenger != VK_NULL_HANDLE) {
            PFN_vkDestroyDebugUtilsMessengerEXT destroy =
                (PFN_vkDestroyDebugUtilsMessengerEXT)gipa(inst, "vkDestroyDebugUtilsMessengerEXT");
            if (destroy) destroy(inst, d->messenger, NULL);
        }
        {
            PFN_vkDestroyInstance destroy = (PFN_vkDestroyInstance)gipa(inst, "vkDestroyInstance");
            if (destroy) destroy(inst, NULL);
        }
    }
    lrt_vku_close_loader(d->loader);
    {   /* the count survives: messages of the destruction count too */
        uint32_t messages = d->message_count;
        memset(d, 0, sizeof *d);
        d->message_count = messages;
    }
}

LRT_VKU_FN int lrt_vku__has_extension(const char *name, const VkExtensionProperties *exts, uint32_t n)
{
    uint32_t i;
    for (i = 0; i < n; ++i)
        if (strcmp(exts[i].extensionName, name) == 0) return 1;
    return 0;
}

/* A VkDevice on pd with one queue of `family` and the extensions exts[0,
   ext_count) and the features chain `features` (a VkPhysicalDeviceFeatures2,
   or NULL) enabled: the device of lrt_vku_device_create, and of programs
   that want another (the tests' device without the library's extension,
   the benchmark's ray-query peers). */
LRT_VKU_FN VkResult lrt_vku_create_vk_device(PFN_vkCreateDevice create, VkPhysicalDevice pd, uint32_t family,
                                             const void *features, const char *const *exts, uint32_t ext_count,
                                             VkDevice *out)
{
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo qi;
    VkDeviceCreateInfo di;
    memset(&qi, 0, sizeof qi);
    qi.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    qi.queueFamilyIndex = family;
    qi.queueCount = 1;
    qi.pQueuePriorities = &priority;
    memset(&di, 0, sizeof di);
    di.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    di.pNext = features;
    di.queueCreateInfoCount = 1;
    di.pQueueCreateInfos = &qi;
    di.enabledExtensionCount = ext_count;
    di.ppEnabledExtensionNames = exts;
    return create(pd, &di, NULL, out);
}

/* Picks the device and its compute queue family; 0 if none will do. */
LRT_VKU_FN int lrt_vku__pick(lrt_vku_device *d, PFN_vkGetInstanceProcAddr gipa, const lrt_vk_requirements *req,
                             VkPhysicalDeviceFeatures2 *on, VkPhysicalDeviceVulkan11Features *on11,
                             VkPhysicalDeviceVulkan12Features *on12, VkResult *vr)
{
    VkInstance inst = d->desc.instance;
    PFN_vkEnumeratePhysicalDevices enumerate = (PFN_vkEnumeratePhysicalDevices)gipa(inst, "vkEnumeratePhysicalDevices");
    PFN_vkGetPhysicalDeviceProperties get_props =
        (PFN_vkGetPhysicalDeviceProperties)gipa(inst, "vkGetPhysicalDeviceProperties");
    PFN_vkGetPhysicalDeviceFeatures2 get_features =
        (PFN_vkGetPhysicalDeviceFeatures2)gipa(inst, "vkGetPhysicalDeviceFeatures2");
    PFN_vkGetPhysicalDeviceQueueFamilyProperties get_families =
        (PFN_vkGetPhysicalDeviceQueueFamilyProperties)gipa(inst, "vkGetPhysicalDeviceQueueFamilyProperties");
    PFN_vkEnumerateDeviceExtensionProperties get_exts =
        (PFN_vkEnumerateDeviceExtensionProperties)gipa(inst, "vkEnumerateDeviceExtensionProperties");
    VkPhysicalDevice devices[16];
    uint32_t n = 16, i;
    *vr = VK_SUCCESS;
    if (!enumerate || !get_props || !get_features || !get_families || !get_exts) return 0;
    *vr = enumerate(inst, &n, devices);
    if (*vr == VK_INCOMPLETE) *vr = VK_SUCCESS; /* the first 16 will do */
    if (*vr != VK_SUCCESS) return 0;
    for (i = 0; i < n; ++i) {
        VkQueueFamilyProperties families[32];
        VkExtensionProperties *exts;
        uint32_t nf = 32, ne = 0, f;
        int ext_ok;
        get_props(devices[i], &d->properties);
        if (d->properties.apiVersion < req->api_version) continue;
        if (get_exts(devices[i], NULL, &ne, NULL) != VK_SUCCESS) continue;
        exts = (VkExtensionProperties *)malloc(sizeof *exts * (ne ? ne : 1));
        if (!exts) continue;
        ext_ok = get_exts(devices[i], NULL, &ne, exts) >= VK_SUCCESS &&
                 lrt_vku__has_extension(req->extensions[0], exts, ne);
        free(exts);
        if (!ext_ok) continue;
        if (!lrt_vku__device_features(get_features, devices[i], req, on, on11, on12)) continue;
        get_families(devices[i], &nf, families);
        for (f = 0; f < nf; ++f) {
            if (families[f].queueFlags & VK_QUEUE_COMPUTE_BIT) {
                d->desc.physical_device = devices[i];
                d->queue_family = f;
                d->timestamp_valid_bits = families[f].timestampValidBits;
                return 1;
            }
        }
    }
    memset(&d->properties, 0, sizeof d->properties);
    return 0;
}

/* Loads the Vulkan loader at run time (libvulkan.so.1, vulkan-1.dll,
   libvulkan.1.dylib: nothing is linked), creates an instance (API 1.2),
   picks the first physical device with Vulkan 1.2, a compute queue,
   VK_KHR_push_descriptor and lrt_vk_get_requirements' features, and creates
   a device with one queue and those enabled. *out must stay where it is
   until destroy (the message callback counts into it). No loader:
   LRT_ERROR_NO_VULKAN_LOADER; no such device: LRT_ERROR_NO_VULKAN_DEVICE;
   validation asked for but absent: LRT_ERROR_MISSING_VULKAN_FEATURE. On
   those and LRT_ERROR_VULKAN, *out is zeroed (but for vk_result) and
   nothing is left created; on a bad argument it is untouched. */
LRT_VKU_FN lrt_result lrt_vku_device_create(lrt_vku_device *out, uint32_t flags)
{
    static const char *const validation_layer = "VK_LAYER_KHRONOS_validation";
    static const char *const validation_exts[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME,
                                                  VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
    const VkValidationFeatureEnableEXT sync = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    const int sync_validate = (flags & LRT_VKU_DEVICE_SYNC_VALIDATION) != 0;
    const int validate = sync_validate || (flags & LRT_VKU_DEVICE_VALIDATION) != 0;
    VkValidationFeaturesEXT vf;
    PFN_vkGetInstanceProcAddr gipa = NULL;
    PFN_vkCreateInstance create_instance;
    PFN_vkCreateDevice create_device;
    PFN_vkGetDeviceQueue get_queue;
    VkApplicationInfo app;
    VkInstanceCreateInfo ii;
    VkDebugUtilsMessengerCreateInfoEXT mi;
    VkPhysicalDeviceFeatures2 on;
    VkPhysicalDeviceVulkan11Features on11;
    VkPhysicalDeviceVulkan12Features on12;
    lrt_vk_requirements req;
    VkResult vr;
    lrt_result r = LRT_SUCCESS;
    if (!out) return LRT_ERROR_NULL_POINTER;
    if (flags & ~(uint32_t)(LRT_VKU_DEVICE_VALIDATION | LRT_VKU_DEVICE_SYNC_VALIDATION)) return LRT_ERROR_INVALID_OPTION;
    memset(out, 0, sizeof *out);
    lrt_vk_get_requirements(&req);
    out->loader = lrt_vku_open_loader(&gipa);
    if (!out->loader) return LRT_ERROR_NO_VULKAN_LOADER;
    create_instance = (PFN_vkCreateInstance)gipa(VK_NULL_HANDLE, "vkCreateInstance");
    if (!create_instance) {
        lrt_vku__device_teardown(out, gipa);
        return LRT_ERROR_NO_VULKAN_LOADER;
    }

    lrt_vku_messenger_info(&mi, lrt_vku__on_message, out);
    if (validate) { /* the layer, and debug utils from anyone (the layer provides it) */
        PFN_vkEnumerateInstanceLayerProperties get_layers =
            (PFN_vkEnumerateInstanceLayerProperties)gipa(VK_NULL_HANDLE, "vkEnumerateInstanceLayerProperties");
        PFN_vkEnumerateInstanceExtensionProperties get_exts =
            (PFN_vkEnumerateInstanceExtensionProperties)gipa(VK_NULL_HANDLE, "vkEnumerateInstanceExtensionProperties");
        VkLayerProperties layers[64];
        VkExtensionProperties exts[256];
        uint32_t nl = 64, ne = 256;
        uint32_t i;
        int found = 0;
        if (get_layers && get_layers(&nl, layers) >= VK_SUCCESS)
            for (i = 0; i < nl; ++i)
                if (strcmp(layers[i].layerName, validation_layer) == 0) found = 1;
        if (found && !(get_exts && get_exts(validation_layer, &ne, exts) >= VK_SUCCESS &&
                       lrt_vku__has_extension(validation_exts[0], exts, ne) &&
                       (!sync_validate || lrt_vku__has_extension(validation_exts[1], exts, ne))))
            found = 0;
        if (!found) {
            lrt_vku__device_teardown(out, gipa);
            return LRT_ERROR_MISSING_VULKAN_FEATURE;
        }
    }
    memset(&app, 0, sizeof app);
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "linear_rt";
    app.pEngineName = "linear_rt";
    app.apiVersion = req.api_version;
    memset(&ii, 0, sizeof ii);
    ii.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ii.pApplicationInfo = &app;
    memset(&vf, 0, sizeof vf);
    vf.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
    vf.enabledValidationFeatureCount = 1;
    vf.pEnabledValidationFeatures = &sync;
    if (validate) {
        ii.pNext = &mi; /* messages of instance creation and destruction too */
        if (sync_validate) {
            ii.pNext = &vf;
            vf.pNext = &mi;
        }
        ii.enabledLayerCount = 1;
        ii.ppEnabledLayerNames = &validation_layer;
        ii.enabledExtensionCount = sync_validate ? 2u : 1u;
        ii.ppEnabledExtensionNames = validation_exts;
    }
    vr = create_instance(&ii, NULL, &out->desc.instance);
    if (vr != VK_SUCCESS) {
        out->desc.instance = VK_NULL_HANDLE;
        lrt_vku__device_teardown(out, gipa);
        /* no driver at all: the loader finds no ICD */
        if (vr == VK_ERROR_INCOMPATIBLE_DRIVER) return LRT_ERROR_NO_VULKAN_DEVICE;
        if (vr == VK_ERROR_LAYER_NOT_PRESENT || vr == VK_ERROR_EXTENSION_NOT_PRESENT)
            return LRT_ERROR_MISSING_VULKAN_FEATURE;
        out->vk_result = vr;
        return LRT_ERROR_VULKAN;
    }
    out->desc.get_instance_proc_addr = gipa;
    out->desc.get_device_proc_addr = (PFN_vkGetDeviceProcAddr)gipa(out->desc.instance, "vkGetDeviceProcAddr");
    if (validate) {
        PFN_vkCreateDebugUtilsMessengerEXT create =
            (PFN_vkCreateDebugUtilsMessengerEXT)gipa(out->desc.instance, "vkCreateDebugUtilsMessengerEXT");
        vr = create ? create(out->desc.instance, &mi, NULL, &out->messenger) : VK_ERROR_EXTENSION_NOT_PRESENT;
        if (vr != VK_SUCCESS) {
            out->messenger = VK_NULL_HANDLE;
            r = LRT_ERROR_VULKAN;
        }
    }
    if (r == LRT_SUCCESS && !lrt_vku__pick(out, gipa, &req, &on, &on11, &on12, &vr))
        r = vr != VK_SUCCESS ? LRT_ERROR_VULKAN : LRT_ERROR_NO_VULKAN_DEVICE;
    create_device = (PFN_vkCreateDevice)gipa(out->desc.instance, "vkCreateDevice");
    if (r == LRT_SUCCESS && (!create_device || !out->desc.get_device_proc_addr)) r = LRT_ERROR_NO_VULKAN_LOADER;
    if (r == LRT_SUCCESS) { /* features 2, 1.1, 1.2: what the kernels need */
        vr = lrt_vku_create_vk_device(create_device, out->desc.physical_device, out->queue_family, &on, req.extensions,
                                      req.extension_count, &out->desc.device);
        if (vr != VK_SUCCESS) {
            out->desc.device = VK_NULL_HANDLE;
            r = LRT_ERROR_VULKAN;
        }
    }
    if (r != LRT_SUCCESS) {
        lrt_vku__device_teardown(out, gipa);
        if (r == LRT_ERROR_VULKAN) out->vk_result = vr;
        return r;
    }
    get_queue = (PFN_vkGetDeviceQueue)out->desc.get_device_proc_addr(out->desc.device, "vkGetDeviceQueue");
    if (get_queue) get_queue(out->desc.device, out->queue_family, 0, &out->queue);
    out->vk_result = VK_SUCCESS;
    return LRT_SUCCESS;
}

/* Waits for the device to idle and destroys device, messenger and instance,
   and unloads the loader. Safe on a zeroed lrt_vku_device. */
LRT_VKU_FN void lrt_vku_device_destroy(lrt_vku_device *device)
{
    if (!device) return;
    lrt_vku__device_teardown(device, device->desc.get_instance_proc_addr);
}

/* ---- around the device: buffers, images, one command buffer, barriers, timestamps --- */
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
    const lrt_vku_device *dev;
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

/* floats in [0,1] -> the bytes of a depth format (unorm: rounded half up,
   which adding 0.5 and truncating is for f >= 0: hence the NOLINTs) */
LRT_VKU_FN void lrt_vku_encode_depth(const float *f, void *out, size_t n, lrt_format format)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        if (format == LRT_FORMAT_UNORM8) ((uint8_t *)out)[i] = (uint8_t)(f[i] * 255.0f + 0.5f); /* NOLINT(bugprone-incorrect-roundings) */
        else if (format == LRT_FORMAT_UNORM16) {
            uint16_t v = (uint16_t)(f[i] * 65535.0f + 0.5f); /* NOLINT(bugprone-incorrect-roundings) */
            memcpy((unsigned char *)out + 2 * i, &v, 2);
        } else memcpy((unsigned char *)out + 4 * i, &f[i], 4);
    }
}

LRT_VKU_FN int lrt_vku_fail(const char *what, VkResult r)
{
    (void)fprintf(stderr, "linear_rt_vk_util: %s failed: VkResult %d\n", what, (int)r);
    return 1;
}

/* Loads the functions, makes the command pool and buffer, the fence and
   (where the queue has timestamps) the query pool. lrt_vku_free undoes it,
   also after a failure half-way. */
LRT_VKU_FN int lrt_vku_init(lrt_vku *t, const lrt_vku_device *dev)
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

/* A global memory barrier recorded through barrier (a program's own
   vkCmdPipelineBarrier: the benchmark's peers keep theirs) */
LRT_VKU_FN void lrt_vku_memory_barrier(PFN_vkCmdPipelineBarrier barrier, VkCommandBuffer cmd, VkPipelineStageFlags src_stage,
                               VkAccessFlags src_access, VkPipelineStageFlags dst_stage, VkAccessFlags dst_access)
{
    VkMemoryBarrier b;
    memset(&b, 0, sizeof b);
    b.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    b.srcAccessMask = src_access;
    b.dstAccessMask = dst_access;
    barrier(cmd, src_stage, dst_stage, 0, 1, &b, 0, NULL, 0, NULL);
}

/* A global memory barrier: what linear_rt.h's BARRIERS asks of its callers. */
LRT_VKU_FN void lrt_vku_barrier(lrt_vku *t, VkPipelineStageFlags src_stage, VkAccessFlags src_access, VkPipelineStageFlags dst_stage,
                        VkAccessFlags dst_access)
{
    lrt_vku_memory_barrier(t->vkCmdPipelineBarrier, t->cmd, src_stage, src_access, dst_stage, dst_access);
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

#ifdef __cplusplus
}
#endif
#endif /* LINEAR_RT_VK_UTIL_H */
