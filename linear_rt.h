/* linear_rt.h - v0.2 - exact screen-space ray tracing by a BVH over the depth buffer

   Reflections, ambient occlusion and contact shadows traced against the
   depth buffer read as a heightfield: an 8-wide BVH laid over it once,
   refitted each frame, walked to the first texel a ray touches (texel (i, j)
   is the box [i,i+1] x [j,j+1] x [depth,1]: docs/MODEL.md of the project).
   A CPU path, and Vulkan kernels (shaders_spv.h) that answer as it does.

   DO THIS in ONE C or C++ file (every other file includes linear_rt.h alone):
       #define LINEAR_RT_IMPLEMENTATION
       #include "linear_rt.h"

   EXAMPLE (complete: make test compiles and runs the lines between the marks)
-- 8< --
#define LINEAR_RT_IMPLEMENTATION
#include "linear_rt.h"
#include <stdio.h>
int main(void)
{
    static float texels[64 * 64]; // depth, 0 near: a wall at 0.5
    static lrt_bvh bvh;           // zeroed before its first build
    lrt_depth depth = {texels, 64, 64, 0, LRT_FORMAT_FLOAT32, 0, NULL};
    lrt_ray ray = {{10.5f, 20.5f, 0.0f}, 0.0f, {0.0f, 0.0f, 1.0f}, 1.0f};
    lrt_hit hit;
    int i;
    for (i = 0; i < 64 * 64; ++i) texels[i] = 0.5f;
    if (lrt_bvh_build(&bvh, &depth, NULL, NULL) != LRT_SUCCESS) return 1;
    lrt_bvh_update(&bvh, &depth, NULL); // each frame, after the depth changed
    lrt_trace(&bvh, &depth, &ray, &hit, 1, 0);
    printf("kind %u t %g texel %u %u\n", (unsigned)hit.kind, (double)hit.t, (unsigned)hit.x, (unsigned)hit.y);
    lrt_bvh_destroy(&bvh);
    return hit.kind == LRT_HIT && hit.t == 0.5f ? 0 : 1;
}
-- 8< --
   OPTIONS (define before the IMPLEMENTATION include) [default]
     LINEAR_RT_STATIC, LINEAR_RT_API  the API's linkage [extern]
     LINEAR_RT_ASSERT(x)            internal checks [assert of <assert.h>]
     LINEAR_RT_MALLOC(size, user), LINEAR_RT_FREE(ptr, user)  both or
                                    neither: lrt_bvh_build's allocator [malloc, free]
     LINEAR_RT_NO_SIMD              plain C walk [SSE2 / AVX2 on x86-64]
     LINEAR_RT_NO_AVX               SSE2 alone [AVX2 walk too]
     LINEAR_RT_NO_RUNTIME_DISPATCH  AVX2 only if the build targets it [gcc and
                                    clang on x86-64 compile it and pick by the CPU]
     LINEAR_RT_SELF                 this file's name, for that second pass ["linear_rt.h"]
     LINEAR_RT_VULKAN               the lrt_vk_* API, in every file using it [off]
     LINEAR_RT_COUNT_NODE_TEST(level), LINEAR_RT_COUNT_TEXEL_TEST()  profiling [nothing]
     LINEAR_RT_WALK_AS_KERNELS      profiling: an expression; where nonzero, every
                                    walk starts as the kernels' do (lrt__walk_origin) [undefined]

   SECTIONS: each opens with a banner that ends in ">>" and its name (search for it)
     usage         USE (CPU), USE (VULKAN), BARRIERS, INPUT, THE TREE: below
     contract      what the kernels and this file share (C and glslang read it)
     api           declarations: limits, result codes, depth in, layout, the BVH
                   and its thickness models, traversal, camera helpers
     vulkan-api    declarations of the Vulkan path (LINEAR_RT_VULKAN)
     impl          the implementation: config macros and the ISA prelude (every
                   SIMD decision: LRT__SSE, LRT__AVX_BUILT, LRT__AVX_AT_RUN_TIME),
                   then by the data's path; every SIMD function sits in an
                   "ISA block:" (AVX2 | SSE2 | scalar versions under one name):
     depth           1. depth in: validation, one texel's raw value, the backs
     heights         2. heights: depth to rounded-up codes, back codes
     layout          3. level geometry and the modified Morton mapping
     nodes           4. nodes: build and update (the refit)
     setup           5. a ray's set-up: the exact arithmetic at the edge of float
                        range, the rare set-up, the common one, the start node
     node-test       6. node and texel tests: a node's 8 children in one step
     walk               the 8-child walk (WALKS, TWINS: every walk and its twin)
     walk-cells         the GPU's cell walk in C: budgeted traces, counts, tests
     batch-avx2         eight rays at once (AVX2), and the trace loop
     trace              the CPU entry points: lrt_trace, lrt_trace_range, lrt_cpu_path
     camera        7. rays from a camera
     vulkan        8. Vulkan: the kernels' host side (SPIR-V in shaders_spv.h)
     walk-avx2     9. setup, walk and batch-avx2 compiled again for AVX2
     licence       MIT

   USE (CPU)                                                            >>usage
       lrt_depth depth = {texels, width, height, row_stride_bytes, LRT_FORMAT_FLOAT32, flags, NULL};
       lrt_bvh bvh = {0};                                      // zeroed (C++: = {})
       lrt_result r = lrt_bvh_build(&bvh, &depth, NULL, NULL); // once per size
       ...each frame, after the depth changed:
       r = lrt_bvh_update(&bvh, &depth, NULL);                 // whole map, or a dirty rect
       r = lrt_trace(&bvh, &depth, rays, hits, ray_count, 0);  // flags: 0
       ...
       lrt_bvh_destroy(&bvh);
   Rays live in screen space: x in [0,W], y in [0,H] in texels, z = depth in
   [0,1] (0 near). A hit says which face of its texel's box it lies on:
   hits[k].face is LRT_FACE_TOP for a surface the camera sees; a side, the
   back or inside (the origin in the solid) is where an engine may shade
   with something else.
   lrt_trace_range() traces a slice of a batch: the BVH and depth are only
   read while tracing, so threads may trace disjoint slices at once.


   USE (VULKAN)
   The same three algorithms as compute kernels (shaders/, embedded as
   SPIR-V), recorded into your command buffers inside your own VkDevice.
       #define LINEAR_RT_VULKAN            // before EVERY include that uses lrt_vk_*
       #define LINEAR_RT_IMPLEMENTATION    // in one file, as for the CPU path
       #include "linear_rt.h"              // includes <vulkan/vulkan.h>; the
                                           // implementation includes "shaders_spv.h"
                                           // (ship it next to linear_rt.h)
       lrt_vk_context_desc cd = {0};       // instance, physical_device, device,
       ...                                 // vkGetInstanceProcAddr (+ optional
       lrt_vk_context *ctx;                // vkGetDeviceProcAddr, allocator, cache)
       lrt_vk_context_create(&cd, &ctx);   // once: layouts, a sampler (pipelines: on first use)
       lrt_vk_bvh_desc bd = {0};           // width, height, format (+ node bits,
       lrt_vk_bvh bvh = {0};               // your buffers or the library's)
       lrt_vk_bvh_create(ctx, &bd, &bvh);
       lrt_vk_depth depth = {0};           // a VkBuffer (offset, row stride) or
       ...                                 // a VkImageView (and its layout)
       lrt_vk_cmd_build(ctx, cmd, &bvh, &depth);                 // once
       ...each frame, with the barriers of BARRIERS between them:
       lrt_vk_cmd_update(ctx, cmd, &bvh, &depth, NULL);          // or a dirty rect
       lrt_vk_cmd_trace(ctx, cmd, &bvh, &depth, rays, 0, hits, 0, n, 0);
       ...
       lrt_vk_bvh_destroy(ctx, &bvh);
       lrt_vk_context_destroy(ctx);
   The library never calls Vulkan by a link-time symbol: every function
   comes from the vkGetInstanceProcAddr / vkGetDeviceProcAddr you give it,
   so VK_NO_PROTOTYPES (volk and the like) is fine. Your device: Vulkan 1.2
   or newer (instance too), VK_KHR_push_descriptor enabled, and the features
   lrt_vk_get_requirements lists (read from the kernels' SPIR-V) enabled.
   The library never owns a queue, submits, waits or allocates per frame;
   the recording functions only read the context and the BVH (but build,
   which marks its tree built), so several threads may record with one
   context at once (a tree's build before anything else records with it).
   The GPU tree is the CPU's node array byte for byte (lrt_vk_bvh.layout is
   an lrt_layout), and the kernels answer what the CPU answers (docs/MODEL.md:
   same kind and texel, t within float rounding). Every walk finds the first
   texel hit in one visiting order, with no stack: the CPU's 8-child walk
   (lrt__walk_origin, section walk; from the ray's origin or the lowest node
   holding the segment), its GLSL twin (lrt_walk_origin: budgets, thickness
   trees, one pass) and, in a GPU's ordinary pass of an infinite tree, the
   cell walk (lrt_walk_cells, one cell a step; its C twin lrt__walk_cells,
   which the tests hold to lrt_trace).
   Tools, tests and examples, which have no engine's device, take theirs
   from linear_rt_vk_util.h, the companion header beside this one
   (lrt_vku_device_create: the loader opened at run time, an instance,
   device and compute queue, optionally the validation layer, an
   lrt_vk_context_desc filled), with the rest such programs need: buffers,
   depth images, one-shot submits, barriers, timestamps.

   BARRIERS. The library records its own barriers inside build (its fill of
   the counters -> its dispatch), inside a trace of two passes (the
   ordinary pass -> the rare pass, which reads the hits the first marked)
   and inside a compacted trace (around its scratch: earlier use -> its
   header's update -> each round -> the next); you record every other one,
   as with VMA. Below,
   CS is VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, accesses lose VK_ACCESS_ and
   _BIT, and "src -> dst" is (stage, access) -> (stage, access). The tree is
   the node and counter ranges of an lrt_vk_bvh.
     before build, update, trace:
       the depth you wrote:   (your stage, your write) -> (CS, SHADER_READ);
                              an image in the same barrier goes to the layout
                              named in lrt_vk_depth (e.g. a depth attachment:
                              (LATE_FRAGMENT_TESTS, DEPTH_STENCIL_ATTACHMENT_WRITE)
                              -> (CS, SHADER_READ), to SHADER_READ_ONLY_OPTIMAL)
     before build, when the tree was used by earlier commands:
                              (CS, SHADER_WRITE) -> (TRANSFER | CS,
                              TRANSFER_WRITE | SHADER_READ | SHADER_WRITE)
     before update or trace, after the build or update of the tree:
                              (CS, SHADER_WRITE) -> (CS, SHADER_READ | SHADER_WRITE)
     before update, after a trace that read the tree (write after read):
                              (CS, 0) -> (CS, 0), or the barrier above
     before trace:
       the rays you wrote:    (your stage, your write) -> (CS, SHADER_READ)
       earlier readers of the hits: (their stage, 0) -> (CS, 0)
     after trace:
       its hits:              (CS, SHADER_WRITE) -> (the reader's stage and
                              access: TRANSFER / TRANSFER_READ for a copy,
                              HOST / HOST_READ for a mapped read after the
                              fence, FRAGMENT_SHADER / SHADER_READ, ...)
     after build, update, trace, before you write that depth again:
                              (CS, 0) -> (your stage, 0) (write after read)
     reading the tree back (LRT_VK_BVH_HOST_VISIBLE): (CS, SHADER_WRITE) ->
                              (HOST, HOST_READ), then wait for the fence.
   Simplest: between consecutive linear_rt commands on one tree, one
   VkMemoryBarrier (CS, SHADER_WRITE) -> (CS | TRANSFER, SHADER_READ |
   SHADER_WRITE | TRANSFER_WRITE) covers every row about the tree. Commands
   in earlier submissions to the queue need these barriers too (a fence
   orders the host, not the next submission's reads).


   INPUT
   Depth maps of 1x1 to LINEAR_RT_MAX_DIM x LINEAR_RT_MAX_DIM texels with any
   row stride, as 8-bit unorm (v/255), 16-bit unorm (v/65535) or 32-bit float,
   standard (0 near) or reversed Z (LRT_DEPTH_REVERSED_Z: d = 1 - v, in the
   input's own arithmetic: (max - v)/max for integers, 1.0f - f for floats).
   The only repairs made to input: a float depth that is NaN or above 1
   becomes 1, below 0 or subnormal becomes 0 (after the reversed-Z flip, so
   NaN is always far); a subnormal ray component reads as 0 of its sign
   (GPUs may flush subnormals: docs/MODEL.md).
   Data needs no alignment (it is read with memcpy).


   THE TREE (see the sections of the implementation, which follow the data)
   - level 0 is the texels; level L+1 groups level L's nodes in 4x2 blocks
     when L is even and 2x4 blocks when L is odd, up to a 1x1 root level.
   - a node stores the 8 heights of its children, h = 1 - depth rounded UP to
     16 bits (c / 65535, so a compressed bound never cuts off a hit); a
     node's own height is the max of its children's and lives in its parent.
   - 8-bit trees (node_bits 8) keep those 16-bit codes above level 1 and
     make each level-1 node one 32-bit word and a 16-bit scale: its 8
     texels' codes as 4-bit steps j down from the node's own height H (in
     its parent), code = H - ((j * scale) >> 4), the scale 16/15 of the
     node's spread, so step 15 lands on its lowest texel (section nodes:
     lrt__compact_steps). The scales follow the level's words. A far floor,
     whose 8 texels differ by a few 16-bit steps, keeps them exactly; a node
     across an edge (a pole or a slab over a floor) keeps its highest and
     lowest texels within one code; a node's update needs its 8 texels
     alone.
   - the texel level is not stored (its heights sit in the level-1 nodes), so
     the tree costs about 2.29 bytes per texel with 16-bit nodes and 1.04
     with 8-bit nodes (each level has 1/8 of the nodes of the one below): a
     stored leaf level of one height per texel would add 2 bytes more, so
     skipping it saves about half.
   - within a level, node (x,y) sits at its modified Morton code: for a level
     grouped 4x2 into its parent, (parent block index) << 3 | y0 x1 x0, for
     2x4, (parent block index) << 3 | y1 y0 x0, the parent block index being
     the block's row-major index in the parent level (with a power-of-two
     width that is the bit string y_n..y_1 | x_n..x_2 | y_0 x_1 x_0 and
     y_n..y_2 | x_n..x_1 | y_1 y_0 x_0 of the design). Levels are stored
     bottom-up, level 1 first, root last. lrt_layout_compute exposes it all.
   - sizes that are not multiples of the blocks are padded with height 0
     (depth 1) nodes; tracing never reports a padding texel.
   - node precision: LRT_NODE_BITS_AUTO picks 8 bits for 8-bit depth and 16
     for 16-bit and float depth. Hits are exact anyway: the last test of every
     candidate texel uses the true depth (read back from the depth map when
     the codes are not the input itself, e.g. float input, or any input in
     8-bit trees).


   WHAT IT DOES NOT DO
   - no GPU work of its own: it records into your command buffers and never
     submits, waits or owns a queue; no view-space rays (the caller clips them
     to the near plane and projects them to screen space); constant and
     relative thickness only under a perspective projection (near, far).


   LICENCE: MIT, at the end of this file.
*/
/* ---- the host/shader contract ---------------------------------- >>contract
   What the kernels (shaders/) and this file must agree on, written once and
   read by both compilers: a shader that defines LRT_GLSL and includes this
   file gets this block alone (shaders/lrt_common.glsl, and an engine's shader
   before shaders/linear_rt.glsl, as examples/vulkan_inline does). The C API
   takes its values from here; the C side checks the push constants' layout
   at compile time (section vulkan). Values carry a u: unsigned in both languages. */
#ifndef LINEAR_RT_CONTRACT
#define LINEAR_RT_CONTRACT
#define LRT_K_MAX_LEVELS 16u            /* stored levels never exceed this */
#define LRT_K_FORMAT_UNORM8 1u          /* lrt_format */
#define LRT_K_FORMAT_UNORM16 2u
#define LRT_K_FORMAT_FLOAT32 3u
#define LRT_K_DEPTH_REVERSED_Z 1u       /* lrt_depth.flags */
#define LRT_K_HIT 1u                    /* lrt_hit_kind */
#define LRT_K_MISS_TMAX 2u
#define LRT_K_MISS_OFF_SCREEN 3u
#define LRT_K_MISS_INVALID_RAY 4u
#define LRT_K_MISS_BUDGET 5u
#define LRT_K_HIT_ESTIMATE 6u
#define LRT_K_TRACE_BUDGET_MASK 0xffffu /* trace flags: bits 0-15, the step budget (0: none) */
#define LRT_K_TRACE_FINISH_SHIFT 16u    /* bits 16-19: a budget's finish, log2 of its samples + 1 (0: none) */
#define LRT_K_TRACE_FINISH_MASK 0xf0000u
#define LRT_K_FINISH_MAX 8u             /* the finish's field at most: 2^7 samples */
#define LRT_K_FINISH_BISECTIONS 8u      /* the finish's refinement, as the benchmark's marches' */
#define LRT_K_FACE_NONE 0u              /* lrt_hit_face */
#define LRT_K_FACE_TOP 1u
#define LRT_K_FACE_SIDE 2u
#define LRT_K_FACE_BACK 3u
#define LRT_K_FACE_INSIDE 4u
#define LRT_K_THICKNESS_INFINITE 0u     /* lrt_thickness */
#define LRT_K_THICKNESS_BACK_MAP 1u
#define LRT_K_THICKNESS_CONSTANT 2u
#define LRT_K_THICKNESS_RELATIVE 3u
#define LRT_K_VK_GROUP_SIZE 64u         /* invocations per workgroup, in x */
#define LRT_K_VK_BINDING_DEPTH_BUFFER 0u /* descriptor set 0 of the kernels */
#define LRT_K_VK_BINDING_DEPTH_IMAGE 1u
#define LRT_K_VK_BINDING_NODES 2u
#define LRT_K_VK_BINDING_COUNTERS 3u
#define LRT_K_VK_BINDING_RAYS 4u
#define LRT_K_VK_BINDING_HITS 5u
#define LRT_K_VK_BINDING_BACK_BUFFER 6u
#define LRT_K_VK_BINDING_BACK_IMAGE 7u
#define LRT_K_VK_BINDING_NODE_TEXELS 8u /* the nodes again, as R32G32B32A32_UINT texels: the trace's reads */
#define LRT_K_VK_BINDING_SCRATCH 9u     /* a compacted trace's lists (lrt_vk_cmd_trace_compacted) */
#define LRT_K_VK_TRACE_ROUNDS 8u        /* a compacted trace's dispatches: slices of 2, 4, ..., 128 cell */
#define LRT_K_VK_TRACE_SLICE 2u         /* steps, then no limit (bench/compaction.py chose them) */
/* The push constants of every kernel, in this order (92 bytes), U32 and
   F32 being the language's 32-bit unsigned and float types: the map
   (texels, format, flags, node bits, levels; a buffer depth's byte offset
   and row stride), the refit's texel rectangle (inclusive) and build flag
   (1: padding written too), the trace's first ray and count, trace flags
   (the step budget), a back-map tree's back map (byte offset, row stride), the tree's
   thickness model with lrt_layout.back_k, and a compacted trace's round and its slice of
   steps (0: no limit). */
#define LRT_K_VK_PUSH_CONSTANTS(U32, F32)                                             \
    U32 width, height, format, flags, node_bits, level_count, depth_offset, row_stride; \
    U32 rect_x0, rect_y0, rect_x1, rect_y1, build, ray_first, ray_count, trace_flags;   \
    U32 back_offset, back_row_stride, thickness;                                      \
    F32 back_k0, back_k1;                                                             \
    U32 trace_round, trace_slice;
#endif /* LINEAR_RT_CONTRACT */

#ifndef LRT_GLSL /* the rest is C */
#ifndef LINEAR_RT_H
#define LINEAR_RT_H

#include <stddef.h>
#include <stdint.h>

#ifndef LINEAR_RT_API
#ifdef LINEAR_RT_STATIC
#define LINEAR_RT_API static
#else
#define LINEAR_RT_API extern
#endif
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---- limits --------------------------------------------------------- >>api */
#define LINEAR_RT_MAX_DIM 16384u            /* largest width or height         */
#define LINEAR_RT_MAX_LEVELS LRT_K_MAX_LEVELS /* stored levels never exceed this */
#define LINEAR_RT_MAX_RAYS_PER_CALL (1u << 30) /* rays in one trace call       */

/* ---- result codes: every entry point returns one ------------------------- */
typedef enum lrt_result {
    LRT_SUCCESS = 0,
    LRT_ERROR_NULL_POINTER = 1,     /* a required pointer argument is NULL          */
    LRT_ERROR_INVALID_SIZE = 2,     /* width or height is 0 or above LINEAR_RT_MAX_DIM */
    LRT_ERROR_INVALID_STRIDE = 3,   /* row stride smaller than one row of texels    */
    LRT_ERROR_INVALID_FORMAT = 4,   /* depth format is not one of lrt_format        */
    LRT_ERROR_INVALID_OPTION = 5,   /* unknown flag bits, node bits not 0/8/16, a budget over 65535; GPU: a map
                                       both buffer and image, a back map an image where the depth is a buffer
                                       (or the reverse), an image layout not listed at lrt_vk_depth.layout,
                                       LRT_VK_BVH_HOST_VISIBLE with your own buffers */
    LRT_ERROR_SIZE_OVERFLOW = 6,    /* the map's byte span exceeds PTRDIFF_MAX      */
    LRT_ERROR_OUT_OF_MEMORY = 7,    /* the allocator returned NULL                  */
    LRT_ERROR_BUFFER_TOO_SMALL = 8, /* caller memory smaller than lrt_bvh_memory_size */
    LRT_ERROR_SIZE_MISMATCH = 9,    /* depth map size differs from the BVH's        */
    LRT_ERROR_INVALID_RECT = 10,    /* dirty rectangle reaches outside the map      */
    LRT_ERROR_TOO_MANY_RAYS = 11,   /* more than LINEAR_RT_MAX_RAYS_PER_CALL rays, or a bad range */
    LRT_ERROR_INVALID_BVH = 12,     /* the BVH was never built, or was destroyed (or is not zeroed memory
                                       nor a built tree: see lrt_bvh)               */
    LRT_ERROR_VULKAN = 13,          /* a Vulkan call failed: its VkResult is kept (lrt_vk_context_vk_result) */
    LRT_ERROR_NO_VULKAN_LOADER = 14, /* the Vulkan loader library could not be loaded */
    LRT_ERROR_NO_VULKAN_DEVICE = 15, /* no driver, or no device with what the kernels need */
    LRT_ERROR_MISSING_VULKAN_FEATURE = 16, /* a Vulkan version, extension, feature, layer or memory type is missing */
    LRT_ERROR_LIMIT_EXCEEDED = 17,  /* a device limit: storage buffer range, dispatch size, image size */
    LRT_ERROR_MISALIGNED = 18,      /* an offset or stride is not a multiple of the texel size or of
                                       the device's storage buffer offset alignment */
    LRT_ERROR_INVALID_CAMERA = 19,  /* a projection matrix with a non-finite entry or no inverse */
    LRT_ERROR_THICKNESS_MISMATCH = 20, /* a back map (lrt_depth.back) given to a tree without LRT_THICKNESS_BACK_MAP,
                                          none given to one with it, or a back map with a back of its own */
    LRT_ERROR_INVALID_THICKNESS = 21, /* an unknown thickness model, or a thickness or (near, far) the constant
                                         or relative model cannot use */
    LRT_ERROR_DEPTH_MISMATCH = 22,  /* the map's format or LRT_DEPTH_REVERSED_Z differs from the tree's (what
                                       it was built from), or the back map's from the depth's */
    LRT_ERROR_ALREADY_BUILT = 23,   /* build or create on a tree that is built: destroy it first */
    LRT_ERROR_CONTEXT_MISMATCH = 24, /* a GPU tree recorded with a context of another VkDevice than the one
                                        it was created with */
    LRT_RESULT_MAX_ENUM = 0x7fffffff
} lrt_result;

/* ---- depth in --------------------------------------------------------------- */
typedef enum lrt_format {
    LRT_FORMAT_UNORM8 = LRT_K_FORMAT_UNORM8,   /* uint8_t,  depth = v / 255   */
    LRT_FORMAT_UNORM16 = LRT_K_FORMAT_UNORM16, /* uint16_t, depth = v / 65535 */
    LRT_FORMAT_FLOAT32 = LRT_K_FORMAT_FLOAT32, /* float,    depth = v (clamped to [0,1], NaN -> 1) */
    LRT_FORMAT_MAX_ENUM = 0x7fffffff
} lrt_format;

/* lrt_depth.flags */
enum {
    LRT_DEPTH_REVERSED_Z = LRT_K_DEPTH_REVERSED_Z /* 1 is near, 0 is far */
};

/* A depth map in memory. The library cannot see your buffer's size: it
   reads row_stride * (height - 1) + width * texel bytes from data, so the
   stride and height you give must fit the buffer you own. */
typedef struct lrt_depth {
    const void *data;     /* first texel of row 0 (texel (x, y) covers [x, x+1] x [y, y+1]) */
    uint32_t width;       /* texels per row, 1..LINEAR_RT_MAX_DIM               */
    uint32_t height;      /* rows, 1..LINEAR_RT_MAX_DIM                         */
    size_t row_stride;    /* BYTES from one row to the next; 0 = tightly packed */
    lrt_format format;
    uint32_t flags;       /* LRT_DEPTH_* bits                                   */
    /* LRT_THICKNESS_BACK_MAP trees, and only they: each texel's back depth
       (a back-face depth pass), a map of the same width, height, format and
       flags with a row stride of its own and no back of its own; NULL
       otherwise. A back in front of the depth counts as the depth
       (docs/MODEL.md). */
    const struct lrt_depth *back;
} lrt_depth;

/* ---- level geometry and Morton mapping ------------------------------------- */
typedef struct lrt_level {
    uint32_t width, height;       /* nodes (texels at level 0) in this level's grid */
    uint32_t block_w, block_h;    /* how this level is grouped into its parents: 4x2 or 2x4 */
    uint32_t span_w_log2, span_h_log2; /* one node covers (1<<span_w) x (1<<span_h) texels */
    size_t offset;                /* first node of this level in the node array   */
    size_t count;                 /* node slots of this level, padding included   */
} lrt_level;

typedef struct lrt_layout {
    uint32_t width, height;       /* texels */
    uint32_t node_bits;           /* 8 or 16: the level-1 nodes' width (THE TREE) */
    uint32_t node_bytes;          /* a node above level 1: 8 children x 16 bits */
    uint32_t level_count;         /* stored levels: levels[1..level_count]; root = levels[level_count] */
    lrt_level levels[LINEAR_RT_MAX_LEVELS + 1]; /* levels[0]: the texels (not stored) */
    size_t node_count;            /* all node slots */
    uint32_t back_codes;          /* 1: a thickness model: each slot also has a back code (the deepest
                                     back depth under it), laid out as the heights, after them */
    size_t bytes;                 /* levels[1].count * level1_node_bytes + the other slots * node_bytes,
                                     twice that with back codes */
    uint32_t thickness;           /* lrt_thickness of the tree (set by the build options) */
    float back_k[2];              /* LRT_THICKNESS_CONSTANT: f / (f - n), T / n; RELATIVE: k f / (f - n),
                                     1 + k (in float: the kernels compute b(d) from the same two) */
    uint32_t level1_node_bytes;   /* 16, or 6: a compact level-1 node (node_bits 8, two levels or more):
                                     a word, and a scale after the level's words */
} lrt_layout;

enum { LRT_NODE_BITS_AUTO = 0 };

/* The tree's shape, a fixed function of (width, height, node_bits). node_bits
   0 means 16 here (the auto choice needs a format: see lrt_build_options). */
LINEAR_RT_API lrt_result lrt_layout_compute(uint32_t width, uint32_t height, uint32_t node_bits, lrt_layout *out);
/* Index within its level of node (x, y) at level 1..level_count (modified
   Morton code, see THE TREE). No range checks: x, y must lie in the level's
   padded grid. */
LINEAR_RT_API size_t lrt_layout_node_index(const lrt_layout *layout, uint32_t level, uint32_t x, uint32_t y);

/* ---- the BVH ----------------------------------------------------------------- */
typedef struct lrt_allocator {
    void *(*alloc)(void *user, size_t size);
    void (*free)(void *user, void *ptr);
    void *user;
} lrt_allocator;

/* What lies behind a texel's depth (docs/MODEL.md, thickness): by default the
   solid reaches the far plane; a tree with a thickness model ends each
   texel's box at a back depth b, d <= b <= 1, so rays pass behind objects.
   Such a tree holds a second code per child (the deepest back under it):
   twice the bytes. Three models:
   - CONSTANT: b is the depth of view distance z(d) + T, T = thickness_value
     in view-space units, under the perspective projection whose planes are
     near_z < far_z (view-space distances; far_z = INFINITY for an infinite
     far plane; lrt_camera_planes reads them from an lrt_camera). Depth is
     0 at near, 1 at far (reversed Z: the flag flips it first).
   - RELATIVE: the same with T = thickness_value * z(d).
   - BACK_MAP: b = max(d, back) from a second map (a back-face depth pass),
     given to build, update and trace by the depth's back pointer:
       lrt_depth back = {back_texels, w, h, 0, LRT_FORMAT_FLOAT32, 0, NULL};
       lrt_depth depth = {texels, w, h, 0, LRT_FORMAT_FLOAT32, 0, &back};
       lrt_bvh_build(&bvh, &depth, &options, NULL); ... lrt_trace(&bvh, &depth, ...);
   The first two need nothing but the depth: b is a function of d, computed
   in float by the same steps on the CPU and in the kernels. On the GPU the
   same options in lrt_vk_bvh_desc (a back map: two lrt_vk_depth, both
   buffers or both images, by lrt_vk_depth.back): the kernels answer as the
   CPU. */
typedef enum lrt_thickness {
    LRT_THICKNESS_INFINITE = LRT_K_THICKNESS_INFINITE, /* [depth, 1]: today's solid, the default */
    LRT_THICKNESS_BACK_MAP = LRT_K_THICKNESS_BACK_MAP, /* [depth, max(depth, back)] */
    LRT_THICKNESS_CONSTANT = LRT_K_THICKNESS_CONSTANT, /* [depth, depth of z(depth) + thickness_value] */
    LRT_THICKNESS_RELATIVE = LRT_K_THICKNESS_RELATIVE, /* [depth, depth of z(depth) * (1 + thickness_value)] */
    LRT_THICKNESS_MAX_ENUM = 0x7fffffff
} lrt_thickness;

typedef struct lrt_build_options {
    uint32_t node_bits;     /* LRT_NODE_BITS_AUTO (0), 8 or 16 */
    uint32_t thickness;     /* lrt_thickness */
    /* CONSTANT and RELATIVE only (else ignored), LRT_ERROR_INVALID_THICKNESS
       unless 0 < thickness_value, 0 < near_z < far_z, all finite but far_z
       (INFINITY allowed), and the model's two constants finite in float */
    float thickness_value;  /* T (view-space units) or k (a fraction of the view distance) */
    float near_z, far_z;    /* the perspective projection's near and far plane distances */
} lrt_build_options;

/* Zero-initialise one (lrt_bvh bvh = {0}; or memset) before its first
   build: build refuses a tree that is built (LRT_ERROR_ALREADY_BUILT:
   destroy it first, e.g. on a resize), so it never leaks or frees what is
   not its own. A tree carries a magic word from build to destroy; the
   other calls answer LRT_ERROR_INVALID_BVH without it. A copy of a built
   lrt_bvh (memcpy, by value) is the same tree, not a new one: destroy one
   of them only. */
typedef struct lrt_bvh {     /* fields are read-only to callers */
    lrt_layout layout;
    void *nodes;             /* layout.bytes: levels bottom-up, 8 heights per node */
    lrt_allocator allocator; /* how nodes were allocated; alloc == NULL: caller-owned */
    uint32_t built;          /* LRT__BUILT (a magic word) between build and destroy, else 0 */
    lrt_format format;       /* what the tree was built from: every later map must agree */
    uint32_t depth_flags;    /*   (its LRT_DEPTH_REVERSED_Z bit too): LRT_ERROR_DEPTH_MISMATCH */
} lrt_bvh;

/* Bytes lrt_bvh_build_in needs for a map of this size and format (the
   nodes plus 15 bytes to align memory of any alignment). */
LINEAR_RT_API lrt_result lrt_bvh_memory_size(uint32_t width, uint32_t height, lrt_format format,
                                             const lrt_build_options *options, size_t *out_bytes);
/* Build once per map size: lays out the tree and fills it from depth.
   options and allocator may be NULL (defaults; LINEAR_RT_MALLOC). *bvh
   must be zeroed or destroyed (else LRT_ERROR_ALREADY_BUILT). On error
   *bvh is left untouched and nothing is allocated. */
LINEAR_RT_API lrt_result lrt_bvh_build(lrt_bvh *bvh, const lrt_depth *depth,
                                       const lrt_build_options *options, const lrt_allocator *allocator);
/* The same into caller-owned memory of at least lrt_bvh_memory_size bytes
   (any alignment); destroy leaves that memory alone. */
LINEAR_RT_API lrt_result lrt_bvh_build_in(lrt_bvh *bvh, const lrt_depth *depth,
                                          const lrt_build_options *options, void *memory, size_t memory_bytes);
/* Frees what build allocated; safe on a zeroed or destroyed lrt_bvh. */
LINEAR_RT_API void lrt_bvh_destroy(lrt_bvh *bvh);

typedef struct lrt_rect { uint32_t x, y, width, height; } lrt_rect; /* texels */

/* Refit every height from depth (dirty == NULL) or only the nodes above the
   texels of *dirty, bottom-up to the root. Heights may go up or down; the
   result is byte-for-byte a fresh build of the same depth map provided the
   depth changed only inside dirty. An empty rect does nothing. */
LINEAR_RT_API lrt_result lrt_bvh_update(lrt_bvh *bvh, const lrt_depth *depth, const lrt_rect *dirty);

/* ---- traversal ------------------------------------------------------------- */
typedef struct lrt_ray {     /* screen space; 8 floats, the same layout as the GPU's */
    float origin[3];         /* x, y in texels, z depth (0 near)              */
    float tmin;              /* 0 <= tmin <= tmax                             */
    float dir[3];            /* need not be normalised; may be 0              */
    float tmax;
} lrt_ray;

typedef enum lrt_hit_kind {
    LRT_HIT = LRT_K_HIT,                           /* t and texel x, y are set */
    LRT_MISS_TMAX = LRT_K_MISS_TMAX,               /* reached tmax on screen without touching the solid */
    LRT_MISS_OFF_SCREEN = LRT_K_MISS_OFF_SCREEN,   /* left (or never met) the screen rectangle: fall back */
    LRT_MISS_INVALID_RAY = LRT_K_MISS_INVALID_RAY, /* NaN/inf component, tmin < 0 or tmin > tmax: not traced */
    LRT_MISS_BUDGET = LRT_K_MISS_BUDGET,           /* the step budget ran out: no hit before t (LRT_TRACE_BUDGET) */
    LRT_HIT_ESTIMATE = LRT_K_HIT_ESTIMATE,         /* the budget ran out, its finish guessed: texel x, y at t (LRT_TRACE_FINISH) */
    LRT_HIT_KIND_MAX_ENUM = 0x7fffffff
} lrt_hit_kind;

/* Where a hit lies on its texel's box [x, x+1] x [y, y+1] x [depth, back]
   (back = 1 without a back map; docs/MODEL.md, "the face of a hit"): on the
   top, a surface the camera sees; on a side or the back (z = back, met by
   a ray coming from behind it), which the camera does not see, where an
   engine may fall back; or inside: the origin at tmin already in the
   solid. On an edge shared by faces any of them is right; ties are told
   as top, then side, then back. */
typedef enum lrt_hit_face {
    LRT_FACE_NONE = LRT_K_FACE_NONE,     /* a miss */
    LRT_FACE_TOP = LRT_K_FACE_TOP,       /* on z = depth of the texel */
    LRT_FACE_SIDE = LRT_K_FACE_SIDE,     /* on x = x, x + 1 or y = y, y + 1 */
    LRT_FACE_BACK = LRT_K_FACE_BACK,     /* on z = back (1 without a back map), entered from behind */
    LRT_FACE_INSIDE = LRT_K_FACE_INSIDE  /* the origin at tmin, inside the box: t = tmin */
} lrt_hit_face;

typedef struct lrt_hit {
    float t;                 /* hit at origin + t * dir; 0 on a miss */
    uint32_t x, y;           /* texel hit; 0 on a miss */
    uint16_t kind;           /* lrt_hit_kind */
    uint16_t face;           /* lrt_hit_face */
} lrt_hit;

/* Trace flags: 0 for the exact walk, or LRT_TRACE_BUDGET(steps) (any other
   bit is LRT_ERROR_INVALID_OPTION).
   LRT_TRACE_BUDGET(steps), 1 <= steps <= LRT_TRACE_BUDGET_MAX: each ray's
   walk takes at most `steps` steps. In a tree without a thickness model a
   step is the GPU's: one cell or texel tested (the cell walk of section
   walk-cells, which every ordinary ray takes there); otherwise, and for a
   ray in a plane of the texel grid or at the edge of float range, a node
   test of the 8-child walk (a level-1 node's 8 texels are one test; a
   camera ray inside one texel column takes none). A ray that would
   need more stops with LRT_MISS_BUDGET and t set to where its segment is
   proven free: no texel is hit at any t' < t (lrt_trace without a budget
   would return no hit before t), so an engine can fall back, or march on
   from there. x, y are 0 and face LRT_FACE_NONE. Every other answer is
   the exact one lrt_trace gives without a budget: a hit is the closest.
   A budgeted walk is the GPU kernels' walk step for step (from the
   origin), so that lrt_vk_cmd_trace counts the same steps and gives the
   same answers bit for bit; LRT_TRACE_BUDGET(0) is 0, no budget.
   LRT_TRACE_BUDGET(steps) | LRT_TRACE_FINISH(n), 0 <= n <= 7: a ray the
   budget stops gets a finish, a march from the proven-free t to the
   segment's end: 2^n + 1 samples 2^-n of it apart, each the texel under
   the point and its exact test at that t, and at the first sample inside
   the solid LRT_K_FINISH_BISECTIONS bisections with the sample before it.
   It answers LRT_HIT_ESTIMATE: a guess, the texel x, y under the last
   sample inside and its t (never before the proven-free t), face the top
   where that texel is the one the ray was over just before (the back for
   v.z < 0), else a side. Its point is in the solid, so the ray hits at or
   before it; but a march can step over a thin object or a corner, so the
   closest hit may lie before it, on another texel (docs/MODEL.md). Where no sample is inside, LRT_MISS_BUDGET as without
   a finish: an engine takes it as a miss, of the kind its ray's point at
   tmax tells (on the screen: LRT_MISS_TMAX). Every other answer stays the
   exact one, bit for bit, and the GPU's finish is this one step for step.
   A finish without a budget is LRT_ERROR_INVALID_OPTION.
   There is no any-hit mode: the walk visits children front to back and
   stops at its first texel hit, which is the closest, so occlusion rays
   (AO, shadows) take the same call; an any-hit flag that changed nothing
   was taken out (a node bound on what is certainly solid, which could end
   occlusion rays higher in the tree, is not built). */

/* Trace count rays into hits (one lrt_hit per ray). depth must be the map
   the BVH was last built or updated from (its size, format, flags and back
   map are checked against the tree's; its contents cannot be). At most LINEAR_RT_MAX_RAYS_PER_CALL
   (2^30) rays a call: a larger count is LRT_ERROR_TOO_MANY_RAYS, returned
   before any ray is read or hit written. */
#define LRT_TRACE_BUDGET_MAX 65535u
#define LRT_TRACE_BUDGET(steps) ((uint32_t)(steps))
#define LRT_TRACE_FINISH(n) (((uint32_t)(n) + 1u) << LRT_K_TRACE_FINISH_SHIFT) /* 2^n + 1 samples, n <= 7 */
LINEAR_RT_API lrt_result lrt_trace(const lrt_bvh *bvh, const lrt_depth *depth, const lrt_ray *rays,
                                   lrt_hit *hits, size_t count, uint32_t flags);
/* Trace rays[first .. end-1] into hits[first .. end-1]: split a batch across
   threads with disjoint ranges. first > end, or more than
   LINEAR_RT_MAX_RAYS_PER_CALL rays: LRT_ERROR_TOO_MANY_RAYS. */
LINEAR_RT_API lrt_result lrt_trace_range(const lrt_bvh *bvh, const lrt_depth *depth, const lrt_ray *rays,
                                         lrt_hit *hits, size_t first, size_t end, uint32_t flags);
/* Which CPU walk lrt_trace runs here: "avx2", "sse2" or "scalar" as the
   build chose, or "avx2 (chosen at run time)" / "sse2 (chosen at run time)"
   where a plain x86-64 build probes the CPU (OPTIONS). A static string. */
LINEAR_RT_API const char *lrt_cpu_path(void);

/* ---- rays from a camera (optional helpers) ---------------------------------
   An engine has view-space rays (a reflection, an AO or a shadow ray from a
   surface point); the tracer takes screen-space segments (docs/MODEL.md). These
   helpers are the set-up every engine would write the same way: a view-space
   point from a texel's depth, and a view-space segment clipped to the near
   and far planes and projected.
   Conventions: the projection maps view space to Vulkan clip space (x, y, z,
   w), 0 <= z <= w between the planes; column-major, m[col * 4 + row] (as
   GLSL stores it); NDC y = -1 is row 0 (Vulkan's viewport). So screen x =
   (ndc.x + 1) / 2 * width, y = (ndc.y + 1) / 2 * height, z = ndc.z, or
   1 - ndc.z with LRT_DEPTH_REVERSED_Z (screen z is always 0 near, as the
   tracer's). Perspective and orthographic projections both work. */
typedef struct lrt_camera {
    float proj[16];          /* view -> clip, column-major */
    float inv_proj[16];      /* clip -> view */
    uint32_t width, height;  /* the depth map's size in texels */
    uint32_t flags;          /* LRT_DEPTH_REVERSED_Z: the projection puts near at z = 1 */
} lrt_camera;

/* A perspective projection in these conventions: right-handed view space
   looking down -z with y up, the vertical field of view in RADIANS (0 < fov
   < pi), aspect = width / height (finite, > 0), 0 < near_z < far_z (far_z
   = INFINITY: an infinite far plane); flags LRT_DEPTH_REVERSED_Z or 0.
   LRT_ERROR_INVALID_CAMERA for values outside those (NaN too) and
   LRT_ERROR_INVALID_OPTION for other flags; out is then left alone. */
LINEAR_RT_API lrt_result lrt_perspective(float out[16], float fov_y_radians, float aspect, float near_z, float far_z,
                                         uint32_t flags);
/* Keeps the projection and its inverse. LRT_ERROR_INVALID_CAMERA for a
   matrix with a non-finite entry or no inverse, or a perspective one (w =
   -c z_view, c > 0) whose planes are not 0 < near < far as the flags read
   them (e.g. near and far swapped); LRT_ERROR_INVALID_SIZE,
   LRT_ERROR_INVALID_OPTION (flags other than LRT_DEPTH_REVERSED_Z). */
LINEAR_RT_API lrt_result lrt_camera_init(lrt_camera *camera, const float projection[16], uint32_t width,
                                         uint32_t height, uint32_t flags);
/* The view-space point at screen point (x, y, depth); 0 when there is none
   (the point is at infinity, or a value is not finite). */
LINEAR_RT_API int lrt_camera_unproject(const lrt_camera *camera, const float screen[3], float view[3]);
/* The screen point of a view-space point; 0 for a point at or behind the eye
   (clip w <= 0) or a non-finite result. */
LINEAR_RT_API int lrt_camera_project(const lrt_camera *camera, const float view[3], float screen[3]);
/* The screen-space ray of the view-space segment from -> to, clipped to the
   near and far planes: origin = screen point of the clipped start, dir = the
   clipped end's screen point - origin, [tmin, tmax] = [0, 1]; t of a hit is
   then a screen-space parameter (lrt_camera_unproject the hit point for its
   view-space position). Returns 1, or 0 when no part of the segment lies
   between the planes or a value is not finite; *ray is then an invalid ray
   (NaN origin), which lrt_trace answers with LRT_MISS_INVALID_RAY.
   A ray leaving a visible surface takes lrt_camera_surface_ray below. */
LINEAR_RT_API int lrt_camera_segment(const lrt_camera *camera, const float from[3], const float to[3],
                                     lrt_ray *ray);
/* THE LIFT (self-intersection; the tracer itself has no policy). A ray
   leaving the visible surface at texel (x, y) starts on that texel's flat
   top (docs/MODEL.md), and the texels around stand up to half their depth
   step above the true surface between them: such a ray would hit its own
   surface's stairs. The recipe, whatever gave the normal (depth, a
   G-buffer, the renderer's own): lower the ray's screen-space origin z
   (move it towards the eye) by lrt_surface_lift(step_x, step_y), where
   step_x and step_y are the depth steps from the texel to its neighbours on
   its own surface, one on each axis (of the two, the one whose line through
   the next texel meets the texel's depth; the larger where both do), each
   plus its change to the next texel (at most the step itself: a curved
   surface's tops stand out more further along; examples/surface.h does it),
   give lrt_camera_surface_ray the normal, and start at tmin = 0.
   lrt_surface_lift = 0.5 * (|step_x| + |step_y|) * 1.01 + 1e-7: half the
   slope, 1% and a hair for rounding. Steps of 0 (no neighbour) leave the
   stairs around the texel uncleared. */
LINEAR_RT_API float lrt_surface_lift(float step_x, float step_y);
/* lrt_camera_segment(from, to), its origin then lifted by at least `lift`
   (lrt_surface_lift): the screen ray of a reflection, AO or shadow ray
   from the view-space surface point `from` with the view-space normal
   `normal` (NULL for none). It lifts more where
   - the normal's tangent plane is steeper on screen than the steps say (a
     curved surface turning away, a silhouette): by lrt_surface_lift of that
     plane's depth steps, at most 8 times `lift` (at a silhouette the slope
     grows without bound);
   - the ray itself would sink into its own texel's top before it leaves the
     texel (a normal that tilts it away from the eye).
   A ray whose end lies on the far plane is lengthened along its own line
   until, lifted, it reaches the far plane again, so that a ray to the sky
   hits the sky texel's top at depth 1, as the model has it. Returns as
   lrt_camera_segment. A ray that leaves the true surface (above its
   tangent plane) then never meets that surface on a convex object or a
   plane (tests/test_lift.c, every normal source); one that a wrong normal
   sends into it (depth normals at an edge, a quantised normal at a grazing
   angle) meets it, as it should. */
LINEAR_RT_API int lrt_camera_surface_ray(const lrt_camera *camera, const float from[3], const float normal[3],
                                         const float to[3], float lift, lrt_ray *ray);
/* The near and far plane distances of a perspective camera (far: INFINITY
   for an infinite far plane), for lrt_build_options' constant and relative
   thickness. Returns 0 (and leaves them alone) for an orthographic or
   otherwise non-perspective projection, or planes not 0 < near < far. */
LINEAR_RT_API int lrt_camera_planes(const lrt_camera *camera, float *near_z, float *far_z);

/* ---- helpers ----------------------------------------------------------------- */
LINEAR_RT_API const char *lrt_result_string(lrt_result result);

#ifdef __cplusplus
}
#endif
#endif /* LINEAR_RT_H */

/* ============================================================================
   The Vulkan API (define LINEAR_RT_VULKAN before including).  >>vulkan-api
   It has its own include guard, so a file may include linear_rt.h first
   without it and again with it.
   ========================================================================== */
#if defined(LINEAR_RT_VULKAN) && !defined(LINEAR_RT_VULKAN_H)
#define LINEAR_RT_VULKAN_H
#include <vulkan/vulkan.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- what a device needs --------------------------------------------------- */
/* Everything the embedded kernels need from the device, read from their
   SPIR-V: enable these when you create your VkDevice. lrt_vk_context_create
   checks that the physical device supports them (it cannot see what you
   enabled). */
typedef struct lrt_vk_requirements {
    uint32_t api_version;                 /* VK_API_VERSION_1_2: instance and device at least this */
    uint32_t extension_count;             /* device extensions to enable: */
    const char *extensions[1];            /*   VK_KHR_push_descriptor */
    /* VkPhysicalDeviceFeatures */
    VkBool32 shader_float64, shader_int64, shader_int16;
    /* VkPhysicalDeviceVulkan11Features */
    VkBool32 storage_buffer_16bit_access;
    /* VkPhysicalDeviceVulkan12Features */
    VkBool32 shader_int8, shader_float16, storage_buffer_8bit_access, shader_buffer_int64_atomics;
    VkBool32 vulkan_memory_model, vulkan_memory_model_device_scope;
    /* VkPhysicalDeviceVulkan11Properties::subgroupSupportedOperations, in compute */
    VkSubgroupFeatureFlags subgroup_operations;
} lrt_vk_requirements;

LINEAR_RT_API lrt_result lrt_vk_get_requirements(lrt_vk_requirements *out);

/* ---- the context: pipelines of the embedded kernels, in your device -------- */
typedef struct lrt_vk_context_desc {
    VkInstance instance;                        /* required */
    VkPhysicalDevice physical_device;           /* required */
    VkDevice device;                            /* required: with the requirements above enabled */
    PFN_vkGetInstanceProcAddr get_instance_proc_addr; /* required: every function pointer comes from it */
    PFN_vkGetDeviceProcAddr get_device_proc_addr;     /* optional: else from get_instance_proc_addr */
    const VkAllocationCallbacks *allocation_callbacks; /* optional: for the Vulkan objects and the
                                                   context's own memory (VK_SYSTEM_ALLOCATION_SCOPE_OBJECT);
                                                   copied, need not outlive the call */
    VkPipelineCache pipeline_cache;             /* optional: used while the context lives (pipelines
                                                   are made on first use) */
    VkResult *vk_result;                        /* optional: where a failing Vulkan call's VkResult
                                                   is written when create returns LRT_ERROR_VULKAN */
    uint32_t flags;                             /* 0, or one of lrt_vk_context_flags */
} lrt_vk_context_desc;

/* How lrt_vk_cmd_trace runs. By default in two passes on a GPU (the
   ordinary rays, then the few at the edge of float range: the GPU's kernel
   then holds none of their code) and in one on a CPU device such as
   lavapipe, which has no registers or occupancy to gain and pays for the
   second pass. Either can be asked for (the tests run both). */
typedef enum lrt_vk_context_flags {
    LRT_VK_TRACE_TWO_PASSES = 1u << 0,
    LRT_VK_TRACE_ONE_PASS = 1u << 1
} lrt_vk_context_flags;

typedef struct lrt_vk_context lrt_vk_context; /* opaque; immutable after create */

/* Loads the device functions, checks the device (Vulkan 1.2, the push
   descriptor extension, the features of lrt_vk_get_requirements) and creates
   one descriptor set layout (push descriptors), one pipeline layout (92 bytes
   of push constants) and one sampler. Its 32 compute pipelines (refit,
   the trace's ordinary pass, rare pass, one pass and budgeted pass, of
   buffer and of image depth, for infinite trees and for trees with a
   thickness model of 16-bit and of 8-bit nodes; and a compacted round of
   each depth source for infinite trees: shaders/README.md) are made on
   first use by the lrt_vk_cmd_* that needs one,
   before it records anything (a failure there: LRT_ERROR_VULKAN and
   lrt_vk_context_vk_result), so a program compiles only the kernels its
   trees and maps take: on lavapipe about half a second for each trace
   pipeline. (Built by a compiler without GCC's atomic builtins, create makes
   all 32.) desc->flags other than lrt_vk_context_flags, or both of them:
   LRT_ERROR_INVALID_OPTION. The trace pipelines read the nodes through
   lrt_vk_bvh.node_texels where maxTexelBufferElements holds every tree the
   device can trace, else through the storage buffer. On error *out is
   untouched and nothing is left created. */
LINEAR_RT_API lrt_result lrt_vk_context_create(const lrt_vk_context_desc *desc, lrt_vk_context **out);
/* Destroys what create made. The caller makes sure the GPU no longer uses
   it (no command buffer recorded with it is pending). NULL is fine. */
LINEAR_RT_API void lrt_vk_context_destroy(lrt_vk_context *ctx);
/* The VkResult of the last Vulkan call that made a function of this context
   return LRT_ERROR_VULKAN (VK_SUCCESS if none; written unsynchronised by
   lrt_vk_bvh_create, the only one that can fail so after create). */
LINEAR_RT_API VkResult lrt_vk_context_vk_result(const lrt_vk_context *ctx);

/* ---- a BVH in GPU memory ------------------------------------------------------ */
enum {
    /* lrt_vk_bvh_desc.flags: library memory must be HOST_VISIBLE | HOST_COHERENT
       (preferably DEVICE_LOCAL too) and lrt_vk_bvh.mapped points at the nodes:
       for tests and tools that read the tree back */
    LRT_VK_BVH_HOST_VISIBLE = 1u
};

typedef struct lrt_vk_bvh_desc {
    uint32_t width, height;      /* texels, 1..LINEAR_RT_MAX_DIM */
    lrt_format format;           /* of the depth it will be built from: picks the node bits; every
                                    map recorded with the tree must have it (LRT_ERROR_DEPTH_MISMATCH) */
    lrt_build_options options;   /* node_bits: LRT_NODE_BITS_AUTO (0), 8 or 16, as lrt_bvh_build */
    uint32_t flags;              /* LRT_VK_BVH_* */
    uint32_t depth_flags;        /* LRT_DEPTH_REVERSED_Z or 0: the Z direction of the maps it is built
                                    from; every map recorded with the tree must have it */
    /* Your buffers (both set), or none (both VK_NULL_HANDLE: the library makes
       one buffer for both). Sizes from lrt_vk_bvh_buffer_sizes; usage
       STORAGE_BUFFER for both, UNIFORM_TEXEL_BUFFER for the nodes (the trace
       kernel reads them through lrt_vk_bvh.node_texels) and TRANSFER_DST for
       the counters (build fills them with 0); offsets multiples of
       minStorageBufferOffsetAlignment, of minTexelBufferOffsetAlignment and
       of 4. */
    VkBuffer nodes;
    VkDeviceSize nodes_offset;
    VkBuffer counters;
    VkDeviceSize counters_offset;
} lrt_vk_bvh_desc;

typedef struct lrt_vk_bvh {      /* fields are read-only to callers */
    lrt_layout layout;           /* the very layout of the CPU's lrt_bvh */
    VkBuffer nodes;              /* layout.bytes at nodes_offset: the CPU's node array, byte for byte */
    VkDeviceSize nodes_offset;
    VkBuffer counters;           /* 4 bytes per node slot: the refit's arrival counters, 0 between
                                    commands (library-made: the nodes' buffer, after the nodes) */
    VkDeviceSize counters_offset;
    VkDeviceSize counters_bytes;
    VkDeviceMemory memory;       /* library-made memory; VK_NULL_HANDLE with your buffers */
    VkBufferView node_texels;    /* the nodes as R32G32B32A32_UINT texels (the first
                                    maxTexelBufferElements of them): llvmpipe reads a texel
                                    buffer without a branch per lane, a storage buffer not */
    void *mapped;                /* the nodes in host memory when the library's memory is
                                    HOST_VISIBLE | HOST_COHERENT (always with LRT_VK_BVH_HOST_VISIBLE),
                                    else NULL; read after the HOST barrier of BARRIERS and the fence */
    uint32_t created;            /* a magic word between create and destroy, else 0 (zero it before
                                    create, as lrt_bvh: create refuses a created one) */
    lrt_format format;           /* the desc's format and depth_flags: every map must agree */
    uint32_t depth_flags;
    VkDevice device;             /* the context's device at create: every command needs a context of it
                                    (else LRT_ERROR_CONTEXT_MISMATCH) */
    uint32_t build_recorded;     /* set by lrt_vk_cmd_build: update and trace need it (else
                                    LRT_ERROR_INVALID_BVH); it says recorded, not yet run */
} lrt_vk_bvh;

/* Bytes of the node and counter ranges of a map of this size and format. */
LINEAR_RT_API lrt_result lrt_vk_bvh_buffer_sizes(uint32_t width, uint32_t height, lrt_format format,
                                                 const lrt_build_options *options, VkDeviceSize *out_nodes_bytes,
                                                 VkDeviceSize *out_counters_bytes);
/* Lays out the tree, binds (or creates) its buffers and makes the nodes'
   texel view; records nothing: the tree is filled by lrt_vk_cmd_build.
   *out must be zeroed or destroyed (else LRT_ERROR_ALREADY_BUILT).
   Library memory: DEVICE_LOCAL preferred, else HOST_VISIBLE. A node or
   counter range past the device's maxStorageBufferRange (a 16384x16384 map
   has 585 MiB of 16-bit nodes) is LRT_ERROR_LIMIT_EXCEEDED. On error *out
   is untouched and nothing is left created. */
LINEAR_RT_API lrt_result lrt_vk_bvh_create(lrt_vk_context *ctx, const lrt_vk_bvh_desc *desc, lrt_vk_bvh *out);
/* Frees what create made (never your buffers); safe on a zeroed or
   destroyed lrt_vk_bvh. The GPU must be done with it. */
LINEAR_RT_API void lrt_vk_bvh_destroy(lrt_vk_context *ctx, lrt_vk_bvh *bvh);

/* ---- depth on the GPU ---------------------------------------------------------- */
typedef struct lrt_vk_depth {
    lrt_format format;           /* as lrt_depth; images: see view */
    uint32_t flags;              /* LRT_DEPTH_REVERSED_Z */
    uint32_t width, height;      /* must equal the BVH's */
    /* either a storage buffer (usage STORAGE_BUFFER) ... */
    VkBuffer buffer;
    VkDeviceSize offset;         /* byte of texel (0,0): a multiple of the texel size */
    VkDeviceSize row_stride;     /* bytes from row to row, 0 = packed: a multiple of the texel size.
                                    The buffer must hold the map's bytes rounded up to a multiple
                                    of 4 past the last texel (the kernels read 32-bit words). */
    /* ... or a sampled image view (buffer = VK_NULL_HANDLE), level 0 read with
       texelFetch: format D32_SFLOAT or R32_SFLOAT for LRT_FORMAT_FLOAT32,
       D16_UNORM or R16_UNORM for UNORM16, R8_UNORM for UNORM8 (the view's
       format cannot be queried: it is your promise); depth formats with the
       DEPTH aspect only; usage SAMPLED */
    VkImageView view;
    VkImageLayout layout;        /* SHADER_READ_ONLY_OPTIMAL, GENERAL, DEPTH_STENCIL_READ_ONLY_OPTIMAL,
                                    DEPTH_READ_ONLY_OPTIMAL or READ_ONLY_OPTIMAL */
    /* LRT_THICKNESS_BACK_MAP trees, and only they: the back map, as lrt_depth.back (same
       width, height, format, flags, a buffer if the depth is one, an image if it is one;
       no back of its own); NULL otherwise */
    const struct lrt_vk_depth *back;
} lrt_vk_depth;

/* ---- recording ------------------------------------------------------------------------
   Each records into your command buffer (in the recording state, on a queue
   with compute): binds its pipeline, pushes its descriptors and constants,
   dispatches. It records no barrier except build's one between its fill of
   the counters and its dispatch: see BARRIERS at the top of the file for
   those you record. Every argument is checked first: on an error nothing is
   recorded. The device's limits are arguments too: a node, counter, depth,
   ray or hit range past maxStorageBufferRange, a dispatch past
   maxComputeWorkGroupCount, or an image depth past maxImageDimension2D is
   LRT_ERROR_LIMIT_EXCEEDED. The command buffer's compute pipeline, push
   descriptors and push constants are left changed. */

/* BuildBVH: fills the counters with 0, then refits every node from depth
   (padding too). Once after create, before any update or trace: it marks
   the tree (build_recorded), and update and trace of a tree whose build was
   never recorded are LRT_ERROR_INVALID_BVH. Every command takes a context
   of the device the tree was created on (else LRT_ERROR_CONTEXT_MISMATCH). */
LINEAR_RT_API lrt_result lrt_vk_cmd_build(lrt_vk_context *ctx, VkCommandBuffer cmd, lrt_vk_bvh *bvh,
                                          const lrt_vk_depth *depth);
/* UpdateBVH: refits the nodes above the texels of *dirty (NULL: the whole
   map), bottom-up to the root, in one dispatch; byte-for-byte a fresh build
   when depth changed only inside dirty. An empty rect records nothing. */
LINEAR_RT_API lrt_result lrt_vk_cmd_update(lrt_vk_context *ctx, VkCommandBuffer cmd, const lrt_vk_bvh *bvh,
                                           const lrt_vk_depth *depth, const lrt_rect *dirty);
/* Traces count lrt_ray at rays_offset into count lrt_hit at hits_offset
   (storage buffers), flags as lrt_trace's (0, or LRT_TRACE_BUDGET(steps): the
   same steps, the same answers bit for bit), one invocation per ray, in
   two dispatches on a GPU (lrt_vk_context_flags): the ordinary pass traces
   every ray but those at the edge of float range (lrt__setup_rare's) and
   marks their hits; after a barrier the rare pass traces the marked ones.
   The ordinary kernel so carries none of the rare set-up's code (a fifth
   of the instructions on a GPU, `make gpu-stats`). Offsets: multiples of minStorageBufferOffsetAlignment; else the library
   binds lower and starts at a later ray, which works when the two offsets
   are the same ray index away from aligned offsets (a slice [first, end) of
   rays and hits arrays that start aligned always is). count 0 records
   nothing; more than LINEAR_RT_MAX_RAYS_PER_CALL is LRT_ERROR_TOO_MANY_RAYS,
   and more rays than maxStorageBufferRange / 32 bytes hold (4 Mi rays in
   lavapipe's 128 MiB) LRT_ERROR_LIMIT_EXCEEDED. */
LINEAR_RT_API lrt_result lrt_vk_cmd_trace(lrt_vk_context *ctx, VkCommandBuffer cmd, const lrt_vk_bvh *bvh,
                                          const lrt_vk_depth *depth, VkBuffer rays, VkDeviceSize rays_offset,
                                          VkBuffer hits, VkDeviceSize hits_offset, uint32_t count, uint32_t flags);

/* A compacted trace: lrt_vk_cmd_trace's answers, bit for bit, in rounds
   that each run only the rays left, in full waves, so that a wave does not
   wait for its slowest ray. Round 0 walks every ray for at most
   LRT_K_VK_TRACE_SLICE cell steps; a ray not done is listed (an atomic
   counter) with its walk's state, and the next round, an indirect
   dispatch, resumes only the listed ones for twice the slice, and so on;
   the last of LRT_K_VK_TRACE_ROUNDS rounds has no limit. Then the rare
   pass. The lists live in scratch you provide, so that a frame's memory is
   planned, as an acceleration structure's build takes scratch:
   lrt_vk_trace_scratch_size(count) bytes at scratch->offset (a multiple of
   minStorageBufferOffsetAlignment) of a buffer of usage STORAGE_BUFFER,
   INDIRECT_BUFFER and TRANSFER_DST, which the trace overwrites (it records
   its own barriers around it; the caller's BARRIERS for rays and hits are
   lrt_vk_cmd_trace's). More than 4194240 rays are traced in turns of that
   many, the scratch used again. A tree with a thickness model (its walk is
   the 8-child walk) and a one-pass context (a CPU device: lavapipe, where
   rounds only add dispatches) are traced as lrt_vk_cmd_trace traces them,
   the scratch untouched. Errors: lrt_vk_cmd_trace's; a NULL scratch or
   buffer LRT_ERROR_NULL_POINTER, a misaligned offset LRT_ERROR_MISALIGNED,
   a size below the one needed LRT_ERROR_BUFFER_TOO_SMALL. */
typedef struct lrt_vk_scratch {
    VkBuffer buffer;
    VkDeviceSize offset, size;
} lrt_vk_scratch;
LINEAR_RT_API VkDeviceSize lrt_vk_trace_scratch_size(uint32_t count);
LINEAR_RT_API lrt_result lrt_vk_cmd_trace_compacted(lrt_vk_context *ctx, VkCommandBuffer cmd, const lrt_vk_bvh *bvh,
                                                    const lrt_vk_depth *depth, VkBuffer rays, VkDeviceSize rays_offset,
                                                    VkBuffer hits, VkDeviceSize hits_offset, uint32_t count,
                                                    uint32_t flags, const lrt_vk_scratch *scratch);

#ifdef __cplusplus
}
#endif
#endif /* LINEAR_RT_VULKAN_H */

/* ======================================================================= >>impl
   The implementation. First its configuration and the ISA prelude: the one
   place that decides which SIMD paths are compiled.
   ========================================================================== */
#ifdef LINEAR_RT_IMPLEMENTATION
#ifndef LRT__AVX2_PASS
/* Floating-point rules. The answers are exact, and equal to the kernels' bit
   for bit, only if every float operation is the IEEE one written: no
   reassociation, no contraction into fma, no reciprocal in place of a
   division, signed zeros, infinities and NaNs kept. An engine may build
   this translation unit with -ffast-math, -Ofast, GNU C's default
   -ffp-contract=fast or MSVC's /fp:fast; the implementation restores the
   rules for its own code, whatever the command line, and hands the
   includer's back at its end (make test builds it under each: the same
   bytes). Subnormals flushed by the includer's start-up code (fast-math's
   FTZ / DAZ) change nothing: the model reads them as 0 (docs/MODEL.md). */
#include <float.h>
/* 16 and 32 (ISO/IEC TS 18661-3) evaluate float as float too: GCC says 16
   where the target has AVX512-FP16 (-march=native on Sapphire Rapids), for
   _Float16 only */
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD != 0 && FLT_EVAL_METHOD != 16 && FLT_EVAL_METHOD != 32
#error "linear_rt.h: floats evaluated in a wider format (FLT_EVAL_METHOD 1, 2 or -1: x87 math, e.g. gcc -m32 without -mfpmath=sse) change its answers: build this file with -msse2 -mfpmath=sse"
#endif
#if defined(__clang__) && ((defined(__apple_build_version__) && __clang_major__ < 13) || __clang_major__ < 12)
/* before float_control (clang 12, Apple clang 13) only contraction can be undone */
#if defined(__FAST_MATH__) || defined(__FINITE_MATH_ONLY__)
#error "linear_rt.h: this clang cannot undo -ffast-math / -ffinite-math-only for the implementation: build the file that defines LINEAR_RT_IMPLEMENTATION without them (clang 12 or newer can)"
#endif
#pragma STDC FP_CONTRACT OFF
#define LRT__FP_CONTRACT_ONLY /* no push: DEFAULT again at the end */
#elif defined(__clang__)
#pragma float_control(precise, on, push) /* no reassociation or reciprocals; NaN, inf, -0 kept */
#pragma clang fp contract(off)
#define LRT__FP_RULES_PUSHED
#elif defined(__GNUC__)
#pragma GCC push_options
#pragma GCC optimize("no-unsafe-math-optimizations", "no-associative-math", "no-reciprocal-math", "signed-zeros", \
                     "no-finite-math-only", "fp-contract=off")
#define LRT__FP_RULES_PUSHED
#elif defined(_MSC_VER)
#pragma float_control(precise, on, push) /* /fp:precise here, also under /fp:fast */
#pragma fp_contract(off)
#define LRT__FP_RULES_PUSHED
#endif
#endif /* !LRT__AVX2_PASS */
#if !defined(LINEAR_RT_IMPLEMENTATION_DONE) || defined(LRT__AVX2_PASS)
#ifndef LRT__AVX2_PASS /* the AVX2 pass (section walk-avx2) compiles only the walk */
#define LINEAR_RT_IMPLEMENTATION_DONE

#include <string.h>
#include <math.h>
/* SSE2 is the x86-64 baseline: compiled wherever the compiler targets it.
   It tests 4 children (or texels) at once where the plain C walk
   (LINEAR_RT_NO_SIMD) tests one (what each path earns: docs/PERFORMANCE.md). */
#if defined(__SSE2__) && !defined(LINEAR_RT_NO_SIMD)
#include <emmintrin.h>
#define LRT__SSE 1
#else
#define LRT__SSE 0
#endif
/* AVX2 and FMA (8 children in one register): compiled in when the build
   targets them (-mavx2 -mfma, -march=native); otherwise, with gcc or clang on
   x86-64, compiled as a second pass of the walk (section walk-avx2) and chosen at
   run time by one CPU probe (lrt__cpu_has_avx2). Every path computes the same
   floats: the answers are equal bit for bit. AVX2 tests a node's 8
   children in one register. */
#if LRT__SSE && defined(__AVX2__) && defined(__FMA__) && !defined(LINEAR_RT_NO_AVX)
#include <immintrin.h>
#define LRT__AVX_BUILT 1 /* the whole file is compiled for AVX2 */
#define LRT__AVX_AT_RUN_TIME 0
#elif LRT__SSE && !defined(LINEAR_RT_NO_AVX) && !defined(LINEAR_RT_NO_RUNTIME_DISPATCH) && \
    (defined(__x86_64__) || defined(__i386__)) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define LRT__AVX_BUILT 0
#define LRT__AVX_AT_RUN_TIME 1 /* the walk twice: SSE2, and AVX2 + FMA by target pragma */
#else
#define LRT__AVX_BUILT 0
#define LRT__AVX_AT_RUN_TIME 0
#endif
#define LRT__AVX LRT__AVX_BUILT /* the pass being compiled: AVX2 or not (section walk-avx2 redefines it) */
#if LRT__AVX_AT_RUN_TIME
/* The one look at the CPU that picks the AVX2 paths (the walk, a row's model
   back codes): libgcc / compiler-rt read CPUID and whether the OS saves the
   AVX state (XGETBV) once at start-up. A function outside the walk's pass
   that has an AVX2 version compiles it with LRT__TARGET_AVX2. */
static int lrt__cpu_has_avx2(void)
{
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi") &&
           __builtin_cpu_supports("bmi2");
}
#define LRT__TARGET_AVX2 __attribute__((target("avx2")))
#define LRT__USE_AVX2() lrt__cpu_has_avx2()
#elif LRT__AVX_BUILT
#define LRT__TARGET_AVX2
#define LRT__USE_AVX2() 1
#endif
#ifndef LINEAR_RT_SELF
#define LINEAR_RT_SELF "linear_rt.h" /* for the AVX2 pass: this file, found beside itself */
#endif

#ifndef LINEAR_RT_COUNT_NODE_TEST
#define LINEAR_RT_COUNT_NODE_TEST(level) ((void)0)
#endif
#ifndef LINEAR_RT_COUNT_TEXEL_TEST
#define LINEAR_RT_COUNT_TEXEL_TEST() ((void)0)
#endif
#ifndef LINEAR_RT_COUNT_FINISH_SAMPLE
#define LINEAR_RT_COUNT_FINISH_SAMPLE() ((void)0)
#endif

#ifndef LINEAR_RT_ASSERT
#include <assert.h>
#define LINEAR_RT_ASSERT(x) assert(x)
#endif

#if defined(LINEAR_RT_MALLOC) != defined(LINEAR_RT_FREE)
#error "linear_rt.h: define both LINEAR_RT_MALLOC and LINEAR_RT_FREE, or neither"
#endif
#ifndef LINEAR_RT_MALLOC
#include <stdlib.h>
#define LINEAR_RT_MALLOC(size, user) ((void)(user), malloc(size))
#define LINEAR_RT_FREE(ptr, user) ((void)(user), free(ptr))
#endif

#ifdef LINEAR_RT_STATIC
#if defined(__GNUC__) || defined(__clang__)
#define LINEAR_RT_DEF static __attribute__((unused)) /* a file may use only part of the API */
#else
#define LINEAR_RT_DEF static
#endif
#else
#define LINEAR_RT_DEF
#endif
#define LRT__INLINE static inline /* C99 and C++: the hot path's small helpers */
#if LRT__SSE
#define LRT__PREFETCH(p) _mm_prefetch((const char *)(p), _MM_HINT_T0)
#elif defined(__GNUC__) || defined(__clang__)
#define LRT__PREFETCH(p) __builtin_prefetch(p)
#else
#define LRT__PREFETCH(p) ((void)(p))
#endif
#if defined(__GNUC__) || defined(__clang__)
#define LRT__FORCE_INLINE static inline __attribute__((always_inline)) /* specialised on a constant argument */
#else
#define LRT__FORCE_INLINE static inline
#endif
#if defined(__GNUC__) || defined(__clang__)
#define LRT__UNUSED __attribute__((unused)) /* for the tools and tests, not the trace */
#else
#define LRT__UNUSED
#endif

#ifdef __cplusplus
extern "C" {
#endif

LINEAR_RT_DEF const char *lrt_result_string(lrt_result result)
{
    switch (result) {
    case LRT_SUCCESS: return "success";
    case LRT_ERROR_NULL_POINTER: return "a required pointer is NULL";
    case LRT_ERROR_INVALID_SIZE: return "width or height is 0 or above LINEAR_RT_MAX_DIM";
    case LRT_ERROR_INVALID_STRIDE: return "row stride is smaller than one row";
    case LRT_ERROR_INVALID_FORMAT: return "unknown depth format";
    case LRT_ERROR_INVALID_OPTION:
        return "unknown flag bits, node bits not 0, 8 or 16, a budget over 65535, or a GPU map given as both a buffer "
               "and an image, a back map unlike its depth (image or buffer), an unsupported image layout, or "
               "host-visible nodes in your own buffers";
    case LRT_ERROR_SIZE_OVERFLOW: return "the depth map's byte span exceeds PTRDIFF_MAX";
    case LRT_ERROR_OUT_OF_MEMORY: return "out of memory";
    case LRT_ERROR_BUFFER_TOO_SMALL: return "memory smaller than lrt_bvh_memory_size";
    case LRT_ERROR_SIZE_MISMATCH: return "depth map size differs from the BVH's";
    case LRT_ERROR_INVALID_RECT: return "dirty rectangle reaches outside the map";
    case LRT_ERROR_TOO_MANY_RAYS: return "too many rays in one call, or a bad range";
    case LRT_ERROR_INVALID_BVH: return "the BVH is not built (never built, destroyed, or not zero-initialised)";
    case LRT_ERROR_VULKAN: return "a Vulkan call failed";
    case LRT_ERROR_NO_VULKAN_LOADER: return "the Vulkan loader could not be loaded";
    case LRT_ERROR_NO_VULKAN_DEVICE: return "no Vulkan device with what linear_rt needs";
    case LRT_ERROR_MISSING_VULKAN_FEATURE: return "a Vulkan version, extension, feature, layer or memory type is missing";
    case LRT_ERROR_LIMIT_EXCEEDED: return "a device limit is exceeded";
    case LRT_ERROR_MISALIGNED: return "an offset or stride is misaligned";
    case LRT_ERROR_INVALID_CAMERA: return "the projection matrix is not finite or not invertible";
    case LRT_ERROR_THICKNESS_MISMATCH:
        return "a back map given to a tree without LRT_THICKNESS_BACK_MAP, none given to one with it, "
               "or a back map with a back of its own";
    case LRT_ERROR_INVALID_THICKNESS:
        return "unknown thickness model, or a thickness or (near, far) planes the constant or relative model cannot use";
    case LRT_ERROR_DEPTH_MISMATCH:
        return "the map's format or reversed-Z flag differs from the tree's, or the back map's from the depth's";
    case LRT_ERROR_ALREADY_BUILT: return "the BVH is already built: destroy it before building again";
    case LRT_ERROR_CONTEXT_MISMATCH: return "the GPU tree was created with a context of another VkDevice";
    default: return "unknown result code";
    }
}

/* ================================================================= >>depth
   1. Depth in: validation and decoding of one texel.
   ========================================================================== */

/* lrt_bvh.built and lrt_vk_bvh.created from build (create) to destroy: a
   word that zeroed memory never holds and stack garbage hardly ever does */
#define LRT__BUILT 0x4c525442u /* "LRTB" */

LRT__FORCE_INLINE uint32_t lrt__format_bytes(lrt_format f)
{
    return f == LRT_FORMAT_UNORM8 ? 1u : f == LRT_FORMAT_UNORM16 ? 2u : f == LRT_FORMAT_FLOAT32 ? 4u : 0u;
}

static lrt_result lrt__check_size(uint32_t width, uint32_t height)
{
    if (width == 0 || height == 0 || width > LINEAR_RT_MAX_DIM || height > LINEAR_RT_MAX_DIM)
        return LRT_ERROR_INVALID_SIZE;
    return LRT_SUCCESS;
}

/* A map's row stride (given: 0 = packed rows of row_bytes). The map spans
   stride*(height-1) + row_bytes bytes: no C object is larger than
   PTRDIFF_MAX, so a span past it is an overflow (one row spans row_bytes,
   whatever its stride, which is then never used). */
static lrt_result lrt__check_stride(size_t given, size_t row_bytes, uint32_t height, size_t *out)
{
    size_t stride = given ? given : row_bytes;
    if (stride < row_bytes) return LRT_ERROR_INVALID_STRIDE;
    if (height == 1) stride = row_bytes;
    else if (stride > ((size_t)PTRDIFF_MAX - row_bytes) / (height - 1)) return LRT_ERROR_SIZE_OVERFLOW;
    *out = stride;
    return LRT_SUCCESS;
}

/* Everything about a depth map that can be wrong, checked before any work. */
static lrt_result lrt__check_depth(const lrt_depth *depth, size_t *out_stride)
{
    uint32_t bpp;
    size_t row_bytes, stride;
    lrt_result r;
    if (!depth || !depth->data) return LRT_ERROR_NULL_POINTER;
    if ((r = lrt__check_size(depth->width, depth->height)) != LRT_SUCCESS) return r;
    bpp = lrt__format_bytes(depth->format);
    if (!bpp) return LRT_ERROR_INVALID_FORMAT;
    if (depth->flags & ~(uint32_t)LRT_DEPTH_REVERSED_Z) return LRT_ERROR_INVALID_OPTION;
    row_bytes = (size_t)depth->width * bpp; /* <= 65536: cannot overflow */
    if ((r = lrt__check_stride(depth->row_stride, row_bytes, depth->height, &stride)) != LRT_SUCCESS) return r;
    *out_stride = stride;
    return LRT_SUCCESS;
}

/* The back map (depth->back) against the tree's thickness model: there
   exactly when the tree has back codes, the same size, format and Z
   direction as the depth, a valid stride of its own. */
static lrt_result lrt__check_back(const lrt_depth *depth, uint32_t thickness, size_t *out_stride)
{
    const lrt_depth *back = depth->back;
    *out_stride = 0;
    if ((back != NULL) != (thickness == LRT_THICKNESS_BACK_MAP)) return LRT_ERROR_THICKNESS_MISMATCH;
    if (!back) return LRT_SUCCESS;
    if (back->back) return LRT_ERROR_THICKNESS_MISMATCH;
    if (!back->data) return LRT_ERROR_NULL_POINTER;
    if (back->width != depth->width || back->height != depth->height) return LRT_ERROR_SIZE_MISMATCH;
    if (back->format != depth->format || back->flags != depth->flags) return LRT_ERROR_DEPTH_MISMATCH;
    return lrt__check_stride(back->row_stride, (size_t)depth->width * lrt__format_bytes(depth->format), depth->height,
                             out_stride);
}

/* A float depth as the model reads it: NaN and above 1 -> 1; below 0, -0
   and subnormal -> 0 (docs/MODEL.md: GPUs may flush subnormals, so no tracer
   may depend on one). The SIMD clamps: min with 1 (minps keeps 1 for NaN),
   then an AND with (d >= 2^-126). */
#define LRT__FLT_MIN 1.17549435e-38f /* 2^-126, the least normal float */
LRT__FORCE_INLINE float lrt__clamp_depth(float f)
{
    if (!(f <= 1.0f)) f = 1.0f; /* NaN too */
    if (!(f >= LRT__FLT_MIN)) f = 0.0f;
    return f;
}
#if LRT__SSE
LRT__FORCE_INLINE __m128 lrt__clamp_depth4(__m128 f) /* lrt__clamp_depth, 4 at once */
{
    f = _mm_min_ps(f, _mm_set1_ps(1.0f));
    return _mm_and_ps(f, _mm_cmpge_ps(f, _mm_set1_ps(LRT__FLT_MIN)));
}
#endif

/* Texel (x, y)'s depth as the model states it, as a raw value: the unorm
   integer v (reversed Z flipped in integers), or the bits of the float after
   the flip (in float) and the clamp. The exact texel test takes its depth
   plane from this without rounding v/max (see lrt__depth_plane). */
LRT__FORCE_INLINE uint32_t lrt__map_raw(const lrt_depth *depth, const void *data, size_t stride, uint32_t x, uint32_t y)
{
    const unsigned char *row = (const unsigned char *)data + stride * y;
    int reversed = (depth->flags & LRT_DEPTH_REVERSED_Z) != 0;
    if (depth->format == LRT_FORMAT_UNORM8) {
        uint32_t v = row[x];
        return reversed ? 255u - v : v;
    } else if (depth->format == LRT_FORMAT_UNORM16) {
        uint16_t v;
        memcpy(&v, row + 2 * (size_t)x, 2);
        return reversed ? 65535u - v : (uint32_t)v;
    } else {
        float f;
        uint32_t bits;
        memcpy(&f, row + 4 * (size_t)x, 4);
        if (reversed) f = 1.0f - f; /* in float: the model's conversion */
        f = lrt__clamp_depth(f);
        memcpy(&bits, &f, 4);
        return bits;
    }
}

LRT__FORCE_INLINE uint32_t lrt__depth_raw(const lrt_depth *depth, size_t stride, uint32_t x, uint32_t y)
{
    return lrt__map_raw(depth, depth->data, stride, x, y);
}

/* Texel (x, y)'s back depth, raw: max(depth, back) (docs/MODEL.md: a back in
   front of the depth is the depth). Raw values order as depths do: a
   unorm's integer, or the bits of a float clamped to [0, 1]. */
LRT__FORCE_INLINE uint32_t lrt__back_raw(const lrt_depth *depth, size_t stride, size_t back_stride, uint32_t x, uint32_t y)
{
    const uint32_t d = lrt__depth_raw(depth, stride, x, y), b = lrt__map_raw(depth, depth->back->data, back_stride, x, y);
    return b > d ? b : d;
}

/* b(d) of the CONSTANT and RELATIVE models (lrt__model_constants) in float,
   the kernels' lrt_model_back step for step: sums and quotients only, so
   no compiler can fuse them differently; within 6.5 float ulps and 3.2e-7
   of docs/MODEL.md's exact b (the relative model 4 ulps; tests/test_reference.c
   measures it). Clamped to 1 and never in
   front of d: d = 1 keeps b = 1 (u = 0, q = inf, the quotient 0). */
LRT__FORCE_INLINE float lrt__model_back(uint32_t thickness, const float k[2], float d)
{
    float b;
    if (thickness == LRT_THICKNESS_CONSTANT) {
        const float u = k[0] - d, q = k[0] / u;
        b = d + k[1] / ((q + k[1]) / u);
    } else {
        b = (d + k[0]) / k[1];
    }
    if (!(b <= 1.0f)) b = 1.0f;
    return b > d ? b : d;
}

/* A raw depth (lrt__map_raw) as the float the models start from. */
LRT__FORCE_INLINE float lrt__raw_to_float(lrt_format format, uint32_t raw)
{
    float d;
    if (format == LRT_FORMAT_UNORM8) return (float)raw / 255.0f;
    if (format == LRT_FORMAT_UNORM16) return (float)raw / 65535.0f;
    memcpy(&d, &raw, 4);
    return d;
}

/* Texel (x, y)'s back under a CONSTANT or RELATIVE model: b(d) as float
   bits, or ~0 when b is not behind a unorm depth's exact v / max (b(d)
   rounds to the float d, below v / max): the box is then the flat plate
   [d, d], its back the depth's own exact plane. */
LRT__FORCE_INLINE uint32_t lrt__model_back_bits(const lrt_layout *L, lrt_format format, uint32_t raw)
{
    const float b = lrt__model_back(L->thickness, L->back_k, lrt__raw_to_float(format, raw));
    uint32_t bits;
    if (format != LRT_FORMAT_FLOAT32 && (double)b * (format == LRT_FORMAT_UNORM8 ? 255.0 : 65535.0) <= (double)raw)
        return ~0u; /* exact in double: 24 by 16 bits */
    memcpy(&bits, &b, 4);
    return bits;
}

/* =============================================================== >>heights
   2. Heights: h = 1 - depth, compressed to 16 bits and rounded UP, so that
      the box a node promises is never smaller than the true one.
   ========================================================================== */

/* ---- ISA block: a row's float depths to height codes, 4 at a time (SSE2 |
   scalar: none): the same clamps (minps keeps 1 for NaN) and the same
   product in double as lrt__row_heights' loop; returns how many it did ---- */
#if LRT__SSE
static uint32_t lrt__float_heights4(const unsigned char *row, uint32_t x0, uint32_t n, int reversed, uint32_t qmax,
                                    uint32_t *codes)
{
    uint32_t i = 0;
    const __m128 one = _mm_set1_ps(1.0f);
    const __m128d q = _mm_set1_pd((double)qmax);
    const __m128i qi = _mm_set1_epi32((int)qmax);
    for (; n - i >= 4u; i += 4) {
        __m128 f = _mm_loadu_ps((const float *)(const void *)(row + 4 * (size_t)(x0 + i)));
        __m128i lo, hi;
        if (reversed) f = _mm_sub_ps(one, f);
        f = lrt__clamp_depth4(f);
        lo = _mm_cvttpd_epi32(_mm_mul_pd(_mm_cvtps_pd(f), q));
        hi = _mm_cvttpd_epi32(_mm_mul_pd(_mm_cvtps_pd(_mm_movehl_ps(f, f)), q));
        _mm_storeu_si128((__m128i *)(void *)(codes + i), _mm_sub_epi32(qi, _mm_unpacklo_epi64(lo, hi)));
    }
    return i;
}
#else
#define lrt__float_heights4(row, x0, n, reversed, qmax, codes) 0u /* the loop does them all */
#endif

/* Height codes of texels [x0, x0+n) of one row: qmax - floor(depth * qmax).
   Integer inputs stay in integers, so 8- and 16-bit depth are exact. One
   loop per format keeps the per-texel work to a load and a convert (this
   is the per-frame cost). */
LRT__FORCE_INLINE void lrt__row_heights(const lrt_depth *depth, const unsigned char *row, uint32_t x0, uint32_t n,
                             uint32_t qmax, uint32_t *codes)
{
    const int reversed = (depth->flags & LRT_DEPTH_REVERSED_Z) != 0;
    uint32_t i;
    if (depth->format == LRT_FORMAT_FLOAT32) {
        for (i = lrt__float_heights4(row, x0, n, reversed, qmax, codes); i < n; ++i) {
            float f;
            memcpy(&f, row + 4 * (size_t)(x0 + i), 4);
            if (reversed) f = 1.0f - f;
            f = lrt__clamp_depth(f);
            /* d * qmax is exact in double, so the floor is too */
            codes[i] = qmax - (uint32_t)((double)f * (double)qmax);
        }
    } else if (depth->format == LRT_FORMAT_UNORM16) {
        for (i = 0; i < n; ++i) {
            uint16_t v;
            memcpy(&v, row + 2 * (size_t)(x0 + i), 2);
            if (reversed) v = (uint16_t)(65535u - v);
            codes[i] = qmax - (uint32_t)(((uint32_t)v * (uint64_t)qmax) / 65535u);
        }
    } else {
        for (i = 0; i < n; ++i) {
            uint32_t v = row[x0 + i];
            if (reversed) v = 255u - v;
            codes[i] = qmax - (v * qmax) / 255u;
        }
    }
}


/* ================================================================ >>layout
   3. Level geometry and the modified Morton mapping.
   ========================================================================== */

LINEAR_RT_DEF lrt_result lrt_layout_compute(uint32_t width, uint32_t height, uint32_t node_bits, lrt_layout *out)
{
    lrt_layout L;
    uint32_t lv;
    lrt_result r;
    if (!out) return LRT_ERROR_NULL_POINTER;
    if ((r = lrt__check_size(width, height)) != LRT_SUCCESS) return r;
    if (node_bits == LRT_NODE_BITS_AUTO) node_bits = 16;
    if (node_bits != 8 && node_bits != 16) return LRT_ERROR_INVALID_OPTION;
    memset(&L, 0, sizeof L);
    L.width = width;
    L.height = height;
    L.node_bits = node_bits;
    L.node_bytes = 16u; /* 8 children x 16 bits */
    L.levels[0].width = width;
    L.levels[0].height = height;
    /* Level lv groups 4x2 into lv+1 when lv is even, 2x4 when odd; stop at a
       1x1 level that is not the texels (a 1x1 map still gets one node). */
    for (lv = 0;; ++lv) {
        lrt_level *c = &L.levels[lv], *p = &L.levels[lv + 1];
        c->block_w = (lv & 1) ? 2u : 4u;
        c->block_h = (lv & 1) ? 4u : 2u;
        p->width = (c->width + c->block_w - 1) / c->block_w;
        p->height = (c->height + c->block_h - 1) / c->block_h;
        p->span_w_log2 = c->span_w_log2 + ((lv & 1) ? 1u : 2u);
        p->span_h_log2 = c->span_h_log2 + ((lv & 1) ? 2u : 1u);
        if (p->width == 1 && p->height == 1) {
            L.level_count = lv + 1;
            break;
        }
        LINEAR_RT_ASSERT(lv + 2 <= LINEAR_RT_MAX_LEVELS);
    }
    {   /* the root level's grouping is unused; give it the alternating pattern */
        lrt_level *root = &L.levels[L.level_count];
        root->block_w = (L.level_count & 1) ? 2u : 4u;
        root->block_h = (L.level_count & 1) ? 4u : 2u;
    }
    /* node slots: every block of the level above holds 8, padding included */
    for (lv = 1; lv <= L.level_count; ++lv) {
        lrt_level *c = &L.levels[lv];
        c->offset = L.node_count;
        c->count = lv == L.level_count ? 1u : (size_t)L.levels[lv + 1].width * L.levels[lv + 1].height * 8u;
        L.node_count += c->count;
    }
    /* a compact level 1 needs a parent to hold its nodes' own heights */
    L.level1_node_bytes = node_bits == 8 && L.level_count >= 2 ? 6u : 16u;
    L.bytes = L.levels[1].count * L.level1_node_bytes + (L.node_count - L.levels[1].count) * L.node_bytes; /* < 2^31 */
    *out = L;
    return LRT_SUCCESS;
}

/* Slot of node (x, y) among the 8 children of its parent: y0 x1 x0 for 4x2
   blocks, y1 y0 x0 for 2x4 blocks. Row-major with x fastest, so flipping the
   bits of one axis reverses that axis' order (used by the traversal). */
LRT__FORCE_INLINE uint32_t lrt__child_slot(const lrt_level *lv, uint32_t x, uint32_t y)
{
    return lv->block_w == 4 ? ((y & 1u) << 2) | (x & 3u) : ((y & 3u) << 1) | (x & 1u);
}

LINEAR_RT_DEF size_t lrt_layout_node_index(const lrt_layout *layout, uint32_t level, uint32_t x, uint32_t y)
{
    const lrt_level *lv = &layout->levels[level];
    size_t block;
    if (level >= layout->level_count) return 0; /* the root */
    block = (size_t)(y >> (lv->block_h == 4 ? 2 : 1)) * layout->levels[level + 1].width +
            (x >> (lv->block_w == 4 ? 2 : 1));
    return block * 8u + lrt__child_slot(lv, x, y);
}

/* ================================================================= >>nodes
   4. Nodes: BuildBVH and UpdateBVH. The tree's shape is implicit in the
      layout, so building is laying out plus a refit of every node; an
      update refits only the nodes above the dirty texels. A node's slot s
      holds the height of child s, which is the max of that child's own 8
      slots: exact, so heights can fall as well as rise, and the refit equals
      a rebuild byte for byte.
   ========================================================================== */

/* ---- ISA block: a row's float depths and backs to back codes, 4 at a time
   (SSE2 | scalar: none): the same clamps, the max, the product in double,
   and ceil as trunc + (trunc < x), as lrt__row_back_codes' loop; returns how
   many it did ---- */
#if LRT__SSE
static uint32_t lrt__float_back_codes4(const unsigned char *drow, const unsigned char *brow, uint32_t x0, uint32_t n,
                                       int reversed, uint32_t qmax, uint32_t *codes)
{
    uint32_t i = 0;
    const __m128 one = _mm_set1_ps(1.0f);
    const __m128d q = _mm_set1_pd((double)qmax);
    for (; n - i >= 4u; i += 4) {
        __m128 f = _mm_loadu_ps((const float *)(const void *)(drow + 4 * (size_t)(x0 + i)));
        __m128 g = _mm_loadu_ps((const float *)(const void *)(brow + 4 * (size_t)(x0 + i)));
        __m128d xl, xh;
        __m128i cl, ch;
        if (reversed) {
            f = _mm_sub_ps(one, f);
            g = _mm_sub_ps(one, g);
        }
        f = _mm_max_ps(lrt__clamp_depth4(f), lrt__clamp_depth4(g));
        xl = _mm_mul_pd(_mm_cvtps_pd(f), q);
        xh = _mm_mul_pd(_mm_cvtps_pd(_mm_movehl_ps(f, f)), q);
        cl = _mm_cvttpd_epi32(xl); /* 2 lanes each, in the low half */
        ch = _mm_cvttpd_epi32(xh);
        /* + 1 where the truncation is below x: the compare's all-ones lanes are -1 */
        cl = _mm_sub_epi32(cl, _mm_shuffle_epi32(_mm_castpd_si128(_mm_cmplt_pd(_mm_cvtepi32_pd(cl), xl)), _MM_SHUFFLE(3, 3, 2, 0)));
        ch = _mm_sub_epi32(ch, _mm_shuffle_epi32(_mm_castpd_si128(_mm_cmplt_pd(_mm_cvtepi32_pd(ch), xh)), _MM_SHUFFLE(3, 3, 2, 0)));
        _mm_storeu_si128((__m128i *)(void *)(codes + i), _mm_unpacklo_epi64(cl, ch));
    }
    return i;
}
#else
#define lrt__float_back_codes4(drow, brow, x0, n, reversed, qmax, codes) 0u /* the loop does them all */
#endif

/* Back codes of texels [x0, x0+n) of one row: ceil(b * qmax) of each
   texel's back depth b = max(depth, back), rounded UP so that a node's back
   is never shallower than a texel's under it (lrt__back_raw's values, one
   loop per format as lrt__row_heights). */
static void lrt__row_back_codes(const lrt_depth *depth, const unsigned char *drow, const unsigned char *brow, uint32_t x0,
                                uint32_t n, uint32_t qmax, uint32_t *codes)
{
    const int reversed = (depth->flags & LRT_DEPTH_REVERSED_Z) != 0;
    uint32_t i;
    if (depth->format == LRT_FORMAT_FLOAT32) {
        for (i = lrt__float_back_codes4(drow, brow, x0, n, reversed, qmax, codes); i < n; ++i) {
            float f, g;
            double x;
            uint32_t c;
            memcpy(&f, drow + 4 * (size_t)(x0 + i), 4);
            memcpy(&g, brow + 4 * (size_t)(x0 + i), 4);
            if (reversed) {
                f = 1.0f - f;
                g = 1.0f - g;
            }
            f = lrt__clamp_depth(f);
            g = lrt__clamp_depth(g);
            x = (double)(g > f ? g : f) * (double)qmax; /* exact in double */
            c = (uint32_t)x;
            codes[i] = c + ((double)c < x);
        }
    } else {
        const uint32_t vmax = depth->format == LRT_FORMAT_UNORM8 ? 255u : 65535u;
        for (i = 0; i < n; ++i) {
            uint32_t v, b;
            if (vmax == 255u) {
                v = drow[x0 + i];
                b = brow[x0 + i];
            } else {
                uint16_t a16, b16;
                memcpy(&a16, drow + 2 * (size_t)(x0 + i), 2);
                memcpy(&b16, brow + 2 * (size_t)(x0 + i), 2);
                v = a16;
                b = b16;
            }
            if (reversed) {
                v = vmax - v;
                b = vmax - b;
            }
            codes[i] = (uint32_t)(((uint64_t)(b > v ? b : v) * qmax + vmax - 1u) / vmax);
        }
    }
}

/* ---- ISA block: a row's back codes under a CONSTANT or RELATIVE model, 4
   at a time (SSE2 | scalar: none): lrt__map_raw and lrt__model_back in
   lanes, the same float operations in the same order (minps keeps 1 for a
   NaN b, maxps keeps d unless b > d), then ceil(b * 65535) in float, for
   b in [0, 1]: B = b * 65536 is exact, t = trunc(B), f = B - t is exact and
   in [0, 1), and b * 65535 = t + f - b with f - b in [-1, 1), so the ceil
   is t + 1 where f > b, t - 1 where f - b = -1 (b = 1), else t. A unorm's
   plate (lrt__model_back_bits: b * vmax <= v) needs no lane of its own: its
   code, the integer c = v * 65535 / vmax, is ceil(b * 65535) as well, for
   b * 65535 lies in (c - 1, c], b being at most v / vmax and at least d,
   v / vmax rounded to float. Returns how many it did ---- */
#if LRT__SSE
static uint32_t lrt__model_back_codes4(const lrt_layout *L, const lrt_depth *depth, const unsigned char *row, uint32_t x0,
                                       uint32_t n, uint32_t qmax, uint32_t *codes)
{
    const lrt_format format = depth->format;
    const int reversed = (depth->flags & LRT_DEPTH_REVERSED_Z) != 0, constant = L->thickness == LRT_THICKNESS_CONSTANT;
    const uint32_t vmax = format == LRT_FORMAT_UNORM8 ? 255u : 65535u;
    const __m128 one = _mm_set1_ps(1.0f), k0 = _mm_set1_ps(L->back_k[0]), k1 = _mm_set1_ps(L->back_k[1]);
    const __m128 vmax_f = _mm_set1_ps((float)vmax), scale = _mm_set1_ps(65536.0f);
    const __m128i vmax_i = _mm_set1_epi32((int)vmax);
    uint32_t i = 0;
    if (qmax != 65535u) return 0; /* the ceil above is that of b * (2^16 - 1) */
    for (; n - i >= 4u; i += 4) {
        __m128 d, b, B, f;
        __m128i t;
        if (format == LRT_FORMAT_FLOAT32) {
            d = _mm_loadu_ps((const float *)(const void *)(row + 4 * (size_t)(x0 + i)));
            if (reversed) d = _mm_sub_ps(one, d);
            d = lrt__clamp_depth4(d);
        } else {
            __m128i v;
            if (format == LRT_FORMAT_UNORM8) {
                int32_t bytes;
                memcpy(&bytes, row + x0 + i, 4);
                v = _mm_unpacklo_epi8(_mm_cvtsi32_si128(bytes), _mm_setzero_si128());
            } else {
                v = _mm_loadl_epi64((const __m128i *)(const void *)(row + 2 * (size_t)(x0 + i)));
            }
            v = _mm_unpacklo_epi16(v, _mm_setzero_si128());
            if (reversed) v = _mm_sub_epi32(vmax_i, v);
            d = _mm_div_ps(_mm_cvtepi32_ps(v), vmax_f); /* lrt__raw_to_float */
        }
        if (constant) {
            const __m128 u = _mm_sub_ps(k0, d), q = _mm_div_ps(k0, u);
            b = _mm_add_ps(d, _mm_div_ps(k1, _mm_div_ps(_mm_add_ps(q, k1), u)));
        } else {
            b = _mm_div_ps(_mm_add_ps(d, k0), k1);
        }
        b = _mm_max_ps(_mm_min_ps(b, one), d);
        B = _mm_mul_ps(b, scale);
        t = _mm_cvttps_epi32(B);
        f = _mm_sub_ps(B, _mm_cvtepi32_ps(t));
        /* the compares' all-ones lanes are -1: t + 1 where f > b, t - 1 where b = 1 */
        t = _mm_sub_epi32(t, _mm_castps_si128(_mm_cmpgt_ps(f, b)));
        t = _mm_add_epi32(t, _mm_castps_si128(_mm_cmpeq_ps(b, one)));
        _mm_storeu_si128((__m128i *)(void *)(codes + i), t);
    }
    return i;
}
#else
#define lrt__model_back_codes4(L, depth, row, x0, n, qmax, codes) ((void)(row), 0u) /* the loop does them all */
#endif

/* ---- ISA block: lrt__model_back_codes4, 8 at a time (AVX2: in an AVX2
   build, or compiled for it by LRT__TARGET_AVX2 and called where the CPU
   has it | none). The same operations in lanes (vminps and vmaxps keep the
   same operand on a NaN as minps and maxps); the target leaves FMA out, so
   the products by 2^16, exact, stay products. Everything it uses is
   an intrinsic: GCC inlines no helper of another target into it ---- */
#if LRT__AVX_BUILT || LRT__AVX_AT_RUN_TIME
static LRT__TARGET_AVX2 uint32_t lrt__model_back_codes8(const lrt_layout *L, const lrt_depth *depth, const unsigned char *row,
                                                        uint32_t x0, uint32_t n, uint32_t qmax, uint32_t *codes,
                                                        uint32_t *heights)
{
    const lrt_format format = depth->format;
    const int reversed = (depth->flags & LRT_DEPTH_REVERSED_Z) != 0, constant = L->thickness == LRT_THICKNESS_CONSTANT;
    const uint32_t vmax = format == LRT_FORMAT_UNORM8 ? 255u : 65535u;
    const __m256 one = _mm256_set1_ps(1.0f), k0 = _mm256_set1_ps(L->back_k[0]), k1 = _mm256_set1_ps(L->back_k[1]);
    const __m256 vmax_f = _mm256_set1_ps((float)vmax), scale = _mm256_set1_ps(65536.0f), least = _mm256_set1_ps(LRT__FLT_MIN);
    const __m256i vmax_i = _mm256_set1_epi32((int)vmax), qi = _mm256_set1_epi32(65535);
    const __m256i unit = _mm256_set1_epi32(format == LRT_FORMAT_UNORM8 ? 257 : 1); /* 65535 / vmax */
    uint32_t i = 0;
    if (qmax != 65535u) return 0; /* as lrt__model_back_codes4 */
    for (; n - i >= 8u; i += 8) {
        __m256 d, b, B, f;
        __m256i t;
        if (format == LRT_FORMAT_FLOAT32) {
            d = _mm256_loadu_ps((const float *)(const void *)(row + 4 * (size_t)(x0 + i)));
            if (reversed) d = _mm256_sub_ps(one, d);
            d = _mm256_min_ps(d, one); /* lrt__clamp_depth4 */
            d = _mm256_and_ps(d, _mm256_cmp_ps(d, least, _CMP_GE_OQ));
            if (heights) {
                /* lrt__row_heights: qmax - floor(d * qmax), in float: D = d * 2^16 is exact and
                   so are T = trunc(D) and F = D - T; d * qmax = T + F - d with F - d in (-1, 1),
                   so floor(d * qmax) = T - (F < d): qmax - T minus the compare's -1 */
                const __m256 D = _mm256_mul_ps(d, scale);
                const __m256i T = _mm256_cvttps_epi32(D);
                const __m256 F = _mm256_sub_ps(D, _mm256_cvtepi32_ps(T));
                _mm256_storeu_si256((__m256i *)(void *)(heights + i),
                                    _mm256_sub_epi32(_mm256_sub_epi32(qi, T),
                                                     _mm256_castps_si256(_mm256_cmp_ps(d, F, _CMP_GT_OQ))));
            }
        } else {
            __m256i v;
            if (format == LRT_FORMAT_UNORM8)
                v = _mm256_cvtepu8_epi32(_mm_loadl_epi64((const __m128i *)(const void *)(row + x0 + i)));
            else
                v = _mm256_cvtepu16_epi32(_mm_loadu_si128((const __m128i *)(const void *)(row + 2 * (size_t)(x0 + i))));
            if (reversed) v = _mm256_sub_epi32(vmax_i, v);
            if (heights) /* lrt__row_heights: qmax - v * qmax / vmax, exact as v * (65535 / vmax) */
                _mm256_storeu_si256((__m256i *)(void *)(heights + i), _mm256_sub_epi32(qi, _mm256_mullo_epi32(v, unit)));
            d = _mm256_div_ps(_mm256_cvtepi32_ps(v), vmax_f);
        }
        if (constant) {
            const __m256 u = _mm256_sub_ps(k0, d), qk = _mm256_div_ps(k0, u);
            b = _mm256_add_ps(d, _mm256_div_ps(k1, _mm256_div_ps(_mm256_add_ps(qk, k1), u)));
        } else {
            b = _mm256_div_ps(_mm256_add_ps(d, k0), k1);
        }
        b = _mm256_max_ps(_mm256_min_ps(b, one), d);
        B = _mm256_mul_ps(b, scale);
        t = _mm256_cvttps_epi32(B);
        f = _mm256_sub_ps(B, _mm256_cvtepi32_ps(t));
        t = _mm256_sub_epi32(t, _mm256_castps_si256(_mm256_cmp_ps(f, b, _CMP_GT_OQ)));
        t = _mm256_add_epi32(t, _mm256_castps_si256(_mm256_cmp_ps(b, one, _CMP_EQ_OQ)));
        _mm256_storeu_si256((__m256i *)(void *)(codes + i), t);
    }
    return i;
}
#endif

/* Back codes of texels [x0, x0+n) of row y under a CONSTANT or RELATIVE
   model: ceil(b * qmax) of lrt__model_back's float b, as above; and their
   height codes (lrt__row_heights) where `heights` is not NULL, from the
   same loads. */
static void lrt__row_model_back_codes(const lrt_layout *L, const lrt_depth *depth, size_t stride, uint32_t y, uint32_t x0,
                                      uint32_t n, uint32_t qmax, uint32_t *codes, uint32_t *heights)
{
    const uint32_t vmax = depth->format == LRT_FORMAT_UNORM8 ? 255u : 65535u;
    const unsigned char *row = (const unsigned char *)depth->data + stride * y;
    uint32_t i = 0;
#if LRT__AVX_BUILT || LRT__AVX_AT_RUN_TIME
    if (LRT__USE_AVX2()) i = lrt__model_back_codes8(L, depth, row, x0, n, qmax, codes, heights);
#endif
    if (heights) lrt__row_heights(depth, row, x0 + i, n - i, qmax, heights + i);
    for (i += lrt__model_back_codes4(L, depth, row, x0 + i, n - i, qmax, codes + i); i < n; ++i) {
        const uint32_t raw = lrt__depth_raw(depth, stride, x0 + i, y), bits = lrt__model_back_bits(L, depth->format, raw);
        float b;
        double x;
        uint32_t c;
        if (bits == ~0u) { /* the plate: ceil(v * qmax / vmax) */
            codes[i] = (uint32_t)(((uint64_t)raw * qmax + vmax - 1u) / vmax);
            continue;
        }
        memcpy(&b, &bits, 4);
        x = (double)b * (double)qmax; /* exact in double */
        c = (uint32_t)x;
        codes[i] = c + ((double)c < x);
    }
}

/* The back codes of the 256 values of an 8-bit depth under a CONSTANT or
   RELATIVE model, for looking up: lrt__row_model_back_codes of a row of
   the values 0-255 under the map's flags, indexed by the stored byte. */
static void lrt__unorm8_model_table(const lrt_layout *L, const lrt_depth *depth, uint32_t qmax, uint32_t table[256])
{
    unsigned char values[256];
    lrt_depth row = *depth;
    uint32_t v;
    for (v = 0; v < 256u; ++v) values[v] = (unsigned char)v;
    row.data = values;
    row.width = 256;
    row.height = 1;
    row.row_stride = 256;
    lrt__row_model_back_codes(L, &row, 256, 0, 0, 256, qmax, table, NULL);
}

/* ---- ISA block: a level-1 node's 4 + 4 16-bit codes (two texel rows)
   stored at code index `node` (SSE2: packed; the signed packs see them moved
   by 2^15 | scalar) ---- */
#if LRT__SSE
LRT__FORCE_INLINE void lrt__store_node4x2(void *nodes, size_t node, const uint32_t *c0, const uint32_t *c1)
{
    const __m128i a = _mm_loadu_si128((const __m128i *)(const void *)c0);
    const __m128i b = _mm_loadu_si128((const __m128i *)(const void *)c1);
    const __m128i h = _mm_set1_epi32(32768);
    const __m128i p = _mm_packs_epi32(_mm_sub_epi32(a, h), _mm_sub_epi32(b, h));
    _mm_storeu_si128((__m128i *)(void *)((uint16_t *)nodes + node), _mm_xor_si128(p, _mm_set1_epi16((short)0x8000)));
}
#else
LRT__FORCE_INLINE void lrt__store_node4x2(void *nodes, size_t node, const uint32_t *c0, const uint32_t *c1)
{
    uint16_t *out = (uint16_t *)nodes + node;
    uint32_t s;
    for (s = 0; s < 4; ++s) {
        out[s] = (uint16_t)c0[s];
        out[4 + s] = (uint16_t)c1[s];
    }
}
#endif

/* The scale of a compact level-1 node whose codes span d = H - lowest:
   16 d / 15 (the 15th step lands within one code of the lowest texel),
   but at least 16 (steps of one code: a spread of up to 15 stays exact)
   and at most 65535 (16 bits; a spread past 61439 ends a little above). */
LRT__FORCE_INLINE uint32_t lrt__compact_scale(uint32_t spread)
{
    const uint32_t s = spread * 16u / 15u;
    return s < 16u ? 16u : s > 65535u ? 65535u : s;
}

/* A compact level-1 node (8-bit trees) from its 8 texels' 16-bit codes
   (slots 0-3 in c0, 4-7 in c1): lrt__compact_bounds gives its own height H
   (the largest code: its parent's code for it) and its scale
   (lrt__compact_scale of the spread: the node's 16-bit code after the
   level's words); lrt__compact_steps its word, whose bits 4s..4s+3 hold
   step j_s, the largest j <= 15 with (j * scale) >> 4 <= H - code_s,
   that is min(15, floor((16 (H - code_s) + 15) / scale)).
   H - ((j_s * scale) >> 4) (lrt__compact_code) is at least code_s: never
   below the texel, and above it by at most scale / 16, about a fifteenth
   of the spread, with the node's highest and lowest texels within one
   code of their own (where the shift of the 3-bit steps before them left
   a lowest texel under a pole or a slab as far as half the spread above
   it). The refit finds every node's height and scale first, then the
   steps, so that the reciprocals (four at a time) stay out of the steps'
   chain.
   ---- ISA block: lrt__compact_bounds and lrt__compact_steps (SSE2: the 8
   codes in one register, the max, min and steps in lanes; the steps'
   quotients by a reciprocal | scalar) ---- */
#if LRT__SSE
LRT__FORCE_INLINE uint32_t lrt__compact_bounds(const uint32_t *c0, const uint32_t *c1, uint32_t *height)
{
    const __m128i bias = _mm_set1_epi32(32768);
    const __m128i x = _mm_packs_epi32(_mm_sub_epi32(_mm_loadu_si128((const __m128i *)(const void *)c0), bias),
                                      _mm_sub_epi32(_mm_loadu_si128((const __m128i *)(const void *)c1), bias));
    __m128i hi = _mm_max_epi16(x, _mm_shuffle_epi32(x, _MM_SHUFFLE(1, 0, 3, 2))); /* codes - 2^15, signed: ordered */
    __m128i lo = _mm_min_epi16(x, _mm_shuffle_epi32(x, _MM_SHUFFLE(1, 0, 3, 2)));
    hi = _mm_max_epi16(hi, _mm_shuffle_epi32(hi, _MM_SHUFFLE(2, 3, 0, 1)));
    lo = _mm_min_epi16(lo, _mm_shuffle_epi32(lo, _MM_SHUFFLE(2, 3, 0, 1)));
    hi = _mm_max_epi16(hi, _mm_srli_epi32(hi, 16));
    lo = _mm_min_epi16(lo, _mm_srli_epi32(lo, 16));
    *height = ((uint32_t)_mm_cvtsi128_si32(hi) & 0xffffu) ^ 0x8000u; /* undo the bias */
    return lrt__compact_scale(*height - (((uint32_t)_mm_cvtsi128_si32(lo) & 0xffffu) ^ 0x8000u));
}

/* floor((16 (H - code) + 15.5) * inv) with inv = 1 / scale in float: the
   quotient below 16, where it counts: the half moves an integer quotient
   0.5 / scale (at least 7.6e-6) above its integer and leaves any other as
   far below the next one, and the two roundings err by at most 2^-23 of a
   quotient below 16 (1.9e-6); checked once for all 2.27e9 pairs of a
   scale and an H - code with a quotient up to 17, and at every step's edge
   by test_core.c:test_compact_boundaries */
LRT__FORCE_INLINE uint32_t lrt__compact_steps(const uint32_t *c0, const uint32_t *c1, uint32_t h, uint32_t scale, float inv)
{
    const __m128i top = _mm_set1_epi32((int)h); /* 16 (H - code) in 32-bit lanes, then in float */
    const __m128i g0 = _mm_slli_epi32(_mm_sub_epi32(top, _mm_loadu_si128((const __m128i *)(const void *)c0)), 4);
    const __m128i g1 = _mm_slli_epi32(_mm_sub_epi32(top, _mm_loadu_si128((const __m128i *)(const void *)c1)), 4);
    const __m128 d = _mm_set1_ps(inv), half = _mm_set1_ps(15.5f);
    const __m128 q0 = _mm_mul_ps(_mm_add_ps(_mm_cvtepi32_ps(g0), half), d);
    const __m128 q1 = _mm_mul_ps(_mm_add_ps(_mm_cvtepi32_ps(g1), half), d);
    __m128i j = _mm_min_epi16(_mm_packs_epi32(_mm_cvttps_epi32(q0), _mm_cvttps_epi32(q1)), _mm_set1_epi16(15));
    (void)scale;
    /* j_2k + 16 j_2k+1 in 32-bit lanes, then those 4 bytes in one word */
    j = _mm_madd_epi16(j, _mm_set1_epi32(16 << 16 | 1));
    j = _mm_packus_epi16(_mm_packs_epi32(j, j), _mm_setzero_si128());
    return (uint32_t)_mm_cvtsi128_si32(j);
}

/* 1 / scale of n <= 16 nodes, four at a time */
LRT__FORCE_INLINE void lrt__compact_inverses(const uint32_t scales[16], float inv[16], uint32_t n)
{
    uint32_t k;
    for (k = 0; k < n; k += 4)
        _mm_storeu_ps(inv + k, _mm_div_ps(_mm_set1_ps(1.0f), _mm_cvtepi32_ps(_mm_loadu_si128((const __m128i *)(const void *)(scales + k)))));
}
#else
LRT__FORCE_INLINE void lrt__compact_inverses(const uint32_t scales[16], float inv[16], uint32_t n)
{
    (void)scales;
    (void)inv;
    (void)n;
}

LRT__FORCE_INLINE uint32_t lrt__compact_bounds(const uint32_t *c0, const uint32_t *c1, uint32_t *height)
{
    uint32_t h = 0, low = 65535u, s;
    for (s = 0; s < 4; ++s) {
        h = c0[s] > h ? c0[s] : h;
        h = c1[s] > h ? c1[s] : h;
        low = c0[s] < low ? c0[s] : low;
        low = c1[s] < low ? c1[s] : low;
    }
    *height = h;
    return lrt__compact_scale(h - low);
}

LRT__FORCE_INLINE uint32_t lrt__compact_steps(const uint32_t *c0, const uint32_t *c1, uint32_t h, uint32_t scale, float inv)
{
    uint32_t word = 0, s;
    (void)inv;
    for (s = 0; s < 4; ++s) {
        const uint32_t j0 = (16u * (h - c0[s]) + 15u) / scale, j1 = (16u * (h - c1[s]) + 15u) / scale;
        word |= (j0 < 15u ? j0 : 15u) << (4u * s);
        word |= (j1 < 15u ? j1 : 15u) << (4u * (s + 4u));
    }
    return word;
}
#endif

/* The code of slot s of a compact level-1 node whose word is `word`, own
   height h and scale `scale` (the kernels' lrt_compact_words) */
LRT__FORCE_INLINE uint32_t lrt__compact_code(uint32_t word, uint32_t h, uint32_t scale, uint32_t s)
{
    return h - ((((word >> (4u * s)) & 15u) * scale) >> 4);
}

/* Code index (16-bit units) of the first code of node slot `node` >= the
   level-1 slots, or of any node of a tree without a compact level 1: the
   compact level-1 nodes before it take 3 units each, not 8 (a word and a
   scale) */
LRT__FORCE_INLINE size_t lrt__code_index(const lrt_layout *L, size_t node)
{
    return node * 8u - (L->level1_node_bytes == 6u ? L->levels[1].count * 5u : 0u);
}

/* Code index of compact level-1 node k's scale: after the level's words */
LRT__FORCE_INLINE size_t lrt__compact_scale_index(const lrt_layout *L, size_t k)
{
    return L->levels[1].count * 2u + k;
}

/* The back codes' first code index: after the heights, laid out as they are */
LRT__FORCE_INLINE size_t lrt__back_code_index(const lrt_layout *L)
{
    return L->back_codes ? L->bytes / 4u : 0u;
}

/* Refit level-1 nodes [nx0,nx1] x [ny0,ny1] from the texels, two texel rows
   at a time: sets 1, their heights; 2, their back codes, which a tree with
   a thickness keeps after the heights (lrt__back_code_index); 3, both, from
   one pass over the map (a CONSTANT or RELATIVE tree: each row's depth is
   read once, and the back codes' divisions overlap the heights' work).
   Texels outside the map get code 0 (padding: height 0; a back of 0, a box
   [1, 0] no ray meets). A compact level 1 stores each node's word and its
   own height, the code in its level-2 parent (whose refit then has nothing
   to add). */
LRT__FORCE_INLINE void lrt__refit_texel_parents(lrt_bvh *bvh, const lrt_depth *depth, size_t stride, uint32_t nx0, uint32_t nx1,
                                     uint32_t ny0, uint32_t ny1, int sets)
{
    const lrt_layout *L = &bvh->layout;
    const uint32_t qmax = 65535u;
    const int compact = L->level1_node_bytes == 6u, back = (sets & 2) != 0;
    uint32_t codes[2][64 + 4], backs[2][64 + 4], table[256]; /* by texel row */
    size_t back_stride = 0;
    uint32_t nx, ny, r, s, chunk;
    int set;
    /* 8-bit depth under a model: 256 back codes, looked up, where the
       texels outnumber them (a small update computes its own) */
    const int look_up = back && L->thickness != LRT_THICKNESS_BACK_MAP && depth->format == LRT_FORMAT_UNORM8 &&
                        (size_t)(nx1 - nx0 + 1u) * (ny1 - ny0 + 1u) * 8u >= 1024u;
    if (look_up) lrt__unorm8_model_table(L, depth, qmax, table);
    if (back) (void)lrt__check_back(depth, L->thickness, &back_stride); /* checked by the caller */
    for (ny = ny0; ny <= ny1; ++ny) {
        const size_t row = lrt_layout_node_index(L, 1, 0, ny);
        /* a compact node's parent: level 2 groups 4x2, so parent px is (px >> 2) * 8 + (px & 3) after parent 0 */
        const size_t parents = compact ? L->levels[2].offset + lrt_layout_node_index(L, 2, 0, ny >> 2) : 0u;
        const uint32_t child_row = (ny & 3u) << 1, parent_step = compact && L->level_count > 2 ? 1u : 0u;
        for (chunk = nx0; chunk <= nx1; chunk += 16) { /* 16 nodes = 64 texels a step */
            uint32_t last = nx1 - chunk < 15 ? nx1 : chunk + 15, tx0 = chunk * 4u;
            uint32_t n = (last - chunk + 1) * 4u, real;
            for (r = 0; r < 2; ++r) {
                uint32_t ty = ny * 2u + r;
                uint32_t *h = codes[r], *c = backs[r];
                real = tx0 >= L->width ? 0u : (L->width - tx0 < n ? L->width - tx0 : n);
                if (ty >= L->height) real = 0;
                if (real && (sets & 1) && !(back && !look_up && L->thickness != LRT_THICKNESS_BACK_MAP))
                    lrt__row_heights(depth, (const unsigned char *)depth->data + stride * ty, tx0, real, qmax, h);
                if (real && look_up)
                    for (s = 0; s < real; ++s) c[s] = table[((const unsigned char *)depth->data + stride * ty)[tx0 + s]];
                else if (real && back && L->thickness != LRT_THICKNESS_BACK_MAP)
                    lrt__row_model_back_codes(L, depth, stride, ty, tx0, real, qmax, c, sets & 1 ? h : NULL);
                else if (real && back)
                    lrt__row_back_codes(depth, (const unsigned char *)depth->data + stride * ty,
                                        (const unsigned char *)depth->back->data + back_stride * ty, tx0, real, qmax, c);
                if (sets & 1)
                    for (s = real; s < n; ++s) h[s] = 0;
                if (sets & 2)
                    for (s = real; s < n; ++s) c[s] = 0;
            }
            for (set = 0; set < 2; ++set) {
                const size_t codes_at = set ? lrt__back_code_index(L) : 0u;
                const uint32_t *c0 = set ? backs[0] : codes[0], *c1 = set ? backs[1] : codes[1];
                if (!(sets & (1 << set))) continue;
                if (compact) {
                    /* scales past the chunk's last node stay 16: their reciprocals (four at a time) are never used */
                    uint32_t heights[16], scales[16] = {16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16};
                    float inv[16];
                    for (nx = chunk; nx <= last; ++nx) { /* heights and scales first (lrt__compact_bounds) */
                        const uint32_t px = (nx >> 1) * parent_step, k = nx - chunk;
                        const size_t node = L->levels[1].offset + row + (size_t)(nx >> 1) * 8u + (nx & 1u);
                        const size_t parent = parents + (size_t)(px >> 2) * 8u + (px & 3u);
                        scales[k] = lrt__compact_bounds(c0 + (size_t)k * 4u, c1 + (size_t)k * 4u, &heights[k]);
                        ((uint16_t *)bvh->nodes)[codes_at + lrt__compact_scale_index(L, node)] = (uint16_t)scales[k];
                        ((uint16_t *)bvh->nodes)[codes_at + lrt__code_index(L, parent) + (child_row | (nx & 1u))] =
                            (uint16_t)heights[k];
                    }
                    lrt__compact_inverses(scales, inv, last - chunk + 1u);
                    for (nx = chunk; nx <= last; ++nx) {
                        const uint32_t k = nx - chunk;
                        const size_t node = L->levels[1].offset + row + (size_t)(nx >> 1) * 8u + (nx & 1u);
                        const uint32_t word =
                            lrt__compact_steps(c0 + (size_t)k * 4u, c1 + (size_t)k * 4u, heights[k], scales[k], inv[k]);
                        memcpy((uint32_t *)bvh->nodes + codes_at / 2u + node, &word, 4);
                    }
                } else {
                    for (nx = chunk; nx <= last; ++nx) {
                        /* level 1 groups 2x4 (lrt_layout_node_index): node nx is 8 slots after nx - 2 */
                        const size_t node = L->levels[1].offset + row + (size_t)(nx >> 1) * 8u + (nx & 1u);
                        lrt__store_node4x2(bvh->nodes, codes_at + node * 8u, c0 + (size_t)(nx - chunk) * 4u,
                                           c1 + (size_t)(nx - chunk) * 4u);
                    }
                }
            }
        }
    }
}

/* Refit nodes [nx0,nx1] x [ny0,ny1] of level lv >= 2 from level lv-1, the
   codes that start at code index `codes` (0: the heights;
   lrt__back_code_index: the back codes, whose max is the deepest back as
   the heights' is the highest top). The 8 children of node (x, y) are
   contiguous: level lv-1's slots (row-major index of (x, y) in level lv) *
   8 + s. Level 2 over a compact level 1 has its codes already (written
   with the words): only its padding nodes are written here. */
static void lrt__refit_level(lrt_bvh *bvh, size_t codes, uint32_t lv, uint32_t nx0, uint32_t nx1, uint32_t ny0,
                             uint32_t ny1)
{
    const lrt_layout *L = &bvh->layout;
    const size_t child_base = L->levels[lv - 1].offset, base = L->levels[lv].offset;
    uint16_t *nodes = (uint16_t *)bvh->nodes;
    uint32_t nx, ny, s, c;
    for (ny = ny0; ny <= ny1; ++ny) {
        for (nx = nx0; nx <= nx1; ++nx) {
            uint16_t *out = nodes + codes + lrt__code_index(L, base + lrt_layout_node_index(L, lv, nx, ny));
            if (nx >= L->levels[lv].width || ny >= L->levels[lv].height) {
                /* a padding node has no children in memory: height 0 */
                memset(out, 0, 16);
            } else if (lv > 2 || L->level1_node_bytes == 16u) {
                const uint16_t *ch = nodes + codes + lrt__code_index(L, child_base + ((size_t)ny * L->levels[lv].width + nx) * 8u);
                for (s = 0; s < 8; ++s) {
                    uint16_t m = 0;
                    for (c = 0; c < 8; ++c) m = ch[s * 8 + c] > m ? ch[s * 8 + c] : m;
                    out[s] = m;
                }
            }
        }
    }
}

/* Refit texels [x0,x1] x [y0,y1] (inclusive) and everything above them. A
   full refit passes the padded grid of every level, so padding is written too. */
static void lrt__refit(lrt_bvh *bvh, const lrt_depth *depth, size_t stride, uint32_t x0, uint32_t x1, uint32_t y0,
                       uint32_t y1, int whole)
{
    const lrt_layout *L = &bvh->layout;
    uint32_t lv;
    for (lv = 1; lv <= L->level_count; ++lv) {
        const lrt_level *v = &L->levels[lv];
        uint32_t nx0 = x0 >> v->span_w_log2, nx1 = x1 >> v->span_w_log2;
        uint32_t ny0 = y0 >> v->span_h_log2, ny1 = y1 >> v->span_h_log2;
        if (whole || lv == L->level_count) {
            /* all slots of the level: the padded grid of its parent blocks */
            nx0 = ny0 = 0;
            if (lv == L->level_count) {
                nx1 = ny1 = 0;
            } else {
                nx1 = L->levels[lv + 1].width * v->block_w - 1;
                ny1 = L->levels[lv + 1].height * v->block_h - 1;
            }
        }
        if (lv == 1) {
            if (L->back_codes && L->thickness != LRT_THICKNESS_BACK_MAP) {
                lrt__refit_texel_parents(bvh, depth, stride, nx0, nx1, ny0, ny1, 3);
            } else {
                lrt__refit_texel_parents(bvh, depth, stride, nx0, nx1, ny0, ny1, 1);
                if (L->back_codes) lrt__refit_texel_parents(bvh, depth, stride, nx0, nx1, ny0, ny1, 2);
            }
        } else {
            lrt__refit_level(bvh, 0, lv, nx0, nx1, ny0, ny1);
            if (L->back_codes) lrt__refit_level(bvh, lrt__back_code_index(L), lv, nx0, nx1, ny0, ny1);
        }
    }
}

#define LRT__ALIGN 16u /* a 16-bit node */

/* The two floats from which lrt__model_back computes b(d) (lrt_layout.back_k),
   in double then rounded once. With s = (f - n) / f, n / z(d) = 1 - d s:
   CONSTANT: n / (z + T) = 1 / (q + T / n) with q = z / n = 1 / (1 - d s), and
   b = (1 - n / (z + T)) / s = d + u (T / n) / (q + T / n), u = 1 / s - d;
   RELATIVE: n / (z (1 + k)) = (1 - d s) / (1 + k), so b = (d + k / s) / (1 + k). */
static lrt_result lrt__model_constants(const lrt_build_options *o, float k[2])
{
    const double value = o->thickness_value, n = o->near_z, f = o->far_z;
    double inv_s, k0, k1;
    float f0, f1;
    if (!(value > 0.0 && value - value == 0.0 && n > 0.0 && n - n == 0.0 && f > n)) return LRT_ERROR_INVALID_THICKNESS;
    inv_s = f == (double)INFINITY ? 1.0 : f / (f - n); /* 1 / s: 1 with an infinite far plane */
    if (o->thickness == LRT_THICKNESS_CONSTANT) {
        k0 = inv_s;
        k1 = value / n;
    } else {
        k0 = value * inv_s;
        k1 = 1.0 + value;
    }
    f0 = (float)k0;
    f1 = (float)k1;
    if (!(f0 - f0 == 0.0f && f1 - f1 == 0.0f && f1 > 0.0f)) return LRT_ERROR_INVALID_THICKNESS;
    k[0] = f0;
    k[1] = f1;
    return LRT_SUCCESS;
}

/* The options' node width and thickness model, then the layout they make. */
static lrt_result lrt__options_layout(uint32_t width, uint32_t height, lrt_format format, const lrt_build_options *options,
                                      lrt_layout *layout)
{
    uint32_t b = options ? options->node_bits : 0u, thickness = options ? options->thickness : 0u;
    lrt_result r;
    if (b == LRT_NODE_BITS_AUTO) b = format == LRT_FORMAT_UNORM8 ? 8u : 16u;
    if (b != 8 && b != 16) return LRT_ERROR_INVALID_OPTION;
    if (thickness > LRT_THICKNESS_RELATIVE) return LRT_ERROR_INVALID_THICKNESS;
    if ((r = lrt_layout_compute(width, height, b, layout)) != LRT_SUCCESS) return r;
    if (thickness != LRT_THICKNESS_INFINITE) {
        layout->back_codes = 1;
        layout->bytes *= 2u; /* < 2^32 for 16384^2 16-bit nodes */
        layout->thickness = thickness;
    }
    if (thickness >= LRT_THICKNESS_CONSTANT) return lrt__model_constants(options, layout->back_k);
    return LRT_SUCCESS;
}

LINEAR_RT_DEF lrt_result lrt_bvh_memory_size(uint32_t width, uint32_t height, lrt_format format,
                                             const lrt_build_options *options, size_t *out_bytes)
{
    lrt_layout L;
    lrt_result r;
    if (!out_bytes) return LRT_ERROR_NULL_POINTER;
    if ((r = lrt__check_size(width, height)) != LRT_SUCCESS) return r;
    if (!lrt__format_bytes(format)) return LRT_ERROR_INVALID_FORMAT;
    if ((r = lrt__options_layout(width, height, format, options, &L)) != LRT_SUCCESS) return r;
    *out_bytes = L.bytes + LRT__ALIGN - 1; /* room to align caller memory */
    return LRT_SUCCESS;
}

/* Shared by both builds: validate everything, then lay out. */
static lrt_result lrt__prepare(const lrt_bvh *bvh, const lrt_depth *depth, const lrt_build_options *options,
                               lrt_layout *layout, size_t *stride)
{
    size_t back_stride;
    lrt_result r;
    if (!bvh) return LRT_ERROR_NULL_POINTER;
    if (bvh->built == LRT__BUILT) return LRT_ERROR_ALREADY_BUILT; /* never leak it, never free what is not ours */
    if ((r = lrt__check_depth(depth, stride)) != LRT_SUCCESS) return r;
    if ((r = lrt__options_layout(depth->width, depth->height, depth->format, options, layout)) != LRT_SUCCESS) return r;
    return lrt__check_back(depth, layout->thickness, &back_stride);
}

static void lrt__finish_build(lrt_bvh *bvh, const lrt_layout *layout, void *nodes, const lrt_allocator *allocator,
                              const lrt_depth *depth, size_t stride)
{
    memset(bvh, 0, sizeof *bvh);
    bvh->layout = *layout;
    bvh->nodes = nodes;
    if (allocator) bvh->allocator = *allocator;
    bvh->format = depth->format;
    bvh->depth_flags = depth->flags;
    bvh->built = LRT__BUILT;
    lrt__refit(bvh, depth, stride, 0, layout->width - 1, 0, layout->height - 1, 1);
}

static void *lrt__default_alloc(void *user, size_t size) { return LINEAR_RT_MALLOC(size, user); }
static void lrt__default_free(void *user, void *ptr) { LINEAR_RT_FREE(ptr, user); }

LINEAR_RT_DEF lrt_result lrt_bvh_build(lrt_bvh *bvh, const lrt_depth *depth, const lrt_build_options *options,
                                       const lrt_allocator *allocator)
{
    lrt_allocator a;
    lrt_layout layout;
    size_t stride;
    void *nodes;
    lrt_result r;
    if ((r = lrt__prepare(bvh, depth, options, &layout, &stride)) != LRT_SUCCESS) return r;
    if (allocator) {
        if (!allocator->alloc || !allocator->free) return LRT_ERROR_NULL_POINTER;
        a = *allocator;
    } else {
        a.alloc = lrt__default_alloc;
        a.free = lrt__default_free;
        a.user = NULL;
    }
    nodes = a.alloc(a.user, layout.bytes);
    if (!nodes) return LRT_ERROR_OUT_OF_MEMORY;
    lrt__finish_build(bvh, &layout, nodes, &a, depth, stride);
    return LRT_SUCCESS;
}

LINEAR_RT_DEF lrt_result lrt_bvh_build_in(lrt_bvh *bvh, const lrt_depth *depth, const lrt_build_options *options,
                                          void *memory, size_t memory_bytes)
{
    lrt_layout layout;
    size_t stride, skip;
    lrt_result r;
    if ((r = lrt__prepare(bvh, depth, options, &layout, &stride)) != LRT_SUCCESS) return r;
    if (!memory) return LRT_ERROR_NULL_POINTER;
    if (memory_bytes < layout.bytes + LRT__ALIGN - 1) return LRT_ERROR_BUFFER_TOO_SMALL;
    /* nodes are read as 16-bit words: start them on a node boundary */
    skip = (LRT__ALIGN - (size_t)((uintptr_t)memory % LRT__ALIGN)) % LRT__ALIGN;
    lrt__finish_build(bvh, &layout, (unsigned char *)memory + skip, NULL, depth, stride);
    return LRT_SUCCESS;
}

LINEAR_RT_DEF void lrt_bvh_destroy(lrt_bvh *bvh)
{
    if (!bvh) return;
    if (bvh->built == LRT__BUILT && bvh->allocator.free && bvh->nodes) bvh->allocator.free(bvh->allocator.user, bvh->nodes);
    memset(bvh, 0, sizeof *bvh);
}

/* The BVH and the depth it was made from must agree before anything is read. */
static lrt_result lrt__check_pair(const lrt_bvh *bvh, const lrt_depth *depth, size_t *stride)
{
    size_t back_stride;
    lrt_result r;
    if (!bvh) return LRT_ERROR_NULL_POINTER;
    if (bvh->built != LRT__BUILT || !bvh->nodes) return LRT_ERROR_INVALID_BVH;
    if ((r = lrt__check_depth(depth, stride)) != LRT_SUCCESS) return r;
    if (depth->width != bvh->layout.width || depth->height != bvh->layout.height) return LRT_ERROR_SIZE_MISMATCH;
    if (depth->format != bvh->format || depth->flags != bvh->depth_flags) return LRT_ERROR_DEPTH_MISMATCH;
    return lrt__check_back(depth, bvh->layout.thickness, &back_stride);
}

LINEAR_RT_DEF lrt_result lrt_bvh_update(lrt_bvh *bvh, const lrt_depth *depth, const lrt_rect *dirty)
{
    size_t stride;
    lrt_result r;
    if ((r = lrt__check_pair(bvh, depth, &stride)) != LRT_SUCCESS) return r;
    if (!dirty) {
        lrt__refit(bvh, depth, stride, 0, depth->width - 1, 0, depth->height - 1, 1);
        return LRT_SUCCESS;
    }
    if (dirty->x > depth->width || dirty->width > depth->width - dirty->x || dirty->y > depth->height ||
        dirty->height > depth->height - dirty->y)
        return LRT_ERROR_INVALID_RECT;
    if (dirty->width == 0 || dirty->height == 0) return LRT_SUCCESS;
    lrt__refit(bvh, depth, stride, dirty->x, dirty->x + dirty->width - 1, dirty->y, dirty->y + dirty->height - 1, 0);
    return LRT_SUCCESS;
}

/* lrt_hit is 4 words on the CPU and in the kernels' hit buffer (lrt_trace.comp) */
typedef char lrt__hit_is_16_bytes[sizeof(lrt_hit) == 16 && sizeof(lrt_ray) == 32 ? 1 : -1];

/* ================================================================= >>setup
   5. A ray's set-up: the types the walk shares, the exact arithmetic at the
      edge of float range and the rare set-up (lrt__setup_rare), the set-up
      every ray takes (lrt__setup_ray) and where its walk starts
      (lrt__start_node). Rays at the edge of float range (a component below
      2^-100 or above 2^16) are set up apart, so that the walk's floats stay
      exact for them: ordinary rays pay one test on their bits.
   ========================================================================== */

/* max/min that drop a NaN candidate (acc is never NaN) */
#define LRT__MAX_KEEP(cand, acc) ((cand) > (acc) ? (cand) : (acc))
#define LRT__MIN_KEEP(cand, acc) ((cand) < (acc) ? (cand) : (acc))

/* A box is met when enter <= exit. Each plane's t is rounded on its own, so
   a ray through a texel corner (exactly: a one-point interval) can find the
   interval empty by an ulp at one corner and not at the next, tie-breaking
   one straight line both ways. Exits are widened by 2^-21 of their size (a
   few ulps, well inside docs/MODEL.md's 8-ulp tolerance) before that comparison,
   so a corner the ray touches always counts; the front-to-back walk then
   keeps the first. The product is exact (a power of two), so fused or not,
   every path computes the same float. An exit that would widen past
   FLT_MAX (tmax = FLT_MAX is the usual "no limit"), or is infinite, stays
   as it is: an entry of +inf (a slab never entered) must never pass. */
#define LRT__WIDEN_EXIT (1.0f / 2097152.0f)
LRT__FORCE_INLINE float lrt__widen(float exit)
{
    float w = exit + fabsf(exit) * LRT__WIDEN_EXIT;
    return w <= 3.40282347e38f ? w : exit;
}

LRT__FORCE_INLINE int lrt__finite(float f) { return f - f == 0.0f; }

LRT__FORCE_INLINE uint32_t lrt__sign_bit(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return u >> 31;
}

/* Entering and leaving t of the slab [lo, hi] along one axis. */
LRT__FORCE_INLINE void lrt__slab(float lo, float hi, float o, float iv, uint32_t neg, float *enter, float *exit)
{
    float a = (lo - o) * iv, b = (hi - o) * iv;
    *enter = LRT__MAX_KEEP(neg ? b : a, *enter);
    *exit = LRT__MIN_KEEP(neg ? a : b, *exit);
}

LRT__FORCE_INLINE float lrt__maxf(float a, float b) { return a > b ? a : b; }

/* Error-free sum (Knuth) and product of floats: a + b = *s + *e and
   a * b = *p + *e exactly. The product's error is exact in double (a float
   product has 48 bits), so no fma is needed and contraction changes nothing;
   the kernels get the same floats from Dekker's split. Both are exact where
   nothing overflows and the product's error is no subnormal: every caller
   keeps its operands so. */
LRT__FORCE_INLINE void lrt__two_sum(float a, float b, float *s, float *e)
{
    float ss = a + b, bb = ss - a;
    *s = ss;
    *e = (a - (ss - bb)) + (b - bb);
}

LRT__FORCE_INLINE void lrt__two_prod(float a, float b, float *p, float *e)
{
    *p = a * b;
    *e = (float)((double)a * (double)b - (double)*p);
}

/* ---- arithmetic at the edge of float range (lrt__crossing, lrt__setup_rare).
   Integers and powers of two from the bits, products scaled into range
   first: the kernels (shaders/linear_rt.glsl) compute the same floats. ---- */

/* floor(log2 |f|) of a finite nonzero float, subnormals included */
LRT__FORCE_INLINE int lrt__ilogb(float f)
{
    uint32_t u;
    int e = -150;
    memcpy(&u, &f, 4);
    u &= 0x7fffffffu;
    if (u >= 0x00800000u) return (int)(u >> 23) - 127;
    while (u) {
        u >>= 1;
        ++e;
    }
    return e;
}

/* 2^k exactly, k in [-149, 127] */
LRT__FORCE_INLINE float lrt__pow2(int k)
{
    uint32_t u = k >= -126 ? (uint32_t)(k + 127) << 23 : 1u << (k + 149);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

/* f 2^-ilogb(f): the significand of a finite nonzero float, in [1, 2), exactly */
static float lrt__signif(float f) { return ldexpf(f, -lrt__ilogb(f)); }

/* Adds x to the expansion acc[0..*m) (Shewchuk's grow-expansion): the sum
   stays exact, its parts grow in size and do not overlap. */
static void lrt__grow(float *acc, int *m, float x)
{
    int j;
    for (j = 0; j < *m; ++j) {
        float hi, lo;
        lrt__two_sum(acc[j], x, &hi, &lo);
        acc[j] = lo;
        x = hi;
    }
    acc[(*m)++] = x;
}

/* The sign of an expansion: that of its largest nonzero part. */
static int lrt__expansion_sign(const float *acc, int m)
{
    while (m-- > 0)
        if (acc[m] != 0.0f) return acc[m] > 0.0f ? 1 : -1;
    return 0;
}

/* Appends a b 2^(extra - scale) to an expansion as an exact pair; the
   caller keeps sh = ilogb(a) + ilogb(b) + extra - scale in [-73, 122], so
   that both parts are normal floats and their sums cannot overflow. */
static void lrt__grow_prod(float *acc, int *m, float a, float b, int extra, int scale)
{
    float p, e, f;
    if (a == 0.0f || b == 0.0f) return;
    f = lrt__pow2(lrt__ilogb(a) + lrt__ilogb(b) + extra - scale);
    lrt__two_prod(lrt__signif(a), lrt__signif(b), &p, &e); /* in [1, 4): exact */
    lrt__grow(acc, m, p * f);
    lrt__grow(acc, m, e * f);
}

/* An expansion's value, the largest part last: faithful. *lo gets the sum
   of that sum's rounding errors, the part of the value it leaves out
   (lrt__expansion_div needs it). */
static float lrt__expansion_value(const float *acc, int m, float *lo)
{
    float sum = 0.0f, err;
    int i;
    *lo = 0.0f;
    for (i = 0; i < m; ++i) {
        lrt__two_sum(sum, acc[i], &sum, &err);
        *lo += err;
    }
    return sum;
}

/* An expansion's value divided by y in [1, 2), times 2^shift, faithfully
   (less than an ulp off): a float division of the rounded value rounds
   twice, which can land an ulp past the float next to the exact quotient
   and put a restart point off the screen (crashes-found 22). The value as
   hi + lo (lrt__expansion_value), scaled to [1, 2) so that the product
   below cannot overflow, then the division's remainder, exact but for lo,
   divided once more. */
static float lrt__expansion_div(const float *acc, int m, float y, int shift)
{
    float lo, hi = lrt__expansion_value(acc, m, &lo), q, p, e;
    int k;
    if (hi == 0.0f) return 0.0f;
    k = lrt__ilogb(hi);
    hi = ldexpf(hi, -k);
    lo = ldexpf(lo, -k);
    q = hi / y;
    lrt__two_prod(q, y, &p, &e); /* q y = p + e; hi - p is exact (p is within an ulp of hi) */
    return ldexpf(q + (((hi - p) - e) + lo) / y, k + shift);
}

/* The restart of a far-away ray (below): (b1 + b2) + (plane - o_a) v_b / v_a,
   or (b1 + b2) + t v_b 2^vexp (by_t), as an exact float expansion acc[0..m)
   times 2^scale (times 1 / v_a unless by_t). The products come in two
   groups, (b1 + b2) v_a and (s + e) v_b with plane - o_a = s + e exactly
   (or t v_b); within a group the second is below 2^-24 of the first and
   above 2^-166 of it, so one scale holds all its bits; a group 2^30 or more
   below the other is left out: no cancellation can make it matter beyond
   2^-29 of the sum. The largest product lands in [2^122, 2^124). */
static void lrt__crossing_sum(float b1, float b2, float o_a, float v_b, float v_a, float plane, int by_t, float t,
                              int vexp, float *acc, int *m, int *scale)
{
    float s = t, e = 0.0f, va = v_a;
    int lb = -10000, ls = -10000, top;
    *m = 0;
    if (by_t) va = 1.0f; /* (b1 + b2) 1 + t v_b 2^vexp */
    else lrt__two_sum(plane, -o_a, &s, &e);
    if (b1 != 0.0f) lb = lrt__ilogb(b1) + lrt__ilogb(va);
    if (s != 0.0f && v_b != 0.0f) ls = lrt__ilogb(s) + lrt__ilogb(v_b) + (by_t ? vexp : 0);
    top = lb > ls ? lb : ls;
    *scale = top - 122;
    if (top == -10000) return; /* 0 */
    if (lb >= top - 30) {
        lrt__grow_prod(acc, m, b1, va, 0, *scale);
        lrt__grow_prod(acc, m, b2, va, 0, *scale);
    }
    if (ls >= top - 30) {
        lrt__grow_prod(acc, m, s, v_b, by_t ? vexp : 0, *scale);
        lrt__grow_prod(acc, m, e, v_b, 0, *scale);
    }
}

/* A coordinate of the restart point of a far-away ray, from that exact
   expansion rounded (faithfully): o_b + (plane - o_a) v_b / v_a where the
   ray enters through plane on axis a, or o_b + t v_b 2^vexp (by_t). No
   product overflows and none of o_b, v_b, v_a is flushed however far apart
   their sizes (fuzz 6b: a v_b 2^120 times smaller than v_a was). far_z: a z
   that rounds to 1, the far plane, while the exact one is not 1 becomes the
   float next to 1 on the exact side: on the far plane the ray would meet
   the flat boxes of far texels, which neither side of it does. The kernels
   compute the very same floats (shaders/linear_rt.glsl, lrt_crossing). */
static float lrt__crossing(float o_b, float o_a, float v_b, float v_a, float plane, int by_t, float t, int vexp,
                           int far_z)
{
    float acc[8], r, lo, d1, d2;
    int m, scale, side;
    if (v_b == 0.0f || (by_t && t == 0.0f)) return o_b;
    lrt__crossing_sum(o_b, 0.0f, o_a, v_b, v_a, plane, by_t, t, vexp, acc, &m, &scale);
    if (m == 0) return 0.0f;
    if (by_t) r = ldexpf(lrt__expansion_value(acc, m, &lo), scale);
    else r = lrt__expansion_div(acc, m, lrt__signif(v_a), scale - lrt__ilogb(v_a));
    if (!far_z || r != 1.0f) return r;
    /* the sign of the exact coordinate minus 1: the same sum from o_b - 1 */
    lrt__two_sum(o_b, -1.0f, &d1, &d2);
    lrt__crossing_sum(d1, d2, o_a, v_b, v_a, plane, by_t, t, vexp, acc, &m, &scale);
    side = lrt__expansion_sign(acc, m) * (!by_t && v_a < 0.0f ? -1 : 1);
    return side > 0 ? 1.00000012f : side < 0 ? 0.99999994f : 1.0f;
}

/* A ray at the edge of float range (lrt__setup_rare) is judged off the
   screen or not at tmax exactly: the sign of o + t v - c, t >= 0, c the
   screen's edge, from an exact expansion where t v and c - o are of a size,
   else from the larger alone. */
static int lrt__side(float o, float v, float t, float c)
{
    float d1, d2, acc[8];
    int m = 0, e, ed, sign;
    lrt__two_sum(c, -o, &d1, &d2); /* c - o = d1 + d2 */
    if (v == 0.0f || t == 0.0f) return d1 > 0.0f ? -1 : d1 < 0.0f ? 1 : 0;
    if (d1 == 0.0f) return v > 0.0f ? 1 : -1;
    e = lrt__ilogb(t) + lrt__ilogb(v); /* 2^e <= |t v| < 2^(e+2) */
    ed = lrt__ilogb(d1);               /* 2^ed <= |d1| < 2^(ed+1), |d2| <= 2^(ed-24) */
    if (e >= ed + 2) return v > 0.0f ? 1 : -1;
    if (e + 3 <= ed) return d1 > 0.0f ? -1 : 1;
    lrt__grow_prod(acc, &m, t, v, 0, e);
    lrt__grow(acc, &m, -ldexpf(d1, -e));
    if (d2 != 0.0f && lrt__ilogb(d2) - e >= -100) {
        lrt__grow(acc, &m, -ldexpf(d2, -e));
        return lrt__expansion_sign(acc, m);
    }
    /* a d2 below 2^-100 of the scale decides only a tie of the rest (whose
       parts are multiples of 2^-48 of it) */
    sign = lrt__expansion_sign(acc, m);
    return sign ? sign : d2 > 0.0f ? -1 : d2 < 0.0f ? 1 : 0;
}

/* Is o + t v on the screen rectangle (closed) at t = tmax? exactly */
static int lrt__on_screen_at_tmax(const lrt_ray *ray, uint32_t width, uint32_t height)
{
    return lrt__side(ray->origin[0], ray->dir[0], ray->tmax, 0.0f) >= 0 &&
           lrt__side(ray->origin[0], ray->dir[0], ray->tmax, (float)width) <= 0 &&
           lrt__side(ray->origin[1], ray->dir[1], ray->tmax, 0.0f) >= 0 &&
           lrt__side(ray->origin[1], ray->dir[1], ray->tmax, (float)height) <= 0;
}

/* A subnormal float read as 0 of its sign (docs/MODEL.md: a GPU may flush
   them, and every tracer must answer alike); in integers, so that no mode
   of the FPU changes it. */
LRT__FORCE_INLINE float lrt__flush_float(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    if ((u & 0x7f800000u) == 0u) u &= 0x80000000u;
    memcpy(&f, &u, 4);
    return f;
}

/* The ray with each subnormal read as 0 of its sign, in *copy. */
static const lrt_ray *lrt__flush_ray(const lrt_ray *ray, lrt_ray *copy)
{
    float f[8];
    int k;
    memcpy(f, ray, sizeof f);
    for (k = 0; k < 8; ++k) f[k] = lrt__flush_float(f[k]);
    memcpy(copy, f, sizeof f);
    return copy;
}

/* t 2^e, a positive t kept positive and every t finite (a scaled tmin or
   tmax that underflowed to 0 made [tmin, tmax] start on the origin: fuzz 3) */
LRT__FORCE_INLINE float lrt__scale_t(float t, int e)
{
    float r = ldexpf(t, e);
    if (r == 0.0f && t > 0.0f) return 1.40129846e-45f; /* the least float */
    return r <= 3.40282347e38f ? r : 3.40282347e38f;
}

/* (p - o) / (v 2^-e), each step rounded once; +-inf past the float range */
static float lrt__plane_t(float p, float o, float v, int e)
{
    const float n = p - o;
    return n == 0.0f ? 0.0f : ldexpf(lrt__signif(n) / lrt__signif(v), lrt__ilogb(n) - lrt__ilogb(v) + e);
}

/* 2^-77 */
#define LRT__TINY_O 6.61744490e-24f
/* the bits of 2^-100 and 2^16 (lrt__setup_ray's test for rare rays) */
#define LRT__RARE_TINY 0x0d800000u
#define LRT__RARE_HUGE 0x47800000u

#if defined(__GNUC__) || defined(__clang__)
#define LRT__NOINLINE __attribute__((noinline))
#define LRT__UNLIKELY(x) __builtin_expect(!!(x), 0)
#else
#define LRT__NOINLINE
#define LRT__UNLIKELY(x) (x)
#endif

/* The restart's axis: the entering planes' t are rounded, and where two
   round to the same float the first taken may not be the last plane the
   ray crosses; restarted there, the ray would start off the screen box on
   another axis, and rounding that coordinate (a slow axis amplifies it)
   could put a ray that only touches the box at a corner inside it. The
   crossings n at axis' plane are exact values rounded once, so an axis
   whose crossing is still before its entering plane (below 0, or above
   hi when it runs backwards) was entered later: returns it, or -1. */
static int lrt__entered_later(const float n[3], const float v[3], const float hi[3], int axis)
{
    int k, later = -1;
    for (k = 0; k < 3 && later < 0; ++k)
        if (k != axis && v[k] != 0.0f && (lrt__sign_bit(v[k]) ? n[k] > hi[k] : n[k] < 0.0f)) later = k;
    return later;
}

/* An origin so far from the screen that (plane - o) loses the screen's
   planes: such a ray restarts where it enters the screen box, in
   lrt__setup_rare, which lrt__setup_ray sends it to (lrt__setup8 tests the
   same on 8 lanes). */
LRT__FORCE_INLINE int lrt__far_origin(const float o[3], uint32_t width, uint32_t height)
{
    return (fabsf(o[0]) > 2.0f * (float)width + 16.0f) | (fabsf(o[1]) > 2.0f * (float)height + 16.0f) | (fabsf(o[2]) > 4.0f);
}

/* Whether a point's coordinate o lies in [0, hi], or (past) whether the
   point just past it along a direction of sign neg (zero: none) does. */
static int lrt__point_in(float o, uint32_t neg, int zero, float hi, int past)
{
    return past ? (o > 0.0f || (o == 0.0f && (!neg || zero))) && (o < hi || (o == hi && (neg || zero)))
                : o >= 0.0f && o <= hi;
}

/* The lowest set bit of m (m != 0). */
LRT__FORCE_INLINE uint32_t lrt__lowest_bit(uint32_t m)
{
#if defined(__GNUC__) || defined(__clang__)
    return (uint32_t)__builtin_ctz(m);
#else
    uint32_t k = 0;
    while (!((m >> k) & 1u)) ++k;
    return k;
#endif
}

/* Bits needed to write m: 0 for 0. */
LRT__FORCE_INLINE uint32_t lrt__bit_length(uint32_t m)
{
#if defined(__GNUC__) || defined(__clang__)
    return m ? 32u - (uint32_t)__builtin_clz(m) : 0u;
#else
    uint32_t k = 0;
    while (m >> k) ++k;
    return k;
#endif
}

#endif /* !LRT__AVX2_PASS: the rest of sections setup, walk and batch-avx2 is compiled in every pass */

/* The node test's register: 8 lanes with AVX2, 4 with SSE2. */
#if LRT__AVX
typedef __m256 lrt__lanes;
#define LRT__BROADCAST(x) _mm256_set1_ps(x)
/* a * b + c where a * b is exact (small integers times powers of two), so
   fused or not it is the same float: one instruction where FMA is there */
#define LRT__EXACT_MADD8(a, b, c) _mm256_fmadd_ps(a, b, c)
#elif LRT__SSE
typedef __m128 lrt__lanes;
#define LRT__BROADCAST(x) _mm_set1_ps(x)
#endif

typedef struct lrt__ray_setup {
    float o[3], v[3], iv[3];
    uint32_t neg_x, neg_y, neg_z; /* sign bits of the direction (-0 counts) */
    float t_lo, t_hi;             /* the ray clipped to the screen and to z <= 1 */
    float t_base;                 /* t of the origin used here on the caller's ray */
    int zk;                       /* 0, or z (o.z, v.z and every depth plane) is scaled by 2^zk (lrt__setup_rare) */
    const struct lrt__signs *sg;  /* the node test's constants of the x and y direction signs (lrt__walk_setup) */
#if LRT__SSE
    lrt__lanes vo[3], viv[3], vt_lo, vt_hi; /* the same, broadcast once for every node test */
#endif
#if LRT__AVX
    /* the node test above level 1 (lrt__cull_children): a plane's t in one
       fused step, p * iv + c, with c moved out by more than that step's
       error (lrt__cull_axis) */
    lrt__lanes cull_iv[2], cull_enter[2], cull_exit[2], cull_za, cull_zb, cull_hi;
    lrt__lanes cull_ba, cull_bb; /* the back plane's t: back code * ba + bb (back-map trees) */
#endif
} lrt__ray_setup;

/* What the node test needs of a ray's x and y direction signs: four sets,
   made once per trace call, so a ray only picks one. */
typedef struct lrt__signs {
    uint32_t flip[2];             /* front-to-back slot order of wide (4x2) and tall (2x4) nodes */
#if LRT__AVX
    /* AVX2 tests a node's children in visiting order: lane k is slot
       k ^ flip[tall], whose codes order[tall] fetches and whose column and
       row planes (in spans) these are, so a mask needs no reordering */
    __m256i order[2];
    __m256 kx_enter[2], kx_exit[2], ky_enter[2], ky_exit[2];
#elif LRT__SSE
    __m128 k_enter[2], k_exit[2]; /* entering / leaving plane of 4 columns (x) or rows (y), in spans */
    __m128 k_rows2, k_cols2;      /* 2 rows (columns): enter, leave of the 1st, of the 2nd (cols: enters, then leaves) */
#endif
} lrt__signs;

/* The lane of a node test's enter / exit arrays that holds the child met
   vis-th in visiting order (slot vis ^ flip): AVX2 tests in visiting order
   (lrt__signs), SSE2 and scalar code in slot order. */
#if LRT__AVX
#define LRT__LANE(vis, slot) (vis)
#else
#define LRT__LANE(vis, slot) (slot)
#endif

/* The t where the ray's z meets the depth plane of a raw depth. A unorm v
   is no float: v/max - o.z is taken as (v - o.z max)/max with o.z max split
   exactly, else its rounding, divided by a grazing ray's tiny v.z, would move
   the hit along the texel top by far more than float rounding of t. v = max
   is depth 1, the far plane, computed as the clip computes it. The kernels
   compute the same floats (lrt_depth_plane). A ray whose z is scaled by
   2^zk (lrt__setup_rare: a v.z too small to invert beside the other
   components) scales the depth by 2^zk too, exactly. */
static float lrt__depth_plane_scaled(const lrt__ray_setup *s, lrt_format format, uint32_t raw)
{
    const uint32_t vmax = format == LRT_FORMAT_UNORM8 ? 255u : 65535u;
    float p, e, n;
    if (format == LRT_FORMAT_FLOAT32 || raw == vmax) {
        float d = 1.0f;
        if (format == LRT_FORMAT_FLOAT32) memcpy(&d, &raw, 4);
        return (ldexpf(d, s->zk) - s->o[2]) * s->iv[2];
    }
    lrt__two_prod(s->o[2], (float)vmax, &p, &e);
    n = (ldexpf((float)raw, s->zk) - p) - e;
    return (n * (vmax == 255u ? 1.0f / 255.0f : 1.0f / 65535.0f)) * s->iv[2];
}

LRT__FORCE_INLINE float lrt__depth_plane(const lrt__ray_setup *s, lrt_format format, uint32_t raw)
{
    const uint32_t vmax = format == LRT_FORMAT_UNORM8 ? 255u : 65535u;
    float p, e, n, t;
    if (s->zk) {
        t = lrt__depth_plane_scaled(s, format, raw); /* rare */
    } else if (format == LRT_FORMAT_FLOAT32 || raw == vmax) {
        float d = 1.0f;
        if (format == LRT_FORMAT_FLOAT32) memcpy(&d, &raw, 4);
        t = (d - s->o[2]) * s->iv[2];
    } else {
        lrt__two_prod(s->o[2], (float)vmax, &p, &e);
        n = ((float)raw - p) - e;
        t = (n * (vmax == 255u ? 1.0f / 255.0f : 1.0f / 65535.0f)) * s->iv[2];
    }
    return t;
}

/* Clips the ray to the screen rectangle and to 0 <= z <= 1 (nothing solid
   lies in front of the near plane or beyond the far one; a depth plane's t
   is then only ever taken for a z in range, where o.z * 65535 cannot
   overflow). Returns the kind a miss would have: off the screen when the
   rectangle's part of [tmin, tmax] is empty or ends before tmax. */
LRT__FORCE_INLINE uint32_t lrt__clip(lrt__ray_setup *s, uint32_t width, uint32_t height, float tmin, float tmax)
{
    /* the far plane's t the way the texel test computes depth planes, so a
       far-plane texel (depth 1) is met exactly at the clip */
    float xy_enter = -INFINITY, xy_exit = INFINITY, t1 = lrt__depth_plane(s, LRT_FORMAT_FLOAT32, 0x3f800000u);
    float t0 = (0.0f - s->o[2]) * s->iv[2]; /* v.z = 0: -inf, +inf or NaN (o.z = 0: dropped) */
    uint32_t kind;
    lrt__slab(0.0f, (float)width, s->o[0], s->iv[0], s->neg_x, &xy_enter, &xy_exit);
    lrt__slab(0.0f, (float)height, s->o[1], s->iv[1], s->neg_y, &xy_enter, &xy_exit);
    s->t_lo = LRT__MAX_KEEP(xy_enter, tmin);
    s->t_hi = LRT__MIN_KEEP(xy_exit, tmax);
    kind = (s->t_lo > s->t_hi || xy_exit < tmax) ? LRT_MISS_OFF_SCREEN : LRT_MISS_TMAX;
    if (s->neg_z) {
        s->t_lo = LRT__MAX_KEEP(t1, s->t_lo);
        s->t_hi = LRT__MIN_KEEP(t0, s->t_hi);
    } else {
        s->t_lo = LRT__MAX_KEEP(t0, s->t_lo);
        s->t_hi = LRT__MIN_KEEP(t1, s->t_hi);
    }
    return kind;
}

/* The set-up of a ray at the edge of float range (lrt__setup_ray says which:
   a component of o or v below 2^-100, a v_k of 2^16 or more, ...; fuzz 3,
   4, 5). The same steps as lrt__setup_ray, on the ray rescaled to max |v|
   in [1, 2) (t counted in units where the ray crosses the screen box within
   |t| <= 2^17, after a restart or from an origin near the screen), so that
   - a plane crossing too close to the origin for float, say
     (plane - o) / 3e23 = 3e-62, is no longer rounded to 0 (fuzz 5);
   - tmin and tmax are scaled by 2^e, a positive one kept positive (fuzz 3);
   - a component v_k below 2^-126 after the rescale (beside the largest:
     its 1/v_k may be +-inf, and (plane - o) * inf is NaN on a plane: fuzz 4)
     moves o_k by less than 2^-109 while the ray is on the screen, so it can
     cross no plane but one through o_k itself, the plane 0 when o_k is
     within 2^-77 of it (x, y), or a depth plane near o.z. Such an x or y
     keeps o_k and takes 1/v_k = +-FLT_MAX (exact on a plane through o_k,
     past 2^17 for every plane 2^-100 or more away); an o_k within 2^-77 of
     0 is scaled with its v_k by a power of two (only the plane 0 is near:
     the scaled ray crosses it exactly when the true one does, the plane 1
     stays far), or moved to +-2^-77 when it leaves or enters past 2^29. A z
     is scaled by 2^zk, its depth planes with it (lrt__depth_plane), so that
     1/v.z is finite: exact for texels, and the nodes' unscaled bounds stay
     below every texel's scaled depth, so their culling stays conservative.
   The kind of a miss is decided exactly: is the caller's ray on the screen
   at tmax (docs/MODEL.md). Returns as lrt__setup_ray. */
/* The restart of lrt__setup_rare's ray from a far-away origin where it
   enters the screen box, with crossings that take every size. The entering
   axis lands on its plane exactly, the others at the exact crossing rounded
   once, so the new origin is off the exact entry point by a rounding of a
   coordinate inside the screen, far below one float ulp of the old one
   (docs/MODEL.md). Returns 0 when the ray enters past tmax, never, or
   beyond the float range. */
static int lrt__restart_far(const lrt_ray *ray, const float hi[3], int e, lrt__ray_setup *s, float *tmin, float *tmax)
{
    float te = *tmin, plane = 0.0f, n[3];
    int axis = -1, tries, k, ok;
    for (k = 0; k < 3; ++k) {
        float p, en;
        if (ray->dir[k] == 0.0f) continue;
        p = lrt__sign_bit(ray->dir[k]) ? hi[k] : 0.0f;
        en = lrt__plane_t(p, s->o[k], ray->dir[k], e);
        if (en > te) {
            te = en;
            axis = k;
            plane = p;
        }
    }
    ok = te <= *tmax; /* enters past tmax, or never */
    for (tries = 0; ok && tries < 3; ++tries) {
        for (k = 0; k < 3; ++k) {
            if (axis < 0) n[k] = lrt__crossing(s->o[k], 0.0f, ray->dir[k], 1.0f, 0.0f, 1, te, -e, k == 2);
            else if (k == axis) n[k] = plane;
            else n[k] = lrt__crossing(s->o[k], s->o[axis], ray->dir[k], ray->dir[axis], plane, 0, 0.0f, 0, k == 2);
            ok &= lrt__finite(n[k]); /* beyond the float range there */
        }
        /* the last try keeps its axis: n and te must be the same
           crossing's (crashes-found 19: a third switch left n at one
           axis's plane and te at another's) */
        if (!ok || axis < 0 || tries == 2 || (k = lrt__entered_later(n, ray->dir, hi, axis)) < 0) break;
        axis = k; /* see lrt__entered_later */
        plane = lrt__sign_bit(ray->dir[k]) ? hi[k] : 0.0f;
        te = lrt__plane_t(plane, s->o[k], ray->dir[k], e);
    }
    if (ok) {
        for (k = 0; k < 3; ++k) s->o[k] = n[k];
        s->t_base = te;
        *tmin = 0.0f;
        *tmax = *tmax - te;
    }
    return ok;
}

static LRT__NOINLINE int lrt__setup_rare(const lrt_ray *caller_ray, uint32_t width, uint32_t height, lrt__ray_setup *s,
                                         float *t_scale, uint32_t *kind)
{
    const float hi[3] = {(float)width, (float)height, 1.0f};
    lrt_ray flushed;
    const lrt_ray *ray = lrt__flush_ray(caller_ray, &flushed);
    float m = 0.0f, tmin = ray->tmin, tmax = ray->tmax;
    int e = 0, k, ok = lrt__finite(tmin) && lrt__finite(tmax) && tmin >= 0.0f && tmin <= tmax, ev[3] = {0, 0, 0};
    uint32_t deg = 0;
    for (k = 0; k < 3; ++k) {
        ok &= lrt__finite(ray->origin[k]) && lrt__finite(ray->dir[k]);
        m = lrt__maxf(m, fabsf(ray->dir[k]));
    }
    *kind = LRT_MISS_INVALID_RAY;
    if (ok) {
        *kind = lrt__on_screen_at_tmax(ray, width, height) ? LRT_MISS_TMAX : LRT_MISS_OFF_SCREEN;
        e = m != 0.0f ? lrt__ilogb(m) : 0; /* v = 0 comes here for a tiny o */
        e = e < -127 ? -127 : e;           /* so that t_scale = 2^-e is a float */
        tmin = lrt__scale_t(tmin, e);
        tmax = lrt__scale_t(tmax, e);
        *t_scale = lrt__pow2(-e);
        for (k = 0; k < 3; ++k) {
            s->o[k] = ray->origin[k];
            s->v[k] = ldexpf(ray->dir[k], -e); /* not times 2^-127: FTZ and DAZ read that as 0 */
            if (ray->dir[k] != 0.0f) {
                ev[k] = lrt__ilogb(ray->dir[k]) - e;
                if (ev[k] < -126) deg |= 1u << k;
            }
        }
        s->t_base = 0.0f;
        s->zk = 0;
        if (lrt__far_origin(s->o, width, height)) ok = lrt__restart_far(ray, hi, e, s, &tmin, &tmax);
    }
    if (ok) {
        for (k = 0; k < 3; ++k) s->iv[k] = 1.0f / s->v[k];
        for (k = 0; k < 2; ++k) { /* an x or y too slow to invert */
            const float big = lrt__sign_bit(ray->dir[k]) ? -3.40282347e38f : 3.40282347e38f;
            float o = s->o[k];
            if (!(deg >> k & 1u)) continue;
            s->iv[k] = big;
            if (o != 0.0f && fabsf(o) < LRT__TINY_O) {
                if (lrt__ilogb(o) - ev[k] >= 30) { /* |(0 - o) / v| > 2^29: leaves or enters long after */
                    s->o[k] = o < 0.0f ? -LRT__TINY_O : LRT__TINY_O;
                } else { /* scale o_k and v_k alike: v_k in [2^-126, 2^-125) */
                    const int kb = -126 - ev[k];
                    s->v[k] = ldexpf(ray->dir[k], -126 - lrt__ilogb(ray->dir[k]));
                    s->o[k] = ldexpf(o, kb);
                    s->iv[k] = 1.0f / s->v[k];
                }
            }
        }
        if (deg & 4u) { /* a z too slow to invert: scale z */
            const int kz = -126 - ev[2] < 100 ? -126 - ev[2] : 100;
            s->v[2] = ldexpf(ray->dir[2], kz - e);
            s->o[2] = ldexpf(s->o[2], kz);
            s->zk = kz;
            s->iv[2] = 1.0f / s->v[2];
            if (!lrt__finite(s->iv[2])) s->iv[2] = lrt__sign_bit(ray->dir[2]) ? -3.40282347e38f : 3.40282347e38f;
        }
        s->neg_x = lrt__sign_bit(s->v[0]);
        s->neg_y = lrt__sign_bit(s->v[1]);
        s->neg_z = lrt__sign_bit(s->v[2]);
        (void)lrt__clip(s, width, height, tmin, tmax);
        ok = s->t_lo <= s->t_hi;
        { /* A segment of no length is its one point: in the box or not by its
             coordinates, not by planes' t, which may lie below 2^-126, where
             x86's FTZ and DAZ modes (and a GPU that flushes) read them as 0
             (found cases 13 and 19 of tests/support/rays.h). The point is o,
             or where lrt__scale_t kept a positive t positive (the least float),
             just past o along v (the kernels' lrt_point_in) */
            uint32_t b0, b1;
            memcpy(&b0, &tmin, 4);
            memcpy(&b1, &tmax, 4);
            if (!s->zk && b0 == b1 && (b1 & 0x7fffffffu) <= 1u) {
                const uint32_t neg[3] = {s->neg_x, s->neg_y, s->neg_z};
                for (k = 0; k < 3; ++k) ok &= lrt__point_in(s->o[k], neg[k], ray->dir[k] == 0.0f, hi[k], b1 == 1u);
            }
        }
    }
    return ok;
}

/* ---- ISA block: a direction, its inverse and its sign bits (SSE2 | scalar) -
   (the SSE2 one divides once for all three) */
#if LRT__SSE
LRT__FORCE_INLINE void lrt__set_direction(lrt__ray_setup *s, const float v[3])
{
    int k;
    const __m128 vv = _mm_set_ps(1.0f, v[2], v[1], v[0]);
    const __m128 iv = _mm_div_ps(_mm_set1_ps(1.0f), vv); /* one division for three */
    const int signs = _mm_movemask_ps(vv);
    float ivs[4];
    _mm_storeu_ps(ivs, iv);
    for (k = 0; k < 3; ++k) {
        s->v[k] = v[k];
        s->iv[k] = ivs[k];
    }
    s->neg_x = (uint32_t)signs & 1u;
    s->neg_y = ((uint32_t)signs >> 1) & 1u;
    s->neg_z = ((uint32_t)signs >> 2) & 1u;
}
#else
LRT__FORCE_INLINE void lrt__set_direction(lrt__ray_setup *s, const float v[3])
{
    int k;
    for (k = 0; k < 3; ++k) {
        s->v[k] = v[k];
        s->iv[k] = 1.0f / v[k];
    }
    s->neg_x = lrt__sign_bit(v[0]);
    s->neg_y = lrt__sign_bit(v[1]);
    s->neg_z = lrt__sign_bit(v[2]);
}
#endif

/* ---- ISA block: a ray's rare test on its bits (SSE2 | scalar) ------------
   One test on the bits of the 8 floats: each is 0, or its size (the bits
   without the sign) lies in [low, high), where low is 2^-100 for o and
   v (2^-126 for tmin and tmax) and high is inf, or 2^16 for v. Anything
   else takes lrt__setup_rare, which validates the ray first: NaN or inf,
   a subnormal (read as 0 there, docs/MODEL.md), a component of o or v
   below 2^-100 but not 0 (a tiny v_k has no finite 1/v_k; a plane near
   such an o_k is crossed at a t that may round to 0), a v_k of 2^16 or
   more (the same with plane - o_k below 2^-110); also |v.z| >= 16 from o.z = 0 (a float depth as small as
   2^-146 is met at such a t). A ray whose one oddity is a large v goes on
   in the common set-up once scaled (lrt__huge_direction). The unsigned
   test x - low < high - low is a signed one after both sides are moved by
   2^31. */
#if LRT__SSE
LRT__FORCE_INLINE int lrt__rare_bits(const lrt_ray *ray)
{
    const __m128i abs_bits = _mm_set1_epi32(0x7fffffff), bias = _mm_set1_epi32((int)0x80000000u);
    const __m128i low = _mm_set_epi32(0x00800000, (int)LRT__RARE_TINY, (int)LRT__RARE_TINY, (int)LRT__RARE_TINY);
    const __m128i span_o = _mm_set_epi32((int)(0x7f000000u ^ 0x80000000u), (int)((0x7f800000u - LRT__RARE_TINY) ^ 0x80000000u),
                                         (int)((0x7f800000u - LRT__RARE_TINY) ^ 0x80000000u),
                                         (int)((0x7f800000u - LRT__RARE_TINY) ^ 0x80000000u));
    const __m128i span_v = _mm_set_epi32((int)(0x7f000000u ^ 0x80000000u), (int)((LRT__RARE_HUGE - LRT__RARE_TINY) ^ 0x80000000u),
                                         (int)((LRT__RARE_HUGE - LRT__RARE_TINY) ^ 0x80000000u),
                                         (int)((LRT__RARE_HUGE - LRT__RARE_TINY) ^ 0x80000000u));
    float f[8];
    __m128i a, b;
    memcpy(f, ray, sizeof f); /* the ray is 8 floats: origin, tmin, dir, tmax; one copy: no partial-store stall */
    a = _mm_and_si128(_mm_loadu_si128((const __m128i *)(const void *)f), abs_bits);
    b = _mm_and_si128(_mm_loadu_si128((const __m128i *)(const void *)(f + 4)), abs_bits);
    a = _mm_or_si128(_mm_cmpeq_epi32(a, _mm_setzero_si128()), _mm_cmplt_epi32(_mm_xor_si128(_mm_sub_epi32(a, low), bias), span_o));
    b = _mm_or_si128(_mm_cmpeq_epi32(b, _mm_setzero_si128()), _mm_cmplt_epi32(_mm_xor_si128(_mm_sub_epi32(b, low), bias), span_v));
    return (_mm_movemask_ps(_mm_castsi128_ps(_mm_and_si128(a, b))) != 15) | ((f[2] == 0.0f) & (fabsf(f[6]) >= 16.0f));
}
#else
LRT__FORCE_INLINE int lrt__rare_bits(const lrt_ray *ray)
{
    uint32_t u[8];
    int k, rare;
    memcpy(u, ray, sizeof u);
    rare = (ray->origin[2] == 0.0f) & (fabsf(ray->dir[2]) >= 16.0f);
    for (k = 0; k < 8; ++k) {
        const uint32_t x = u[k] & 0x7fffffffu, low = (k & 3) == 3 ? 0x00800000u : LRT__RARE_TINY;
        const uint32_t high = (k & 3) == 3 || k < 3 ? 0x7f800000u : LRT__RARE_HUGE;
        rare |= x != 0u && !(x - low < high - low);
    }
    return rare;
}
#endif

/* A rare ray whose one oddity is a direction of 2^16 or more: every other
   component ordinary, the origin near the screen, and the ray scaled as
   lrt__setup_rare scales it (max |v| in [1, 2), t by 2^e) ordinary too, a
   nonzero v_k still 2^-100 or more and tmax still finite. That scaled ray
   takes the common set-up, which is all lrt__setup_rare would do with it
   but for the kind of a miss, there decided on the caller's ray: here by
   the clip, as for any ordinary ray. Camera-facing steps reflect rays
   straight back at the camera this way (a v.z of about 10^6): common in a
   frame, so not left to the rare set-up. Returns e (16 to 125), or 0:
   lrt__setup_rare. */
LRT__FORCE_INLINE int lrt__huge_direction(const lrt_ray *ray, uint32_t width, uint32_t height)
{
    uint32_t u[8];
    float m = lrt__maxf(lrt__maxf(fabsf(ray->dir[0]), fabsf(ray->dir[1])), fabsf(ray->dir[2]));
    int k, e, ok;
    if (!(m >= 65536.0f && m < 8.50705917e37f)) return 0; /* below 2^126: 2^-e stays a normal float */
    e = lrt__ilogb(m);
    ok = !lrt__far_origin(ray->origin, width, height);
    memcpy(u, ray, sizeof u);
    for (k = 0; k < 8; ++k) {
        const uint32_t x = u[k] & 0x7fffffffu;
        if (k < 3) ok &= x == 0u || (x >= LRT__RARE_TINY && x < 0x7f800000u); /* origin: as lrt__rare_bits */
        else if (k == 3 || k == 7) /* tmin, tmax: 0 or normal, and finite once scaled */
            ok &= x == 0u || (x >= 0x00800000u && x < 0x7f800000u && (int)(x >> 23) - 127 + e <= 127);
        else ok &= x == 0u || (x < 0x7f800000u && (int)(x >> 23) - 127 - e >= -100); /* v_k 2^-e: 2^-100 or more */
    }
    return ok ? e : 0;
}

/* Validates and clips one ray; returns 0 with *kind set when nothing is left
   to walk. Directions at the edge of float range take lrt__setup_rare (but
   for a direction that is only large: lrt__huge_direction). */
LRT__FORCE_INLINE int lrt__setup_ray(const lrt_ray *ray, uint32_t width, uint32_t height, lrt__ray_setup *s, float *t_scale,
                          uint32_t *kind)
{
    float v[3], tmin = ray->tmin, tmax = ray->tmax;
    int k, rare, ok = 0;
    *t_scale = 1.0f;
    rare = lrt__rare_bits(ray);
    /* a far-away origin restarts in lrt__setup_rare too (one restart for both
       kinds of ray, and the kernels' common set-up stays short) */
    rare |= lrt__far_origin(ray->origin, width, height);
    for (k = 0; k < 3; ++k) v[k] = ray->dir[k];
    if (LRT__UNLIKELY(rare)) {
        const int e = lrt__huge_direction(ray, width, height);
        if (e) { /* lrt__setup_rare's scaling, then the common set-up */
            for (k = 0; k < 3; ++k) v[k] = ray->dir[k] * lrt__pow2(-e);
            tmin = lrt__scale_t(tmin, e);
            tmax = lrt__scale_t(tmax, e);
            *t_scale = lrt__pow2(-e);
            rare = 0;
        } else { /* through a copy, so that *s stays the caller's own (kept in registers) */
            lrt__ray_setup r;
            float ts = 1.0f;
            uint32_t kd = 0;
            ok = lrt__setup_rare(ray, width, height, &r, &ts, &kd);
            *s = r;
            *t_scale = ts;
            *kind = kd;
        }
    }
    if (rare) {
        /* set up by lrt__setup_rare */
    } else if (!(tmin >= 0.0f) || !(tmin <= tmax)) {
        *kind = LRT_MISS_INVALID_RAY;
    } else {
        for (k = 0; k < 3; ++k) s->o[k] = ray->origin[k];
        s->zk = 0;
        lrt__set_direction(s, v);
        s->t_base = 0.0f;
        *kind = lrt__clip(s, width, height, tmin, tmax);
        ok = s->t_lo <= s->t_hi;
    }
    return ok;
}

/* Per-level constants of the walk, so the hot loop does shifts and adds.
   Level lv's children come in 2x4 blocks when lv is even, 4x2 when odd
   (lrt_layout_compute), so a node's shape is a bit of its level. */
typedef struct lrt__walk_level {
    size_t first;                      /* code index of the level's first node (lrt__code_index) */
    size_t children;                   /* the level below's: node (x, y)'s children are at children + (y * width + x) * 64
                                          (a compact level 1's word k is at code index 8 k) */
    uint32_t width, height;            /* the level's grid: nodes per row (the block row of the level below), rows */
    uint32_t span_w_log2, span_h_log2; /* texels per node of this level */
    float child_span_w, child_span_h;  /* texels per child, as float */
} lrt__walk_level;

typedef struct lrt__walk {
    const lrt_layout *L;
    const void *nodes;
    const lrt_depth *depth;
    size_t stride;
    uint32_t compact1; /* 8-bit trees: level-1 nodes are words (lrt__compact_steps) */
    uint32_t row_prefetch_level; /* 3: entering a level-2 node prefetches the depth rows the exact test reads; ~0: never */
    float decode_scale; /* just below 1/65535: decoded bounds never exceed the true ones */
    size_t back_codes;  /* 0, or the code index of the back codes (a back-map tree) */
    size_t back_stride; /* of the back map (LRT_THICKNESS_BACK_MAP) */
    float back_scale;   /* just above 1/65535: a decoded back is never shallower than the true one */
    int exact_codes;    /* the level-1 codes are the input depth itself */
    float code_depth0, code_step; /* a node's depth plane is code_depth0 + code * code_step (lrt__cull_children) */
    int plain_float;    /* float depth, standard Z */
    int back_after_depth; /* a texel's back plane's t is never before its depth plane's, for v.z > 0:
                             the same formula (lrt__depth_plane) on a back never in front of the depth
                             (a back map, or float depth); a model's float back of unorm depth may not be */
    uint32_t texels8_w, texels8_h; /* plain float: level-1 nodes (x, y) below these lie inside the map (lrt__texels8) */
    float extent[2];    /* the root's span in texels: no node's plane lies beyond it */
    uint32_t budget;    /* steps a ray may take (LRT_TRACE_BUDGET), 0: no limit */
    uint32_t finish;    /* a budget's finish: log2 of its samples + 1 (LRT_TRACE_FINISH), 0: none */
    lrt__walk_level lv[LINEAR_RT_MAX_LEVELS + 1];
    uint8_t start_level[2][33]; /* lowest level whose nodes span 2^b texels along x / y */
    lrt__signs signs[4];        /* by neg_x | neg_y << 1 */
} lrt__walk;

/* ---- ISA block: the node test's sign constants (AVX2 | SSE2 | scalar) ---- */
#if LRT__AVX
static void lrt__signs_lanes_init(lrt__signs *g, uint32_t neg_x, uint32_t neg_y)
{
    const __m256i k = _mm256_set_epi32(7, 6, 5, 4, 3, 2, 1, 0);
    uint32_t tall, lane;
    g->order[0] = _mm256_xor_si256(k, _mm256_set1_epi32((int)g->flip[0]));
    g->order[1] = _mm256_xor_si256(k, _mm256_set1_epi32((int)g->flip[1]));
    for (tall = 0; tall < 2u; ++tall) {
        float xe[8], xx[8], ye[8], yx[8];
        for (lane = 0; lane < 8u; ++lane) {
            /* a wide node's slot k is column k&3, row k>>2; a tall one's column k&1, row k>>1 */
            const uint32_t slot = lane ^ g->flip[tall];
            const uint32_t c = tall ? slot & 1u : slot & 3u, r = tall ? slot >> 1 : slot >> 2;
            xe[lane] = (float)(c + neg_x);
            xx[lane] = (float)(c + 1u - neg_x);
            ye[lane] = (float)(r + neg_y);
            yx[lane] = (float)(r + 1u - neg_y);
        }
        g->kx_enter[tall] = _mm256_loadu_ps(xe);
        g->kx_exit[tall] = _mm256_loadu_ps(xx);
        g->ky_enter[tall] = _mm256_loadu_ps(ye);
        g->ky_exit[tall] = _mm256_loadu_ps(yx);
    }
}
#elif LRT__SSE
static void lrt__signs_lanes_init(lrt__signs *g, uint32_t neg_x, uint32_t neg_y)
{
    const __m128 k0123 = _mm_set_ps(3.0f, 2.0f, 1.0f, 0.0f), k1234 = _mm_set_ps(4.0f, 3.0f, 2.0f, 1.0f);
    const __m128 nx = _mm_set1_ps((float)neg_x), ny = _mm_set1_ps((float)neg_y);
    /* plane k of column (row) c: enters at c + neg, leaves at c + 1 - neg */
    g->k_enter[0] = _mm_add_ps(k0123, nx);
    g->k_exit[0] = _mm_sub_ps(k1234, nx);
    g->k_enter[1] = _mm_add_ps(k0123, ny);
    g->k_exit[1] = _mm_sub_ps(k1234, ny);
    g->k_rows2 = _mm_set_ps(2.0f - (float)neg_y, 1.0f + (float)neg_y, 1.0f - (float)neg_y, (float)neg_y);
    g->k_cols2 = _mm_set_ps(2.0f - (float)neg_x, 1.0f - (float)neg_x, 1.0f + (float)neg_x, (float)neg_x);
}
#else
static void lrt__signs_lanes_init(lrt__signs *g, uint32_t neg_x, uint32_t neg_y)
{
    (void)g;
    (void)neg_x;
    (void)neg_y;
}
#endif

/* The sign constants of the node test for neg_x, neg_y: flip bits of each
   axis that runs backwards, so bit k of a mask is slot k ^ flip. */
static void lrt__signs_init(lrt__signs *g, uint32_t neg_x, uint32_t neg_y)
{
    g->flip[0] = (neg_x ? 3u : 0u) | (neg_y ? 4u : 0u);
    g->flip[1] = (neg_x ? 1u : 0u) | (neg_y ? 6u : 0u);
    lrt__signs_lanes_init(g, neg_x, neg_y);
}

static void lrt__walk_init(lrt__walk *w, const lrt_bvh *bvh, const lrt_depth *depth, size_t stride)
{
    const lrt_layout *L = &bvh->layout;
    uint32_t i, b;
    memset(w, 0, sizeof *w);
    w->L = L;
    w->nodes = bvh->nodes;
    w->depth = depth;
    w->stride = stride;
    w->compact1 = L->level1_node_bytes == 6u;
    /* 2^-20 below 1/65535: a node's decoded depth stays below every texel
       depth under it by more than the float rounding of its plane's t, so
       culling in float never drops a hit that the texel test (in double) finds */
    w->decode_scale = (1.0f / 65535.0f) * (1.0f - 1.0f / 1048576.0f);
    w->exact_codes = depth->format != LRT_FORMAT_FLOAT32 && !w->compact1;
    w->row_prefetch_level = w->exact_codes ? ~0u : 3u;
    w->back_scale = (1.0f / 65535.0f) * (1.0f + 1.0f / 1048576.0f);
    w->code_depth0 = 65535.0f * w->decode_scale;
    w->code_step = -w->decode_scale;
    if (L->back_codes) {
        w->back_codes = lrt__back_code_index(L);
        (void)lrt__check_back(depth, L->thickness, &w->back_stride); /* checked by lrt_trace */
        w->back_after_depth = L->thickness == LRT_THICKNESS_BACK_MAP || depth->format == LRT_FORMAT_FLOAT32;
    }
    w->plain_float = depth->format == LRT_FORMAT_FLOAT32 && !(depth->flags & LRT_DEPTH_REVERSED_Z);
    w->texels8_w = w->plain_float ? L->width / 4u : 0u;
    w->texels8_h = w->plain_float ? L->height / 2u : 0u;
    for (i = 1; i <= L->level_count; ++i) {
        lrt__walk_level *v = &w->lv[i];
        v->first = i == 1 ? L->levels[1].offset * 8u : lrt__code_index(L, L->levels[i].offset); /* level 1: word k at 8 k */
        v->children = i <= 2 ? L->levels[1].offset * 8u : lrt__code_index(L, L->levels[i - 1].offset); /* (level 1's: unused) */
        v->width = L->levels[i].width;
        v->height = L->levels[i].height;
        v->span_w_log2 = L->levels[i].span_w_log2;
        v->span_h_log2 = L->levels[i].span_h_log2;
        v->child_span_w = (float)(1u << L->levels[i - 1].span_w_log2);
        v->child_span_h = (float)(1u << L->levels[i - 1].span_h_log2);
    }
    w->extent[0] = (float)(1u << L->levels[L->level_count].span_w_log2);
    w->extent[1] = (float)(1u << L->levels[L->level_count].span_h_log2);
    for (b = 0; b <= 32u; ++b) {
        uint32_t lx = 0, ly = 0;
        while (lx < L->level_count && L->levels[lx].span_w_log2 < b) ++lx;
        while (ly < L->level_count && L->levels[ly].span_h_log2 < b) ++ly;
        w->start_level[0][b] = (uint8_t)lx;
        w->start_level[1][b] = (uint8_t)ly;
    }
    for (i = 0; i < 4u; ++i) lrt__signs_init(&w->signs[i], i & 1u, i >> 1);
}

/* Lowest level whose single node holds texels i0 to i1 on both axes, and
   that node. Two texel indices share a node of a level exactly when their
   highest differing bit is below the level's span, so the level is a
   table lookup per axis. */
LRT__FORCE_INLINE uint32_t lrt__start_level(const lrt__walk *w, const uint32_t i0[2], const uint32_t i1[2], uint32_t neg_x,
                                            uint32_t neg_y, uint32_t *sx, uint32_t *sy, uint32_t *px, uint32_t *py)
{
    const lrt_layout *L = w->L;
    *px = neg_x ? i1[0] : i0[0]; /* the range's corner the segment starts from (lrt__walk_origin) */
    *py = neg_y ? i1[1] : i0[1];
    uint32_t lv = w->start_level[0][lrt__bit_length(i0[0] ^ i1[0])];
    const uint32_t ly = w->start_level[1][lrt__bit_length(i0[1] ^ i1[1])];
    lv = lv > ly ? lv : ly;
    *sx = i0[0] >> L->levels[lv].span_w_log2;
    *sy = i0[1] >> L->levels[lv].span_h_log2;
    if (lv == L->level_count) *sx = *sy = 0;
    return lv;
}

/* ---- ISA block: the texel columns and rows a clipped segment can touch,
   widened by a margin far above float rounding (SSE2: x and y side by side,
   the same floats as the scalar loop) ---- */
#if LRT__SSE
LRT__FORCE_INLINE void lrt__texel_range(const lrt__walk *w, const lrt__ray_setup *s, uint32_t i0[2], uint32_t i1[2])
{
    const lrt_layout *L = w->L;
    const __m128 o = _mm_set_ps(0.0f, 0.0f, s->o[1], s->o[0]), v = _mm_set_ps(0.0f, 0.0f, s->v[1], s->v[0]);
    const __m128 lim = _mm_set_ps(0.0f, 0.0f, (float)(L->height - 1u), (float)(L->width - 1u));
    const __m128 a = _mm_add_ps(o, _mm_mul_ps(_mm_set1_ps(s->t_lo), v));
    const __m128 b = _mm_add_ps(o, _mm_mul_ps(_mm_set1_ps(s->t_hi), v));
    const __m128 abs_bits = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    const __m128 size = _mm_add_ps(_mm_add_ps(_mm_and_ps(o, abs_bits), _mm_and_ps(_mm_sub_ps(a, o), abs_bits)),
                                   _mm_and_ps(_mm_sub_ps(b, o), abs_bits));
    const __m128 mg = _mm_add_ps(_mm_set1_ps(1e-3f), _mm_mul_ps(_mm_set1_ps(1e-5f), size));
    /* min_ps(p, q) is p < q ? p : q, max_ps(p, q) is p > q ? p : q: the
       selects below, NaN included */
    __m128 lo = _mm_sub_ps(_mm_min_ps(a, b), mg), hi = _mm_add_ps(_mm_max_ps(b, a), mg);
    __m128i l, h;
    lo = _mm_min_ps(_mm_max_ps(lo, _mm_setzero_ps()), lim);
    hi = _mm_max_ps(_mm_min_ps(hi, lim), _mm_setzero_ps());
    l = _mm_cvttps_epi32(lo);
    h = _mm_cvttps_epi32(hi);
    i0[0] = (uint32_t)_mm_cvtsi128_si32(l);
    i1[0] = (uint32_t)_mm_cvtsi128_si32(h);
    i0[1] = (uint32_t)_mm_cvtsi128_si32(_mm_shuffle_epi32(l, _MM_SHUFFLE(1, 1, 1, 1)));
    i1[1] = (uint32_t)_mm_cvtsi128_si32(_mm_shuffle_epi32(h, _MM_SHUFFLE(1, 1, 1, 1)));
}
#else
LRT__FORCE_INLINE void lrt__texel_range(const lrt__walk *w, const lrt__ray_setup *s, uint32_t i0[2], uint32_t i1[2])
{
    const lrt_layout *L = w->L;
    int k;
    for (k = 0; k < 2; ++k) {
        const float lim = (float)((k ? L->height : L->width) - 1u);
        float a = s->o[k] + s->t_lo * s->v[k], b = s->o[k] + s->t_hi * s->v[k];
        float mg = 1e-3f + 1e-5f * (fabsf(s->o[k]) + fabsf(a - s->o[k]) + fabsf(b - s->o[k]));
        float lo = (a < b ? a : b) - mg, hi = (a < b ? b : a) + mg;
        /* clamp, then convert; a NaN (from overflow) clamps to the whole map */
        lo = lo > 0.0f ? lo : 0.0f;
        lo = lo < lim ? lo : lim;
        hi = hi < lim ? hi : lim;
        hi = hi > 0.0f ? hi : 0.0f;
        i0[k] = (uint32_t)(int32_t)lo;
        i1[k] = (uint32_t)(int32_t)hi;
    }
}
#endif

/* Lowest level whose single node holds every texel the clipped segment can
   touch: the walk starts there instead of at the root, and a segment inside
   one texel (a camera ray, say) is level 0: one exact box test. The texel
   box is widened by a margin far above float rounding, so it is
   conservative. */
LRT__FORCE_INLINE uint32_t lrt__start_node(const lrt__walk *w, const lrt__ray_setup *s, uint32_t *sx, uint32_t *sy,
                                           uint32_t *px, uint32_t *py)
{
    uint32_t i0[2], i1[2], lv = 0u;
    if (s->v[0] == 0.0f && s->v[1] == 0.0f && (float)(int32_t)s->o[0] != s->o[0] && (float)(int32_t)s->o[1] != s->o[1]) {
        /* a camera ray inside one texel's column (the clip put o on the
           screen; off a texel edge, no neighbour's closed box is met) */
        *sx = *px = (uint32_t)(int32_t)s->o[0];
        *sy = *py = (uint32_t)(int32_t)s->o[1];
    } else {
        lrt__texel_range(w, s, i0, i1);
        lv = lrt__start_level(w, i0, i1, s->neg_x, s->neg_y, sx, sy, px, py);
    }
    return lv;
}

/* First code of node (x, y) of level lv in the node array (code units):
   the row-major block of its parent, then its slot in the block. */
LRT__FORCE_INLINE size_t lrt__node_slot(const lrt__walk *w, uint32_t lv, uint32_t x, uint32_t y)
{
    size_t index = 0;
    if (lv < w->L->level_count) {
        const uint32_t bw_log2 = (lv & 1u) ? 1u : 2u, bh_log2 = 3u - bw_log2;
        const size_t block = (size_t)(y >> bh_log2) * w->lv[lv + 1].width + (x >> bw_log2);
        index = block * 8u + (((y & ((1u << bh_log2) - 1u)) << bw_log2) | (x & ((1u << bw_log2) - 1u)));
    }
    return w->lv[lv].first + index * 8u;
}

/* First code of the children of node (x, y) of level lv >= 2: the nodes of
   level lv - 1 in its block, whose first codes follow 8 apart. */
LRT__FORCE_INLINE size_t lrt__children_slot(const lrt__walk *w, uint32_t lv, uint32_t x, uint32_t y)
{
    const lrt__walk_level *v = &w->lv[lv];
    return v->children + ((size_t)y * v->width + x) * 64u;
}

#if !LRT__AVX
/* Reorders a slot mask so that bit k is slot k ^ flip: then walking bits from
   the lowest is walking the children front to back. XOR by 4, 2, 1 swaps
   nibbles, bit pairs, neighbours. */
LRT__FORCE_INLINE uint32_t lrt__order_mask(uint32_t m, uint32_t flip)
{
    if (flip & 4u) m = ((m & 0x0fu) << 4) | ((m >> 4) & 0x0fu);
    if (flip & 2u) m = ((m & 0x33u) << 2) | ((m >> 2) & 0x33u);
    if (flip & 1u) m = ((m & 0x55u) << 1) | ((m >> 1) & 0x55u);
    return m;
}
#endif

/* The codes from code index `slot` on (heights, or back codes past back_codes). */
LRT__FORCE_INLINE const uint16_t *lrt__codes(const lrt__walk *w, size_t slot)
{
    return (const uint16_t *)w->nodes + slot;
}

/* The level-1 code of texel (x, y) on the map where the codes are the
   input's own integers (exact_codes: lrt__test_texel reads the texel's raw
   depth off it); 0 otherwise. */
LRT__FORCE_INLINE uint32_t lrt__texel_code(const lrt__walk *w, uint32_t x, uint32_t y)
{
    return w->exact_codes ? *lrt__codes(w, lrt__node_slot(w, 1, x >> 2, y >> 1) + (((y & 1u) << 2) | (x & 3u))) : 0u;
}

#if LRT__SSE
/* A node's 8 codes as 16-bit lanes, in slot order. */
LRT__FORCE_INLINE __m128i lrt__load_codes(const uint16_t *codes)
{
    return _mm_loadu_si128((const __m128i *)(const void *)codes);
}
#endif

/* An AVX2 build (-march=native) compiles the walk tuned as the run-time
   AVX2 pass is: GCC 12 tuning it for a Zen 4 host made it markedly slower
   (docs/PERFORMANCE.md). Tuning picks among the same instructions, so the
   same floats come out. LINEAR_RT_KEEP_TUNING keeps the command line's. */
#if LRT__AVX_BUILT && defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 8 && !defined(LINEAR_RT_KEEP_TUNING)
#pragma GCC push_options
#pragma GCC target("tune=icelake-server")
#define LRT__WALK_TUNED
#endif
/* ============================================================= >>node-test
   6. The node and texel tests the walks below are made of: a node's 8
   children against a ray in one step (ISA blocks: AVX2 | SSE2 | scalar), a
   ray's constants in lanes, and a level-1 node's first texel hit. Every t
   of a plane is (plane - o) * (1/v): monotone in the plane, so a child's
   interval never exceeds its parent's and culling never loses a hit the
   final texel test would find. A 0 direction component gives infinite
   inverses and NaN exactly on a plane; NaN is dropped by the max/min
   accumulations, which makes such slabs closed, as the model says.
   ========================================================================== */

/* ---- ISA block: the node tests (AVX2 | SSE2 | scalar) ----------------------
   lrt__test_children in each; AVX2 also has lrt__cull_children (levels
   above 1) and lrt__texels8 (level 1 of plain float depth).
   lrt__test_children: the children of node (nx, ny) at level lv whose
   boxes the ray meets, as a bit mask in visiting order (bit k is slot
   k ^ flip, lrt__order_mask); enter[k] / exit[k] bound the ray inside the x and y slabs of the child of
   lane k (LRT__LANE): the texel test adds the texel's own z planes, so no
   node's rounded bound ever moves a hit's t (or its face).
   Slot k of a wide (4x2) node is column k&3, row k>>2; of a tall (2x4) node
   column k&1, row k>>1. Each plane's t is computed once, the same way at
   every level, which keeps the culling monotone. tall is a constant where
   this is inlined, so each shape gets its own straight code. */
#if LRT__AVX
/* lrt__widen in 8 lanes, as written there: the product, then the sum */
LRT__FORCE_INLINE __m256 lrt__widen8(__m256 ex)
{
    const __m256 grown = _mm256_add_ps(ex, _mm256_mul_ps(_mm256_andnot_ps(_mm256_set1_ps(-0.0f), ex), _mm256_set1_ps(LRT__WIDEN_EXIT)));
    return _mm256_blendv_ps(ex, grown, _mm256_cmp_ps(grown, _mm256_set1_ps(3.40282347e38f), _CMP_LE_OQ));
}

/* The ray inside the x and y slabs of node (x0, y0)'s 8 children, in
   visiting order: lane k's planes are x0 + k' * span with k' from the sign
   set's tables (exact), then the same (plane - o) / v as every level's. */
LRT__FORCE_INLINE void lrt__slabs8(const lrt__ray_setup *s, const lrt__walk_level *v, float x0, float y0, uint32_t tall,
                                   __m256 *enter, __m256 *exit)
{
    const lrt__signs *g = s->sg;
    const __m256 X0 = _mm256_set1_ps(x0), Y0 = _mm256_set1_ps(y0);
    const __m256 sw = _mm256_set1_ps(v->child_span_w), sh = _mm256_set1_ps(v->child_span_h);
    const __m256 xe = _mm256_mul_ps(_mm256_sub_ps(LRT__EXACT_MADD8(g->kx_enter[tall], sw, X0), s->vo[0]), s->viv[0]);
    const __m256 xx = _mm256_mul_ps(_mm256_sub_ps(LRT__EXACT_MADD8(g->kx_exit[tall], sw, X0), s->vo[0]), s->viv[0]);
    const __m256 ye = _mm256_mul_ps(_mm256_sub_ps(LRT__EXACT_MADD8(g->ky_enter[tall], sh, Y0), s->vo[1]), s->viv[1]);
    const __m256 yx = _mm256_mul_ps(_mm256_sub_ps(LRT__EXACT_MADD8(g->ky_exit[tall], sh, Y0), s->vo[1]), s->viv[1]);
    *enter = _mm256_max_ps(ye, _mm256_max_ps(xe, s->vt_lo));
    *exit = _mm256_min_ps(yx, _mm256_min_ps(xx, s->vt_hi));
}

/* The z plane at t = tz of each lane: it leaves (v.z < 0) or enters; a NaN
   tz keeps the other operand */
LRT__FORCE_INLINE void lrt__z_plane8(__m256 tz, uint32_t neg_z, __m256 *enter, __m256 *exit)
{
    if (neg_z) *exit = _mm256_min_ps(tz, *exit);
    else *enter = _mm256_max_ps(tz, *enter);
}

/* The exact boxes of node (x0, y0)'s 8 children (codes c16, in slot order;
   their back codes at backs) in visiting order. */
LRT__FORCE_INLINE void lrt__box8(const lrt__walk *w, const lrt__ray_setup *s, const lrt__walk_level *v, float x0, float y0,
                                 __m128i c16, const uint16_t *backs, uint32_t tall, uint32_t neg_z, __m256 *enter,
                                 __m256 *exit, __m256 *enter_xy, __m256 *exit_xy)
{
    const __m256i codes = _mm256_permutevar8x32_epi32(_mm256_cvtepu16_epi32(c16), s->sg->order[tall]);
    /* the decoded depth: (65535 - code) * decode_scale */
    const __m256 dz = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_sub_epi32(_mm256_set1_epi32(65535), codes)),
                                    _mm256_set1_ps(w->decode_scale));
    lrt__slabs8(s, v, x0, y0, tall, enter, exit);
    *enter_xy = *enter;
    *exit_xy = *exit;
    lrt__z_plane8(_mm256_mul_ps(_mm256_sub_ps(dz, s->vo[2]), s->viv[2]), neg_z, enter, exit);
    if (w->back_codes && !s->zk) { /* the back plane; not for a z scaled by 2^zk: unscaled codes would cut it */
        const __m256i back = _mm256_permutevar8x32_epi32(_mm256_cvtepu16_epi32(lrt__load_codes(backs)), s->sg->order[tall]);
        const __m256 bz = _mm256_mul_ps(_mm256_cvtepi32_ps(back), _mm256_set1_ps(w->back_scale));
        lrt__z_plane8(_mm256_mul_ps(_mm256_sub_ps(bz, s->vo[2]), s->viv[2]), neg_z ^ 1u, enter, exit);
    }
}

LRT__FORCE_INLINE __m256 lrt__clamp_depth8(__m256 d) /* lrt__clamp_depth, 8 at once */
{
    d = _mm256_min_ps(d, _mm256_set1_ps(1.0f));
    return _mm256_and_ps(d, _mm256_cmp_ps(d, _mm256_set1_ps(LRT__FLT_MIN), _CMP_GE_OQ));
}

/* Level-1 node (nx, ny) of plain float depth, wholly inside the map:
   lrt__test_texel of its 8 texels at once (the same floats: the clamps,
   (d - o.z) / v.z, lrt__widen), no branch per texel and no codes. The
   texel loop of lrt__level1_codes_hit tests a texel only if its box with the
   node's code passes too, but that box holds whenever the texel does: the
   decoded plane is never deeper than the depth (lrt__walk_init), rounding
   keeps that order, so its t bounds the ray no tighter. Returns the slot
   of the first texel met in visiting order, the one that loop finds, its
   t and its planes' (lrt__test_texel); 8 if none. */
LRT__FORCE_INLINE uint32_t lrt__texels8(const lrt__walk *w, const lrt__ray_setup *s, uint32_t nx, uint32_t ny, uint32_t neg_z,
                                        float *t, float planes[2])
{
    const unsigned char *row = (const unsigned char *)w->depth->data + w->stride * 2u * ny + 16u * (size_t)nx;
    const __m128 row0 = _mm_loadu_ps((const float *)(const void *)row);
    const __m128 row1 = _mm_loadu_ps((const float *)(const void *)(row + w->stride));
    __m256 d = _mm256_permutevar8x32_ps(_mm256_insertf128_ps(_mm256_castps128_ps256(row0), row1, 1), s->sg->order[0]), en, ex;
    __m256 tz, tb = _mm256_setzero_ps();
    float lanes[8];
    uint32_t mask;
    lrt__slabs8(s, &w->lv[1], (float)(nx * 4u), (float)(ny * 2u), 0u, &en, &ex);
    d = lrt__clamp_depth8(d);
    tz = _mm256_mul_ps(_mm256_sub_ps(d, s->vo[2]), s->viv[2]);
    lrt__z_plane8(tz, neg_z, &en, &ex);
    mask = (uint32_t)_mm256_movemask_ps(_mm256_cmp_ps(en, lrt__widen8(ex), _CMP_LE_OQ));
    /* the texels' backs the same way (lrt__back_plane), read only where they
       can decide (lrt__test_texel): some texel passes without them, and the
       first that does is not one entered through its top going down */
    if (mask && w->back_codes &&
        (neg_z || !w->back_after_depth ||
         !((uint32_t)_mm256_movemask_ps(_mm256_cmp_ps(en, tz, _CMP_EQ_OQ)) >> lrt__lowest_bit(mask) & 1u))) {
        const float *k = w->L->back_k;
        __m256 b;
        if (w->L->thickness == LRT_THICKNESS_BACK_MAP) { /* b = max(depth, back) */
            const unsigned char *brow = (const unsigned char *)w->depth->back->data + w->back_stride * 2u * ny + 16u * (size_t)nx;
            const __m128 b0 = _mm_loadu_ps((const float *)(const void *)brow);
            const __m128 b1 = _mm_loadu_ps((const float *)(const void *)(brow + w->back_stride));
            b = _mm256_permutevar8x32_ps(_mm256_insertf128_ps(_mm256_castps128_ps256(b0), b1, 1), s->sg->order[0]);
            b = lrt__clamp_depth8(b);
        } else if (w->L->thickness == LRT_THICKNESS_CONSTANT) { /* lrt__model_back, 8 at once */
            const __m256 k0 = _mm256_set1_ps(k[0]), k1 = _mm256_set1_ps(k[1]), u = _mm256_sub_ps(k0, d);
            b = _mm256_add_ps(_mm256_div_ps(k0, u), k1);
            b = _mm256_add_ps(d, _mm256_div_ps(k1, _mm256_div_ps(b, u)));
            b = _mm256_min_ps(b, _mm256_set1_ps(1.0f));
        } else {
            b = _mm256_div_ps(_mm256_add_ps(d, _mm256_set1_ps(k[0])), _mm256_set1_ps(k[1]));
            b = _mm256_min_ps(b, _mm256_set1_ps(1.0f));
        }
        b = _mm256_max_ps(b, d);
        tb = _mm256_mul_ps(_mm256_sub_ps(b, s->vo[2]), s->viv[2]);
        lrt__z_plane8(tb, neg_z ^ 1u, &en, &ex);
        mask = (uint32_t)_mm256_movemask_ps(_mm256_cmp_ps(en, lrt__widen8(ex), _CMP_LE_OQ));
    }
    if (!mask) return 8u;
    mask = lrt__lowest_bit(mask);
    _mm256_storeu_ps(lanes, en);
    *t = lanes[mask];
    _mm256_storeu_ps(lanes, tz);
    planes[0] = lanes[mask];
    _mm256_storeu_ps(lanes, tb);
    planes[1] = lanes[mask];
    return mask ^ s->sg->flip[0];
}

LRT__FORCE_INLINE uint32_t lrt__test_children(const lrt__walk *w, const lrt__ray_setup *s, uint32_t lv, uint32_t nx, uint32_t ny,
                                   const uint16_t *codes, const uint16_t *backs, float enter[8], float exit[8], uint32_t tall,
                                   uint32_t neg_z)
{
    const lrt__walk_level *v = &w->lv[lv];
    __m256 en, ex, en_xy, ex_xy;
    lrt__box8(w, s, v, (float)(nx << v->span_w_log2), (float)(ny << v->span_h_log2), lrt__load_codes(codes), backs, tall,
              neg_z, &en, &ex, &en_xy, &ex_xy);
    _mm256_storeu_ps(enter, en_xy);
    _mm256_storeu_ps(exit, ex_xy);
    return (uint32_t)_mm256_movemask_ps(_mm256_cmp_ps(en, lrt__widen8(ex), _CMP_LE_OQ));
}

/* The test of lrt__test_children above level 1, where only a mask is
   needed: each plane's t in one fused step with the margins of
   lrt__cull_axis, the z plane straight from the codes, no widening (the
   margins hold it). It keeps every child the exact test keeps. */
LRT__FORCE_INLINE uint32_t lrt__cull_children(const lrt__walk *w, const lrt__ray_setup *s, uint32_t lv, uint32_t nx,
                                              uint32_t ny, size_t slot0, uint32_t tall, uint32_t neg_z)
{
    const lrt__walk_level *v = &w->lv[lv];
    const lrt__signs *g = s->sg;
    const __m256 X0 = _mm256_set1_ps((float)(nx << v->span_w_log2)), Y0 = _mm256_set1_ps((float)(ny << v->span_h_log2));
    const __m256 sw = _mm256_set1_ps(v->child_span_w), sh = _mm256_set1_ps(v->child_span_h);
    const __m256 xe = LRT__EXACT_MADD8(LRT__EXACT_MADD8(g->kx_enter[tall], sw, X0), s->cull_iv[0], s->cull_enter[0]);
    const __m256 xx = LRT__EXACT_MADD8(LRT__EXACT_MADD8(g->kx_exit[tall], sw, X0), s->cull_iv[0], s->cull_exit[0]);
    const __m256 ye = LRT__EXACT_MADD8(LRT__EXACT_MADD8(g->ky_enter[tall], sh, Y0), s->cull_iv[1], s->cull_enter[1]);
    const __m256 yx = LRT__EXACT_MADD8(LRT__EXACT_MADD8(g->ky_exit[tall], sh, Y0), s->cull_iv[1], s->cull_exit[1]);
    const __m256i codes = _mm256_permutevar8x32_epi32(_mm256_cvtepu16_epi32(lrt__load_codes(lrt__codes(w, slot0))), g->order[tall]);
    const __m256 tz = LRT__EXACT_MADD8(_mm256_cvtepi32_ps(codes), s->cull_za, s->cull_zb);
    /* X0 and Y0 wait for the parent's test, the codes' load is ahead of them */
    __m256 en = _mm256_max_ps(_mm256_max_ps(xe, ye), neg_z ? s->vt_lo : _mm256_max_ps(tz, s->vt_lo));
    __m256 ex = _mm256_min_ps(_mm256_min_ps(xx, yx), neg_z ? _mm256_min_ps(tz, s->cull_hi) : s->cull_hi);
    if (w->back_codes && !s->zk) { /* the back plane, with margins of its own (lrt__cull_constants) */
        const __m256i back =
            _mm256_permutevar8x32_epi32(_mm256_cvtepu16_epi32(lrt__load_codes(lrt__codes(w, w->back_codes + slot0))), g->order[tall]);
        const __m256 tb = LRT__EXACT_MADD8(_mm256_cvtepi32_ps(back), s->cull_ba, s->cull_bb);
        if (neg_z) en = _mm256_max_ps(tb, en);
        else ex = _mm256_min_ps(tb, ex);
    }
    return (uint32_t)_mm256_movemask_ps(_mm256_cmp_ps(en, ex, _CMP_LE_OQ));
}
#elif LRT__SSE
/* The x and y slabs of a node's 8 children: entering and leaving t of
   slots 0..3 in [0], of slots 4..7 in [1]. Every plane is x0 + k * span
   with k a small integer (exact): the ray's direction signs, set once per
   ray (lrt__walk_setup), pick which k enters and which leaves, so no
   per-node selects. */
LRT__FORCE_INLINE void lrt__child_slabs(const lrt__ray_setup *s, const lrt__walk_level *v, float x0, float y0,
                                        uint32_t tall, __m128 xe[2], __m128 xx[2], __m128 ye[2], __m128 yx[2])
{
    const __m128 X0 = _mm_set1_ps(x0), Y0 = _mm_set1_ps(y0);
    const __m128 sw = _mm_set1_ps(v->child_span_w), sh = _mm_set1_ps(v->child_span_h);
    if (!tall) { /* 4 columns, 2 rows */
        const __m128 r = _mm_mul_ps(_mm_sub_ps(_mm_add_ps(Y0, _mm_mul_ps(s->sg->k_rows2, sh)), s->vo[1]), s->viv[1]);
        xe[0] = xe[1] = _mm_mul_ps(_mm_sub_ps(_mm_add_ps(X0, _mm_mul_ps(s->sg->k_enter[0], sw)), s->vo[0]), s->viv[0]);
        xx[0] = xx[1] = _mm_mul_ps(_mm_sub_ps(_mm_add_ps(X0, _mm_mul_ps(s->sg->k_exit[0], sw)), s->vo[0]), s->viv[0]);
        ye[0] = _mm_shuffle_ps(r, r, _MM_SHUFFLE(0, 0, 0, 0)); /* r: row 0 enter, exit, row 1 enter, exit */
        yx[0] = _mm_shuffle_ps(r, r, _MM_SHUFFLE(1, 1, 1, 1));
        ye[1] = _mm_shuffle_ps(r, r, _MM_SHUFFLE(2, 2, 2, 2));
        yx[1] = _mm_shuffle_ps(r, r, _MM_SHUFFLE(3, 3, 3, 3));
    } else {     /* 2 columns, 4 rows; lanes alternate columns 0, 1 */
        const __m128 c = _mm_mul_ps(_mm_sub_ps(_mm_add_ps(X0, _mm_mul_ps(s->sg->k_cols2, sw)), s->vo[0]), s->viv[0]);
        const __m128 re = _mm_mul_ps(_mm_sub_ps(_mm_add_ps(Y0, _mm_mul_ps(s->sg->k_enter[1], sh)), s->vo[1]), s->viv[1]);
        const __m128 rx = _mm_mul_ps(_mm_sub_ps(_mm_add_ps(Y0, _mm_mul_ps(s->sg->k_exit[1], sh)), s->vo[1]), s->viv[1]);
        xe[0] = xe[1] = _mm_shuffle_ps(c, c, _MM_SHUFFLE(1, 0, 1, 0)); /* c: column 0, 1 enter, column 0, 1 exit */
        xx[0] = xx[1] = _mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 2, 3, 2));
        ye[0] = _mm_unpacklo_ps(re, re);
        ye[1] = _mm_unpackhi_ps(re, re);
        yx[0] = _mm_unpacklo_ps(rx, rx);
        yx[1] = _mm_unpackhi_ps(rx, rx);
    }
}

LRT__FORCE_INLINE uint32_t lrt__test_children(const lrt__walk *w, const lrt__ray_setup *s, uint32_t lv, uint32_t nx, uint32_t ny,
                                   const uint16_t *codes, const uint16_t *backs, float enter[8], float exit[8], uint32_t tall,
                                   uint32_t neg_z)
{
    const lrt__walk_level *v = &w->lv[lv];
    const float x0 = (float)(nx << v->span_w_log2), y0 = (float)(ny << v->span_h_log2);
    uint32_t mask = 0;
    /* 65535 - code in integers, then one conversion: exact, one step shorter */
    const __m128i c16 = lrt__load_codes(codes);
    const __m128i zero = _mm_setzero_si128(), qmax = _mm_set1_epi32(65535);
    __m128 xe[2], xx[2], ye[2], yx[2];
    uint32_t k;
    const __m128 dz[2] = { /* the decoded depth: (65535 - code) * decode_scale */
        _mm_mul_ps(_mm_cvtepi32_ps(_mm_sub_epi32(qmax, _mm_unpacklo_epi16(c16, zero))), _mm_set1_ps(w->decode_scale)),
        _mm_mul_ps(_mm_cvtepi32_ps(_mm_sub_epi32(qmax, _mm_unpackhi_epi16(c16, zero))), _mm_set1_ps(w->decode_scale))};
    lrt__child_slabs(s, v, x0, y0, tall, xe, xx, ye, yx);
    for (k = 0; k < 2; ++k) {
        const __m128 tz = _mm_mul_ps(_mm_sub_ps(dz[k], s->vo[2]), s->viv[2]);
        __m128 en = _mm_max_ps(xe[k], s->vt_lo), ex = _mm_min_ps(xx[k], s->vt_hi); /* maxps/minps keep the 2nd operand on NaN */
        en = _mm_max_ps(ye[k], en);
        ex = _mm_min_ps(yx[k], ex);
        _mm_storeu_ps(enter + 4 * (size_t)k, en); /* the slabs alone: the texel test adds its own planes */
        _mm_storeu_ps(exit + 4 * (size_t)k, ex);
        if (neg_z) ex = _mm_min_ps(tz, ex); /* the z plane leaves (v.z < 0) or enters */
        else en = _mm_max_ps(tz, en);
        if (w->back_codes && !s->zk) { /* the back plane; not for a z scaled by 2^zk: unscaled codes would cut it */
            const __m128i b16 = lrt__load_codes(backs);
            const __m128 bz = _mm_cvtepi32_ps(k ? _mm_unpackhi_epi16(b16, zero) : _mm_unpacklo_epi16(b16, zero));
            const __m128 tb = _mm_mul_ps(_mm_sub_ps(_mm_mul_ps(bz, _mm_set1_ps(w->back_scale)), s->vo[2]), s->viv[2]);
            if (neg_z) en = _mm_max_ps(tb, en);
            else ex = _mm_min_ps(tb, ex);
        }
        { /* lrt__widen: ex + |ex| 2^-21 where that stays finite, else ex */
            const __m128 grown = _mm_add_ps(ex, _mm_mul_ps(_mm_andnot_ps(_mm_set1_ps(-0.0f), ex), _mm_set1_ps(LRT__WIDEN_EXIT)));
            const __m128 ok = _mm_cmple_ps(grown, _mm_set1_ps(3.40282347e38f));
            const __m128 widened = _mm_or_ps(_mm_and_ps(ok, grown), _mm_andnot_ps(ok, ex));
            mask |= (uint32_t)_mm_movemask_ps(_mm_cmple_ps(en, widened)) << (4 * k);
        }
    }
    return lrt__order_mask(mask, s->sg->flip[tall]);
}
#else
LRT__FORCE_INLINE uint32_t lrt__test_children(const lrt__walk *w, const lrt__ray_setup *s, uint32_t lv, uint32_t nx, uint32_t ny,
                                   const uint16_t *codes, const uint16_t *backs, float enter[8], float exit[8], uint32_t tall,
                                   uint32_t neg_z)
{
    const lrt__walk_level *v = &w->lv[lv];
    const float x0 = (float)(nx << v->span_w_log2), y0 = (float)(ny << v->span_h_log2);
    uint32_t mask = 0;
    const uint32_t bw = tall ? 2u : 4u, bh = tall ? 4u : 2u;
    uint32_t k;
    float dz[8], bz[8], px[5], py[5];
    for (k = 0; k < 8; ++k) {
        dz[k] = (float)(65535 - (int)codes[k]) * w->decode_scale;
        bz[k] = w->back_codes ? (float)backs[k] * w->back_scale : 0.0f;
    }
    for (k = 0; k <= bw; ++k) px[k] = ((x0 + (float)k * v->child_span_w) - s->o[0]) * s->iv[0];
    for (k = 0; k <= bh; ++k) py[k] = ((y0 + (float)k * v->child_span_h) - s->o[1]) * s->iv[1];
    for (k = 0; k < 8; ++k) {
        uint32_t c = tall ? (k & 1u) : (k & 3u), r = tall ? (k >> 1) : (k >> 2);
        float tz = (dz[k] - s->o[2]) * s->iv[2];
        float en = s->t_lo, ex = s->t_hi;
        en = LRT__MAX_KEEP(px[c + s->neg_x], en);
        en = LRT__MAX_KEEP(py[r + s->neg_y], en);
        ex = LRT__MIN_KEEP(px[c + 1 - s->neg_x], ex);
        ex = LRT__MIN_KEEP(py[r + 1 - s->neg_y], ex);
        enter[k] = en; /* the slabs alone: the texel test adds its own planes */
        exit[k] = ex;
        if (neg_z) ex = LRT__MIN_KEEP(tz, ex);
        else en = LRT__MAX_KEEP(tz, en);
        if (w->back_codes && !s->zk) { /* the back plane; not for a z scaled by 2^zk: unscaled codes would cut it */
            const float tb = (bz[k] - s->o[2]) * s->iv[2];
            if (neg_z) en = LRT__MAX_KEEP(tb, en);
            else ex = LRT__MIN_KEEP(tb, ex);
        }
        mask |= (uint32_t)(en <= lrt__widen(ex)) << k;
    }
    return lrt__order_mask(mask, s->sg->flip[tall]);
}
#endif
#if !LRT__AVX
/* Above level 1 only the mask is needed: the SSE2 and scalar paths take the
   whole test (AVX2 has a faster one, above). */
LRT__FORCE_INLINE uint32_t lrt__cull_children(const lrt__walk *w, const lrt__ray_setup *s, uint32_t lv, uint32_t nx,
                                              uint32_t ny, size_t slot0, uint32_t tall, uint32_t neg_z)
{
    float enter[8], exit[8];
    return lrt__test_children(w, s, lv, nx, ny, lrt__codes(w, slot0), lrt__codes(w, w->back_codes + slot0), enter, exit, tall,
                              neg_z);
}
#endif

/* The t where the ray's z meets texel (tx, ty)'s back depth (a tree with
   a thickness model), the way lrt__depth_plane meets its depth. Not inlined:
   in the texel test it made every trace loop larger, the infinite trees'
   too, which never call it. */
static LRT__NOINLINE float lrt__back_plane(const lrt__walk *w, const lrt__ray_setup *s, uint32_t tx, uint32_t ty)
{
    const lrt_format format = w->depth->format;
    float plane;
    if (w->L->thickness == LRT_THICKNESS_BACK_MAP) {
        plane = lrt__depth_plane(s, format, lrt__back_raw(w->depth, w->stride, w->back_stride, tx, ty));
    } else {
        const uint32_t raw = lrt__depth_raw(w->depth, w->stride, tx, ty), bits = lrt__model_back_bits(w->L, format, raw);
        plane = bits == ~0u ? lrt__depth_plane(s, format, raw) : lrt__depth_plane(s, LRT_FORMAT_FLOAT32, bits);
    }
    return plane;
}

/* The exact test of one candidate texel against its true depth. planes:
   the t of its depth plane and of its back plane (0 without a back), which
   lrt__face compares with the hit's t instead of reading the texel again
   (the kernels' lrt_test_texel). */
LRT__FORCE_INLINE int lrt__test_texel(const lrt__walk *w, const lrt__ray_setup *s, uint32_t tx, uint32_t ty, float enter,
                           float exit, uint32_t code, float *t, float planes[2])
{
    int hit = 0;
    planes[0] = planes[1] = 0.0f;
    *t = 0.0f;
    if (tx < w->L->width && ty < w->L->height) { /* not padding */
        float tz;
        if (w->plain_float && !s->zk) { /* the common case, straight: lrt__depth_raw, then lrt__depth_plane */
            float d;
            memcpy(&d, (const unsigned char *)w->depth->data + w->stride * ty + 4 * (size_t)tx, 4);
            d = lrt__clamp_depth(d);
            tz = (d - s->o[2]) * s->iv[2];
        } else if (w->exact_codes) { /* the code is the input's own integer, scaled by 65535/vmax (1 or 257) */
            const uint32_t vmax = w->depth->format == LRT_FORMAT_UNORM8 ? 255u : 65535u;
            tz = lrt__depth_plane(s, w->depth->format, (65535u - code) / (65535u / vmax));
        } else {
            tz = lrt__depth_plane(s, w->depth->format, lrt__depth_raw(w->depth, w->stride, tx, ty));
        }
        planes[0] = tz;
        if (s->neg_z) exit = LRT__MIN_KEEP(tz, exit);
        else enter = LRT__MAX_KEEP(tz, enter);
        hit = enter <= lrt__widen(exit);
        /* the back plane (entered going up, v.z < 0; left going down) only
           narrows [enter, exit]: not read after a miss, nor for a ray going
           down that enters through the top, whose back plane comes no earlier */
        if (hit && w->back_codes && (s->neg_z || enter != tz || !w->back_after_depth)) {
            const float tb = lrt__back_plane(w, s, tx, ty);
            planes[1] = tb;
            if (s->neg_z) enter = LRT__MAX_KEEP(tb, enter);
            else exit = LRT__MIN_KEEP(tb, exit);
            hit = enter <= lrt__widen(exit);
        }
        *t = enter;
    }
    return hit;
}

/* The face of a hit at t (lrt_hit_face): which plane of texel (tx, ty)'s
   box gave its entering t. Every test computes a plane's t the same way
   ((plane - o) * (1/v), and lrt__depth_plane for depth), so the plane that
   won the max is found by equality, once per ray, whichever path tested
   the texel. t_lo holds what is left: tmin (inside), or the far plane. */
LRT__FORCE_INLINE uint32_t lrt__face(const lrt__walk *w, const lrt__ray_setup *s, uint32_t tx, uint32_t ty, float t,
                                     const float planes[2])
{
    /* the top: its plane, or the near plane where the ray enters the screen
       box through it onto a texel of depth 0 (lrt__clip's t0; the depth
       plane's own t, rounded otherwise, may lie an ulp before it:
       crashes-found 21) */
    uint32_t face = LRT_FACE_INSIDE;
    if (!s->neg_z && (planes[0] == t || (0.0f - s->o[2]) * s->iv[2] == t)) face = LRT_FACE_TOP;
    else if (((float)(tx + s->neg_x) - s->o[0]) * s->iv[0] == t || ((float)(ty + s->neg_y) - s->o[1]) * s->iv[1] == t)
        face = LRT_FACE_SIDE;
    else if (s->neg_z && (w->back_codes ? planes[1] : lrt__depth_plane(s, LRT_FORMAT_FLOAT32, 0x3f800000u)) == t)
        face = LRT_FACE_BACK;
    return face;
}

/* A hit at t of the walked ray, told in the caller's ray: undo the restart
   and the rescale, and stay inside [tmin, tmax] despite rounding. */
/* A walk's t as the ray's: the set-up's scale undone, clamped to [tmin, tmax] */
LRT__FORCE_INLINE float lrt__ray_t(const lrt_ray *ray, const lrt__ray_setup *s, float t_scale, float t)
{
    const float lo = lrt__flush_float(ray->tmin), hi = lrt__flush_float(ray->tmax); /* as the walk read them */
    /* t_scale is 2^-127 (subnormal: 0 under DAZ) only after lrt__setup_rare's e = 127 */
    t = t_scale >= 1.17549435e-38f ? (t + s->t_base) * t_scale : ldexpf(t + s->t_base, -127);
    return t < lo ? lo : t > hi ? hi : t;
}

LRT__FORCE_INLINE void lrt__report_hit(const lrt__walk *w, const lrt_ray *ray, const lrt__ray_setup *s, float t_scale, float t,
                                 uint32_t tx, uint32_t ty, const float planes[2], lrt_hit *hit)
{
    hit->face = (uint16_t)lrt__face(w, s, tx, ty, t, planes);
    hit->t = lrt__ray_t(ray, s, t_scale, t);
    hit->x = tx;
    hit->y = ty;
    hit->kind = LRT_HIT;
}

/* The nodes above level 1 only cull: a child they keep is tested again
   below, and level 1 and the texels use the exact planes. So their test
   may take a plane's t as p * iv + c (one fused step, c = -o iv) instead
   of (p - o) * iv, if it never culls a child that the exact planes keep.
   Its error is a few ulps of (|p| + |o|) |iv| with |p| <= extent, so c is
   moved out (down for entering planes, up for leaving ones) by 2^-19 of
   that, and by 2^-19 |t_hi| for the exits' widening (lrt__widen: an exit
   <= t_hi grows by at most 2^-21 |t_hi|). A plane the ray never crosses
   (v_k = 0, or below 2^-100) has an infinite or huge iv, taken as
   +-2^100 here with |t_hi| more margin: then a plane more than 2^-90 or so
   of a texel from o still culls as it does exactly (t beyond t_hi either
   way), a nearer one never culls. Nothing here is NaN: iv and c are
   finite, so p * iv + c is finite or an infinite c. A step budget counts
   node tests, so these floats are the kernels' float for float: a product
   rounded before its sum, as their `precise` keeps it. LRT__ROUNDED keeps
   it so where a compiler would fuse a multiply into the next add (GCC's
   -ffp-contract=fast, its default outside ISO C; clang's within an
   expression). */
#define LRT__CULL_IV_MAX 1.26765060e30f     /* 2^100 */
#define LRT__CULL_MARGIN (1.0f / 524288.0f) /* 2^-19 */
#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || (defined(__i386__) && defined(__SSE_MATH__)))
#define LRT__ROUNDED(x) __asm__("" : "+x"(x))
#elif (defined(__GNUC__) || defined(__clang__)) && defined(__aarch64__)
#define LRT__ROUNDED(x) __asm__("" : "+w"(x))
#else
#define LRT__ROUNDED(x)                                                                                           \
    do {                                                                                                          \
        volatile float lrt__rounded = (x);                                                                        \
        (x) = lrt__rounded;                                                                                       \
    } while (0)
#endif

/* a ray's constants of one axis (the kernels' lrt_cull_axis, float for
   float: each product rounded, LRT__ROUNDED) */
LRT__FORCE_INLINE void lrt__cull_axis(float o, float iv, float extent, float t_hi, float *civ, float *c_en, float *c_ex)
{
    const int huge = !(fabsf(iv) < LRT__CULL_IV_MAX); /* a 0 direction's inverse is infinite */
    const float m = huge ? LRT__CULL_IV_MAX : fabsf(iv);
    float c, d, far;
    *civ = lrt__sign_bit(iv) ? -m : m;
    c = -o * *civ;
    LRT__ROUNDED(c);
    d = (fabsf(o) + extent) * m;
    LRT__ROUNDED(d);
    far = fabsf(t_hi) * (huge ? 2.0f : LRT__CULL_MARGIN); /* both by a power of two: exact */
    d = d * LRT__CULL_MARGIN + far;
    *c_en = c - d;
    *c_ex = c + d;
}

#if LRT__AVX

/* The constants of lrt__cull_children, in this order, each LRT__CULL_STRIDE
   floats after the last where 8 rays are set up together (lrt__setup8). */
enum { LRT__CULL_IV_X, LRT__CULL_IV_Y, LRT__CULL_ENTER_X, LRT__CULL_ENTER_Y, LRT__CULL_EXIT_X, LRT__CULL_EXIT_Y,
       LRT__CULL_ZA, LRT__CULL_ZB, LRT__CULL_HI, LRT__CULL_BA, LRT__CULL_BB, LRT__CULL_COUNT };

static void lrt__cull_constants(const lrt__walk *w, const lrt__ray_setup *s, float c[LRT__CULL_COUNT])
{
    float zb_enter, zb_exit;
    int axis;
    for (axis = 0; axis < 2; ++axis)
        lrt__cull_axis(s->o[axis], s->iv[axis], w->extent[axis], s->t_hi, &c[LRT__CULL_IV_X + axis],
                       &c[LRT__CULL_ENTER_X + axis], &c[LRT__CULL_EXIT_X + axis]);
    /* z: a node's plane is (65535 - code) * decode_scale, below 1 */
    lrt__cull_axis(s->o[2] - w->code_depth0, s->iv[2], 1.0f, s->t_hi, &c[LRT__CULL_ZA], &zb_enter, &zb_exit);
    c[LRT__CULL_ZA] = w->code_step * c[LRT__CULL_ZA];
    c[LRT__CULL_ZB] = s->neg_z ? zb_exit : zb_enter;
    c[LRT__CULL_HI] = lrt__widen(s->t_hi);
    /* the back plane is back code * back_scale: it enters going up, leaves going down */
    lrt__cull_axis(s->o[2], s->iv[2], 1.0f, s->t_hi, &c[LRT__CULL_BA], &zb_enter, &zb_exit);
    c[LRT__CULL_BA] = w->back_scale * c[LRT__CULL_BA];
    c[LRT__CULL_BB] = s->neg_z ? zb_enter : zb_exit;
}
#endif

/* ---- ISA block: a ray's constants in lanes, once per ray (AVX2 | SSE2 |
   scalar): o, 1/v and the clipped t in every lane; AVX2 adds
   lrt__cull_children's planes ---- */
#if LRT__SSE
LRT__FORCE_INLINE void lrt__broadcast_ray(lrt__ray_setup *s)
{
    int axis;
    for (axis = 0; axis < 3; ++axis) {
        s->vo[axis] = LRT__BROADCAST(s->o[axis]);
        s->viv[axis] = LRT__BROADCAST(s->iv[axis]);
    }
    s->vt_lo = LRT__BROADCAST(s->t_lo);
    s->vt_hi = LRT__BROADCAST(s->t_hi);
}
#endif
#if LRT__AVX
LRT__FORCE_INLINE void lrt__ray_lanes(const lrt__walk *w, lrt__ray_setup *s, const float *cull, size_t stride)
{
    float own[LRT__CULL_COUNT];
    int axis;
    if (!cull) { /* a ray set up alone (lrt__setup8 made a batch's) */
        lrt__cull_constants(w, s, own);
        cull = own;
        stride = 1;
    }
    lrt__broadcast_ray(s);
    for (axis = 0; axis < 2; ++axis) {
        s->cull_iv[axis] = LRT__BROADCAST(cull[(LRT__CULL_IV_X + axis) * stride]);
        s->cull_enter[axis] = LRT__BROADCAST(cull[(LRT__CULL_ENTER_X + axis) * stride]);
        s->cull_exit[axis] = LRT__BROADCAST(cull[(LRT__CULL_EXIT_X + axis) * stride]);
    }
    s->cull_za = LRT__BROADCAST(cull[LRT__CULL_ZA * stride]);
    s->cull_zb = LRT__BROADCAST(cull[LRT__CULL_ZB * stride]);
    s->cull_hi = LRT__BROADCAST(cull[LRT__CULL_HI * stride]);
    s->cull_ba = LRT__BROADCAST(cull[LRT__CULL_BA * stride]);
    s->cull_bb = LRT__BROADCAST(cull[LRT__CULL_BB * stride]);
}
#elif LRT__SSE
LRT__FORCE_INLINE void lrt__ray_lanes(const lrt__walk *w, lrt__ray_setup *s, const float *cull, size_t stride)
{
    (void)w;
    (void)cull;
    (void)stride;
    lrt__broadcast_ray(s);
}
#else
LRT__FORCE_INLINE void lrt__ray_lanes(const lrt__walk *w, lrt__ray_setup *s, const float *cull, size_t stride)
{
    (void)w;
    (void)s;
    (void)cull;
    (void)stride;
}
#endif

/* Per-ray constants of every node test, set once a ray is walked; cull:
   lrt__cull_constants, stride floats apart, or NULL (AVX2 only). */
LRT__FORCE_INLINE void lrt__walk_setup(const lrt__walk *w, lrt__ray_setup *s, const float *cull, size_t stride)
{
    s->sg = &w->signs[s->neg_x | (s->neg_y << 1)];
    lrt__ray_lanes(w, s, cull, stride);
}

/* The walk is a chain of dependent loads, so it starts loads ahead of
   their use: the depth rows below a level-2 node, and every child's codes
   (below). Forced inline: gcc 12 takes a function that only prefetches
   for one without effects and drops its calls. */

/* The depth rows of level-2 node (nx, ny) (8x8 texels), which the exact
   texel tests below it read, as the walk enters it: two node tests ahead
   of the first read. Rows inside the map only; one add a row, as
   registers are scarce here. */
LRT__FORCE_INLINE void lrt__prefetch_rows(const lrt__walk *w, uint32_t nx, uint32_t ny)
{
    const uint32_t tx = nx * 8u < w->L->width ? nx * 8u : w->L->width - 1u, ty = ny * 8u;
    const uint32_t end = w->L->height - ty < 8u ? w->L->height : ty + 8u; /* the node's rows inside the map */
    const size_t stride = w->stride;
    const unsigned char *row = (const unsigned char *)w->depth->data + (size_t)tx * lrt__format_bytes(w->depth->format) + stride * ty;
    uint32_t y;
    LRT__PREFETCH(row);
    for (y = ty + 1u; y < end; ++y) {
        row += stride;
        LRT__PREFETCH(row);
    }
}

/* The codes of every child the walk may visit (1 or 2 cache lines), while
   the first child is worked on. */
LRT__FORCE_INLINE void lrt__prefetch_children(const lrt__walk *w, size_t children)
{
    const unsigned char *codes = (const unsigned char *)w->nodes + children * 2u;
    LRT__PREFETCH(codes);
    /* the 8 children's codes fill 8 whole slots (padding included): 128
       bytes of 16-bit codes, whose second line this is (compact level-1
       words: 32 bytes, and this a line never read) */
    LRT__PREFETCH(codes + 64);
}

/* The 8 codes of compact level-1 node k of the codes at code index `at`
   (the heights, or the back codes): its word, its scale, and its own
   height at code index at + `height` (lrt__compact_steps) */
LRT__FORCE_INLINE void lrt__compact_codes(const lrt__walk *w, size_t at, size_t k, size_t height, uint16_t codes[8])
{
    const uint32_t h = *lrt__codes(w, at + height), scale = *lrt__codes(w, at + lrt__compact_scale_index(w->L, k));
    uint32_t bits, s;
    memcpy(&bits, (const uint32_t *)w->nodes + at / 2u + k, 4);
    for (s = 0; s < 8u; ++s) codes[s] = (uint16_t)lrt__compact_code(bits, h, scale, s);
}

/* The 8 codes of level-1 node (nx, ny) whose first code index is slot0,
   and its back codes (a back-map tree), at codes[0] and codes[1]: the
   node's own in the array, or decoded into buf from its compact word and
   its height in its parent. */
LRT__FORCE_INLINE void lrt__level1_codes(const lrt__walk *w, uint32_t nx, uint32_t ny, size_t slot0, uint16_t buf[16],
                                         const uint16_t *codes[2])
{
    size_t height;
    codes[0] = lrt__codes(w, slot0);
    codes[1] = lrt__codes(w, w->back_codes + slot0);
    if (!w->compact1) return;
    height = lrt__node_slot(w, 2, nx >> 1, ny >> 2) + (((ny & 3u) << 1) | (nx & 1u)); /* level 1 groups 2x4 */
    lrt__compact_codes(w, 0, slot0 >> 3, height, buf);
    codes[0] = buf;
    codes[1] = buf + 8;
    if (w->back_codes) lrt__compact_codes(w, w->back_codes, slot0 >> 3, height, buf + 8);
}

/* Level-1 node (nx, ny): the first texel under it that the ray hits, in
   visiting order (returns 0 if none), by its codes, then the exact test of
   each texel they let through. neg_z is a constant where this is inlined. */
LRT__FORCE_INLINE int lrt__level1_codes_hit(const lrt__walk *w, const lrt__ray_setup *s, uint32_t nx, uint32_t ny, size_t slot0,
                                      uint32_t neg_z, uint32_t *tx, uint32_t *ty, float *t, float planes[2])
{
    const uint32_t flip = s->sg->flip[0];
    float enter[8], exit[8];
    uint16_t buf[16];
    const uint16_t *codes[2]; /* the heights, the back codes */
    uint32_t mask;
    lrt__level1_codes(w, nx, ny, slot0, buf, codes);
    mask = lrt__test_children(w, s, 1u, nx, ny, codes[0], codes[1], enter, exit, 0u, neg_z);
    while (mask) { /* texels: the exact test, front to back */
        const uint32_t vis = lrt__lowest_bit(mask), slot = vis ^ flip, lane = LRT__LANE(vis, slot);
        *tx = nx * 4u + (slot & 3u);
        *ty = ny * 2u + (slot >> 2);
        mask &= mask - 1u;
        LINEAR_RT_COUNT_TEXEL_TEST();
        if (lrt__test_texel(w, s, *tx, *ty, enter[lane], exit[lane], codes[0][slot], t, planes)) return 1;
    }
    return 0;
}

/* A ray in a plane of the texel grid: x constant on a texel edge (v.x = 0,
   o.x whole), or y. The texels on both sides of that plane are met over
   the same t, so the walk's visiting order is not their order along the
   ray (its first hit is the exact one of the ray moved off the plane by an
   ulp, docs/MODEL.md), and a budgeted walk proves nothing about the t of
   what it has not tested (lrt__budget_t). */
LRT__FORCE_INLINE int lrt__in_grid_plane(const lrt__ray_setup *s)
{
    return (s->v[0] == 0.0f && floorf(s->o[0]) == s->o[0]) || (s->v[1] == 0.0f && floorf(s->o[1]) == s->o[1]);
}

/* ---- ISA block: a level-1 node's first texel hit (AVX2 | SSE2 and scalar):
   AVX2 reads a node of plain float depth inside the map straight from the
   depth (lrt__texels8), 8 texels at once, with no codes ---- */
#if LRT__AVX
LRT__FORCE_INLINE int lrt__level1_hit(const lrt__walk *w, const lrt__ray_setup *s, uint32_t nx, uint32_t ny, size_t slot0,
                                      uint32_t neg_z, uint32_t *tx, uint32_t *ty, float *t, float planes[2])
{
    if (nx < w->texels8_w && ny < w->texels8_h && !s->zk) {
        const uint32_t slot = lrt__texels8(w, s, nx, ny, neg_z, t, planes);
        *tx = nx * 4u + (slot & 3u);
        *ty = ny * 2u + (slot >> 2);
        return slot < 8u;
    }
    return lrt__level1_codes_hit(w, s, nx, ny, slot0, neg_z, tx, ty, t, planes);
}
#else
LRT__FORCE_INLINE int lrt__level1_hit(const lrt__walk *w, const lrt__ray_setup *s, uint32_t nx, uint32_t ny, size_t slot0,
                                      uint32_t neg_z, uint32_t *tx, uint32_t *ty, float *t, float planes[2])
{
    return lrt__level1_codes_hit(w, s, nx, ny, slot0, neg_z, tx, ty, t, planes);
}
#endif

/* ================================================================== >>walk
   WALKS: which pass runs which walk, and where.
     pass                                entry (C | GLSL)                  walk
     CPU trace                           lrt__trace_walk                   lrt__walk_origin (8 children a step)
     GPU ordinary, infinite tree         lrt_trace_ray_ordinary            lrt_walk_cells (one cell a step)
     GPU ordinary, thickness tree        lrt_trace_ray_ordinary            lrt_walk_origin
     GPU ordinary with a step budget     lrt_trace_ray_ordinary_budget     infinite: lrt_walk_cells, else lrt_walk_origin
     CPU trace with a step budget        lrt__trace_cells (infinite tree)  lrt__walk_cells
     GPU rare pass, one pass             lrt_trace_ray                     lrt_walk_origin
     counts of a GPU wave (bench)        lrt__walk_cells_ray               lrt__walk_cells
   TWINS: each C helper of the walks and its GLSL twin: the same floats, one
   exit each, and the parameters both name in one order (C's w, the walk's
   constants, stands where GLSL's p does; C reads a zero component off v,
   GLSL passes zero; a C walk reports into the caller's lrt_hit, a GLSL
   walk returns what it found). make check fails when a name below is
   defined on one side only, or the order differs (tests/walk_twins.sh).
   -- twins --
     lrt__walk_origin ~ lrt_walk_origin      lrt__walk_cells ~ lrt_walk_cells
     lrt__cell_axis ~ lrt_cell_axis          lrt__cross_texel ~ lrt_cross_texel
     lrt__split_level_x ~ lrt_split_level_x  lrt__split_level_y ~ lrt_split_level_y
     lrt__in_grid_plane ~ lrt_in_grid_plane
     lrt__test_texel ~ lrt_test_texel        lrt__first_texel ~ lrt_first_texel
     lrt__report_hit ~ lrt_report_hit        lrt__budget_t ~ lrt_budget_t
     lrt__report_budget ~ lrt_report_budget  lrt__finish ~ lrt_finish
     lrt__finish_inside ~ lrt_finish_inside  lrt__finish_texel ~ lrt_finish_texel
     lrt__cull_setup ~ lrt_cull_setup        lrt__kernel_cull_children ~ lrt_cull_children
     lrt__cull_slab ~ lrt_cull_slab          lrt__cull_axis ~ lrt_cull_axis
     lrt__start_node ~ lrt_start_node        lrt__setup_ray ~ lrt_setup_ray
     lrt__setup_rare ~ lrt_setup_rare        lrt__far_origin ~ lrt_far_origin
     lrt__child ~ lrt_child                  lrt__child_slot ~ lrt_child_slot
     lrt__face ~ lrt_face                    lrt__clip ~ lrt_clip
     lrt__slab ~ lrt_slab                    lrt__widen ~ lrt_widen
     lrt__depth_plane ~ lrt_depth_plane      lrt__back_plane ~ lrt_back_plane
     lrt__plane_t ~ lrt_plane_t              lrt__ray_t ~ lrt_ray_t
     lrt__point_in ~ lrt_point_in            lrt__entered_later ~ lrt_entered_later
   -- end twins --
   The 8-child walk (RayQuery.Proceed of the design), specialised for this
   tree: no triangles, no instances, no stored boxes. A node's children form
   a 4x2 or 2x4 grid, so their x/y slabs come from 5+3 shared planes; the
   only per-child work is the z plane of its height. Children are visited
   front to back (row-major order with the axes flipped by the ray's
   direction signs is front to back for any straight line), so the first
   texel hit found is the closest and the walk stops there. One walk
   (lrt__walk_origin, the kernels' lrt_walk_origin step for step) starts at
   the lowest node holding the whole segment and goes down, or, for a long
   ray that starts on the surface, at the level-1 node where it starts and
   climbs: the same order, the same first hit.
   ========================================================================== */

/* Where the walk (lrt__walk_origin below) starts: at the origin for a ray
   that starts on the surface (at most 1/64 in front of the depth of the
   texel it starts in, or behind it) and goes far (its start node at level 4
   or above, and 16 texels or more along x or y); otherwise at the start
   node, from which it goes down. (The kernels start at the origin: this
   rule there won segments and lost reflections.) Long rays from the surface
   (shadows past thin poles, flat rays over 8-bit steps) win from the
   origin, which skips the nodes above; rays that meet nothing lose (one
   test of the start node ends them), and so do short ones. The surface
   test reads one depth, a cache miss for random rays on a large map; the
   figures: docs/PERFORMANCE.md. */
#define LRT__ORIGIN_MIN_LEVEL 4u
#define LRT__ORIGIN_MIN_REACH 16.0f
#define LRT__ORIGIN_SURFACE (1.0f / 64.0f)
LRT__FORCE_INLINE int lrt__from_origin(const lrt__walk *w, const lrt__ray_setup *s, uint32_t lv, uint32_t px, uint32_t py)
{
    const float reach = (s->t_hi - s->t_lo) * lrt__maxf(fabsf(s->v[0]), fabsf(s->v[1])); /* texels along x or y */
    if (lv < LRT__ORIGIN_MIN_LEVEL || s->zk || !(reach >= LRT__ORIGIN_MIN_REACH)) return 0;
    return s->o[2] >= lrt__raw_to_float(w->depth->format, lrt__depth_raw(w->depth, w->stride, px, py)) - LRT__ORIGIN_SURFACE;
}

/* The kernels' lrt_first_texel, the texel along one axis where their walk
   starts: the one holding o + t_lo v, or one behind it whose edge lies
   within the widening of t_lo. The CPU's walk starts from its texel range's
   corner instead, which can be the texel behind where the start lies within
   that range's margin of an edge: a budgeted walk, and a counting copy
   (LINEAR_RT_WALK_AS_KERNELS), must start where the kernels do. */
#ifdef LINEAR_RT_WALK_AS_KERNELS
#define LRT__AS_KERNELS (LINEAR_RT_WALK_AS_KERNELS)
#else
#define LRT__AS_KERNELS 0
#endif
static int lrt__first_texel(float o, float v, float iv, uint32_t neg, float t_lo, int size)
{
    float p = o + t_lo * v;
    int c;
    p = p > -2.0f ? p : -2.0f;
    p = p < (float)size + 2.0f ? p : (float)size + 2.0f;
    c = (int)floorf(p);
    if (v == 0.0f) c -= (neg == 0u && (float)c == o) ? 1 : 0; /* on an edge: the first in order */
    c = c < 0 ? 0 : c > size - 1 ? size - 1 : c;
    while (v != 0.0f) { /* while the texel behind it is touched at t_lo */
        const int b = neg ? c + 1 : c - 1;
        float e;
        if (b < 0 || b >= size) break;
        e = ((float)(neg ? c + 1 : c) - o) * iv;
        if (!(t_lo <= lrt__widen(e))) break;
        c = b;
    }
    return c;
}

/* Child `slot` of node (nx, ny) of level lv: its node at level lv - 1 (the
   kernels' lrt_child). Levels lv odd group their children 4x2, even 2x4. */
LRT__FORCE_INLINE void lrt__child(uint32_t lv, uint32_t *nx, uint32_t *ny, uint32_t slot)
{
    const uint32_t bw_log2 = (lv & 1u) ? 2u : 1u;
    *nx = (*nx << bw_log2) + (slot & ((1u << bw_log2) - 1u));
    *ny = (*ny << (3u - bw_log2)) + (slot >> bw_log2);
}

/* ---- the budgeted walk's node test: the kernels' floats -------------------
   A step budget counts node tests, so a budgeted walk must take the
   kernels' steps, not only give their answers: its node test above level 1
   culls with shaders/linear_rt.glsl's lrt_cull_children float for float
   (its planes p * iv + c as a product, then a sum), on every ISA. */
typedef struct lrt__cull { /* the kernels' LrtCull */
    float iv[2], en[2], ex[2]; /* x and y: plane p is entered at p * iv + en, left at p * iv + ex */
    float za, zb, ba, bb;      /* a child's depth plane: code * za + zb; its back plane: back code * ba + bb */
    float lo, hi;              /* t_lo, and t_hi widened */
} lrt__cull;

/* the kernels' lrt_cull_setup */
static void lrt__cull_setup(const lrt__walk *w, const lrt__ray_setup *s, lrt__cull *c)
{
    float za, en, ex;
    int axis;
    for (axis = 0; axis < 2; ++axis)
        lrt__cull_axis(s->o[axis], s->iv[axis], w->extent[axis], s->t_hi, &c->iv[axis], &c->en[axis], &c->ex[axis]);
    /* a child's depth plane is (65535 - code) * decode_scale */
    lrt__cull_axis(s->o[2] - w->code_depth0, s->iv[2], 1.0f, s->t_hi, &za, &en, &ex);
    c->za = w->code_step * za;
    c->zb = s->neg_z ? ex : en;
    /* the back plane is back code * back_scale: entered going up, left going down */
    lrt__cull_axis(s->o[2], s->iv[2], 1.0f, s->t_hi, &za, &en, &ex);
    c->ba = w->back_scale * za;
    c->bb = s->neg_z ? en : ex;
    c->lo = s->t_lo;
    c->hi = lrt__widen(s->t_hi);
}

/* the entering and leaving t of column (row) [a, a + step], clamped (the kernels' lrt_cull_slab) */
LRT__FORCE_INLINE void lrt__cull_slab(const lrt__cull *c, int axis, float a, float step, uint32_t neg, float *en,
                                             float *ex)
{
    float ta = a * c->iv[axis], tb = (a + step) * c->iv[axis], e, x;
    LRT__ROUNDED(ta);
    LRT__ROUNDED(tb);
    e = (neg ? tb : ta) + c->en[axis];
    x = (neg ? ta : tb) + c->ex[axis];
    *en = e > c->lo ? e : c->lo;
    *ex = x < c->hi ? x : c->hi;
}

/* The children of node (nx, ny) of level lv >= 2 that the kernels' node test
   keeps (lrt_cull_children), bit k for the child met k-th in visiting order:
   AVX2 in 8 lanes (visiting order, lrt__signs), else slot by slot. */
#if LRT__AVX
#if defined(__GNUC__) || defined(__clang__)
#define LRT__ROUNDED8(x) __asm__("" : "+x"(x))
#else
#define LRT__ROUNDED8(x) ((void)0)
#endif
LRT__FORCE_INLINE uint32_t lrt__kernel_cull_children(const lrt__walk *w, const lrt__ray_setup *s, const lrt__cull *c,
                                                     uint32_t lv, uint32_t nx, uint32_t ny, size_t slot0, uint32_t neg_z)
{
    const lrt__walk_level *v = &w->lv[lv];
    const lrt__signs *g = s->sg;
    const uint32_t tall = (lv & 1u) ^ 1u;
    const __m256 X0 = _mm256_set1_ps((float)(nx << v->span_w_log2)), Y0 = _mm256_set1_ps((float)(ny << v->span_h_log2));
    const __m256 sw = _mm256_set1_ps(v->child_span_w), sh = _mm256_set1_ps(v->child_span_h);
    /* each lane's planes x0 + k * span: small integers, exact however rounded */
    __m256 xe = _mm256_mul_ps(_mm256_add_ps(_mm256_mul_ps(g->kx_enter[tall], sw), X0), _mm256_set1_ps(c->iv[0]));
    __m256 xx = _mm256_mul_ps(_mm256_add_ps(_mm256_mul_ps(g->kx_exit[tall], sw), X0), _mm256_set1_ps(c->iv[0]));
    __m256 ye = _mm256_mul_ps(_mm256_add_ps(_mm256_mul_ps(g->ky_enter[tall], sh), Y0), _mm256_set1_ps(c->iv[1]));
    __m256 yx = _mm256_mul_ps(_mm256_add_ps(_mm256_mul_ps(g->ky_exit[tall], sh), Y0), _mm256_set1_ps(c->iv[1]));
    const __m256i codes = _mm256_permutevar8x32_epi32(_mm256_cvtepu16_epi32(lrt__load_codes(lrt__codes(w, slot0))), g->order[tall]);
    __m256 tz = _mm256_mul_ps(_mm256_cvtepi32_ps(codes), _mm256_set1_ps(c->za)), en, ex;
    LRT__ROUNDED8(xe);
    LRT__ROUNDED8(xx);
    LRT__ROUNDED8(ye);
    LRT__ROUNDED8(yx);
    LRT__ROUNDED8(tz);
    xe = _mm256_add_ps(xe, _mm256_set1_ps(c->en[0]));
    xx = _mm256_add_ps(xx, _mm256_set1_ps(c->ex[0]));
    ye = _mm256_add_ps(ye, _mm256_set1_ps(c->en[1]));
    yx = _mm256_add_ps(yx, _mm256_set1_ps(c->ex[1]));
    tz = _mm256_add_ps(tz, _mm256_set1_ps(c->zb));
    en = _mm256_max_ps(_mm256_max_ps(xe, ye), neg_z ? _mm256_set1_ps(c->lo) : _mm256_max_ps(tz, _mm256_set1_ps(c->lo)));
    ex = _mm256_min_ps(_mm256_min_ps(xx, yx), neg_z ? _mm256_min_ps(tz, _mm256_set1_ps(c->hi)) : _mm256_set1_ps(c->hi));
    if (w->back_codes && !s->zk) { /* the back plane (none for a z scaled by 2^zk: the codes would cut it) */
        const __m256i back =
            _mm256_permutevar8x32_epi32(_mm256_cvtepu16_epi32(lrt__load_codes(lrt__codes(w, w->back_codes + slot0))), g->order[tall]);
        __m256 tb = _mm256_mul_ps(_mm256_cvtepi32_ps(back), _mm256_set1_ps(c->ba));
        LRT__ROUNDED8(tb);
        tb = _mm256_add_ps(tb, _mm256_set1_ps(c->bb));
        if (neg_z) en = _mm256_max_ps(tb, en);
        else ex = _mm256_min_ps(tb, ex);
    }
    return (uint32_t)_mm256_movemask_ps(_mm256_cmp_ps(en, ex, _CMP_LE_OQ));
}
#else
static uint32_t lrt__kernel_cull_children(const lrt__walk *w, const lrt__ray_setup *s, const lrt__cull *c, uint32_t lv,
                                          uint32_t nx, uint32_t ny, size_t slot0, uint32_t neg_z)
{
    const lrt__walk_level *v = &w->lv[lv];
    const uint32_t tall = (lv & 1u) ^ 1u, flip = s->sg->flip[tall];
    const float sw = v->child_span_w, sh = v->child_span_h;
    const float x0 = (float)(nx << v->span_w_log2), y0 = (float)(ny << v->span_h_log2);
    const uint16_t *codes = lrt__codes(w, slot0), *backs = lrt__codes(w, w->back_codes + slot0);
    const int back = w->back_codes && !s->zk; /* no back plane for a z scaled by 2^zk: the codes would cut it */
    uint32_t slot, met = 0u, m = 0u, k;
    for (slot = 0; slot < 8u; ++slot) {
        const uint32_t col = tall ? slot & 1u : slot & 3u, row = tall ? slot >> 1 : slot >> 2;
        float ce, cx, re, rx, tz, tb, en, ex;
        lrt__cull_slab(c, 0, x0 + sw * (float)col, sw, s->neg_x, &ce, &cx);
        lrt__cull_slab(c, 1, y0 + sh * (float)row, sh, s->neg_y, &re, &rx);
        tz = (float)codes[slot] * c->za;
        LRT__ROUNDED(tz);
        tz += c->zb;
        tb = back ? (float)backs[slot] * c->ba : 0.0f;
        LRT__ROUNDED(tb);
        tb += c->bb;
        en = ce > re ? ce : re;
        ex = cx < rx ? cx : rx;
        if (neg_z) {
            en = back && tb > en ? tb : en;
            ex = tz < ex ? tz : ex;
        } else {
            en = tz > en ? tz : en;
            ex = back && tb < ex ? tb : ex;
        }
        met |= (uint32_t)(en <= ex) << slot;
    }
    for (k = 0; k < 8u; ++k) m |= ((met >> (k ^ flip)) & 1u) << k; /* into visiting order */
    return m;
}
#endif

/* Where a budgeted walk that stops before it tests node (lv, nx, ny) has
   proven its segment free (lrt_budget_t): its segment is proven free before the t where it
   enters that node, or, where the walk has just climbed to it (eligible:
   the children after the one it came from), before the t where it leaves
   that child (of the min of the two where the ray misses the node's box).
   Each plane's t, (p - o) * iv, is monotone in p: a node later in visiting
   order is entered no earlier than one before it is left, one inside a
   node no earlier than that node is entered, and a texel's hit lies in its
   box. So lrt_trace without a budget reports no hit before this t. A ray
   in a grid plane (lrt__in_grid_plane) meets texels out of visiting
   order: t_lo. */
LRT__FORCE_INLINE float lrt__budget_t(const lrt__walk *w, const lrt__ray_setup *s, uint32_t lv, uint32_t nx, uint32_t ny,
                                      uint32_t eligible)
{
    float en = s->t_lo, ex = s->t_hi, x0, y0, t;
    if (eligible != 0xffu) { /* the child it came from, k-th in visiting order */
        const uint32_t k = eligible ? lrt__lowest_bit(eligible) - 1u : 7u;
        lrt__child(lv, &nx, &ny, k ^ s->sg->flip[(lv & 1u) ^ 1u]);
        lv -= 1u;
    }
    x0 = (float)(nx << w->lv[lv].span_w_log2);
    y0 = (float)(ny << w->lv[lv].span_h_log2);
    lrt__slab(x0, x0 + (float)(1u << w->lv[lv].span_w_log2), s->o[0], s->iv[0], s->neg_x, &en, &ex);
    lrt__slab(y0, y0 + (float)(1u << w->lv[lv].span_h_log2), s->o[1], s->iv[1], s->neg_y, &en, &ex);
    t = eligible != 0xffu || ex < en ? ex : en;
    return t > s->t_lo && !lrt__in_grid_plane(s) ? t : s->t_lo; /* a grid plane's ray has proven nothing */
}

/* ---- the finish of a budget (LRT_TRACE_FINISH): a march from the free t -- */

/* The texel under the point at walk t along one axis (lrt_finish_texel):
   o + t v floored, on the map (a NaN: 0). */
LRT__FORCE_INLINE uint32_t lrt__finish_texel(float o, float v, float t, uint32_t size)
{
    const float p = o + t * v;
    return p >= 1.0f ? (p < (float)size ? (uint32_t)p : size - 1u) : 0u;
}

/* Whether the point at walk t lies in the solid of the texel under it
   (lrt_finish_inside): that texel's exact test over [t, t]; the texel in
   *x, *y. */
LRT__FORCE_INLINE int lrt__finish_inside(const lrt__walk *w, const lrt__ray_setup *s, float t, uint32_t *x, uint32_t *y)
{
    float tt, planes[2];
    LINEAR_RT_COUNT_FINISH_SAMPLE();
    *x = lrt__finish_texel(s->o[0], s->v[0], t, w->L->width);
    *y = lrt__finish_texel(s->o[1], s->v[1], t, w->L->height);
    return lrt__test_texel(w, s, *x, *y, t, t, lrt__texel_code(w, *x, *y), &tt, planes);
}

/* The finish (lrt_finish): samples at t0 + k (t1 - t0) 2^-n, k = 0 .. 2^n,
   t1 the segment's end (LRT_TRACE_FINISH says what it answers). Returns 1
   with the texel of the last sample inside, its t and the face guessed. */
static LRT__NOINLINE int lrt__finish(const lrt__walk *w, const lrt__ray_setup *s, float t0, uint32_t *hx, uint32_t *hy,
                                     float *ht, uint32_t *face)
{
    const uint32_t n = w->finish - 1u < LRT_K_FINISH_MAX - 1u ? w->finish - 1u : LRT_K_FINISH_MAX - 1u, steps = 1u << n;
    const float t1 = s->t_hi > t0 ? s->t_hi : t0, dt = (t1 - t0) * lrt__pow2(-(int)n);
    float lo = t0, hi = t0;
    uint32_t k, b, inside = 0u, x = 0u, y = 0u, lx = 0u, ly = 0u;
    for (k = 0; k <= steps && !inside; ++k) { /* [lo, hi]: the sample before, this one */
        lo = hi;
        lx = x;
        ly = y;
        hi = k == steps ? t1 : t0 + dt * (float)k;
        inside = (uint32_t)lrt__finish_inside(w, s, hi, &x, &y);
    }
    if (k == 1u) { /* inside at t0: the ray was over this texel before it */
        lx = x;
        ly = y;
    }
    for (b = 0; inside && k > 1u && b < LRT_K_FINISH_BISECTIONS; ++b) {
        const float mid = 0.5f * (lo + hi);
        uint32_t mx, my;
        if (lrt__finish_inside(w, s, mid, &mx, &my)) {
            hi = mid;
            x = mx;
            y = my;
        } else {
            lo = mid;
            lx = mx;
            ly = my;
        }
    }
    *hx = x;
    *hy = y;
    *ht = hi;
    *face = lx == x && ly == y ? (s->neg_z ? LRT_FACE_BACK : LRT_FACE_TOP) : LRT_FACE_SIDE;
    return (int)inside;
}

/* A budget's stop at the walk's t, proven free before it, told in the
   caller's ray: its finish's estimate, or a budget miss. */
LRT__FORCE_INLINE void lrt__report_budget(const lrt__walk *w, const lrt_ray *ray, const lrt__ray_setup *s, float t_scale,
                                          float t, lrt_hit *hit)
{
    uint32_t x, y, face;
    float at;
    hit->x = hit->y = 0;
    hit->face = LRT_FACE_NONE;
    hit->kind = LRT_MISS_BUDGET;
    if (w->finish && lrt__finish(w, s, t, &x, &y, &at, &face)) {
        t = at;
        hit->x = x;
        hit->y = y;
        hit->face = (uint16_t)face;
        hit->kind = LRT_HIT_ESTIMATE;
    }
    hit->t = lrt__ray_t(ray, s, t_scale, t);
}

/* The walk (shaders/linear_rt.glsl's lrt_walk_origin, the same steps under
   the same names): from the level-1 node of texel (px, py), where the
   segment starts, if lrt__from_origin says so, else from the start node
   (nx, ny) of level top >= 1, which holds the whole segment. A step tests
   the current node's children; at level 1 the texels the codes let through
   get their exact test, in visiting order; above it the walk goes down into
   the first child met, and the others wait in masks[lv] (one byte a level:
   the state is a few registers and these bytes, no stack of nodes). A node
   done, the walk takes the next pending child of the lowest level that has
   one, in one step (busy: a bit a level whose byte is not empty); where
   none has, it climbs to the parent of the current node's ancestor of
   level reached (the highest it has climbed to), never tested (the walk
   began below it), whose children after that ancestor are all that is
   left to test, unless the segment ends inside the ancestor.
   Returns 1 once a hit is reported. neg_z is a constant where this is
   inlined, and so is tall in each of the three copies of the node test
   (tall nodes, wide ones above the texels, level 1). */
LRT__FORCE_INLINE int lrt__walk_origin(const lrt__walk *w, const lrt_ray *ray, lrt_hit *hit, const lrt__ray_setup *s,
                                       float t_scale, uint32_t top, uint32_t nx, uint32_t ny, uint32_t px, uint32_t py,
                                       uint32_t budgeted, uint32_t neg_z)
{
    /* the levels above lv up to reached were tested: masks[] holds their
       pending children, and bit L of busy says masks[L] is not empty */
    uint32_t lv = top, eligible = 0xffu, reached, busy = 0u, steps = 0u;
    int reported = 0; /* the walk's one exit, after its loop */
    uint8_t masks[LINEAR_RT_MAX_LEVELS + 2];
    size_t slot0;
    lrt__cull kc; /* a budgeted walk's node test (lrt__kernel_cull_children) */
    if (budgeted) lrt__cull_setup(w, s, &kc);
    /* a budgeted walk (and profiling) starts as the kernels' walk
       (lrt_walk_origin) does: at the level-1 node of the texel where the
       segment starts */
    if (budgeted || LRT__AS_KERNELS) {
        px = (uint32_t)lrt__first_texel(s->o[0], s->v[0], s->iv[0], s->neg_x, s->t_lo, (int)w->L->width);
        py = (uint32_t)lrt__first_texel(s->o[1], s->v[1], s->iv[1], s->neg_y, s->t_lo, (int)w->L->height);
        lv = 1u;
        nx = px >> 2;
        ny = py >> 1;
    } else if (lrt__from_origin(w, s, top, px, py)) {
        lv = 1u;
        nx = px >> 2;
        ny = py >> 1;
    }
    reached = lv;
    slot0 = lrt__node_slot(w, lv, nx, ny);
    for (;;) {
        if (budgeted && steps++ == w->budget) { /* the budget is spent: the next node is not tested */
            lrt__report_budget(w, ray, s, t_scale, lrt__budget_t(w, s, lv, nx, ny, eligible), hit);
            reported = 1;
            break;
        }
        if (lv == 1u) { /* texels: the exact test, in visiting order */
            uint32_t tx, ty;
            float t, planes[2];
            LINEAR_RT_COUNT_NODE_TEST(1u);
            if (lrt__level1_hit(w, s, nx, ny, slot0, neg_z, &tx, &ty, &t, planes)) {
                lrt__report_hit(w, ray, s, t_scale, t, tx, ty, planes, hit);
                reported = 1;
                break;
            }
        } else {
            const uint32_t tall = (lv & 1u) ^ 1u;
            const size_t children = lrt__children_slot(w, lv, nx, ny);
            uint32_t m;
            lrt__prefetch_children(w, children);
            LINEAR_RT_COUNT_NODE_TEST(lv);
            if (budgeted) m = lrt__kernel_cull_children(w, s, &kc, lv, nx, ny, slot0, neg_z);
            else m = tall ? lrt__cull_children(w, s, lv, nx, ny, slot0, 1u, neg_z) : lrt__cull_children(w, s, lv, nx, ny, slot0, 0u, neg_z);
            /* a padding node (past its level's grid) has no children in
               memory: a ray whose culling is loose there (an axis it does
               not move along, on the map's far edge) must not go down into
               it (fuzz_core: a read past the nodes) */
            m &= eligible & (uint32_t)-(int32_t)((nx < w->lv[lv].width) & (ny < w->lv[lv].height));
            if (m) { /* down into the first child met; the others wait in masks */
                const uint32_t slot = lrt__lowest_bit(m) ^ s->sg->flip[tall], rest = m & (m - 1u);
                masks[lv] = (uint8_t)rest;
                busy |= (uint32_t)(rest != 0u) << lv;
                lrt__child(lv, &nx, &ny, slot);
                slot0 = children + (size_t)slot * 8u;
                if (lv == w->row_prefetch_level) lrt__prefetch_rows(w, nx, ny); /* level 3 is wide */
                lv -= 1u;
                eligible = 0xffu;
                continue;
            }
        }
        /* this node is done: the next pending child of the lowest busy
           level (the levels between are done), or up past reached (a block
           of its own: in C++ the continue above may not jump past x0's
           initialisation into its scope) */
        {
            const uint32_t x0 = nx << w->lv[lv].span_w_log2, y0 = ny << w->lv[lv].span_h_log2; /* its first texel */
            if (busy) {
                const uint32_t up = lrt__lowest_bit(busy), tall = (up & 1u) ^ 1u; /* up's children are tall */
                const uint32_t ux = x0 >> w->lv[up].span_w_log2, uy = y0 >> w->lv[up].span_h_log2;
                const uint32_t pend = masks[up], slot = lrt__lowest_bit(pend) ^ s->sg->flip[tall];
                masks[up] = (uint8_t)(pend & (pend - 1u));
                busy &= masks[up] ? ~0u : ~(1u << up);
                nx = ux;
                ny = uy;
                lrt__child(up, &nx, &ny, slot);
                slot0 = lrt__children_slot(w, up, ux, uy) + (size_t)slot * 8u;
                if (up == w->row_prefetch_level) lrt__prefetch_rows(w, nx, ny);
                lv = up - 1u;
                eligible = 0xffu;
            } else {
                /* the parent of the ancestor of level reached was never
                   tested (the walk began below it): unless the segment ends
                   inside that ancestor, the children after it */
                const uint32_t up = reached + 1u, tall = (up & 1u) ^ 1u, bw_log2 = tall ? 1u : 2u; /* the parent's block */
                uint32_t sw, sh, ax, ay, k;
                float fx, fy, ex_x, ex_y;
                if (reached >= top) break; /* the start node, which holds the segment, is done */
                sw = w->lv[reached].span_w_log2;
                sh = w->lv[reached].span_h_log2;
                ax = x0 >> sw;
                ay = y0 >> sh;
                fx = (float)((s->neg_x ? ax : ax + 1u) << sw);
                fy = (float)((s->neg_y ? ay : ay + 1u) << sh);
                /* an axis the ray does not move along: never left (an
                   infinite t), unless the ray lies on the far edge (0 times
                   an infinite inverse: NaN), where the next node is touched
                   too, as the kernels take it */
                ex_x = (fx - s->o[0]) * s->iv[0];
                ex_y = (fy - s->o[1]) * s->iv[1];
                if (ex_x != ex_x) ex_x = -INFINITY;
                if (ex_y != ex_y) ex_y = -INFINITY;
                if (LRT__MIN_KEEP(ex_x, ex_y) > lrt__widen(s->t_hi)) break; /* the segment ends inside it */
                k = lrt__child_slot(&w->L->levels[reached], ax, ay) ^ s->sg->flip[tall];
                eligible = ~((2u << k) - 1u) & 0xffu;
                lv = reached = up;
                nx = ax >> bw_log2;
                ny = ay >> (3u - bw_log2);
                slot0 = lrt__node_slot(w, lv, nx, ny);
            }
        }
    }
    return reported;
}

/* The walk's two copies (sign of v.z), each a function of its own: inlined
   where the rays are set up, the walk's registers cost the camera rays,
   which never walk, 7-10% (build/bench --only "linear_rt cpu" --threads 1
   --size 512, two alternated runs). */
static LRT__NOINLINE int lrt__walk_up(const lrt__walk *w, const lrt_ray *ray, lrt_hit *hit, const lrt__ray_setup *s,
                                      float t_scale, uint32_t top, uint32_t nx, uint32_t ny, uint32_t px, uint32_t py)
{
    return lrt__walk_origin(w, ray, hit, s, t_scale, top, nx, ny, px, py, 0u, 0u);
}
static LRT__NOINLINE int lrt__walk_down(const lrt__walk *w, const lrt_ray *ray, lrt_hit *hit, const lrt__ray_setup *s,
                                        float t_scale, uint32_t top, uint32_t nx, uint32_t ny, uint32_t px, uint32_t py)
{
    return lrt__walk_origin(w, ray, hit, s, t_scale, top, nx, ny, px, py, 0u, 1u);
}
/* the budgeted walk (LRT_TRACE_BUDGET): copies of their own, so that the
   exact walk carries no step count */
static LRT__NOINLINE int lrt__walk_up_budget(const lrt__walk *w, const lrt_ray *ray, lrt_hit *hit, const lrt__ray_setup *s,
                                             float t_scale, uint32_t top, uint32_t nx, uint32_t ny, uint32_t px, uint32_t py)
{
    return lrt__walk_origin(w, ray, hit, s, t_scale, top, nx, ny, px, py, 1u, 0u);
}
static LRT__NOINLINE int lrt__walk_down_budget(const lrt__walk *w, const lrt_ray *ray, lrt_hit *hit, const lrt__ray_setup *s,
                                               float t_scale, uint32_t top, uint32_t nx, uint32_t ny, uint32_t px, uint32_t py)
{
    return lrt__walk_origin(w, ray, hit, s, t_scale, top, nx, ny, px, py, 1u, 1u);
}

/* Whether lrt_trace takes a set-up ray to the cell walk (section walk-cells): in an infinite
   tree, with a budget (whose steps must be the kernels'), a ray their
   ordinary pass would (lrt_trace_ray_ordinary_budget): not rare (a large
   direction alone is not), and in no plane of the texel grid. */
LRT__FORCE_INLINE int lrt__walk_cells_takes(const lrt__walk *w, const lrt_ray *ray, const lrt__ray_setup *s)
{
    const uint32_t W = w->L->width, H = w->L->height;
    if (!w->budget || w->back_codes) return 0;
    if ((lrt__rare_bits(ray) || lrt__far_origin(ray->origin, W, H)) && !lrt__huge_direction(ray, W, H)) return 0;
    return !lrt__in_grid_plane(s);
}

static void lrt__trace_cells(const lrt__walk *w, const lrt_ray *ray, lrt_hit *hit, const lrt__ray_setup *s, float t_scale,
                             uint32_t kind); /* section walk-cells */

/* The trace of a set-up ray from node (nx, ny) of level lv (lrt__start_node);
   cull: lrt__cull_constants, stride floats apart, where AVX2 builds them
   (NULL: made here). */
LRT__FORCE_INLINE void lrt__trace_from(const lrt__walk *w, const lrt_ray *ray, lrt_hit *hit, lrt__ray_setup *s, float t_scale,
                                       uint32_t kind, uint32_t lv, uint32_t nx, uint32_t ny, uint32_t px, uint32_t py,
                                       const float *cull, size_t stride)
{
    /* a budget counts the kernels' steps: the cell walk's where it takes
       the ray (lrt__walk_cells_takes; 0 without a budget) */
    const int cells = lrt__walk_cells_takes(w, ray, s);
    if (lv == 0) { /* one texel: its box alone decides */
        const float x0 = (float)nx, y0 = (float)ny;
        float en = s->t_lo, ex = s->t_hi, t, planes[2];
        LINEAR_RT_COUNT_NODE_TEST(0u);
        lrt__slab(x0, x0 + 1.0f, s->o[0], s->iv[0], s->neg_x, &en, &ex);
        lrt__slab(y0, y0 + 1.0f, s->o[1], s->iv[1], s->neg_y, &en, &ex);
        if (lrt__test_texel(w, s, nx, ny, en, ex, lrt__texel_code(w, nx, ny), &t, planes)) {
            lrt__report_hit(w, ray, s, t_scale, t, nx, ny, planes, hit);
            return; /* the cell walk's first step, its first texel, is this one */
        }
        if (!cells) {
            hit->kind = (uint16_t)kind;
            return;
        }
        /* a miss: the cell walk may take more steps to prove it */
    }
    if (cells) {
        lrt__trace_cells(w, ray, hit, s, t_scale, kind);
        return;
    }
    lrt__walk_setup(w, s, cull, stride);
    /* the walk, with the sign of v.z a constant of its node tests */
    if (w->budget ? !(s->neg_z ? lrt__walk_down_budget(w, ray, hit, s, t_scale, lv, nx, ny, px, py)
                               : lrt__walk_up_budget(w, ray, hit, s, t_scale, lv, nx, ny, px, py))
                  : !(s->neg_z ? lrt__walk_down(w, ray, hit, s, t_scale, lv, nx, ny, px, py)
                               : lrt__walk_up(w, ray, hit, s, t_scale, lv, nx, ny, px, py)))
        hit->kind = (uint16_t)kind;
}

LRT__FORCE_INLINE void lrt__trace_one(const lrt__walk *w, const lrt_ray *ray, lrt_hit *hit)
{
    const lrt_layout *L = w->L;
    lrt__ray_setup s;
    float t_scale;
    uint32_t kind, lv, nx, ny, px, py;
    hit->t = 0.0f;
    hit->x = hit->y = 0;
    hit->face = LRT_FACE_NONE;
    if (!lrt__setup_ray(ray, L->width, L->height, &s, &t_scale, &kind)) {
        hit->kind = (uint16_t)kind;
        return;
    }
    lv = lrt__start_node(w, &s, &nx, &ny, &px, &py);
    lrt__trace_from(w, ray, hit, &s, t_scale, kind, lv, nx, ny, px, py, NULL, 0);
}

/* ============================================================ >>walk-cells
   The GPU's cell walk, in C: the kernels' ordinary pass of an infinite
   tree, one cell or texel a step: a budgeted CPU trace's walk there, the
   benchmark's counts and the tests (below).
   ========================================================================== */
/* ---- the GPU's cell walk, in C ------------------------------------------------
   The kernels' exact ordinary pass of an infinite tree walks one cell a
   step (shaders/linear_rt.glsl, lrt_walk_cells, which says why its answer
   is the walk above's: the first texel hit in the same visiting order).
   This is that walk step for step, its floats the kernels' (a cell's code
   plane lrt__cull_setup's, a texel's test lrt__test_texel), for the
   benchmark's count of what a GPU wave pays (bench/visits.c), the tests,
   which hold its hits to lrt_trace's, and a budgeted trace of an infinite
   tree (lrt__walk_cells_takes), whose budget counts the kernels' steps.
   An exact CPU trace keeps the 8-child walk: its node test is cheap in
   SIMD lanes. Compiled in both passes; its GLSL twins: the TWINS table of
   section walk. */
/* The lowest level whose nodes hold texel columns a and b (x, lrt_split_level_x)
   or rows a and b (y, lrt_split_level_y) apart, less one: -1 for one texel.
   Level lv spans 2^ceil(lv * 3 / 2) texels along x, 2^floor: the highest
   bit where a and b differ (GLSL's findMSB) gives it. */
LRT__UNUSED static int lrt__find_msb(uint32_t d)
{
    int m = 31;
    while (m > 0 && !(d >> m)) --m;
    return d ? m : -1;
}
LRT__UNUSED static int lrt__split_level_x(int a, int b)
{
    return a == b ? -1 : (2 * lrt__find_msb((uint32_t)(a ^ b))) / 3;
}
LRT__UNUSED static int lrt__split_level_y(int a, int b)
{
    return a == b ? -1 : (2 * lrt__find_msb((uint32_t)(a ^ b)) + 1) / 3;
}

/* lrt_cross_texel */
LRT__UNUSED static int lrt__cross_texel(float o, float v, float iv, uint32_t neg, float t, int lo, int hi, int cur)
{
    int c = cur;
    if (v != 0.0f) {
        float q = o + t * v, e;
        int b;
        q = q < (float)lo ? (float)lo : q > (float)hi ? (float)hi : q;
        c = (int)floorf(q);
        b = neg ? c + 1 : c - 1;
        e = ((float)(neg ? c + 1 : c) - o) * iv;
        c = (b >= lo && b <= hi && t <= lrt__widen(e)) ? b : c;
    }
    return c;
}

/* lrt_cell_axis */
LRT__UNUSED static void lrt__cell_axis(int a, int n, float o, float v, float iv, uint32_t neg, float *en, float *ex,
                                       float *leave, int *past, int *last)
{
    float ta = ((float)a - o) * iv, tb = ((float)(a + n) - o) * iv;
    LRT__ROUNDED(ta);
    LRT__ROUNDED(tb);
    lrt__slab((float)a, (float)(a + n), o, iv, neg, en, ex);
    *leave = v == 0.0f ? INFINITY : neg ? ta : tb;
    *past = neg ? a - 1 : a + n;
    *last = neg ? a : a + n - 1;
}

/* what lrt__walk_cells found (lrt_walk_cells' LRT_WALK_*) */
#define LRT__WALK_MISS 0u
#define LRT__WALK_HIT 1u
#define LRT__WALK_BUDGET 2u

/* lrt_walk_cells of a set-up thin ray, step for step: LRT__WALK_HIT with
   the first texel hit (*hx, *hy), its t and planes; LRT__WALK_MISS; or, with
   a budget (cell steps, 0: none), LRT__WALK_BUDGET where the next step
   would pass it, *ht then the t before which the segment is proven free
   (the GLSL says why). counts, where not NULL, add the steps taken [0] and
   the texels tested among them [1]. */
static uint32_t lrt__walk_cells(const lrt__walk *w, const lrt__ray_setup *s, uint32_t budget, uint32_t *hx, uint32_t *hy,
                                float *ht, float hplanes[2], size_t counts[2])
{
    const lrt_layout *L = w->L;
    lrt__cull c;
    int x, y, lv = 0, pend = 0;
    uint32_t steps = 0, found = LRT__WALK_MISS;
    float free_t = s->t_lo; /* no hit before it */
    lrt__cull_setup(w, s, &c);
    x = lrt__cross_texel(s->o[0], s->v[0], s->iv[0], s->neg_x, s->t_lo, 0, (int)L->width - 1, (int)s->o[0]);
    y = lrt__cross_texel(s->o[1], s->v[1], s->iv[1], s->neg_y, s->t_lo, 0, (int)L->height - 1, (int)s->o[1]);
    *hx = *hy = 0;
    *ht = 0.0f;
    hplanes[0] = hplanes[1] = 0.0f;
    for (;;) {
        const int sw = lv + ((lv + 1) >> 1), sh = lv + (lv >> 1);
        const int cx = x >> sw, cy = y >> sh; /* x, y >= 0: a move to -1 ends the walk */
        float en = s->t_lo, ex = s->t_hi, lx, ly;
        int px, py, lastx, lasty, met = 0, to = lv - 1;
        if (budget && steps == budget) { /* spent: the next cell is not tested */
            *ht = free_t;
            found = LRT__WALK_BUDGET;
            break;
        }
        ++steps;
        lrt__cell_axis(cx << sw, 1 << sw, s->o[0], s->v[0], s->iv[0], s->neg_x, &en, &ex, &lx, &px, &lastx);
        lrt__cell_axis(cy << sh, 1 << sh, s->o[1], s->v[1], s->iv[1], s->neg_y, &en, &ex, &ly, &py, &lasty);
        if (lv == 0) {
            const int on = (uint32_t)x < L->width && (uint32_t)y < L->height;
            const uint32_t code = on ? lrt__texel_code(w, (uint32_t)x, (uint32_t)y) : 0u;
            if (counts) ++counts[1];
            if (lrt__test_texel(w, s, (uint32_t)x, (uint32_t)y, en, ex, code, ht, hplanes)) {
                *hx = (uint32_t)x;
                *hy = (uint32_t)y;
                found = LRT__WALK_HIT;
                break;
            }
        } else if ((uint32_t)x < L->width && (uint32_t)y < L->height) {
            const uint32_t bw = ((uint32_t)lv & 1u) ? 1u : 2u, bh = 3u - bw;
            const size_t code = lrt__node_slot(w, (uint32_t)lv + 1u, (uint32_t)cx >> bw, (uint32_t)cy >> bh) +
                                ((((uint32_t)cy & ((1u << bh) - 1u)) << bw) | ((uint32_t)cx & ((1u << bw) - 1u)));
            float tz = (float)*lrt__codes(w, code) * c.za, e0 = en, x0 = lrt__widen(ex);
            LRT__ROUNDED(tz);
            tz += c.zb;
            if (s->neg_z) x0 = tz < x0 ? tz : x0;
            else e0 = tz > e0 ? tz : e0;
            if (w->back_codes) {
                float tb = (float)*lrt__codes(w, w->back_codes + code) * c.ba;
                LRT__ROUNDED(tb);
                tb += c.bb;
                if (s->neg_z) e0 = tb > e0 ? tb : e0;
                else x0 = tb < x0 ? tb : x0;
            }
            met = e0 <= x0;
        }
        if (!met) {
            const int bx = lrt__split_level_x(lastx, px), by = lrt__split_level_y(lasty, py);
            const float lt = lx < ly ? lx : ly;
            if (pend) {
                x += (pend & 1) == (int)s->neg_x ? 1 : -1;
                y += (pend & 1) == (int)s->neg_y ? -1 : 1;
                to = pend >> 2;
                pend = 0;
            } else if (!(lt <= lrt__widen(s->t_hi))) {
                break; /* the segment ends in this cell */
            } else {
                free_t = free_t > lt ? free_t : lt; /* every cell before the next is done */
                if ((lx > ly ? lx : ly) <= lrt__widen(lt)) {
                    const int a_first = bx <= by;
                    x = a_first ? px : lastx;
                    y = a_first ? lasty : py;
                    to = a_first ? bx : by;
                    pend = ((bx > by ? bx : by) << 2) | 2 | a_first;
                } else if (lx < ly) {
                    y = lrt__cross_texel(s->o[1], s->v[1], s->iv[1], s->neg_y, lx, cy << sh, ((cy + 1) << sh) - 1, y);
                    x = px;
                    to = bx;
                } else {
                    x = lrt__cross_texel(s->o[0], s->v[0], s->iv[0], s->neg_x, ly, cx << sw, ((cx + 1) << sw) - 1, x);
                    y = py;
                    to = by;
                }
            }
            if (to >= (int)L->level_count) break; /* past the root's cell: off the screen */
        }
        lv = to;
    }
    if (counts) counts[0] += steps;
    return found;
}

/* A budgeted ray of an infinite tree through the cell walk (lrt_trace_cells
   of the kernels), called by both passes of the walk: scalar code, once. */
static LRT__NOINLINE void lrt__trace_cells(const lrt__walk *w, const lrt_ray *ray, lrt_hit *hit, const lrt__ray_setup *s,
                                           float t_scale, uint32_t kind)
{
    uint32_t hx, hy, found;
    float t, planes[2];
    found = lrt__walk_cells(w, s, w->budget, &hx, &hy, &t, planes, NULL);
    if (found == LRT__WALK_HIT) {
        lrt__report_hit(w, ray, s, t_scale, t, hx, hy, planes, hit);
    } else if (found == LRT__WALK_BUDGET) {
        lrt__report_budget(w, ray, s, t_scale, t, hit);
    } else {
        hit->t = 0.0f;
        hit->x = hit->y = 0;
        hit->face = LRT_FACE_NONE;
        hit->kind = (uint16_t)kind;
    }
}


#ifndef LRT__AVX2_PASS
/* One ray through the cell walk, for code after this file (where the walk's
   names may stand for their AVX2 pass): 0 where the kernels' ordinary pass
   would not take it to the cell walk (a rare ray, one in a plane of the
   texel grid, or nothing to walk), else 1 with *steps, *texels added to,
   *hit and its texel. */
LRT__UNUSED static int lrt__walk_cells_ray(const lrt_bvh *bvh, const lrt_depth *depth, const lrt_ray *ray, uint32_t *steps,
                                           size_t *texels, int *hit, uint32_t *hx, uint32_t *hy)
{
    lrt__walk w;
    lrt__ray_setup s;
    size_t stride = 0, counts[2] = {0, 0};
    float t_scale, t, planes[2];
    uint32_t kind;
    *hit = 0;
    if (lrt__check_depth(depth, &stride) != LRT_SUCCESS) return 0;
    if ((lrt__rare_bits(ray) || lrt__far_origin(ray->origin, depth->width, depth->height)) &&
        !lrt__huge_direction(ray, depth->width, depth->height))
        return 0;
    if (!lrt__setup_ray(ray, depth->width, depth->height, &s, &t_scale, &kind) || lrt__in_grid_plane(&s)) return 0;
    lrt__walk_init(&w, bvh, depth, stride);
    *hit = lrt__walk_cells(&w, &s, 0u, hx, hy, &t, planes, counts) == LRT__WALK_HIT;
    *steps = (uint32_t)counts[0];
    *texels += counts[1];
    return 1;
}
#endif /* !LRT__AVX2_PASS: lrt__walk_cells_ray */

/* ============================================================ >>batch-avx2
   Eight rays at once (AVX2): set up side by side, then each walked, and the
   trace loop (lrt__trace_walk) that takes a batch in eights where it can.
   ========================================================================== */
#if LRT__AVX
/* Eight rays set up side by side: the same floats as lrt__setup_ray,
   lrt__start_node and lrt__cull_constants, one ray a lane, with no branch
   on a ray's signs or kind. A lane that needs more (a ray at the edge of
   float range, or a far origin to restart) is left to lrt__setup_ray.
   Row k of each array holds one value of the 8 rays. */
typedef struct lrt__batch8 {
    float o[3][8], v[3][8], iv[3][8], t_lo[8], t_hi[8];
    float cull[LRT__CULL_COUNT][8]; /* lrt__cull_constants */
    float t_scale[8];               /* 2^-e of a ray scaled by lrt__huge_direction, else 1 (set when huge) */
    int huge;                       /* lanes with a direction of 2^16 or more */
    uint32_t i0[2][8], i1[2][8];    /* lrt__start_node's texel range, x and y */
    uint32_t kind[8];
    uint32_t one_by_one, walk, column; /* lane masks: for lrt__setup_ray; something to walk; a camera ray in one texel column */
} lrt__batch8;

/* lanes where the float bits x are 0 or their size lies in [low, low + span) (lrt__setup_ray) */
LRT__FORCE_INLINE __m256i lrt__bits_in(__m256 x, uint32_t low, uint32_t span)
{
    const __m256i size = _mm256_and_si256(_mm256_castps_si256(x), _mm256_set1_epi32(0x7fffffff));
    const __m256i bias = _mm256_set1_epi32((int)0x80000000u);
    const __m256i moved = _mm256_xor_si256(_mm256_sub_epi32(size, _mm256_set1_epi32((int)low)), bias);
    return _mm256_or_si256(_mm256_cmpeq_epi32(size, _mm256_setzero_si256()),
                           _mm256_cmpgt_epi32(_mm256_set1_epi32((int)(span ^ 0x80000000u)), moved));
}

/* lrt__cull_axis on 8 lanes */
LRT__FORCE_INLINE void lrt__cull_axis8(__m256 o, __m256 iv, float extent, __m256 t_hi, float *cull_iv, float *c_enter, float *c_exit)
{
    const __m256 sign = _mm256_set1_ps(-0.0f), size = _mm256_andnot_ps(sign, iv);
    const __m256 huge = _mm256_cmp_ps(size, _mm256_set1_ps(LRT__CULL_IV_MAX), _CMP_NLT_UQ);
    const __m256 m = _mm256_blendv_ps(size, _mm256_set1_ps(LRT__CULL_IV_MAX), huge);
    const __m256 ivc = _mm256_or_ps(m, _mm256_and_ps(sign, iv)), c = _mm256_mul_ps(_mm256_xor_ps(o, sign), ivc);
    const __m256 d = _mm256_add_ps(
        _mm256_mul_ps(_mm256_mul_ps(_mm256_add_ps(_mm256_andnot_ps(sign, o), _mm256_set1_ps(extent)), m),
                      _mm256_set1_ps(LRT__CULL_MARGIN)),
        _mm256_mul_ps(_mm256_andnot_ps(sign, t_hi), _mm256_blendv_ps(_mm256_set1_ps(LRT__CULL_MARGIN), _mm256_set1_ps(2.0f), huge)));
    _mm256_storeu_ps(cull_iv, ivc);
    _mm256_storeu_ps(c_enter, _mm256_sub_ps(c, d));
    _mm256_storeu_ps(c_exit, _mm256_add_ps(c, d));
}

/* lrt__far_origin on 8 lanes */
LRT__FORCE_INLINE __m256 lrt__far8(const lrt_layout *L, const __m256 o[3])
{
    const __m256 sign = _mm256_set1_ps(-0.0f);
    const __m256 far = _mm256_or_ps(_mm256_cmp_ps(_mm256_andnot_ps(sign, o[0]), _mm256_set1_ps(2.0f * (float)L->width + 16.0f), _CMP_GT_OQ),
                                    _mm256_cmp_ps(_mm256_andnot_ps(sign, o[1]), _mm256_set1_ps(2.0f * (float)L->height + 16.0f), _CMP_GT_OQ));
    return _mm256_or_ps(far, _mm256_cmp_ps(_mm256_andnot_ps(sign, o[2]), _mm256_set1_ps(4.0f), _CMP_GT_OQ));
}

/* lrt__huge_direction on 8 lanes, given their |v| bits av and the largest
   mb (lrt__setup8's): such a ray scaled by 2^-e, its t by 2^e
   (b->t_scale); a far origin is left to the bit test of lrt__setup8, which
   sends it one by one. Apart, so that lrt__setup8 stays short for camera
   rays. */
static LRT__NOINLINE void lrt__huge8(const lrt__walk *w, const __m256 o[3], __m256 v[3], __m256 *tmin, __m256 *tmax,
                                     const __m256i av[3], __m256i mb, lrt__batch8 *b)
{
    const lrt_layout *L = w->L;
    const __m256 one = _mm256_set1_ps(1.0f);
    const __m256i abs_bits = _mm256_set1_epi32(0x7fffffff), lo = _mm256_set1_epi32(-101), hi = _mm256_set1_epi32(128);
    __m256i at[2], e, h;
    __m256 down, up, hf;
    int k;
    at[0] = _mm256_and_si256(_mm256_castps_si256(*tmin), abs_bits);
    at[1] = _mm256_and_si256(_mm256_castps_si256(*tmax), abs_bits);
    e = _mm256_sub_epi32(_mm256_srli_epi32(mb, 23), _mm256_set1_epi32(127));
    h = _mm256_and_si256(_mm256_cmpgt_epi32(mb, _mm256_set1_epi32(0x477fffff)), _mm256_cmpgt_epi32(_mm256_set1_epi32(0x7e800000), mb));
    for (k = 0; k < 3; ++k) {
        const __m256i ev = _mm256_sub_epi32(_mm256_srli_epi32(av[k], 23), e); /* v_k 2^-e: 2^-100 or more */
        h = _mm256_and_si256(h, lrt__bits_in(o[k], LRT__RARE_TINY, 0x7f800000u - LRT__RARE_TINY));
        h = _mm256_and_si256(h, _mm256_or_si256(_mm256_cmpeq_epi32(av[k], _mm256_setzero_si256()),
                                                _mm256_cmpgt_epi32(_mm256_sub_epi32(ev, _mm256_set1_epi32(127)), lo)));
    }
    for (k = 0; k < 2; ++k) { /* 0 or normal, and finite once scaled */
        const __m256i et = _mm256_add_epi32(_mm256_sub_epi32(_mm256_srli_epi32(at[k], 23), _mm256_set1_epi32(127)), e);
        h = _mm256_and_si256(h, lrt__bits_in(k ? *tmax : *tmin, 0x00800000u, 0x7f000000u));
        h = _mm256_and_si256(h, _mm256_or_si256(_mm256_cmpeq_epi32(at[k], _mm256_setzero_si256()), _mm256_cmpgt_epi32(hi, et)));
    }
    hf = _mm256_andnot_ps(lrt__far8(L, o), _mm256_castsi256_ps(h));
    down = _mm256_castsi256_ps(_mm256_slli_epi32(_mm256_sub_epi32(_mm256_set1_epi32(127), e), 23));
    up = _mm256_castsi256_ps(_mm256_slli_epi32(_mm256_add_epi32(_mm256_set1_epi32(127), e), 23));
    for (k = 0; k < 3; ++k) v[k] = _mm256_blendv_ps(v[k], _mm256_mul_ps(v[k], down), hf);
    *tmin = _mm256_blendv_ps(*tmin, _mm256_mul_ps(*tmin, up), hf);
    *tmax = _mm256_blendv_ps(*tmax, _mm256_mul_ps(*tmax, up), hf);
    _mm256_storeu_ps(b->t_scale, _mm256_blendv_ps(one, down, hf));
}

static void lrt__setup8(const lrt__walk *w, const lrt_ray *rays, lrt__batch8 *b)
{
    const lrt_layout *L = w->L;
    const float *f = (const float *)(const void *)rays; /* 8 floats a ray: origin, tmin, dir, tmax */
    const __m256 sign = _mm256_set1_ps(-0.0f), zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
    __m256 r[8], t[8], o[3], v[3], iv[3], tmin, tmax, enter, exit, t_lo, t_hi, neg[3], bad, walk;
    int k;
    for (k = 0; k < 8; ++k) r[k] = _mm256_loadu_ps(f + (size_t)k * 8u);
    for (k = 0; k < 8; k += 2) { /* 8x8 transpose: row k of r is ray k, of the result value k */
        t[k] = _mm256_unpacklo_ps(r[k], r[k + 1]);
        t[k + 1] = _mm256_unpackhi_ps(r[k], r[k + 1]);
    }
    for (k = 0; k < 8; k += 4) {
        r[k] = _mm256_shuffle_ps(t[k], t[k + 2], _MM_SHUFFLE(1, 0, 1, 0));
        r[k + 1] = _mm256_shuffle_ps(t[k], t[k + 2], _MM_SHUFFLE(3, 2, 3, 2));
        r[k + 2] = _mm256_shuffle_ps(t[k + 1], t[k + 3], _MM_SHUFFLE(1, 0, 1, 0));
        r[k + 3] = _mm256_shuffle_ps(t[k + 1], t[k + 3], _MM_SHUFFLE(3, 2, 3, 2));
    }
    for (k = 0; k < 4; ++k) {
        t[k] = _mm256_permute2f128_ps(r[k], r[k + 4], 0x20);
        t[k + 4] = _mm256_permute2f128_ps(r[k], r[k + 4], 0x31);
    }
    o[0] = t[0], o[1] = t[1], o[2] = t[2], tmin = t[3], v[0] = t[4], v[1] = t[5], v[2] = t[6], tmax = t[7];
    { /* lrt__huge_direction: a batch with no direction of 2^16 or more
         (camera rays) pays one compare */
        const __m256i abs_bits = _mm256_set1_epi32(0x7fffffff);
        __m256i av[3], mb;
        for (k = 0; k < 3; ++k) av[k] = _mm256_and_si256(_mm256_castps_si256(v[k]), abs_bits);
        mb = _mm256_max_epi32(_mm256_max_epi32(av[0], av[1]), av[2]);
        b->huge = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(mb, _mm256_set1_epi32(0x477fffff))));
        if (LRT__UNLIKELY(b->huge)) lrt__huge8(w, o, v, &tmin, &tmax, av, mb, b);
    }
    { /* the bit test of lrt__setup_ray: such lanes go one by one */
        __m256i ok = _mm256_and_si256(lrt__bits_in(tmin, 0x00800000u, 0x7f000000u), lrt__bits_in(tmax, 0x00800000u, 0x7f000000u));
        for (k = 0; k < 3; ++k) {
            ok = _mm256_and_si256(ok, lrt__bits_in(o[k], LRT__RARE_TINY, 0x7f800000u - LRT__RARE_TINY));
            ok = _mm256_and_si256(ok, lrt__bits_in(v[k], LRT__RARE_TINY, LRT__RARE_HUGE - LRT__RARE_TINY));
        }
        bad = _mm256_or_ps(_mm256_castsi256_ps(_mm256_xor_si256(ok, _mm256_set1_epi32(-1))),
                           _mm256_and_ps(_mm256_cmp_ps(o[2], zero, _CMP_EQ_OQ),
                                         _mm256_cmp_ps(_mm256_andnot_ps(sign, v[2]), _mm256_set1_ps(16.0f), _CMP_GE_OQ)));
    }
    for (k = 0; k < 3; ++k) {
        iv[k] = _mm256_div_ps(one, v[k]);
        neg[k] = _mm256_castsi256_ps(_mm256_srai_epi32(_mm256_castps_si256(v[k]), 31));
    }
    { /* lrt__clip */
        const __m256 t1 = _mm256_mul_ps(_mm256_sub_ps(one, o[2]), iv[2]), t0 = _mm256_mul_ps(_mm256_sub_ps(zero, o[2]), iv[2]);
        const __m256 size[2] = {_mm256_set1_ps((float)L->width), _mm256_set1_ps((float)L->height)};
        __m256 kind;
        enter = _mm256_set1_ps(-INFINITY);
        exit = _mm256_set1_ps(INFINITY);
        for (k = 0; k < 2; ++k) {
            const __m256 a = _mm256_mul_ps(_mm256_sub_ps(zero, o[k]), iv[k]), c = _mm256_mul_ps(_mm256_sub_ps(size[k], o[k]), iv[k]);
            enter = _mm256_max_ps(_mm256_blendv_ps(a, c, neg[k]), enter);
            exit = _mm256_min_ps(_mm256_blendv_ps(c, a, neg[k]), exit);
        }
        t_lo = _mm256_max_ps(enter, tmin);
        t_hi = _mm256_min_ps(exit, tmax);
        kind = _mm256_or_ps(_mm256_cmp_ps(t_lo, t_hi, _CMP_GT_OQ), _mm256_cmp_ps(exit, tmax, _CMP_LT_OQ));
        _mm256_storeu_si256((__m256i *)(void *)b->kind,
                            _mm256_blendv_epi8(_mm256_set1_epi32(LRT_MISS_TMAX), _mm256_set1_epi32(LRT_MISS_OFF_SCREEN),
                                               _mm256_castps_si256(kind)));
        t_lo = _mm256_max_ps(_mm256_blendv_ps(t0, t1, neg[2]), t_lo);
        t_hi = _mm256_min_ps(_mm256_blendv_ps(t1, t0, neg[2]), t_hi);
    }
    { /* an invalid range: no walk, kind LRT_MISS_INVALID_RAY */
        const __m256 invalid = _mm256_or_ps(_mm256_cmp_ps(tmin, zero, _CMP_NGE_UQ), _mm256_cmp_ps(tmin, tmax, _CMP_NLE_UQ));
        _mm256_storeu_si256((__m256i *)(void *)b->kind, _mm256_blendv_epi8(_mm256_loadu_si256((const __m256i *)(const void *)b->kind),
                                                                              _mm256_set1_epi32(LRT_MISS_INVALID_RAY),
                                                                              _mm256_castps_si256(invalid)));
        walk = _mm256_andnot_ps(invalid, _mm256_cmp_ps(t_lo, t_hi, _CMP_LE_OQ));
        /* a far origin restarts: one by one */
        bad = _mm256_or_ps(bad, _mm256_and_ps(walk, lrt__far8(L, o)));
    }
    b->one_by_one = (uint32_t)_mm256_movemask_ps(bad);
    b->walk = (uint32_t)_mm256_movemask_ps(walk);
    { /* lrt__start_node */
        const __m256 lim[2] = {_mm256_set1_ps((float)(L->width - 1u)), _mm256_set1_ps((float)(L->height - 1u))};
        __m256 column = _mm256_and_ps(_mm256_cmp_ps(v[0], zero, _CMP_EQ_OQ), _mm256_cmp_ps(v[1], zero, _CMP_EQ_OQ));
        for (k = 0; k < 2; ++k) {
            const __m256 a = _mm256_add_ps(o[k], _mm256_mul_ps(t_lo, v[k])), c = _mm256_add_ps(o[k], _mm256_mul_ps(t_hi, v[k]));
            const __m256 size = _mm256_add_ps(_mm256_add_ps(_mm256_andnot_ps(sign, o[k]), _mm256_andnot_ps(sign, _mm256_sub_ps(a, o[k]))),
                                              _mm256_andnot_ps(sign, _mm256_sub_ps(c, o[k])));
            const __m256 mg = _mm256_add_ps(_mm256_set1_ps(1e-3f), _mm256_mul_ps(_mm256_set1_ps(1e-5f), size));
            const __m256i within = _mm256_cvttps_epi32(o[k]);
            __m256 lo = _mm256_sub_ps(_mm256_min_ps(a, c), mg), hi = _mm256_add_ps(_mm256_max_ps(c, a), mg);
            lo = _mm256_min_ps(_mm256_max_ps(lo, zero), lim[k]);
            hi = _mm256_max_ps(_mm256_min_ps(hi, lim[k]), zero);
            column = _mm256_and_ps(column, _mm256_cmp_ps(_mm256_cvtepi32_ps(within), o[k], _CMP_NEQ_UQ));
            _mm256_storeu_si256((__m256i *)(void *)b->i0[k], _mm256_cvttps_epi32(lo));
            _mm256_storeu_si256((__m256i *)(void *)b->i1[k], _mm256_cvttps_epi32(hi));
        }
        b->column = (uint32_t)_mm256_movemask_ps(column);
    }
    { /* lrt__cull_constants */
        __m256 zb_enter, zb_exit, ivz;
        for (k = 0; k < 2; ++k)
            lrt__cull_axis8(o[k], iv[k], w->extent[k], t_hi, b->cull[LRT__CULL_IV_X + k], b->cull[LRT__CULL_ENTER_X + k],
                            b->cull[LRT__CULL_EXIT_X + k]);
        lrt__cull_axis8(_mm256_sub_ps(o[2], _mm256_set1_ps(w->code_depth0)), iv[2], 1.0f, t_hi, b->cull[LRT__CULL_ZA],
                        b->cull[LRT__CULL_ZB], b->cull[LRT__CULL_HI]);
        ivz = _mm256_loadu_ps(b->cull[LRT__CULL_ZA]);
        zb_enter = _mm256_loadu_ps(b->cull[LRT__CULL_ZB]);
        zb_exit = _mm256_loadu_ps(b->cull[LRT__CULL_HI]);
        _mm256_storeu_ps(b->cull[LRT__CULL_ZA], _mm256_mul_ps(_mm256_set1_ps(w->code_step), ivz));
        _mm256_storeu_ps(b->cull[LRT__CULL_ZB], _mm256_blendv_ps(zb_enter, zb_exit, neg[2]));
        if (w->back_codes) { /* the back plane: enters going up, leaves going down */
            float exits[8];
            lrt__cull_axis8(o[2], iv[2], 1.0f, t_hi, b->cull[LRT__CULL_BA], b->cull[LRT__CULL_BB], exits);
            _mm256_storeu_ps(b->cull[LRT__CULL_BA],
                             _mm256_mul_ps(_mm256_set1_ps(w->back_scale), _mm256_loadu_ps(b->cull[LRT__CULL_BA])));
            _mm256_storeu_ps(b->cull[LRT__CULL_BB],
                             _mm256_blendv_ps(_mm256_loadu_ps(exits), _mm256_loadu_ps(b->cull[LRT__CULL_BB]), neg[2]));
        }
        { /* lrt__widen(t_hi) */
            const __m256 grown = _mm256_add_ps(t_hi, _mm256_mul_ps(_mm256_andnot_ps(sign, t_hi), _mm256_set1_ps(LRT__WIDEN_EXIT)));
            _mm256_storeu_ps(b->cull[LRT__CULL_HI],
                             _mm256_blendv_ps(t_hi, grown, _mm256_cmp_ps(grown, _mm256_set1_ps(3.40282347e38f), _CMP_LE_OQ)));
        }
    }
    for (k = 0; k < 3; ++k) {
        _mm256_storeu_ps(b->o[k], o[k]);
        _mm256_storeu_ps(b->v[k], v[k]);
        _mm256_storeu_ps(b->iv[k], iv[k]);
    }
    _mm256_storeu_ps(b->t_lo, t_lo);
    _mm256_storeu_ps(b->t_hi, t_hi);
}

/* 8 rays: set up together, then walked one by one. */
LRT__FORCE_INLINE void lrt__trace8(const lrt__walk *w, const lrt_ray *rays, lrt_hit *hits)
{
    lrt__batch8 b;
    uint32_t j;
    lrt__setup8(w, rays, &b);
    for (j = 0; j < 8u; ++j) {
        lrt__ray_setup s;
        lrt_hit *hit = &hits[j];
        uint32_t k, lv, nx, ny, px, py;
        if ((b.one_by_one >> j) & 1u) {
            lrt__trace_one(w, &rays[j], hit);
            continue;
        }
        hit->t = 0.0f;
        hit->x = hit->y = 0;
        hit->face = LRT_FACE_NONE;
        if (!((b.walk >> j) & 1u)) {
            hit->kind = (uint16_t)b.kind[j];
            continue;
        }
        for (k = 0; k < 3u; ++k) {
            s.o[k] = b.o[k][j];
            s.v[k] = b.v[k][j];
            s.iv[k] = b.iv[k][j];
        }
        s.neg_x = lrt__sign_bit(s.v[0]);
        s.neg_y = lrt__sign_bit(s.v[1]);
        s.neg_z = lrt__sign_bit(s.v[2]);
        s.t_lo = b.t_lo[j];
        s.t_hi = b.t_hi[j];
        s.t_base = 0.0f;
        s.zk = 0;
        if ((b.column >> j) & 1u) { /* lrt__start_node's camera ray */
            lv = 0;
            nx = px = (uint32_t)(int32_t)s.o[0];
            ny = py = (uint32_t)(int32_t)s.o[1];
        } else {
            const uint32_t i0[2] = {b.i0[0][j], b.i0[1][j]}, i1[2] = {b.i1[0][j], b.i1[1][j]};
            lv = lrt__start_level(w, i0, i1, s.neg_x, s.neg_y, &nx, &ny, &px, &py);
        }
        lrt__trace_from(w, &rays[j], hit, &s, (b.huge >> j) & 1 ? b.t_scale[j] : 1.0f, b.kind[j], lv, nx, ny, px, py,
                        &b.cull[0][j], 8);
    }
}

/* Rays first..end in batches of 8 (returns the first ray left over). */
LRT__FORCE_INLINE size_t lrt__trace_batches(const lrt__walk *w, const lrt_ray *rays, lrt_hit *hits, size_t first, size_t end)
{
    for (; end - first >= 8u; first += 8) lrt__trace8(w, rays + first, hits + first);
    return first;
}
#else
#define lrt__trace_batches(w, rays, hits, first, end) (first) /* none: every ray alone (lrt__trace_one) */
#endif

/* The walk of lrt_trace_range once its arguments are checked. */
static void lrt__trace_walk(const lrt_bvh *bvh, const lrt_depth *depth, size_t stride, const lrt_ray *rays,
                            lrt_hit *hits, size_t first, size_t end, uint32_t flags)
{
    lrt__walk w;
    size_t i;
    lrt__walk_init(&w, bvh, depth, stride);
    w.budget = flags & LRT_K_TRACE_BUDGET_MASK;
    w.finish = (flags & LRT_K_TRACE_FINISH_MASK) >> LRT_K_TRACE_FINISH_SHIFT;
    for (i = lrt__trace_batches(&w, rays, hits, first, end); i < end; ++i) lrt__trace_one(&w, &rays[i], &hits[i]);
}

/* the macros whose text differs between the passes */
#undef LRT__BROADCAST
#undef LRT__LANE
#if !LRT__AVX
#undef lrt__trace_batches
#endif
#ifdef LRT__EXACT_MADD8
#undef LRT__EXACT_MADD8
#endif

#ifndef LRT__AVX2_PASS
/* ================================================================= >>trace
   The CPU entry points of section api: lrt_cpu_path, lrt_trace_range and
   lrt_trace check their arguments, pick the walk (this pass's, or the AVX2
   pass's where the CPU has it) and hand it the batch. Compiled once.
   ========================================================================== */
/* The AVX2 walk, compiled at the end of this file (section walk-avx2),
   picked by lrt__cpu_has_avx2 (section impl). */
#if LRT__AVX_AT_RUN_TIME
static void lrt__trace_walk_avx2(const lrt_bvh *bvh, const lrt_depth *depth, size_t stride, const lrt_ray *rays,
                                 lrt_hit *hits, size_t first, size_t end, uint32_t flags);
#endif /* LRT__AVX_AT_RUN_TIME */

LINEAR_RT_DEF const char *lrt_cpu_path(void)
{
#if LRT__AVX_AT_RUN_TIME
    return lrt__cpu_has_avx2() ? "avx2 (chosen at run time)" : "sse2 (chosen at run time)";
#elif LRT__AVX_BUILT
    return "avx2";
#elif LRT__SSE
    return "sse2";
#else
    return "scalar";
#endif
}

/* Trace flags a call takes (lrt_trace, lrt_vk_cmd_trace): a budget, and a
   finish (2^0 to 2^7 samples) only with one. */
static int lrt__trace_flags_ok(uint32_t flags)
{
    const uint32_t finish = (flags & LRT_K_TRACE_FINISH_MASK) >> LRT_K_TRACE_FINISH_SHIFT;
    return !(flags & ~(LRT_K_TRACE_BUDGET_MASK | LRT_K_TRACE_FINISH_MASK)) && finish <= LRT_K_FINISH_MAX &&
           (!finish || (flags & LRT_K_TRACE_BUDGET_MASK));
}

LINEAR_RT_DEF lrt_result lrt_trace_range(const lrt_bvh *bvh, const lrt_depth *depth, const lrt_ray *rays,
                                         lrt_hit *hits, size_t first, size_t end, uint32_t flags)
{
    size_t stride;
    lrt_result r;
    if ((r = lrt__check_pair(bvh, depth, &stride)) != LRT_SUCCESS) return r;
    if (!lrt__trace_flags_ok(flags)) return LRT_ERROR_INVALID_OPTION;
    if (first > end || end - first > LINEAR_RT_MAX_RAYS_PER_CALL) return LRT_ERROR_TOO_MANY_RAYS;
    if (first == end) return LRT_SUCCESS;
    if (!rays || !hits) return LRT_ERROR_NULL_POINTER;
#if LRT__AVX_AT_RUN_TIME
    if (lrt__cpu_has_avx2()) {
        lrt__trace_walk_avx2(bvh, depth, stride, rays, hits, first, end, flags);
        return LRT_SUCCESS;
    }
#endif
    lrt__trace_walk(bvh, depth, stride, rays, hits, first, end, flags);
    return LRT_SUCCESS;
}

LINEAR_RT_DEF lrt_result lrt_trace(const lrt_bvh *bvh, const lrt_depth *depth, const lrt_ray *rays, lrt_hit *hits,
                                   size_t count, uint32_t flags)
{
    return lrt_trace_range(bvh, depth, rays, hits, 0, count, flags);
}

#ifdef LRT__WALK_TUNED
#pragma GCC pop_options
#undef LRT__WALK_TUNED
#endif
/* ================================================================ >>camera
   6. Rays from a camera: view space -> clip space -> screen space. Optional
      helpers for the ray set-up (the tracer never calls them). Double
      precision throughout: the matrices of a far plane at 1e4 are badly
      conditioned in float, and this runs once per ray, not per node.
   ========================================================================== */
LINEAR_RT_DEF lrt_result lrt_perspective(float out[16], float fov_y_radians, float aspect, float near_z, float far_z,
                                         uint32_t flags)
{
    const double fov = fov_y_radians, a = aspect, n = near_z, fa = far_z, pi = 3.14159265358979323846;
    const int infinite = fa == (double)INFINITY;
    double f, m[16];
    int k;
    if (!out) return LRT_ERROR_NULL_POINTER;
    if (flags & ~(uint32_t)LRT_DEPTH_REVERSED_Z) return LRT_ERROR_INVALID_OPTION;
    /* NaN fails every compare; a near plane of a subnormal is no plane in float */
    if (!(fov > 0.0 && fov < pi && a > 0.0 && a <= 3.0e38 && n >= 1.17549435e-38 && n <= 3.0e38 && fa > n) ||
        (!infinite && (float)n >= (float)fa))
        return LRT_ERROR_INVALID_CAMERA;
    f = 1.0 / tan(0.5 * fov);
    for (k = 0; k < 16; ++k) m[k] = 0.0;
    m[0] = f / a;
    m[5] = -f;   /* y up in view space, row 0 at the top of the image */
    m[11] = -1.0; /* w = -z: the distance in front of the eye */
    if (flags & LRT_DEPTH_REVERSED_Z) {
        m[10] = infinite ? 0.0 : n / (fa - n);
        m[14] = infinite ? n : n * fa / (fa - n);
    } else {
        m[10] = infinite ? -1.0 : fa / (n - fa);
        m[14] = infinite ? -n : n * fa / (n - fa);
    }
    for (k = 0; k < 16; ++k)
        if (!(fabs(m[k]) <= 3.0e38)) return LRT_ERROR_INVALID_CAMERA; /* an aspect or fov that overflows float */
    for (k = 0; k < 16; ++k) out[k] = (float)m[k];
    return LRT_SUCCESS;
}

/* Inverse by cofactors; 0 when singular (relative to the matrix's scale) or
   not finite. */
static int lrt__invert4(const float *m, float *out)
{
    double a[16], inv[16], det, scale = 0.0;
    int k;
    for (k = 0; k < 16; ++k) {
        a[k] = m[k];
        if (!(a[k] - a[k] == 0.0)) return 0;
        scale = fabs(a[k]) > scale ? fabs(a[k]) : scale;
    }
    inv[0] = a[5] * a[10] * a[15] - a[5] * a[11] * a[14] - a[9] * a[6] * a[15] + a[9] * a[7] * a[14] + a[13] * a[6] * a[11] - a[13] * a[7] * a[10];
    inv[4] = -a[4] * a[10] * a[15] + a[4] * a[11] * a[14] + a[8] * a[6] * a[15] - a[8] * a[7] * a[14] - a[12] * a[6] * a[11] + a[12] * a[7] * a[10];
    inv[8] = a[4] * a[9] * a[15] - a[4] * a[11] * a[13] - a[8] * a[5] * a[15] + a[8] * a[7] * a[13] + a[12] * a[5] * a[11] - a[12] * a[7] * a[9];
    inv[12] = -a[4] * a[9] * a[14] + a[4] * a[10] * a[13] + a[8] * a[5] * a[14] - a[8] * a[6] * a[13] - a[12] * a[5] * a[10] + a[12] * a[6] * a[9];
    inv[1] = -a[1] * a[10] * a[15] + a[1] * a[11] * a[14] + a[9] * a[2] * a[15] - a[9] * a[3] * a[14] - a[13] * a[2] * a[11] + a[13] * a[3] * a[10];
    inv[5] = a[0] * a[10] * a[15] - a[0] * a[11] * a[14] - a[8] * a[2] * a[15] + a[8] * a[3] * a[14] + a[12] * a[2] * a[11] - a[12] * a[3] * a[10];
    inv[9] = -a[0] * a[9] * a[15] + a[0] * a[11] * a[13] + a[8] * a[1] * a[15] - a[8] * a[3] * a[13] - a[12] * a[1] * a[11] + a[12] * a[3] * a[9];
    inv[13] = a[0] * a[9] * a[14] - a[0] * a[10] * a[13] - a[8] * a[1] * a[14] + a[8] * a[2] * a[13] + a[12] * a[1] * a[10] - a[12] * a[2] * a[9];
    inv[2] = a[1] * a[6] * a[15] - a[1] * a[7] * a[14] - a[5] * a[2] * a[15] + a[5] * a[3] * a[14] + a[13] * a[2] * a[7] - a[13] * a[3] * a[6];
    inv[6] = -a[0] * a[6] * a[15] + a[0] * a[7] * a[14] + a[4] * a[2] * a[15] - a[4] * a[3] * a[14] - a[12] * a[2] * a[7] + a[12] * a[3] * a[6];
    inv[10] = a[0] * a[5] * a[15] - a[0] * a[7] * a[13] - a[4] * a[1] * a[15] + a[4] * a[3] * a[13] + a[12] * a[1] * a[7] - a[12] * a[3] * a[5];
    inv[14] = -a[0] * a[5] * a[14] + a[0] * a[6] * a[13] + a[4] * a[1] * a[14] - a[4] * a[2] * a[13] - a[12] * a[1] * a[6] + a[12] * a[2] * a[5];
    inv[3] = -a[1] * a[6] * a[11] + a[1] * a[7] * a[10] + a[5] * a[2] * a[11] - a[5] * a[3] * a[10] - a[9] * a[2] * a[7] + a[9] * a[3] * a[6];
    inv[7] = a[0] * a[6] * a[11] - a[0] * a[7] * a[10] - a[4] * a[2] * a[11] + a[4] * a[3] * a[10] + a[8] * a[2] * a[7] - a[8] * a[3] * a[6];
    inv[11] = -a[0] * a[5] * a[11] + a[0] * a[7] * a[9] + a[4] * a[1] * a[11] - a[4] * a[3] * a[9] - a[8] * a[1] * a[7] + a[8] * a[3] * a[5];
    inv[15] = a[0] * a[5] * a[10] - a[0] * a[6] * a[9] - a[4] * a[1] * a[10] + a[4] * a[2] * a[9] + a[8] * a[1] * a[6] - a[8] * a[2] * a[5];
    det = a[0] * inv[0] + a[1] * inv[4] + a[2] * inv[8] + a[3] * inv[12];
    /* a 4x4 determinant scales as scale^4: below 1e-12 of that is singular for float input */
    if (!(fabs(det) > 1e-12 * scale * scale * scale * scale)) return 0;
    for (k = 0; k < 16; ++k) {
        double v = inv[k] / det;
        if (!(fabs(v) <= 3.0e38)) return 0;
        out[k] = (float)v;
    }
    return 1;
}

/* w = -c z_view (c > 0) and nothing else in w, nor in z from x and y */
static int lrt__is_perspective(const float *m)
{
    return m[3] == 0.0f && m[7] == 0.0f && m[15] == 0.0f && m[11] < 0.0f && m[2] == 0.0f && m[6] == 0.0f;
}

LINEAR_RT_DEF lrt_result lrt_camera_init(lrt_camera *camera, const float projection[16], uint32_t width,
                                         uint32_t height, uint32_t flags)
{
    lrt_camera c;
    float near_z, far_z;
    int k;
    if (!camera || !projection) return LRT_ERROR_NULL_POINTER;
    if (width == 0 || height == 0 || width > LINEAR_RT_MAX_DIM || height > LINEAR_RT_MAX_DIM) return LRT_ERROR_INVALID_SIZE;
    if (flags & ~(uint32_t)LRT_DEPTH_REVERSED_Z) return LRT_ERROR_INVALID_OPTION;
    for (k = 0; k < 16; ++k) c.proj[k] = projection[k];
    if (!lrt__invert4(c.proj, c.inv_proj)) return LRT_ERROR_INVALID_CAMERA;
    c.width = width;
    c.height = height;
    c.flags = flags;
    if (lrt__is_perspective(c.proj) && !lrt_camera_planes(&c, &near_z, &far_z)) return LRT_ERROR_INVALID_CAMERA;
    *camera = c;
    return LRT_SUCCESS;
}

/* clip = m * (p, 1), column-major */
static void lrt__transform(const float *m, const double p[4], double out[4])
{
    int r;
    for (r = 0; r < 4; ++r)
        out[r] = (double)m[r] * p[0] + (double)m[4 + r] * p[1] + (double)m[8 + r] * p[2] + (double)m[12 + r] * p[3];
}

/* Screen point of a clip-space point with w > 0; 0 if not finite in float. */
static int lrt__clip_to_screen(const lrt_camera *c, const double clip[4], float screen[3])
{
    double x = (clip[0] / clip[3] + 1.0) * 0.5 * (double)c->width;
    double y = (clip[1] / clip[3] + 1.0) * 0.5 * (double)c->height;
    double z = clip[2] / clip[3];
    if (c->flags & LRT_DEPTH_REVERSED_Z) z = 1.0 - z;
    if (!(fabs(x) <= 3.0e38 && fabs(y) <= 3.0e38 && fabs(z) <= 3.0e38)) return 0;
    screen[0] = (float)x;
    screen[1] = (float)y;
    screen[2] = (float)z;
    return 1;
}

LINEAR_RT_DEF int lrt_camera_unproject(const lrt_camera *camera, const float screen[3], float view[3])
{
    double ndc[4], p[4];
    int k;
    if (!camera || !screen || !view) return 0;
    ndc[0] = 2.0 * (double)screen[0] / (double)camera->width - 1.0;
    ndc[1] = 2.0 * (double)screen[1] / (double)camera->height - 1.0;
    ndc[2] = (camera->flags & LRT_DEPTH_REVERSED_Z) ? 1.0 - (double)screen[2] : (double)screen[2];
    ndc[3] = 1.0;
    lrt__transform(camera->inv_proj, ndc, p);
    if (!(p[3] != 0.0)) return 0;
    for (k = 0; k < 3; ++k) {
        double v = p[k] / p[3];
        if (!(fabs(v) <= 3.0e38)) return 0;
        view[k] = (float)v;
    }
    return 1;
}

LINEAR_RT_DEF int lrt_camera_project(const lrt_camera *camera, const float view[3], float screen[3])
{
    double p[4], clip[4];
    if (!camera || !view || !screen) return 0;
    p[0] = view[0];
    p[1] = view[1];
    p[2] = view[2];
    p[3] = 1.0;
    lrt__transform(camera->proj, p, clip);
    if (!(clip[3] > 0.0)) return 0;
    return lrt__clip_to_screen(camera, clip, screen);
}

LINEAR_RT_DEF int lrt_camera_segment(const lrt_camera *camera, const float from[3], const float to[3], lrt_ray *ray)
{
    double a[4], b[4], ca[4], cb[4], s0 = 0.0, s1 = 1.0, fa[3], fb[3], pa[4], pb[4];
    float sa[3], sb[3];
    int k;
    if (!ray) return 0;
    for (k = 0; k < 3; ++k) ray->origin[k] = ray->dir[k] = NAN;
    ray->tmin = 0.0f;
    ray->tmax = 1.0f;
    if (!camera || !from || !to) return 0;
    for (k = 0; k < 3; ++k) {
        a[k] = from[k];
        b[k] = to[k];
        if (!(a[k] - a[k] == 0.0 && b[k] - b[k] == 0.0)) return 0;
    }
    a[3] = b[3] = 1.0;
    lrt__transform(camera->proj, a, ca);
    lrt__transform(camera->proj, b, cb);
    /* clip space is linear along the segment: keep s where z >= 0, w - z >= 0
       (between the planes) and w > 0 (in front of the eye) */
    fa[0] = ca[2];         fb[0] = cb[2];
    fa[1] = ca[3] - ca[2]; fb[1] = cb[3] - cb[2];
    fa[2] = ca[3];         fb[2] = cb[3];
    for (k = 0; k < 3; ++k) {
        if (fa[k] < 0.0 && fb[k] < 0.0) return 0;
        if (fa[k] < 0.0) { double s = fa[k] / (fa[k] - fb[k]); s0 = s > s0 ? s : s0; }
        else if (fb[k] < 0.0) { double s = fa[k] / (fa[k] - fb[k]); s1 = s < s1 ? s : s1; }
    }
    if (!(s0 <= s1)) return 0;
    for (k = 0; k < 4; ++k) {
        pa[k] = ca[k] + s0 * (cb[k] - ca[k]);
        pb[k] = ca[k] + s1 * (cb[k] - ca[k]);
    }
    if (!(pa[3] > 0.0 && pb[3] > 0.0)) return 0; /* touches the eye (w = 0) only */
    if (!lrt__clip_to_screen(camera, pa, sa) || !lrt__clip_to_screen(camera, pb, sb)) return 0;
    for (k = 0; k < 3; ++k) {
        ray->origin[k] = sa[k];
        ray->dir[k] = sb[k] - sa[k];
    }
    return 1;
}

LINEAR_RT_DEF float lrt_surface_lift(float step_x, float step_y)
{
    return 0.5f * (fabsf(step_x) + fabsf(step_y)) * 1.01f + 1e-7f;
}

/* The screen depth where the line of sight through screen point (sx, sy)
   meets the plane through `point` with normal `normal`; 0 when it does not
   (parallel, or a point the camera cannot unproject). */
static int lrt__plane_depth(const lrt_camera *camera, const float point[3], const float normal[3], float sx, float sy,
                            double *depth)
{
    const float s0[3] = {sx, sy, 0.25f}, s1[3] = {sx, sy, 0.75f};
    float a[3], b[3], q[3], out[3];
    double nd = 0.0, nq = 0.0, t;
    int k;
    if (!lrt_camera_unproject(camera, s0, a) || !lrt_camera_unproject(camera, s1, b)) return 0;
    for (k = 0; k < 3; ++k) {
        nd += (double)normal[k] * ((double)b[k] - a[k]);
        nq += (double)normal[k] * ((double)point[k] - a[k]);
    }
    if (nd == 0.0) return 0;
    t = nq / nd;
    for (k = 0; k < 3; ++k) q[k] = (float)(a[k] + t * ((double)b[k] - a[k]));
    if (!lrt_camera_project(camera, q, out)) return 0;
    *depth = out[2];
    return 1;
}

/* The ray starts at its texel's centre, on the texel's flat top. The
   texel tops around stand at most half the true surface's slope above it
   where the surface is convex or flat, and the ray stays above the tangent
   plane of a true normal: so the slope of that plane lifts too, when the
   steps (secants) say less, as at a curved surface's edge. Lifted by
   `lift`, the ray must still clear its own top until it leaves the texel:
   one that goes away from the eye (dir z > 0) sinks by dir z * t_out there,
   t_out the t where it crosses the texel's first side; so the lift is at
   least that, 1% and a hair more. A ray whose end is on the far plane is
   lengthened along its line to reach it again: it is lifted by the same
   amount all along, and still ends at depth 1. */
LINEAR_RT_DEF int lrt_camera_surface_ray(const lrt_camera *camera, const float from[3], const float normal[3],
                                         const float to[3], float lift, lrt_ray *ray)
{
    double t_out = INFINITY, need, d[4];
    int k, to_far;
    if (!lrt_camera_segment(camera, from, to, ray)) return 0;
    if (normal && lift > 0.0f && lrt__plane_depth(camera, from, normal, ray->origin[0] + 0.5f, ray->origin[1], &d[0]) &&
        lrt__plane_depth(camera, from, normal, ray->origin[0] - 0.5f, ray->origin[1], &d[1]) &&
        lrt__plane_depth(camera, from, normal, ray->origin[0], ray->origin[1] + 0.5f, &d[2]) &&
        lrt__plane_depth(camera, from, normal, ray->origin[0], ray->origin[1] - 0.5f, &d[3])) {
        need = 0.5 * (fabs(d[0] - d[1]) + fabs(d[2] - d[3])) * 1.01 + 1e-7;
        if (need > 8.0 * lift) need = 8.0 * lift;
        if (need > (double)lift) lift = (float)need;
    }
    for (k = 0; k < 2; ++k) { /* where the ray leaves the origin's texel */
        const double o = ray->origin[k], v = ray->dir[k], cell = floor(o);
        const double t = v > 0.0 ? (cell + 1.0 - o) / v : v < 0.0 ? (cell - o) / v : INFINITY;
        if (t < t_out) t_out = t;
    }
    to_far = ray->origin[2] + ray->dir[2] >= 1.0f && ray->dir[2] > 0.0f;
    if (ray->dir[2] > 0.0f && (t_out < 1.0 || (to_far && t_out < INFINITY))) {
        need = (double)ray->dir[2] * t_out * 1.01 + 1e-7;
        if (need > (double)lift) lift = (float)need;
    }
    ray->origin[2] -= lift;
    if (to_far) { /* the same line, lengthened to reach the far plane again */
        const float s = 1.0f + lift / ray->dir[2];
        for (k = 0; k < 3; ++k) ray->dir[k] *= s;
    }
    return 1;
}

/* Clip z = A zv + B and w = -c zv (view space looks down -z): depth
   (A zv + B) / (-c zv) is 0 at zv = -near and 1 at zv = -far, so
   near = B / A and far = B / (A + c), infinite when A = -c; reversed Z
   stores 1 - that depth, so A and B come back as -c - A and -B. */
LINEAR_RT_DEF int lrt_camera_planes(const lrt_camera *camera, float *near_z, float *far_z)
{
    const float *m;
    double c, a, b, n, f;
    if (!camera || !near_z || !far_z) return 0;
    m = camera->proj;
    if (!lrt__is_perspective(m)) return 0;
    c = -(double)m[11];
    a = m[10];
    b = m[14];
    if (camera->flags & LRT_DEPTH_REVERSED_Z) {
        a = -c - a;
        b = -b;
    }
    if (a == 0.0) return 0;
    n = b / a;
    f = a + c == 0.0 ? INFINITY : b / (a + c);
    if (!(n > 0.0 && n <= 3.0e38 && f > n) || (float)n >= (float)f) return 0;
    *near_z = (float)n;
    *far_z = f > 3.0e38 ? INFINITY : (float)f;
    return 1;
}

#ifdef __cplusplus
}
#endif
#endif /* !LRT__AVX2_PASS */
#endif /* LINEAR_RT_IMPLEMENTATION_DONE */

/* ================================================================ >>vulkan
   7. Vulkan: the kernels of shaders/ (BuildBVH and UpdateBVH in one refit
      kernel, the traversal in another), recorded into the caller's command
      buffers inside the caller's device. Host and kernels agree on
      shaders/README.md: bindings, push constants, dispatch shape.
   ========================================================================== */
#if defined(LINEAR_RT_VULKAN) && !defined(LINEAR_RT_VULKAN_IMPLEMENTATION_DONE) && !defined(LRT__AVX2_PASS)
#define LINEAR_RT_VULKAN_IMPLEMENTATION_DONE

#include "shaders_spv.h" /* lrt_spv_{refit,trace}_{buffer,image}: make spv */

#ifdef __cplusplus
extern "C" {
#endif

/* ---- which device features the SPIR-V asks for --------------------------- */

enum { LRT__SPV_CAPABILITY = 17 }; /* OpCapability */

static void lrt__spv_requirements(const uint32_t *words, size_t count, lrt_vk_requirements *req)
{
    size_t i = 5; /* after the header */
    while (i < count) {
        uint32_t n = words[i] >> 16, op = words[i] & 0xffffu;
        if (n == 0) break;
        if (op == LRT__SPV_CAPABILITY && n >= 2 && i + 1 < count) {
            switch (words[i + 1]) {
            case 9: req->shader_float16 = VK_TRUE; break;
            case 10: req->shader_float64 = VK_TRUE; break;
            case 11: req->shader_int64 = VK_TRUE; break;
            case 12: req->shader_buffer_int64_atomics = VK_TRUE; break;
            case 22: req->shader_int16 = VK_TRUE; break;
            case 39: req->shader_int8 = VK_TRUE; break;
            case 61: req->subgroup_operations |= VK_SUBGROUP_FEATURE_BASIC_BIT; break;
            case 62: req->subgroup_operations |= VK_SUBGROUP_FEATURE_VOTE_BIT; break;
            case 63: req->subgroup_operations |= VK_SUBGROUP_FEATURE_ARITHMETIC_BIT; break;
            case 64: req->subgroup_operations |= VK_SUBGROUP_FEATURE_BALLOT_BIT; break;
            case 65: req->subgroup_operations |= VK_SUBGROUP_FEATURE_SHUFFLE_BIT; break;
            case 66: req->subgroup_operations |= VK_SUBGROUP_FEATURE_SHUFFLE_RELATIVE_BIT; break;
            case 67: req->subgroup_operations |= VK_SUBGROUP_FEATURE_CLUSTERED_BIT; break;
            case 68: req->subgroup_operations |= VK_SUBGROUP_FEATURE_QUAD_BIT; break;
            case 4433: req->storage_buffer_16bit_access = VK_TRUE; break;
            case 4448: req->storage_buffer_8bit_access = VK_TRUE; break;
            case 5345: req->vulkan_memory_model = VK_TRUE; break;
            case 5346: req->vulkan_memory_model_device_scope = VK_TRUE; break;
            default: break; /* core in Vulkan 1.2 compute */
            }
        }
        i += n;
    }
}

typedef struct lrt__vk_module {
    const uint32_t *code;
    size_t bytes;
} lrt__vk_module;

/* The pipelines, in this order. */
/* the four kernels (a trace: its ordinary pass), the trace kernel's rare
   pass (specialization constant 3, lrt_trace_pass, 1), its one pass (2)
   and its ordinary pass with a step budget (3: the exact ordinary pass
   carries no step count), then the same for trees with a thickness
   model, of 16-bit nodes, then of 8-bit nodes (constant 0, lrt_back_trees,
   true: other trees' pipelines carry no back code; constant 1,
   lrt_back_node_bits, the node width: known to the compiler, it drops the
   other width's code from the back-code reads); last a compacted trace's
   round (4), for infinite trees alone: the cell walk's */
enum { LRT__VK_REFIT_BUFFER, LRT__VK_REFIT_IMAGE, LRT__VK_TRACE_BUFFER, LRT__VK_TRACE_IMAGE, LRT__VK_RARE_BUFFER,
       LRT__VK_RARE_IMAGE, LRT__VK_WHOLE_BUFFER, LRT__VK_WHOLE_IMAGE, LRT__VK_BUDGET_BUFFER, LRT__VK_BUDGET_IMAGE,
       LRT__VK_MODULES,
       LRT__VK_ROUND_BUFFER = 3 * LRT__VK_MODULES, LRT__VK_ROUND_IMAGE,
       LRT__VK_PIPELINES };

/* Pipelines are made on first use, not by lrt_vk_context_create: a
   program pays only for the kernels its trees and maps take (llvmpipe
   compiles each trace pipeline for about half a second). Threads record
   with one context at once, so a pipeline is published with an atomic
   compare-and-swap, and a thread that loses the race destroys its own.
   Without GCC's atomic builtins (GCC, Clang) create makes them all. */
#if defined(__GNUC__) || defined(__clang__)
#define LRT__VK_LAZY 1
#else
#define LRT__VK_LAZY 0
#endif

/* The trace modules. tests/test_vulkan.c built as
   test_vulkan_hlsl defines these before the implementation: the same kernel
   compiled from HLSL (tests/hlsl/lrt_trace.hlsl over shaders/linear_rt.hlsl),
   run in its place through every test. */
#ifndef LRT__VK_TRACE_BUFFER_SPV
#define LRT__VK_TRACE_BUFFER_SPV lrt_spv_trace_buffer
#define LRT__VK_TRACE_BUFFER_SPV_SIZE lrt_spv_trace_buffer_SIZE
#endif
#ifndef LRT__VK_TRACE_IMAGE_SPV
#define LRT__VK_TRACE_IMAGE_SPV lrt_spv_trace_image
#define LRT__VK_TRACE_IMAGE_SPV_SIZE lrt_spv_trace_image_SIZE
#endif

static lrt__vk_module lrt__vk_module_at(int which)
{
    lrt__vk_module m;
    switch (which) {
    case LRT__VK_REFIT_BUFFER: m.code = lrt_spv_refit_buffer; m.bytes = lrt_spv_refit_buffer_SIZE; break;
    case LRT__VK_REFIT_IMAGE: m.code = lrt_spv_refit_image; m.bytes = lrt_spv_refit_image_SIZE; break;
    case LRT__VK_TRACE_BUFFER:
    case LRT__VK_RARE_BUFFER:
    case LRT__VK_BUDGET_BUFFER:
    case LRT__VK_WHOLE_BUFFER: m.code = LRT__VK_TRACE_BUFFER_SPV; m.bytes = LRT__VK_TRACE_BUFFER_SPV_SIZE; break;
    default: m.code = LRT__VK_TRACE_IMAGE_SPV; m.bytes = LRT__VK_TRACE_IMAGE_SPV_SIZE; break;
    }
    return m;
}

LINEAR_RT_DEF lrt_result lrt_vk_get_requirements(lrt_vk_requirements *out)
{
    lrt_vk_requirements req;
    int k;
    if (!out) return LRT_ERROR_NULL_POINTER;
    memset(&req, 0, sizeof req);
    req.api_version = VK_API_VERSION_1_2;
    req.extension_count = 1;
    req.extensions[0] = VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME;
    for (k = 0; k < LRT__VK_MODULES; ++k) {
        lrt__vk_module m = lrt__vk_module_at(k);
        lrt__spv_requirements(m.code, m.bytes / 4u, &req);
    }
    *out = req;
    return LRT_SUCCESS;
}

/* ---- the context ------------------------------------------------------------- */

/* Every Vulkan function the library calls, loaded from the caller's getters. */
#define LRT__VK_INSTANCE_FUNCS(X)                                                                                 \
    X(vkGetPhysicalDeviceProperties)                                                                              \
    X(vkGetPhysicalDeviceProperties2)                                                                             \
    X(vkGetPhysicalDeviceFeatures2)                                                                               \
    X(vkGetPhysicalDeviceMemoryProperties)                                                                        \
    X(vkEnumerateDeviceExtensionProperties)
#define LRT__VK_DEVICE_FUNCS(X)                                                                                   \
    X(vkCreateShaderModule) X(vkDestroyShaderModule) X(vkCreateDescriptorSetLayout)                              \
    X(vkDestroyDescriptorSetLayout) X(vkCreatePipelineLayout) X(vkDestroyPipelineLayout)                         \
    X(vkCreateComputePipelines) X(vkDestroyPipeline) X(vkCreateSampler) X(vkDestroySampler) X(vkCreateBuffer)   \
    X(vkDestroyBuffer) X(vkCreateBufferView) X(vkDestroyBufferView) X(vkGetBufferMemoryRequirements)            \
    X(vkAllocateMemory) X(vkFreeMemory) X(vkBindBufferMemory) X(vkMapMemory) X(vkUnmapMemory)                    \
    X(vkCmdBindPipeline) X(vkCmdPushDescriptorSetKHR) X(vkCmdPushConstants) X(vkCmdDispatch) X(vkCmdFillBuffer)  \
    X(vkCmdPipelineBarrier) X(vkCmdDispatchIndirect) X(vkCmdUpdateBuffer)

struct lrt_vk_context {
    VkDevice device;
    VkPhysicalDevice physical_device;
    VkAllocationCallbacks allocation_callbacks;
    const VkAllocationCallbacks *callbacks; /* &allocation_callbacks or NULL */
    VkResult vk_result;
    VkPhysicalDeviceLimits limits;
    VkPhysicalDeviceMemoryProperties memory_properties;
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout pipeline_layout;
    VkSampler sampler;
    VkPipeline pipelines[LRT__VK_PIPELINES]; /* made on first use where LRT__VK_LAZY (lrt__vk_pipeline) */
    VkPipelineCache cache;                   /* the desc's, for them */
    uint32_t float_modes; /* LRT__VK_FLOAT_*: what lrt__vk_float_controls adds to the kernels */
    uint32_t node_texels; /* 1: the trace reads lrt_vk_bvh.node_texels (lrt__vk_node_texels) */
    uint32_t two_passes;  /* 1: lrt_vk_cmd_trace's two passes (lrt_vk_context_flags) */
#define LRT__VK_MEMBER(name) PFN_##name p_##name;
    LRT__VK_INSTANCE_FUNCS(LRT__VK_MEMBER)
    LRT__VK_DEVICE_FUNCS(LRT__VK_MEMBER)
#undef LRT__VK_MEMBER
};

/* The push constants of the contract block, the same fields the kernels declare. */
typedef struct lrt__vk_push {
    LRT_K_VK_PUSH_CONSTANTS(uint32_t, float)
} lrt__vk_push;
/* the layout both sides assume: 23 packed 4-byte fields */
typedef char lrt__vk_push_is_92_bytes[sizeof(lrt__vk_push) == 92 && offsetof(lrt__vk_push, trace_flags) == 60 &&
                                              offsetof(lrt__vk_push, back_k0) == 76 && sizeof(float) == 4 ? 1 : -1];

enum {
    LRT__VK_BIND_DEPTH_BUFFER = LRT_K_VK_BINDING_DEPTH_BUFFER, LRT__VK_BIND_DEPTH_IMAGE = LRT_K_VK_BINDING_DEPTH_IMAGE,
    LRT__VK_BIND_NODES = LRT_K_VK_BINDING_NODES, LRT__VK_BIND_COUNTERS = LRT_K_VK_BINDING_COUNTERS,
    LRT__VK_BIND_RAYS = LRT_K_VK_BINDING_RAYS, LRT__VK_BIND_HITS = LRT_K_VK_BINDING_HITS,
    LRT__VK_BIND_BACK_BUFFER = LRT_K_VK_BINDING_BACK_BUFFER, LRT__VK_BIND_BACK_IMAGE = LRT_K_VK_BINDING_BACK_IMAGE,
    LRT__VK_BIND_NODE_TEXELS = LRT_K_VK_BINDING_NODE_TEXELS, LRT__VK_BIND_SCRATCH = LRT_K_VK_BINDING_SCRATCH,
    LRT__VK_BINDINGS = 10
};
#define LRT__VK_GROUP LRT_K_VK_GROUP_SIZE /* invocations per workgroup, in x */
#define LRT__VK_GROUPS_PER_ROW 65535u /* above this many groups the dispatch is 2D */

static void *lrt__vk_host_alloc(const VkAllocationCallbacks *cb, size_t size)
{
    if (cb) return cb->pfnAllocation(cb->pUserData, size, 16, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT);
    return LINEAR_RT_MALLOC(size, NULL);
}

static void lrt__vk_host_free(const VkAllocationCallbacks *cb, void *ptr)
{
    if (!ptr) return;
    if (cb) cb->pfnFree(cb->pUserData, ptr);
    else LINEAR_RT_FREE(ptr, NULL);
}

/* 1 the device has the extension, 0 it has not (or *vr says why not), -1
   the list could not be allocated */
static int lrt__vk_has_extension(lrt_vk_context *c, const char *name, const VkAllocationCallbacks *cb, VkResult *vr)
{
    uint32_t n = 0, i;
    VkExtensionProperties *props;
    int found = 0;
    *vr = c->p_vkEnumerateDeviceExtensionProperties(c->physical_device, NULL, &n, NULL);
    if (*vr != VK_SUCCESS) return 0;
    props = (VkExtensionProperties *)lrt__vk_host_alloc(cb, sizeof *props * (n ? n : 1));
    if (!props) return -1; /* out of host memory: not a missing extension */
    *vr = c->p_vkEnumerateDeviceExtensionProperties(c->physical_device, NULL, &n, props);
    if (*vr == VK_INCOMPLETE) *vr = VK_SUCCESS; /* a layer added one meanwhile: what we have is enough */
    for (i = 0; *vr == VK_SUCCESS && i < n; ++i)
        if (strcmp(props[i].extensionName, name) == 0) found = 1;
    lrt__vk_host_free(cb, props);
    return found;
}

/* The kernels' floats as the CPU's, where the device can (Vulkan 1.2's
   float controls): a / b rounded to nearest even, and infinities, NaN and
   the sign of 0 kept. Vulkan lets a device's a / b be 2.5 ulps off unless
   the shader asks for RoundingModeRTE; an NVIDIA H200 without it built
   thickness trees whose back codes differed from the CPU's and answered
   5% of the test rays with other last bits of t; with it, those agreed bit
   for bit. glslang has no GLSL for these modes, so
   the host adds them to each kernel's SPIR-V (1.5: the capabilities are
   core): an OpCapability each, and an OpExecutionMode each for the entry
   point, 32-bit floats. */
enum { LRT__VK_FLOAT_RTE = 1, LRT__VK_FLOAT_KEEP_INF_NAN = 2 };
enum { LRT__SPV_OP_ENTRY_POINT = 15, LRT__SPV_OP_EXECUTION_MODE = 16, LRT__SPV_OP_CAPABILITY = 17 };
static const uint32_t lrt__spv_float_modes[2][2] = {{4467u, 4462u},  /* RoundingModeRTE: capability, mode */
                                                    {4466u, 4461u}}; /* SignedZeroInfNanPreserve */

/* The kernel's words with the modes of float_modes added, in host memory
   the caller frees; NULL: out of memory, or no entry point in the module. */
static uint32_t *lrt__vk_float_controls(const VkAllocationCallbacks *cb, const uint32_t *code, size_t words,
                                        uint32_t float_modes, size_t *out_words)
{
    size_t i = 5, after_entry = 0, o, add = 0;
    uint32_t entry = 0, k, *w;
    while (i < words) { /* the last OpEntryPoint: execution modes follow it */
        const uint32_t n = code[i] >> 16;
        if (n == 0 || n > words - i) return NULL;
        if ((code[i] & 0xffffu) == LRT__SPV_OP_ENTRY_POINT && n >= 3) {
            entry = code[i + 2];
            after_entry = i + n;
        }
        i += n;
    }
    if (!after_entry) return NULL;
    for (k = 0; k < 2; ++k)
        if (float_modes & (1u << k)) add += 6;
    w = (uint32_t *)lrt__vk_host_alloc(cb, (words + add) * sizeof *w);
    if (!w) return NULL;
    memcpy(w, code, 5 * sizeof *w); /* the header; capabilities come first */
    o = 5;
    for (k = 0; k < 2; ++k)
        if (float_modes & (1u << k)) {
            w[o++] = 2u << 16 | LRT__SPV_OP_CAPABILITY;
            w[o++] = lrt__spv_float_modes[k][0];
        }
    memcpy(w + o, code + 5, (after_entry - 5) * sizeof *w);
    o += after_entry - 5;
    for (k = 0; k < 2; ++k)
        if (float_modes & (1u << k)) {
            w[o++] = 4u << 16 | LRT__SPV_OP_EXECUTION_MODE;
            w[o++] = entry;
            w[o++] = lrt__spv_float_modes[k][1];
            w[o++] = 32u;
        }
    memcpy(w + o, code + after_entry, (words - after_entry) * sizeof *w);
    *out_words = words + add;
    return w;
}

/* Does the physical device support what the kernels need? */
static int lrt__vk_supports(lrt_vk_context *c, const lrt_vk_requirements *req)
{
    VkPhysicalDeviceFeatures2 f;
    VkPhysicalDeviceVulkan11Features f11;
    VkPhysicalDeviceVulkan12Features f12;
    VkPhysicalDeviceProperties2 p;
    VkPhysicalDeviceVulkan11Properties p11;
    VkPhysicalDeviceVulkan12Properties p12;
    memset(&p12, 0, sizeof p12);
    memset(&f, 0, sizeof f);
    memset(&f11, 0, sizeof f11);
    memset(&f12, 0, sizeof f12);
    memset(&p, 0, sizeof p);
    memset(&p11, 0, sizeof p11);
    f.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    f11.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES;
    f12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
    f.pNext = &f11;
    f11.pNext = &f12;
    c->p_vkGetPhysicalDeviceFeatures2(c->physical_device, &f);
    p.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    p11.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES;
    p12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES;
    p.pNext = &p11;
    p11.pNext = &p12;
    c->p_vkGetPhysicalDeviceProperties2(c->physical_device, &p);
    /* RTE for 32-bit floats alone needs the widths' rounding independent */
    c->float_modes = 0;
    if (p12.shaderRoundingModeRTEFloat32 && p12.roundingModeIndependence != VK_SHADER_FLOAT_CONTROLS_INDEPENDENCE_NONE)
        c->float_modes |= LRT__VK_FLOAT_RTE;
    /* not on lavapipe: its kernels agree with the CPU bit for bit without
       it, and it slows them there */
    if (p12.shaderSignedZeroInfNanPreserveFloat32 && p12.driverID != VK_DRIVER_ID_MESA_LLVMPIPE)
        c->float_modes |= LRT__VK_FLOAT_KEEP_INF_NAN;
#define LRT__NEED(want, have) if ((want) && !(have)) return 0
    LRT__NEED(req->shader_float64, f.features.shaderFloat64);
    LRT__NEED(req->shader_int64, f.features.shaderInt64);
    LRT__NEED(req->shader_int16, f.features.shaderInt16);
    LRT__NEED(req->storage_buffer_16bit_access, f11.storageBuffer16BitAccess);
    LRT__NEED(req->shader_int8, f12.shaderInt8);
    LRT__NEED(req->shader_float16, f12.shaderFloat16);
    LRT__NEED(req->storage_buffer_8bit_access, f12.storageBuffer8BitAccess);
    LRT__NEED(req->shader_buffer_int64_atomics, f12.shaderBufferInt64Atomics);
    LRT__NEED(req->vulkan_memory_model, f12.vulkanMemoryModel);
    LRT__NEED(req->vulkan_memory_model_device_scope, f12.vulkanMemoryModelDeviceScope);
#undef LRT__NEED
    if (req->subgroup_operations) {
        if (!(p11.subgroupSupportedStages & VK_SHADER_STAGE_COMPUTE_BIT)) return 0;
        if ((p11.subgroupSupportedOperations & req->subgroup_operations) != req->subgroup_operations) return 0;
    }
    return 1;
}

static void lrt__vk_destroy_objects(lrt_vk_context *c)
{
    int k;
    for (k = 0; k < LRT__VK_PIPELINES; ++k)
        if (c->pipelines[k] != VK_NULL_HANDLE) c->p_vkDestroyPipeline(c->device, c->pipelines[k], c->callbacks);
    if (c->pipeline_layout != VK_NULL_HANDLE) c->p_vkDestroyPipelineLayout(c->device, c->pipeline_layout, c->callbacks);
    if (c->set_layout != VK_NULL_HANDLE) c->p_vkDestroyDescriptorSetLayout(c->device, c->set_layout, c->callbacks);
    if (c->sampler != VK_NULL_HANDLE) c->p_vkDestroySampler(c->device, c->sampler, c->callbacks);
}

/* Whether the trace kernel reads nodes through a uniform texel buffer, which
   llvmpipe loads without a branch per lane as it does not a storage buffer:
   where the device's texel
   buffers hold every tree it can trace, the smaller of the largest tree
   (LINEAR_RT_MAX_DIM squared texels, 16-bit nodes, back codes) and
   maxStorageBufferRange. Else (the Vulkan minimum is 65536 texels) the
   storage buffer. */
static uint32_t lrt__vk_node_texels(const VkPhysicalDeviceLimits *limits)
{
    lrt_build_options o;
    lrt_layout L;
    VkDeviceSize most = limits->maxStorageBufferRange;
    memset(&o, 0, sizeof o);
    o.node_bits = 16;
    o.thickness = LRT_THICKNESS_BACK_MAP;
    if (lrt__options_layout(LINEAR_RT_MAX_DIM, LINEAR_RT_MAX_DIM, LRT_FORMAT_FLOAT32, &o, &L) == LRT_SUCCESS &&
        (VkDeviceSize)L.bytes < most)
        most = (VkDeviceSize)L.bytes;
    return most / 16u <= limits->maxTexelBufferElements;
}

/* Pipeline p (the enum above, times the tree's variant) of the context. */
static VkResult lrt__vk_make_pipeline(lrt_vk_context *c, int p, VkPipeline *out)
{
    /* a round: the ordinary pass's module (of its depth source), an infinite tree's */
    const int round = p >= LRT__VK_ROUND_BUFFER, kernel = round ? LRT__VK_TRACE_BUFFER + (p - LRT__VK_ROUND_BUFFER)
                                                                : p % LRT__VK_MODULES;
    lrt__vk_module m = lrt__vk_module_at(kernel);
    /* VkBool32 lrt_back_trees, node bits, VkBool32 lrt_node_texels, lrt_trace_pass (the
       refit has no constant 3: an entry for a constant a module lacks is ignored) */
    const uint32_t pass = round                                                               ? 4u
                          : kernel == LRT__VK_RARE_BUFFER || kernel == LRT__VK_RARE_IMAGE     ? 1u
                          : kernel == LRT__VK_WHOLE_BUFFER || kernel == LRT__VK_WHOLE_IMAGE   ? 2u
                          : kernel == LRT__VK_BUDGET_BUFFER || kernel == LRT__VK_BUDGET_IMAGE ? 3u
                                                                                              : 0u;
    const uint32_t consts[4] = {!round && p >= LRT__VK_MODULES, !round && p >= 2 * LRT__VK_MODULES ? 8u : 16u,
                                c->node_texels, pass};
    VkSpecializationMapEntry entry[4];
    VkSpecializationInfo spec;
    VkShaderModuleCreateInfo mi;
    VkComputePipelineCreateInfo ci;
    VkShaderModule module;
    VkResult vr;
    entry[0].constantID = 0;
    entry[0].offset = 0;
    entry[0].size = sizeof consts[0];
    entry[1].constantID = 1;
    entry[1].offset = sizeof consts[0];
    entry[1].size = sizeof consts[1];
    entry[2].constantID = 2;
    entry[2].offset = 2 * sizeof consts[0];
    entry[2].size = sizeof consts[2];
    entry[3].constantID = 3;
    entry[3].offset = 3 * sizeof consts[0];
    entry[3].size = sizeof consts[3];
    spec.mapEntryCount = 4;
    spec.pMapEntries = entry;
    spec.dataSize = sizeof consts;
    spec.pData = consts;
    memset(&mi, 0, sizeof mi);
    mi.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    mi.codeSize = m.bytes;
    mi.pCode = m.code;
    if (c->float_modes) {
        size_t words = 0;
        uint32_t *patched = lrt__vk_float_controls(c->callbacks, m.code, m.bytes / 4u, c->float_modes, &words);
        if (!patched) return VK_ERROR_OUT_OF_HOST_MEMORY;
        mi.codeSize = words * 4u;
        mi.pCode = patched;
        vr = c->p_vkCreateShaderModule(c->device, &mi, c->callbacks, &module);
        lrt__vk_host_free(c->callbacks, patched);
    } else {
        vr = c->p_vkCreateShaderModule(c->device, &mi, c->callbacks, &module);
    }
    if (vr != VK_SUCCESS) return vr;
    memset(&ci, 0, sizeof ci);
    ci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = module;
    ci.stage.pName = "main";
    ci.stage.pSpecializationInfo = &spec;
    ci.layout = c->pipeline_layout;
    ci.basePipelineIndex = -1;
    *out = VK_NULL_HANDLE;
    vr = c->p_vkCreateComputePipelines(c->device, c->cache, 1, &ci, c->callbacks, out);
    c->p_vkDestroyShaderModule(c->device, module, c->callbacks);
    if (vr != VK_SUCCESS) *out = VK_NULL_HANDLE;
    return vr;
}

/* Creates the Vulkan objects; on failure returns the VkResult (objects made
   so far are left for lrt__vk_destroy_objects). */
static VkResult lrt__vk_create_objects(lrt_vk_context *c)
{
    VkSamplerCreateInfo si;
    VkDescriptorSetLayoutBinding b[LRT__VK_BINDINGS];
    VkDescriptorSetLayoutCreateInfo li;
    VkPushConstantRange pr;
    VkPipelineLayoutCreateInfo pi;
    VkResult vr;
    uint32_t k;
    int p;

    memset(&si, 0, sizeof si);
    si.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
    si.magFilter = si.minFilter = VK_FILTER_NEAREST;
    si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    si.maxLod = 0.0f;
    si.borderColor = VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE;
    if ((vr = c->p_vkCreateSampler(c->device, &si, c->callbacks, &c->sampler)) != VK_SUCCESS) return vr;

    memset(b, 0, sizeof b);
    for (k = 0; k < LRT__VK_BINDINGS; ++k) {
        b[k].binding = k;
        b[k].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        b[k].descriptorCount = 1;
        b[k].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    b[LRT__VK_BIND_DEPTH_IMAGE].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    b[LRT__VK_BIND_DEPTH_IMAGE].pImmutableSamplers = &c->sampler; /* pushes give the view alone */
    b[LRT__VK_BIND_BACK_IMAGE].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    b[LRT__VK_BIND_BACK_IMAGE].pImmutableSamplers = &c->sampler;
    b[LRT__VK_BIND_NODE_TEXELS].descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
    memset(&li, 0, sizeof li);
    li.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    li.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
    li.bindingCount = LRT__VK_BINDINGS;
    li.pBindings = b;
    if ((vr = c->p_vkCreateDescriptorSetLayout(c->device, &li, c->callbacks, &c->set_layout)) != VK_SUCCESS) return vr;

    memset(&pr, 0, sizeof pr);
    pr.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    pr.size = (uint32_t)sizeof(lrt__vk_push);
    memset(&pi, 0, sizeof pi);
    pi.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    pi.setLayoutCount = 1;
    pi.pSetLayouts = &c->set_layout;
    pi.pushConstantRangeCount = 1;
    pi.pPushConstantRanges = &pr;
    if ((vr = c->p_vkCreatePipelineLayout(c->device, &pi, c->callbacks, &c->pipeline_layout)) != VK_SUCCESS) return vr;

#if !LRT__VK_LAZY
    for (p = 0; p < LRT__VK_PIPELINES; ++p)
        if ((vr = lrt__vk_make_pipeline(c, p, &c->pipelines[p])) != VK_SUCCESS) return vr;
#else
    (void)p;
#endif
    return VK_SUCCESS;
}

LINEAR_RT_DEF lrt_result lrt_vk_context_create(const lrt_vk_context_desc *desc, lrt_vk_context **out)
{
    const VkAllocationCallbacks *cb;
    PFN_vkGetDeviceProcAddr gdpa;
    lrt_vk_requirements req;
    VkPhysicalDeviceProperties props;
    lrt_vk_context *c;
    VkResult vr = VK_SUCCESS;
    int missing = 0, has_ext = 0;
    if (!desc || !out) return LRT_ERROR_NULL_POINTER;
    if (desc->instance == VK_NULL_HANDLE || desc->physical_device == VK_NULL_HANDLE ||
        desc->device == VK_NULL_HANDLE || !desc->get_instance_proc_addr)
        return LRT_ERROR_NULL_POINTER;
    if (desc->flags & ~(uint32_t)(LRT_VK_TRACE_TWO_PASSES | LRT_VK_TRACE_ONE_PASS) ||
        desc->flags == (LRT_VK_TRACE_TWO_PASSES | LRT_VK_TRACE_ONE_PASS))
        return LRT_ERROR_INVALID_OPTION;
    cb = desc->allocation_callbacks;
    if (cb && (!cb->pfnAllocation || !cb->pfnFree || !cb->pfnReallocation)) return LRT_ERROR_NULL_POINTER;
    c = (lrt_vk_context *)lrt__vk_host_alloc(cb, sizeof *c);
    if (!c) return LRT_ERROR_OUT_OF_MEMORY;
    memset(c, 0, sizeof *c);
    c->device = desc->device;
    c->physical_device = desc->physical_device;
    if (cb) {
        c->allocation_callbacks = *cb;
        c->callbacks = &c->allocation_callbacks;
    }
    gdpa = desc->get_device_proc_addr;
    if (!gdpa)
        gdpa = (PFN_vkGetDeviceProcAddr)desc->get_instance_proc_addr(desc->instance, "vkGetDeviceProcAddr");
    if (!gdpa) missing = 1;
#define LRT__VK_LOAD_I(name)                                                                                     \
    c->p_##name = (PFN_##name)desc->get_instance_proc_addr(desc->instance, #name);                                \
    if (!c->p_##name) missing = 1;
#define LRT__VK_LOAD_D(name)                                                                                     \
    if (gdpa) c->p_##name = (PFN_##name)gdpa(desc->device, #name);                                                \
    if (!c->p_##name) missing = 1;
    LRT__VK_INSTANCE_FUNCS(LRT__VK_LOAD_I)
    LRT__VK_DEVICE_FUNCS(LRT__VK_LOAD_D)
#undef LRT__VK_LOAD_I
#undef LRT__VK_LOAD_D
    /* vkCmdPushDescriptorSetKHR is NULL when the extension is not enabled */
    if (missing) {
        lrt__vk_host_free(cb, c);
        return LRT_ERROR_MISSING_VULKAN_FEATURE;
    }
    c->p_vkGetPhysicalDeviceProperties(c->physical_device, &props);
    c->limits = props.limits;
    c->node_texels = lrt__vk_node_texels(&c->limits);
    c->two_passes = (desc->flags & LRT_VK_TRACE_TWO_PASSES) ||
                    (!(desc->flags & LRT_VK_TRACE_ONE_PASS) && props.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU);
    c->p_vkGetPhysicalDeviceMemoryProperties(c->physical_device, &c->memory_properties);
    lrt_vk_get_requirements(&req);
    if (props.apiVersion < req.api_version || !lrt__vk_supports(c, &req) ||
        (has_ext = lrt__vk_has_extension(c, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME, cb, &vr)) != 1) {
        lrt__vk_host_free(cb, c);
        if (has_ext < 0) return LRT_ERROR_OUT_OF_MEMORY;
        if (vr != VK_SUCCESS) {
            if (desc->vk_result) *desc->vk_result = vr;
            return LRT_ERROR_VULKAN;
        }
        return LRT_ERROR_MISSING_VULKAN_FEATURE;
    }
    c->cache = desc->pipeline_cache;
    if ((vr = lrt__vk_create_objects(c)) != VK_SUCCESS) {
        lrt__vk_destroy_objects(c);
        lrt__vk_host_free(cb, c);
        if (desc->vk_result) *desc->vk_result = vr;
        return LRT_ERROR_VULKAN;
    }
    *out = c;
    return LRT_SUCCESS;
}

LINEAR_RT_DEF void lrt_vk_context_destroy(lrt_vk_context *ctx)
{
    if (!ctx) return;
    lrt__vk_destroy_objects(ctx);
    lrt__vk_host_free(ctx->callbacks, ctx); /* callbacks points into ctx: read before the free */
}

LINEAR_RT_DEF VkResult lrt_vk_context_vk_result(const lrt_vk_context *ctx)
{
    return ctx ? ctx->vk_result : VK_SUCCESS;
}

/* ---- GPU BVHs ------------------------------------------------------------------- */

static VkDeviceSize lrt__vk_align_up(VkDeviceSize v, VkDeviceSize a) { return (v + a - 1) / a * a; }

/* minStorageBufferOffsetAlignment, made a multiple of 4 (fills and words) */
static VkDeviceSize lrt__vk_storage_alignment(const lrt_vk_context *c)
{
    VkDeviceSize a = c->limits.minStorageBufferOffsetAlignment;
    return a < 4 ? 4 : a;
}

/* minTexelBufferOffsetAlignment (at least 1: never a division by 0) */
static VkDeviceSize lrt__vk_texel_alignment(const lrt_vk_context *c)
{
    VkDeviceSize a = c->limits.minTexelBufferOffsetAlignment;
    return a < 1 ? 1 : a;
}

static lrt_result lrt__vk_layout(uint32_t width, uint32_t height, lrt_format format, const lrt_build_options *options,
                                 lrt_layout *layout)
{
    lrt_result r;
    if ((r = lrt__check_size(width, height)) != LRT_SUCCESS) return r;
    if (!lrt__format_bytes(format)) return LRT_ERROR_INVALID_FORMAT;
    return lrt__options_layout(width, height, format, options, layout);
}

LINEAR_RT_DEF lrt_result lrt_vk_bvh_buffer_sizes(uint32_t width, uint32_t height, lrt_format format,
                                                 const lrt_build_options *options, VkDeviceSize *out_nodes_bytes,
                                                 VkDeviceSize *out_counters_bytes)
{
    lrt_layout L;
    lrt_result r;
    if (!out_nodes_bytes || !out_counters_bytes) return LRT_ERROR_NULL_POINTER;
    if ((r = lrt__vk_layout(width, height, format, options, &L)) != LRT_SUCCESS) return r;
    *out_nodes_bytes = (VkDeviceSize)L.bytes;
    *out_counters_bytes = (VkDeviceSize)L.node_count * 4u;
    return LRT_SUCCESS;
}

/* The memory type for library buffers: the first of the allowed types with
   all of `want`, trying the wishes in order; -1 if none. */
static int lrt__vk_memory_type(const lrt_vk_context *c, uint32_t allowed, const VkMemoryPropertyFlags *wishes, int n)
{
    int w;
    uint32_t i;
    for (w = 0; w < n; ++w)
        for (i = 0; i < c->memory_properties.memoryTypeCount; ++i)
            if (((allowed >> i) & 1u) && (c->memory_properties.memoryTypes[i].propertyFlags & wishes[w]) == wishes[w])
                return (int)i;
    return -1;
}

LINEAR_RT_DEF lrt_result lrt_vk_bvh_create(lrt_vk_context *ctx, const lrt_vk_bvh_desc *desc, lrt_vk_bvh *out)
{
    const VkMemoryPropertyFlags DL = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT,
                                HV = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    lrt_vk_bvh bvh;
    lrt_layout L;
    VkDeviceSize align, nodes_bytes, counters_bytes, max_range;
    VkBufferViewCreateInfo vi;
    VkResult vr;
    lrt_result r;
    if (!ctx || !desc || !out) return LRT_ERROR_NULL_POINTER;
    if (out->created == LRT__BUILT) return LRT_ERROR_ALREADY_BUILT;
    if ((r = lrt__vk_layout(desc->width, desc->height, desc->format, &desc->options, &L)) != LRT_SUCCESS) return r;
    if (desc->flags & ~(uint32_t)LRT_VK_BVH_HOST_VISIBLE) return LRT_ERROR_INVALID_OPTION;
    if (desc->depth_flags & ~(uint32_t)LRT_DEPTH_REVERSED_Z) return LRT_ERROR_INVALID_OPTION;
    if ((desc->nodes == VK_NULL_HANDLE) != (desc->counters == VK_NULL_HANDLE)) return LRT_ERROR_NULL_POINTER;
    align = lrt__vk_storage_alignment(ctx);
    nodes_bytes = (VkDeviceSize)L.bytes;
    counters_bytes = (VkDeviceSize)L.node_count * 4u;
    max_range = ctx->limits.maxStorageBufferRange;
    if (nodes_bytes > max_range || counters_bytes > max_range) return LRT_ERROR_LIMIT_EXCEEDED;
    memset(&bvh, 0, sizeof bvh);
    bvh.layout = L;
    bvh.counters_bytes = counters_bytes;
    bvh.format = desc->format;
    bvh.depth_flags = desc->depth_flags;
    bvh.device = ctx->device;
    if (desc->nodes != VK_NULL_HANDLE) { /* the caller's buffers */
        if (desc->flags & LRT_VK_BVH_HOST_VISIBLE) return LRT_ERROR_INVALID_OPTION;
        if (desc->nodes_offset % align || desc->counters_offset % align ||
            desc->nodes_offset % lrt__vk_texel_alignment(ctx))
            return LRT_ERROR_MISALIGNED;
        bvh.nodes = desc->nodes;
        bvh.nodes_offset = desc->nodes_offset;
        bvh.counters = desc->counters;
        bvh.counters_offset = desc->counters_offset;
    } else { /* one buffer: nodes, then the counters at the next aligned offset */
        VkBufferCreateInfo bi;
        VkMemoryRequirements mr;
        VkMemoryAllocateInfo ai;
        VkMemoryPropertyFlags wishes[4];
        int type, n = 0;
        memset(&bi, 0, sizeof bi);
        bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
        bi.size = lrt__vk_align_up(nodes_bytes, align) + counters_bytes;
        bi.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT |
                   VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
        bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
        if ((vr = ctx->p_vkCreateBuffer(ctx->device, &bi, ctx->callbacks, &bvh.nodes)) != VK_SUCCESS) {
            ctx->vk_result = vr;
            return LRT_ERROR_VULKAN;
        }
        ctx->p_vkGetBufferMemoryRequirements(ctx->device, bvh.nodes, &mr);
        if (desc->flags & LRT_VK_BVH_HOST_VISIBLE) {
            wishes[n++] = DL | HV;
            wishes[n++] = HV;
        } else {
            wishes[n++] = DL;
            wishes[n++] = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
            wishes[n++] = 0;
        }
        type = lrt__vk_memory_type(ctx, mr.memoryTypeBits, wishes, n);
        if (type < 0) {
            ctx->p_vkDestroyBuffer(ctx->device, bvh.nodes, ctx->callbacks);
            return LRT_ERROR_MISSING_VULKAN_FEATURE;
        }
        memset(&ai, 0, sizeof ai);
        ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
        ai.allocationSize = mr.size;
        ai.memoryTypeIndex = (uint32_t)type;
        vr = ctx->p_vkAllocateMemory(ctx->device, &ai, ctx->callbacks, &bvh.memory);
        if (vr == VK_SUCCESS) vr = ctx->p_vkBindBufferMemory(ctx->device, bvh.nodes, bvh.memory, 0);
        if (vr == VK_SUCCESS && (ctx->memory_properties.memoryTypes[type].propertyFlags & HV) == HV)
            vr = ctx->p_vkMapMemory(ctx->device, bvh.memory, 0, VK_WHOLE_SIZE, 0, &bvh.mapped);
        if (vr != VK_SUCCESS) {
            ctx->p_vkDestroyBuffer(ctx->device, bvh.nodes, ctx->callbacks);
            if (bvh.memory != VK_NULL_HANDLE) ctx->p_vkFreeMemory(ctx->device, bvh.memory, ctx->callbacks);
            ctx->vk_result = vr;
            return LRT_ERROR_VULKAN;
        }
        bvh.counters = bvh.nodes;
        bvh.counters_offset = lrt__vk_align_up(nodes_bytes, align);
    }
    bvh.created = LRT__BUILT;
    memset(&vi, 0, sizeof vi);
    vi.sType = VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO;
    vi.buffer = bvh.nodes;
    vi.format = VK_FORMAT_R32G32B32A32_UINT;
    vi.offset = bvh.nodes_offset;
    vi.range = nodes_bytes & ~(VkDeviceSize)15; /* whole nodes: all of them (a multiple of 16) */
    if (vi.range / 16u > ctx->limits.maxTexelBufferElements) /* then the trace reads the storage buffer */
        vi.range = ctx->limits.maxTexelBufferElements ? (VkDeviceSize)ctx->limits.maxTexelBufferElements * 16u : 16u;
    if ((vr = ctx->p_vkCreateBufferView(ctx->device, &vi, ctx->callbacks, &bvh.node_texels)) != VK_SUCCESS) {
        bvh.node_texels = VK_NULL_HANDLE;
        lrt_vk_bvh_destroy(ctx, &bvh);
        ctx->vk_result = vr;
        return LRT_ERROR_VULKAN;
    }
    *out = bvh;
    return LRT_SUCCESS;
}

LINEAR_RT_DEF void lrt_vk_bvh_destroy(lrt_vk_context *ctx, lrt_vk_bvh *bvh)
{
    if (!bvh) return;
    /* a context of another device would free handles it does not own: the tree is left for the right one */
    if (ctx && bvh->created == LRT__BUILT && bvh->device != ctx->device) return;
    if (ctx && bvh->created == LRT__BUILT && bvh->node_texels != VK_NULL_HANDLE)
        ctx->p_vkDestroyBufferView(ctx->device, bvh->node_texels, ctx->callbacks);
    if (ctx && bvh->created == LRT__BUILT && bvh->memory != VK_NULL_HANDLE) {
        if (bvh->mapped) ctx->p_vkUnmapMemory(ctx->device, bvh->memory);
        ctx->p_vkDestroyBuffer(ctx->device, bvh->nodes, ctx->callbacks);
        ctx->p_vkFreeMemory(ctx->device, bvh->memory, ctx->callbacks);
    }
    memset(bvh, 0, sizeof *bvh);
}

/* ---- recording ------------------------------------------------------------------ */

/* A checked depth source, ready to push. */
typedef struct lrt__vk_source {
    int image;
    VkDescriptorBufferInfo buffer; /* the depth binding's range: from an aligned offset */
    VkDescriptorImageInfo view;
    uint32_t depth_offset, row_stride;
    /* the back map's, the same way (a back-map tree); else the depth's again,
       so that the binding the kernels name always holds something valid */
    VkDescriptorBufferInfo back_buffer;
    VkDescriptorImageInfo back_view;
    uint32_t back_offset, back_row_stride;
} lrt__vk_source;

static int lrt__vk_layout_ok(VkImageLayout layout)
{
    switch (layout) {
    case VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL:
    case VK_IMAGE_LAYOUT_GENERAL:
    case VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL:
#ifdef VK_VERSION_1_2
    case VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL:
#endif
#ifdef VK_VERSION_1_3
    case VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL:
#endif
        return 1;
    default: return 0;
    }
}

/* Everything about a BVH and its depth that can be wrong, before recording. */
/* One map (the depth, or its back map) as the kernels bind it: a buffer
   range from an aligned offset (*offset: the map's first byte in it), or a
   sampled image view. */
static lrt_result lrt__vk_map(const lrt_vk_context *c, const lrt_vk_depth *map, uint32_t bpp, int *image,
                              VkDescriptorBufferInfo *buffer, VkDescriptorImageInfo *view, uint32_t *offset,
                              uint32_t *row_stride)
{
    if (map->buffer == VK_NULL_HANDLE && map->view == VK_NULL_HANDLE) return LRT_ERROR_NULL_POINTER;
    if (map->buffer != VK_NULL_HANDLE && map->view != VK_NULL_HANDLE) return LRT_ERROR_INVALID_OPTION;
    *image = map->buffer == VK_NULL_HANDLE;
    if (!*image) {
        const VkDeviceSize row_bytes = (VkDeviceSize)map->width * bpp, max_range = c->limits.maxStorageBufferRange;
        /* one row spans row_bytes whatever its stride, which is then never used */
        const VkDeviceSize stride = map->row_stride && map->height > 1 ? map->row_stride : row_bytes;
        VkDeviceSize base, rem, span;
        if (stride < row_bytes) return LRT_ERROR_INVALID_STRIDE;
        if (map->offset % bpp || stride % bpp) return LRT_ERROR_MISALIGNED;
        base = map->offset - map->offset % lrt__vk_storage_alignment(c);
        rem = map->offset - base;
        /* the bound range, in words: rem + stride * (height - 1) + row_bytes, rounded up */
        if (stride > max_range) return LRT_ERROR_LIMIT_EXCEEDED;
        span = rem + stride * (map->height - 1u) + row_bytes;
        span = lrt__vk_align_up(span, 4);
        if (span > max_range) return LRT_ERROR_LIMIT_EXCEEDED;
        buffer->buffer = map->buffer;
        buffer->offset = base;
        buffer->range = span;
        *offset = (uint32_t)rem;
        *row_stride = (uint32_t)stride;
    } else {
        if (!lrt__vk_layout_ok(map->layout)) return LRT_ERROR_INVALID_OPTION;
        if (map->width > c->limits.maxImageDimension2D || map->height > c->limits.maxImageDimension2D)
            return LRT_ERROR_LIMIT_EXCEEDED; /* no such image on this device */
        view->sampler = c->sampler; /* immutable in the layout anyway */
        view->imageView = map->view;
        view->imageLayout = map->layout;
    }
    return LRT_SUCCESS;
}

static lrt_result lrt__vk_check_maps(const lrt_vk_context *c, VkCommandBuffer cmd, const lrt_vk_bvh *bvh,
                                     const lrt_vk_depth *depth, lrt__vk_source *src)
{
    const lrt_vk_depth *back;
    uint32_t bpp;
    int back_image;
    lrt_result r;
    if (!c || !cmd || !bvh || !depth) return LRT_ERROR_NULL_POINTER;
    back = depth->back;
    if (bvh->created != LRT__BUILT) return LRT_ERROR_INVALID_BVH;
    if (bvh->device != c->device) return LRT_ERROR_CONTEXT_MISMATCH;
    if ((r = lrt__check_size(depth->width, depth->height)) != LRT_SUCCESS) return r;
    bpp = lrt__format_bytes(depth->format);
    if (!bpp) return LRT_ERROR_INVALID_FORMAT;
    if (depth->flags & ~(uint32_t)LRT_DEPTH_REVERSED_Z) return LRT_ERROR_INVALID_OPTION;
    if (depth->width != bvh->layout.width || depth->height != bvh->layout.height) return LRT_ERROR_SIZE_MISMATCH;
    if (depth->format != bvh->format || depth->flags != bvh->depth_flags) return LRT_ERROR_DEPTH_MISMATCH;
    /* the tree's ranges against this context's device (create checked its own) */
    if ((VkDeviceSize)bvh->layout.bytes > c->limits.maxStorageBufferRange ||
        bvh->counters_bytes > c->limits.maxStorageBufferRange)
        return LRT_ERROR_LIMIT_EXCEEDED;
    memset(src, 0, sizeof *src);
    if ((r = lrt__vk_map(c, depth, bpp, &src->image, &src->buffer, &src->view, &src->depth_offset, &src->row_stride)) !=
        LRT_SUCCESS)
        return r;
    src->back_buffer = src->buffer;
    src->back_view = src->view;
    /* a back map exactly with a back-map tree, described as the depth is (lrt__check_back) */
    if ((back != NULL) != (bvh->layout.thickness == LRT_THICKNESS_BACK_MAP)) return LRT_ERROR_THICKNESS_MISMATCH;
    if (!back) return LRT_SUCCESS;
    if (back->back) return LRT_ERROR_THICKNESS_MISMATCH;
    if (back->width != depth->width || back->height != depth->height) return LRT_ERROR_SIZE_MISMATCH;
    if (back->format != depth->format || back->flags != depth->flags) return LRT_ERROR_DEPTH_MISMATCH;
    if ((r = lrt__vk_map(c, back, bpp, &back_image, &src->back_buffer, &src->back_view, &src->back_offset,
                         &src->back_row_stride)) != LRT_SUCCESS)
        return r;
    return back_image == src->image ? LRT_SUCCESS : LRT_ERROR_INVALID_OPTION; /* both buffers, or both images */
}

/* build: 1 for lrt_vk_cmd_build, which alone may find the tree unbuilt
   (last: the arguments' own errors are the more telling) */
static lrt_result lrt__vk_check(const lrt_vk_context *c, VkCommandBuffer cmd, const lrt_vk_bvh *bvh,
                                const lrt_vk_depth *depth, int build, lrt__vk_source *src)
{
    lrt_result r = lrt__vk_check_maps(c, cmd, bvh, depth, src);
    if (r == LRT_SUCCESS && !build && bvh->build_recorded != LRT__BUILT) r = LRT_ERROR_INVALID_BVH;
    return r;
}

/* Workgroups for n invocations: 1D up to 65535 groups, then rows of them. */
static lrt_result lrt__vk_groups(const lrt_vk_context *c, uint64_t n, uint32_t *gx, uint32_t *gy)
{
    uint64_t groups = (n + LRT__VK_GROUP - 1) / LRT__VK_GROUP, row = LRT__VK_GROUPS_PER_ROW, rows;
    if (c->limits.maxComputeWorkGroupCount[0] < row) row = c->limits.maxComputeWorkGroupCount[0];
    if (row == 0) return LRT_ERROR_LIMIT_EXCEEDED;
    if (groups <= row) {
        *gx = (uint32_t)groups;
        *gy = 1;
        return LRT_SUCCESS;
    }
    rows = (groups + row - 1) / row;
    if (rows > c->limits.maxComputeWorkGroupCount[1]) return LRT_ERROR_LIMIT_EXCEEDED;
    *gx = (uint32_t)((groups + rows - 1) / rows); /* as even as possible: at most rows-1 idle groups */
    *gy = (uint32_t)rows;
    return LRT_SUCCESS;
}

static void lrt__vk_push_common(const lrt_vk_bvh *bvh, const lrt_vk_depth *depth, const lrt__vk_source *src,
                                lrt__vk_push *pc)
{
    memset(pc, 0, sizeof *pc);
    pc->width = depth->width;
    pc->height = depth->height;
    pc->format = (uint32_t)depth->format;
    pc->flags = depth->flags;
    pc->node_bits = bvh->layout.node_bits;
    pc->level_count = bvh->layout.level_count;
    pc->depth_offset = src->depth_offset;
    pc->row_stride = src->row_stride;
    pc->back_offset = src->back_offset;
    pc->back_row_stride = src->back_row_stride;
    pc->thickness = bvh->layout.thickness;
    pc->back_k0 = bvh->layout.back_k[0];
    pc->back_k1 = bvh->layout.back_k[1];
}

/* Binds, pushes descriptors (depth, nodes, the extra ones: the refit's
   counters or the trace's rays and hits, the back map, and for the trace the
   nodes' texel view) and constants, and dispatches gx x gy groups. */
/* Pipeline `kernel` (the enum's first LRT__VK_MODULES) for the tree's
   variant, made now if no one has (LRT__VK_LAZY); before anything is
   recorded, so a failure records nothing. */
static lrt_result lrt__vk_pipeline(lrt_vk_context *c, int kernel, const lrt_vk_bvh *bvh, VkPipeline *out)
{
    const int p = kernel >= LRT__VK_ROUND_BUFFER ? kernel /* an infinite tree's */
                                                 : kernel + (!bvh->layout.back_codes         ? 0
                                                             : bvh->layout.node_bits == 16 ? LRT__VK_MODULES
                                                                                           : 2 * LRT__VK_MODULES);
#if LRT__VK_LAZY
    VkPipeline have = __atomic_load_n(&c->pipelines[p], __ATOMIC_ACQUIRE), none = VK_NULL_HANDLE;
    VkResult vr;
    if (have == VK_NULL_HANDLE) {
        if ((vr = lrt__vk_make_pipeline(c, p, &have)) != VK_SUCCESS) {
            c->vk_result = vr;
            return vr == VK_ERROR_OUT_OF_HOST_MEMORY ? LRT_ERROR_OUT_OF_MEMORY : LRT_ERROR_VULKAN;
        }
        if (!__atomic_compare_exchange_n(&c->pipelines[p], &none, have, 0, __ATOMIC_ACQ_REL, __ATOMIC_ACQUIRE)) {
            c->p_vkDestroyPipeline(c->device, have, c->callbacks);
            have = none; /* the winner's */
        }
    }
    *out = have;
#else
    *out = c->pipelines[p];
#endif
    return LRT_SUCCESS;
}

static void lrt__vk_bind(lrt_vk_context *c, VkCommandBuffer cmd, VkPipeline pipeline, int trace, const lrt_vk_bvh *bvh,
                         const lrt__vk_source *src, const VkDescriptorBufferInfo *extra, const uint32_t *extra_binding,
                         uint32_t extra_count, const lrt__vk_push *pc)
{
    VkWriteDescriptorSet w[7];
    VkDescriptorBufferInfo nodes;
    uint32_t k, n = 3 + extra_count;
    memset(w, 0, sizeof w);
    for (k = 0; k < sizeof w / sizeof w[0]; ++k) { /* storage buffers unless set otherwise below */
        w[k].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        w[k].descriptorCount = 1;
        w[k].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    }
    if (src->image) {
        w[0].dstBinding = LRT__VK_BIND_DEPTH_IMAGE;
        w[0].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
        w[0].pImageInfo = &src->view;
    } else {
        w[0].dstBinding = LRT__VK_BIND_DEPTH_BUFFER;
        w[0].pBufferInfo = &src->buffer;
    }
    nodes.buffer = bvh->nodes;
    nodes.offset = bvh->nodes_offset;
    nodes.range = (VkDeviceSize)bvh->layout.bytes;
    w[1].dstBinding = LRT__VK_BIND_NODES;
    w[1].pBufferInfo = &nodes;
    for (k = 0; k < extra_count; ++k) {
        w[2 + k].dstBinding = extra_binding[k];
        w[2 + k].pBufferInfo = &extra[k];
    }
    if (src->image) { /* the back map (the depth again without one) */
        w[2 + k].dstBinding = LRT__VK_BIND_BACK_IMAGE;
        w[2 + k].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
        w[2 + k].pImageInfo = &src->back_view;
    } else {
        w[2 + k].dstBinding = LRT__VK_BIND_BACK_BUFFER;
        w[2 + k].pBufferInfo = &src->back_buffer;
    }
    if (trace) {
        w[n].dstBinding = LRT__VK_BIND_NODE_TEXELS;
        w[n].descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
        w[n++].pTexelBufferView = &bvh->node_texels;
    }
    c->p_vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    c->p_vkCmdPushDescriptorSetKHR(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, c->pipeline_layout, 0, n, w);
    c->p_vkCmdPushConstants(cmd, c->pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, (uint32_t)sizeof *pc, pc);
}

static void lrt__vk_record(lrt_vk_context *c, VkCommandBuffer cmd, VkPipeline pipeline, int trace, const lrt_vk_bvh *bvh,
                           const lrt__vk_source *src, const VkDescriptorBufferInfo *extra, const uint32_t *extra_binding,
                           uint32_t extra_count, const lrt__vk_push *pc, uint32_t gx, uint32_t gy)
{
    lrt__vk_bind(c, cmd, pipeline, trace, bvh, src, extra, extra_binding, extra_count, pc);
    c->p_vkCmdDispatch(cmd, gx, gy, 1);
}

/* One refit dispatch over texels [x0,x1] x [y0,y1]: one invocation per
   level-2 node above them (8x8 texels; shaders/README.md). */
static lrt_result lrt__vk_refit(lrt_vk_context *c, VkCommandBuffer cmd, const lrt_vk_bvh *bvh,
                                const lrt_vk_depth *depth, const lrt__vk_source *src, uint32_t x0, uint32_t y0,
                                uint32_t x1, uint32_t y1, int build)
{
    const uint32_t cols = (x1 >> 3) - (x0 >> 3) + 1u, rows = (y1 >> 3) - (y0 >> 3) + 1u;
    const uint32_t binding = LRT__VK_BIND_COUNTERS;
    VkDescriptorBufferInfo counters;
    lrt__vk_push pc;
    uint32_t gx, gy;
    VkPipeline pipeline;
    lrt_result r;
    if ((r = lrt__vk_groups(c, (uint64_t)cols * rows, &gx, &gy)) != LRT_SUCCESS) return r;
    if ((r = lrt__vk_pipeline(c, src->image ? LRT__VK_REFIT_IMAGE : LRT__VK_REFIT_BUFFER, bvh, &pipeline)) != LRT_SUCCESS)
        return r;
    if (build) { /* the counters start at 0; the refit leaves them at 0 */
        VkBufferMemoryBarrier b;
        c->p_vkCmdFillBuffer(cmd, bvh->counters, bvh->counters_offset, bvh->counters_bytes, 0u);
        memset(&b, 0, sizeof b);
        b.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER;
        b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
        b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        b.buffer = bvh->counters;
        b.offset = bvh->counters_offset;
        b.size = bvh->counters_bytes;
        c->p_vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0,
                                  NULL, 1, &b, 0, NULL);
    }
    lrt__vk_push_common(bvh, depth, src, &pc);
    pc.rect_x0 = x0;
    pc.rect_y0 = y0;
    pc.rect_x1 = x1;
    pc.rect_y1 = y1;
    pc.build = build ? 1u : 0u;
    counters.buffer = bvh->counters;
    counters.offset = bvh->counters_offset;
    counters.range = bvh->counters_bytes;
    lrt__vk_record(c, cmd, pipeline, 0, bvh, src, &counters, &binding, 1, &pc, gx, gy);
    return LRT_SUCCESS;
}

LINEAR_RT_DEF lrt_result lrt_vk_cmd_build(lrt_vk_context *ctx, VkCommandBuffer cmd, lrt_vk_bvh *bvh,
                                          const lrt_vk_depth *depth)
{
    lrt__vk_source src;
    lrt_result r;
    if ((r = lrt__vk_check(ctx, cmd, bvh, depth, 1, &src)) != LRT_SUCCESS) return r;
    r = lrt__vk_refit(ctx, cmd, bvh, depth, &src, 0, 0, depth->width - 1u, depth->height - 1u, 1);
    if (r == LRT_SUCCESS) bvh->build_recorded = LRT__BUILT;
    return r;
}

LINEAR_RT_DEF lrt_result lrt_vk_cmd_update(lrt_vk_context *ctx, VkCommandBuffer cmd, const lrt_vk_bvh *bvh,
                                           const lrt_vk_depth *depth, const lrt_rect *dirty)
{
    lrt__vk_source src;
    lrt_result r;
    if ((r = lrt__vk_check(ctx, cmd, bvh, depth, 0, &src)) != LRT_SUCCESS) return r;
    if (!dirty) return lrt__vk_refit(ctx, cmd, bvh, depth, &src, 0, 0, depth->width - 1u, depth->height - 1u, 0);
    if (dirty->x > depth->width || dirty->width > depth->width - dirty->x || dirty->y > depth->height ||
        dirty->height > depth->height - dirty->y)
        return LRT_ERROR_INVALID_RECT;
    if (dirty->width == 0 || dirty->height == 0) return LRT_SUCCESS;
    return lrt__vk_refit(ctx, cmd, bvh, depth, &src, dirty->x, dirty->y, dirty->x + dirty->width - 1u,
                         dirty->y + dirty->height - 1u, 0);
}

/* A trace's arguments checked and turned into what every pass records:
   the rays and hits bound `first` rays before the given offsets (aligned
   offsets; the kernel starts at ray `first`), the hits once more where a
   pass has no scratch (binding 2: never read there), the push constants
   and the one-dispatch groups. *none where count is 0: nothing to record. */
typedef struct lrt__vk_trace_call {
    lrt__vk_source src;
    VkDescriptorBufferInfo io[3];
    lrt__vk_push pc;
    uint32_t gx, gy, none;
} lrt__vk_trace_call;

static lrt_result lrt__vk_trace_prepare(lrt_vk_context *ctx, VkCommandBuffer cmd, const lrt_vk_bvh *bvh,
                                        const lrt_vk_depth *depth, VkBuffer rays, VkDeviceSize rays_offset, VkBuffer hits,
                                        VkDeviceSize hits_offset, uint32_t count, uint32_t flags, lrt__vk_trace_call *t)
{
    const VkDeviceSize ray_bytes = sizeof(lrt_ray), hit_bytes = sizeof(lrt_hit);
    VkDeviceSize align, first;
    lrt_result r;
    t->none = 1;
    if ((r = lrt__vk_check(ctx, cmd, bvh, depth, 0, &t->src)) != LRT_SUCCESS) return r;
    if (!lrt__trace_flags_ok(flags)) return LRT_ERROR_INVALID_OPTION;
    if (count > LINEAR_RT_MAX_RAYS_PER_CALL) return LRT_ERROR_TOO_MANY_RAYS;
    if (count == 0) return LRT_SUCCESS;
    if (rays == VK_NULL_HANDLE || hits == VK_NULL_HANDLE) return LRT_ERROR_NULL_POINTER;
    align = lrt__vk_storage_alignment(ctx);
    for (first = 0; first < align; ++first) {
        if (first * ray_bytes > rays_offset || first * hit_bytes > hits_offset) {
            first = align;
            break;
        }
        if ((rays_offset - first * ray_bytes) % align == 0 && (hits_offset - first * hit_bytes) % align == 0) break;
    }
    if (first == align) return LRT_ERROR_MISALIGNED;
    if ((first + count) * ray_bytes > ctx->limits.maxStorageBufferRange) return LRT_ERROR_LIMIT_EXCEEDED;
    if ((r = lrt__vk_groups(ctx, count, &t->gx, &t->gy)) != LRT_SUCCESS) return r;
    t->io[0].buffer = rays;
    t->io[0].offset = rays_offset - first * ray_bytes;
    t->io[0].range = (first + count) * ray_bytes;
    t->io[1].buffer = hits;
    t->io[1].offset = hits_offset - first * hit_bytes;
    t->io[1].range = (first + count) * hit_bytes;
    t->io[2] = t->io[1];
    lrt__vk_push_common(bvh, depth, &t->src, &t->pc);
    t->pc.ray_first = (uint32_t)first;
    t->pc.ray_count = count;
    t->pc.trace_flags = flags;
    t->none = 0;
    return LRT_SUCCESS;
}

static const uint32_t lrt__vk_trace_bindings[3] = {LRT__VK_BIND_RAYS, LRT__VK_BIND_HITS, LRT__VK_BIND_SCRATCH};

/* A barrier between two of the trace's commands on one queue. */
static void lrt__vk_barrier(lrt_vk_context *ctx, VkCommandBuffer cmd, VkPipelineStageFlags src_stages,
                            VkAccessFlags src_access, VkPipelineStageFlags dst_stages, VkAccessFlags dst_access)
{
    VkMemoryBarrier mb;
    memset(&mb, 0, sizeof mb);
    mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    mb.srcAccessMask = src_access;
    mb.dstAccessMask = dst_access;
    ctx->p_vkCmdPipelineBarrier(cmd, src_stages, dst_stages, 0, 1, &mb, 0, NULL, 0, NULL);
}

/* The rare pass, after the ordinary pass (or rounds) that marked its rays
   (shaders/lrt_trace.comp): it reads the marks. */
static void lrt__vk_rare_pass(lrt_vk_context *ctx, VkCommandBuffer cmd, VkPipeline rare, const lrt_vk_bvh *bvh,
                              const lrt__vk_trace_call *t)
{
    lrt__vk_barrier(ctx, cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                    VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    lrt__vk_record(ctx, cmd, rare, 1, bvh, &t->src, t->io, lrt__vk_trace_bindings, 3, &t->pc, t->gx, t->gy);
}

/* The one-dispatch trace: the ordinary pass and the rare pass, or one pass. */
static lrt_result lrt__vk_trace_passes(lrt_vk_context *ctx, VkCommandBuffer cmd, const lrt_vk_bvh *bvh,
                                       lrt__vk_trace_call *t)
{
    VkPipeline ordinary, rare = VK_NULL_HANDLE;
    lrt_result r;
    if (!ctx->two_passes) { /* the whole kernel, every ray */
        if ((r = lrt__vk_pipeline(ctx, t->src.image ? LRT__VK_WHOLE_IMAGE : LRT__VK_WHOLE_BUFFER, bvh, &ordinary)) !=
            LRT_SUCCESS)
            return r;
    } else if ((r = lrt__vk_pipeline(ctx, t->pc.trace_flags ? (t->src.image ? LRT__VK_BUDGET_IMAGE : LRT__VK_BUDGET_BUFFER)
                                                           : (t->src.image ? LRT__VK_TRACE_IMAGE : LRT__VK_TRACE_BUFFER),
                                     bvh, &ordinary)) != LRT_SUCCESS ||
               (r = lrt__vk_pipeline(ctx, t->src.image ? LRT__VK_RARE_IMAGE : LRT__VK_RARE_BUFFER, bvh, &rare)) !=
                   LRT_SUCCESS) {
        return r;
    }
    lrt__vk_record(ctx, cmd, ordinary, 1, bvh, &t->src, t->io, lrt__vk_trace_bindings, 3, &t->pc, t->gx, t->gy);
    if (ctx->two_passes) lrt__vk_rare_pass(ctx, cmd, rare, bvh, t);
    return LRT_SUCCESS;
}

LINEAR_RT_DEF lrt_result lrt_vk_cmd_trace(lrt_vk_context *ctx, VkCommandBuffer cmd, const lrt_vk_bvh *bvh,
                                          const lrt_vk_depth *depth, VkBuffer rays, VkDeviceSize rays_offset,
                                          VkBuffer hits, VkDeviceSize hits_offset, uint32_t count, uint32_t flags)
{
    lrt__vk_trace_call t;
    lrt_result r = lrt__vk_trace_prepare(ctx, cmd, bvh, depth, rays, rays_offset, hits, hits_offset, count, flags, &t);
    return r != LRT_SUCCESS || t.none ? r : lrt__vk_trace_passes(ctx, cmd, bvh, &t);
}

/* Rays a round of a compacted trace takes at most: one row of groups (the
   indirect dispatches are 1D). */
#define LRT__VK_ROUND_RAYS ((VkDeviceSize)LRT__VK_GROUPS_PER_ROW * LRT__VK_GROUP)

LINEAR_RT_DEF VkDeviceSize lrt_vk_trace_scratch_size(uint32_t count)
{
    const VkDeviceSize n = count < LRT__VK_ROUND_RAYS ? count : LRT__VK_ROUND_RAYS;
    return 16u * ((VkDeviceSize)(LRT_K_VK_TRACE_ROUNDS - 1u) + 2u * n);
}

LINEAR_RT_DEF lrt_result lrt_vk_cmd_trace_compacted(lrt_vk_context *ctx, VkCommandBuffer cmd, const lrt_vk_bvh *bvh,
                                                    const lrt_vk_depth *depth, VkBuffer rays, VkDeviceSize rays_offset,
                                                    VkBuffer hits, VkDeviceSize hits_offset, uint32_t count,
                                                    uint32_t flags, const lrt_vk_scratch *scratch)
{
    const VkPipelineStageFlags compute = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
    const VkPipelineStageFlags compute_indirect = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT;
    const VkAccessFlags use = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
    uint32_t header[4 * (LRT_K_VK_TRACE_ROUNDS - 1u)], k, done, per_round;
    VkPipeline round, rare;
    lrt__vk_trace_call t;
    lrt_result r = lrt__vk_trace_prepare(ctx, cmd, bvh, depth, rays, rays_offset, hits, hits_offset, count, flags, &t);
    if (r != LRT_SUCCESS || t.none) return r;
    if (!scratch || scratch->buffer == VK_NULL_HANDLE) return LRT_ERROR_NULL_POINTER;
    if (scratch->offset % lrt__vk_storage_alignment(ctx)) return LRT_ERROR_MISALIGNED;
    if (scratch->size < lrt_vk_trace_scratch_size(count)) return LRT_ERROR_BUFFER_TOO_SMALL;
    /* a thickness tree's walk is the 8-child walk, and a CPU device traces in one pass */
    if (bvh->layout.back_codes || !ctx->two_passes) return lrt__vk_trace_passes(ctx, cmd, bvh, &t);
    if ((r = lrt__vk_pipeline(ctx, t.src.image ? LRT__VK_ROUND_IMAGE : LRT__VK_ROUND_BUFFER, bvh, &round)) != LRT_SUCCESS ||
        (r = lrt__vk_pipeline(ctx, t.src.image ? LRT__VK_RARE_IMAGE : LRT__VK_RARE_BUFFER, bvh, &rare)) != LRT_SUCCESS)
        return r;
    per_round = (uint32_t)LRT__VK_ROUND_RAYS;
    if (ctx->limits.maxComputeWorkGroupCount[0] < LRT__VK_GROUPS_PER_ROW)
        per_round = ctx->limits.maxComputeWorkGroupCount[0] * LRT__VK_GROUP;
    if (per_round == 0) return LRT_ERROR_LIMIT_EXCEEDED;
    for (k = 0; k < 4u * (LRT_K_VK_TRACE_ROUNDS - 1u); ++k) /* each list empty: (0, 1, 1) groups, no rays */
        header[k] = (k & 3u) == 1u || (k & 3u) == 2u;
    for (done = 0; done < count; done += per_round) {
        const uint32_t n = count - done < per_round ? count - done : per_round;
        lrt__vk_trace_call c = t;
        c.io[2].buffer = scratch->buffer;
        c.io[2].offset = scratch->offset;
        c.io[2].range = lrt_vk_trace_scratch_size(n);
        c.pc.ray_first = t.pc.ray_first + done;
        c.pc.ray_count = n;
        /* the lists' counts to zero, after whatever used the scratch before */
        lrt__vk_barrier(ctx, cmd, compute_indirect, use, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
        ctx->p_vkCmdUpdateBuffer(cmd, scratch->buffer, scratch->offset, sizeof header, header);
        lrt__vk_barrier(ctx, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, compute_indirect, use);
        for (k = 0; k < LRT_K_VK_TRACE_ROUNDS; ++k) {
            /* slices doubling from LRT_K_VK_TRACE_SLICE; the last without a limit */
            c.pc.trace_round = k;
            c.pc.trace_slice = k + 1u < LRT_K_VK_TRACE_ROUNDS ? LRT_K_VK_TRACE_SLICE << k : 0u;
            if (k == 0) {
                lrt__vk_record(ctx, cmd, round, 1, bvh, &c.src, c.io, lrt__vk_trace_bindings, 3, &c.pc,
                               (n + LRT__VK_GROUP - 1u) / LRT__VK_GROUP, 1);
                continue;
            }
            lrt__vk_barrier(ctx, cmd, compute, VK_ACCESS_SHADER_WRITE_BIT, compute_indirect, use);
            ctx->p_vkCmdPushConstants(cmd, ctx->pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, (uint32_t)sizeof c.pc, &c.pc);
            ctx->p_vkCmdDispatchIndirect(cmd, scratch->buffer, scratch->offset + (VkDeviceSize)16u * (k - 1u));
        }
    }
    lrt__vk_rare_pass(ctx, cmd, rare, bvh, &t);
    return LRT_SUCCESS;
}

#ifdef __cplusplus
}
#endif
#endif /* LINEAR_RT_VULKAN && !LINEAR_RT_VULKAN_IMPLEMENTATION_DONE */

/* ============================================================= >>walk-avx2
   The AVX2 pass, last in the implementation: for plain x86-64, this file
   includes itself with LRT__AVX2_PASS defined, which compiles sections
   setup (but its exact arithmetic), walk and batch-avx2 again for AVX2,
   FMA, BMI1 and BMI2, under names ending in _avx2; nothing follows, so the
   names need no #undef. What they call of the once-compiled code must be
   LRT__FORCE_INLINE, the rare set-up's calls excepted (make test-header
   checks it); tests/test_paths.c holds both walks to the same bits.
   ========================================================================== */
#if LRT__AVX_AT_RUN_TIME && !defined(LRT__AVX2_PASS) && !defined(LRT__AVX2_DONE)
#define LRT__AVX2_DONE
#define LRT__AVX2_PASS
#undef LRT__AVX
#define LRT__AVX 1
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2,fma,bmi,bmi2"))), apply_to = function)
#else
#pragma GCC push_options
#if __GNUC__ >= 8
#pragma GCC target("avx2,fma,bmi,bmi2,tune=icelake-server") /* generic tuning serves pre-AVX2 cores too */
#else
#pragma GCC target("avx2,fma,bmi,bmi2")
#endif
#endif

#define lrt__back_plane lrt__back_plane_avx2
#define lrt__batch8 lrt__batch8_avx2
#define lrt__bits_in lrt__bits_in_avx2
#define lrt__box8 lrt__box8_avx2
#define lrt__broadcast_ray lrt__broadcast_ray_avx2
#define lrt__child_slabs lrt__child_slabs_avx2
#define lrt__children_slot lrt__children_slot_avx2
#define lrt__clip lrt__clip_avx2
#define lrt__codes lrt__codes_avx2
#define lrt__texel_code lrt__texel_code_avx2
#define lrt__cull_axis lrt__cull_axis_avx2
#define lrt__cull_axis8 lrt__cull_axis8_avx2
#define lrt__cull_children lrt__cull_children_avx2
#define lrt__cull_constants lrt__cull_constants_avx2
#define lrt__depth_plane lrt__depth_plane_avx2
#define lrt__depth_plane_scaled lrt__depth_plane_scaled_avx2
#define lrt__face lrt__face_avx2
#define lrt__lanes lrt__lanes_avx2
#define lrt__huge_direction lrt__huge_direction_avx2
#define lrt__huge8 lrt__huge8_avx2
#define lrt__far8 lrt__far8_avx2
#define lrt__compact_codes lrt__compact_codes_avx2
#define lrt__level1_codes lrt__level1_codes_avx2
#define lrt__level1_codes_hit lrt__level1_codes_hit_avx2
#define lrt__in_grid_plane lrt__in_grid_plane_avx2
#define lrt__walk_cells_takes lrt__walk_cells_takes_avx2
#define lrt__split_level_x lrt__split_level_x_avx2
#define lrt__split_level_y lrt__split_level_y_avx2
#define lrt__find_msb lrt__find_msb_avx2
#define lrt__cross_texel lrt__cross_texel_avx2
#define lrt__cell_axis lrt__cell_axis_avx2
#define lrt__walk_cells lrt__walk_cells_avx2
#define lrt__trace_cells lrt__trace_cells_avx2
#define lrt__level1_hit lrt__level1_hit_avx2
#define lrt__load_codes lrt__load_codes_avx2
#define lrt__node_slot lrt__node_slot_avx2
#define lrt__order_mask lrt__order_mask_avx2
#define lrt__prefetch_children lrt__prefetch_children_avx2
#define lrt__prefetch_rows lrt__prefetch_rows_avx2
#define lrt__rare_bits lrt__rare_bits_avx2
#define lrt__ray_lanes lrt__ray_lanes_avx2
#define lrt__ray_setup lrt__ray_setup_avx2
#define lrt__report_hit lrt__report_hit_avx2
#define lrt__report_budget lrt__report_budget_avx2
#define lrt__budget_t lrt__budget_t_avx2
#define lrt__finish lrt__finish_avx2
#define lrt__finish_inside lrt__finish_inside_avx2
#define lrt__finish_texel lrt__finish_texel_avx2
#define lrt__cull lrt__cull_avx2
#define lrt__cull_setup lrt__cull_setup_avx2
#define lrt__cull_slab lrt__cull_slab_avx2
#define lrt__kernel_cull_children lrt__kernel_cull_children_avx2
#define lrt__ray_t lrt__ray_t_avx2
#define lrt__set_direction lrt__set_direction_avx2
#define lrt__setup8 lrt__setup8_avx2
#define lrt__setup_rare lrt__setup_rare_avx2
#define lrt__restart_far lrt__restart_far_avx2
#define lrt__setup_ray lrt__setup_ray_avx2
#define lrt__signs lrt__signs_avx2
#define lrt__signs_init lrt__signs_init_avx2
#define lrt__signs_lanes_init lrt__signs_lanes_init_avx2
#define lrt__slabs8 lrt__slabs8_avx2
#define lrt__start_level lrt__start_level_avx2
#define lrt__start_node lrt__start_node_avx2
#define lrt__test_children lrt__test_children_avx2
#define lrt__test_texel lrt__test_texel_avx2
#define lrt__clamp_depth8 lrt__clamp_depth8_avx2
#define lrt__texel_range lrt__texel_range_avx2
#define lrt__texels8 lrt__texels8_avx2
#define lrt__trace8 lrt__trace8_avx2
#define lrt__trace_batches lrt__trace_batches_avx2
#define lrt__trace_from lrt__trace_from_avx2
#define lrt__trace_one lrt__trace_one_avx2
#define lrt__trace_walk lrt__trace_walk_avx2
#define lrt__walk lrt__walk_avx2
#define lrt__walk_init lrt__walk_init_avx2
#define lrt__walk_level lrt__walk_level_avx2
#define lrt__walk_origin lrt__walk_origin_avx2
#define lrt__child lrt__child_avx2
#define lrt__walk_up lrt__walk_up_avx2
#define lrt__walk_down lrt__walk_down_avx2
#define lrt__walk_up_budget lrt__walk_up_budget_avx2
#define lrt__walk_down_budget lrt__walk_down_budget_avx2
#define lrt__from_origin lrt__from_origin_avx2
#define lrt__first_texel lrt__first_texel_avx2
#define lrt__walk_setup lrt__walk_setup_avx2
#define lrt__widen8 lrt__widen8_avx2
#define lrt__z_plane8 lrt__z_plane8_avx2
#include LINEAR_RT_SELF
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#undef LRT__AVX
#define LRT__AVX LRT__AVX_BUILT
#undef LRT__AVX2_PASS
#endif /* the AVX2 pass */
#if defined(LRT__FP_CONTRACT_ONLY) && !defined(LRT__AVX2_PASS)
#undef LRT__FP_CONTRACT_ONLY
#pragma STDC FP_CONTRACT DEFAULT
#endif
#if defined(LRT__FP_RULES_PUSHED) && !defined(LRT__AVX2_PASS) /* the includer's floating-point rules again */
#undef LRT__FP_RULES_PUSHED
#if defined(__clang__)
#pragma float_control(pop)
#elif defined(__GNUC__)
#pragma GCC pop_options
#elif defined(_MSC_VER)
#pragma float_control(pop)
#endif
#endif
#endif /* LINEAR_RT_IMPLEMENTATION */

#endif /* LRT_GLSL */

/*
--------------------------------------------------------------------- >>licence
MIT License

Copyright (c) 2026 the linear_rt authors

Permission is hereby granted, free of charge, to any person obtaining a copy of
this software and associated documentation files (the "Software"), to deal in
the Software without restriction, including without limitation the rights to
use, copy, modify, merge, publish, distribute, sublicense, and/or sell copies
of the Software, and to permit persons to whom the Software is furnished to do
so, subject to the following conditions:

The above copyright notice and this permission notice shall be included in all
copies or substantial portions of the Software.

THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY,
FITNESS FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE
AUTHORS OR COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER
LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM,
OUT OF OR IN CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE
SOFTWARE.
------------------------------------------------------------------------------
*/
