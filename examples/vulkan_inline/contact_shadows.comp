#version 450
#extension GL_GOOGLE_include_directive : require
// contact_shadows.comp - an engine's own compute shader that traces
// linear_rt's BVH inline: one invocation per texel, one short screen-space
// shadow ray towards the light, any hit. Writes 1 (shadowed), 0 (lit) or
// 2 (sky: no ray) per texel.
//
// To include linear_rt.glsl a shader provides four things:
//   0. the host/shader contract: #define LRT_GLSL and #include "linear_rt.h"
//      (its >>contract block alone: formats, kinds, bindings, ...);
//   1. the depth (here a storage buffer at the library's depth binding,
//      LRT_DEPTH_IMAGE 0) and the node array of an lrt_vk_bvh, as macros the
//      include reads;
//   2. LRT_DEPTH_IMAGE, LRT_DEPTH_WORD(i) and LRT_NODE_WORD(i), defined before
//      the #include;
//   3. an LrtParams (the first 8 fields of the contract's push constants)
//      for each lrt_trace_ray call.
// Compile: glslangValidator -V --target-env vulkan1.2 -I. -Ishaders contact_shadows.comp

// 0. the contract
#define LRT_GLSL 1
#include "linear_rt.h"

layout(local_size_x = 8, local_size_y = 8) in;

// 1. the library's buffers, at the library's own binding numbers (any set
// and binding would do: the macros below are all the include sees)
layout(set = 0, binding = LRT_K_VK_BINDING_DEPTH_BUFFER, std430) readonly buffer Depth { uint words[]; } depth_buf;
layout(set = 0, binding = LRT_K_VK_BINDING_NODES, std430) readonly buffer Nodes { uint words[]; } node_buf;
// our own output: one uint per texel
layout(set = 0, binding = 3, std430) writeonly buffer Shadow { uint texels[]; } shadow_buf;

// the LrtParams fields (as the host fills them from lrt_vk_bvh.layout), then ours
layout(push_constant) uniform Push {
    uint width, height, format, flags, node_bits, level_count, depth_offset, row_stride;
    vec3 light;  // the shadow ray for t in [0, 1]: x, y in texels, z in depth per unit of (1 - depth)
    float bias;  // added to the lift of a ray's origin off its own surface
} pc;

// 2. how the include reads them
#define LRT_DEPTH_IMAGE 0
#define LRT_DEPTH_WORD(i) depth_buf.words[i]
#define LRT_NODE_WORD(i) node_buf.words[i]
#include "linear_rt.glsl"

// 3. the parameters of the tree and the depth
LrtParams params()
{
    LrtParams p;
    p.width = pc.width;
    p.height = pc.height;
    p.format = pc.format;
    p.flags = pc.flags;
    p.node_bits = pc.node_bits;
    p.level_count = pc.level_count;
    p.depth_offset = pc.depth_offset;
    p.row_stride = pc.row_stride;
    p.back_offset = 0u; // an infinite-thickness tree: no back map, no model
    p.back_row_stride = 0u;
    p.thickness = LRT_THICKNESS_INFINITE;
    p.back_k0 = 0.0;
    p.back_k1 = 0.0;
    return p;
}

// depth of texel (x, y) as the tracer sees it (lrt_depth_raw: the float's bits
// after docs/MODEL.md's clamp; this example's depth is LRT_FORMAT_FLOAT32),
// clamped to the map's edge
float depth_at(LrtParams p, int x, int y)
{
    x = clamp(x, 0, int(p.width) - 1);
    y = clamp(y, 0, int(p.height) - 1);
    return uintBitsToFloat(lrt_depth_raw(p, uint(x), uint(y)));
}

// the smaller depth step to a neighbour on either side (a sky neighbour's
// step is large, so the other side wins)
float slope(float d, float a, float b)
{
    precise float sa = abs(d - a), sb = abs(b - d);
    return min(sa, sb);
}

void main()
{
    LrtParams p = params();
    ivec2 c = ivec2(gl_GlobalInvocationID.xy);
    if (c.x >= int(p.width) || c.y >= int(p.height)) return;
    uint k = uint(c.y) * p.width + uint(c.x);
    float d = depth_at(p, c.x, c.y);
    if (d >= 1.0) { // sky: nothing to shadow
        shadow_buf.texels[k] = 2u;
        return;
    }
    // A ray from the texel's own surface is inside its box (docs/MODEL.md): lift it
    // towards the eye by half the depth step to its neighbours, so that it
    // clears a plane through them, plus a bias.
    float sx = slope(d, depth_at(p, c.x - 1, c.y), depth_at(p, c.x + 1, c.y));
    float sy = slope(d, depth_at(p, c.x, c.y - 1), depth_at(p, c.x, c.y + 1));
    precise float s = sx + sy;
    precise float lift = 0.5 * s + pc.bias;
    precise float oz = d - lift;
    // A fixed screen-space step in x and y; in z, scaled by (1 - depth) (about
    // near / view distance), so that the ray climbs as steeply near and far.
    precise float far = 1.0 - d;
    precise float vz = pc.light.z * far;
    vec3 origin = vec3(float(c.x) + 0.5, float(c.y) + 0.5, oz);
    vec3 dir = vec3(pc.light.xy, vz);
    LrtHit h = lrt_trace_ray(p, origin, 0.0, dir, 1.0);
    shadow_buf.texels[k] = h.kind == LRT_HIT ? 1u : 0u;
}
