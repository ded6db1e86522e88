#version 460
#extension GL_GOOGLE_include_directive : require
// vkp_march64.comp - the classic fixed-step linear march with binary
// refinement (scored, not exact): bench/march_cpu.c's "march64 cpu"
// (examples/march.h's march_linear) in float. The ray's interval clipped to
// the screen box [t0, t1] is cut into 64 equal steps; the samples at t0 + k
// (t1 - t0) / 64, k = 0..64, read the depth of the texel under the point. The
// first sample at or behind it (z >= depth, less vkp_common.glsl's bias, and
// z <= its back) ends the march: sample 0 is a hit at t0 (the ray starts
// inside); otherwise 8 bisection steps between the sample before (in front)
// and this one keep the one behind, and its t and texel are reported. A march
// that ends in front misses, its kind by docs/MODEL.md's rule.
#include "vkp_common.glsl"

const int VKP_STEPS = 64;
const int VKP_REFINE = 8;

bool vkp_solid(VkpRay r, float t, out uint i, out uint j)
{
    vec3 p = r.o + t * r.v;
    i = vkp_cell(p.x, pc.width);
    j = vkp_cell(p.y, pc.height);
    return vkp_behind(p.z, vkp_depth_at(i, j)) && p.z <= vkp_back_at(i, j); // inside [d, b]
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
    float prev = t0;
    for (int k = 0; k <= VKP_STEPS; ++k) {
        float t = k == VKP_STEPS ? t1 : t0 + (t1 - t0) * float(k) / float(VKP_STEPS);
        uint i, j;
        if (vkp_solid(r, t, i, j)) {
            float lo = prev, hi = t;
            if (k > 0)
                for (int b = 0; b < VKP_REFINE; ++b) {
                    float mid = 0.5 * (lo + hi);
                    uint mi, mj;
                    if (vkp_solid(r, mid, mi, mj)) {
                        hi = mid;
                        i = mi;
                        j = mj;
                    } else {
                        lo = mid;
                    }
                }
            vkp_hits.h[ri] = vkp_march_hit(r, hi, i, j);
            return;
        }
        prev = t;
    }
    vkp_hits.h[ri] = vkp_miss(r);
}
