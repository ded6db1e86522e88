// linear_rt.hlsl - the inline tracer of linear_rt.glsl for HLSL: the same
// body, read through this prelude. There is one source of the walks, the
// height codes and the depth reads: linear_rt.glsl, written in the part of
// GLSL that maps onto HLSL name for name (types, bit casts, findMSB). This
// file maps those names and supplies the one built-in HLSL lacks
// (umulExtended); nothing of the tracer is written twice, so the two cannot
// drift.
//
// The includer declares, before including (as for linear_rt.glsl):
//   #include "linear_rt.h" with LRT_GLSL defined (its >>contract block only)
//   #define LRT_DEPTH_IMAGE 0 or 1
//   #define LRT_NODE_WORD(i)      word i of the node array: nodes.Load((i) * 4)
//   (optional: LRT_NODE_QUAD(i), the same array as uint4: nodes.Load4((i) * 16))
//   #define LRT_DEPTH_WORD(i)     word i of the depth buffer (LRT_DEPTH_IMAGE 0)
//   #define LRT_DEPTH_TEXEL(x, y) depth.Load(int3(x, y, 0)).r (LRT_DEPTH_IMAGE 1)
//   and for a back-map tree LRT_BACK_WORD(i) / LRT_BACK_TEXEL(x, y), and
//   #define LRT_BACK_TREES false where no tree with a thickness model is traced
//   (LRT_INFINITE_TREES false where only such trees are)
// then calls lrt_trace_ray(p, origin, tmin, dir, tmax) with an LrtParams p
// (the first fields of the contract's push constants; a constant buffer or
// push constants of the includer's own).
//
// Written for glslang's HLSL front end (tested here: HLSL -> SPIR-V on
// lavapipe) and Shader Model 6.0 HLSL as DXC reads it (not tested here: no
// DXC on this machine). Avoided for that: 64-bit integers (the 32 x 32-bit
// product is four 16-bit ones below), half precision, mad() and any
// intrinsic that may fuse; vector constructors from one scalar; struct
// constructors. `precise` is HLSL's own keyword, with GLSL's meaning.

#ifndef LINEAR_RT_HLSL
#define LINEAR_RT_HLSL

#define vec2 float2
#define vec3 float3
#define vec4 float4
#define ivec2 int2
#define ivec3 int3
#define ivec4 int4
#define uvec2 uint2
#define uvec3 uint3
#define uvec4 uint4
#define bvec2 bool2
#define bvec3 bool3
#define floatBitsToUint asuint
#define floatBitsToInt asint
#define uintBitsToFloat asfloat
#define intBitsToFloat asfloat
// GLSL's findMSB is -1 for 0, as HLSL's firstbithigh (0xffffffff) read as an int
#define findMSB(x) int(firstbithigh(x))
#define findLSB(x) int(firstbitlow(x))

// GLSL's umulExtended: the 64-bit product of two 32-bit words, exactly,
// from four 16 x 16-bit products (no 64-bit integers needed)
void umulExtended(uint a, uint b, out uint hi, out uint lo)
{
    uint a0 = a & 0xffffu, a1 = a >> 16, b0 = b & 0xffffu, b1 = b >> 16;
    uint p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0, p11 = a1 * b1;
    uint mid = (p00 >> 16) + (p01 & 0xffffu) + (p10 & 0xffffu);
    lo = (mid << 16) | (p00 & 0xffffu);
    hi = p11 + (p01 >> 16) + (p10 >> 16) + (mid >> 16);
}

// GLSL's constants at file scope are HLSL's static const (the body's
// function-local ones are constant expressions: the same there)
#define const static const
#include "linear_rt.glsl"
#undef const

#endif // LINEAR_RT_HLSL
