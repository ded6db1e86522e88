// tests/hlsl/lrt_trace.hlsl - shaders/lrt_trace.comp again, written in HLSL
// over shaders/linear_rt.hlsl: the same bindings, push constants and
// specialization constants as the library's trace kernel (buffer depth), so
// that test_vulkan_hlsl (tests/test_vulkan.c built with TEST_HLSL) runs
// every one of test_vulkan's traces through it in the library's place and
// checks the answers against the CPU's, bit for bit. Compiled by glslang's
// HLSL front end: glslangValidator -D -V -e main -S comp.
// HLSL has no gl_NumWorkGroups: a 2D dispatch's row is worked out (main).
#define LRT_GLSL 1
#include "../../linear_rt.h"

struct LrtPush {
    LRT_K_VK_PUSH_CONSTANTS(uint, float)
};
[[vk::push_constant]] ConstantBuffer<LrtPush> pc;

// the contract's binding numbers (LRT_K_VK_BINDING_*), written as literals:
// an attribute takes no macro that carries a u, and glslang's #if reads none;
// a wrong one fails test_vulkan_hlsl (the validation layer and the answers)

#if LRT_HLSL_DEPTH_IMAGE
// sampled images, which glslang's --auto-sampled-textures makes the combined
// image samplers the library binds
[[vk::binding(1, 0)]] Texture2D<float> lrt_depth_image;
[[vk::binding(7, 0)]] Texture2D<float> lrt_back_image;
#else
[[vk::binding(0, 0)]] ByteAddressBuffer lrt_depth;
[[vk::binding(6, 0)]] ByteAddressBuffer lrt_back;
#endif
[[vk::binding(2, 0)]] ByteAddressBuffer lrt_nodes;
#if !LRT_HLSL_DEPTH_IMAGE
// (not in the image variant: --auto-sampled-textures would make this texel
// buffer a sampled image too; there a node's codes come from the storage
// buffer, the same bytes)
[[vk::binding(8, 0)]] Buffer<uint4> lrt_node_view;
#endif
struct LrtRayIn {
    float3 origin;
    float tmin;
    float3 dir;
    float tmax;
};
[[vk::binding(4, 0)]] StructuredBuffer<LrtRayIn> lrt_rays;
[[vk::binding(5, 0)]] RWStructuredBuffer<uint4> lrt_hits;
// a compacted trace's lists (lrt_trace.comp's LrtScratch: q[k] at byte 16 k)
[[vk::binding(9, 0)]] RWByteAddressBuffer lrt_scratch;

[[vk::constant_id(0)]] const bool lrt_back_trees = false;
[[vk::constant_id(1)]] const uint lrt_back_node_bits = 16u;
[[vk::constant_id(2)]] const bool lrt_node_texels = false;
[[vk::constant_id(3)]] const uint lrt_trace_pass = 0u;

uint4 lrt_node_quad(uint i)
{
#if !LRT_HLSL_DEPTH_IMAGE
    if (lrt_node_texels) return lrt_node_view.Load(int(i));
#endif
    return lrt_nodes.Load4(i * 16u);
}

#if LRT_HLSL_DEPTH_IMAGE
#define LRT_DEPTH_IMAGE 1
#define LRT_DEPTH_TEXEL(x, y) lrt_depth_image.Load(int3(int(x), int(y), 0))
#define LRT_BACK_TEXEL(x, y) lrt_back_image.Load(int3(int(x), int(y), 0))
#else
#define LRT_DEPTH_IMAGE 0
#define LRT_DEPTH_WORD(i) lrt_depth.Load((i) * 4u)
#define LRT_BACK_WORD(i) lrt_back.Load((i) * 4u)
#endif
#define LRT_NODE_WORD(i) lrt_nodes.Load((i) * 4u)
#define LRT_NODE_QUAD(i) lrt_node_quad(i)
#define LRT_BACK_TREES lrt_back_trees
#define LRT_INFINITE_TREES (!lrt_back_trees) // as lrt_common.glsl: thickness trees alone
#include "../../shaders/linear_rt.hlsl"

// lrt_common.glsl's lrt_params, written again in HLSL on purpose: this file is
// the library's trace kernel in the other language, line for line
LrtParams lrt_params()
{
    LrtParams p;
    p.width = pc.width;
    p.height = pc.height;
    p.format = pc.format;
    p.flags = pc.flags;
    p.node_bits = LRT_BACK_TREES ? lrt_back_node_bits : pc.node_bits;
    p.level_count = pc.level_count;
    p.depth_offset = pc.depth_offset;
    p.row_stride = pc.row_stride;
    p.back_offset = pc.back_offset;
    p.back_row_stride = pc.back_row_stride;
    p.thickness = pc.thickness;
    p.back_k0 = pc.back_k0;
    p.back_k1 = pc.back_k1;
    return p;
}

static const uint LRT_RARE_MARK = 0xffffffffu;

void lrt_trace_one(uint idx)
{
    uint i = pc.ray_first + idx;
    LrtRayIn r = lrt_rays[i];
    LrtHit hit;
    uint flags = lrt_trace_pass == 0u ? 0u : pc.trace_flags;
    if (lrt_trace_pass == 1u || lrt_trace_pass == 2u) {
        hit = lrt_trace_ray_budget(lrt_params(), r.origin, r.tmin, r.dir, r.tmax, flags);
    } else {
        bool rare;
        hit = lrt_trace_ray_ordinary_budget(lrt_params(), r.origin, r.tmin, r.dir, r.tmax, flags, rare);
        if (rare) {
            lrt_hits[i] = uint4(0u, 0u, 0u, LRT_RARE_MARK);
            return;
        }
    }
    lrt_hits[i] = uint4(asuint(hit.t), hit.x, hit.y, lrt_hit_word3(hit));
}

// lrt_trace.comp's compacted round, line for line
static const uint LRT_LISTS = LRT_K_VK_TRACE_ROUNDS - 1u;

uint4 lrt_list_entry(uint i, LrtCells c)
{
    return uint4(i, uint(c.x + 1) | (uint(c.y + 1) << 16), uint(c.lv) | (uint(c.pend) << 8) | (c.steps << 16),
                 asuint(c.free_t));
}

LrtCells lrt_list_cells(uint4 q)
{
    LrtCells c;
    c.x = int(q.y & 0xffffu) - 1;
    c.y = int(q.y >> 16) - 1;
    c.lv = int(q.z & 0xffu);
    c.pend = int((q.z >> 8) & 0xffu);
    c.steps = q.z >> 16;
    c.free_t = asfloat(q.w);
    return c;
}

void lrt_trace_round(uint idx)
{
    uint round = pc.trace_round, budget = pc.trace_flags & LRT_K_TRACE_BUDGET_MASK, i = idx;
    LrtCells c;
    c.x = c.y = c.lv = c.pend = 0;
    c.free_t = 0.0;
    c.steps = 0u;
    if (round != 0u) {
        if (idx >= lrt_scratch.Load(16u * (round - 1u) + 12u)) return;
        uint4 q = lrt_scratch.Load4(16u * (LRT_LISTS + ((round - 1u) & 1u) * pc.ray_count + idx));
        i = q.x;
        c = lrt_list_cells(q);
    }
    LrtRayIn r = lrt_rays[pc.ray_first + i];
    LrtParams p = lrt_params();
    LrtSetup s;
    uint kind;
    int e;
    bool rare;
    bool set = lrt_setup_unless_rare(p, r.origin, r.tmin, r.dir, r.tmax, s, e, kind, rare);
    rare = rare || (set && !lrt_walk_cells_takes(s));
    if (!set || rare) {
        LrtHit miss = lrt_miss(kind);
        lrt_hits[pc.ray_first + i] = rare ? uint4(0u, 0u, 0u, LRT_RARE_MARK)
                                          : uint4(asuint(miss.t), miss.x, miss.y, lrt_hit_word3(miss));
        return;
    }
    if (round == 0u) c = lrt_cells_start(p, s);
    uint stop = pc.trace_slice != 0u ? c.steps + pc.trace_slice : 0u;
    if (budget != 0u && (stop == 0u || stop > budget)) stop = budget;
    uint hx, hy;
    float ht;
    float2 hplanes;
    uint found = lrt_walk_cells_from(p, s, c, stop, hx, hy, ht, hplanes);
    if (found == LRT_WALK_BUDGET && c.steps != budget) {
        if (budget == 0u) c.steps = 0u;
        uint n, groups;
        lrt_scratch.InterlockedAdd(16u * round + 12u, 1u, n);
        if (n % LRT_K_VK_GROUP_SIZE == 0u) lrt_scratch.InterlockedAdd(16u * round, 1u, groups);
        lrt_scratch.Store4(16u * (LRT_LISTS + (round & 1u) * pc.ray_count + n), lrt_list_entry(i, c));
        return;
    }
    LrtHit hit = lrt_cells_answer(p, s, e, kind, r.tmin, r.tmax, found, hx, hy, ht, hplanes, pc.trace_flags);
    lrt_hits[pc.ray_first + i] = uint4(asuint(hit.t), hit.x, hit.y, lrt_hit_word3(hit));
}

// HLSL has no gl_NumWorkGroups: a 2D dispatch's row of groups is worked
// out as the host does (lrt__vk_groups), for a device whose
// maxComputeWorkGroupCount[0] is at least the library's row of 65535 groups
// (lavapipe's, and most GPUs'; test_vulkan's trace in rows of a lowered
// limit is not run through it)
[numthreads(LRT_K_VK_GROUP_SIZE, 1, 1)]
void main(uint3 gid : SV_GroupID, uint3 lid : SV_GroupThreadID)
{
    uint groups = (pc.ray_count + LRT_K_VK_GROUP_SIZE - 1u) / LRT_K_VK_GROUP_SIZE;
    uint rows = (groups + 65534u) / 65535u;
    uint row = (groups + rows - 1u) / rows;
    uint idx = (gid.y * row + gid.x) * LRT_K_VK_GROUP_SIZE + lid.x;
    if (idx >= pc.ray_count) return;
    if (lrt_trace_pass == 1u && lrt_hits[pc.ray_first + idx].w != LRT_RARE_MARK) return;
    if (lrt_trace_pass == 4u) lrt_trace_round(idx);
    else lrt_trace_one(idx);
}
