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
// with a step budget (trace flags: LRT_TRACE_BUDGET), which 0 leaves out;
// 4: a round of a compacted trace of an infinite tree (lrt_trace_round)
layout(constant_id = 3) const uint lrt_trace_pass = 0u;
// a rare ray's hit between the passes: no kind and face a hit has
const uint LRT_RARE_MARK = 0xffffffffu;

// A compacted trace's lists (pass 4; other passes bind some buffer here and
// never read it). Not coherent: within a round invocations meet only in
// the atomics, and a round reads what the one before wrote after a
// barrier. q[r], r < LRT_K_VK_TRACE_ROUNDS - 1, the rays round r
// left for round r + 1 as (workgroups, 1, 1, count), the arguments of that
// round's indirect dispatch and its count; then two lists of
// pc.ray_count entries, the rounds taking turns: a ray's index and its
// walk's state (lrt_list_entry)
layout(set = 0, binding = LRT_K_VK_BINDING_SCRATCH, std430) buffer LrtScratch { uvec4 q[]; } lrt_scratch;
const uint LRT_LISTS = LRT_K_VK_TRACE_ROUNDS - 1u; // q's first list entry

// the ray of hit i (a slice's index), traced by the pass's function
void lrt_trace_one(uint idx)
{
    uint i = pc.ray_first + idx;
    LrtRayIn r = lrt_rays.r[i];
    LrtHit hit;
    // the trace flags (LRT_TRACE_BUDGET, LRT_TRACE_FINISH); the exact ordinary pass's a constant 0
    uint flags = lrt_trace_pass == 0u ? 0u : pc.trace_flags;
    if (lrt_trace_pass == 1u || lrt_trace_pass == 2u) {
        hit = lrt_trace_ray_budget(lrt_params(), r.origin, r.tmin, r.dir, r.tmax, flags);
    } else {
        bool rare; // an infinite tree's rays walk cells; a thickness tree's the 8-child walk
        hit = lrt_trace_ray_ordinary_budget(lrt_params(), r.origin, r.tmin, r.dir, r.tmax, flags, rare);
        if (rare) {
            lrt_hits.h[i] = uvec4(0u, 0u, 0u, LRT_RARE_MARK);
            return;
        }
    }
    lrt_hits.h[i] = uvec4(floatBitsToUint(hit.t), hit.x, hit.y, lrt_hit_word3(hit));
}

// a listed ray: its index, its cursor (one past the screen at -1: + 1),
// its level, corner and steps (at most a budget: 16 bits), its free t
uvec4 lrt_list_entry(uint i, LrtCells c)
{
    return uvec4(i, uint(c.x + 1) | (uint(c.y + 1) << 16), uint(c.lv) | (uint(c.pend) << 8) | (c.steps << 16),
                 floatBitsToUint(c.free_t));
}

LrtCells lrt_list_cells(uvec4 q)
{
    LrtCells c;
    c.x = int(q.y & 0xffffu) - 1;
    c.y = int(q.y >> 16) - 1;
    c.lv = int(q.z & 0xffu);
    c.pend = int((q.z >> 8) & 0xffu);
    c.steps = q.z >> 16;
    c.free_t = uintBitsToFloat(q.w);
    return c;
}

// Round pc.trace_round of a compacted trace: round 0 takes every ray as
// the ordinary pass does (the rare ones marked for the rare pass), later
// rounds the rays the round before listed, resumed where they stopped
// (their set-up made again: the same numbers). A ray walks at most
// pc.trace_slice cell steps (0: no limit, the last round) and its budget's;
// one the slice stopped is listed for the next round, in full waves
void lrt_trace_round(uint idx)
{
    uint round = pc.trace_round, budget = pc.trace_flags & LRT_K_TRACE_BUDGET_MASK, i = idx;
    LrtCells c;
    if (round != 0u) {
        if (idx >= lrt_scratch.q[round - 1u].w) return;
        uvec4 q = lrt_scratch.q[LRT_LISTS + ((round - 1u) & 1u) * pc.ray_count + idx];
        i = q.x;
        c = lrt_list_cells(q);
    }
    LrtRayIn r = lrt_rays.r[pc.ray_first + i];
    LrtParams p = lrt_params();
    LrtSetup s;
    uint kind;
    int e;
    bool rare;
    bool set = lrt_setup_unless_rare(p, r.origin, r.tmin, r.dir, r.tmax, s, e, kind, rare);
    rare = rare || (set && !lrt_walk_cells_takes(s));
    if (!set || rare) { // round 0 alone: a listed ray was set up and taken
        LrtHit miss = lrt_miss(kind);
        lrt_hits.h[pc.ray_first + i] = rare ? uvec4(0u, 0u, 0u, LRT_RARE_MARK)
                                            : uvec4(floatBitsToUint(miss.t), miss.x, miss.y, lrt_hit_word3(miss));
        return;
    }
    if (round == 0u) c = lrt_cells_start(p, s);
    uint stop = pc.trace_slice != 0u ? c.steps + pc.trace_slice : 0u;
    if (budget != 0u && (stop == 0u || stop > budget)) stop = budget;
    uint hx, hy;
    float ht;
    vec2 hplanes;
    uint found = lrt_walk_cells_from(p, s, c, stop, hx, hy, ht, hplanes);
    if (found == LRT_WALK_BUDGET && c.steps != budget) { // the slice ended: on in the next round
        if (budget == 0u) c.steps = 0u; // counted for a budget alone
        uint n = atomicAdd(lrt_scratch.q[round].w, 1u);
        if (n % LRT_K_VK_GROUP_SIZE == 0u) atomicAdd(lrt_scratch.q[round].x, 1u);
        lrt_scratch.q[LRT_LISTS + (round & 1u) * pc.ray_count + n] = lrt_list_entry(i, c);
        return;
    }
    LrtHit hit = lrt_cells_answer(p, s, e, kind, r.tmin, r.tmax, found, hx, hy, ht, hplanes, pc.trace_flags);
    lrt_hits.h[pc.ray_first + i] = uvec4(floatBitsToUint(hit.t), hit.x, hit.y, lrt_hit_word3(hit));
}

void main()
{
    uint idx = lrt_invocation();
    if (idx >= pc.ray_count) return;
    // the rare pass: the marked hits only (a wave without one only reads)
    if (lrt_trace_pass == 1u && lrt_hits.h[pc.ray_first + idx].w != LRT_RARE_MARK) return;
    if (lrt_trace_pass == 4u) lrt_trace_round(idx);
    else lrt_trace_one(idx);
}
