#version 460
#extension GL_GOOGLE_include_directive : require
// vkp_aabb_gen.comp - the AABB of every texel box [i,i+1] x [j,j+1] x [d,b]
// (b = 1, or its back depth with a thickness),
// primitive k being texel table[k] (the texels in Z order: lavapipe's builder
// keeps the submission order, so the order makes the tree). One invocation
// per primitive; pc.ray_count = the number of primitives.
#include "vkp_common.glsl"

layout(set = 0, binding = 3, std430) readonly buffer VkpTable { uint texel[]; } vkp_table;
layout(set = 0, binding = 4, std430) writeonly buffer VkpAabbs { float f[]; } vkp_aabbs;

void main()
{
    uint k = gl_GlobalInvocationID.x + pc.ray_first;
    if (gl_GlobalInvocationID.x >= pc.ray_count) return;
    uint texel = vkp_table.texel[k];
    uint i = texel % pc.width, j = texel / pc.width;
    uint b = k * 6u;
    vkp_aabbs.f[b + 0u] = float(i);
    vkp_aabbs.f[b + 1u] = float(j);
    vkp_aabbs.f[b + 2u] = vkp_depth.depth[texel];
    vkp_aabbs.f[b + 3u] = float(i + 1u);
    vkp_aabbs.f[b + 4u] = float(j + 1u);
    vkp_aabbs.f[b + 5u] = vkp_back_at(i, j);
}
