#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require // the nodes' texel view
// lrt_trace.comp - one ray per invocation through the BVH: its closest hit,
// into hits[ray_first + i].
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
layout(set = 0, binding = LRT_K_VK_BINDING_HITS, std430) writeonly buffer LrtHits { uvec4 h[]; } lrt_hits; // lrt_hit: t, x, y, kind | face << 16

void main()
{
    uint idx = lrt_invocation();
    if (idx >= pc.ray_count) return;
    uint i = pc.ray_first + idx;
    LrtRayIn r = lrt_rays.r[i];
    LrtHit hit = lrt_trace_ray(lrt_params(), r.origin, r.tmin, r.dir, r.tmax);
    lrt_hits.h[i] = uvec4(floatBitsToUint(hit.t), hit.x, hit.y, lrt_hit_word3(hit));
}
