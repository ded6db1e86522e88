#version 460
#extension GL_GOOGLE_include_directive : require
// vkp_rq_tri.comp - a generic ray-query BVH over the same solid as opaque
// triangles: texel tops (two triangles at z = d), the vertical walls between
// neighbours of different depth, and the walls on the screen border
// (primitive k belongs to texel table[k]: a wall to the nearer texel), in Z
// order. The query finds the closest triangle (or, pc.flags bit 0, any).
// A ray that starts in the solid touches no triangle first: the texels under
// its first point are tested before the query (lavapipe reports no triangle
// exactly at the query's tmin either).
#include "vkp_common.glsl"
#include "vkp_rq.glsl"

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
    VkpQuery s = vkp_query(r, t0, t1, false);
    uint hx, hy;
    // in the solid at its first point: decided on the ray itself at tmin;
    // when clipped, on the (rounded) entry point into the screen box, clamped
    // onto the box when it is off by its rounding only (a point farther off,
    // from a far-away origin, is left where it is)
    vec3 entry = clamp(s.p0, vec3(0.0), vec3(float(pc.width), float(pc.height), 1.0));
    if (any(greaterThan(abs(entry - s.p0), vec3(1e-5) * (1.0 + abs(s.p0))))) entry = s.p0;
    if (t0 == r.tmin ? vkp_inside(r.o, r.v, t0, hx, hy) : vkp_inside_point(entry, hx, hy)) {
        vkp_hits.h[ri] = vkp_hit(t0, hx, hy);
        return;
    }
    if (r.v == vec3(0.0) || t0 == t1) { // a point: in the solid or not
        vkp_hits.h[ri] = vkp_miss(r);
        return;
    }
    // the query ends a little past the real end (vkp_widen): a hit there
    // counts as one at the end (the far plane met exactly at the end comes
    // back that far off)
    rayQueryEXT q;
    uint rflags = gl_RayFlagsOpaqueEXT | ((pc.flags & 1u) != 0u ? gl_RayFlagsTerminateOnFirstHitEXT : 0u);
    rayQueryInitializeEXT(q, vkp_tlas, rflags, 0xffu, s.o, s.s0, r.v, vkp_widen(s.s1, s.o, r.v));
    while (rayQueryProceedEXT(q)) {
    }
    if (rayQueryGetIntersectionTypeEXT(q, true) == gl_RayQueryCommittedIntersectionTriangleEXT) {
        float t = rayQueryGetIntersectionTEXT(q, true);
        uint texel = vkp_table.texel[rayQueryGetIntersectionPrimitiveIndexEXT(q, true)];
        vkp_hits.h[ri] = vkp_hit(s.base + min(t, s.s1), vkp_texel_x(texel), vkp_texel_y(texel));
        return;
    }
    vkp_hits.h[ri] = vkp_miss(r);
}
