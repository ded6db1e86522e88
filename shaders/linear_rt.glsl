// linear_rt.glsl - the BVH of linear_rt.h in GLSL: layout maths, Morton
// index, height codes, depth reads and the traversal (lrt_trace_ray), for the
// library's own kernels and for an engine shader that traces inline.
//
// The includer declares, before including:
//   #define LRT_GLSL 1 and #include "linear_rt.h" (its >>contract block: the
//     numbers host and shader share; the rest of that file is skipped)
//   #define LRT_DEPTH_IMAGE 0 or 1
//   #define LRT_NODE_WORD(i)      word i of the node array (uint)
//   (optional: LRT_NODE_QUAD(i), the same array read as uvec4: a node's
//   codes in one load, as lrt_common.glsl does; through a uniform texel
//   buffer where it can, which llvmpipe reads without a branch per lane)
//   #define LRT_DEPTH_WORD(i)     word i of the depth buffer (LRT_DEPTH_IMAGE 0)
//   #define LRT_DEPTH_TEXEL(x, y) texelFetch(depth, ivec2(x, y), 0).r (LRT_DEPTH_IMAGE 1)
// and passes an LrtParams (the first fields of the push constants of the
// contract). For a
// back-map tree (LrtParams.thickness LRT_THICKNESS_BACK_MAP) also
//   #define LRT_BACK_WORD(i) / LRT_BACK_TEXEL(x, y)  the back map, as the depth
// (without them such a tree cannot be traced here), and #define
// LRT_BACK_TREES false where no tree with a thickness model is traced: the
// back code folds away (LRT_INFINITE_TREES false where only such trees are:
// the cell walk does).
// Float and integer arithmetic only: no shaderFloat64, no reliance on fma.
//
// The numbers follow linear_rt.h step by step, so both paths give the same
// answers up to float rounding: every plane crossing the answer rests on is
// (plane - o) * (1/v) in float (a node's test only culls: plane * (1/v) + c
// with margins, as linear_rt.h's AVX2 node test); a is_unorm depth plane's
// distance v/max - o.z is taken exactly with Dekker's product (linear_rt.h
// uses double); a zero direction component is a closed slab (handled
// without NaN or inf arithmetic). The walk (lrt_trace_ray, below) starts at
// the ray's origin and needs no stack; it visits children in the CPU walk's
// front-to-back order, so the first texel hit is the closest and the CPU's.
// lrt_trace_ray_ordinary (a GPU's pass) walks one cell a step instead
// (lrt_walk_cells), in that same order, so it finds that same texel.
// lrt_trace_ray_budget caps the node tests of a ray as linear_rt.h's
// LRT_TRACE_BUDGET does, step for step (LRT_MISS_BUDGET, t proven free),
// and finishes it as LRT_TRACE_FINISH does (LRT_HIT_ESTIMATE).
// `precise` keeps compilers from fusing or reordering what must round the
// way it is written.

#ifndef LINEAR_RT_GLSL
#define LINEAR_RT_GLSL

// the numbers host and shader share: linear_rt.h's >>contract block
#ifndef LINEAR_RT_CONTRACT
#error "define LRT_GLSL and include linear_rt.h before linear_rt.glsl"
#endif
#define LRT_MAX_LEVELS int(LRT_K_MAX_LEVELS)
#define LRT_HIT LRT_K_HIT
#define LRT_MISS_TMAX LRT_K_MISS_TMAX
#define LRT_MISS_OFF_SCREEN LRT_K_MISS_OFF_SCREEN
#define LRT_MISS_INVALID_RAY LRT_K_MISS_INVALID_RAY
#define LRT_MISS_BUDGET LRT_K_MISS_BUDGET
#define LRT_HIT_ESTIMATE LRT_K_HIT_ESTIMATE
#define LRT_FACE_NONE LRT_K_FACE_NONE
#define LRT_FACE_TOP LRT_K_FACE_TOP
#define LRT_FACE_SIDE LRT_K_FACE_SIDE
#define LRT_FACE_BACK LRT_K_FACE_BACK
#define LRT_FACE_INSIDE LRT_K_FACE_INSIDE
#define LRT_UNORM8 LRT_K_FORMAT_UNORM8   // LrtParams.format
#define LRT_UNORM16 LRT_K_FORMAT_UNORM16
#define LRT_FLOAT32 LRT_K_FORMAT_FLOAT32
#define LRT_REVERSED_Z LRT_K_DEPTH_REVERSED_Z // LrtParams.flags
#define LRT_THICKNESS_INFINITE LRT_K_THICKNESS_INFINITE // LrtParams.thickness
#define LRT_THICKNESS_BACK_MAP LRT_K_THICKNESS_BACK_MAP
#define LRT_THICKNESS_CONSTANT LRT_K_THICKNESS_CONSTANT
#define LRT_THICKNESS_RELATIVE LRT_K_THICKNESS_RELATIVE

// false: no back-map trees here, and their code folds away (a branch the
// compiler cannot remove costs lavapipe on every secondary ray)
#ifndef LRT_BACK_TREES
#define LRT_BACK_TREES true
#endif
// false: every tree traced here has a thickness model, and the cell walk
// (which only infinite trees take) folds away
#ifndef LRT_INFINITE_TREES
#define LRT_INFINITE_TREES true
#endif
#ifndef LRT_BACK_WORD
#define LRT_BACK_WORD(i) 0u
#endif
#ifndef LRT_BACK_TEXEL
#define LRT_BACK_TEXEL(x, y) 1.0
#endif
#define LRT_INF uintBitsToFloat(0x7f800000u)

struct LrtParams {
    uint width, height, format, flags, node_bits, level_count, depth_offset, row_stride;
    uint back_offset, back_row_stride; // the back map's, in bytes (buffers; back-map trees only)
    uint thickness;                    // the tree's model (lrt_layout.thickness)
    float back_k0, back_k1;            // lrt_layout.back_k: the constant and relative models' b(d)
};

// lrt_hit of linear_rt.h, fields apart; lrt_hit_word3 packs kind and face
// as that struct's 4th word holds them
struct LrtHit {
    float t;
    uint x, y, kind, face;
};

uint lrt_hit_word3(LrtHit h) { return h.kind | (h.face << 16); }

// ============================================================================
// Level geometry and the modified Morton mapping (as lrt_layout_compute)
// ============================================================================

// level L groups 4x2 into L+1 when L is even, 2x4 when odd
uint lrt_bw_log2(uint level) { return (level & 1u) != 0u ? 1u : 2u; }
uint lrt_bh_log2(uint level) { return (level & 1u) != 0u ? 2u : 1u; }
// one node of a level covers (1 << span_w) x (1 << span_h) texels
uint lrt_span_w_log2(uint level) { return level + ((level + 1u) >> 1); }
uint lrt_span_h_log2(uint level) { return level + (level >> 1); }

// slot of node (x, y) among its parent's 8 children: y0 x1 x0 (4x2), y1 y0 x0 (2x4)
uint lrt_child_slot(uint level, uint x, uint y)
{
    return lrt_bw_log2(level) == 2u ? ((y & 1u) << 2) | (x & 3u) : ((y & 3u) << 1) | (x & 1u);
}

// the 16-bit code at code index `slot` of the node array
uint lrt_code(uint slot) { return (LRT_NODE_WORD(slot >> 1) >> ((slot & 1u) * 16u)) & 0xffffu; }

// 8-bit trees of two levels or more: each level-1 node is one word and a
// scale (linear_rt.h's lrt__compact_steps), 16-bit codes above it
bool lrt_compact(LrtParams p) { return p.node_bits == 8u && p.level_count >= 2u; }

// ============================================================================
// Depth in: texel (x, y) as the model states it
// ============================================================================

// The raw depth: for is_unorm formats the integer v (reversed Z flipped in
// integers); for float the bits of the float after the flip (in float) and
// the model's clamp (NaN and above 1 -> 1, below 0 -> 0).
uint lrt_clamp_float_bits(float g)
{
    uint b = floatBitsToUint(g);
    if ((b & 0x7fffffffu) > 0x7f800000u) return 0x3f800000u;   // NaN
    if ((b >> 31) != 0u || (b & 0x7f800000u) == 0u) return 0u;  // below 0, -0, 0, subnormal
    if (b > 0x3f800000u) return 0x3f800000u;                    // above 1
    return b;
}

#if LRT_DEPTH_IMAGE
// the raw value of a texel fetched from an image (depth or back map)
uint lrt_raw_of_texel(LrtParams p, float f)
{
    bool rev = (p.flags & LRT_REVERSED_Z) != 0u;
    if (p.format == LRT_UNORM8) { uint v = uint(f * 255.0 + 0.5); return rev ? 255u - v : v; }
    if (p.format == LRT_UNORM16) { uint v = uint(f * 65535.0 + 0.5); return rev ? 65535u - v : v; }
    precise float g = rev ? 1.0 - f : f;
    return lrt_clamp_float_bits(g);
}

uint lrt_depth_raw(LrtParams p, uint x, uint y) { return lrt_raw_of_texel(p, LRT_DEPTH_TEXEL(x, y)); }
uint lrt_back_map_raw(LrtParams p, uint x, uint y) { return lrt_raw_of_texel(p, LRT_BACK_TEXEL(x, y)); }
#else
// the raw value of the texel at byte addr of a buffer whose word holding it is word
uint lrt_raw_of_word(LrtParams p, uint word, uint addr)
{
    bool rev = (p.flags & LRT_REVERSED_Z) != 0u;
    if (p.format == LRT_UNORM8) { uint v = (word >> ((addr & 3u) * 8u)) & 0xffu; return rev ? 255u - v : v; }
    if (p.format == LRT_UNORM16) { uint v = (word >> ((addr & 2u) * 8u)) & 0xffffu; return rev ? 65535u - v : v; }
    precise float f = uintBitsToFloat(word);
    precise float g = rev ? 1.0 - f : f;
    return lrt_clamp_float_bits(g);
}

uint lrt_texel_addr(LrtParams p, uint offset, uint stride, uint x, uint y)
{
    return offset + y * stride + x * (p.format == LRT_UNORM8 ? 1u : p.format == LRT_UNORM16 ? 2u : 4u);
}

uint lrt_depth_raw(LrtParams p, uint x, uint y)
{
    uint addr = lrt_texel_addr(p, p.depth_offset, p.row_stride, x, y);
    return lrt_raw_of_word(p, LRT_DEPTH_WORD(addr >> 2), addr);
}

uint lrt_back_map_raw(LrtParams p, uint x, uint y)
{
    uint addr = lrt_texel_addr(p, p.back_offset, p.back_row_stride, x, y);
    return lrt_raw_of_word(p, LRT_BACK_WORD(addr >> 2), addr);
}
#endif

// b(d) of the constant and relative models, linear_rt.h's lrt__model_back
// step for step (sums and quotients only: nothing to fuse), clamped to 1
// and never in front of d
float lrt_model_back(LrtParams p, float d)
{
    precise float b;
    if (p.thickness == LRT_THICKNESS_CONSTANT) {
        precise float u = p.back_k0 - d;
        precise float q = p.back_k0 / u;
        b = d + p.back_k1 / ((q + p.back_k1) / u);
    } else {
        b = (d + p.back_k0) / p.back_k1;
    }
    if (!(b <= 1.0)) b = 1.0;
    return b > d ? b : d;
}

// ---- error-free transformations in float (Knuth's sum, Dekker's product) ----
void lrt_two_sum(float a, float b, out float s, out float e)
{
    precise float ss = a + b;
    precise float bb = ss - a;
    precise float ee = (a - (ss - bb)) + (b - bb);
    s = ss;
    e = ee;
}
void lrt_two_prod(float a, float b, out float p, out float e)
{
    precise float pp = a * b;
    precise float ca = 4097.0 * a, cb = 4097.0 * b; // 2^12 + 1 splits a float in halves
    precise float ah = ca - (ca - a), al = a - ah;
    precise float bh = cb - (cb - b), bl = b - bh;
    precise float ee = ((ah * bh - pp) + ah * bl + al * bh) + al * bl;
    p = pp;
    e = ee;
}

// the sign of x * max - v for a is_unorm raw value v (max 255 or 65535),
// exactly: where a depth v / max lies against x, without rounding v / max
int lrt_scaled_sign(float x, uint format, uint raw)
{
    float pp, e;
    lrt_two_prod(x, format == LRT_UNORM8 ? 255.0 : 65535.0, pp, e);
    if (pp != float(raw)) return pp < float(raw) ? -1 : 1;
    return e < 0.0 ? -1 : e > 0.0 ? 1 : 0;
}

// a texel's back under the constant or relative model: b(d) as float bits,
// or ~0u when b is not behind a is_unorm depth's exact v / max (b rounds to
// the float d, below v / max): the box is then the flat plate [d, d], its
// back the depth's own exact plane (linear_rt.h's lrt__model_back_bits)
uint lrt_model_back_bits(LrtParams p, uint raw)
{
    precise float df = p.format == LRT_UNORM8 ? float(raw) / 255.0 : p.format == LRT_UNORM16 ? float(raw) / 65535.0 : uintBitsToFloat(raw);
    float b = lrt_model_back(p, df);
    if (p.format != LRT_FLOAT32 && lrt_scaled_sign(b, p.format, raw) <= 0) return ~0u; // b <= v / max
    return floatBitsToUint(b);
}

// texel (x, y)'s back depth as a raw value and its format: max(depth,
// back) for a back map (a back in front of the depth is the depth), else
// lrt_model_back_bits (float), the depth itself for a plate
uint lrt_texel_back(LrtParams p, uint x, uint y, out uint format)
{
    uint d = lrt_depth_raw(p, x, y);
    format = p.format;
    if (p.thickness == LRT_THICKNESS_BACK_MAP) return max(d, lrt_back_map_raw(p, x, y));
    uint bits = lrt_model_back_bits(p, d);
    if (bits == ~0u) return d;
    format = LRT_FLOAT32;
    return bits;
}

// ============================================================================
// Heights: code = qmax - floor(depth * qmax), rounded so a bound never cuts a hit
// ============================================================================

// floor(d * qmax) of a float d in [0,1], exactly: d = m * 2^(e - 150) with a
// 24-bit m, so the product is m * qmax (at most 40 bits) shifted
uint lrt_floor_scaled(uint dbits, uint qmax)
{
    uint e = (dbits >> 23) & 0xffu;
    if (e == 0u) return 0u;
    uint m = (dbits & 0x7fffffu) | 0x800000u, hi, lo;
    umulExtended(m, qmax, hi, lo);
    int sh = 150 - int(e);
    if (sh >= 64) return 0u;
    if (sh >= 32) return hi >> uint(sh - 32);
    if (sh == 0) return lo;
    return (lo >> uint(sh)) | (hi << uint(32 - sh));
}

// is d * qmax a whole number (lrt_floor_scaled's shifted-out bits all 0)
bool lrt_scaled_is_whole(uint dbits, uint qmax)
{
    uint e = (dbits >> 23) & 0xffu;
    if (e == 0u) return true; // 0
    uint m = (dbits & 0x7fffffu) | 0x800000u, hi, lo;
    umulExtended(m, qmax, hi, lo);
    int sh = 150 - int(e);
    if (sh <= 0) return true;
    if (sh >= 64) return hi == 0u && lo == 0u;
    if (sh >= 32) return lo == 0u && (hi & ((1u << uint(sh - 32)) - 1u)) == 0u;
    return (lo & ((1u << uint(sh)) - 1u)) == 0u;
}

uint lrt_texel_code(LrtParams p, uint x, uint y)
{
    uint qmax = 65535u;
    uint raw = lrt_depth_raw(p, x, y);
    if (p.format == LRT_UNORM8) return qmax - (raw * qmax) / 255u;
    if (p.format == LRT_UNORM16) return qmax - (raw * qmax) / 65535u; // < 2^32
    return qmax - lrt_floor_scaled(raw, qmax);
}

// a back-map tree's back code of texel (x, y): ceil(b * qmax), rounded UP
// so that a node's back is never shallower than a texel's under it
uint lrt_texel_back_code(LrtParams p, uint x, uint y)
{
    uint qmax = 65535u;
    uint format;
    uint raw = lrt_texel_back(p, x, y, format);
    if (format == LRT_UNORM8) return (raw * qmax + 254u) / 255u;
    if (format == LRT_UNORM16) return (raw * qmax + 65534u) / 65535u; // < 2^32
    return lrt_floor_scaled(raw, qmax) + (lrt_scaled_is_whole(raw, qmax) ? 0u : 1u);
}

// ============================================================================
// Traversal (RayQuery.Proceed of the design)
// ============================================================================

struct LrtSetup {
    vec3 o, v, iv;
    uvec3 neg;      // sign bits of the direction (-0 counts)
    bvec3 zero;     // the direction component is 0: a closed slab, no planes
    float t_lo, t_hi, t_base;
    int zk;         // 0, or z (o.z, v.z and every depth plane) is scaled by 2^zk (lrt_setup_rare)
};

// entering / leaving t of the slab [lo, hi] along one axis, as linear_rt.h's
// lrt__slab: an axis the ray does not move along is all or nothing
void lrt_slab(float lo, float hi, float o, float iv, uint neg, bool zero, inout float en, inout float ex)
{
    precise float a = (lo - o) * iv, b = (hi - o) * iv;
    if (zero) {
        bool inside = lo <= o && o <= hi;
        a = inside ? -LRT_INF : LRT_INF;
        b = inside ? LRT_INF : -LRT_INF;
        neg = 0u;
    }
    en = max(neg != 0u ? b : a, en);
    ex = min(neg != 0u ? a : b, ex);
}

// ---- arithmetic at the edge of float range (lrt_crossing, lrt_setup_rare),
// as linear_rt.h: exponents and powers of two from the bits, products scaled
// into range first, ldexp rounded once. They need subnormal floats kept, as
// lavapipe keeps them; on a GPU that flushes them (these kernels do not ask
// for denorm preservation) the rare rays that need them may be answered
// otherwise than on the CPU (shaders/README.md). ----

// floor(log2 |f|) of a finite nonzero float, subnormals included
int lrt_ilogb(float f)
{
    uint u = floatBitsToUint(f) & 0x7fffffffu;
    return u >= 0x00800000u ? int(u >> 23) - 127 : findMSB(u) - 149;
}

// 2^k exactly, k in [-149, 127]
float lrt_pow2(int k)
{
    return uintBitsToFloat(k >= -126 ? uint(k + 127) << 23 : 1u << uint(k + 149));
}

// f 2^-ilogb(f), in [1, 2) with f's sign, exactly
float lrt_signif(float f)
{
    uint b = floatBitsToUint(f), m = b & 0x007fffffu;
    if ((b & 0x7f800000u) == 0u) m = (m << uint(23 - findMSB(m))) & 0x007fffffu; // subnormal
    return uintBitsToFloat((b & 0x80000000u) | 0x3f800000u | m);
}

// x 2^k rounded once, as C's ldexpf (GLSL's ldexp may flush or round twice)
float lrt_ldexp(float x, int k)
{
    if (x == 0.0 || k == 0) return x;
    float y = lrt_signif(x), zero = uintBitsToFloat(floatBitsToUint(x) & 0x80000000u);
    int j = lrt_ilogb(x) + k; // the exponent of the result
    if (j > 127) return y * lrt_pow2(127) * 2.0; // +-inf
    if (j >= -149) {
        precise float r = y * lrt_pow2(j);
        return r;
    }
    if (j == -150) return abs(y) > 1.0 ? uintBitsToFloat(floatBitsToUint(zero) | 1u) : zero; // to nearest, ties to even
    return zero;
}

// The rare set-up's parts and axes are picked by selects among named
// components: as float arrays indexed per lane, they cost lavapipe on every
// dispatch whatever rays came, and as vectors indexed per lane more than
// selects. The walk's pending masks (m[lv >> 2]) stay indexed: selects
// there cost more (docs/PERFORMANCE.md).
float lrt_pick(vec4 v, int k) { return k == 0 ? v.x : k == 1 ? v.y : k == 2 ? v.z : v.w; }
float lrt_axis(vec3 v, int k) { return k == 0 ? v.x : k == 1 ? v.y : v.z; }
vec4 lrt_put(vec4 v, int k, float f) { return vec4(k == 0 ? f : v.x, k == 1 ? f : v.y, k == 2 ? f : v.z, k == 3 ? f : v.w); }

// an expansion: m parts, part j in lo (j < 4) or hi (j - 4), the largest last
struct LrtExpansion {
    vec4 lo, hi;
    int m;
};

#ifdef LINEAR_RT_HLSL
LrtExpansion lrt_expansion() // (field by field: HLSL has no struct constructors)
{
    LrtExpansion x;
    x.lo = vec4(0.0, 0.0, 0.0, 0.0);
    x.hi = vec4(0.0, 0.0, 0.0, 0.0);
    x.m = 0;
    return x;
}
#else
LrtExpansion lrt_expansion() { return LrtExpansion(vec4(0.0, 0.0, 0.0, 0.0), vec4(0.0, 0.0, 0.0, 0.0), 0); }
#endif
float lrt_part(LrtExpansion x, int j) { return j < 4 ? lrt_pick(x.lo, j) : lrt_pick(x.hi, j - 4); }
void lrt_set_part(inout LrtExpansion x, int j, float v)
{
    x.lo = j < 4 ? lrt_put(x.lo, j, v) : x.lo;
    x.hi = j < 4 ? x.hi : lrt_put(x.hi, j - 4, v);
}

// adds v to the expansion (Shewchuk's grow-expansion)
void lrt_grow(inout LrtExpansion x, float v)
{
    for (int j = 0; j < x.m; ++j) {
        float hi, lo;
        lrt_two_sum(lrt_part(x, j), v, hi, lo);
        lrt_set_part(x, j, lo);
        v = hi;
    }
    lrt_set_part(x, x.m++, v);
}

int lrt_expansion_sign(LrtExpansion x)
{
    for (int i = x.m - 1; i >= 0; --i)
        if (lrt_part(x, i) != 0.0) return lrt_part(x, i) > 0.0 ? 1 : -1;
    return 0;
}

// an expansion's value, the largest part last: faithful; lo gets the sum
// of that sum's rounding errors (linear_rt.h's lrt__expansion_value)
float lrt_expansion_value(LrtExpansion x, out float lo)
{
    float sum = 0.0;
    lo = 0.0;
    for (int i = 0; i < x.m; ++i) {
        float s, err;
        lrt_two_sum(sum, lrt_part(x, i), s, err);
        sum = s;
        precise float l = lo + err;
        lo = l;
    }
    return sum;
}

// an expansion's value divided by y in [1, 2), times 2^shift, faithfully
// (a division of its rounded value rounds twice: crashes-found 22), as
// linear_rt.h's lrt__expansion_div
float lrt_expansion_div(LrtExpansion x, float y, int shift)
{
    float lo, hi = lrt_expansion_value(x, lo);
    if (hi == 0.0) return 0.0;
    int k = lrt_ilogb(hi);
    hi = lrt_ldexp(hi, -k);
    lo = lrt_ldexp(lo, -k);
    precise float q = hi / y;
    float p, e;
    lrt_two_prod(q, y, p, e); // q y = p + e; hi - p is exact
    precise float r = q + (((hi - p) - e) + lo) / y;
    return lrt_ldexp(r, k + shift);
}

// appends a b 2^(extra - scale) as an exact pair (the caller keeps the
// product's exponent within [-73, 122] of the scale)
void lrt_grow_prod(inout LrtExpansion x, float a, float b, int extra, int scale)
{
    if (a == 0.0 || b == 0.0) return;
    float f = lrt_pow2(lrt_ilogb(a) + lrt_ilogb(b) + extra - scale), p, e;
    lrt_two_prod(lrt_signif(a), lrt_signif(b), p, e);
    precise float pf = p * f, ef = e * f;
    lrt_grow(x, pf);
    lrt_grow(x, ef);
}

// the t where the ray's z reaches the depth plane of a raw depth (see
// lrt_depth_raw); for a z that does not change, the box [d, 1] holds the
// ray wholly (-inf as an entry, +inf as an exit) or not at all. A ray whose
// z is scaled by 2^zk (lrt_setup_rare) scales the depth too, exactly.
float lrt_depth_plane(LrtSetup s, uint format, uint raw)
{
    bool is_unorm = format != LRT_FLOAT32 && raw != (format == LRT_UNORM8 ? 255u : 65535u); // v = max is d = 1 exactly
    float d = format == LRT_FLOAT32 ? uintBitsToFloat(raw) : is_unorm ? 0.0 : 1.0;
    // o.z * max = p + e exactly (one product for both uses below; is_unorm only)
    float qm = format == LRT_UNORM8 ? 255.0 : 65535.0, p = 0.0, e = 0.0, v = float(raw);
    if (format != LRT_FLOAT32) lrt_two_prod(s.o.z, qm, p, e);
    if (s.zero.z) {
        // v/max <= o.z, compared without rounding v/max: v <= o.z * max
        // (lrt_scaled_sign's test, on the same product)
        bool inside = is_unorm ? (p != v ? p > v : e >= 0.0) : d <= s.o.z;
        return (s.neg.z != 0u) == inside ? LRT_INF : -LRT_INF;
    }
    if (!is_unorm) {
        if (s.zk != 0) d = lrt_ldexp(d, s.zk);
        precise float t = (d - s.o.z) * s.iv.z;
        return t;
    }
    // v/max - o.z = (v - o.z * max) / max
    if (s.zk != 0) v = lrt_ldexp(v, s.zk);
    precise float n = (v - p) - e;
    // 1.0f/255.0f and 1.0f/65535.0f as linear_rt.h rounds them
    float inv_qm = format == LRT_UNORM8 ? uintBitsToFloat(0x3b808081u) : uintBitsToFloat(0x37800080u);
    precise float t = (n * inv_qm) * s.iv.z;
    return t;
}

// the screen rectangle and 0 <= z <= 1 (the near and far planes); returns
// the kind of a miss
uint lrt_clip(inout LrtSetup s, LrtParams p, float tmin, float tmax)
{
    float xy_en = -LRT_INF, xy_ex = LRT_INF;
    lrt_slab(0.0, float(p.width), s.o.x, s.iv.x, s.neg.x, s.zero.x, xy_en, xy_ex);
    lrt_slab(0.0, float(p.height), s.o.y, s.iv.y, s.neg.y, s.zero.y, xy_en, xy_ex);
    s.t_lo = max(xy_en, tmin);
    s.t_hi = min(xy_ex, tmax);
    uint kind = (s.t_lo > s.t_hi || xy_ex < tmax) ? LRT_MISS_OFF_SCREEN : LRT_MISS_TMAX;
    // the far plane z = 1 bounds the box from the other side than a depth
    // plane does: for a z that does not change, it keeps the ray iff o.z <= 1
    float t1 = s.zero.z ? (((s.neg.z != 0u) == (s.o.z <= 1.0)) ? -LRT_INF : LRT_INF)
                        : lrt_depth_plane(s, LRT_FLOAT32, floatBitsToUint(1.0));
    // the near plane z = 0 bounds it from the same side as a depth plane:
    // for a z that does not change, it keeps the ray iff o.z >= 0
    precise float tn = (0.0 - s.o.z) * s.iv.z;
    float t0 = s.zero.z ? (((s.neg.z != 0u) == (s.o.z >= 0.0)) ? LRT_INF : -LRT_INF) : tn;
    if (s.neg.z != 0u) {
        s.t_lo = max(t1, s.t_lo);
        s.t_hi = min(t0, s.t_hi);
    } else {
        s.t_lo = max(t0, s.t_lo);
        s.t_hi = min(t1, s.t_hi);
    }
    return kind;
}

bool lrt_finite(float f) { return (floatBitsToUint(f) & 0x7f800000u) != 0x7f800000u; }

// The restart of a far-away ray, as linear_rt.h's lrt__crossing_sum:
// (b1 + b2) + (plane - o_a) v_b / v_a, or (b1 + b2) + t v_b 2^vexp (by_t),
// as an exact expansion acc times 2^scale (times 1 / v_a unless by_t),
// the largest product in [2^122, 2^124), a group 2^30 below the other left out
void lrt_crossing_sum(float b1, float b2, float o_a, float v_b, float v_a, float plane, bool by_t, float t, int vexp,
                      out LrtExpansion acc, out int scale)
{
    float s = t, e = 0.0, va = v_a;
    int lb = -10000, ls = -10000;
    acc = lrt_expansion();
    if (by_t) va = 1.0;
    else lrt_two_sum(plane, -o_a, s, e);
    if (b1 != 0.0) lb = lrt_ilogb(b1) + lrt_ilogb(va);
    if (s != 0.0 && v_b != 0.0) ls = lrt_ilogb(s) + lrt_ilogb(v_b) + (by_t ? vexp : 0);
    int top = max(lb, ls);
    scale = top - 122;
    if (top == -10000) return;
    if (lb >= top - 30) {
        lrt_grow_prod(acc, b1, va, 0, scale);
        lrt_grow_prod(acc, b2, va, 0, scale);
    }
    if (ls >= top - 30) {
        lrt_grow_prod(acc, s, v_b, by_t ? vexp : 0, scale);
        lrt_grow_prod(acc, e, v_b, 0, scale);
    }
}

// a coordinate of the restart point: o_b + (plane - o_a) v_b / v_a (or
// o_b + t v_b 2^vexp), rounded faithfully; far_z: a z that rounds to 1
// but is not 1 becomes the float next to 1 on its side, as linear_rt.h's
// lrt__crossing
float lrt_crossing(float o_b, float o_a, float v_b, float v_a, float plane, bool by_t, float t, int vexp, bool far_z)
{
    if (v_b == 0.0 || (by_t && t == 0.0)) return o_b;
    LrtExpansion acc;
    float r;
    int scale;
    lrt_crossing_sum(o_b, 0.0, o_a, v_b, v_a, plane, by_t, t, vexp, acc, scale);
    if (acc.m == 0) return 0.0;
    if (by_t) {
        float lo;
        r = lrt_ldexp(lrt_expansion_value(acc, lo), scale);
    } else {
        r = lrt_expansion_div(acc, lrt_signif(v_a), scale - lrt_ilogb(v_a));
    }
    if (!far_z || r != 1.0) return r;
    float d1, d2;
    lrt_two_sum(o_b, -1.0, d1, d2);
    lrt_crossing_sum(d1, d2, o_a, v_b, v_a, plane, by_t, t, vexp, acc, scale);
    int side = lrt_expansion_sign(acc) * (!by_t && v_a < 0.0 ? -1 : 1);
    return side > 0 ? uintBitsToFloat(0x3f800001u) : side < 0 ? uintBitsToFloat(0x3f7fffffu) : 1.0;
}

// the sign of o + t v - c, exactly (t >= 0), as linear_rt.h's lrt__side
int lrt_side(float o, float v, float t, float c)
{
    float d1, d2;
    LrtExpansion acc = lrt_expansion();
    lrt_two_sum(c, -o, d1, d2);
    if (v == 0.0 || t == 0.0) return d1 > 0.0 ? -1 : d1 < 0.0 ? 1 : 0;
    if (d1 == 0.0) return v > 0.0 ? 1 : -1;
    int e = lrt_ilogb(t) + lrt_ilogb(v), ed = lrt_ilogb(d1);
    if (e >= ed + 2) return v > 0.0 ? 1 : -1;
    if (e + 3 <= ed) return d1 > 0.0 ? -1 : 1;
    lrt_grow_prod(acc, t, v, 0, e);
    lrt_grow(acc, -lrt_ldexp(d1, -e));
    if (d2 != 0.0 && lrt_ilogb(d2) - e >= -100) {
        lrt_grow(acc, -lrt_ldexp(d2, -e));
        return lrt_expansion_sign(acc);
    }
    int sign = lrt_expansion_sign(acc);
    return sign != 0 ? sign : d2 > 0.0 ? -1 : d2 < 0.0 ? 1 : 0;
}

// t 2^e, a positive t kept positive and every t finite
float lrt_scale_t(float t, int e)
{
    float r = lrt_ldexp(t, e);
    if (r == 0.0 && t > 0.0) return uintBitsToFloat(1u);
    return r <= uintBitsToFloat(0x7f7fffffu) ? r : uintBitsToFloat(0x7f7fffffu);
}

// (p - o) / (v 2^-e), each step rounded once
float lrt_plane_t(float p, float o, float v, int e)
{
    precise float n = p - o;
    if (n == 0.0) return 0.0;
    precise float q = lrt_signif(n) / lrt_signif(v);
    return lrt_ldexp(q, lrt_ilogb(n) - lrt_ilogb(v) + e);
}

// the restart's axis, as linear_rt.h's lrt__entered_later: an axis whose
// crossing at the taken plane is still before its entering plane was
// entered later (entering planes' t that round to one float); -1: none
int lrt_entered_later(vec3 n, vec3 v, vec3 hi, int axis)
{
    for (int k = 0; k < 3; ++k) {
        if (k == axis || v[k] == 0.0) continue;
        if ((floatBitsToUint(v[k]) >> 31) != 0u ? n[k] > hi[k] : n[k] < 0.0) return k;
    }
    return -1;
}

// an origin so far from the screen that (plane - o) loses its planes: the
// ray restarts on the screen box in lrt_setup_rare (linear_rt.h's lrt__far_origin)
bool lrt_far_origin(LrtParams p, vec3 o)
{
    return abs(o.x) > 2.0 * float(p.width) + 16.0 || abs(o.y) > 2.0 * float(p.height) + 16.0 || abs(o.z) > 4.0;
}

// a subnormal read as 0 of its sign, in integers (linear_rt.h's
// lrt__flush_ray): the same on a device that flushes them as on one that
// keeps them
float lrt_flush(float x)
{
    uint b = floatBitsToUint(x);
    return (b & 0x7f800000u) == 0u ? uintBitsToFloat(b & 0x80000000u) : x;
}

// whether a point's coordinate o lies in [0, hi], or (past) whether the
// point just past it along a direction of sign neg (zero: none) does
bool lrt_point_in(float o, uint neg, bool zero, float hi, bool past)
{
    if (!past) return o >= 0.0 && o <= hi;
    return (o > 0.0 || (o == 0.0 && (neg == 0u || zero))) && (o < hi || (o == hi && (neg != 0u || zero)));
}

// The set-up of a ray at the edge of float range, as linear_rt.h's
// lrt__setup_rare (read its comment): subnormals read as 0, rescaled to
// max |v| in [1, 2), a component too slow to invert beside the largest kept
// exact by a scale of its axis, the kind of a miss decided exactly.
bool lrt_setup_rare(LrtParams p, vec3 o, float tmin, vec3 v, float tmax, out LrtSetup s, out int t_exp, out uint kind)
{
    o = vec3(lrt_flush(o.x), lrt_flush(o.y), lrt_flush(o.z));
    v = vec3(lrt_flush(v.x), lrt_flush(v.y), lrt_flush(v.z));
    tmin = lrt_flush(tmin);
    tmax = lrt_flush(tmax);
    const float FLT_MAX = uintBitsToFloat(0x7f7fffffu), TINY_O = uintBitsToFloat(0x1a000000u); // 2^-77
    // (vectors, not arrays: see lrt_pick)
    vec3 hi3 = vec3(float(p.width), float(p.height), 1.0), o3 = o, v3 = v, sv, iv;
    s.o = o;
    s.v = v;
    s.iv = vec3(0.0, 0.0, 0.0);
    s.neg = uvec3(0u, 0u, 0u);
    s.zero = bvec3(false);
    s.t_lo = 0.0;
    s.t_hi = -1.0;
    s.t_base = 0.0;
    s.zk = 0;
    t_exp = 0;
    if (!lrt_finite(o.x) || !lrt_finite(o.y) || !lrt_finite(o.z) || !lrt_finite(v.x) || !lrt_finite(v.y) ||
        !lrt_finite(v.z) || !lrt_finite(tmin) || !lrt_finite(tmax) || !(tmin >= 0.0) || !(tmin <= tmax)) {
        kind = LRT_MISS_INVALID_RAY;
        return false;
    }
    kind = lrt_side(o.x, v.x, tmax, 0.0) >= 0 && lrt_side(o.x, v.x, tmax, float(p.width)) <= 0 &&
                   lrt_side(o.y, v.y, tmax, 0.0) >= 0 && lrt_side(o.y, v.y, tmax, float(p.height)) <= 0
               ? LRT_MISS_TMAX
               : LRT_MISS_OFF_SCREEN;
    float m = max(max(abs(v.x), abs(v.y)), abs(v.z));
    int e = m != 0.0 ? max(lrt_ilogb(m), -127) : 0;
    ivec3 ev = ivec3(0, 0, 0);
    uint deg = 0u;
    tmin = lrt_scale_t(tmin, e);
    tmax = lrt_scale_t(tmax, e);
    t_exp = -e;
    for (int k = 0; k < 3; ++k) {
        // v 2^-e by lrt_ldexp, not times lrt_pow2(-e): that factor is
        // subnormal for e = 127, which a flushing device reads as 0
        sv[k] = lrt_ldexp(v3[k], -e);
        if (v3[k] != 0.0) {
            ev[k] = lrt_ilogb(v3[k]) - e;
            if (ev[k] < -126) deg |= 1u << uint(k);
        }
    }
    if (lrt_far_origin(p, o)) {
        float te = tmin, plane = 0.0;
        vec3 n3;
        int axis = -1;
        for (int k = 0; k < 3; ++k) {
            if (v3[k] == 0.0) continue;
            float pl = (floatBitsToUint(v3[k]) >> 31) != 0u ? hi3[k] : 0.0;
            float en = lrt_plane_t(pl, o3[k], v3[k], e);
            if (en > te) {
                te = en;
                axis = k;
                plane = pl;
            }
        }
        if (!(te <= tmax)) return false;
        for (int tries = 0; tries < 3; ++tries) {
            for (int k = 0; k < 3; ++k) {
                if (axis < 0) n3[k] = lrt_crossing(o3[k], 0.0, v3[k], 1.0, 0.0, true, te, -e, k == 2);
                else if (k == axis) n3[k] = plane;
                else n3[k] = lrt_crossing(o3[k], lrt_axis(o3, axis), v3[k], lrt_axis(v3, axis), plane, false, 0.0, 0, k == 2);
                if (!lrt_finite(n3[k])) return false;
            }
            // the last try keeps its axis: n3 and te the same crossing's (linear_rt.h)
            int later = axis < 0 || tries == 2 ? -1 : lrt_entered_later(n3, v3, hi3, axis);
            if (later < 0) break;
            axis = later; // see lrt_entered_later
            plane = (floatBitsToUint(lrt_axis(v3, later)) >> 31) != 0u ? lrt_axis(hi3, later) : 0.0;
            te = lrt_plane_t(plane, lrt_axis(o3, later), lrt_axis(v3, later), e);
        }
        o3 = n3;
        s.t_base = te;
        tmin = 0.0;
        precise float rest = tmax - te;
        tmax = rest;
    }
    for (int k = 0; k < 3; ++k) iv[k] = sv[k] == 0.0 ? 0.0 : 1.0 / sv[k];
    for (int k = 0; k < 2; ++k) { // an x or y too slow to invert
        if ((deg & (1u << uint(k))) == 0u) continue;
        float oo = o3[k];
        iv[k] = (floatBitsToUint(v3[k]) >> 31) != 0u ? -FLT_MAX : FLT_MAX;
        if (oo != 0.0 && abs(oo) < TINY_O) {
            if (lrt_ilogb(oo) - ev[k] >= 30) {
                o3[k] = oo < 0.0 ? -TINY_O : TINY_O;
            } else {
                sv[k] = lrt_ldexp(v3[k], -126 - lrt_ilogb(v3[k]));
                o3[k] = lrt_ldexp(oo, -126 - ev[k]);
                iv[k] = 1.0 / sv[k];
            }
        }
    }
    if ((deg & 4u) != 0u) { // a z too slow to invert: scale z
        int kz = min(-126 - ev[2], 100);
        sv[2] = lrt_ldexp(v3[2], kz - e);
        o3[2] = lrt_ldexp(o3[2], kz);
        s.zk = kz;
        iv[2] = 1.0 / sv[2];
        if (sv[2] == 0.0 || !lrt_finite(iv[2])) iv[2] = (floatBitsToUint(v3[2]) >> 31) != 0u ? -FLT_MAX : FLT_MAX;
    }
    s.o = vec3(o3[0], o3[1], o3[2]);
    s.v = vec3(sv[0], sv[1], sv[2]);
    s.iv = vec3(iv[0], iv[1], iv[2]);
    s.neg = uvec3(floatBitsToUint(sv[0]) >> 31, floatBitsToUint(sv[1]) >> 31, floatBitsToUint(sv[2]) >> 31);
    s.zero = bvec3(v.x == 0.0, v.y == 0.0, v.z == 0.0);
    lrt_clip(s, p, tmin, tmax);
    // A segment of no length is its one point: in the box or not by its
    // coordinates, exactly, not by planes' t, which may lie below 2^-126,
    // where a device that flushes subnormals reads them as 0 (found case 19
    // of tests/support/rays.h: o.z = -1.18e-38, v.z = 2.48e38, t in [0, 0]).
    // The point is o, or where lrt_scale_t kept a positive t positive (the
    // least subnormal, read as 0 there too: found case 13), just past o
    // along v
    uint tb = floatBitsToUint(tmax);
    if (s.zk == 0 && floatBitsToUint(tmin) == tb && (tb & 0x7fffffffu) <= 1u) {
        bool past = tb == 1u;
        if (!lrt_point_in(s.o.x, s.neg.x, s.zero.x, float(p.width), past) ||
            !lrt_point_in(s.o.y, s.neg.y, s.zero.y, float(p.height), past) ||
            !lrt_point_in(s.o.z, s.neg.z, s.zero.z, 1.0, past))
            return false;
    }
    return s.t_lo <= s.t_hi;
}

// true for a ray the ordinary set-up cannot take exactly: the rays that
// linear_rt.h takes through lrt__setup_rare (the same tests on the bits): a
// component of o or v, tmin or tmax at the edge of float range, an origin
// far off the map, a steep ray from z = 0. Almost none in a frame; the
// library's kernels trace them in a second pass (lrt_trace_ray_ordinary).
// Else e: a direction of 2^16 or more whose only oddity that is
// (linear_rt.h's lrt__huge_direction) is scaled by 2^-e, as lrt_setup_rare
// would, and takes the ordinary set-up (e 16 to 125); 0 for any other ray
bool lrt_ray_rare(LrtParams p, vec3 o, float tmin, vec3 v, float tmax, out int e)
{
    uvec3 ao = floatBitsToUint(o) & 0x7fffffffu, av = floatBitsToUint(v) & 0x7fffffffu;
    const uint TINY = 0x0d800000u, HUGE = 0x47800000u; // 2^-100, 2^16
    uvec2 at = floatBitsToUint(vec2(tmin, tmax)) & 0x7fffffffu;
    uint mb = max(max(av.x, av.y), av.z); // finite floats order as their bits
    bool big = mb >= HUGE;
    e = big ? int(mb >> 23) - 127 : 0;
    bool rare = lrt_far_origin(p, o) || (big && mb >= 0x7e800000u); // 2^126 and up, inf, NaN: no normal 2^-e
    for (int k = 0; k < 3; ++k) {
        rare = rare || (ao[k] != 0u && !(ao[k] - TINY < 0x7f800000u - TINY));
        // below 2^-100, once scaled by 2^-e (e 0: a direction not large)
        rare = rare || (av[k] != 0u && int(av[k] >> 23) - 127 - e < -100);
    }
    for (int k = 0; k < 2; ++k) // 0 or normal, and finite once scaled
        rare = rare || (at[k] != 0u && !(at[k] - 0x00800000u < 0x7f000000u && int(at[k] >> 23) - 127 + e <= 127));
    rare = rare || (!big && o.z == 0.0 && abs(v.z) >= 16.0); // a steep ray from z = 0 (never large here)
    e = rare ? 0 : e;
    return rare;
}

// the set-up of a ray lrt_ray_rare lets through, scaled by its 2^-e (2^e
// and 2^-e normal, every product exact, none subnormal or past the largest
// float: lrt_ray_rare's checks): validate and clip; false with kind set
// when nothing is left to walk
bool lrt_setup_ordinary(LrtParams p, vec3 o, float tmin, vec3 v, float tmax, int e, out LrtSetup s, out uint kind)
{
    float up = lrt_pow2(e);
    tmin *= up;
    tmax *= up;
    v *= lrt_pow2(-e);
    s.o = o;
    s.t_base = 0.0;
    s.zk = 0;
    if (!(tmin >= 0.0) || !(tmin <= tmax)) {
        kind = LRT_MISS_INVALID_RAY;
        return false;
    }
    s.v = v;
    s.neg = uvec3(floatBitsToUint(v.x) >> 31, floatBitsToUint(v.y) >> 31, floatBitsToUint(v.z) >> 31);
    s.zero = bvec3(v.x == 0.0, v.y == 0.0, v.z == 0.0);
    s.iv = vec3(s.zero.x ? 0.0 : 1.0 / v.x, s.zero.y ? 0.0 : 1.0 / v.y, s.zero.z ? 0.0 : 1.0 / v.z);
    kind = lrt_clip(s, p, tmin, tmax);
    return s.t_lo <= s.t_hi;
}

// validates and clips any ray; false with kind set when nothing is left to
// walk. A rare ray takes lrt_setup_rare; the set-up scaled t by 2^-t_exp
bool lrt_setup_ray(LrtParams p, vec3 o, float tmin, vec3 v, float tmax, out LrtSetup s, out int t_exp, out uint kind)
{
    int e;
    if (lrt_ray_rare(p, o, tmin, v, tmax, e)) return lrt_setup_rare(p, o, tmin, v, tmax, s, t_exp, kind);
    t_exp = -e;
    return lrt_setup_ordinary(p, o, tmin, v, tmax, e, s, kind);
}

// lowest level whose one node holds every texel the clipped segment can
// touch (0: a single texel), as lrt__start_node
uint lrt_start_node(LrtParams p, LrtSetup s, out uint sx, out uint sy)
{
    uint i0[2], i1[2];
    if (s.zero.x && s.zero.y && float(int(s.o.x)) != s.o.x && float(int(s.o.y)) != s.o.y) {
        // a camera ray inside one texel's column (the clip put o on the
        // screen; off a texel edge, no neighbour's closed box is met)
        sx = uint(int(s.o.x));
        sy = uint(int(s.o.y));
        return 0u;
    }
    for (int k = 0; k < 2; ++k) {
        float o = s.o[k], v = s.v[k];
        float lim = float((k == 1 ? p.height : p.width) - 1u);
        precise float a = o + s.t_lo * v, b = o + s.t_hi * v;
        precise float mg = 1e-3 + 1e-5 * (abs(o) + abs(a - o) + abs(b - o));
        precise float lo = min(a, b) - mg, hi = max(a, b) + mg;
        lo = lo > 0.0 ? lo : 0.0;
        lo = lo < lim ? lo : lim;
        hi = hi < lim ? hi : lim;
        hi = hi > 0.0 ? hi : 0.0;
        i0[k] = uint(int(lo));
        i1[k] = uint(int(hi));
    }
    uint lv = 0u;
    for (; lv < p.level_count; ++lv) {
        if ((i0[0] >> lrt_span_w_log2(lv)) == (i1[0] >> lrt_span_w_log2(lv)) &&
            (i0[1] >> lrt_span_h_log2(lv)) == (i1[1] >> lrt_span_h_log2(lv)))
            break;
    }
    sx = lv == p.level_count ? 0u : i0[0] >> lrt_span_w_log2(lv);
    sy = lv == p.level_count ? 0u : i0[1] >> lrt_span_h_log2(lv);
    return lv;
}

// exits widened by 2^-21 of their size before en <= ex, as linear_rt.h's
// lrt__widen: a ray through a texel corner meets it however each plane's t
// rounds (the product is exact, so fusing changes nothing); an exit that
// would widen past the largest float, or is infinite, stays as it is
float lrt_widen(float ex)
{
    precise float w = ex + abs(ex) * (1.0 / 2097152.0);
    return w <= uintBitsToFloat(0x7f7fffffu) ? w : ex;
}

// the exact test of a candidate texel against its true depth
// the t where the ray's z reaches a raw back depth: lrt_depth_plane's t,
// and for a z that does not change, the box [.., b] holds the ray wholly
// or not at all, from the other side than a depth plane does
float lrt_back_plane(LrtSetup s, uint format, uint raw)
{
    if (!s.zero.z) return lrt_depth_plane(s, format, raw);
    bool is_unorm = format != LRT_FLOAT32 && raw != (format == LRT_UNORM8 ? 255u : 65535u);
    bool inside = is_unorm ? lrt_scaled_sign(s.o.z, format, raw) <= 0 // o.z * max <= v
                        : s.o.z <= (format == LRT_FLOAT32 ? uintBitsToFloat(raw) : 1.0); // o.z <= b
    return (s.neg.z != 0u) == inside ? -LRT_INF : LRT_INF;
}

bool lrt_has_back(LrtParams p) { return LRT_BACK_TREES && p.thickness != LRT_THICKNESS_INFINITE; }

// (planes: its depth plane's t and its back plane's, which lrt_face
// compares with the hit's t instead of reading the texel again)
bool lrt_test_texel(LrtParams p, LrtSetup s, uint tx, uint ty, float en, float ex, out float t, out vec2 planes)
{
    t = 0.0;
    planes = vec2(0.0, 0.0);
    if (tx >= p.width || ty >= p.height) return false; // padding
    float tz = lrt_depth_plane(s, p.format, lrt_depth_raw(p, tx, ty));
    planes.x = tz;
    if (s.neg.z != 0u) ex = min(tz, ex);
    else en = max(tz, en);
    // the back plane (entered going up, v.z < 0; left going down) only
    // narrows [en, ex]: not read after a miss, nor for a ray going down
    // that enters through the top, whose back plane comes no earlier (the
    // same plane on a back never in front: a back map, or float depth)
    bool back_after_depth = p.thickness == LRT_THICKNESS_BACK_MAP || p.format == LRT_FLOAT32;
    bool hit = en <= lrt_widen(ex);
    if (hit && lrt_has_back(p) && (s.neg.z != 0u || en != tz || !back_after_depth)) {
        uint format;
        uint raw = lrt_texel_back(p, tx, ty, format);
        float tb = lrt_back_plane(s, format, raw);
        planes.y = tb;
        if (s.neg.z != 0u) en = max(tb, en);
        else ex = min(tb, ex);
        hit = en <= lrt_widen(ex);
    }
    t = en;
    return hit;
}

// the face of a hit at t in texel (tx, ty), as linear_rt.h's lrt__face:
// the plane whose t is the entering t, found by equality (an axis the ray
// does not move along has no plane there)
uint lrt_face(LrtParams p, LrtSetup s, uint tx, uint ty, float t, vec2 planes)
{
    // the top: its plane, or the near plane where the ray enters the screen
    // box through it onto a texel of depth 0 (lrt_clip's tn), as linear_rt.h
    precise float tn = (0.0 - s.o.z) * s.iv.z;
    if (s.neg.z == 0u && !s.zero.z && (planes.x == t || tn == t)) return LRT_FACE_TOP;
    precise float xe = (float(tx + s.neg.x) - s.o.x) * s.iv.x, ye = (float(ty + s.neg.y) - s.o.y) * s.iv.y;
    if ((!s.zero.x && xe == t) || (!s.zero.y && ye == t)) return LRT_FACE_SIDE;
    // the back plane (a moving z: lrt_back_plane's t is the depth plane's),
    // or without a back the far plane
    float back = lrt_has_back(p) ? planes.y : lrt_depth_plane(s, LRT_FLOAT32, floatBitsToUint(1.0));
    if (s.neg.z != 0u && !s.zero.z && back == t) return LRT_FACE_BACK;
    return LRT_FACE_INSIDE;
}

// (scale_normal: 2^t_exp is a normal float, as linear_rt.h's t_scale >=
// FLT_MIN, and the scale is that product)
// a walk's t as the ray's (linear_rt.h's lrt__ray_t): the set-up's scale
// undone, clamped to [tmin, tmax]
float lrt_ray_t(LrtSetup s, int t_exp, bool scale_normal, float t, float tmin, float tmax)
{
    precise float tb = t + s.t_base;
    // t + (+0) is +0 for t = -0: a compiler that folds x + 0 to x (the
    // ordinary set-up's t_base is the constant 0) keeps -0, the CPU not
    if (tb == 0.0 && floatBitsToUint(s.t_base) == 0u) tb = 0.0;
    precise float product = tb * lrt_pow2(t_exp);
    float tt = scale_normal ? product : lrt_ldexp(tb, t_exp); // the set-up's scale undone (2^t_exp may be subnormal)
    float lo = lrt_flush(tmin), hi = lrt_flush(tmax); // as the walk read them
    return tt < lo ? lo : tt > hi ? hi : tt;
}

LrtHit lrt_report_hit(LrtParams p, LrtSetup s, int t_exp, bool scale_normal, float t, float tmin, float tmax, uint tx,
                      uint ty, vec2 planes)
{
    LrtHit h;
    h.t = lrt_ray_t(s, t_exp, scale_normal, t, tmin, tmax);
    h.x = tx;
    h.y = ty;
    h.kind = LRT_HIT;
    h.face = lrt_face(p, s, tx, ty, t, planes);
    return h;
}

// nodes (texels at 0) in a row / column of level lv's grid: ceil(size / span)
// (nested ceilings of divisions are one ceiling), no per-level table
uint lrt_grid_w(uint width, uint lv) { return (width + (1u << lrt_span_w_log2(lv)) - 1u) >> lrt_span_w_log2(lv); }
uint lrt_grid_h(uint height, uint lv) { return (height + (1u << lrt_span_h_log2(lv)) - 1u) >> lrt_span_h_log2(lv); }

// node slots of stored level lv (every block of the level above holds 8)
uint lrt_level_slots(LrtParams p, uint lv)
{
    return lv >= p.level_count ? 1u : lrt_grid_w(p.width, lv + 1u) * lrt_grid_h(p.height, lv + 1u) * 8u;
}

// the first back code of a back-map tree: after every node's heights (a
// compact level-1 node takes 2 code units, not 8)
uint lrt_back_codes(LrtParams p)
{
    uint total = 0u;
    for (uint lv = 1u; lv <= p.level_count; ++lv) total += lrt_level_slots(p, lv);
    return total * 8u - (lrt_compact(p) ? lrt_level_slots(p, 1u) * 5u : 0u);
}

// first code of node (nx, ny) of stored level lv, whose first node is at
// off: its Morton index in the level (no table: from the push constants).
// A compact level-1 node's word is at word index code0 / 8.
uint lrt_node_code0(LrtParams p, uint lv, uint off, uint nx, uint ny)
{
    uint index = 0u;
    if (lv < p.level_count) {
        index = ((ny >> lrt_bh_log2(lv)) * lrt_grid_w(p.width, lv + 1u) + (nx >> lrt_bw_log2(lv))) * 8u +
                lrt_child_slot(lv, nx, ny);
    }
    return (off + index) * 8u - (lv >= 2u && lrt_compact(p) ? lrt_level_slots(p, 1u) * 5u : 0u);
}

// ---- the walk: from the ray's origin up and down the tree, no stack ----
//
// The CPU's walk (linear_rt.h) goes down from the top and visits children
// in visiting order (row-major with the axes flipped by the direction's
// signs, front to back along any straight line), so its hit is the first
// texel in that order that passes its exact test. This walk finds the same
// texel without descending at the origin: it starts at the level-1 node of
// the first texel the ray touches (every texel the ray can touch comes at
// or after it in visiting order), takes that node's children, and when a
// node is done goes to its next pending sibling, or up to its parent to
// take the children after it. Its state is the position (a texel of the
// current node), the level, and per level the 8 bits of the children still
// to visit (a uvec4): registers, no array.

// the first texel along one axis that the ray touches at t_lo: the one
// holding o + t_lo v, or one behind it whose edge lies within the widening
// of t_lo (docs/MODEL.md: a touch is a hit), found with the planes' own t
int lrt_first_texel(float o, float v, float iv, uint neg, bool zero, float t_lo, int size)
{
    precise float p = o + t_lo * v;
    p = p > -2.0 ? p : -2.0;
    p = p < float(size) + 2.0 ? p : float(size) + 2.0;
    int c = int(floor(p));
    if (zero) return clamp(c - ((neg == 0u && float(c) == o) ? 1 : 0), 0, size - 1); // on an edge: the first in order
    c = clamp(c, 0, size - 1);
    for (;;) { // while the texel behind it is touched at t_lo
        int b = neg != 0u ? c + 1 : c - 1;
        if (b < 0 || b >= size) break;
        precise float e = (float(neg != 0u ? c + 1 : c) - o) * iv; // the plane between them
        if (!(t_lo <= lrt_widen(e))) break;
        c = b;
    }
    return c;
}

// child `slot` of node (nx, ny) of level lv: its node (x, y) at level lv - 1
// (linear_rt.h's lrt__child)
uvec2 lrt_child(uint lv, uint nx, uint ny, uint slot)
{
    uint bwl = lrt_bw_log2(lv - 1u);
    return uvec2((nx << bwl) + (slot & ((1u << bwl) - 1u)), (ny << (3u - bwl)) + (slot >> bwl));
}

uint lrt_mask_get(uvec4 m, uint lv) { return (m[lv >> 2] >> ((lv & 3u) * 8u)) & 0xffu; }
uvec4 lrt_mask_set(uvec4 m, uint lv, uint bits)
{
    uint sh = (lv & 3u) * 8u;
    m[lv >> 2] = (m[lv >> 2] & ~(0xffu << sh)) | (bits << sh);
    return m;
}

// the 8 codes from code slot0 on (a node's) in one go: 4 words, one load
// of a uvec4 where the includer gives LRT_NODE_QUAD (fewer loads, each
// behind a branch per lane on llvmpipe)
uvec4 lrt_node_words(uint slot0)
{
#ifdef LRT_NODE_QUAD
    return LRT_NODE_QUAD(slot0 >> 3);
#else
    return uvec4(LRT_NODE_WORD(slot0 >> 1), LRT_NODE_WORD((slot0 >> 1) + 1u), LRT_NODE_WORD((slot0 >> 1) + 2u),
                 LRT_NODE_WORD((slot0 >> 1) + 3u));
#endif
}

// a compact level-1 node's 8 codes, packed as lrt_node_words gives a
// node's: h - ((j_s * scale) >> 4) for its word's 4-bit steps j_s, h its
// own height in its parent (linear_rt.h's lrt__compact_code)
uvec4 lrt_compact_words(uint word, uint h, uint scale)
{
    uvec4 at = uvec4(0u, 8u, 16u, 24u);
    uvec4 lo = uvec4(h) - ((((uvec4(word) >> at) & 15u) * scale) >> 4u);
    uvec4 hi = uvec4(h) - ((((uvec4(word) >> (at + 4u)) & 15u) * scale) >> 4u);
    return lo | (hi << 16u);
}

// code index of compact level-1 node k's scale: after the level's words
uint lrt_compact_scale_slot(LrtParams p, uint k) { return lrt_level_slots(p, 1u) * 2u + k; }

// code slot of a node whose words are w (lrt_code's order)
uint lrt_code_in(uvec4 w, uint slot) { return (w[slot >> 1] >> ((slot & 1u) * 16u)) & 0xffffu; }

// The node test's planes, once per walked ray (linear_rt.h's
// lrt__cull_constants). A node's codes only cull (a texel they let through
// gets its exact test), so a plane p's t may be p * iv + c (c = -o iv), one
// step, fused or not, if c is moved out by more than that step's error: a
// few ulps of (|p| + |o|) |iv| with |p| <= extent, so 2^-19 of it, and
// 2^-19 |t_hi| for the exits' widening (lrt_widen grows an exit <= t_hi by
// at most 2^-21 |t_hi|). An axis the ray does not move along (or by less
// than 2^-100) takes iv = +-2^100 and |t_hi| more margin: a plane more than
// about 2^-90 of a texel from o culls as it does exactly, a nearer one never.
struct LrtCull {
    vec2 iv, en, ex; // x and y: plane p is entered at p * iv + en, left at p * iv + ex
    float za, zb;    // a child's depth plane: t = code * za + zb
    float ba, bb;    // its back plane: t = back code * ba + bb
    float lo, hi;    // the segment: t_lo, and t_hi widened
};

void lrt_cull_axis(float o, float iv, uint neg, bool zero, float extent, float t_hi, out float civ, out float c_en,
                   out float c_ex)
{
    const float IV_MAX = 1.26765060e30; // 2^100
    const float MARGIN = 1.0 / 524288.0; // 2^-19
    bool huge = zero || !(abs(iv) < IV_MAX);
    float m = huge ? IV_MAX : abs(iv);
    civ = neg != 0u ? -m : m;
    precise float c = -o * civ;
    precise float d = (abs(o) + extent) * m * MARGIN + abs(t_hi) * (huge ? 2.0 : MARGIN);
    precise float a = c - d, b = c + d;
    c_en = a;
    c_ex = b;
}

LrtCull lrt_cull_setup(LrtParams p, LrtSetup s)
{
    // just below 1/65535, the same float as linear_rt.h's decode_scale
    float decode_scale = uintBitsToFloat(0x37800078u);
    // just above 1/65535, linear_rt.h's back_scale
    float back_scale = uintBitsToFloat(0x37800088u);
    LrtCull c;
    float zen, zex, za;
    lrt_cull_axis(s.o.x, s.iv.x, s.neg.x, s.zero.x, float(1u << lrt_span_w_log2(p.level_count)), s.t_hi, c.iv.x, c.en.x,
                  c.ex.x);
    lrt_cull_axis(s.o.y, s.iv.y, s.neg.y, s.zero.y, float(1u << lrt_span_h_log2(p.level_count)), s.t_hi, c.iv.y, c.en.y,
                  c.ex.y);
    // a child's depth plane is (65535 - code) * decode_scale, below 1
    precise float oz = s.o.z - 65535.0 * decode_scale;
    lrt_cull_axis(oz, s.iv.z, s.neg.z, s.zero.z, 1.0, s.t_hi, za, zen, zex);
    precise float zan = -decode_scale * za;
    c.za = zan;
    c.zb = s.neg.z != 0u ? zex : zen;
    // the back plane is back code * back_scale: entered going up, left going down
    lrt_cull_axis(s.o.z, s.iv.z, s.neg.z, s.zero.z, 1.0, s.t_hi, za, zen, zex);
    precise float ban = back_scale * za;
    c.ba = ban;
    c.bb = s.neg.z != 0u ? zen : zex;
    c.lo = s.t_lo;
    c.hi = lrt_widen(s.t_hi);
    return c;
}

// entering and leaving t of the column (row) [a, a + step] of a node, by
// the cull's planes, clamped to the segment
void lrt_cull_slab(LrtCull c, int axis, float a, float step, uint neg, out float en, out float ex)
{
    float b = a + step; // exact: small integers times powers of two
    precise float ta = a * c.iv[axis], tb = b * c.iv[axis];
    precise float e = (neg != 0u ? tb : ta) + c.en[axis], x = (neg != 0u ? ta : tb) + c.ex[axis];
    en = max(e, c.lo);
    ex = min(x, c.hi);
}

// the children of node (nx, ny) of level lv >= 1 that the ray may meet, bit
// k for the child met k-th in visiting order (slot k ^ flip): the cull's
// planes, never tighter than the exact ones. One loop for 4x2 and 2x4
// nodes: a child's column and row select among the node's 4 columns and 4
// rows (a SIMD device runs both sides of a branch on the node's shape where
// its lanes differ)
uint lrt_cull_children(LrtParams p, LrtSetup s, LrtCull c, uint lv, uint off, uint nx, uint ny, uint flip, uint back_base,
                       bool back)
{
    uint cl = lv - 1u;
    bool tall = lrt_bw_log2(cl) == 1u;
    float sw = float(1u << lrt_span_w_log2(cl)), sh = float(1u << lrt_span_h_log2(cl));
    float x0 = float((nx << lrt_bw_log2(cl)) << lrt_span_w_log2(cl)), y0 = float((ny << lrt_bh_log2(cl)) << lrt_span_h_log2(cl));
    uint slot0 = lrt_node_code0(p, lv, off, nx, ny);
    uvec4 w, b; // the codes and the back codes
    if (lv == 1u && lrt_compact(p)) { // with the node's own height, in its level-2 parent
        uint own = lrt_node_code0(p, 2u, lrt_level_slots(p, 1u), nx >> 1, ny >> 2) + lrt_child_slot(1u, nx, ny);
        uint k = slot0 >> 3, scale = lrt_compact_scale_slot(p, k);
        w = lrt_compact_words(LRT_NODE_WORD(k), lrt_code(own), lrt_code(scale));
        b = back ? lrt_compact_words(LRT_NODE_WORD((back_base >> 1) + k), lrt_code(back_base + own), lrt_code(back_base + scale))
                 : uvec4(0u, 0u, 0u, 0u);
    } else {
        w = lrt_node_words(slot0);
        b = back ? lrt_node_words(back_base + slot0) : uvec4(0u, 0u, 0u, 0u);
    }
    // the depth plane bounds a child's entry where the ray goes away from
    // the camera, its exit where it comes nearer; the back plane the other
    // way round. Selects, no branch in the slot loop: llvmpipe branches on
    // every if a lane may take
    bool nz = s.neg.z != 0u;
    uint met = 0u; // bit slot: the child of that slot met
    for (uint slot = 0u; slot < 8u; ++slot) { // 4x2: slot = row << 2 | column; 2x4: row << 1 | column
        // a child's column and row planes, each slot's own (lrt_cull_slab):
        // the 4 columns' and rows' planes computed once would hold 16
        // registers through the loop
        float ce, cx, re, rx;
        lrt_cull_slab(c, 0, x0 + sw * float(tall ? slot & 1u : slot & 3u), sw, s.neg.x, ce, cx);
        lrt_cull_slab(c, 1, y0 + sh * float(tall ? slot >> 1 : slot >> 2), sh, s.neg.y, re, rx);
        precise float tz = float(lrt_code_in(w, slot)) * c.za + c.zb;
        precise float tb = float(lrt_code_in(b, slot)) * c.ba + c.bb;
        float en = max(max(ce, re), max(nz ? -LRT_INF : tz, back && nz ? tb : -LRT_INF));
        float ex = min(min(cx, rx), min(nz ? tz : LRT_INF, back && !nz ? tb : LRT_INF));
        met |= (en <= ex ? 1u : 0u) << slot;
    }
    // into visiting order: bit k for slot k ^ flip
    met = (flip & 1u) != 0u ? ((met & 0x55u) << 1) | ((met >> 1) & 0x55u) : met;
    met = (flip & 2u) != 0u ? ((met & 0x33u) << 2) | ((met >> 2) & 0x33u) : met;
    met = (flip & 4u) != 0u ? ((met & 0x0fu) << 4) | (met >> 4) : met;
    return met;
}

// the flip into visiting order of a level-lv node's children: those of
// 2x4 blocks or of 4x2 blocks (lrt_walk_origin's flip_tall, flip_wide)
uint lrt_flip_of(uint lv, uint flip_tall, uint flip_wide) { return lrt_bw_log2(lv - 1u) == 1u ? flip_tall : flip_wide; }

// a ray in a plane of the texel grid (linear_rt.h's lrt__in_grid_plane): x
// constant on a texel edge (v.x = 0, o.x whole), or y. The texels on both
// sides are met over the same t, out of visiting order
bool lrt_in_grid_plane(vec3 o, bvec3 zero) { return (zero.x && floor(o.x) == o.x) || (zero.y && floor(o.y) == o.y); }

// Where a budgeted walk that stops before it tests node (lv, nx, ny) has
// proven its segment free (linear_rt.h's lrt__budget_t, which says
// why): before the t where it enters that node, or, where it has just
// climbed to it (eligible: the children after the one it came from),
// before the t where it leaves that child
float lrt_budget_t(LrtSetup s, uint lv, uint nx, uint ny, uint eligible, uint flip_tall, uint flip_wide)
{
    if (lrt_in_grid_plane(s.o, s.zero)) return s.t_lo; // texels met out of visiting order: nothing proven
    if (eligible != 0xffu) { // the child it came from, k-th in visiting order
        uint k = eligible != 0u ? uint(findLSB(eligible)) - 1u : 7u;
        uvec2 c = lrt_child(lv, nx, ny, k ^ lrt_flip_of(lv, flip_tall, flip_wide));
        nx = c.x;
        ny = c.y;
        lv -= 1u;
    }
    float en = s.t_lo, ex = s.t_hi;
    float x0 = float(nx << lrt_span_w_log2(lv)), y0 = float(ny << lrt_span_h_log2(lv));
    lrt_slab(x0, x0 + float(1u << lrt_span_w_log2(lv)), s.o.x, s.iv.x, s.neg.x, s.zero.x, en, ex);
    lrt_slab(y0, y0 + float(1u << lrt_span_h_log2(lv)), s.o.y, s.iv.y, s.neg.y, s.zero.y, en, ex);
    float t = eligible != 0xffu || ex < en ? ex : en;
    return t > s.t_lo ? t : s.t_lo;
}

// ---- the finish of a budget (LRT_TRACE_FINISH): a march from the free t,
// linear_rt.h's lrt__finish step for step (which says what it answers)

// the texel under the point at walk t along one axis: o + t v floored, on
// the map (a NaN: 0)
uint lrt_finish_texel(float o, float v, float t, uint size)
{
    precise float q = o + t * v;
    return q >= 1.0 ? (q < float(size) ? uint(q) : size - 1u) : 0u;
}

// whether the point at walk t lies in the solid of the texel (x, y) under
// it: that texel's exact test over [t, t]
bool lrt_finish_inside(LrtParams p, LrtSetup s, float t, out uint x, out uint y)
{
    float tt;
    vec2 planes;
    x = lrt_finish_texel(s.o.x, s.v.x, t, p.width);
    y = lrt_finish_texel(s.o.y, s.v.y, t, p.height);
    return lrt_test_texel(p, s, x, y, t, t, tt, planes);
}

// samples at t0 + k (t1 - t0) 2^-n, k = 0 .. 2^n (finish: n + 1), t1 the
// segment's end; at the first inside, bisections with the sample before.
// true with the texel of the last sample inside, its t and the face guessed
bool lrt_finish(LrtParams p, LrtSetup s, uint finish, float t0, out uint hx, out uint hy, out float ht, out uint face)
{
    uint n = min(finish - 1u, LRT_K_FINISH_MAX - 1u), steps = 1u << n; // (an engine's own flags: at most 2^7)
    float t1 = s.t_hi > t0 ? s.t_hi : t0;
    precise float dt = (t1 - t0) * lrt_pow2(-int(n));
    float lo = t0, hi = t0;
    uint x = 0u, y = 0u, lx = 0u, ly = 0u, k = 0u;
    bool inside = false;
    for (; k <= steps && !inside; ++k) { // [lo, hi]: the sample before, this one
        lo = hi;
        lx = x;
        ly = y;
        precise float at = t0 + dt * float(k);
        hi = k == steps ? t1 : at;
        inside = lrt_finish_inside(p, s, hi, x, y);
    }
    if (k == 1u) { // inside at t0: the ray was over this texel before it
        lx = x;
        ly = y;
    }
    for (uint b = 0u; inside && k > 1u && b < LRT_K_FINISH_BISECTIONS; ++b) {
        precise float mid = 0.5 * (lo + hi);
        uint mx, my;
        if (lrt_finish_inside(p, s, mid, mx, my)) {
            hi = mid;
            x = mx;
            y = my;
        } else {
            lo = mid;
            lx = mx;
            ly = my;
        }
    }
    hx = x;
    hy = y;
    ht = hi;
    face = lx == x && ly == y ? (s.neg.z != 0u ? LRT_FACE_BACK : LRT_FACE_TOP) : LRT_FACE_SIDE;
    return inside;
}

// a budget's stop at walk t, proven free before it, told in the caller's
// ray: its finish's estimate (finish: the trace flags' field), or a budget miss
LrtHit lrt_report_budget(LrtParams p, LrtSetup s, int t_exp, bool scale_normal, float t, float tmin, float tmax, uint finish)
{
    LrtHit hit;
    hit.x = 0u;
    hit.y = 0u;
    hit.kind = LRT_MISS_BUDGET;
    hit.face = LRT_FACE_NONE;
    float at;
    uint x, y, face;
    // (nested: HLSL's && evaluates both sides, and a finish of 0 would march 2^31 steps)
    if (finish != 0u) {
        if (lrt_finish(p, s, finish, t, x, y, at, face)) {
            t = at;
            hit.x = x;
            hit.y = y;
            hit.kind = LRT_HIT_ESTIMATE;
            hit.face = face;
        }
    }
    hit.t = lrt_ray_t(s, t_exp, scale_normal, t, tmin, tmax);
    return hit;
}

// what lrt_walk_origin found
const uint LRT_WALK_MISS = 0u;
const uint LRT_WALK_HIT = 1u;
const uint LRT_WALK_BUDGET = 2u; // the budget ran out before a node's test

// The walk (linear_rt.h's lrt__walk_origin, the same steps under the same
// names): from the level-1 node of the texel where the segment starts, up to
// the start node of level top, which holds the whole segment. A step tests
// the current node's children; at level 1 the texels the codes let through
// get their exact test, in visiting order; above it the walk goes down into
// the first child met, and the others wait in masks (8 bits a level: the
// state is a few registers, no stack). A node done, the walk takes the next
// pending child of the lowest level that has one, in one step, or climbs
// past the levels it has tested; a parent never tested (the walk began
// below it) has only the children after the one just walked left to test,
// unless the segment ends inside that one. LRT_WALK_HIT with the first
// texel hit (hx, hy) and its t; LRT_WALK_MISS; or, with a budget (node
// tests, 0: none), LRT_WALK_BUDGET where the next test would pass it, ht
// then the t before which the segment is proven free (lrt_budget_t). Top 0:
// the segment's one texel (sx, sy) of lrt_start_node, its exact test alone
// (one call site of lrt_test_texel: a GPU pays for each copy's code).
uint lrt_walk_origin(LrtParams p, LrtSetup s, uint top, uint sx, uint sy, uint budget, out uint hx, out uint hy,
                     out float ht, out vec2 hplanes)
{
    hplanes = vec2(0.0, 0.0);
    hx = 0u;
    hy = 0u;
    ht = 0.0;
    uint back_base = lrt_has_back(p) ? lrt_back_codes(p) : 0u;
    // the back plane; not for a z scaled by 2^zk (lrt_setup_rare): the unscaled codes would cut it
    bool back = lrt_has_back(p) && s.zk == 0;
    // top 0 (a camera ray): no node test, and no start texel to search for
    LrtCull cull = lrt_cull_setup(p, s);
    uint px = sx, py = sy;
    if (top != 0u) {
        px = uint(lrt_first_texel(s.o.x, s.v.x, s.iv.x, s.neg.x, s.zero.x, s.t_lo, int(p.width)));
        py = uint(lrt_first_texel(s.o.y, s.v.y, s.iv.y, s.neg.y, s.zero.y, s.t_lo, int(p.height)));
    }
    uint flip_wide = (s.neg.x != 0u ? 3u : 0u) | (s.neg.y != 0u ? 4u : 0u); // children in 4x2 blocks
    uint flip_tall = (s.neg.x != 0u ? 1u : 0u) | (s.neg.y != 0u ? 6u : 0u); // in 2x4 blocks
    // the texel where the segment starts (px, py), and its level-1 node
    uint lv = 1u, nx = px >> 2, ny = py >> 1, off = 0u; // the node, and its level's first node
    // the levels above lv up to reached (the highest the walk has climbed
    // to) were tested: masks holds their pending children, a byte a level,
    // and bit L of busy says level L's byte is not empty
    uint eligible = 0xffu, reached = 1u, busy = 0u, steps = 0u;
    // top 0: the bit of texel (px, py) in visiting order
    uint one = top == 0u ? 1u << ((((py & 1u) << 2) | (px & 3u)) ^ lrt_flip_of(1u, flip_tall, flip_wide)) : 0u;
    uvec4 masks = uvec4(0u, 0u, 0u, 0u);
    for (;;) {
        if (budget != 0u && steps == budget) { // the budget is spent: the next node is not tested
            ht = lrt_budget_t(s, lv, nx, ny, eligible, flip_tall, flip_wide);
            return LRT_WALK_BUDGET;
        }
        ++steps;
        uint flip = lrt_flip_of(lv, flip_tall, flip_wide);
        uint m = one; // top 0: the one texel, no node tested
        if (one == 0u) m = lrt_cull_children(p, s, cull, lv, off, nx, ny, flip, back_base, back) & eligible;
        one = 0u;
        // a padding node (past its level's grid) has no children in memory:
        // never down into one (fuzz_core: a read past the nodes)
        if (lv >= 2u && (nx >= lrt_grid_w(p.width, lv) || ny >= lrt_grid_h(p.height, lv))) m = 0u;
        if (lv == 1u) { // texels: the exact test, in visiting order
            while (m != 0u) {
                uint slot = uint(findLSB(m)) ^ flip;
                m &= m - 1u;
                uint tx = nx * 4u + (slot & 3u), ty = ny * 2u + (slot >> 2);
                float en = s.t_lo, ex = s.t_hi, t;
                lrt_slab(float(tx), float(tx + 1u), s.o.x, s.iv.x, s.neg.x, s.zero.x, en, ex);
                lrt_slab(float(ty), float(ty + 1u), s.o.y, s.iv.y, s.neg.y, s.zero.y, en, ex);
                if (lrt_test_texel(p, s, tx, ty, en, ex, t, hplanes)) {
                    hx = tx;
                    hy = ty;
                    ht = t;
                    return LRT_WALK_HIT;
                }
            }
        } else if (m != 0u) { // down into the first child met; the others wait in masks
            uint slot = uint(findLSB(m)) ^ flip;
            uint rest = m & (m - 1u);
            masks = lrt_mask_set(masks, lv, rest);
            busy |= (rest != 0u ? 1u : 0u) << lv;
            uvec2 c = lrt_child(lv, nx, ny, slot);
            nx = c.x;
            ny = c.y;
            lv -= 1u;
            off -= lrt_level_slots(p, lv);
            eligible = 0xffu;
            continue;
        }
        // this node is done. The next node in one step, not a loop over the
        // levels climbed: a SIMD group would run such a loop as often as its
        // slowest lane climbs. It is the next pending child of the lowest
        // level that has one (the levels between hold none: they are done),
        // or where none has, the children after this node's ancestor of
        // level reached in that ancestor's parent, never tested (the walk
        // began below it), unless the segment ends inside the ancestor
        uint to; // the level of the next node
        uint x0 = nx << lrt_span_w_log2(lv), y0 = ny << lrt_span_h_log2(lv); // this node's first texel
        if (busy != 0u) {
            uint up = uint(findLSB(busy));
            to = up - 1u;
            uint ux = x0 >> lrt_span_w_log2(up), uy = y0 >> lrt_span_h_log2(up);
            uint pend = lrt_mask_get(masks, up);
            uint slot = uint(findLSB(pend)) ^ lrt_flip_of(up, flip_tall, flip_wide);
            pend &= pend - 1u;
            masks = lrt_mask_set(masks, up, pend);
            busy &= pend != 0u ? ~0u : ~(1u << up);
            uvec2 c = lrt_child(up, ux, uy, slot);
            nx = c.x;
            ny = c.y;
            eligible = 0xffu;
        } else {
            if (reached >= top) return LRT_WALK_MISS; // the start node, which holds the segment, is done
            // the ancestor of level reached; an axis the ray does not move
            // along: never left, unless the ray lies on the far edge, where
            // the next node is touched too
            uint sw = lrt_span_w_log2(reached), sh = lrt_span_h_log2(reached);
            uint ax = x0 >> sw, ay = y0 >> sh;
            float fx = float((s.neg.x != 0u ? ax : ax + 1u) << sw), fy = float((s.neg.y != 0u ? ay : ay + 1u) << sh);
            float ex_x = fx == s.o.x ? -LRT_INF : LRT_INF, ex_y = fy == s.o.y ? -LRT_INF : LRT_INF;
            if (!s.zero.x) { precise float e = (fx - s.o.x) * s.iv.x; ex_x = e; }
            if (!s.zero.y) { precise float e = (fy - s.o.y) * s.iv.y; ex_y = e; }
            if (min(ex_x, ex_y) > lrt_widen(s.t_hi)) return LRT_WALK_MISS;
            uint bwl = lrt_bw_log2(reached);
            uint k = lrt_child_slot(reached, ax, ay) ^ lrt_flip_of(reached + 1u, flip_tall, flip_wide);
            eligible = ~((2u << k) - 1u) & 0xffu;
            to = reached + 1u;
            reached = to;
            nx = ax >> bwl;
            ny = ay >> (3u - bwl);
        }
        for (; lv < to; ++lv) off += lrt_level_slots(p, lv);
    }
    return LRT_WALK_MISS;
}

// the walk of a set-up ray, and its report; budget: node tests (0: none).
// A segment inside one texel (a camera ray) takes that texel's exact test
// apart, or with walk_one through the walk's copy of it: a GPU pays for every
// copy's code, ray or no ray, and a CPU device for each step of the walk's
// set-up that a camera ray would skip
LrtHit lrt_trace_setup(LrtParams p, LrtSetup s, int t_exp, bool scale_normal, uint kind, float tmin, float tmax,
                       uint flags, bool walk_one)
{
    uint budget = flags & LRT_K_TRACE_BUDGET_MASK;
    LrtHit hit;
    hit.t = 0.0;
    hit.x = 0u;
    hit.y = 0u;
    hit.face = LRT_FACE_NONE;
    uint nx, ny, hx, hy;
    float ht;
    vec2 hplanes; // the hit texel's planes (lrt_test_texel)
    uint found;
    uint top = lrt_start_node(p, s, nx, ny); // the lowest node holding the segment: its level
    if (top == 0u && !walk_one) { // one texel, (nx, ny): its box alone decides, no node tested
        float en = s.t_lo, ex = s.t_hi;
        lrt_slab(float(nx), float(nx + 1u), s.o.x, s.iv.x, s.neg.x, s.zero.x, en, ex);
        lrt_slab(float(ny), float(ny + 1u), s.o.y, s.iv.y, s.neg.y, s.zero.y, en, ex);
        found = lrt_test_texel(p, s, nx, ny, en, ex, ht, hplanes) ? LRT_WALK_HIT : LRT_WALK_MISS;
        hx = nx;
        hy = ny;
    } else {
        found = lrt_walk_origin(p, s, top, nx, ny, budget, hx, hy, ht, hplanes);
    }
    // the answer after the walk's loop: the hit's report (its face) and a
    // budget's finish stay out of it
    hit.kind = kind;
    if (found == LRT_WALK_HIT) hit = lrt_report_hit(p, s, t_exp, scale_normal, ht, tmin, tmax, hx, hy, hplanes);
    else if (found == LRT_WALK_BUDGET)
        hit = lrt_report_budget(p, s, t_exp, scale_normal, ht, tmin, tmax, flags >> LRT_K_TRACE_FINISH_SHIFT);
    return hit;
}

// ---- the cell walk: the exact ordinary pass on a GPU ----
//
// lrt_walk_origin tests a node's 8 children at once and keeps the pending
// ones in masks: its answer is the first texel in visiting order whose exact
// test passes, since a node's codes only cull. This walk finds that texel
// with a GPU's weight: one cell a step, as a Hi-Z walk does. Its state is a
// cursor (the texel where the ray enters the current cell), the level of the
// cell and that level's first node. A step tests the cursor's cell: a
// texel's exact test, or above level 0 the cell's code from its parent
// node, under the exact planes of its column and row. A cell met is entered
// (the cell of the cursor one level down); a cell not met is left: the
// cursor moves to the cell the ray enters next, and the walk tests it at
// the highest level whose cell the move changed (its parent holds the cells
// done before: never tested again, never needed).
//
// Why the order is the CPU's. Along a ray, cells of one level come in
// visiting order (row-major with the axes flipped by the direction's
// signs, front to back), but for the cells a ray touches only at a corner
// (docs/MODEL.md: a touch is a hit, an exit widened by lrt_widen). Leaving
// cell C whose column exit tx and row exit ty are within a widening of each
// other, both neighbours A (the next column) and B (the next row) may be
// touched: the walk visits both, A first unless the column boundary is the
// coarser (then B's cell comes first among the parent's children), and then
// the cell past the corner. Where they are not, the one not entered is not
// touched (its entry is past its exit widened): the exits are the exact
// test's own planes, so no margin is needed. That holds for a ray whose
// widening is small beside a texel (a thin ray, as every ordinary ray is)
// and that lies in no plane of the texel grid (lrt_walk_cells_takes); the
// others are traced by the rare pass.

// a ray the cell walk traces: one in no plane of the texel grid (the
// texels on both sides are met over the same t, out of order). Every
// ordinary ray is thin: its origin lies within 2 size + 16 of the screen
// (lrt_far_origin) and its segment on the screen (lrt_clip), so t v spans
// at most 3 x 16384 + 16 texels along an axis (LINEAR_RT_MAX_DIM), and an
// exit's widening (2^-21 t) stays below 2^-5 of a texel's t
bool lrt_walk_cells_takes(LrtSetup s) { return !lrt_in_grid_plane(s.o, s.zero); }

// the highest level whose nodes' columns (rows) split texel columns a and b:
// the largest L with span (L + (L + 1) / 2, rows L + L / 2) at most the
// highest bit where a and b differ. Column -1 (past the screen's first)
// differs from 0 in bit 31: a level past every tree's root
int lrt_split_level_x(int a, int b) { return a == b ? -1 : (2 * findMSB(uint(a ^ b))) / 3; }
int lrt_split_level_y(int a, int b) { return a == b ? -1 : (2 * findMSB(uint(a ^ b)) + 1) / 3; }

// the texel along one axis where the ray enters a cell through its other
// axis's face at t: the one holding o + t v within the cell's [lo, hi], or
// the one behind it if the ray touches it at t (its exit widened); o + t v
// is off by far less than a texel on a thin ray, so one look behind is all
int lrt_cross_texel(float o, float v, float iv, uint neg, bool zero, float t, int lo, int hi, int cur)
{
    if (zero) return cur;
    float q = o + t * v;
    int c = int(floor(clamp(q, float(lo), float(hi))));
    int b = neg != 0u ? c + 1 : c - 1;
    precise float e = (float(neg != 0u ? c + 1 : c) - o) * iv;
    return (b >= lo && b <= hi && t <= lrt_widen(e)) ? b : c;
}

// the code index of cell (cx, cy) of level lv >= 1 in its parent's node,
// whose level's first node is off: lrt_node_code0 of the parent plus the
// cell's slot. A parent and its own parent take 3 bits of x and 3 of y
// whatever their shapes (4x2 under 2x4, or 2x4 under 4x2), so the
// grandparent is (cx >> 3, cy >> 3); the root's (0, 0) needs no case. A
// compact level 1 (8-bit trees) takes fewer codes: the caller subtracts them
uint lrt_cell_code(LrtParams p, uint lv, uint off, uint cx, uint cy)
{
    uint slots = lrt_child_slot(lv + 1u, cx >> lrt_bw_log2(lv), cy >> lrt_bh_log2(lv)) << 3 | lrt_child_slot(lv, cx, cy);
    uint index = ((cy >> 3) * lrt_grid_w(p.width, lv + 2u) + (cx >> 3)) * 64u + slots;
    return off * 8u + index;
}

// one axis of a cell [a, a + n): its slab (lrt_slab's numbers), the t where
// the ray leaves it along this axis (+inf: it does not move along it), the
// texel past it and its last texel in visiting order
void lrt_cell_axis(int a, int n, float o, float iv, uint neg, bool zero, inout float en, inout float ex, out float leave,
                   out int past, out int last)
{
    precise float ta = (float(a) - o) * iv, tb = (float(a + n) - o) * iv;
    lrt_slab(float(a), float(a + n), o, iv, neg, zero, en, ex);
    leave = zero ? LRT_INF : neg != 0u ? ta : tb;
    past = neg != 0u ? a - 1 : a + n;
    last = neg != 0u ? a : a + n - 1;
}

// The cell walk's state between two steps: all a compacted pass keeps of a
// ray it resumes (with the ray, whose set-up it makes again)
struct LrtCells {
    int x, y;     // the cursor (int: it may stand one texel past the screen)
    int lv;       // the level of the cell tested next
    int pend;     // a corner's second cell, entered by the next move (below)
    float free_t; // no hit before it
    uint steps;   // cells and texels tested
};

// the walk's start: the cursor on the first texel the segment touches
// (every texel it touches comes at or after it in visiting order); an axis
// the ray does not move along: o's texel (o is on the screen, on no texel
// edge)
LrtCells lrt_cells_start(LrtParams p, LrtSetup s)
{
    LrtCells c;
    c.x = lrt_cross_texel(s.o.x, s.v.x, s.iv.x, s.neg.x, s.zero.x, s.t_lo, 0, int(p.width) - 1, int(s.o.x));
    c.y = lrt_cross_texel(s.o.y, s.v.y, s.iv.y, s.neg.y, s.zero.y, s.t_lo, 0, int(p.height) - 1, int(s.o.y));
    c.lv = 0;
    c.pend = 0;
    c.free_t = s.t_lo;
    c.steps = 0u;
    return c;
}

// The walk of an ordinary thin ray (lrt_trace_ray_ordinary) from state c:
// LRT_WALK_HIT with the first texel hit (hx, hy), its t and planes, or
// LRT_WALK_MISS; with stop (a count of steps, 0: none) LRT_WALK_BUDGET
// where the next step would pass it, c then the state to go on from and ht
// the t before which the segment is proven free: the t where the ray left
// the last cell it left by a move. Each plane's t, (p - o) * iv, is
// monotone in p, so every cell after it in visiting order (a corner's
// second cell too) is entered no earlier, and a texel's hit lies in its box
uint lrt_walk_cells_from(LrtParams p, LrtSetup s, inout LrtCells c, uint stop, out uint hx, out uint hy, out float ht,
                         out vec2 hplanes)
{
    hplanes = vec2(0.0, 0.0);
    hx = 0u;
    hy = 0u;
    ht = 0.0;
    uint back_base = lrt_has_back(p) ? lrt_back_codes(p) : 0u;
    bool back = lrt_has_back(p);
    // a compact level 1's nodes take fewer codes (lrt_node_code0)
    uint compact = lrt_compact(p) ? lrt_level_slots(p, 1u) * 5u : 0u;
    LrtCull cull = lrt_cull_setup(p, s); // its depth and back planes: a code's t in one step
    int x = c.x, y = c.y;
    int lv = c.lv; // the level of the cell tested
    uint off = 0u; // the first node of level lv + 1, which holds its code
    for (int l = 1; l <= lv; ++l) off += lrt_level_slots(p, uint(l));
    // a corner's second cell, entered by the next move (0: none): 1, one
    // texel back in x and on in y from the cursor (A came first), 2, on in
    // x and back in y (B came first); the level of that move above
    int pend = c.pend;
    float free_t = c.free_t;
    uint steps = c.steps;
    for (;;) {
        if (stop != 0u && steps == stop) { // the next cell is not tested
            c.x = x;
            c.y = y;
            c.lv = lv;
            c.pend = pend;
            c.free_t = free_t;
            c.steps = steps;
            ht = free_t;
            return LRT_WALK_BUDGET;
        }
        ++steps;
        uint sw = lrt_span_w_log2(uint(lv)), sh = lrt_span_h_log2(uint(lv));
        int cx = x >> sw, cy = y >> sh; // the cell (int: the cursor may stand past the screen)
        float en = s.t_lo, ex = s.t_hi, lx, ly;
        int px, py, lastx, lasty;
        lrt_cell_axis(cx << sw, 1 << sw, s.o.x, s.iv.x, s.neg.x, s.zero.x, en, ex, lx, px, lastx);
        lrt_cell_axis(cy << sh, 1 << sh, s.o.y, s.iv.y, s.neg.y, s.zero.y, en, ex, ly, py, lasty);
        bool met = false;
        if (lv == 0) {
            float t;
            if (lrt_test_texel(p, s, uint(x), uint(y), en, ex, t, hplanes)) {
                hx = uint(x);
                hy = uint(y);
                ht = t;
                return LRT_WALK_HIT;
            }
        } else if (uint(x) < p.width && uint(y) < p.height) {
            // a cell on the screen (a cursor past its edge, where a corner
            // took it, stands in no node): its code, in its parent's node
            uint code = lrt_cell_code(p, uint(lv), off, uint(cx), uint(cy)) - compact;
            bool nz = s.neg.z != 0u;
            precise float tz = float(lrt_code(code)) * cull.za + cull.zb;
            float tb = back ? float(lrt_code(back_base + code)) * cull.ba + cull.bb : 0.0;
            float e0 = max(en, max(nz ? -LRT_INF : tz, back && nz ? tb : -LRT_INF));
            float x0 = min(lrt_widen(ex), min(nz ? tz : LRT_INF, back && !nz ? tb : LRT_INF));
            met = e0 <= x0;
        }
        // met: into the cell of the cursor one level down. Else the cell is
        // done and the cursor moves to the cell the ray enters next, tested
        // at the highest level whose cell the move changed: the level of the
        // column (row) boundary crossed
        int to = lv - 1;
        if (!met) {
            int bx = lrt_split_level_x(lastx, px), by = lrt_split_level_y(lasty, py);
            float lt = min(lx, ly);
            if (pend != 0) { // the second cell of a corner
                x += (pend & 1) == (s.neg.x != 0u ? 1 : 0) ? 1 : -1;
                y += (pend & 1) == (s.neg.y != 0u ? 1 : 0) ? -1 : 1;
                to = pend >> 2;
                pend = 0;
            } else if (!(lt <= lrt_widen(s.t_hi))) {
                return LRT_WALK_MISS; // the segment ends in this cell
            } else {
                free_t = max(free_t, lt); // every cell before the next is done
                if (max(lx, ly) <= lrt_widen(lt)) { // a corner: both neighbours, in visiting order
                    bool a_first = bx <= by;
                    x = a_first ? px : lastx;
                    y = a_first ? lasty : py;
                    to = a_first ? bx : by;
                    pend = (max(bx, by) << 2) | 2 | (a_first ? 1 : 0);
                } else { // the next column, or the next row: one texel along the other axis
                    bool along_x = lx < ly;
                    int c = along_x
                                ? lrt_cross_texel(s.o.y, s.v.y, s.iv.y, s.neg.y, s.zero.y, lx, cy << sh, ((cy + 1) << sh) - 1, y)
                                : lrt_cross_texel(s.o.x, s.v.x, s.iv.x, s.neg.x, s.zero.x, ly, cx << sw, ((cx + 1) << sw) - 1, x);
                    x = along_x ? px : c;
                    y = along_x ? c : py;
                    to = along_x ? bx : by;
                }
            }
            if (to >= int(p.level_count)) return LRT_WALK_MISS; // past the root's cell: off the screen
        }
        while (lv != to) { // level by level: off follows
            bool up = lv < to;
            uint n = lrt_level_slots(p, uint(up ? lv + 1 : lv));
            off = up ? off + n : off - n;
            lv += up ? 1 : -1;
        }
    }
    return LRT_WALK_MISS;
}

// the walk from the segment's start, with a budget (cell steps, 0: none)
uint lrt_walk_cells(LrtParams p, LrtSetup s, uint budget, out uint hx, out uint hy, out float ht, out vec2 hplanes)
{
    LrtCells c = lrt_cells_start(p, s);
    return lrt_walk_cells_from(p, s, c, budget, hx, hy, ht, hplanes);
}

// a miss of the kind a failed set-up gave
LrtHit lrt_miss(uint kind)
{
    LrtHit hit;
    hit.t = 0.0;
    hit.x = 0u;
    hit.y = 0u;
    hit.kind = kind;
    hit.face = LRT_FACE_NONE;
    return hit;
}

// the ordinary set-up of a ray lrt_ray_rare lets through (scaled by its
// 2^-e); false with rare set for one it does not, or with kind set when
// nothing is left to walk
bool lrt_setup_unless_rare(LrtParams p, vec3 o, float tmin, vec3 v, float tmax, out LrtSetup s, out int e, out uint kind,
                           out bool rare)
{
    kind = LRT_MISS_INVALID_RAY;
    rare = lrt_ray_rare(p, o, tmin, v, tmax, e);
    return !rare && lrt_setup_ordinary(p, o, tmin, v, tmax, e, s, kind);
}

// the answer of a cell walk over a set-up ordinary ray (scaled by 2^-e)
// that found what found says, with its texel, t and planes (flags: the
// trace flags, whose finish a budget's stop takes)
LrtHit lrt_cells_answer(LrtParams p, LrtSetup s, int e, uint kind, float tmin, float tmax, uint found, uint hx, uint hy,
                        float ht, vec2 hplanes, uint flags)
{
    // e <= 125: 2^-e is normal
    LrtHit hit = lrt_miss(kind);
    if (found == LRT_WALK_HIT) hit = lrt_report_hit(p, s, -e, true, ht, tmin, tmax, hx, hy, hplanes);
    else if (found == LRT_WALK_BUDGET)
        hit = lrt_report_budget(p, s, -e, true, ht, tmin, tmax, flags >> LRT_K_TRACE_FINISH_SHIFT);
    return hit;
}

// a set-up ordinary thin ray of an infinite tree through the cell walk
// (flags: the trace flags, a budget and its finish)
LrtHit lrt_trace_cells(LrtParams p, LrtSetup s, int e, uint kind, float tmin, float tmax, uint flags)
{
    uint hx, hy;
    float ht;
    vec2 hplanes;
    uint found = lrt_walk_cells(p, s, flags & LRT_K_TRACE_BUDGET_MASK, hx, hy, ht, hplanes);
    return lrt_cells_answer(p, s, e, kind, tmin, tmax, found, hx, hy, ht, hplanes, flags);
}

// an ordinary ray, without the rare set-up's code: a shader a fraction of
// lrt_trace_ray's size, with a step budget as lrt_trace_ray_budget's. rare
// true (and the hit undefined) for a ray only lrt_setup_rare can set up
// (lrt_ray_rare; a direction that is only large is scaled here), or, in an
// infinite tree, one the cell walk does not take (lrt_walk_cells_takes),
// which lrt_trace_ray_budget then traces, e.g. in a second pass as the
// library's own kernel does. The same answer as lrt_trace_ray_budget for
// every other ray: an infinite tree's by the cell walk, a thickness
// tree's by the 8-child walk, whose wider step pays where each texel test
// also reads a back (docs/PERFORMANCE.md, what a wave pays)
LrtHit lrt_trace_ray_ordinary_budget(LrtParams p, vec3 origin, float tmin, vec3 dir, float tmax, uint flags,
                                     out bool rare)
{
    LrtSetup s;
    uint kind;
    int e;
    if (!lrt_setup_unless_rare(p, origin, tmin, dir, tmax, s, e, kind, rare)) return lrt_miss(kind);
    if (!LRT_INFINITE_TREES || lrt_has_back(p)) return lrt_trace_setup(p, s, -e, true, kind, tmin, tmax, flags, true);
    rare = !lrt_walk_cells_takes(s);
    return rare ? lrt_miss(kind) : lrt_trace_cells(p, s, e, kind, tmin, tmax, flags);
}

// the same, the exact walk
LrtHit lrt_trace_ray_ordinary(LrtParams p, vec3 origin, float tmin, vec3 dir, float tmax, out bool rare)
{
    return lrt_trace_ray_ordinary_budget(p, origin, tmin, dir, tmax, 0u, rare);
}

// any ray: lrt_trace of linear_rt.h, with its trace flags: a step budget
// (LRT_TRACE_BUDGET, 0 for none; a ray that needs more gets
// LRT_MISS_BUDGET) and its finish (LRT_TRACE_FINISH). A budget counts
// the steps of the walk lrt_trace takes: in an infinite tree the cell
// walk's for the rays it takes (lrt_trace_ray_ordinary_budget), else the
// 8-child walk's node tests
LrtHit lrt_trace_ray_budget(LrtParams p, vec3 origin, float tmin, vec3 dir, float tmax, uint flags)
{
    if (flags != 0u && LRT_INFINITE_TREES && !lrt_has_back(p)) {
        bool rare;
        LrtHit hit = lrt_trace_ray_ordinary_budget(p, origin, tmin, dir, tmax, flags, rare);
        if (!rare) return hit;
    }
    LrtSetup s;
    int t_exp; // the set-up scaled t by 2^-t_exp
    uint kind;
    if (!lrt_setup_ray(p, origin, tmin, dir, tmax, s, t_exp, kind)) return lrt_miss(kind);
    return lrt_trace_setup(p, s, t_exp, false, kind, tmin, tmax, flags, false);
}

// any ray, the exact walk
LrtHit lrt_trace_ray(LrtParams p, vec3 origin, float tmin, vec3 dir, float tmax)
{
    return lrt_trace_ray_budget(p, origin, tmin, dir, tmax, 0u);
}

#endif
