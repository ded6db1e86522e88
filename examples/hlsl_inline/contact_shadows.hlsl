// contact_shadows.hlsl - examples/vulkan_inline/contact_shadows.comp in HLSL:
// an engine's own compute shader that traces linear_rt's BVH inline, one
// invocation per texel, one short screen-space shadow ray towards the light,
// any hit. Writes 1 (shadowed), 0 (lit) or 2 (sky: no ray) per texel.
//
// To include linear_rt.hlsl a shader provides four things:
//   0. the host/shader contract: #define LRT_GLSL and #include "linear_rt.h"
//      (its >>contract block alone: formats, kinds, bindings, ...; the macro
//      is named for the first shading language, and serves both);
//   1. the depth (here a ByteAddressBuffer: float depth, word i at byte 4 i)
//      and the node array of an lrt_vk_bvh, as resources of its own;
//   2. LRT_DEPTH_IMAGE, LRT_DEPTH_WORD(i) and LRT_NODE_WORD(i), defined before
//      the #include;
//   3. an LrtParams (the first 8 fields of the contract's push constants)
//      for each lrt_trace_ray call: here push constants; a constant buffer
//      (D3D12's root constants) does as well.
// Compile (glslang's HLSL front end; the make rule is in vulkan_inline.mk):
//   glslangValidator -D -V --target-env vulkan1.1 -e main -S comp -I. -Ishaders contact_shadows.hlsl
// DXC reads the same source (-spirv for Vulkan, or DXIL for D3D12 with
// register() bindings in place of [[vk::binding]]); not tested here.

// 0. the contract
#define LRT_GLSL 1
#include "linear_rt.h"

// 1. the library's buffers, at the library's own binding numbers (any set
// and binding would do: the macros below are all the include sees)
[[vk::binding(0, 0)]] ByteAddressBuffer depth_buf; // LRT_K_VK_BINDING_DEPTH_BUFFER
[[vk::binding(2, 0)]] ByteAddressBuffer node_buf;  // LRT_K_VK_BINDING_NODES
// our own output: one uint per texel
[[vk::binding(3, 0)]] RWStructuredBuffer<uint> shadow_buf;

// the LrtParams fields (as the host fills them from lrt_vk_bvh.layout), then ours
struct Push {
    uint width, height, format, flags, node_bits, level_count, depth_offset, row_stride;
    float3 light; // the shadow ray for t in [0, 1]: x, y in texels, z in depth per unit of (1 - depth)
    float bias;   // added to the lift of a ray's origin off its own surface
};
[[vk::push_constant]] ConstantBuffer<Push> pc;

// 2. how the include reads them
#define LRT_DEPTH_IMAGE 0
#define LRT_DEPTH_WORD(i) depth_buf.Load((i) * 4u)
#define LRT_NODE_WORD(i) node_buf.Load((i) * 4u)
#include "linear_rt.hlsl"

// 3. the parameters of the tree and the depth (as contact_shadows.comp fills
// them, on purpose: the example stands alone, a copy to start from)
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
    return asfloat(lrt_depth_raw(p, uint(x), uint(y)));
}

// the smaller depth step to a neighbour on either side (a sky neighbour's
// step is large, so the other side wins)
float slope(float d, float a, float b)
{
    precise float sa = abs(d - a), sb = abs(b - d);
    return min(sa, sb);
}

[numthreads(8, 8, 1)]
void main(uint3 id : SV_DispatchThreadID)
{
    LrtParams p = params();
    int2 c = int2(id.xy);
    if (c.x >= int(p.width) || c.y >= int(p.height)) return;
    uint k = uint(c.y) * p.width + uint(c.x);
    float d = depth_at(p, c.x, c.y);
    if (d >= 1.0) { // sky: nothing to shadow
        shadow_buf[k] = 2u;
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
    float3 origin = float3(float(c.x) + 0.5, float(c.y) + 0.5, oz);
    float3 dir = float3(pc.light.xy, vz);
    LrtHit h = lrt_trace_ray(p, origin, 0.0, dir, 1.0);
    shadow_buf[k] = h.kind == LRT_HIT ? 1u : 0u;
}
