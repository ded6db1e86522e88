#version 450
#extension GL_GOOGLE_include_directive : require
// lrt_refit.comp - BuildBVH and UpdateBVH of the design in one dispatch.
//
// Invocation i refits one level-2 node above the texel rectangle (8x8
// texels): its 8 level-1 children from the texels, then itself. It then
// climbs: after its node is written (and a buffer barrier), it counts itself
// in at its parent; the invocation that completes the parent's count of
// children inside the rectangle resets the counter, reads all 8 children and
// writes the parent, and so on to the root. Nobody waits for anybody, so the
// one dispatch is correct on any GPU (and has no workgroup barrier, which
// CPU implementations such as lavapipe pay dearly for). Heights may fall as
// well as rise: a parent is recomputed from its children, never max-ed with
// its old value. Children outside the rectangle keep their codes (their
// heights are read back); padding children are written (as 0) on a build.
// A back-map tree (thickness) refits its back codes (after all the heights,
// lrt_back_codes) alongside, the same way: a parent's is the max of its
// children's. An 8-bit tree's level-1 nodes are compact words
// (lrt_compact_word), each node's own height in its level-2 parent; for a
// child outside the rectangle that height is read from the parent as it is.
#include "lrt_common.glsl"

layout(set = 0, binding = LRT_K_VK_BINDING_COUNTERS, std430) coherent buffer LrtCounters { uint c[]; } lrt_counters;

// writes 8 codes as node `slot0` (code units)
void lrt_store_node(uint slot0, uint codes[8])
{
    for (uint k = 0u; k < 4u; ++k) lrt_nodes.words[(slot0 >> 1) + k] = codes[2u * k] | (codes[2u * k + 1u] << 16);
}

// a padding node: all codes 0 (written on a build only)
void lrt_store_zero_node(uint slot0)
{
    uint zero[8] = uint[8](0u, 0u, 0u, 0u, 0u, 0u, 0u, 0u);
    lrt_store_node(slot0, zero);
}

// the largest of node `slot0`'s 8 codes: that node's own height
uint lrt_node_max(uint slot0)
{
    uint m = 0u;
    for (uint k = 0u; k < 8u; ++k) m = max(m, lrt_code(slot0 + k));
    return m;
}

// max of 8 codes: the height of their node
uint lrt_codes_max(uint codes[8])
{
    uint m = 0u;
    for (uint k = 0u; k < 8u; ++k) m = max(m, codes[k]);
    return m;
}

// a compact level-1 node's scale and word (linear_rt.h's
// lrt__compact_scale and lrt__compact_bounds / _steps): the scale 16 (h -
// lowest) / 15 within [16, 65535], and per texel the greatest 4-bit step j
// with (j * scale) >> 4 <= h - code, down from its height h
uint lrt_compact_scale(uint codes[8], uint h)
{
    uint low = 65535u;
    for (uint k = 0u; k < 8u; ++k) low = min(low, codes[k]);
    return clamp((h - low) * 16u / 15u, 16u, 65535u);
}

uint lrt_compact_word(uint codes[8], uint h, uint scale)
{
    uint word = 0u;
    for (uint k = 0u; k < 8u; ++k) {
        // bit by bit from the top: no integer division (lavapipe runs one per lane)
        uint j = 0u;
        for (uint b = 8u; b != 0u; b >>= 1) j += ((j + b) * scale) >> 4 <= h - codes[k] ? b : 0u;
        word |= j << (4u * k);
    }
    return word;
}

// the scales of a level-2 node's 8 children, level-1 nodes k0 to k0 + 7
// (k0 a multiple of 8: four whole words, this invocation's alone), of the
// codes that start at code index `at` (0, or the back codes')
void lrt_store_scales(LrtParams p, uint at, uint k0, uint scales[8])
{
    uint slot = at + lrt_compact_scale_slot(p, k0);
    for (uint k = 0u; k < 4u; ++k) lrt_nodes.words[(slot >> 1) + k] = scales[2u * k] | (scales[2u * k + 1u] << 16);
}

void main()
{
    LrtParams p = lrt_params();
    bool back = lrt_has_back(p);
    uint bb = back ? lrt_back_codes(p) : 0u; // the back codes' first slot
    uint bcodes[8], bheights[8];
    // the rectangle at level 1 and at level 2 (one level-2 node: 2x4 level-1 nodes, 8x8 texels)
    uint x0 = pc.rect_x0 >> 2, x1 = pc.rect_x1 >> 2, y0 = pc.rect_y0 >> 1, y1 = pc.rect_y1 >> 1;
    uint cols = (x1 >> 1) - (x0 >> 1) + 1u, idx = lrt_invocation();
    if (idx >= cols * ((y1 >> 2) - (y0 >> 2) + 1u)) return;
    uint nx = (x0 >> 1) + idx % cols, ny = (y0 >> 2) + idx / cols;
    uint w1 = (p.width + 3u) >> 2, h1 = (p.height + 1u) >> 1, codes[8], heights[8], scales[8], bscales[8];
    if (p.level_count == 1u) { // the one level-1 node is the root
        for (uint s = 0u; s < 8u; ++s) {
            uint tx = s & 3u, ty = s >> 2;
            bool real = tx < p.width && ty < p.height;
            codes[s] = real ? lrt_texel_code(p, tx, ty) : 0u;
            bcodes[s] = real && back ? lrt_texel_back_code(p, tx, ty) : 0u;
        }
        lrt_store_node(0u, codes);
        if (back) lrt_store_node(bb, bcodes);
        return;
    }
    // level 1 starts the node array; node (nx, ny) of level 2 has its 8
    // children (2x4) at block nx + ny * w2 of it
    // (level offsets and grid sizes by arithmetic, as the walk takes them:
    // a per-level table is an array lavapipe keeps in memory)
    uint w2 = (w1 + 1u) >> 1;
    uint block = (ny * w2 + nx) * 64u;
    uint off = lrt_level_slots(p, 1u); // level 2's first node
    uint node = lrt_node_code0(p, 2u, off, nx, ny);
    bool compact = lrt_compact(p);
    for (uint c = 0u; c < 8u; ++c) {
        uint cx = nx * 2u + (c & 1u), cy = ny * 4u + (c >> 1), slot0 = block + c * 8u;
        if (cx >= w1 || cy >= h1) { // a padding child: height 0, its node 0 on a build
            heights[c] = bheights[c] = 0u;
            scales[c] = bscales[c] = 16u; // (lrt_compact_scale of 8 codes 0, as the CPU's build writes it)
            if (pc.build != 0u && compact) {
                lrt_nodes.words[slot0 >> 3] = 0u;
                if (back) lrt_nodes.words[(bb >> 1) + (slot0 >> 3)] = 0u;
            } else if (pc.build != 0u) {
                lrt_store_zero_node(slot0);
                if (back) lrt_store_zero_node(bb + slot0);
            }
        } else if (cx < x0 || cx > x1 || cy < y0 || cy > y1) { // outside the rectangle: as it is
            heights[c] = compact ? lrt_code(node + c) : lrt_node_max(slot0);
            bheights[c] = !back ? 0u : compact ? lrt_code(bb + node + c) : lrt_node_max(bb + slot0);
            scales[c] = compact ? lrt_code(lrt_compact_scale_slot(p, slot0 >> 3)) : 0u;
            bscales[c] = compact && back ? lrt_code(bb + lrt_compact_scale_slot(p, slot0 >> 3)) : 0u;
        } else {
            for (uint s = 0u; s < 8u; ++s) {
                uint tx = cx * 4u + (s & 3u), ty = cy * 2u + (s >> 2);
                bool real = tx < p.width && ty < p.height;
                codes[s] = real ? lrt_texel_code(p, tx, ty) : 0u;
                bcodes[s] = real && back ? lrt_texel_back_code(p, tx, ty) : 0u;
            }
            heights[c] = lrt_codes_max(codes);
            bheights[c] = lrt_codes_max(bcodes);
            if (compact) {
                scales[c] = lrt_compact_scale(codes, heights[c]);
                bscales[c] = back ? lrt_compact_scale(bcodes, bheights[c]) : 0u;
                lrt_nodes.words[slot0 >> 3] = lrt_compact_word(codes, heights[c], scales[c]);
                if (back) lrt_nodes.words[(bb >> 1) + (slot0 >> 3)] = lrt_compact_word(bcodes, bheights[c], bscales[c]);
            } else {
                lrt_store_node(slot0, codes);
                if (back) lrt_store_node(bb + slot0, bcodes);
            }
        }
    }
    if (compact) { // the 8 children's scales, those outside the rectangle as they were
        lrt_store_scales(p, 0u, block >> 3, scales);
        if (back) lrt_store_scales(p, bb, block >> 3, bscales);
    }
    lrt_store_node(node, heights);
    if (back) lrt_store_node(bb + node, bheights);
    if (p.level_count == 2u) return;

    // climb: count in at the parent; its counter is indexed by the parent's
    // block of children, level lv's first node of that block
    x0 >>= 1;
    x1 >>= 1;
    y0 >>= 2;
    y1 >>= 2;
    for (uint lv = 2u; lv < p.level_count; ++lv) {
        uint bwl = lrt_bw_log2(lv), bhl = lrt_bh_log2(lv);
        uint px = nx >> bwl, py = ny >> bhl;
        uint counter = off + (py * lrt_grid_w(p.width, lv + 1u) + px) * 8u;
        // the parent's children inside this level's rectangle: how many arrive
        uint cx0 = max(px << bwl, x0), cx1 = min(((px + 1u) << bwl) - 1u, x1);
        uint cy0 = max(py << bhl, y0), cy1 = min(((py + 1u) << bhl) - 1u, y1);
        uint expected = (cx1 - cx0 + 1u) * (cy1 - cy0 + 1u);
        memoryBarrierBuffer(); // our node before our arrival
        if (atomicAdd(lrt_counters.c[counter], 1u) + 1u != expected) return;
        atomicExchange(lrt_counters.c[counter], 0u); // ready for the next dispatch
        memoryBarrierBuffer(); // the siblings' nodes after their arrivals
        // children of (px, py) are contiguous: level lv's block of the parent
        uint first_child = counter * 8u - (compact ? lrt_level_slots(p, 1u) * 5u : 0u); // (lrt_node_code0)
        for (uint s = 0u; s < 8u; ++s) {
            uint cx = (px << bwl) + (bwl == 2u ? (s & 3u) : (s & 1u));
            uint cy = (py << bhl) + (bwl == 2u ? (s >> 2) : (s >> 1));
            if (cx < lrt_grid_w(p.width, lv) && cy < lrt_grid_h(p.height, lv)) {
                codes[s] = lrt_node_max(first_child + s * 8u);
                bcodes[s] = back ? lrt_node_max(bb + first_child + s * 8u) : 0u;
            } else { // a padding child: height 0, and on a build its node is 0 too
                codes[s] = bcodes[s] = 0u;
                if (pc.build != 0u) lrt_store_zero_node(first_child + s * 8u);
                if (pc.build != 0u && back) lrt_store_zero_node(bb + first_child + s * 8u);
            }
        }
        off += lrt_level_slots(p, lv); // level lv + 1's first node
        node = lrt_node_code0(p, lv + 1u, off, px, py);
        lrt_store_node(node, codes);
        if (back) lrt_store_node(bb + node, bcodes);
        nx = px;
        ny = py;
        x0 >>= bwl;
        x1 >>= bwl;
        y0 >>= bhl;
        y1 >>= bhl;
    }
}
