// lrt_common.glsl - the bindings and push constants of linear_rt's own
// kernels (shaders/README.md), then the shared code of linear_rt.glsl.


// the host/shader contract: linear_rt.h's >>contract block, read here
#define LRT_GLSL 1
#include "../linear_rt.h"

layout(local_size_x = LRT_K_VK_GROUP_SIZE) in;

layout(push_constant) uniform LrtPush { LRT_K_VK_PUSH_CONSTANTS(uint, float) } pc;

#if LRT_DEPTH_IMAGE
layout(set = 0, binding = LRT_K_VK_BINDING_DEPTH_IMAGE) uniform sampler2D lrt_depth_image;
#define LRT_DEPTH_TEXEL(x, y) texelFetch(lrt_depth_image, ivec2(int(x), int(y)), 0).r
// a back-map tree's back map (thickness): the depth again when there is none
layout(set = 0, binding = LRT_K_VK_BINDING_BACK_IMAGE) uniform sampler2D lrt_back_image;
#define LRT_BACK_TEXEL(x, y) texelFetch(lrt_back_image, ivec2(int(x), int(y)), 0).r
#else
layout(set = 0, binding = LRT_K_VK_BINDING_DEPTH_BUFFER, std430) readonly buffer LrtDepth { uint words[]; } lrt_depth;
#define LRT_DEPTH_WORD(i) lrt_depth.words[i]
layout(set = 0, binding = LRT_K_VK_BINDING_BACK_BUFFER, std430) readonly buffer LrtBack { uint words[]; } lrt_back;
#define LRT_BACK_WORD(i) lrt_back.words[i]
#endif
// the refit reads nodes other invocations wrote (coherent); the trace kernel
// only reads them (lrt_trace.comp defines readonly: a GPU may cache them)
#ifndef LRT_NODES_ACCESS
#define LRT_NODES_ACCESS coherent
#endif
layout(set = 0, binding = LRT_K_VK_BINDING_NODES, std430) LRT_NODES_ACCESS buffer LrtNodes { uint words[]; } lrt_nodes;
#define LRT_NODE_WORD(i) lrt_nodes.words[i]
// the trace kernel reads a node's codes in one uvec4 load: through a texel
// view of the same buffer where the host says so (lrt_node_texels: llvmpipe
// reads a texel buffer without a branch per lane; single words read so did
// not gain), else from the storage buffer (a device with small texel
// buffers)
#ifdef LRT_NODES_QUADS
layout(set = 0, binding = LRT_K_VK_BINDING_NODES, std430) readonly buffer LrtNodeQuads { uvec4 quads[]; } lrt_node_quads;
layout(set = 0, binding = LRT_K_VK_BINDING_NODE_TEXELS) uniform utextureBuffer lrt_node_view;
layout(constant_id = 2) const bool lrt_node_texels = false;
uvec4 lrt_node_quad(uint i)
{
    if (lrt_node_texels) return texelFetch(lrt_node_view, int(i));
    return lrt_node_quads.quads[i];
}
#define LRT_NODE_QUAD(i) lrt_node_quad(i)
#endif

// back-map trees get pipelines of their own (the host sets this to true for
// them): with false the back code folds away, so other trees pay nothing
layout(constant_id = 0) const bool lrt_back_trees = false;
#define LRT_BACK_TREES lrt_back_trees
#define LRT_INFINITE_TREES (!lrt_back_trees) // the host picks these pipelines for thickness trees alone
// and their node width (8: a compact level 1, or 16): a constant, so the
// decoding folds
layout(constant_id = 1) const uint lrt_back_node_bits = 16u;

#include "linear_rt.glsl"

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

// this invocation's index in a 1D or 2D dispatch of LRT_K_VK_GROUP_SIZE-wide groups
uint lrt_invocation()
{
    return (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * LRT_K_VK_GROUP_SIZE + gl_LocalInvocationID.x;
}
