// vkp_rq.glsl - what the two ray-query kernels share: the acceleration
// structure, the primitive -> texel table, and the set-up of the query's ray.
#extension GL_EXT_ray_query : require

layout(set = 0, binding = 3, std430) readonly buffer VkpTable { uint texel[]; } vkp_table;
layout(set = 0, binding = 5) uniform accelerationStructureEXT vkp_tlas;

// The query's interval ends a little past the ray's: lavapipe reports no
// candidate exactly at the query's tmax (a far-plane texel at t = tmax would
// be lost), and a triangle's t comes back with an error of a few ulps of the
// coordinates (relative to the origin's and the direction's scale, not to
// t). The margin: 1e-6 of t, or 4e-7 of the coordinates' scale along the
// ray, whichever is more (a few 1e-7 texel: well inside docs/MODEL.md's 1e-5).
float vkp_widen(float t, vec3 o, vec3 v)
{
    float m = max(max(abs(v.x), abs(v.y)), abs(v.z));
    float c = 1.0 + max(max(abs(o.x), abs(o.y)), abs(o.z));
    return t + max(max(abs(t) * 1e-6, m > 0.0 ? 4e-7 * c / m : 0.0), 1e-30);
}

// The query's ray: the clipped interval [t0, t1] of the given ray, on the
// ray itself when its origin is in the screen box (t0 == tmin), else on the
// ray re-based at its entry point (t0 becomes 0) so that a far-away origin
// does not cost the query its precision. Reported t = base + the query's t.
struct VkpQuery {
    vec3 o;      // the query's origin
    float base;  // t of the query's origin on the given ray
    float s0, s1;// the clipped interval in the query's t
    vec3 p0;     // the point at s0
};

// A query ray that does not move along an axis and lies exactly in a plane
// of the boxes there (x or y an integer: a cell edge; z: a texel top) makes
// the traversal's slab test compute 0 * inf = NaN, and lavapipe then drops
// the boxes on both sides. Such an origin component is moved by one ulp
// (into the screen, or towards the far plane for z), which docs/MODEL.md's
// tolerance allows (the answer is exact for that ray). z only for boxes: a
// triangle query nudged onto a texel top would lie in its plane.
float vkp_off_plane(float o, float v, float hi, bool integer_planes)
{
    if (!(v == 0.0 || vkp_nonfinite(1.0 / v))) return o;
    if (integer_planes && o != floor(o)) return o;
    if (o >= hi) return uintBitsToFloat(floatBitsToUint(o) - 1u);
    if (o == 0.0) return 1e-30;
    return o > 0.0 ? uintBitsToFloat(floatBitsToUint(o) + 1u) : o;
}

VkpQuery vkp_query(VkpRay r, float t0, float t1, bool nudge_z)
{
    VkpQuery q;
    if (t0 > r.tmin) {
        q.o = r.o + t0 * r.v;
        q.base = t0;
        q.s0 = 0.0;
        q.s1 = t1 - t0;
        q.p0 = q.o;
    } else {
        q.o = r.o;
        q.base = 0.0;
        q.s0 = t0;
        q.s1 = t1;
        q.p0 = r.o + t0 * r.v;
    }
    q.o.x = vkp_off_plane(q.o.x, r.v.x, float(pc.width), true);
    q.o.y = vkp_off_plane(q.o.y, r.v.y, float(pc.height), true);
    if (nudge_z) q.o.z = vkp_off_plane(q.o.z, r.v.z, 1.0, false);
    return q;
}

uint vkp_texel_x(uint texel) { return texel % pc.width; }
uint vkp_texel_y(uint texel) { return texel / pc.width; }
