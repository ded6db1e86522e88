#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require // the nodes' texel view
// lrt_trace.comp - one ray per invocation through the BVH: its closest hit,
// into hits[ray_first + i], in two passes (lrt_trace_pass). The ordinary
// pass traces every ray but the rare ones (lrt_ray_rare), whose hits it
// marks; the rare pass, after a barrier, traces the marked ones with the
// exact rare set-up. The ordinary pass so holds none of that set-up's code:
// on a GPU a kernel pays registers and instructions for code its rays never
// run.
#define LRT_NODES_ACCESS readonly // (lrt_common.glsl)
#define LRT_NODES_QUADS
#include "lrt_common.glsl"

struct LrtRayIn {
    vec3 origin;
    float tmin;
    vec3 dir;
    float tmax;
};
layout(set = 0, binding = LRT_K_VK_BINDING_RAYS, std430) readonly buffer LrtRays { LrtRayIn r[]; } lrt_rays;
layout(set = 0, binding = LRT_K_VK_BINDING_HITS, std430) buffer LrtHits { uvec4 h[]; } lrt_hits; // lrt_hit: t, x, y, kind | face << 16

// 0: the ordinary pass; 1: the rare pass; 2: one pass, every ray by the
// whole code (a CPU device: lrt_vk_context_flags); 3: the ordinary pass
// with a step budget (trace flags: LRT_TRACE_BUDGET), which 0 leaves out
layout(constant_id = 3) const uint lrt_trace_pass = 0u;
// a rare ray's hit between the passes: no kind and face a hit has
const uint LRT_RARE_MARK = 0xffffffffu;

// the ray of hit i (a slice's index), traced by the pass's function
void lrt_trace_one(uint idx)
{
    uint i = pc.ray_first + idx;
    LrtRayIn r = lrt_rays.r[i];
    LrtHit hit;
    // LRT_TRACE_BUDGET: steps, 0 for none; the exact ordinary pass's a constant 0
    uint budget = lrt_trace_pass == 0u ? 0u : pc.trace_flags & LRT_K_TRACE_BUDGET_MASK;
    if (lrt_trace_pass == 1u || lrt_trace_pass == 2u) {
        hit = lrt_trace_ray_budget(lrt_params(), r.origin, r.tmin, r.dir, r.tmax, budget);
    } else {
        bool rare; // an infinite tree's rays walk cells; a thickness tree's the 8-child walk
        hit = lrt_trace_ray_ordinary_budget(lrt_params(), r.origin, r.tmin, r.dir, r.tmax, budget, rare);
        if (rare) {
            lrt_hits.h[i] = uvec4(0u, 0u, 0u, LRT_RARE_MARK);
            return;
        }
    }
    lrt_hits.h[i] = uvec4(floatBitsToUint(hit.t), hit.x, hit.y, lrt_hit_word3(hit));
}

void main()
{
    uint idx = lrt_invocation();
    if (idx >= pc.ray_count) return;
    // the rare pass: the marked hits only (a wave without one only reads)
    if (lrt_trace_pass == 1u && lrt_hits.h[pc.ray_first + idx].w != LRT_RARE_MARK) return;
    lrt_trace_one(idx);
}
