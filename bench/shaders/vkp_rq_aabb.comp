#version 460
#extension GL_GOOGLE_include_directive : require
// vkp_rq_aabb.comp - a generic ray-query BVH over the depth map: one
// procedural AABB per texel box [i,i+1] x [j,j+1] x [d,b] (b: 1, or the
// texel's back depth with a thickness; primitive k is
// texel table[k], in Z order), one TLAS instance. Each AABB candidate gets
// the exact slab test of its box; the smallest entry t is committed (closest
// hit), or the first one ends the query (pc.flags bit 0: any hit).
#include "vkp_common.glsl"
#include "vkp_rq.glsl"

// Entry t of the ray o + t v into the box [lo, hi] within [ta, tb]: docs/MODEL.md's
// plane crossings (plane - o) * (1 / v), and a zero component tested by o.
bool vkp_box(vec3 o, vec3 v, vec3 iv, vec3 lo, vec3 hi, float ta, float tb, out float te)
{
    float t0 = ta, t1 = tb;
    bool ok = true;
    for (int c = 0; c < 3; ++c) {
        if (v[c] == 0.0 || vkp_nonfinite(iv[c])) {
            ok = ok && o[c] >= lo[c] && o[c] <= hi[c];
        } else {
            precise float a = (lo[c] - o[c]) * iv[c];
            precise float b = (hi[c] - o[c]) * iv[c];
            t0 = max(t0, min(a, b));
            t1 = min(t1, max(a, b));
        }
    }
    te = t0;
    return ok && t0 <= t1;
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
    VkpQuery s = vkp_query(r, t0, t1, true);
    uint hx, hy;
    if (r.v == vec3(0.0)) { // a point: in the solid or not
        vkp_hits.h[ri] = vkp_inside(r.o, r.v, t0, hx, hy) ? vkp_hit(t0, hx, hy) : vkp_miss(r);
        return;
    }
    vec3 iv = 1.0 / r.v; // a component whose reciprocal overflows: as 0 in vkp_box
    bool found = false;
    float best = s.s1;
    uint best_texel = 0u;
    rayQueryEXT q;
    // widened at both ends (boxes exactly at an end are reported); the exact
    // test clips every entry to the real [s0, s1]
    rayQueryInitializeEXT(q, vkp_tlas, (pc.flags & 1u) != 0u ? gl_RayFlagsTerminateOnFirstHitEXT : gl_RayFlagsNoneEXT,
                          0xffu, s.o, max(s.s0 - max(abs(s.s0) * 1e-6, 1e-30), 0.0), r.v, vkp_widen(s.s1, s.o, r.v));
    while (rayQueryProceedEXT(q)) {
        if (rayQueryGetIntersectionTypeEXT(q, false) != gl_RayQueryCandidateIntersectionAABBEXT) continue;
        uint texel = vkp_table.texel[rayQueryGetIntersectionPrimitiveIndexEXT(q, false)];
        uint i = vkp_texel_x(texel), j = vkp_texel_y(texel);
        vec3 lo = vec3(float(i), float(j), vkp_depth.depth[texel]);
        vec3 hi = vec3(float(i + 1u), float(j + 1u), vkp_back_at(i, j));
        float te;
        if (vkp_box(s.o, r.v, iv, lo, hi, s.s0, best, te) && (!found || te < best)) {
            found = true;
            best = te;
            best_texel = texel;
            rayQueryGenerateIntersectionEXT(q, te);
        }
    }
    vkp_hits.h[ri] = found ? vkp_hit(s.base + best, vkp_texel_x(best_texel), vkp_texel_y(best_texel)) : vkp_miss(r);
}
