#version 460
#extension GL_GOOGLE_include_directive : require
// vkp_dda.comp - a per-pixel DDA march with a thickness, after McGuire and
// Mara (scored, not exact): bench/march_cpu.c's "dda cpu" (stride 1) in
// float. The clipped segment [t0, t1] (parameter s in [0, 1]) is walked
// along its major screen axis one pixel column (row) at a time: a step is
// the stretch [sa, sb] of the segment inside one column, in the order the
// ray crosses them (a segment with no motion on the screen: one step over
// all of it). The step samples the texel under the middle of its stretch
// and reads its depth d; over the stretch the ray's depth covers
// [zlo, zhi]: a hit is zhi >= d (less vkp_common.glsl's bias) and
// zlo <= d + 0.02, the surface being taken as 0.02 deep. The reported t is
// where the ray enters [d, d + 0.02] within the stretch, the texel the one
// sampled. At most max(W, H) steps; a walk that ends without a hit misses,
// its kind by docs/MODEL.md's rule.
#include "vkp_common.glsl"

const float VKP_THICKNESS = 0.02;

// the clipped segment: p0 + s dl, s in [0, 1]; a: its major coordinate at
// s = 0, da its change, ida = 1 / da
struct VkpLine {
    vec3 p0, dl;
    float a0, da, ida;
};

// s where the line's major coordinate is e, clamped to [0, 1]
float vkp_line_s(VkpLine L, float e) { return clamp((e - L.a0) * L.ida, 0.0, 1.0); }

// the stretch [sa, sb] against the texel under its middle; on a hit, sh is
// where the ray enters [d, d + thickness]
bool vkp_dda_test(VkpLine L, float sa, float sb, out uint i, out uint j, out float sh)
{
    float s = 0.5 * (sa + sb);
    i = vkp_cell(L.p0.x + s * L.dl.x, pc.width);
    j = vkp_cell(L.p0.y + s * L.dl.y, pc.height);
    float d = vkp_depth_at(i, j);
    // a scene's own thickness where it has one (its back depths), as the CPU's DDA
    float th = (pc.flags & VKP_FLAG_BACK) != 0u ? vkp_back_at(i, j) - d : VKP_THICKNESS;
    float za = L.p0.z + sa * L.dl.z, zb = L.p0.z + sb * L.dl.z;
    sh = sa;
    if (!(vkp_behind(max(za, zb), d) && min(za, zb) <= d + th)) return false;
    if (!(vkp_behind(za, d) && za <= d + th))
        sh = clamp(sa + ((za < d ? d : d + th) - za) / (zb - za) * (sb - sa), sa, sb);
    return true;
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
    VkpLine L;
    L.p0 = r.o + t0 * r.v;
    L.dl = (r.o + t1 * r.v) - L.p0;
    bool y_major = abs(L.dl.y) > abs(L.dl.x);
    L.a0 = y_major ? L.p0.y : L.p0.x;
    L.da = y_major ? L.dl.y : L.dl.x;
    L.ida = L.da != 0.0 ? 1.0 / L.da : 0.0;
    float a1 = L.a0 + L.da;
    // the columns [c, c+1] the segment passes, c0 first, n of them, sg the direction
    int c0 = 0, n = 1, sg = 0;
    if (L.da > 0.0) {
        c0 = int(floor(L.a0));
        n = int(ceil(a1)) - c0;
        sg = 1;
    } else if (L.da < 0.0) {
        c0 = int(ceil(L.a0)) - 1;
        n = c0 - int(floor(a1)) + 1;
        sg = -1;
    }
    n = min(max(n, 1), int(max(pc.width, pc.height)));
    float edge = sg < 0 ? 1.0 : 0.0;
    for (int k = 0; k < n; ++k) {
        float sa = 0.0, sb = 1.0, sh;
        uint i, j;
        if (sg != 0) {
            sa = vkp_line_s(L, float(c0 + sg * k) + edge);
            sb = vkp_line_s(L, float(c0 + sg * (k + 1)) + edge);
        }
        if (vkp_dda_test(L, sa, sb, i, j, sh)) {
            vkp_hits.h[ri] = vkp_march_hit(r, t0 + sh * (t1 - t0), i, j);
            return;
        }
    }
    vkp_hits.h[ri] = vkp_miss(r);
}
