/* tests/fuzz/fuzz_core.c - libFuzzer harness of the CPU path of linear_rt.h.

   The input bytes are read as a depth map (size, format, flags, row stride,
   data offset, node bits, depth values), a batch of rays and a dirty rect,
   and (byte 16, the thickness selector) the tree's thickness model
   (LRT_THICKNESS_INFINITE, LRT_THICKNESS_BACK_MAP, LRT_THICKNESS_CONSTANT,
   LRT_THICKNESS_RELATIVE or an invalid value), whether the depth's back
   pointer is set, and that back map (its stride, its values from the
   depth's palette, or one fault: NULL, another size, format or Z
   direction, a bad stride, bad flags, a back of its own). A 0 there is the infinite model
   with the flags as before: an older input with a 0 inserted at byte 16
   reads as it did (but for the one texel of a 1x1 8-bit map, which older
   versions left unfilled). The constant and relative models take their
   thickness_value, near_z and far_z from bytes read after the fixed fields
   (read_model): sane ones (0.002..10, near 0.05..2, far finite or
   INFINITY) or wild ones (0, negative, NaN, infinities, denormals, huge,
   far at or below near, raw floats); only inputs that select these models
   (byte 16 = 7 with bit 6 or 7 set: an invalid thickness before them)
   read those bytes, so older inputs keep their meaning.
   It builds (lrt_bvh_build and lrt_bvh_build_in into exactly
   lrt_bvh_memory_size heap bytes), traces, judges every answer with the
   exact reference of tests/support/reference.h (ref_check: docs/MODEL.md's "Right, and
   how right"; with the back map as the reference's b, or the reference's
   own b of the constant or relative model, ref_map_set_back_constant /
   ref_map_set_back_relative), then changes the depth (and the back map)
   inside the rect, updates and compares the nodes with a fresh build byte
   for byte. A model's parameters are judged by the header's rules alone
   (model_errors: LRT_ERROR_INVALID_THICKNESS, and the tree's back_k are
   the two constants computed in double and rounded to float); a tree the
   library builds from parameters the reference refuses is a failure. It
   also traces and updates a back-map tree without its back map, any other
   tree with one (a faulty one too: never read), a back-map tree with a
   faulty back map, the tree with a map of another format or Z direction
   (which, read as the tree's, would run past the map's bytes: refused
   before a read), builds over the built tree (refused, the tree intact),
   and traces a tree of garbage bytes (refused). Every result code must be one the header documents
   for the inputs given; any disagreement prints what differed and aborts.
   The depth structs and both maps are heap blocks of exactly their size
   (one lrt_depth without a back map), so ASan sees any read past them. */
#define LINEAR_RT_IMPLEMENTATION
#include "../../linear_rt.h"
#include "../support/reference.h"
#include "fuzz_common.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- reading the input: zeros once it runs out -------------------------- */
typedef struct input { const uint8_t *p; size_t n, at; } input;

static uint8_t u8(input *in) { return in->at < in->n ? in->p[in->at++] : 0; }
static uint16_t u16(input *in) { uint16_t a = u8(in); return (uint16_t)(a | (uint16_t)u8(in) << 8); }
static uint32_t u32(input *in) { uint32_t a = u16(in); return a | (uint32_t)u16(in) << 16; }
static float f32(input *in) { uint32_t b = u32(in); float f; memcpy(&f, &b, 4); return f; }

#define FAIL(...) (fprintf(stderr, "fuzz_core: " __VA_ARGS__), fputc('\n', stderr), abort())

/* Result codes: the documented set of errors of one call. A call must
   succeed when the set is empty, else return one of its members (the
   header does not order its checks). */
typedef uint32_t codes;
#define CODE(c) ((codes)1u << (c))

static char g_map[256]; /* the map under test, for failure messages */

static void expect(const char *what, lrt_result got, codes errors)
{
    if (errors == 0 && got == LRT_SUCCESS) return;
    if ((unsigned)got < 32 && (errors & CODE(got))) return;
    FAIL("%s returned %d (%s); documented errors for this input: 0x%x", what, (int)got, lrt_result_string(got),
         (unsigned)errors);
}

/* ---- the depth map -------------------------------------------------------- */
static uint32_t bytes_per_texel(uint32_t format) { return format >= 1 && format <= 3 ? (format == 3 ? 4u : format) : 0u; }

/* A map's stride against its rows (the depth's own, or the back map's
   against the depth's width, height and format): INVALID_STRIDE,
   SIZE_OVERFLOW, else its byte span. */
static codes stride_errors(size_t row_stride, uint32_t width, uint32_t height, uint32_t bpp, size_t *span)
{
    size_t row = (size_t)width * bpp, stride = row_stride ? row_stride : row;
    if (stride < row) return CODE(LRT_ERROR_INVALID_STRIDE);
    if (height > 1 && stride > ((size_t)PTRDIFF_MAX - row) / (height - 1))
        return CODE(LRT_ERROR_SIZE_OVERFLOW); /* the span, stride*(h-1) + row, exceeds PTRDIFF_MAX */
    if (height >= 1) *span = stride * (height - 1) + row;
    return 0;
}

/* What lrt__check_depth must say about a map, from the header's words alone. */
static codes depth_errors(const lrt_depth *d, size_t *span)
{
    codes e = 0;
    uint32_t bpp = bytes_per_texel((uint32_t)d->format);
    *span = 0;
    if (!d->data) e |= CODE(LRT_ERROR_NULL_POINTER);
    if (d->width == 0 || d->height == 0 || d->width > LINEAR_RT_MAX_DIM || d->height > LINEAR_RT_MAX_DIM)
        e |= CODE(LRT_ERROR_INVALID_SIZE);
    if (!bpp) e |= CODE(LRT_ERROR_INVALID_FORMAT);
    if (d->flags & ~(uint32_t)LRT_DEPTH_REVERSED_Z) e |= CODE(LRT_ERROR_INVALID_OPTION);
    if (bpp && d->width <= LINEAR_RT_MAX_DIM && d->height <= LINEAR_RT_MAX_DIM)
        e |= stride_errors(d->row_stride, d->width, d->height, bpp, span);
    return e;
}

/* A double rounded once to float32 is finite: below the midpoint of
   FLT_MAX and 2^128 (the midpoint itself rounds to the even 2^128, inf). */
static int float_finite(double x) { return fabs(x) < (double)FLT_MAX + ldexp(1.0, 103); }

/* ... and positive: above half the smallest denormal (2^-150, a tie that
   rounds to the even 0). */
static int float_positive(double x) { return x > ldexp(1.0, -150); }

/* The CONSTANT and RELATIVE models' parameters, from the header's words
   (lrt_build_options, lrt_layout.back_k): INVALID_THICKNESS unless
   0 < thickness_value, 0 < near_z < far_z, all finite but far_z (which may
   be +INFINITY), and the two constants, each computed in double and
   rounded once to float, are finite (the second > 0):
     inv_s = far infinite ? 1 : far / (far - near);
     CONSTANT: k0 = inv_s, k1 = value / near;  RELATIVE: k0 = value * inv_s, k1 = 1 + value.
   k: the two constants as floats, when valid. */
static codes model_errors(const lrt_build_options *o, float k[2])
{
    const double value = o->thickness_value, n = o->near_z, f = o->far_z;
    double inv_s, k0, k1;
    if (!isfinite(value) || value <= 0.0 || !isfinite(n) || n <= 0.0 || isnan(f) || !(n < f))
        return CODE(LRT_ERROR_INVALID_THICKNESS);
    inv_s = isinf(f) ? 1.0 : f / (f - n);
    k0 = o->thickness == LRT_THICKNESS_CONSTANT ? inv_s : value * inv_s;
    k1 = o->thickness == LRT_THICKNESS_CONSTANT ? value / n : 1.0 + value;
    if (!float_finite(k0) || !float_finite(k1) || !float_positive(k1)) return CODE(LRT_ERROR_INVALID_THICKNESS);
    k[0] = (float)k0; /* in range: no undefined conversion */
    k[1] = (float)k1;
    return 0;
}

/* The options: node bits not 0/8/16 (INVALID_OPTION), a thickness not one
   of lrt_thickness (INVALID_THICKNESS), the parameters of the constant and relative models
   (INVALID_THICKNESS, model_errors). */
static codes bits_errors(const lrt_build_options *o)
{
    codes e = 0;
    float k[2];
    if (o && o->node_bits != 0 && o->node_bits != 8 && o->node_bits != 16) e |= CODE(LRT_ERROR_INVALID_OPTION);
    if (o && o->thickness > LRT_THICKNESS_RELATIVE) e |= CODE(LRT_ERROR_INVALID_THICKNESS);
    if (o && (o->thickness == LRT_THICKNESS_CONSTANT || o->thickness == LRT_THICKNESS_RELATIVE)) e |= model_errors(o, k);
    return e;
}

static uint32_t thickness_of(const lrt_build_options *o) { return o ? o->thickness : (uint32_t)LRT_THICKNESS_INFINITE; }

/* The back map (dp->back) against the depth dp and the thickness model
   (the options' for a build, the tree's for update and trace), from the
   header's words: a back map exactly with a back-map model, else
   THICKNESS_MISMATCH (and the back map is not looked at); with both, the
   back map has no back of its own (THICKNESS_MISMATCH), data, the depth's
   size, format and flags (DEPTH_MISMATCH) and a stride of its own that
   fits the depth's rows. *span: the back map's bytes when that stride is
   valid. */
static codes back_errors(const lrt_depth *dp, uint32_t thickness, size_t *span)
{
    const lrt_depth *d = dp;
    int follows = d->back != NULL, back_model = thickness == LRT_THICKNESS_BACK_MAP;
    const lrt_depth *b;
    uint32_t bpp = bytes_per_texel((uint32_t)d->format);
    codes e = 0;
    *span = 0;
    if (follows != back_model) return CODE(LRT_ERROR_THICKNESS_MISMATCH);
    if (!follows) return 0;
    b = d->back;
    if (b->back) e |= CODE(LRT_ERROR_THICKNESS_MISMATCH);
    if (!b->data) e |= CODE(LRT_ERROR_NULL_POINTER);
    if (b->width != d->width || b->height != d->height) e |= CODE(LRT_ERROR_SIZE_MISMATCH);
    if (b->format != d->format || b->flags != d->flags) e |= CODE(LRT_ERROR_DEPTH_MISMATCH);
    if (bpp && d->width >= 1 && d->height >= 1 && d->width <= LINEAR_RT_MAX_DIM && d->height <= LINEAR_RT_MAX_DIM)
        e |= stride_errors(b->row_stride, d->width, d->height, bpp, span);
    return e;
}

/* What lrt__check_pair (update, trace) must say about a tree and a map pair. */
static codes pair_errors(const lrt_bvh *bvh, const lrt_depth *dp)
{
    size_t span;
    codes e = depth_errors(&dp[0], &span);
    if (!bvh->built) e |= CODE(LRT_ERROR_INVALID_BVH);
    else {
        if (dp[0].width != bvh->layout.width || dp[0].height != bvh->layout.height) e |= CODE(LRT_ERROR_SIZE_MISMATCH);
        if (dp[0].format != bvh->format || dp[0].flags != bvh->depth_flags) e |= CODE(LRT_ERROR_DEPTH_MISMATCH);
    }
    return e | back_errors(dp, bvh->built ? bvh->layout.thickness : (uint32_t)LRT_THICKNESS_INFINITE, &span);
}

/* A heap copy of a depth and, when its back pointer is set (to anything),
   of `back` as its back map: exactly the lrt_depth structs the library may
   read, the first's back pointing at the second. */
static lrt_depth *depth_pair(const lrt_depth *depth, const lrt_depth *back)
{
    size_t n = depth->back ? 2 : 1;
    lrt_depth *p = (lrt_depth *)malloc(n * sizeof *p);
    if (!p) return NULL;
    p[0] = *depth;
    if (n == 2) {
        p[1] = *back;
        p[0].back = &p[1];
    }
    return p;
}

/* One fault of a back map (k = 0..7): NULL data, another width, another
   height, another format, the other Z direction, a stride below a row, a
   stride whose span overflows, a flag bit of its own or a back of its own. Some are no fault
   for some maps (no stride is below a one-byte row; one row never
   overflows): back_errors() says. */
static void back_fault(lrt_depth *b, const lrt_depth *d, uint32_t k, uint8_t x)
{
    static const uint32_t odd_formats[4] = {0, 4, 255, 0x80000000u};
    size_t row = (size_t)d->width * (bytes_per_texel((uint32_t)d->format) ? bytes_per_texel((uint32_t)d->format) : 4u);
    switch (k & 7) {
    case 0: b->data = NULL; break;
    case 1: b->width = (x & 1) || d->width <= 1 ? d->width + 1 + (x >> 5) : d->width - 1; break;
    case 2: b->height = (x & 1) || d->height <= 1 ? d->height + 1 + (x >> 5) : d->height - 1; break;
    case 3: b->format = (lrt_format)((x & 1) ? odd_formats[(x >> 1) & 3] : 1u + ((uint32_t)d->format + (x >> 1 & 1)) % 3u); break;
    case 4: b->flags = (d->flags & LRT_DEPTH_REVERSED_Z) ^ LRT_DEPTH_REVERSED_Z; break;
    case 5: b->row_stride = row > 1 ? 1 + (size_t)x % (row - 1) : 0; break;
    case 6: b->row_stride = ((size_t)PTRDIFF_MAX - row) / (d->height > 1 ? d->height - 1 : 1) + (x % 3); break;
    default:
        if (x & 1) b->back = b; /* never read: refused for being there */
        else b->flags = (d->flags & LRT_DEPTH_REVERSED_Z) | 1u << (1 + x % 31);
        break;
    }
}

/* Texel values from the input: a palette of up to 16 raw texels (ties,
   terraces, NaN and out-of-range floats) indexed by nibbles, or the raw
   bytes; both cycle over the rest of the input when it runs short. */
typedef struct texels { const uint8_t *p; size_t n, at; int palette; uint8_t pal[16][4]; uint32_t pal_n; } texels;

static uint8_t tx_byte(texels *t) { return t->n ? t->p[t->at++ % t->n] : (uint8_t)(t->at++ * 37u); }

static void tx_init(texels *t, const uint8_t *p, size_t n, uint8_t mode, uint32_t bpp)
{
    uint32_t k, b;
    memset(t, 0, sizeof *t);
    t->p = p;
    t->n = n;
    t->palette = !(mode & 1);
    t->pal_n = 1 + ((mode >> 1) & 15);
    for (k = 0; k < t->pal_n; ++k)
        for (b = 0; b < bpp; ++b) t->pal[k][b] = tx_byte(t);
}

static void tx_fill(texels *t, unsigned char *texel, uint32_t bpp)
{
    uint32_t b;
    if (t->palette) memcpy(texel, t->pal[tx_byte(t) % t->pal_n], bpp);
    else for (b = 0; b < bpp; ++b) texel[b] = tx_byte(t);
}

/* Fill the texels of [x0, x1) x [y0, y1) of a map (row by row). */
static void tx_fill_rect(texels *t, unsigned char *map, size_t stride, uint32_t bpp, uint32_t x0, uint32_t x1, uint32_t y0,
                         uint32_t y1)
{
    uint32_t i, j;
    for (j = y0; j < y1; ++j)
        for (i = x0; i < x1; ++i) tx_fill(t, map + stride * j + (size_t)i * bpp, bpp);
}

/* ---- rays ---------------------------------------------------------------------
   Each of a ray's 8 floats is either 4 raw bytes (NaN, inf, huge, negative)
   or built from one byte on a grid that makes real hits, texel edges,
   corners and grazing texel tops (or backs, with a back map) common. */
static float texel_top(const ref_map *m, float x, float y, int back)
{
    int i, j;
    if (!(x >= 0.0f)) x = 0.0f; /* NaN too */
    if (!(y >= 0.0f)) y = 0.0f;
    i = x < (float)m->w ? (int)x : m->w - 1;
    j = y < (float)m->h ? (int)y : m->h - 1;
    return (float)(back && m->b ? m->b : m->d)[(size_t)j * (size_t)m->w + (size_t)i];
}

static lrt_ray make_ray(input *in, const ref_map *m)
{
    float v[8];
    uint8_t raw = u8(in);
    int k;
    for (k = 0; k < 8; ++k) {
        uint8_t b;
        if (raw >> k & 1) { v[k] = f32(in); continue; }
        b = u8(in);
        switch (k) {
        case 0: v[k] = (float)((uint32_t)b * (uint32_t)(m->w + 2) * 4u / 256u) / 4.0f - 1.0f; break; /* quarter texels */
        case 1: v[k] = (float)((uint32_t)b * (uint32_t)(m->h + 2) * 4u / 256u) / 4.0f - 1.0f; break;
        case 2: v[k] = (b & 1) ? texel_top(m, v[0], v[1], b & 2) : (float)(b >> 1) / 127.0f; break; /* top or back */
        case 3: v[k] = (b & 3) ? (float)b / 64.0f : 0.0f; break; /* tmin */
        case 4: case 5: v[k] = (float)(int8_t)b / 8.0f; break;
        case 6: v[k] = (float)(int8_t)b / 256.0f; break;
        default: v[k] = b == 255 ? FLT_MAX : b == 254 ? v[3] : v[3] + (float)b / 16.0f; break; /* tmax */
        }
    }
    {
        lrt_ray r;
        r.origin[0] = v[0]; r.origin[1] = v[1]; r.origin[2] = v[2]; r.tmin = v[3];
        r.dir[0] = v[4]; r.dir[1] = v[5]; r.dir[2] = v[6]; r.tmax = v[7];
        return r;
    }
}

/* Every answer is judged strictly: the bugs the fuzzer found are fixed
   (crashes-found/README.md), and none is let pass as "known" any more. */
static unsigned long g_judged;

/* how many answers were judged, printed when a run ends */
static void fuzz_print_counts(void)
{
    fprintf(stderr, "fuzz_core: %lu answers judged by the reference\n", g_judged);
}

/* For a failure message: the depths (and backs) around the exact hit of a ray. */
static void print_neighbourhood(const ref_map *m, const ref_ray *q)
{
    ref_result e = ref_trace_ray(m, q);
    int i, j, back;
    if (e.kind != REF_HIT) return;
    fprintf(stderr, "fuzz_core: exact hit t=%.17g in (%d,%d), face %d\n", e.t, e.x, e.y, e.face);
    for (back = 0; back <= (m->b != NULL); ++back) {
        const double *z = back ? m->b : m->d;
        fprintf(stderr, "fuzz_core: %s of rows %d..%d, columns %d..%d:\n", back ? "backs" : "depths", e.y - 2, e.y + 2,
                e.x - 2, e.x + 2);
        for (j = e.y - 2; j <= e.y + 2; ++j, fputc('\n', stderr))
            for (i = e.x - 2; i <= e.x + 2; ++i)
                if (i >= 0 && j >= 0 && i < m->w && j < m->h) fprintf(stderr, " %.9f", z[(size_t)j * (size_t)m->w + (size_t)i]);
                else fprintf(stderr, " -----------");
    }
}

/* Every answer judged by the reference; misses must carry t = 0, x = y = 0. */
static void judge(const ref_map *m, const lrt_ray *rays, const lrt_hit *hits, size_t n, uint32_t flags)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        const lrt_ray *r = &rays[i];
        const lrt_hit *h = &hits[i];
        ref_ray q;
        ref_answer a;
        char why[768];
        memcpy(q.o, r->origin, sizeof q.o);
        memcpy(q.v, r->dir, sizeof q.v);
        q.tmin = r->tmin;
        q.tmax = r->tmax;
        a.kind = (int)h->kind;
        a.t = h->t;
        a.x = (int)h->x;
        a.y = (int)h->y;
        a.face = (int)h->face;
        if (!ref_check(m, &q, &a, 0 /* closest hit */, why, sizeof why)) {
            print_neighbourhood(m, &q);
            FAIL("%s, ray %zu%s o=(%a %a %a) v=(%a %a %a) t=[%a %a]: %s", g_map, i, flags ? " (any-hit)" : "",
                 r->origin[0], r->origin[1], r->origin[2], r->dir[0], r->dir[1], r->dir[2], r->tmin, r->tmax, why);
        }
        ++g_judged;
        if (h->kind != LRT_HIT && (h->t != 0.0f || h->x != 0 || h->y != 0))
            FAIL("ray %zu: a miss (kind %u) with t=%a x=%u y=%u, not 0", i, h->kind, h->t, h->x, h->y);
    }
}

/* A subnormal float reads as 0 of its sign (docs/MODEL.md): a range [0, -2^-133]
   is [0, -0], and its budget miss at t = 0 lies in it. */
static float read_flushed(float f)
{
    return fabsf(f) < FLT_MIN ? copysignf(0.0f, f) : f;
}

/* A step budget's answers against the exact walk's: the same but for budget
   misses, whose t lies in [tmin, tmax] and not past the exact hit, x, y 0
   and no face, and a finish's estimates, whose t lies in [tmin, tmax], with
   a face. */
static void judge_budget(const lrt_ray *rays, const lrt_hit *hits, const lrt_hit *exact, size_t n, uint32_t budget)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        const lrt_hit *h = &hits[i], *e = &exact[i];
        const float tmin = read_flushed(rays[i].tmin), tmax = read_flushed(rays[i].tmax);
        if (h->kind == LRT_HIT_ESTIMATE) {
            if (!(h->t >= tmin && h->t <= tmax) || h->face < LRT_FACE_TOP || h->face > LRT_FACE_BACK)
                FAIL("%s, budget %#x, ray %zu: an estimate at t %a (%u,%u) face %u outside [%a, %a]", g_map, budget, i, h->t,
                     h->x, h->y, h->face, rays[i].tmin, rays[i].tmax);
        } else if (h->kind != LRT_MISS_BUDGET) {
            if (memcmp(h, e, sizeof *h) != 0)
                FAIL("%s, budget %u, ray %zu: kind %u t %a (%u,%u), the exact walk kind %u t %a (%u,%u)", g_map, budget, i,
                     h->kind, h->t, h->x, h->y, e->kind, e->t, e->x, e->y);
        } else if (!(h->t >= tmin && h->t <= tmax) || h->x || h->y || h->face != LRT_FACE_NONE ||
                   (e->kind == LRT_HIT && h->t > e->t)) {
            FAIL("%s, budget %u, ray %zu: a budget miss at t %a (%u,%u) face %u, the exact walk kind %u t %a; ray o %a %a %a "
                 "v %a %a %a t %a..%a", g_map, budget, i, h->t, h->x, h->y, h->face, e->kind, e->t, rays[i].origin[0],
                 rays[i].origin[1], rays[i].origin[2], rays[i].dir[0], rays[i].dir[1], rays[i].dir[2], rays[i].tmin, rays[i].tmax);
        }
    }
}

/* ---- the constant and relative models' parameters ------------------------------
   Read after the fixed fields (and node_bits_raw) when byte 16 selects one
   of these models: a kind byte pk, then each of thickness_value, near_z,
   far_z in turn, as its kind says. pk bits 0-1: the value, bits 2-3: near
   (0, 1: one byte on a sane grid; 2: one byte, a wild value; 3: four raw
   bytes); bits 4-6: far (0-2: one byte, near times 1 + 2^-4 .. 2^12; 3:
   +INFINITY, no byte; 4: one byte, a wild value; 5: four raw bytes; 6: one
   byte, at near: equal, one float above or below, a few ulps above; 7:
   one byte, huge and finite); bit 7 unused. sane: only the sane kinds
   (the value's and near's bit 1 cleared, far finite or INFINITY by bit 4). */
static float wild_float(uint8_t b)
{
    static const float wild[16] = {0.0f, 1e-45f, 1e-40f, FLT_MIN, 1e-30f, 1e-7f, 0.5f, 1.0f,
                                   3.0f, 1e7f, 1e30f, 1.7e38f, FLT_MAX, 0.0f, 0.0f, 0.0f};
    float v = wild[b & 15];
    if ((b & 15) == 13) v = INFINITY;
    if ((b & 15) == 14 || (b & 15) == 15) v = NAN;
    return (b & 16) ? -v : v;
}

static float grid(uint8_t b, double lo, double hi) /* lo .. hi, logarithmic */
{
    return (float)(lo * pow(hi / lo, (double)b / 255.0));
}

static void read_model(input *in, int relative, int sane, lrt_build_options *o)
{
    uint8_t pk = u8(in), b;
    uint32_t vk = pk & 3, nk = pk >> 2 & 3, fk = pk >> 4 & 7;
    if (sane) { vk &= 1; nk &= 1; fk = (fk & 1) ? 3 : 0; }
    if (vk == 3) o->thickness_value = f32(in);
    else if (vk == 2) o->thickness_value = wild_float(u8(in));
    else o->thickness_value = relative ? grid(u8(in), 0.002, 2.0) : grid(u8(in), 0.01, 10.0); /* k, or T in metres */
    if (nk == 3) o->near_z = f32(in);
    else if (nk == 2) o->near_z = wild_float(u8(in));
    else o->near_z = grid(u8(in), 0.05, 2.0);
    switch (fk) {
    case 3: o->far_z = INFINITY; break;
    case 4: o->far_z = wild_float(u8(in)); break;
    case 5: o->far_z = f32(in); break;
    case 6:
        b = u8(in);
        o->far_z = (b & 3) == 0 ? o->near_z
                   : (b & 3) == 1 ? nextafterf(o->near_z, INFINITY)
                   : (b & 3) == 2 ? nextafterf(o->near_z, -INFINITY)
                                  : o->near_z * (1.0f + (float)(1 + (b >> 2)) * FLT_EPSILON);
        break;
    case 7: b = u8(in); o->far_z = ldexpf(FLT_MAX, -(int)(b % 64)); break;
    default: o->far_z = (float)((double)o->near_z * (1.0 + exp2((double)u8(in) / 16.0 - 4.0))); break;
    }
}

/* ---- one input ------------------------------------------------------------------ */
enum { MAX_RAYS = 96 };
#define MAX_MAP_BYTES ((size_t)64 << 20) /* a valid map larger than this gets NULL data */
#define ALIGN_SLACK 15u                  /* lrt_bvh_memory_size: the nodes plus 15 bytes */

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const uint32_t odd_formats[8] = {0, 4, 5, 7, 255, 0x10001, 0x7fffffff, 0x80000000u};
    static const uint32_t odd_sizes[4] = {0, LINEAR_RT_MAX_DIM, LINEAR_RT_MAX_DIM + 1, 0xffffffffu};
    static const uint32_t odd_thickness[4] = {4, 7, 0x80000000u, 0xffffffffu}; /* 2 was one before CONSTANT */
    input in = {data, size, 0};
    uint8_t size_sel = u8(&in), wb = u8(&in), hb = u8(&in), fmt_sel = u8(&in), flag_sel = u8(&in);
    uint8_t stride_sel = u8(&in), bits_sel = u8(&in), depth_mode = u8(&in), ray_sel = u8(&in), trace_sel = u8(&in);
    uint8_t rect_sel = u8(&in), rect_b[4], misc = u8(&in), back_sel, tmode, back_k;
    lrt_depth d, bk;          /* the depth, and its back map when d.back is set (to &bk) */
    lrt_depth *dp = NULL;     /* what the library is given: one or two heap structs (depth_pair) */
    lrt_build_options opt;
    const lrt_build_options *popt;
    uint32_t bpp, w, h, node_bits_raw = 0, trace_flags, thick;
    size_t span = 0, bspan = 0, alloc_span, balloc, boff, mem_bytes = 0, nrays, k;
    codes derr, bfaults, berr;
    unsigned char *store, *store2 = NULL, *bstore = NULL, *bstore2 = NULL, *mem = NULL;
    int have_map, have_back, model;
    lrt_bvh bvh = {0}, bvh_in = {0}, sentinel = {0}, fresh = {0};
    lrt_ray *rays;
    lrt_hit *hits, *hits2;
    ref_map ref;
    texels tx;
    lrt_result r, r_in;
    lrt_rect rect;

    memset(&bvh, 0, sizeof bvh);
    memset(&bvh_in, 0, sizeof bvh_in);
    for (k = 0; k < 4; ++k) rect_b[k] = u8(&in);
    back_sel = u8(&in);
    if (bits_sel % 4 == 3) node_bits_raw = u32(&in);
    tmode = back_sel & 7;
    back_k = back_sel >> 3;
    memset(&opt, 0, sizeof opt);
    model = tmode == 7 && (back_sel & 0xc0) != 0; /* the constant or relative model: its parameters next */
    if (model) read_model(&in, (back_sel & 8) != 0, (back_sel & 0xc0) == 0x40, &opt);
    else if (rect_sel & 1) { /* the other models ignore these: wild ones change nothing */
        opt.thickness_value = wild_float(rect_b[0]);
        opt.near_z = wild_float(rect_b[1]);
        opt.far_z = wild_float(rect_b[2]);
    }

    /* size: small most of the time, sometimes a few hundred, rarely invalid
       or at the limit (then one or two rows) */
    w = 1u + wb % 64u;
    h = 1u + hb % 64u;
    if ((size_sel & 7) == 7) w = 1u + (uint32_t)wb * 5u / 4u + (size_sel >> 3);
    if ((size_sel & 0x38) == 0x38) h = 1u + (uint32_t)hb * 5u / 4u + (size_sel >> 6);
    if (size_sel == 0xc0) { w = odd_sizes[wb & 3]; h = 1u + (hb & 1); }
    if (size_sel == 0xc1) { h = odd_sizes[hb & 3]; w = 1u + (wb & 1); }

    memset(&d, 0, sizeof d);
    d.width = w;
    d.height = h;
    d.format = (lrt_format)(fmt_sel < 240 ? 1u + fmt_sel % 3u : odd_formats[fmt_sel & 7]);
    d.flags = flag_sel < 128 ? (flag_sel & 1u) : 1u << (flag_sel & 31);
    bpp = bytes_per_texel((uint32_t)d.format);
    {   /* stride: packed, padded, too small, or at the overflow boundary */
        size_t row = (size_t)w * (bpp ? bpp : 4u);
        uint32_t s = stride_sel % 8u;
        d.row_stride = s < 4 ? 0 : s < 6 ? row + (stride_sel >> 3) : s == 6 ? (row > 1 ? 1 + (stride_sel >> 3) % (row - 1) : 0)
                                                                              : ((size_t)PTRDIFF_MAX - row) / (h > 1 ? h - 1 : 1) + (stride_sel >> 3) % 3;
    }
    opt.node_bits = bits_sel % 4 == 0 ? 0u : bits_sel % 4 == 1 ? 8u : bits_sel % 4 == 2 ? 16u : node_bits_raw;
    popt = (bits_sel & 0x80) && bits_sel % 4 == 0 ? NULL : &opt;

    /* thickness (byte 16): bits 0-2 (tmode) 0: the infinite model, the flags
       as flag_sel made them; 1-4: a back-map tree with its back map; 5: a
       back-map tree without one; 6: an infinite tree with one; 7: bits 6-7
       0: an invalid thickness (4, 7, 2^31 or 2^32-1 by bits 3-4), the back
       map there when bit 5 is set; bits 6-7 1-3: the CONSTANT (bit 3 clear)
       or RELATIVE (bit 3 set) model with parameters read next (read_model:
       1 the sane ones only, 2-3 any), and a back map, a mismatch, when bit
       5 is set. Bits 3-7 (back_k): below 24 a valid back map (packed,
       padded by 1-8 bytes, or a stride of exactly one row), else the fault
       back_k - 24 (back_fault). */
    opt.thickness = tmode == 0 || tmode == 6 ? (uint32_t)LRT_THICKNESS_INFINITE
                    : tmode <= 5             ? (uint32_t)LRT_THICKNESS_BACK_MAP
                    : model                  ? (back_sel & 8 ? (uint32_t)LRT_THICKNESS_RELATIVE : (uint32_t)LRT_THICKNESS_CONSTANT)
                                             : odd_thickness[back_k & 3];
    if ((tmode >= 1 && tmode <= 4) || tmode == 6 || (tmode == 7 && (back_sel & 0x20))) d.back = &bk;
    thick = thickness_of(popt);
    memset(&bk, 0, sizeof bk);
    bk.width = w;
    bk.height = h;
    bk.format = d.format;
    bk.flags = d.flags & LRT_DEPTH_REVERSED_Z;
    {
        size_t row = (size_t)w * (bpp ? bpp : 4u);
        bk.row_stride = back_k % 3 == 0 ? 0 : back_k % 3 == 1 ? row + 1 + back_k / 3 : row;
    }
    bk.data = (const void *)1; /* non-NULL for back_errors; set below */
    if (back_k >= 24) back_fault(&bk, &d, back_k - 24u, (uint8_t)(stride_sel ^ hb));

    /* rays come next in the input; the depth cycles over what is left after them */
    nrays = ray_sel % (MAX_RAYS + 1);
    d.data = (const void *)1; /* non-NULL for depth_errors; set below */
    derr = depth_errors(&d, &span);
    /* memory exactly the span, at an unaligned offset, so that ASan sees any
       read past the map; a tiny block where the span is absurd (nothing may be read) */
    have_map = !(derr & (CODE(LRT_ERROR_INVALID_SIZE) | CODE(LRT_ERROR_INVALID_FORMAT) | CODE(LRT_ERROR_INVALID_STRIDE) |
                         CODE(LRT_ERROR_SIZE_OVERFLOW)));
    alloc_span = have_map ? span : 1;
    store = (unsigned char *)malloc((alloc_span > MAX_MAP_BYTES ? 1 : alloc_span) + 3);
    if (!store) return 0;
    d.data = store + (misc & 3);
    /* a valid map too large to allocate (a stride just below the overflow
       boundary): only NULL data keeps the library from reading it */
    if ((misc & 0xfc) == 0xfc || alloc_span > MAX_MAP_BYTES) { d.data = NULL; alloc_span = 1; have_map = 0; }
    derr = depth_errors(&d, &span);

    {   /* the back map: its own span (the depth's rows, its stride) when its
           description is valid, at an odd offset; else a tiny block */
        lrt_depth two[2];
        two[0] = d;
        two[1] = bk;
        two[0].back = &two[1];
        bfaults = back_errors(two, LRT_THICKNESS_BACK_MAP, &bspan);
        have_back = bfaults == 0 && bspan > 0 && bspan <= MAX_MAP_BYTES;
        balloc = have_back ? bspan : 1;
        boff = (misc & 0x80) ? 3 : 1;
        bstore = (unsigned char *)malloc(balloc + boff);
        if (!bstore) { free(store); return 0; }
        if (bk.data) bk.data = bfaults == 0 && bspan > MAX_MAP_BYTES ? NULL : bstore + boff; /* too large: NULL */
    }
    dp = depth_pair(&d, &bk);

    rays = (lrt_ray *)malloc(sizeof(lrt_ray) * (nrays ? nrays : 1));
    hits = (lrt_hit *)malloc(sizeof(lrt_hit) * (nrays ? nrays : 1));
    hits2 = (lrt_hit *)malloc(sizeof(lrt_hit) * (nrays ? nrays : 1));
    memset(&ref, 0, sizeof ref);
    if (!dp || !rays || !hits || !hits2) goto done;
    {
        size_t unused;
        berr = derr | bits_errors(popt) | back_errors(dp, thick, &unused);
    }

    /* fill the maps (where there are any): row by row, padding too; the
       back map after the depth, from the same palette (ties, backs in
       front of the depth) */
    {
        size_t at_rays = in.at;
        in.at = in.n < in.at + nrays * 9u ? in.n : in.at + nrays * 9u; /* roughly past the structured rays */
        tx_init(&tx, in.p + in.at, in.n - in.at, depth_mode, bpp);
        in.at = at_rays;
        if (have_map) {
            memset(store, 0xa5, alloc_span + 3);
            tx_fill_rect(&tx, (unsigned char *)d.data, d.row_stride ? d.row_stride : (size_t)w * bpp, bpp, 0, w, 0, h);
        }
        if (have_back) {
            memset(bstore, 0xa5, balloc + boff);
            tx_fill_rect(&tx, (unsigned char *)bk.data, bk.row_stride ? bk.row_stride : (size_t)w * bpp, bpp, 0, w, 0, h);
        }
    }

    /* lrt_bvh_memory_size knows size, format, node bits and the thickness
       model (with its parameters) only; a tree with any thickness model has
       twice the infinite one's bytes (the nodes, not the slack) */
    {
        codes merr = bits_errors(popt);
        if (w == 0 || h == 0 || w > LINEAR_RT_MAX_DIM || h > LINEAR_RT_MAX_DIM) merr |= CODE(LRT_ERROR_INVALID_SIZE);
        if (!bpp) merr |= CODE(LRT_ERROR_INVALID_FORMAT);
        expect("lrt_bvh_memory_size", lrt_bvh_memory_size(w, h, d.format, popt, &mem_bytes), merr);
        if (merr) mem_bytes = 0;
        if (!merr && thick != LRT_THICKNESS_INFINITE) {
            lrt_build_options o0 = opt;
            size_t m0 = 0;
            o0.thickness = LRT_THICKNESS_INFINITE;
            expect("lrt_bvh_memory_size (infinite)", lrt_bvh_memory_size(w, h, d.format, &o0, &m0), 0);
            if (m0 < ALIGN_SLACK || mem_bytes - ALIGN_SLACK != 2 * (m0 - ALIGN_SLACK))
                FAIL("lrt_bvh_memory_size: %zu bytes for a tree of thickness %u, %zu for an infinite one", mem_bytes, thick, m0);
        }
    }

    /* build, twice; on an error the lrt_bvh is untouched */
    memset(&bvh, 0x5a, sizeof bvh);
    sentinel = bvh;
    r = lrt_bvh_build(&bvh, dp, popt, NULL);
    expect("lrt_bvh_build", r, berr);
    if (r != LRT_SUCCESS && memcmp(&bvh, &sentinel, sizeof bvh) != 0) FAIL("lrt_bvh_build wrote the lrt_bvh on an error");
    if (r != LRT_SUCCESS) memset(&bvh, 0, sizeof bvh);
    if (r == LRT_SUCCESS) { /* the thickness model, its bytes and its constants */
        lrt_layout L;
        int back = thick != LRT_THICKNESS_INFINITE;
        expect("lrt_layout_compute", lrt_layout_compute(w, h, bvh.layout.node_bits, &L), 0);
        if ((bvh.layout.back_codes != 0) != back || bvh.layout.thickness != thick ||
            bvh.layout.bytes != L.bytes * (back ? 2u : 1u) || bvh.layout.bytes + ALIGN_SLACK != mem_bytes)
            FAIL("thickness %u: the tree has thickness %u, back_codes %u and %zu bytes (%zu without back codes, memory "
                 "size %zu)",
                 thick, bvh.layout.thickness, bvh.layout.back_codes, bvh.layout.bytes, L.bytes, mem_bytes);
        if (thick == LRT_THICKNESS_CONSTANT || thick == LRT_THICKNESS_RELATIVE) {
            float kk[2] = {0.0f, 0.0f};
            (void)model_errors(&opt, kk);
            if (memcmp(kk, bvh.layout.back_k, sizeof kk) != 0)
                FAIL("thickness %u, value %a, near %a, far %a: back_k (%a, %a), expected (%a, %a)", thick,
                     opt.thickness_value, opt.near_z, opt.far_z, bvh.layout.back_k[0], bvh.layout.back_k[1], kk[0], kk[1]);
        }
    }
    {   /* exactly lrt_bvh_memory_size bytes, ending at the block's end, at any alignment;
           sometimes one byte short */
        size_t shift = (misc >> 2) & 15, give = mem_bytes;
        codes ierr = berr;
        if ((misc & 0x40) && give) { give -= 1; ierr |= CODE(LRT_ERROR_BUFFER_TOO_SMALL); }
        mem = (unsigned char *)malloc(shift + (give ? give : 1));
        if (!mem) goto done;
        if (!give) ierr |= CODE(LRT_ERROR_BUFFER_TOO_SMALL) | CODE(LRT_ERROR_NULL_POINTER); /* no size known */
        memset(&bvh_in, 0x5a, sizeof bvh_in);
        r_in = lrt_bvh_build_in(&bvh_in, dp, popt, give ? mem + shift : NULL, give);
        expect("lrt_bvh_build_in", r_in, ierr);
        if (r_in != LRT_SUCCESS && memcmp(&bvh_in, &sentinel, sizeof bvh_in) != 0)
            FAIL("lrt_bvh_build_in wrote the lrt_bvh on an error");
        if (r_in != LRT_SUCCESS) memset(&bvh_in, 0, sizeof bvh_in);
    }
    if (r == LRT_SUCCESS && bvh_in.built &&
        (memcmp(&bvh.layout, &bvh_in.layout, sizeof bvh.layout) != 0 ||
         memcmp(bvh.nodes, bvh_in.nodes, bvh.layout.bytes) != 0))
        FAIL("lrt_bvh_build_in made another tree than lrt_bvh_build");

    if (thick == LRT_THICKNESS_BACK_MAP)
        snprintf(g_map, sizeof g_map, "%ux%u map, format %u, flags %u, row stride %zu, %u-bit nodes, back map row stride %zu",
                 w, h, (unsigned)d.format, d.flags, d.row_stride, bvh.layout.node_bits, bk.row_stride);
    else if (thick == LRT_THICKNESS_CONSTANT || thick == LRT_THICKNESS_RELATIVE)
        snprintf(g_map, sizeof g_map,
                 "%ux%u map, format %u, flags %u, row stride %zu, %u-bit nodes, %s thickness %a (%.9g), near %a (%.9g), far "
                 "%a (%.9g)",
                 w, h, (unsigned)d.format, d.flags, d.row_stride, bvh.layout.node_bits,
                 thick == LRT_THICKNESS_CONSTANT ? "constant" : "relative", opt.thickness_value, opt.thickness_value,
                 opt.near_z, opt.near_z, opt.far_z, opt.far_z);
    else
        snprintf(g_map, sizeof g_map, "%ux%u map, format %u, flags %u, row stride %zu, %u-bit nodes", w, h,
                 (unsigned)d.format, d.flags, d.row_stride, bvh.layout.node_bits);

    /* rays and the trace flags */
    if (r == LRT_SUCCESS &&
        ref_map_from_raw(&ref, d.data, (int)w, (int)h, d.row_stride, (int)d.format, (int)(d.flags & 1)) != 0)
        FAIL("the reference could not read a map the library accepted");
    if (r == LRT_SUCCESS && thick == LRT_THICKNESS_BACK_MAP &&
        ref_map_set_back_from_raw(&ref, bk.data, bk.row_stride, (int)d.format, (int)(d.flags & 1)) != 0)
        FAIL("the reference could not read a back map the library accepted");
    if (r == LRT_SUCCESS && (thick == LRT_THICKNESS_CONSTANT || thick == LRT_THICKNESS_RELATIVE) &&
        (thick == LRT_THICKNESS_CONSTANT
             ? ref_map_set_back_constant(&ref, opt.thickness_value, opt.near_z, opt.far_z)
             : ref_map_set_back_relative(&ref, opt.thickness_value, opt.near_z, opt.far_z)) != 0)
        FAIL("the reference refused %s thickness %a, near %a, far %a, which the library accepted",
             thick == LRT_THICKNESS_CONSTANT ? "constant" : "relative", opt.thickness_value, opt.near_z, opt.far_z);
    {
        ref_map unit = {1, 1, NULL, NULL};
        double one = 1.0;
        unit.d = &one;
        for (k = 0; k < nrays; ++k) rays[k] = make_ray(&in, ref.d ? &ref : &unit);
    }
    /* a budget of 1 step, with a finish of 2^0 to 2^7 samples every other time, or one bit */
    trace_flags = trace_sel < 200 ? (trace_sel & 1u) | ((trace_sel & 3u) == 3u ? LRT_TRACE_FINISH((trace_sel >> 2) & 7u) : 0u)
                                  : 1u << (trace_sel & 31);

    if (r != LRT_SUCCESS) { /* an unbuilt tree cannot be traced or updated */
        lrt_bvh zero = {0};
        memset(&zero, 0, sizeof zero);
        expect("lrt_trace (unbuilt)", lrt_trace(&zero, dp, rays, hits, nrays, trace_flags), pair_errors(&zero, dp));
        expect("lrt_bvh_update (unbuilt)", lrt_bvh_update(&zero, dp, NULL), pair_errors(&zero, dp));
        goto done;
    }

    /* trace: the whole batch, judged; two slices and the build_in tree agree */
    {
        codes fe = fuzz_trace_flags_bad(trace_flags) ? CODE(LRT_ERROR_INVALID_OPTION) : 0;
        codes terr = fe | pair_errors(&bvh, dp);
        size_t split = nrays ? rect_sel % (nrays + 1) : 0;
        r = lrt_trace(&bvh, dp, rays, hits, nrays, trace_flags);
        expect("lrt_trace", r, terr);
        if (r == LRT_SUCCESS && trace_flags) { /* a budget: the exact walk's answers, judged, then the budget's by them */
            expect("lrt_trace (no budget)", lrt_trace(&bvh, dp, rays, hits2, nrays, 0), 0);
            judge(&ref, rays, hits2, nrays, 0);
            judge_budget(rays, hits, hits2, nrays, trace_flags);
        }
        if (r == LRT_SUCCESS) {
            if (!trace_flags) judge(&ref, rays, hits, nrays, trace_flags);
            expect("lrt_trace_range", lrt_trace_range(&bvh, dp, rays, hits2, 0, split, trace_flags), 0);
            expect("lrt_trace_range", lrt_trace_range(&bvh, dp, rays, hits2, split, nrays, trace_flags), 0);
            if (nrays && memcmp(hits, hits2, sizeof(lrt_hit) * nrays) != 0) FAIL("two slices differ from one batch");
            if (bvh_in.built) {
                expect("lrt_trace (build_in)", lrt_trace(&bvh_in, dp, rays, hits2, nrays, trace_flags), 0);
                if (nrays && memcmp(hits, hits2, sizeof(lrt_hit) * nrays) != 0)
                    FAIL("the build_in tree traces otherwise");
            }
        }
        expect("lrt_trace_range (end before first)", lrt_trace_range(&bvh, dp, rays, hits, split + 1, split, 0),
               CODE(LRT_ERROR_TOO_MANY_RAYS));
        if (nrays) expect("lrt_trace (NULL hits)", lrt_trace(&bvh, dp, rays, NULL, nrays, trace_flags),
                          CODE(LRT_ERROR_NULL_POINTER) | terr);

        /* The thickness model must match: a back-map tree without its back
           map, an infinite tree with one (the depth itself, as good a back
           map as any); then a back-map tree with a faulty back map. Refused
           before anything is read or written: a failed update that changed
           the tree shows in the comparison with a rebuild below. */
        {
            lrt_depth flip = d, as_back = d, *dpx;
            codes xe;
            flip.back = flip.back ? NULL : &as_back;
            as_back.back = NULL;
            if (thick != LRT_THICKNESS_BACK_MAP && (rect_sel & 2)) /* not read: a mismatch before anything */
                back_fault(&as_back, &d, (uint32_t)(ray_sel ^ misc), (uint8_t)(rect_b[1] ^ trace_sel));
            dpx = depth_pair(&flip, &as_back);
            if (!dpx) goto done;
            xe = pair_errors(&bvh, dpx);
            if (xe != CODE(LRT_ERROR_THICKNESS_MISMATCH)) FAIL("harness: a flipped flag should be a mismatch (0x%x)", (unsigned)xe);
            expect("lrt_trace (thickness mismatch)", lrt_trace(&bvh, dpx, rays, hits2, nrays, trace_flags), xe | fe);
            expect("lrt_trace_range (thickness mismatch)", lrt_trace_range(&bvh, dpx, rays, hits2, 0, nrays, 0), xe);
            expect("lrt_bvh_update (thickness mismatch)", lrt_bvh_update(&bvh, dpx, NULL), xe);
            free(dpx);
        }
        {   /* a map of another format or Z direction than the tree's (and its
               back map with it): refused before any read, which as the
               tree's format would run past the map's bytes */
            lrt_depth other = d, *dpo;
            codes oe;
            if (misc & 0x20) other.flags ^= LRT_DEPTH_REVERSED_Z;
            else other.format = (lrt_format)(1u + ((uint32_t)d.format + (trace_sel & 1u)) % 3u);
            dpo = depth_pair(&other, &bk);
            if (!dpo) goto done;
            if (dpo[0].back) {
                dpo[1].format = other.format;
                dpo[1].flags = other.flags;
            }
            oe = pair_errors(&bvh, dpo);
            if (!(oe & CODE(LRT_ERROR_DEPTH_MISMATCH))) FAIL("harness: another format or Z should be a depth mismatch");
            expect("lrt_trace (another format or Z)", lrt_trace(&bvh, dpo, rays, hits2, nrays, trace_flags), oe | fe);
            expect("lrt_bvh_update (another format or Z)", lrt_bvh_update(&bvh, dpo, NULL), oe);
            free(dpo);
        }
        {   /* a build over the built tree is refused and leaves it as it was
               (LeakSanitizer would see a tree it dropped); a tree of garbage
               bytes is no tree */
            lrt_bvh before = bvh, junk;
            expect("lrt_bvh_build (over a built tree)", lrt_bvh_build(&bvh, dp, popt, NULL), CODE(LRT_ERROR_ALREADY_BUILT));
            expect("lrt_bvh_build_in (over a built tree)", lrt_bvh_build_in(&bvh, dp, popt, mem, mem_bytes),
                   CODE(LRT_ERROR_ALREADY_BUILT));
            if (memcmp(&before, &bvh, sizeof bvh) != 0) FAIL("a refused build over a built tree changed it");
            memset(&junk, 0x5a ^ (misc & 7), sizeof junk);
            expect("lrt_trace (a tree of garbage bytes)", lrt_trace(&junk, dp, rays, hits2, nrays, 0),
                   CODE(LRT_ERROR_INVALID_BVH));
            expect("lrt_bvh_update (a tree of garbage bytes)", lrt_bvh_update(&junk, dp, NULL), CODE(LRT_ERROR_INVALID_BVH));
        }
        if (thick == LRT_THICKNESS_BACK_MAP) {
            lrt_depth bad = bk, *dpf;
            codes be;
            back_fault(&bad, &d, (uint32_t)(ray_sel + back_sel + rect_sel), (uint8_t)(rect_b[0] ^ misc));
            dpf = depth_pair(&d, &bad);
            if (!dpf) goto done;
            be = pair_errors(&bvh, dpf); /* 0 where the fault is none for this map: then it traces */
            if (!be) { /* no fault after all: only if it reads no more than the back map's bytes */
                size_t fspan;
                (void)back_errors(dpf, LRT_THICKNESS_BACK_MAP, &fspan);
                if (fspan > bspan) { dpf[1].data = NULL; be = pair_errors(&bvh, dpf); }
            }
            expect("lrt_trace (faulty back map)", lrt_trace(&bvh, dpf, rays, hits2, nrays, trace_flags), be | fe);
            if (be) expect("lrt_bvh_update (faulty back map)", lrt_bvh_update(&bvh, dpf, NULL), be);
            free(dpf);
        }
    }

    /* update: change the depth and the back map inside a rect (or
       anywhere, for a whole-map update), then compare with a fresh build
       of the new maps */
    {
        int whole = (rect_sel & 0xc0) == 0xc0;
        size_t stride = d.row_stride ? d.row_stride : (size_t)w * bpp;
        uint64_t x1, y1;
        codes uerr;
        lrt_depth d2 = d, bk2 = bk, *dp2;
        if (rect_sel & 0x20) { /* raw: mostly outside the map */
            rect.x = rect_b[0] * 3u; rect.y = rect_b[1] * 3u;
            rect.width = (rect_b[2] & 0x80) ? 0xffffffffu - rect_b[2] : rect_b[2];
            rect.height = (rect_b[3] & 0x80) ? 0xffffffffu - rect_b[3] : rect_b[3];
        } else {
            rect.x = rect_b[0] % (w + 1); rect.y = rect_b[1] % (h + 1);
            rect.width = rect_b[2] % (w - rect.x + 1); rect.height = rect_b[3] % (h - rect.y + 1);
        }
        x1 = (uint64_t)rect.x + rect.width;
        y1 = (uint64_t)rect.y + rect.height;
        uerr = x1 > w || y1 > h ? CODE(LRT_ERROR_INVALID_RECT) : 0;
        store2 = (unsigned char *)malloc(alloc_span + 3);
        bstore2 = (unsigned char *)malloc(balloc + boff);
        if (!store2 || !bstore2) goto done;
        memcpy(store2, store, alloc_span + 3);
        memcpy(bstore2, bstore, balloc + boff);
        d2.data = store2 + ((const unsigned char *)d.data - store);
        if (bk.data) bk2.data = bstore2 + ((const unsigned char *)bk.data - bstore);
        tx_init(&tx, in.p + in.at, in.n - in.at, (uint8_t)(depth_mode ^ 0x5b), bpp);
        if (whole || uerr == 0) {
            uint32_t x0 = whole ? 0 : rect.x, y0 = whole ? 0 : rect.y, xe = whole ? w : (uint32_t)x1, ye = whole ? h : (uint32_t)y1;
            tx_fill_rect(&tx, (unsigned char *)d2.data, stride, bpp, x0, xe, y0, ye);
            if (thick == LRT_THICKNESS_BACK_MAP)
                tx_fill_rect(&tx, (unsigned char *)bk2.data, bk.row_stride ? bk.row_stride : (size_t)w * bpp, bpp, x0, xe, y0,
                             ye);
        }
        dp2 = depth_pair(&d2, &bk2);
        if (!dp2) goto done;
        r = lrt_bvh_update(&bvh, dp2, whole ? NULL : &rect);
        expect("lrt_bvh_update", r, pair_errors(&bvh, dp2) | (whole ? 0 : uerr));
        if (r == LRT_SUCCESS) {
            expect("lrt_bvh_build (after the update)", lrt_bvh_build(&fresh, dp2, popt, NULL), 0);
            if (memcmp(fresh.nodes, bvh.nodes, bvh.layout.bytes) != 0) {
                size_t at = 0;
                while (((unsigned char *)fresh.nodes)[at] == ((unsigned char *)bvh.nodes)[at]) ++at;
                FAIL("%ux%u fmt %u flags %u bits %u thickness %u: update of rect (%u,%u %ux%u)%s differs from a rebuild "
                     "at node byte %zu of %zu%s",
                     w, h, (unsigned)d.format, d.flags, bvh.layout.node_bits, thick,
                     rect.x, rect.y, rect.width, rect.height, whole ? " (whole map)" : "", at, bvh.layout.bytes,
                     bvh.layout.back_codes && at >= bvh.layout.bytes / 2 ? " (a back code)" : "");
            }
            lrt_bvh_destroy(&fresh);
        }
        {   /* another size is refused */
            lrt_depth d3 = d2, *dp3;
            codes se;
            d3.width = w > 1 ? w - 1 : w + 1;
            if (d3.width > w) d3.data = NULL; /* no bytes for a wider map: NULL is as good an answer */
            dp3 = depth_pair(&d3, &bk2);
            if (!dp3) { free(dp2); goto done; }
            se = pair_errors(&bvh, dp3);
            if (!(se & CODE(LRT_ERROR_SIZE_MISMATCH))) FAIL("harness: another width should be a size mismatch");
            expect("lrt_bvh_update (another size)", lrt_bvh_update(&bvh, dp3, NULL), se);
            free(dp3);
        }
        free(dp2);
    }

done:
    lrt_bvh_destroy(&bvh);
    lrt_bvh_destroy(&bvh_in);
    ref_map_free(&ref);
    free(dp);
    free(store);
    free(store2);
    free(bstore);
    free(bstore2);
    free(mem);
    free(rays);
    free(hits);
    free(hits2);
    return 0;
}
