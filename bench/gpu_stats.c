/* bench/gpu_stats.c - what the GPU kernels weigh on AMD GPUs, without one.

   Lavapipe (the CPU driver the tests run on) cannot show what makes a GPU
   kernel slow. Mesa's RADV driver, told RADV_FORCE_FAMILY=<chip>, makes a
   Vulkan device on null hardware: nothing can be dispatched there, but
   pipelines compile with AMD's production compiler (ACO), and
   VK_KHR_pipeline_executable_properties reads back their weight. This
   program does that for RDNA3 (navi31), RDNA2 (navi21) and GCN (vega10),
   one process each (the chip is read from the environment), and prints one
   table per GPU: every compute pipeline of lrt_vk_context_create, then the
   benchmark's Vulkan peers (bench/shaders, as bench/m_vk_peers.c compiles
   them). The tables go to stdout and to a markdown file (--out, default
   build/gpu-stats.md).

   The library's pipelines are the library's own: lrt_vk_context_create
   runs on the RADV device, given a vkGetDeviceProcAddr that hands it a
   wrapped vkCreateShaderModule (which records which of shaders_spv.h's
   four kernels each module is, and which float-control modes the library
   patched into it) and a wrapped vkCreateComputePipelines (which adds
   VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR, and records each
   pipeline with its specialization constants). Nothing is copied from the
   library: its SPIR-V, its patching, its specialization and its device
   checks are what compile. Each row is named from what was recorded, not
   from an assumed order; a module that is not one of the four kernels, or
   a count other than 30, fails the run.

   Exit status: 0 tables written; 77 no RADV here (no loader, no
   radeon_icd.json, no RADV device): one line says so (1 under CI=true);
   1 something failed (a GPU without figures for the library's trace
   pipeline among them).

   Options: --gpu NAME (one of navi31 navi21 vega10, or another family RADV
   knows; repeatable), --out FILE, --all (every statistic of every
   pipeline, to stderr), --quick (the test's: of the library's pipelines
   only the plain trace one compiles, every one is still made and
   identified; no bench peers), --weights FILE (each pipeline's loops as tab-separated
   values: the benchmark's estimate reads them). GPU_STATS_RADV_ICD: another
   radeon_icd.json; GS_ISA=FILE: every disassembly appended there. */
#define _POSIX_C_SOURCE 200809L
#ifndef LINEAR_RT_VULKAN
#define LINEAR_RT_VULKAN
#endif
#ifndef VK_NO_PROTOTYPES
#define VK_NO_PROTOTYPES
#endif
#define LINEAR_RT_IMPLEMENTATION
#include "../linear_rt.h"
#include "../linear_rt_vk_util.h" /* the loader, a device with one queue */

#ifdef GPU_STATS_HAVE_PEERS
#include "bench_vk_spv.h" /* vkp_spv_<kernel>: bench/shaders/vkp_<kernel>.comp, as make bench compiles them */
#endif

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#define GS_DEFAULT_ICD "/usr/share/vulkan/icd.d/radeon_icd.json"
#define GS_SKIP 77

static const char *const gs_default_gpus[][2] = {{"navi31", "RDNA3"}, {"navi21", "RDNA2"}, {"vega10", "GCN"}};
enum { GS_DEFAULT_GPUS = 3 };

/* ---- the statistics ----------------------------------------------------------- */

/* The columns: RADV's statistic names (ACO's for the first and the branches). */
enum { GS_INSTR, GS_CODE, GS_VGPR, GS_SGPR, GS_VSPILL, GS_SSPILL, GS_BRANCH, GS_WAVES, GS_COLS };
static const char *const gs_stat_names[GS_COLS] = {"Instructions",  "Code size",     "VGPRs",    "SGPRs",
                                                   "Spilled VGPRs", "Spilled SGPRs", "Branches", "Subgroups per SIMD"};

typedef struct gs_row {
    char name[64];
    char why[200]; /* empty: figures below */
    int left_out;  /* --quick */
    int has[GS_COLS];
    unsigned long long v[GS_COLS];
    /* from the compiled code (gs_loops): static instructions of the whole
       program, of its outermost loop's body and of the largest loop inside
       that one (0: none); loads: the memory instructions (buffer, global,
       image, scalar memory) in the outermost loop's body, and of them those
       in the inner loop */
    int has_isa;
    unsigned isa_total, isa_outer, isa_inner, loads_outer, loads_inner;
    unsigned isa_skippable; /* of the outer loop's body: what a wave skips when no lane needs it (the blocks
                               s_cbranch_execz jumps over, outermost ones, the inner loop's aside) */
    unsigned isa_exit;      /* of those, the blocks that store a result (the innermost skipped block around
                               each store): a lane runs them once, as it leaves */
    unsigned isa_aside;     /* the largest loading loop outside the outermost one (a budget's finish: its
                               march after the walk), its body; 0: none */
} gs_row;

enum { GS_MAX_ROWS = 64 };
static gs_row gs_rows[GS_MAX_ROWS];
static int gs_rows_lost; /* a row past GS_MAX_ROWS: the run fails */
static int gs_row_count;
static int gs_all; /* --all: every statistic, to stderr */

typedef struct gs_vk {
    void *lib;
    PFN_vkGetInstanceProcAddr gipa;
    VkInstance instance;
    VkPhysicalDevice pd;
    char device_name[VK_MAX_PHYSICAL_DEVICE_NAME_SIZE];
    char driver_info[VK_MAX_DRIVER_NAME_SIZE + VK_MAX_DRIVER_INFO_SIZE + 2];
    int has_rt; /* acceleration structures and ray queries */
} gs_vk;

static gs_row *gs_new_row(const char *name)
{
    gs_row *r;
    if (gs_row_count == GS_MAX_ROWS) {
        ++gs_rows_lost;
        return NULL;
    }
    r = &gs_rows[gs_row_count++];
    memset(r, 0, sizeof *r);
    snprintf(r->name, sizeof r->name, "%s", name);
    return r;
}

static const char *gs_vk_result(VkResult r)
{
    switch (r) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_UNKNOWN: return "VK_ERROR_UNKNOWN";
    default: return "a VkResult";
    }
}

/* Reads the statistics of pipeline's one executable into row. */
/* The loops of a disassembly (RADV's "Assembly" representation: one
   instruction a line, "BB<n>:" labels, branches naming their target): the
   outermost loop runs from its head to the last branch back to it, the
   largest loop inside it likewise. Labels do not count; scheduling hints
   (s_delay_alu, s_waitcnt...) do, as the hardware issues them. A step of a
   walk is one trip round the outer loop: its body is the step's weight. */
static int gs_is_label(const char *line, size_t len)
{
    size_t k = 0;
    while (k < len && (line[k] == ' ' || line[k] == '\t')) ++k;
    if (len - k < 4 || strncmp(line + k, "BB", 2) != 0) return 0;
    for (k += 2; k < len && line[k] >= '0' && line[k] <= '9'; ++k) {}
    return k < len && line[k] == ':';
}

static int gs_is_load(const char *line, size_t len)
{
    static const char *const ops[] = {"buffer_load", "global_load", "image_load", "image_sample", "s_load",
                                      "s_buffer_load", "flat_load", "tbuffer_load", "buffer_atomic", "global_atomic"};
    size_t k, o;
    for (o = 0; o < sizeof ops / sizeof ops[0]; ++o) {
        const size_t n = strlen(ops[o]);
        for (k = 0; k + n <= len; ++k)
            if (strncmp(line + k, ops[o], n) == 0) return 1;
    }
    return 0;
}

/* an instruction: neither blank nor a label */
static int gs_is_instruction(const char *line, size_t len)
{
    size_t q;
    for (q = 0; q < len; ++q)
        if (line[q] != ' ' && line[q] != '\t' && line[q] != '\r') return !gs_is_label(line, len);
    return 0;
}

/* the line of the label an s_cbranch_execz on this line jumps to, or -1 */
static int gs_execz_target(const char *line, size_t len, const int *label_line)
{
    const char *b = strstr(line, "s_cbranch_execz");
    int id;
    if (!b || (size_t)(b - line) > len || !(b = strstr(b, "BB")) || (size_t)(b - line) > len) return -1;
    id = atoi(b + 2);
    return id >= 0 && id < 4096 ? label_line[id] : -1;
}

static void gs_loops(const char *text, gs_row *row)
{
    enum { MAX_LINES = 20000 };
    static const char *line[MAX_LINES];
    static size_t len[MAX_LINES];
    static int label_line[4096];
    size_t n = 0, k;
    int heads_a[512], heads_b[512], nheads = 0, h, outer = -1, inner = -1, aside = -1;
    const char *p = text;
    memset(label_line, -1, sizeof label_line);
    while (*p && n < MAX_LINES) {
        const char *e = strchr(p, '\n');
        size_t l = e ? (size_t)(e - p) : strlen(p);
        line[n] = p;
        len[n] = l;
        if (gs_is_label(p, l)) {
            const char *b = strstr(p, "BB");
            int id = atoi(b + 2);
            if (id >= 0 && id < 4096) label_line[id] = (int)n;
        }
        ++n;
        p = e ? e + 1 : p + l;
    }
    for (k = 0; k < n; ++k) { /* branches back: loops */
        const char *b = NULL;
        size_t q;
        for (q = 0; q + 3 < len[k]; ++q)
            if (line[k][q] == 'B' && line[k][q + 1] == 'B' && line[k][q + 2] >= '0' && line[k][q + 2] <= '9') b = line[k] + q;
        if (!b || gs_is_label(line[k], len[k]) || !strstr(line[k], "branch")) continue;
        {
            const int id = atoi(b + 2), a = id >= 0 && id < 4096 ? label_line[id] : -1;
            if (a < 0 || a >= (int)k) continue;
            for (h = 0; h < nheads && heads_a[h] != a; ++h) {}
            if (h == nheads && nheads < 512) heads_a[nheads++] = a, heads_b[h] = (int)k;
            else if (h < nheads && heads_b[h] < (int)k) heads_b[h] = (int)k;
        }
    }
    /* a walk reads memory every step: the outer loop is the largest that loads (a
       loop without, such as the rare set-up's rescaling, is not a walk), the inner
       the largest loading loop inside it */
    for (h = 0; h < nheads; ++h) {
        int loads = 0;
        for (k = (size_t)heads_a[h]; (int)k <= heads_b[h] && !loads; ++k) loads = gs_is_load(line[k], len[k]);
        if (!loads) heads_b[h] = heads_a[h] - 1; /* out of the running */
    }
    for (h = 0; h < nheads; ++h)
        if (heads_b[h] >= heads_a[h] && (outer < 0 || heads_b[h] - heads_a[h] > heads_b[outer] - heads_a[outer])) outer = h;
    for (h = 0; outer >= 0 && h < nheads; ++h)
        if (h != outer && heads_b[h] >= heads_a[h] && heads_a[h] > heads_a[outer] && heads_b[h] < heads_b[outer] &&
            (inner < 0 || heads_b[h] - heads_a[h] > heads_b[inner] - heads_a[inner]))
            inner = h;
    for (h = 0; outer >= 0 && h < nheads; ++h) /* beside the walk: before or after its loop */
        if (h != outer && heads_b[h] >= heads_a[h] && (heads_a[h] > heads_b[outer] || heads_b[h] < heads_a[outer]) &&
            (aside < 0 || heads_b[h] - heads_a[h] > heads_b[aside] - heads_a[aside]))
            aside = h;
    row->isa_total = row->isa_outer = row->isa_inner = row->loads_outer = row->loads_inner = row->isa_skippable = 0;
    row->isa_exit = row->isa_aside = 0;
    if (outer >= 0) { /* the exits: the innermost execz-skipped block around each store in the loop */
        int ra[256], rb[256], nr = 0, used[256], r2;
        for (k = (size_t)heads_a[outer]; (int)k <= heads_b[outer] && nr < 256; ++k) {
            const int a = gs_execz_target(line[k], len[k], label_line);
            if (a > (int)k && a <= heads_b[outer]) ra[nr] = (int)k, rb[nr] = a, used[nr++] = 0;
        }
        for (k = (size_t)heads_a[outer]; (int)k <= heads_b[outer]; ++k) {
            const char *st = strstr(line[k], "_store");
            int best = -1;
            if (!st || (size_t)(st - line[k]) > len[k]) continue;
            for (r2 = 0; r2 < nr; ++r2)
                if (ra[r2] < (int)k && (int)k < rb[r2] && (best < 0 || rb[r2] - ra[r2] < rb[best] - ra[best])) best = r2;
            if (best >= 0) used[best] = 1;
        }
        for (r2 = 0; r2 < nr; ++r2) {
            size_t q2;
            if (!used[r2]) continue;
            for (q2 = (size_t)ra[r2] + 1; (int)q2 < rb[r2]; ++q2) row->isa_exit += (unsigned)gs_is_instruction(line[q2], len[q2]);
        }
    }
    if (outer >= 0) { /* forward s_cbranch_execz inside the outer loop body: the blocks it skips */
        int skip_to = -1;
        for (k = (size_t)heads_a[outer]; (int)k <= heads_b[outer]; ++k) {
            int a;
            if ((int)k < skip_to) {
                if (gs_is_instruction(line[k], len[k]) && !(inner >= 0 && (int)k >= heads_a[inner] && (int)k <= heads_b[inner]))
                    ++row->isa_skippable;
                continue;
            }
            a = gs_execz_target(line[k], len[k], label_line);
            if (a > (int)k && a <= heads_b[outer]) skip_to = a;
        }
    }
    for (k = 0; k < n; ++k) {
        int in_outer, in_inner;
        if (!gs_is_instruction(line[k], len[k])) continue;
        in_outer = outer >= 0 && (int)k >= heads_a[outer] && (int)k <= heads_b[outer];
        in_inner = inner >= 0 && (int)k >= heads_a[inner] && (int)k <= heads_b[inner];
        ++row->isa_total;
        row->isa_aside += (unsigned)(aside >= 0 && (int)k >= heads_a[aside] && (int)k <= heads_b[aside]);
        row->isa_outer += (unsigned)in_outer;
        row->isa_inner += (unsigned)in_inner;
        if (gs_is_load(line[k], len[k])) {
            row->loads_outer += (unsigned)in_outer;
            row->loads_inner += (unsigned)in_inner;
        }
    }
    row->has_isa = 1;
}

/* The disassembly of a pipeline made with CAPTURE_INTERNAL_REPRESENTATIONS:
   its loops into row (gs_loops); GS_ISA=FILE appends every text there. */
static void gs_read_isa(VkDevice dev, PFN_vkGetDeviceProcAddr gdpa, const VkPipelineExecutableInfoKHR *ei, gs_row *row)
{
    PFN_vkGetPipelineExecutableInternalRepresentationsKHR get_ir =
        (PFN_vkGetPipelineExecutableInternalRepresentationsKHR)gdpa(dev, "vkGetPipelineExecutableInternalRepresentationsKHR");
    VkPipelineExecutableInternalRepresentationKHR *ir;
    uint32_t n = 0, i;
    if (!get_ir || get_ir(dev, ei, &n, NULL) != VK_SUCCESS || n == 0) return;
    ir = (VkPipelineExecutableInternalRepresentationKHR *)calloc(n, sizeof *ir);
    if (!ir) return;
    for (i = 0; i < n; ++i) ir[i].sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INTERNAL_REPRESENTATION_KHR;
    if (get_ir(dev, ei, &n, ir) >= VK_SUCCESS) {
        for (i = 0; i < n; ++i) { /* sizes first, then the texts */
            if (ir[i].isText && ir[i].dataSize) ir[i].pData = calloc(1, ir[i].dataSize + 1);
        }
        if (get_ir(dev, ei, &n, ir) >= VK_SUCCESS)
            for (i = 0; i < n; ++i) {
                const char *isa_file = getenv("GS_ISA");
                if (!ir[i].pData) continue;
                if (isa_file && *isa_file) {
                    FILE *f = fopen(isa_file, "a");
                    if (f) {
                        fprintf(f, "==== %s: %s\n%s\n", row->name, ir[i].name, (const char *)ir[i].pData);
                        fclose(f);
                    }
                }
                if (strcmp(ir[i].name, "Assembly") == 0) gs_loops((const char *)ir[i].pData, row);
            }
    }
    for (i = 0; i < n; ++i) free(ir[i].pData);
    free(ir);
}

static void gs_read_stats(VkDevice dev, PFN_vkGetDeviceProcAddr gdpa, VkPipeline pipeline, gs_row *row)
{
    PFN_vkGetPipelineExecutablePropertiesKHR get_exes =
        (PFN_vkGetPipelineExecutablePropertiesKHR)gdpa(dev, "vkGetPipelineExecutablePropertiesKHR");
    PFN_vkGetPipelineExecutableStatisticsKHR get_stats =
        (PFN_vkGetPipelineExecutableStatisticsKHR)gdpa(dev, "vkGetPipelineExecutableStatisticsKHR");
    VkPipelineInfoKHR pi;
    VkPipelineExecutableInfoKHR ei;
    VkPipelineExecutableStatisticKHR *st;
    uint32_t ne = 0, ns = 0, i, c;
    VkResult r;
    if (!get_exes || !get_stats) {
        snprintf(row->why, sizeof row->why, "no vkGetPipelineExecutableStatisticsKHR");
        return;
    }
    memset(&pi, 0, sizeof pi);
    pi.sType = VK_STRUCTURE_TYPE_PIPELINE_INFO_KHR;
    pi.pipeline = pipeline;
    if ((r = get_exes(dev, &pi, &ne, NULL)) != VK_SUCCESS || ne < 1) {
        snprintf(row->why, sizeof row->why, "no executable (%s)", gs_vk_result(r));
        return;
    }
    memset(&ei, 0, sizeof ei);
    ei.sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR;
    ei.pipeline = pipeline;
    ei.executableIndex = 0; /* a compute pipeline has one */
    if ((r = get_stats(dev, &ei, &ns, NULL)) != VK_SUCCESS || ns == 0) {
        snprintf(row->why, sizeof row->why, "no statistics (%s)", gs_vk_result(r));
        return;
    }
    st = (VkPipelineExecutableStatisticKHR *)calloc(ns, sizeof *st);
    if (!st) {
        snprintf(row->why, sizeof row->why, "out of memory");
        return;
    }
    for (i = 0; i < ns; ++i) st[i].sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR;
    if ((r = get_stats(dev, &ei, &ns, st)) < VK_SUCCESS) {
        snprintf(row->why, sizeof row->why, "no statistics (%s)", gs_vk_result(r));
        free(st);
        return;
    }
    for (i = 0; i < ns; ++i) {
        unsigned long long v = 0;
        switch (st[i].format) {
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR: v = st[i].value.b32; break;
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR:
            v = st[i].value.i64 < 0 ? 0 : (unsigned long long)st[i].value.i64;
            break;
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR: v = (unsigned long long)st[i].value.u64; break;
        default: v = (unsigned long long)(st[i].value.f64 + 0.5); break;
        }
        if (gs_all) fprintf(stderr, "  %-28s %-26s %llu\n", row->name, st[i].name, v);
        for (c = 0; c < GS_COLS; ++c)
            if (!row->has[c] && strcmp(st[i].name, gs_stat_names[c]) == 0) {
                row->has[c] = 1;
                row->v[c] = v;
            }
    }
    free(st);
    gs_read_isa(dev, gdpa, &ei, row);
}

/* ---- the RADV device ------------------------------------------------------- */

/* Opens the loader, an instance and RADV's physical device; GS_SKIP: no RADV. */
static int gs_open(gs_vk *g)
{
    PFN_vkCreateInstance create_instance;
    PFN_vkEnumeratePhysicalDevices enumerate;
    PFN_vkGetPhysicalDeviceProperties2 get_props;
    PFN_vkEnumerateDeviceExtensionProperties get_exts;
    VkApplicationInfo app;
    VkInstanceCreateInfo ii;
    VkPhysicalDevice pds[16];
    uint32_t n = 16, i;
    VkResult r;
    memset(g, 0, sizeof *g);
    if (!(g->lib = lrt_vku_open_loader(&g->gipa))) {
        printf("no Vulkan loader (libvulkan.so.1)\n");
        return GS_SKIP;
    }
    create_instance = (PFN_vkCreateInstance)g->gipa(VK_NULL_HANDLE, "vkCreateInstance");
    if (!create_instance) return GS_SKIP;
    memset(&app, 0, sizeof app);
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "linear_rt gpu_stats";
    app.apiVersion = VK_API_VERSION_1_2;
    memset(&ii, 0, sizeof ii);
    ii.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ii.pApplicationInfo = &app;
    if ((r = create_instance(&ii, NULL, &g->instance)) != VK_SUCCESS) {
        g->instance = VK_NULL_HANDLE;
        printf("vkCreateInstance: %s (no RADV driver?)\n", gs_vk_result(r));
        return r == VK_ERROR_INCOMPATIBLE_DRIVER ? GS_SKIP : 1;
    }
    enumerate = (PFN_vkEnumeratePhysicalDevices)g->gipa(g->instance, "vkEnumeratePhysicalDevices");
    get_props = (PFN_vkGetPhysicalDeviceProperties2)g->gipa(g->instance, "vkGetPhysicalDeviceProperties2");
    get_exts = (PFN_vkEnumerateDeviceExtensionProperties)g->gipa(g->instance, "vkEnumerateDeviceExtensionProperties");
    if (!enumerate || !get_props || !get_exts) return 1;
    r = enumerate(g->instance, &n, pds);
    if (r < VK_SUCCESS) n = 0;
    for (i = 0; i < n; ++i) {
        VkPhysicalDeviceProperties2 p;
        VkPhysicalDeviceDriverProperties dp;
        VkExtensionProperties *exts;
        uint32_t ne = 0, k;
        int pep = 0, push = 0, as = 0, rq = 0, dho = 0;
        memset(&p, 0, sizeof p);
        memset(&dp, 0, sizeof dp);
        p.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
        dp.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES;
        p.pNext = &dp;
        get_props(pds[i], &p);
        if (dp.driverID != VK_DRIVER_ID_MESA_RADV) continue;
        if (get_exts(pds[i], NULL, &ne, NULL) != VK_SUCCESS) continue;
        exts = (VkExtensionProperties *)calloc(ne ? ne : 1, sizeof *exts);
        if (!exts) return 1;
        if (get_exts(pds[i], NULL, &ne, exts) < VK_SUCCESS) ne = 0;
        for (k = 0; k < ne; ++k) {
            const char *e = exts[k].extensionName;
            pep |= strcmp(e, VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME) == 0;
            push |= strcmp(e, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME) == 0;
            as |= strcmp(e, VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME) == 0;
            rq |= strcmp(e, VK_KHR_RAY_QUERY_EXTENSION_NAME) == 0;
            dho |= strcmp(e, VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME) == 0;
        }
        free(exts);
        if (!pep || !push) {
            printf("%s: no %s\n", p.properties.deviceName,
                   pep ? VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME : VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME);
            return 1;
        }
        g->pd = pds[i];
        g->has_rt = as && rq && dho;
        snprintf(g->device_name, sizeof g->device_name, "%s", p.properties.deviceName);
        snprintf(g->driver_info, sizeof g->driver_info, "%s %s", dp.driverName, dp.driverInfo);
        return 0;
    }
    printf("%s: no RADV device (no RADV, or not a chip this Mesa knows)\n", getenv("RADV_FORCE_FAMILY"));
    return GS_SKIP;
}

static void gs_close(gs_vk *g)
{
    if (g->instance != VK_NULL_HANDLE) {
        PFN_vkDestroyInstance destroy = (PFN_vkDestroyInstance)g->gipa(g->instance, "vkDestroyInstance");
        if (destroy) destroy(g->instance, NULL);
    }
    lrt_vku_close_loader(g->lib);
    memset(g, 0, sizeof *g);
}

enum { GS_DEVICE_LIBRARY, GS_DEVICE_PEERS, GS_DEVICE_RAY_QUERY };

/* A device as its user makes it, with pipelineExecutableInfo on as well:
   the library's (lrt_vk_get_requirements: its features and extension, as
   lrt_vku_device_create enables them), the peers' (no feature, as
   bench/m_vk_peers.c), the ray-query peers' (bufferDeviceAddress,
   accelerationStructure, rayQuery and their three extensions, as it). */
static VkResult gs_device(const gs_vk *g, int kind, VkDevice *out, char *why, size_t n)
{
    PFN_vkGetPhysicalDeviceFeatures2 get_features =
        (PFN_vkGetPhysicalDeviceFeatures2)g->gipa(g->instance, "vkGetPhysicalDeviceFeatures2");
    PFN_vkCreateDevice create = (PFN_vkCreateDevice)g->gipa(g->instance, "vkCreateDevice");
    PFN_vkGetPhysicalDeviceQueueFamilyProperties get_families =
        (PFN_vkGetPhysicalDeviceQueueFamilyProperties)g->gipa(g->instance, "vkGetPhysicalDeviceQueueFamilyProperties");
    VkPhysicalDeviceFeatures2 f, on;
    VkPhysicalDeviceVulkan11Features f11, on11;
    VkPhysicalDeviceVulkan12Features f12, on12;
    VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR pep;
    VkPhysicalDeviceAccelerationStructureFeaturesKHR fas;
    VkPhysicalDeviceRayQueryFeaturesKHR frq;
    VkQueueFamilyProperties fams[32];
    const char *exts[4];
    uint32_t ne = 0, nf = 32, fam;
    lrt_vk_requirements req;
    VkResult r;
    if (!get_features || !create || !get_families) return VK_ERROR_INITIALIZATION_FAILED;
    memset(&f, 0, sizeof f);
    memset(&f11, 0, sizeof f11);
    memset(&f12, 0, sizeof f12);
    memset(&on, 0, sizeof on);
    memset(&on11, 0, sizeof on11);
    memset(&on12, 0, sizeof on12);
    memset(&pep, 0, sizeof pep);
    memset(&fas, 0, sizeof fas);
    memset(&frq, 0, sizeof frq);
    f.sType = on.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    f11.sType = on11.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES;
    f12.sType = on12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
    pep.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR;
    fas.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR;
    frq.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR;
    f.pNext = &f11;
    f11.pNext = &f12;
    get_features(g->pd, &f);
    on.pNext = &on11;
    on11.pNext = &on12;
    on12.pNext = &pep;
    pep.pipelineExecutableInfo = VK_TRUE;
    exts[ne++] = VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME;
    if (kind == GS_DEVICE_LIBRARY) {
        lrt_vk_get_requirements(&req);
#define GS_WANT(want, have, set)                                                                                 \
    if (want) {                                                                                                   \
        if (!(have)) {                                                                                            \
            snprintf(why, n, "no %s", #have);                                                                     \
            return VK_ERROR_FEATURE_NOT_PRESENT;                                                                  \
        }                                                                                                         \
        (set) = VK_TRUE;                                                                                          \
    }
        GS_WANT(req.shader_float64, f.features.shaderFloat64, on.features.shaderFloat64)
        GS_WANT(req.shader_int64, f.features.shaderInt64, on.features.shaderInt64)
        GS_WANT(req.shader_int16, f.features.shaderInt16, on.features.shaderInt16)
        GS_WANT(req.storage_buffer_16bit_access, f11.storageBuffer16BitAccess, on11.storageBuffer16BitAccess)
        GS_WANT(req.shader_int8, f12.shaderInt8, on12.shaderInt8)
        GS_WANT(req.shader_float16, f12.shaderFloat16, on12.shaderFloat16)
        GS_WANT(req.storage_buffer_8bit_access, f12.storageBuffer8BitAccess, on12.storageBuffer8BitAccess)
        GS_WANT(req.shader_buffer_int64_atomics, f12.shaderBufferInt64Atomics, on12.shaderBufferInt64Atomics)
        GS_WANT(req.vulkan_memory_model, f12.vulkanMemoryModel, on12.vulkanMemoryModel)
        GS_WANT(req.vulkan_memory_model_device_scope, f12.vulkanMemoryModelDeviceScope,
                on12.vulkanMemoryModelDeviceScope)
#undef GS_WANT
        exts[ne++] = req.extensions[0]; /* VK_KHR_push_descriptor */
    } else if (kind == GS_DEVICE_RAY_QUERY) {
        on12.bufferDeviceAddress = VK_TRUE;
        fas.accelerationStructure = VK_TRUE;
        frq.rayQuery = VK_TRUE;
        pep.pNext = &fas;
        fas.pNext = &frq;
        exts[ne++] = VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME;
        exts[ne++] = VK_KHR_RAY_QUERY_EXTENSION_NAME;
        exts[ne++] = VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME;
    }
    get_families(g->pd, &nf, fams);
    for (fam = 0; fam < nf && !(fams[fam].queueFlags & VK_QUEUE_COMPUTE_BIT); ++fam) {
    }
    if (fam == nf) {
        snprintf(why, n, "no compute queue");
        return VK_ERROR_FEATURE_NOT_PRESENT;
    }
    if ((r = lrt_vku_create_vk_device(create, g->pd, fam, &on, exts, ne, out)) != VK_SUCCESS) {
        *out = VK_NULL_HANDLE;
        snprintf(why, n, "vkCreateDevice: %s", gs_vk_result(r));
    }
    return r;
}

static void gs_destroy_device(const gs_vk *g, VkDevice dev)
{
    PFN_vkGetDeviceProcAddr gdpa = (PFN_vkGetDeviceProcAddr)g->gipa(g->instance, "vkGetDeviceProcAddr");
    PFN_vkDestroyDevice destroy = gdpa ? (PFN_vkDestroyDevice)gdpa(dev, "vkDestroyDevice") : NULL;
    if (destroy) destroy(dev, NULL);
}

/* ---- the library's pipelines, as lrt_vk_context_create makes them -------------- */

static const char *const gs_kernel_names[4] = {"refit buffer", "refit image", "trace buffer", "trace image"};

/* Which of shaders_spv.h's kernels a module's words are, once the float
   controls the library may add (OpCapability RoundingModeRTE 4467 /
   SignedZeroInfNanPreserve 4466 and their OpExecutionMode 4462 / 4461 for
   32-bit floats) are taken out; -1: none. *modes: those found (1 RTE, 2
   inf/NaN). */
static int gs_identify(const uint32_t *code, size_t words, uint32_t *modes)
{
    const uint32_t *kernels[4] = {lrt_spv_refit_buffer, lrt_spv_refit_image, lrt_spv_trace_buffer, lrt_spv_trace_image};
    const size_t sizes[4] = {lrt_spv_refit_buffer_SIZE, lrt_spv_refit_image_SIZE, lrt_spv_trace_buffer_SIZE,
                             lrt_spv_trace_image_SIZE};
    uint32_t *w;
    size_t i = 5, o = 5;
    int k, found = -1;
    *modes = 0;
    if (words < 5 || !(w = (uint32_t *)malloc(words * sizeof *w))) return -1;
    memcpy(w, code, 5 * sizeof *w);
    while (i < words) {
        const uint32_t op = code[i] & 0xffffu, n = code[i] >> 16;
        if (n == 0 || n > words - i) break;
        if (op == 17 && n == 2 && (code[i + 1] == 4467u || code[i + 1] == 4466u)) {
            *modes |= code[i + 1] == 4467u ? 1u : 2u;
        } else if (!(op == 16 && n == 4 && (code[i + 2] == 4462u || code[i + 2] == 4461u) && code[i + 3] == 32u)) {
            memcpy(w + o, code + i, n * sizeof *w);
            o += n;
        }
        i += n;
    }
    for (k = 0; k < 4 && i == words; ++k)
        if (o * 4u == sizes[k] && memcmp(w, kernels[k], sizes[k]) == 0) found = k;
    free(w);
    return found;
}

/* What the wrappers saw. */
typedef struct gs_module_seen {
    VkShaderModule module;
    int kernel;
    uint32_t modes;
} gs_module_seen;
typedef struct gs_pipeline_seen {
    VkPipeline pipeline;
    int kernel;
    uint32_t modes;
    uint32_t consts[4]; /* lrt_back_trees, lrt_back_node_bits, lrt_node_texels, lrt_trace_pass (ids 0-3) */
    int has_const[4];
    int skipped; /* --quick: not compiled */
} gs_pipeline_seen;
enum { GS_MAX_SEEN = 64 };
static PFN_vkGetDeviceProcAddr gs_real_gdpa;
static PFN_vkCreateShaderModule gs_real_create_module;
static PFN_vkCreateComputePipelines gs_real_create_pipelines;
static gs_module_seen gs_modules[GS_MAX_SEEN];
static gs_pipeline_seen gs_pipelines[GS_MAX_SEEN];
static int gs_module_count, gs_pipeline_count, gs_unknown_modules;

static VKAPI_ATTR VkResult VKAPI_CALL gs_create_module(VkDevice dev, const VkShaderModuleCreateInfo *ci,
                                                       const VkAllocationCallbacks *cb, VkShaderModule *out)
{
    VkResult r = gs_real_create_module(dev, ci, cb, out);
    if (r == VK_SUCCESS && gs_module_count < GS_MAX_SEEN) {
        gs_module_seen *m = &gs_modules[gs_module_count++];
        m->module = *out;
        m->kernel = gs_identify(ci->pCode, ci->codeSize / 4u, &m->modes);
        if (m->kernel < 0) ++gs_unknown_modules;
    }
    return r;
}

/* --quick: the library's plain trace pipeline alone is compiled; the others
   get a handle of ours (gs_fake), which the wrapped vkDestroyPipeline drops */
static int gs_quick;
static char gs_fake[GS_MAX_SEEN];
static PFN_vkDestroyPipeline gs_real_destroy_pipeline;

static int gs_is_fake(VkPipeline p)
{
    int k;
    for (k = 0; k < GS_MAX_SEEN; ++k)
        if (p == (VkPipeline)(uintptr_t)&gs_fake[k]) return 1;
    return 0;
}

static VKAPI_ATTR void VKAPI_CALL gs_destroy_pipeline(VkDevice dev, VkPipeline p, const VkAllocationCallbacks *cb)
{
    if (!gs_is_fake(p)) gs_real_destroy_pipeline(dev, p, cb);
}

/* one at a time, each recorded with its kernel and specialization */
static VKAPI_ATTR VkResult VKAPI_CALL gs_create_pipelines(VkDevice dev, VkPipelineCache cache, uint32_t count,
                                                          const VkComputePipelineCreateInfo *infos,
                                                          const VkAllocationCallbacks *cb, VkPipeline *out)
{
    uint32_t i, e;
    int k;
    for (i = 0; i < count; ++i) out[i] = VK_NULL_HANDLE;
    for (i = 0; i < count; ++i) {
        VkComputePipelineCreateInfo ci = infos[i];
        const VkSpecializationInfo *s = ci.stage.pSpecializationInfo;
        gs_pipeline_seen seen;
        VkResult r;
        memset(&seen, 0, sizeof seen);
        seen.kernel = -1;
        for (k = 0; k < gs_module_count; ++k)
            if (gs_modules[k].module == ci.stage.module) {
                seen.kernel = gs_modules[k].kernel;
                seen.modes = gs_modules[k].modes;
            }
        for (e = 0; s && e < s->mapEntryCount; ++e) {
            const VkSpecializationMapEntry *m = &s->pMapEntries[e];
            if (m->constantID < 4 && m->size == 4 && m->offset + 4 <= s->dataSize) {
                memcpy(&seen.consts[m->constantID], (const char *)s->pData + m->offset, 4);
                seen.has_const[m->constantID] = 1;
            }
        }
        if (gs_pipeline_count == GS_MAX_SEEN) return VK_ERROR_OUT_OF_HOST_MEMORY;
        if (gs_quick && !(seen.kernel == 2 && seen.has_const[0] && !seen.consts[0] && !seen.consts[3])) {
            seen.pipeline = (VkPipeline)(uintptr_t)&gs_fake[gs_pipeline_count];
            seen.skipped = 1;
        } else {
            ci.flags |= VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR |
                        VK_PIPELINE_CREATE_CAPTURE_INTERNAL_REPRESENTATIONS_BIT_KHR;
            if ((r = gs_real_create_pipelines(dev, cache, 1, &ci, cb, &seen.pipeline)) != VK_SUCCESS) return r;
        }
        gs_pipelines[gs_pipeline_count++] = seen;
        out[i] = seen.pipeline;
    }
    return VK_SUCCESS;
}

static VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL gs_gdpa(VkDevice dev, const char *name)
{
    PFN_vkVoidFunction f = gs_real_gdpa(dev, name);
    if (f && strcmp(name, "vkCreateShaderModule") == 0) {
        gs_real_create_module = (PFN_vkCreateShaderModule)f;
        return (PFN_vkVoidFunction)gs_create_module;
    }
    if (f && strcmp(name, "vkDestroyPipeline") == 0) {
        gs_real_destroy_pipeline = (PFN_vkDestroyPipeline)f;
        return (PFN_vkVoidFunction)gs_destroy_pipeline;
    }
    if (f && strcmp(name, "vkCreateComputePipelines") == 0) {
        gs_real_create_pipelines = (PFN_vkCreateComputePipelines)f;
        return (PFN_vkVoidFunction)gs_create_pipelines;
    }
    return f;
}

/* The library's 32 pipelines, a row each; returns nonzero where it failed.
   *modes, *texels: the float controls and the node texel choice it made. */
static int gs_library(const gs_vk *g, uint32_t *modes, int *texels, char *why, size_t n)
{
    lrt_vk_context_desc desc;
    lrt_vk_context *ctx = NULL;
    VkDevice dev;
    VkResult vr = VK_SUCCESS;
    lrt_result lr;
    int i, bad = 0;
    if (gs_device(g, GS_DEVICE_LIBRARY, &dev, why, n) != VK_SUCCESS) return 1;
    gs_real_gdpa = (PFN_vkGetDeviceProcAddr)g->gipa(g->instance, "vkGetDeviceProcAddr");
    gs_module_count = gs_pipeline_count = gs_unknown_modules = 0;
    memset(&desc, 0, sizeof desc);
    desc.instance = g->instance;
    desc.physical_device = g->pd;
    desc.device = dev;
    desc.get_instance_proc_addr = g->gipa;
    desc.get_device_proc_addr = gs_gdpa;
    desc.vk_result = &vr;
    if ((lr = lrt_vk_context_create(&desc, &ctx)) != LRT_SUCCESS) {
        snprintf(why, n, "lrt_vk_context_create: %s (%s)", lrt_result_string(lr), gs_vk_result(vr));
        gs_destroy_device(g, dev);
        return 1;
    }
    /* the context makes its pipelines on first use (LRT__VK_LAZY): all of them, now */
    for (i = 0; i < LRT__VK_PIPELINES; ++i)
        if (ctx->pipelines[i] == VK_NULL_HANDLE && (vr = lrt__vk_make_pipeline(ctx, i, &ctx->pipelines[i])) != VK_SUCCESS) {
            snprintf(why, n, "pipeline %d: %s", i, gs_vk_result(vr));
            lrt_vk_context_destroy(ctx);
            gs_destroy_device(g, dev);
            return 1;
        }
    if (gs_pipeline_count != LRT__VK_PIPELINES || gs_unknown_modules) {
        snprintf(why, n, "lrt_vk_context_create made %d pipelines (%d of modules not shaders_spv.h's), not %d",
                 gs_pipeline_count, gs_unknown_modules, (int)LRT__VK_PIPELINES);
        bad = 1;
    }
    *modes = 0;
    *texels = -1;
    for (i = 0; i < gs_pipeline_count; ++i) {
        const gs_pipeline_seen *p = &gs_pipelines[i];
        char name[64];
        gs_row *row;
        if (p->kernel < 0 || !p->has_const[0] || !p->has_const[1]) {
            snprintf(name, sizeof name, "linear_rt pipeline %d (unknown)", i);
            bad = 1;
        } else {
            const char *pass = p->kernel < 2            ? ""
                               : p->consts[3] == 1 ? ", rare pass"
                               : p->consts[3] == 2 ? ", one pass"
                               : p->consts[3] == 3 ? ", budgeted"
                               : p->consts[3] == 4 ? ", compacted round"
                                                   : "";
            if (!p->consts[0])
                snprintf(name, sizeof name, "linear_rt %s%s", gs_kernel_names[p->kernel], pass);
            else
                snprintf(name, sizeof name, "linear_rt %s%s, back %u-bit", gs_kernel_names[p->kernel], pass, p->consts[1]);
        }
        if (!(row = gs_new_row(name))) break;
        if (p->skipped) {
            snprintf(row->why, sizeof row->why, "left out (--quick)");
            row->left_out = 1;
        } else
            gs_read_stats(dev, gs_real_gdpa, p->pipeline, row);
        *modes |= p->modes;
        if (p->has_const[2]) *texels = (int)p->consts[2];
    }
    lrt_vk_context_destroy(ctx);
    gs_destroy_device(g, dev);
    return bad;
}

/* ---- the benchmark's peers, as bench/m_vk_peers.c makes them -------------------- */

/* --spv NAME=FILE:MASK[:C0,C1,...]: a SPIR-V module of another commit (an
   old kernel, to weigh what a GPU ran then), its bindings the bits of MASK,
   all storage buffers, 128 bytes of push constants, its specialization
   constants 0, 1, ... the numbers given (uint32) */
static const char *gs_extra[8];
static int gs_extra_count;

typedef struct gs_peer {
    const char *name;
    const uint32_t *code;
    size_t size;
    uint32_t bindings; /* m_vk_peers.c's vkp_bindings of the kind: 0 depth .. 5 TLAS */
    int ray_query;
    int plain; /* --spv: every binding a storage buffer, 128 bytes of push constants */
    uint32_t consts[4]; /* --spv: specialization constants 0..nconsts-1 (uint32: a bool is 0 or 1) */
    uint32_t nconsts;
} gs_peer;

/* one row; the pipeline layout as m_vk_peers.c's: its kind's bindings, 96
   bytes of push constants (vkp_push) */
static void gs_peer_row(const gs_vk *g, VkDevice dev, const gs_peer *peer)
{
    PFN_vkGetDeviceProcAddr gdpa = (PFN_vkGetDeviceProcAddr)g->gipa(g->instance, "vkGetDeviceProcAddr");
#define GS_D(name) PFN_##name name = (PFN_##name)gdpa(dev, #name);
    GS_D(vkCreateDescriptorSetLayout) GS_D(vkDestroyDescriptorSetLayout) GS_D(vkCreatePipelineLayout)
    GS_D(vkDestroyPipelineLayout) GS_D(vkCreateShaderModule) GS_D(vkDestroyShaderModule)
    GS_D(vkCreateComputePipelines) GS_D(vkDestroyPipeline)
#undef GS_D
    VkDescriptorSetLayoutBinding b[9];
    VkSpecializationMapEntry entries[4];
    VkSpecializationInfo spec;
    VkDescriptorSetLayoutCreateInfo li;
    VkPushConstantRange pr;
    VkPipelineLayoutCreateInfo pli;
    VkShaderModuleCreateInfo mi;
    VkComputePipelineCreateInfo ci;
    VkDescriptorSetLayout dsl = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkShaderModule module = VK_NULL_HANDLE;
    VkPipeline pipe = VK_NULL_HANDLE;
    uint32_t nb = 0, k;
    VkResult r;
    gs_row *row = gs_new_row(peer->name);
    if (!row) return;
    memset(b, 0, sizeof b);
    for (k = 0; k < 9; ++k) {
        if (!((peer->bindings >> k) & 1u)) continue;
        b[nb].binding = k;
        b[nb].descriptorType = k == 5 && !peer->plain ? VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR
                                                      : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        b[nb].descriptorCount = 1;
        b[nb].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
        ++nb;
    }
    memset(&li, 0, sizeof li);
    li.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    li.bindingCount = nb;
    li.pBindings = b;
    memset(&pr, 0, sizeof pr);
    pr.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    pr.size = peer->plain ? 128 : 96; /* vkp_push: 8 + 16 uint32_t */
    memset(&pli, 0, sizeof pli);
    pli.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    pli.setLayoutCount = 1;
    pli.pSetLayouts = &dsl;
    pli.pushConstantRangeCount = 1;
    pli.pPushConstantRanges = &pr;
    memset(&mi, 0, sizeof mi);
    mi.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    mi.codeSize = peer->size;
    mi.pCode = peer->code;
    if ((r = vkCreateDescriptorSetLayout(dev, &li, NULL, &dsl)) != VK_SUCCESS)
        snprintf(row->why, sizeof row->why, "vkCreateDescriptorSetLayout: %s", gs_vk_result(r));
    else if ((r = vkCreatePipelineLayout(dev, &pli, NULL, &layout)) != VK_SUCCESS)
        snprintf(row->why, sizeof row->why, "vkCreatePipelineLayout: %s", gs_vk_result(r));
    else if ((r = vkCreateShaderModule(dev, &mi, NULL, &module)) != VK_SUCCESS)
        snprintf(row->why, sizeof row->why, "vkCreateShaderModule: %s", gs_vk_result(r));
    if (!row->why[0]) {
        memset(&ci, 0, sizeof ci);
        ci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
        ci.flags = VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR | VK_PIPELINE_CREATE_CAPTURE_INTERNAL_REPRESENTATIONS_BIT_KHR;
        ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
        ci.stage.module = module;
        ci.stage.pName = "main";
        ci.layout = layout;
        ci.basePipelineIndex = -1;
        if (peer->nconsts) {
            for (k = 0; k < peer->nconsts; ++k) {
                entries[k].constantID = k;
                entries[k].offset = 4u * k;
                entries[k].size = 4;
            }
            spec.mapEntryCount = peer->nconsts;
            spec.pMapEntries = entries;
            spec.dataSize = 4u * peer->nconsts;
            spec.pData = peer->consts;
            ci.stage.pSpecializationInfo = &spec;
        }
        if ((r = vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &ci, NULL, &pipe)) != VK_SUCCESS) {
            pipe = VK_NULL_HANDLE;
            snprintf(row->why, sizeof row->why, "vkCreateComputePipelines: %s", gs_vk_result(r));
        } else {
            gs_read_stats(dev, gdpa, pipe, row);
        }
    }
    if (pipe != VK_NULL_HANDLE) vkDestroyPipeline(dev, pipe, NULL);
    if (module != VK_NULL_HANDLE) vkDestroyShaderModule(dev, module, NULL);
    if (layout != VK_NULL_HANDLE) vkDestroyPipelineLayout(dev, layout, NULL);
    if (dsl != VK_NULL_HANDLE) vkDestroyDescriptorSetLayout(dev, dsl, NULL);
}

static void gs_peers(const gs_vk *g)
{
#ifdef GPU_STATS_HAVE_PEERS
    static const gs_peer peers[] = {
        {"bench march64", vkp_spv_march64, vkp_spv_march64_SIZE, 0x07u, 0, 0, {0, 0, 0, 0}, 0},
        {"bench dda", vkp_spv_dda, vkp_spv_dda_SIZE, 0x07u, 0, 0, {0, 0, 0, 0}, 0},
        {"bench hiz64", vkp_spv_hiz, vkp_spv_hiz_SIZE, 0x17u, 0, 0, {0, 0, 0, 0}, 0},
        {"bench hiz64 mip build", vkp_spv_hiz_mip, vkp_spv_hiz_mip_SIZE, 0x17u, 0, 0, {0, 0, 0, 0}, 0},
        {"bench rq aabb", vkp_spv_rq_aabb, vkp_spv_rq_aabb_SIZE, 0x3fu, 1, 0, {0, 0, 0, 0}, 0},
        {"bench rq aabb, AABB build", vkp_spv_aabb_gen, vkp_spv_aabb_gen_SIZE, 0x3fu, 1, 0, {0, 0, 0, 0}, 0},
        {"bench rq triangles", vkp_spv_rq_tri, vkp_spv_rq_tri_SIZE, 0x2fu, 1, 0, {0, 0, 0, 0}, 0}};
    int kind;
    for (kind = GS_DEVICE_PEERS; kind <= GS_DEVICE_RAY_QUERY; ++kind) {
        VkDevice dev = VK_NULL_HANDLE;
        char why[200] = "";
        size_t i;
        int ok = kind == GS_DEVICE_PEERS || g->has_rt;
        if (!ok) snprintf(why, sizeof why, "no ray queries on this device");
        else if (gs_device(g, kind, &dev, why, sizeof why) != VK_SUCCESS) ok = 0;
        for (i = 0; i < sizeof peers / sizeof peers[0]; ++i) {
            gs_row *row;
            if (peers[i].ray_query != (kind == GS_DEVICE_RAY_QUERY)) continue;
            if (ok) gs_peer_row(g, dev, &peers[i]);
            else if ((row = gs_new_row(peers[i].name)) != NULL) snprintf(row->why, sizeof row->why, "%s", why);
        }
        if (dev != VK_NULL_HANDLE) gs_destroy_device(g, dev);
    }
#else
    gs_row *row = gs_new_row("bench peers");
    (void)g;
    if (row) snprintf(row->why, sizeof row->why, "not built: no glslang when this was compiled (make bench's kernels)");
#endif
}

/* --spv modules, on the peers' plain device */
static void gs_extras(const gs_vk *g)
{
    int i;
    for (i = 0; i < gs_extra_count; ++i) {
        char name[64], path[400];
        const char *eq = strchr(gs_extra[i], '='), *colon = eq ? strchr(eq, ':') : NULL;
        unsigned long mask;
        FILE *f;
        long bytes;
        uint32_t *code = NULL;
        gs_peer peer;
        VkDevice dev = VK_NULL_HANDLE;
        char why[200] = "";
        gs_row *row;
        if (!eq || !colon || colon < eq || (size_t)(eq - gs_extra[i]) >= sizeof name ||
            (size_t)(colon - eq - 1) >= sizeof path) {
            if ((row = gs_new_row(gs_extra[i])) != NULL) snprintf(row->why, sizeof row->why, "--spv NAME=FILE:MASK");
            continue;
        }
        memcpy(name, gs_extra[i], (size_t)(eq - gs_extra[i]));
        name[eq - gs_extra[i]] = 0;
        memcpy(path, eq + 1, (size_t)(colon - eq - 1));
        path[colon - eq - 1] = 0;
        {
            char *end;
            mask = strtoul(colon + 1, &end, 0);
            peer.nconsts = 0;
            while (*end == ':' || *end == ',') {
                if (peer.nconsts == 4) break;
                peer.consts[peer.nconsts++] = (uint32_t)strtoul(end + 1, &end, 0);
            }
        }
        if (!(f = fopen(path, "rb")) || fseek(f, 0, SEEK_END) || (bytes = ftell(f)) <= 0 || bytes % 4 ||
            fseek(f, 0, SEEK_SET) || !(code = (uint32_t *)malloc((size_t)bytes)) ||
            fread(code, 1, (size_t)bytes, f) != (size_t)bytes) {
            if ((row = gs_new_row(name)) != NULL) snprintf(row->why, sizeof row->why, "cannot read %.150s", path);
            if (f) fclose(f);
            free(code);
            continue;
        }
        fclose(f);
        if (gs_device(g, GS_DEVICE_PEERS, &dev, why, sizeof why) != VK_SUCCESS) {
            if ((row = gs_new_row(name)) != NULL) snprintf(row->why, sizeof row->why, "%s", why);
        } else {
            peer.name = name;
            peer.code = code;
            peer.size = (size_t)bytes;
            peer.bindings = (uint32_t)mask;
            peer.ray_query = 0;
            peer.plain = 1;
            gs_peer_row(g, dev, &peer);
            gs_destroy_device(g, dev);
        }
        free(code);
    }
}

/* ---- one GPU ------------------------------------------------------------------ */

static void gs_print_table(FILE *f, const char *gpu, const char *arch, const gs_vk *g, uint32_t modes, int texels)
{
    int i, c, left_out = 0;
    fprintf(f, "### %s (%s): %s, %s\n\n", arch, gpu, g->device_name, g->driver_info);
    fprintf(f, "linear_rt's pipelines as lrt_vk_context_create makes them there: float controls %s%s%s, "
               "nodes read through %s.\n\n",
            modes & 1u ? "RTE" : "", modes == 3u ? " + " : modes ? "" : "none", modes & 2u ? "inf/NaN kept" : "",
            texels == 1 ? "a uniform texel buffer" : texels == 0 ? "the storage buffer" : "?");
    fprintf(f, "| pipeline | instructions | code bytes | VGPRs | SGPRs | spilled VGPRs / SGPRs | branches | waves per SIMD "
               "| loop body (loads) | inner loop (loads) |\n");
    fprintf(f, "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n");
    for (i = 0; i < gs_row_count; ++i) {
        const gs_row *r = &gs_rows[i];
        char cell[GS_COLS][24];
        if (r->left_out) {
            ++left_out;
            continue;
        }
        if (r->why[0]) {
            fprintf(f, "| %s | not compiled: %s |||||||||\n", r->name, r->why);
            continue;
        }
        for (c = 0; c < GS_COLS; ++c) {
            if (r->has[c]) snprintf(cell[c], sizeof cell[c], "%llu", r->v[c]);
            else snprintf(cell[c], sizeof cell[c], "-");
        }
        fprintf(f, "| %s | %s | %s | %s | %s | %s / %s | %s | %s | ", r->name, cell[GS_INSTR], cell[GS_CODE],
                cell[GS_VGPR], cell[GS_SGPR], cell[GS_VSPILL], cell[GS_SSPILL], cell[GS_BRANCH], cell[GS_WAVES]);
        if (r->has_isa && r->isa_outer) fprintf(f, "%u (%u) | ", r->isa_outer, r->loads_outer);
        else fprintf(f, "%s | ", r->has_isa ? "no loop" : "-");
        if (r->has_isa && r->isa_inner) fprintf(f, "%u (%u) |\n", r->isa_inner, r->loads_inner);
        else fprintf(f, "- |\n");
    }
    if (left_out) fprintf(f, "\n--quick: %d more rows left out (every pipeline is made; one compiled)\n", left_out);
    fprintf(f, "\n");
}

/* The rows as tab-separated values for the benchmark's estimate (bench/main.c
   reads them: no weight is typed there): gpu, pipeline, instructions,
   VGPRs, waves per SIMD, loop body, inner loop, loads in each. */
static int gs_write_weights(const char *path, const char *gpu)
{
    FILE *f = fopen(path, "a");
    int i;
    if (!f) return 1;
    for (i = 0; i < gs_row_count; ++i) {
        const gs_row *r = &gs_rows[i];
        if (r->why[0] || r->left_out || !r->has_isa) continue;
        fprintf(f, "%s\t%s\t%llu\t%llu\t%llu\t%u\t%u\t%u\t%u\t%u\t%u\t%u\n", gpu, r->name, r->v[GS_INSTR], r->v[GS_VGPR],
                r->v[GS_WAVES], r->isa_outer, r->isa_inner, r->loads_outer, r->loads_inner, r->isa_skippable, r->isa_exit,
                r->isa_aside);
    }
    return fclose(f) != 0;
}

/* In a child process: the environment names the chip. */
static const char *gs_weights_path; /* --weights FILE */

static int gs_one_gpu(const char *gpu, const char *arch, const char *icd, const char *out_path)
{
    gs_vk g;
    char why[200] = "";
    uint32_t modes = 0;
    int texels = -1, rc, i, trace_ok = 0;
    FILE *f;
    setenv("VK_ICD_FILENAMES", icd, 1);
    setenv("VK_DRIVER_FILES", icd, 1);
    setenv("RADV_FORCE_FAMILY", gpu, 1);
    setenv("MESA_SHADER_CACHE_DISABLE", "true", 1); /* every figure from a compilation */
    unsetenv("VK_INSTANCE_LAYERS");
    if ((rc = gs_open(&g)) != 0) {
        gs_close(&g);
        return rc;
    }
    if (gs_library(&g, &modes, &texels, why, sizeof why)) {
        gs_row *row = gs_new_row("linear_rt");
        if (row) snprintf(row->why, sizeof row->why, "%s", why);
    }
    if (gs_quick) {
        gs_row *row = gs_new_row("bench peers");
        if (row) {
            snprintf(row->why, sizeof row->why, "left out (--quick)");
            row->left_out = 1;
        }
    } else
        gs_peers(&g);
    gs_extras(&g);
    gs_print_table(stdout, gpu, arch, &g, modes, texels);
    fflush(stdout);
    if ((f = fopen(out_path, "a")) != NULL) {
        gs_print_table(f, gpu, arch, &g, modes, texels);
        if (fclose(f) != 0) rc = 1;
    } else {
        fprintf(stderr, "gpu_stats: cannot write %s\n", out_path);
        rc = 1;
    }
    gs_close(&g);
    for (i = 0; i < gs_row_count; ++i)
        if (strcmp(gs_rows[i].name, "linear_rt trace buffer") == 0 && !gs_rows[i].why[0] &&
            gs_rows[i].has[GS_INSTR] && gs_rows[i].v[GS_INSTR] && gs_rows[i].has[GS_VGPR] &&
            gs_rows[i].v[GS_VGPR] && gs_rows[i].has[GS_WAVES] && gs_rows[i].v[GS_WAVES])
            trace_ok = 1;
    if (!trace_ok) {
        fprintf(stderr, "gpu_stats: %s: no figures for linear_rt's trace pipeline\n", gpu);
        rc = 1;
    }
    for (i = 0; i < gs_row_count; ++i)
        if (strncmp(gs_rows[i].name, "linear_rt", 9) == 0 && gs_rows[i].why[0] && !gs_rows[i].left_out) rc = 1;
    /* every pipeline made is compiled: the peers too (ray-query ones where the device has ray queries) */
    for (i = 0; i < gs_row_count; ++i)
        if (!gs_rows[i].left_out && gs_rows[i].why[0] && strcmp(gs_rows[i].why, "no ray queries on this device") != 0) {
            fprintf(stderr, "gpu_stats: %s: %s not compiled: %s\n", gpu, gs_rows[i].name, gs_rows[i].why);
            rc = 1;
        }
    if (gs_rows_lost) {
        fprintf(stderr, "gpu_stats: %s: %d pipelines past the table's %d rows\n", gpu, gs_rows_lost, GS_MAX_ROWS);
        rc = 1;
    }
    if (gs_weights_path && gs_write_weights(gs_weights_path, gpu)) {
        fprintf(stderr, "gpu_stats: cannot write %s\n", gs_weights_path);
        rc = 1;
    }
    return rc;
}

/* A new file holding `text`; 1 (said on stderr) when it cannot be written */
static int gs_start_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f || fputs(text, f) < 0 || fclose(f) != 0) {
        fprintf(stderr, "gpu_stats: cannot write %s\n", path);
        return 1;
    }
    return 0;
}

static const char *gs_arch(const char *gpu)
{
    int i;
    for (i = 0; i < GS_DEFAULT_GPUS; ++i)
        if (strcmp(gpu, gs_default_gpus[i][0]) == 0) return gs_default_gpus[i][1];
    return gpu;
}

int main(int argc, char **argv)
{
    const char *gpus[16];
    const char *out_path = "build/gpu-stats.md", *icd = getenv("GPU_STATS_RADV_ICD");
    const char *ci = getenv("CI");
    const int under_ci = ci && strcmp(ci, "true") == 0;
    int ngpu = 0, i, skipped = 0, failed = 0;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--gpu") == 0 && i + 1 < argc && ngpu < 16) gpus[ngpu++] = argv[++i];
        else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc) out_path = argv[++i];
        else if (strcmp(argv[i], "--all") == 0) gs_all = 1;
        else if (strcmp(argv[i], "--quick") == 0) gs_quick = 1;
        else if (strcmp(argv[i], "--weights") == 0 && i + 1 < argc) gs_weights_path = argv[++i];
        else if (strcmp(argv[i], "--spv") == 0 && i + 1 < argc && gs_extra_count < 8) gs_extra[gs_extra_count++] = argv[++i];
        else {
            fprintf(stderr, "usage: %s [--gpu navi31|navi21|vega10|...]... [--out FILE] [--weights FILE] [--spv NAME=FILE:MASK]... [--all] [--quick]\n",
                    argv[0]);
            return 2;
        }
    }
    if (!ngpu)
        for (i = 0; i < GS_DEFAULT_GPUS; ++i) gpus[ngpu++] = gs_default_gpus[i][0];
    if (!icd) icd = GS_DEFAULT_ICD;
    if (access(icd, R_OK) != 0) {
        printf("gpu_stats: %s: no %s (RADV: Debian's mesa-vulkan-drivers)\n", under_ci ? "FAIL under CI=true" : "skipped",
               icd);
        return under_ci ? 1 : GS_SKIP;
    }
    if (gs_start_file(out_path, "## The kernels' weight on AMD GPUs\n\n"
                                "Compiled by Mesa's RADV (ACO) on null hardware (RADV_FORCE_FAMILY), read through "
                                "VK_KHR_pipeline_executable_properties (bench/gpu_stats.c, make gpu-stats). "
                                "Instructions: ACO's count; code bytes: the binary's size. SGPRs: as allocated (RDNA "
                                "gives every wave 128). Waves per SIMD: RADV's \"Subgroups per SIMD\", the occupancy the "
                                "registers allow. Loops: from the disassembly (a walk: the largest loop that loads). "
                                "build/gpu_stats --all lists every statistic (latency, VALU/SALU counts...).\n\n") ||
        (gs_weights_path &&
         gs_start_file(gs_weights_path,
                       "# bench/gpu_stats.c --weights: gpu pipeline instructions vgprs waves_per_simd loop_body inner_loop "
                       "loop_loads inner_loads loop_skippable loop_exits (static counts of the compiled code; loops from "
                       "its branches; skippable: the loop body's blocks a wave jumps over when no lane enters them; "
                       "exits: those that store a result, run once by a lane as it leaves; aside_loop: the largest "
                       "loading loop beside the outermost, a budget's finish)\n")))
        return 1;
    fflush(stdout);
    for (i = 0; i < ngpu; ++i) {
        int status = 0, rc;
        pid_t pid = fork();
        if (pid < 0) {
            perror("gpu_stats: fork");
            return 1;
        }
        if (pid == 0) {
            rc = gs_one_gpu(gpus[i], gs_arch(gpus[i]), icd, out_path);
            fflush(stdout);
            fflush(stderr);
            _exit(rc);
        }
        if (waitpid(pid, &status, 0) != pid) status = 1 << 8;
        rc = WIFEXITED(status) ? WEXITSTATUS(status) : 1;
        if (!WIFEXITED(status)) fprintf(stderr, "gpu_stats: %s: the compiler crashed (signal %d)\n", gpus[i],
                                        WIFSIGNALED(status) ? WTERMSIG(status) : 0);
        if (rc == GS_SKIP) ++skipped;
        else if (rc != 0) ++failed;
    }
    if (skipped == ngpu) {
        printf("gpu_stats: %s: no RADV device here (above)\n", under_ci ? "FAIL under CI=true" : "skipped");
        return under_ci ? 1 : GS_SKIP;
    }
    if (skipped || failed) {
        printf("gpu_stats: FAIL: %d of %d GPUs without tables or with failures (above)\n", skipped + failed, ngpu);
        return 1;
    }
    printf("gpu_stats: %d tables, also in %s\n", ngpu, out_path);
    return 0;
}
