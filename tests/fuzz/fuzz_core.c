/* tests/fuzz/fuzz_core.c - libFuzzer harness of the CPU path of linear_rt.h.

   The input bytes are read as a depth map (size, format, flags, row stride,
   data offset, node bits, depth values), a batch of rays and a dirty rect.
   It builds (lrt_bvh_build and lrt_bvh_build_in into exactly
   lrt_bvh_memory_size heap bytes), traces, judges every answer with the
   exact reference of tests/reference.h (ref_check: MODEL.md's "Right, and
   how right"), then changes the depth inside the rect, updates and compares
   the nodes with a fresh build byte for byte. Every result code must be one
   the header documents for the inputs given; any disagreement prints what
   differed and aborts. */
#define LINEAR_RT_IMPLEMENTATION
#include "../../linear_rt.h"
#include "../reference.h"

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

static char g_map[160]; /* the map under test, for failure messages */

static void expect(const char *what, lrt_result got, codes errors)
{
    if (errors == 0 && got == LRT_SUCCESS) return;
    if ((unsigned)got < 32 && (errors & CODE(got))) return;
    FAIL("%s returned %d (%s); documented errors for this input: 0x%x", what, (int)got, lrt_result_string(got),
         (unsigned)errors);
}

/* ---- the depth map -------------------------------------------------------- */
static uint32_t bytes_per_texel(uint32_t format) { return format >= 1 && format <= 3 ? (format == 3 ? 4u : format) : 0u; }

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
    if (bpp && d->width <= LINEAR_RT_MAX_DIM && d->height <= LINEAR_RT_MAX_DIM) {
        size_t row = (size_t)d->width * bpp, stride = d->row_stride ? d->row_stride : row;
        if (stride < row) e |= CODE(LRT_ERROR_INVALID_STRIDE);
        else if (d->height > 1 && stride > ((size_t)PTRDIFF_MAX - row) / (d->height - 1))
            e |= CODE(LRT_ERROR_SIZE_OVERFLOW); /* the span, stride*(h-1) + row, exceeds PTRDIFF_MAX */
        else if (d->height >= 1) *span = stride * (d->height - 1) + row;
    }
    return e;
}

static codes bits_errors(const lrt_build_options *o)
{
    return o && o->node_bits != 0 && o->node_bits != 8 && o->node_bits != 16 ? CODE(LRT_ERROR_INVALID_OPTION) : 0;
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

/* ---- rays ---------------------------------------------------------------------
   Each of a ray's 8 floats is either 4 raw bytes (NaN, inf, huge, negative)
   or built from one byte on a grid that makes real hits, texel edges,
   corners and grazing texel tops common. */
static float texel_top(const ref_map *m, float x, float y)
{
    int i, j;
    if (!(x >= 0.0f)) x = 0.0f; /* NaN too */
    if (!(y >= 0.0f)) y = 0.0f;
    i = x < (float)m->w ? (int)x : m->w - 1;
    j = y < (float)m->h ? (int)y : m->h - 1;
    return (float)m->d[(size_t)j * (size_t)m->w + (size_t)i];
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
        case 2: v[k] = (b & 1) ? texel_top(m, v[0], v[1]) : (float)(b >> 1) / 127.0f; break;
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
static void print_judged(void)
{
    fprintf(stderr, "fuzz_core: %lu answers judged by the reference\n", g_judged);
}

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    atexit(print_judged);
    return 0;
}

/* For a failure message: the depths around the exact hit of a ray. */
static void print_neighbourhood(const ref_map *m, const ref_ray *q)
{
    ref_result e = ref_trace_ray(m, q);
    int i, j;
    if (e.kind != REF_HIT) return;
    fprintf(stderr, "fuzz_core: exact hit t=%.17g in (%d,%d); depths of rows %d..%d, columns %d..%d:\n", e.t, e.x, e.y,
            e.y - 2, e.y + 2, e.x - 2, e.x + 2);
    for (j = e.y - 2; j <= e.y + 2; ++j, fputc('\n', stderr))
        for (i = e.x - 2; i <= e.x + 2; ++i)
            if (i >= 0 && j >= 0 && i < m->w && j < m->h) fprintf(stderr, " %.9f", m->d[(size_t)j * (size_t)m->w + (size_t)i]);
            else fprintf(stderr, " -----------");
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
        if (!ref_check(m, &q, &a, (flags & LRT_TRACE_ANY_HIT) != 0, why, sizeof why)) {
            print_neighbourhood(m, &q);
            FAIL("%s, ray %zu%s o=(%a %a %a) v=(%a %a %a) t=[%a %a]: %s", g_map, i, flags ? " (any-hit)" : "",
                 r->origin[0], r->origin[1], r->origin[2], r->dir[0], r->dir[1], r->dir[2], r->tmin, r->tmax, why);
        }
        ++g_judged;
        if (h->kind != LRT_HIT && (h->t != 0.0f || h->x != 0 || h->y != 0))
            FAIL("ray %zu: a miss (kind %u) with t=%a x=%u y=%u, not 0", i, h->kind, h->t, h->x, h->y);
    }
}

/* ---- one input ------------------------------------------------------------------ */
enum { MAX_RAYS = 96 };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const uint32_t odd_formats[8] = {0, 4, 5, 7, 255, 0x10001, 0x7fffffff, 0x80000000u};
    static const uint32_t odd_sizes[4] = {0, LINEAR_RT_MAX_DIM, LINEAR_RT_MAX_DIM + 1, 0xffffffffu};
    input in = {data, size, 0};
    uint8_t size_sel = u8(&in), wb = u8(&in), hb = u8(&in), fmt_sel = u8(&in), flag_sel = u8(&in);
    uint8_t stride_sel = u8(&in), bits_sel = u8(&in), depth_mode = u8(&in), ray_sel = u8(&in), trace_sel = u8(&in);
    uint8_t rect_sel = u8(&in), rect_b[4], misc = u8(&in);
    lrt_depth d;
    lrt_build_options opt;
    const lrt_build_options *popt;
    uint32_t bpp, w, h, node_bits_raw = 0, trace_flags, i, j;
    size_t span = 0, alloc_span, mem_bytes = 0, nrays, k;
    codes derr, berr;
    unsigned char *store, *store2 = NULL, *mem = NULL;
    lrt_bvh bvh, bvh_in, sentinel, fresh;
    lrt_ray *rays;
    lrt_hit *hits, *hits2;
    ref_map ref;
    texels tx;
    lrt_result r, r_in;
    lrt_rect rect;

    memset(&bvh, 0, sizeof bvh);
    memset(&bvh_in, 0, sizeof bvh_in);
    for (k = 0; k < 4; ++k) rect_b[k] = u8(&in);
    if (bits_sel % 4 == 3) node_bits_raw = u32(&in);

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
    memset(&opt, 0, sizeof opt);
    opt.node_bits = bits_sel % 4 == 0 ? 0u : bits_sel % 4 == 1 ? 8u : bits_sel % 4 == 2 ? 16u : node_bits_raw;
    popt = (bits_sel & 0x80) && bits_sel % 4 == 0 ? NULL : &opt;

    /* rays come next in the input; the depth cycles over what is left after them */
    nrays = ray_sel % (MAX_RAYS + 1);
    d.data = (const void *)1; /* non-NULL for depth_errors; set below */
    derr = depth_errors(&d, &span);
    /* memory exactly the span, at an unaligned offset, so that ASan sees any
       read past the map; a tiny block where the span is absurd (nothing may be read) */
    alloc_span = derr & (CODE(LRT_ERROR_INVALID_SIZE) | CODE(LRT_ERROR_INVALID_FORMAT) | CODE(LRT_ERROR_INVALID_STRIDE) |
                         CODE(LRT_ERROR_SIZE_OVERFLOW))
                     ? 1
                     : span;
    store = (unsigned char *)malloc((alloc_span > ((size_t)64 << 20) ? 1 : alloc_span) + 3);
    if (!store) return 0;
    d.data = store + (misc & 3);
    /* a valid map too large to allocate (a stride just below the overflow
       boundary): only NULL data keeps the library from reading it */
    if ((misc & 0xfc) == 0xfc || alloc_span > ((size_t)64 << 20)) { d.data = NULL; alloc_span = 1; }
    derr = depth_errors(&d, &span);
    berr = derr | bits_errors(popt);

    rays = (lrt_ray *)malloc(sizeof(lrt_ray) * (nrays ? nrays : 1));
    hits = (lrt_hit *)malloc(sizeof(lrt_hit) * (nrays ? nrays : 1));
    hits2 = (lrt_hit *)malloc(sizeof(lrt_hit) * (nrays ? nrays : 1));
    memset(&ref, 0, sizeof ref);
    if (!rays || !hits || !hits2) goto done;

    /* fill the map (where there is one): row by row, padding too */
    if (alloc_span > 1) {
        size_t stride = d.row_stride ? d.row_stride : (size_t)w * bpp;
        size_t at_rays = in.at;
        in.at = in.n < in.at + nrays * 9u ? in.n : in.at + nrays * 9u; /* roughly past the structured rays */
        tx_init(&tx, in.p + in.at, in.n - in.at, depth_mode, bpp);
        in.at = at_rays;
        memset(store, 0xa5, alloc_span + 3);
        for (j = 0; j < h; ++j)
            for (i = 0; i < w; ++i) tx_fill(&tx, (unsigned char *)d.data + stride * j + (size_t)i * bpp, bpp);
    }

    /* lrt_bvh_memory_size knows size, format and node bits only */
    {
        codes merr = bits_errors(popt);
        if (w == 0 || h == 0 || w > LINEAR_RT_MAX_DIM || h > LINEAR_RT_MAX_DIM) merr |= CODE(LRT_ERROR_INVALID_SIZE);
        if (!bpp) merr |= CODE(LRT_ERROR_INVALID_FORMAT);
        expect("lrt_bvh_memory_size", lrt_bvh_memory_size(w, h, d.format, popt, &mem_bytes), merr);
        if (merr) mem_bytes = 0;
    }

    /* build, twice; on an error the lrt_bvh is untouched */
    memset(&bvh, 0x5a, sizeof bvh);
    sentinel = bvh;
    r = lrt_bvh_build(&bvh, &d, popt, NULL);
    expect("lrt_bvh_build", r, berr);
    if (r != LRT_SUCCESS && memcmp(&bvh, &sentinel, sizeof bvh) != 0) FAIL("lrt_bvh_build wrote the lrt_bvh on an error");
    if (r != LRT_SUCCESS) memset(&bvh, 0, sizeof bvh);
    {   /* exactly lrt_bvh_memory_size bytes, ending at the block's end, at any alignment;
           sometimes one byte short */
        size_t shift = (misc >> 2) & 15, give = mem_bytes;
        codes ierr = berr;
        if ((misc & 0x40) && give) { give -= 1; ierr |= CODE(LRT_ERROR_BUFFER_TOO_SMALL); }
        mem = (unsigned char *)malloc(shift + (give ? give : 1));
        if (!mem) goto done;
        if (!give) ierr |= CODE(LRT_ERROR_BUFFER_TOO_SMALL) | CODE(LRT_ERROR_NULL_POINTER); /* no size known */
        memset(&bvh_in, 0x5a, sizeof bvh_in);
        r_in = lrt_bvh_build_in(&bvh_in, &d, popt, give ? mem + shift : NULL, give);
        expect("lrt_bvh_build_in", r_in, ierr);
        if (r_in != LRT_SUCCESS && memcmp(&bvh_in, &sentinel, sizeof bvh_in) != 0)
            FAIL("lrt_bvh_build_in wrote the lrt_bvh on an error");
        if (r_in != LRT_SUCCESS) memset(&bvh_in, 0, sizeof bvh_in);
    }
    if (r == LRT_SUCCESS && bvh_in.built &&
        (memcmp(&bvh.layout, &bvh_in.layout, sizeof bvh.layout) != 0 ||
         memcmp(bvh.nodes, bvh_in.nodes, bvh.layout.bytes) != 0))
        FAIL("lrt_bvh_build_in made another tree than lrt_bvh_build");

    snprintf(g_map, sizeof g_map, "%ux%u map, format %u, flags %u, row stride %zu, %u-bit nodes", w, h,
             (unsigned)d.format, d.flags, d.row_stride, bvh.layout.node_bits);

    /* rays and the trace flags */
    if (r == LRT_SUCCESS &&
        ref_map_from_raw(&ref, d.data, (int)w, (int)h, d.row_stride, (int)d.format, (int)(d.flags & 1)) != 0)
        FAIL("the reference could not read a map the library accepted");
    {
        ref_map unit = {1, 1, NULL, NULL};
        double one = 1.0;
        unit.d = &one;
        for (k = 0; k < nrays; ++k) rays[k] = make_ray(&in, ref.d ? &ref : &unit);
    }
    trace_flags = trace_sel < 200 ? (trace_sel & 1u) : 1u << (trace_sel & 31);

    if (r != LRT_SUCCESS) { /* an unbuilt tree cannot be traced or updated */
        lrt_bvh zero;
        memset(&zero, 0, sizeof zero);
        expect("lrt_trace (unbuilt)", lrt_trace(&zero, &d, rays, hits, nrays, trace_flags),
               CODE(LRT_ERROR_INVALID_BVH) | derr);
        expect("lrt_bvh_update (unbuilt)", lrt_bvh_update(&zero, &d, NULL), CODE(LRT_ERROR_INVALID_BVH) | derr);
        goto done;
    }

    /* trace: the whole batch, judged; two slices and the build_in tree agree */
    {
        codes terr = trace_flags & ~(uint32_t)LRT_TRACE_ANY_HIT ? CODE(LRT_ERROR_INVALID_OPTION) : 0;
        size_t split = nrays ? rect_sel % (nrays + 1) : 0;
        r = lrt_trace(&bvh, &d, rays, hits, nrays, trace_flags);
        expect("lrt_trace", r, terr);
        if (r == LRT_SUCCESS) {
            judge(&ref, rays, hits, nrays, trace_flags);
            expect("lrt_trace_range", lrt_trace_range(&bvh, &d, rays, hits2, 0, split, trace_flags), 0);
            expect("lrt_trace_range", lrt_trace_range(&bvh, &d, rays, hits2, split, nrays, trace_flags), 0);
            if (nrays && memcmp(hits, hits2, sizeof(lrt_hit) * nrays) != 0) FAIL("two slices differ from one batch");
            if (bvh_in.built) {
                expect("lrt_trace (build_in)", lrt_trace(&bvh_in, &d, rays, hits2, nrays, trace_flags), 0);
                if (nrays && memcmp(hits, hits2, sizeof(lrt_hit) * nrays) != 0)
                    FAIL("the build_in tree traces otherwise");
            }
        }
        expect("lrt_trace_range (end before first)", lrt_trace_range(&bvh, &d, rays, hits, split + 1, split, 0),
               CODE(LRT_ERROR_TOO_MANY_RAYS));
        if (nrays) expect("lrt_trace (NULL hits)", lrt_trace(&bvh, &d, rays, NULL, nrays, trace_flags),
                          CODE(LRT_ERROR_NULL_POINTER) | terr);
    }

    /* update: change the depth inside a rect (or anywhere, for a whole-map
       update), then compare with a fresh build of the new map */
    {
        int whole = (rect_sel & 0xc0) == 0xc0;
        size_t stride = d.row_stride ? d.row_stride : (size_t)w * bpp;
        uint64_t x1, y1;
        codes uerr;
        lrt_depth d2 = d;
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
        if (!store2) goto done;
        memcpy(store2, store, alloc_span + 3);
        d2.data = store2 + ((const unsigned char *)d.data - store);
        tx_init(&tx, in.p + in.at, in.n - in.at, (uint8_t)(depth_mode ^ 0x5b), bpp);
        for (j = 0; j < h; ++j)
            for (i = 0; i < w; ++i) {
                int inside = whole || (uerr == 0 && i >= rect.x && i < x1 && j >= rect.y && j < y1);
                if (inside) tx_fill(&tx, (unsigned char *)d2.data + stride * j + (size_t)i * bpp, bpp);
            }
        r = lrt_bvh_update(&bvh, &d2, whole ? NULL : &rect);
        expect("lrt_bvh_update", r, whole ? 0 : uerr);
        if (r == LRT_SUCCESS) {
            expect("lrt_bvh_build (after the update)", lrt_bvh_build(&fresh, &d2, popt, NULL), 0);
            if (memcmp(fresh.nodes, bvh.nodes, bvh.layout.bytes) != 0) {
                size_t at = 0;
                while (((unsigned char *)fresh.nodes)[at] == ((unsigned char *)bvh.nodes)[at]) ++at;
                FAIL("%ux%u fmt %u flags %u bits %u: update of rect (%u,%u %ux%u)%s differs from a rebuild at node "
                     "byte %zu of %zu",
                     w, h, (unsigned)d.format, d.flags, bvh.layout.node_bits, rect.x, rect.y, rect.width, rect.height,
                     whole ? " (whole map)" : "", at, bvh.layout.bytes);
            }
            lrt_bvh_destroy(&fresh);
        }
        {   /* another size is refused */
            lrt_depth d3 = d2;
            d3.width = w > 1 ? w - 1 : w + 1;
            if (d3.width > w) d3.data = NULL; /* no bytes for a wider map: NULL is as good an answer */
            r = lrt_bvh_update(&bvh, &d3, NULL);
            expect("lrt_bvh_update (another size)", r,
                   CODE(LRT_ERROR_SIZE_MISMATCH) | (d3.data ? 0 : CODE(LRT_ERROR_NULL_POINTER)));
        }
    }

done:
    lrt_bvh_destroy(&bvh);
    lrt_bvh_destroy(&bvh_in);
    ref_map_free(&ref);
    free(store);
    free(store2);
    free(mem);
    free(rays);
    free(hits);
    free(hits2);
    return 0;
}
