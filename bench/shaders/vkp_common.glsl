// vkp_common.glsl - what every Vulkan peer of the benchmark shares (ray-query
// BVHs and screen-space marches, bench/m_vk_peers.c): the buffers, the push
// constants, and docs/MODEL.md's rules for invalid rays, the two kinds of miss and
// the clip of a ray to the screen box. Included by each bench/shaders/vkp_*.comp.
//
// Bindings (set 0; a kernel declares only those it uses):
//   0 depth   float per texel, row 0 first, 0 near (standard Z, already clamped);
//             with a thickness (pc.flags bit 1) then each texel's back depth
//             b = max(depth, back), the box [d, b]
//   1 rays    lrt_ray  {vec3 origin; float tmin; vec3 dir; float tmax;}
//   2 hits    lrt_hit  {float t; uint x, y, kind;} (kind < 2^16: the face half is 0, not reported)
//   3 table   uint per primitive: the texel (y*width + x) it belongs to
//   4 aux     float or AABB storage: AABBs written from depth, or Hi-Z mips
//   5 tlas    the top-level acceleration structure (ray-query kernels)

layout(local_size_x = 64) in;

layout(push_constant, std430) uniform VkpPush {
    uint width, height;     // texels
    uint ray_first;         // first ray of this dispatch
    uint ray_count;         // rays in this dispatch (or texels of the level being written)
    uint flags;             // bit 0: any hit will do (occlusion); bit 1: back depths follow
    uint level_count;       // Hi-Z: levels, level 0 being the depth map itself
    uint level;             // Hi-Z mip build: the level written
    uint pad;
    uint offsets[16];       // Hi-Z: float offset of level k (k >= 1) in aux
} pc;

struct VkpRay {
    vec3 o;
    float tmin;
    vec3 v;
    float tmax;
};
struct VkpHit {
    float t;
    uint x, y, kind;
};

const uint VKP_HIT = 1u;
const uint VKP_MISS_TMAX = 2u;
const uint VKP_MISS_OFF_SCREEN = 3u;
const uint VKP_MISS_INVALID = 4u;

layout(set = 0, binding = 0, std430) readonly buffer VkpDepth { float depth[]; } vkp_depth;
layout(set = 0, binding = 1, std430) readonly buffer VkpRays { VkpRay r[]; } vkp_rays;
layout(set = 0, binding = 2, std430) writeonly buffer VkpHits { VkpHit h[]; } vkp_hits;

float vkp_depth_at(uint x, uint y) { return vkp_depth.depth[y * pc.width + x]; }
const uint VKP_FLAG_BACK = 2u;
// the back of texel (x, y): its back depth with a thickness, else 1 (infinite)
float vkp_back_at(uint x, uint y)
{
    return (pc.flags & VKP_FLAG_BACK) != 0u ? vkp_depth.depth[(pc.height + y) * pc.width + x] : 1.0;
}

// a NaN or an infinity (read from the bits: no fast-math assumption can drop it)
bool vkp_nonfinite(float f) { return (floatBitsToUint(f) & 0x7f800000u) == 0x7f800000u; }

bool vkp_invalid(VkpRay r)
{
    bool bad = vkp_nonfinite(r.o.x) || vkp_nonfinite(r.o.y) || vkp_nonfinite(r.o.z) || vkp_nonfinite(r.v.x) ||
               vkp_nonfinite(r.v.y) || vkp_nonfinite(r.v.z) || vkp_nonfinite(r.tmin) || vkp_nonfinite(r.tmax);
    return bad || !(r.tmin >= 0.0) || !(r.tmin <= r.tmax);
}

VkpHit vkp_hit(float t, uint x, uint y) { return VkpHit(t, x, y, VKP_HIT); }

// a march's hit: t clamped to the ray's [tmin, tmax], as the CPU marches do
VkpHit vkp_march_hit(VkpRay r, float t, uint x, uint y) { return VkpHit(clamp(t, r.tmin, r.tmax), x, y, VKP_HIT); }

// docs/MODEL.md: a miss is a tmax miss when the point at tmax lies in the closed
// screen rectangle (x and y only), else the ray left the screen.
VkpHit vkp_miss(VkpRay r)
{
    precise float x = r.o.x + r.tmax * r.v.x;
    precise float y = r.o.y + r.tmax * r.v.y;
    bool on = x >= 0.0 && x <= float(pc.width) && y >= 0.0 && y <= float(pc.height);
    return VkpHit(0.0, 0u, 0u, on ? VKP_MISS_TMAX : VKP_MISS_OFF_SCREEN);
}

// [t0, t1] narrowed to where lo <= o + t v <= hi; false if never. Crossings
// are (plane - o) * (1 / v), the arithmetic of the AABB kernel's box test, so
// that a box face on the screen box's (the far plane) meets the clipped end
// exactly. A v whose reciprocal overflows moves the ray by less than any
// rounding: it counts as 0.
bool vkp_slab(float lo, float hi, float o, float v, inout float t0, inout float t1)
{
    float iv = 1.0 / v;
    if (v == 0.0 || vkp_nonfinite(iv)) return o >= lo && o <= hi;
    precise float a = (lo - o) * iv;
    precise float b = (hi - o) * iv;
    t0 = max(t0, min(a, b));
    t1 = min(t1, max(a, b));
    return true;
}

// The ray's interval clipped to the screen box [0,W] x [0,H] x [0,1], which
// holds every texel box; false if it never meets it.
bool vkp_clip(VkpRay r, out float t0, out float t1)
{
    t0 = r.tmin;
    t1 = r.tmax;
    bool ok = vkp_slab(0.0, float(pc.width), r.o.x, r.v.x, t0, t1);
    ok = vkp_slab(0.0, float(pc.height), r.o.y, r.v.y, t0, t1) && ok;
    ok = vkp_slab(0.0, 1.0, r.o.z, r.v.z, t0, t1) && ok;
    return ok && t0 <= t1;
}

// The marches' depth test: z at or behind d. On the far plane (d = 1) less a
// bias of 1e-6, the guard against float rounding that the CPU marches of
// bench/march_cpu.c and examples/march.h, in double, do without: a ray that
// ends exactly on the far plane, z = 1 at the clipped end t1, computes z a
// few ulps short of it in float. Nowhere else: a ray lifted off its own
// surface by less than the bias (the examples' lift on flat or
// 16-bit-quantised far surfaces can be 1e-7) would otherwise hit itself at
// once.
const float VKP_DEPTH_BIAS = 1e-6;
bool vkp_behind(float z, float d) { return z >= (d >= 1.0 ? d - VKP_DEPTH_BIAS : d); }

// the texel column (or row) under a screen coordinate, clamped to the map
uint vkp_cell(float c, uint n) { return uint(clamp(floor(c), 0.0, float(n - 1u))); }

// Is p in the solid? Every texel whose closed footprint holds p.xy (up to 4
// on an edge or a corner) is asked; the first that holds p gives the texel.
bool vkp_inside_point(vec3 p, out uint hx, out uint hy)
{
    hx = 0u;
    hy = 0u;
    if (!(p.x >= 0.0 && p.x <= float(pc.width) && p.y >= 0.0 && p.y <= float(pc.height) && p.z <= 1.0))
        return false;
    uint i1 = vkp_cell(p.x, pc.width), j1 = vkp_cell(p.y, pc.height);
    uint i0 = (float(i1) == p.x && i1 > 0u) ? i1 - 1u : i1;
    uint j0 = (float(j1) == p.y && j1 > 0u) ? j1 - 1u : j1;
    for (uint j = j0; j <= j1; ++j)
        for (uint i = i0; i <= i1; ++i)
            if (p.z >= vkp_depth_at(i, j) && p.z <= vkp_back_at(i, j)) {
                hx = i;
                hy = j;
                return true;
            }
    return false;
}

// lo <= o + t v, decided on o - lo and the fused t v: the sign of the exact
// value whenever o - lo is exact (o and lo within a factor 2: a point near
// the plane), where rounding o + t v first could cross the plane.
bool vkp_at_or_past(float o, float v, float t, float lo)
{
    precise float e = fma(t, v, o - lo);
    return e >= 0.0;
}

// Is the point at t of the ray o + t v in the solid? As vkp_inside_point, but
// each face of a candidate box decided by vkp_at_or_past: a ray that starts
// a hair above a texel top is not rounded into it.
bool vkp_inside(vec3 o, vec3 v, float t, out uint hx, out uint hy)
{
    vec3 p = o + t * v;
    hx = 0u;
    hy = 0u;
    if (!(abs(p.x) < 3.0e38 && abs(p.y) < 3.0e38 && abs(p.z) < 3.0e38)) return false;
    float ex = 1e-5 * (1.0 + abs(p.x)), ey = 1e-5 * (1.0 + abs(p.y));
    uint i0 = vkp_cell(p.x - ex, pc.width), i1 = vkp_cell(p.x + ex, pc.width);
    uint j0 = vkp_cell(p.y - ey, pc.height), j1 = vkp_cell(p.y + ey, pc.height);
    if (!vkp_at_or_past(-o.z, -v.z, t, -1.0)) return false; // z <= 1
    for (uint j = j0; j <= j1; ++j)
        for (uint i = i0; i <= i1; ++i)
            if (vkp_at_or_past(o.x, v.x, t, float(i)) && vkp_at_or_past(-o.x, -v.x, t, -float(i + 1u)) &&
                vkp_at_or_past(o.y, v.y, t, float(j)) && vkp_at_or_past(-o.y, -v.y, t, -float(j + 1u)) &&
                vkp_at_or_past(o.z, v.z, t, vkp_depth_at(i, j)) && vkp_at_or_past(-o.z, -v.z, t, -vkp_back_at(i, j))) {
                hx = i;
                hy = j;
                return true;
            }
    return false;
}
