#version 460
#extension GL_GOOGLE_include_directive : require
// vkp_hiz.comp - a hierarchical min-depth (Hi-Z) traversal with an iteration
// cap of 64, after AMD FidelityFX SSSR (scored, not exact):
// bench/march_cpu.c's "hiz64 cpu" in float. Level 0 is the depth map,
// level l+1 the 2x2 minimum of level l (vkp_hiz_mip.comp); a cell of level
// l covers texels [x 2^l, (x+1) 2^l) x [y 2^l, (y+1) 2^l), clipped to the map.
// The walk starts at level 0 at the clipped start t0; each iteration looks at
// the cell of the current level under the ray's point:
//   - the point at or behind the cell's min depth (less vkp_common.glsl's
//     bias): at level 0 a hit (the texel's box holds the point; with a
//     thickness, behind its back, on to the next texel); above, go down a
//     level;
//   - else, if the ray moves away from the camera and reaches the min depth
//     inside the cell and before t1: advance to it and go down a level (at
//     level 0 a hit there);
//   - else a segment ending inside the cell misses; otherwise advance to the
//     cell's exit and go up a level (the top level at most).
// The cell of a point just across a boundary is found with a nudge along the
// ray of max(W, H) * 2^-21 texel (a few ulps of the screen's coordinates: the
// CPU's 1e-6 texel, in double, would round away in float). After 64
// iterations the walk gives up: a miss of kind tmax, as the CPU's. t1 is
// allowed a relative 1e-6 of rounding (reaching the far plane exactly at the
// end is a hit at the end).
#include "vkp_common.glsl"
#include "vkp_hiz.glsl"

const uint VKP_ITERATIONS = 64u;

// t where the ray leaves [lo, hi] along one axis, moving with velocity v,
// iv = 1 / v: vkp_slab's arithmetic, so that a cell's exit on the screen's
// edge is exactly the clipped end t1
float vkp_exit(float lo, float hi, float o, float v, float iv)
{
    if (v == 0.0 || vkp_nonfinite(iv)) return 3.0e38;
    precise float e = ((v > 0.0 ? hi : lo) - o) * iv;
    return e;
}

void main()
{
    if (gl_GlobalInvocationID.x >= pc.ray_count) return;
    uint ri = pc.ray_first + gl_GlobalInvocationID.x;
    VkpRay r = vkp_rays.r[ri];
    float t0, t1;
    if (vkp_invalid(r)) {
        vkp_hits.h[ri] = VkpHit(0.0, 0u, 0u, VKP_MISS_INVALID);
        return;
    }
    if (!vkp_clip(r, t0, t1)) {
        vkp_hits.h[ri] = vkp_miss(r);
        return;
    }
    float e = float(max(pc.width, pc.height)) * (1.0 / 2097152.0);
    vec2 nudge = vec2(r.v.x > 0.0 ? e : r.v.x < 0.0 ? -e : 0.0, r.v.y > 0.0 ? e : r.v.y < 0.0 ? -e : 0.0);
    vec2 iv = 1.0 / r.v.xy;
    uint top = pc.level_count - 1u, level = 0u;
    float t = t0, t_end = t1 + abs(t1) * 1e-6;
    for (uint it = 0u; it < VKP_ITERATIONS; ++it) {
        vec3 p = r.o + t * r.v;
        float s = float(1u << level);
        uint cx = vkp_cell((p.x + nudge.x) / s, vkp_level_width(level));
        uint cy = vkp_cell((p.y + nudge.y) / s, vkp_level_height(level));
        float d = vkp_hiz_at(level, cx, cy);
        float tb = min(vkp_exit(float(cx) * s, float(cx + 1u) * s, r.o.x, r.v.x, iv.x),
                       vkp_exit(float(cy) * s, float(cy + 1u) * s, r.o.y, r.v.y, iv.y));
        if (vkp_behind(p.z, d)) {
            if (level > 0u) {
                --level;
                continue;
            }
            if (p.z <= vkp_back_at(cx, cy)) {
                vkp_hits.h[ri] = vkp_march_hit(r, t, cx, cy);
                return;
            }
            // behind this texel's back (thickness): on to the next texel
            if (tb >= t1) {
                vkp_hits.h[ri] = vkp_miss(r);
                return;
            }
            t = max(t, tb);
            continue;
        }
        float tz = r.v.z > 0.0 ? (d - r.o.z) / r.v.z : 3.0e38;
        if (tz <= tb && tz <= t_end) { // reaches the cell's min depth inside the cell
            t = max(t, tz);
            if (level == 0u) {
                vkp_hits.h[ri] = vkp_march_hit(r, min(t, t1), cx, cy);
                return;
            }
            --level;
            continue;
        }
        if (tb >= t1) { // ends in this cell, in front of all of it
            vkp_hits.h[ri] = vkp_miss(r);
            return;
        }
        t = max(t, tb);
        level = min(level + 1u, top);
    }
    vkp_hits.h[ri] = VkpHit(0.0, 0u, 0u, VKP_MISS_TMAX); // gave up at the cap
}
