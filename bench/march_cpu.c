/* bench/march_cpu.c - classic screen-space marching on the CPU: what an
   engine programmer writes today instead of linear_rt. Approximate methods,
   scored against the reference (exact = 0), each its own bench_method:

     "march16 cpu" ... "march128 cpu"   fixed-step linear march in t with
                                        8 bisection steps of refinement
     "dda cpu", "dda stride4 cpu"       per-pixel DDA with a thickness
                                        (McGuire & Mara 2014)
     "hiz64 cpu", "hiz128 cpu"          hierarchical min-depth traversal
                                        with an iteration cap (AMD FidelityFX
                                        SSSR)

   Common rules (docs/MODEL.md): those of examples/march.h, the classic
   march as a user writes it, whose march_linear is the fixed-step march
   here ("march64 cpu" is the demo's side-by-side march, the same code):
   invalid rays are flagged and not traced, every march first clips
   [tmin, tmax] to the screen box, a miss is told apart by the point at tmax,
   the texel "under" a point is (floor x, floor y) clamped to the map, and
   the arithmetic is double.

   Threads: trace splits the batch into `threads` contiguous slices on
   pthreads (bench/march_common.h). */
#include "bench.h"
#include "march_common.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef enum { MARCH_LINEAR, MARCH_DDA, MARCH_HIZ } march_kind;

#define HIZ_MAX_LEVELS 32
/* DDA thickness in depth units (0 near, 1 far): a sample counts as a hit when
   the ray's depth range over the pixel meets [depth, depth + 0.02]. Post-
   projection depth is non-linear, so this is thin near the camera and deep
   far away: with the default scene's planes (0.1 m and 60 m) a surface at
   depth 0.5 is 0.20 m away and 0.02 behind it is 8 mm further; at depth
   0.98 it is 4.6 m away and 0.02 behind it is the far plane. Engines tune
   the thickness per scene (often in view space); this is one fixed,
   documented choice, the same for every scene. */
#define DDA_THICKNESS 0.02

typedef struct march {
    march_kind kind;
    int param;       /* linear: steps; dda: stride; hiz: iteration cap */
    int threads;
    /* Hi-Z: level 0 is the scene's own depth (borrowed at trace time);
       levels 1.. are owned, in one allocation */
    int levels;
    uint32_t lw[HIZ_MAX_LEVELS], lh[HIZ_MAX_LEVELS];
    size_t loff[HIZ_MAX_LEVELS];
    float *chain;
    size_t chain_floats;
    uint32_t cw, ch; /* size the chain was laid out for */
} march;

typedef struct march_job {
    const march *m;
    march_map map; /* the depth, and the scene's back depths or NULL (infinite thickness) */
    const lrt_ray *rays;
    lrt_hit *hits;
} march_job;

/* m's job over the scene's maps: rays into hits (NULL: the caller keeps its
   own, as bench/wave.c does) */
static void march_job_init(march_job *jb, const march *m, const bench_scene *sc, const lrt_ray *rays, lrt_hit *hits)
{
    jb->m = m;
    jb->map.depth = sc->depth;
    jb->map.back = sc->back;
    jb->map.w = sc->width;
    jb->map.h = sc->height;
    jb->rays = rays;
    jb->hits = hits;
}

/* ---- fixed-step linear march with binary refinement: examples/march.h ---------------- */
static void linear_one(const march_job *jb, const lrt_ray *r, lrt_hit *hit)
{
    march_linear(&jb->map, jb->m->param, r, hit);
}

/* ---- per-pixel DDA with stride and thickness (McGuire & Mara 2014) -------------------
   The clipped segment's 2D line is walked pixel by pixel along its major
   axis (the one it moves further along): column c (row, for a steep line)
   is the stretch of the segment inside [c, c+1] on that axis, the first
   column the one the segment starts in, as for a ray starting at a pixel
   centre in the original. Step k samples column k * stride: the pixel under
   the middle of that column's stretch, depth d. The ray's depth is linear
   along the line; over the step's stretch, stride columns centred on the
   sampled one ([k S - S/2, k S + S/2), clipped to the segment: the
   original's half-step z estimates either side of the sample), it covers
   [zlo, zhi]; a hit is zhi >= d and zlo <= d + DDA_THICKNESS (the surface is
   taken to be DDA_THICKNESS deep: rays passing further behind it go on),
   reported where the ray enters [d, d + thickness] within the stretch.
   With stride S > 1, a step that hits is refined over the last stride: the
   columns after the previous sample up to the end of this step's stretch
   are tested one by one (each with its own stretch) and the first that hits
   is reported (the coarse sample if none does).
   At most max(W, H) steps (the original's iteration cap; a stride-1 walk
   across the whole screen takes at most that many); a ray whose walk ends
   (the segment's end, or the cap) without a hit misses, its kind by
   docs/MODEL.md's rule. */
typedef struct dda_line {
    double x0, y0, z0, dx, dy, dz; /* the clipped segment, s in [0, 1] */
    int axis;                      /* the major axis: 0 x, 1 y */
    double a0, da, inv_da;         /* its major coordinate at s = 0, its change, 1 / change */
} dda_line;

/* s where the line's major coordinate is e, clamped to [0, 1] */
static double dda_s(const dda_line *L, double e)
{
    double s = (e - L->a0) * L->inv_da;
    return s < 0.0 ? 0.0 : s > 1.0 ? 1.0 : s;
}

/* Tests the ray's depth over the stretch [sa, sb] against the pixel under
   the point at ss; on a hit, *s_hit is where the ray enters the thickness
   slab. */
static int dda_test(const march_job *jb, const dda_line *L, double ss, double sa, double sb, uint32_t *i, uint32_t *j,
                    double *s_hit)
{
    double d, za, zb, lo, hi, thick;
    size_t k;
    MARCH_COUNT_STEP();
    *i = march_texel(L->x0 + ss * L->dx, jb->map.w);
    *j = march_texel(L->y0 + ss * L->dy, jb->map.h);
    k = (size_t)*j * jb->map.w + *i;
    d = (double)march_depth(jb->map.depth[k]);
    thick = jb->map.back ? march_back(&jb->map, k) - d : DDA_THICKNESS; /* a scene's own thickness where it has one */
    za = L->z0 + sa * L->dz;
    zb = L->z0 + sb * L->dz;
    lo = za < zb ? za : zb;
    hi = za < zb ? zb : za;
    if (!(hi >= d && lo <= d + thick)) return 0;
    if (za >= d && za <= d + thick) *s_hit = sa;
    else *s_hit = sa + ((za < d ? d : d + thick) - za) / (zb - za) * (sb - sa);
    return 1;
}

static void dda_one(const march_job *jb, const lrt_ray *r, lrt_hit *hit)
{
    const uint32_t w = jb->map.w, h = jb->map.h;
    const long stride = jb->m->param, cap = (long)(w > h ? w : h);
    double t0, t1, s_hit, a1, e0;
    dda_line L;
    uint32_t i, j;
    long c0, n, k, sg;
    if (!march_begin(r, w, h, hit, &t0, &t1)) return;
    L.x0 = (double)r->origin[0] + t0 * (double)r->dir[0];
    L.y0 = (double)r->origin[1] + t0 * (double)r->dir[1];
    L.z0 = (double)r->origin[2] + t0 * (double)r->dir[2];
    L.dx = (double)r->origin[0] + t1 * (double)r->dir[0] - L.x0;
    L.dy = (double)r->origin[1] + t1 * (double)r->dir[1] - L.y0;
    L.dz = (double)r->origin[2] + t1 * (double)r->dir[2] - L.z0;
    L.axis = fabs(L.dy) > fabs(L.dx);
    L.a0 = L.axis ? L.y0 : L.x0;
    L.da = L.axis ? L.dy : L.dx;
    L.inv_da = L.da != 0.0 ? 1.0 / L.da : 0.0;
    a1 = L.a0 + L.da;
    /* the columns the segment passes, n of them: the q-th (q = 0 first) is
       [e0 + sg q, e0 + sg (q+1)] on the major axis */
    if (L.da > 0.0) {
        c0 = (long)floor(L.a0);
        n = (long)ceil(a1) - c0;
        sg = 1;
        e0 = (double)c0;
    } else if (L.da < 0.0) {
        c0 = (long)ceil(L.a0) - 1;
        n = c0 - (long)floor(a1) + 1;
        sg = -1;
        e0 = (double)c0 + 1.0;
    } else { /* no motion on the screen: one step over the whole segment */
        n = 1;
        sg = 0;
        e0 = 0.0;
    }
    if (n < 1) n = 1;
    for (k = 0; k < cap; ++k) {
        const long sc = k * stride < n ? k * stride : n - 1; /* the sampled column */
        const long first = k * stride - stride / 2 > 0 ? k * stride - stride / 2 : 0;
        const long last = k * stride + (stride - stride / 2) < n ? k * stride + (stride - stride / 2) : n;
        double sa = 0.0, sb = 1.0, ss = 0.5;
        if (first >= n) break;
        if (sg) {
            sa = dda_s(&L, e0 + (double)(sg * first));
            sb = dda_s(&L, e0 + (double)(sg * last));
            ss = stride == 1 ? 0.5 * (sa + sb)
                             : 0.5 * (dda_s(&L, e0 + (double)(sg * sc)) + dda_s(&L, e0 + (double)(sg * (sc + 1))));
        }
        if (dda_test(jb, &L, ss, sa, sb, &i, &j, &s_hit)) {
            if (stride > 1 && sg) { /* the last stride, pixel by pixel: the first column that hits */
                long c;
                for (c = k > 0 ? (k - 1) * stride + 1 : 0; c < last; ++c) {
                    double fa = dda_s(&L, e0 + (double)(sg * c)), fb = dda_s(&L, e0 + (double)(sg * (c + 1))), fs;
                    uint32_t fi, fj;
                    if (dda_test(jb, &L, 0.5 * (fa + fb), fa, fb, &fi, &fj, &fs)) {
                        i = fi;
                        j = fj;
                        s_hit = fs;
                        break;
                    }
                }
            }
            march_set_hit(r, t0 + s_hit * (t1 - t0), i, j, hit);
            return;
        }
    }
    march_set_miss(hit, march_miss_kind(r, w, h));
}

/* ---- hierarchical min-depth (Hi-Z) traversal (FidelityFX SSSR) -----------------------
   Level 0 is the depth map; level l+1 is the 2x2 minimum (nearest depth) of
   level l, ceil(w/2) x ceil(h/2) (an odd last row/column reduces the 1 or 2
   texels it has), down to 1x1; a cell of level l covers texels
   [x 2^l, (x+1) 2^l) x [y 2^l, (y+1) 2^l), clipped to the map.
   The walk starts at level 0 at the clipped start t0. Each iteration looks
   at the cell of the current level under the ray's point:
   - the point is at or behind the cell's min depth: at level 0 that is a
     hit (the texel's box holds the point); above, go down a level;
   - else the ray is advanced to the nearer of the cell's exit (the next cell
     boundary along x or y) and, for rays moving away from the camera, the
     point where it reaches the cell's min depth (nothing in the cell can be
     hit before either): reaching the min depth first goes down a level
     (at level 0 it is a hit at that t); crossing the boundary first goes up a
     level (the ray cleared the whole cell; the top level at most);
   - the segment ending inside the cell, in front of its min depth, is a miss.
   The cell of a point just across a boundary is found with a 1e-6 texel
   nudge along the ray (SSSR's offset, much smaller). After the iteration cap
   the walk gives up: a miss of kind LRT_MISS_TMAX, as SSSR reports no hit. */
static void hiz_one(const march_job *jb, const lrt_ray *r, lrt_hit *hit)
{
    const march *m = jb->m;
    const uint32_t w = jb->map.w, h = jb->map.h;
    const int cap = m->param, top = m->levels - 1;
    double o[3], v[3], t0, t1, t, nx, ny;
    int k, lv = 0;
    if (!march_begin(r, w, h, hit, &t0, &t1)) return;
    for (k = 0; k < 3; ++k) {
        o[k] = r->origin[k];
        v[k] = r->dir[k];
    }
    nx = v[0] > 0.0 ? 1e-6 : v[0] < 0.0 ? -1e-6 : 0.0;
    ny = v[1] > 0.0 ? 1e-6 : v[1] < 0.0 ? -1e-6 : 0.0;
    t = t0;
    for (k = 0; k < cap; ++k) {
        const double s = (double)(1u << lv), inv_s = 1.0 / s; /* exact: powers of two */
        const uint32_t lw = m->lw[lv], lh = m->lh[lv];
        const float *level = lv == 0 ? jb->map.depth : m->chain + m->loff[lv];
        double x = o[0] + t * v[0], y = o[1] + t * v[1], z = o[2] + t * v[2], zmin, tx, ty, tb, tz;
        uint32_t cx = march_texel((x + nx) * inv_s, lw), cy = march_texel((y + ny) * inv_s, lh);
        MARCH_COUNT_STEP(); /* one iteration (bench/wave.c) */
        zmin = (double)(lv == 0 ? march_depth(level[(size_t)cy * lw + cx]) : level[(size_t)cy * lw + cx]);
        if (z >= zmin) {
            if (lv > 0) {
                --lv;
                continue;
            }
            if (z <= march_back(&jb->map, (size_t)cy * lw + cx)) {
                march_set_hit(r, t, cx, cy, hit);
                return;
            }
            /* behind this texel's back (thickness): on to the next texel */
            tx = v[0] > 0.0 ? ((double)(cx + 1u) - o[0]) / v[0] : v[0] < 0.0 ? ((double)cx - o[0]) / v[0] : HUGE_VAL;
            ty = v[1] > 0.0 ? ((double)(cy + 1u) - o[1]) / v[1] : v[1] < 0.0 ? ((double)cy - o[1]) / v[1] : HUGE_VAL;
            tb = tx < ty ? tx : ty;
            if (tb >= t1) {
                march_set_miss(hit, march_miss_kind(r, w, h));
                return;
            }
            if (tb > t) t = tb;
            continue;
        }
        tx = v[0] > 0.0 ? ((double)(cx + 1u) * s - o[0]) / v[0] : v[0] < 0.0 ? ((double)cx * s - o[0]) / v[0] : HUGE_VAL;
        ty = v[1] > 0.0 ? ((double)(cy + 1u) * s - o[1]) / v[1] : v[1] < 0.0 ? ((double)cy * s - o[1]) / v[1] : HUGE_VAL;
        tb = tx < ty ? tx : ty;
        tz = v[2] > 0.0 ? (zmin - o[2]) / v[2] : HUGE_VAL;
        if (tz <= tb && tz <= t1) { /* reaches the cell's min depth inside the cell */
            if (tz > t) t = tz;
            if (lv == 0) {
                march_set_hit(r, t, cx, cy, hit);
                return;
            }
            --lv;
            continue;
        }
        if (tb >= t1) { /* ends in this cell, in front of all of it */
            march_set_miss(hit, march_miss_kind(r, w, h));
            return;
        }
        if (tb > t) t = tb;
        if (lv < top) ++lv;
    }
    march_set_miss(hit, LRT_MISS_TMAX); /* gave up at the cap */
}

/* the mip chain: levels 1.. of the min-depth pyramid */
static int hiz_layout(march *m, uint32_t w, uint32_t h)
{
    size_t total = 0;
    int l = 0;
    m->lw[0] = w;
    m->lh[0] = h;
    m->loff[0] = 0;
    while ((m->lw[l] > 1u || m->lh[l] > 1u) && l + 1 < HIZ_MAX_LEVELS) {
        m->lw[l + 1] = (m->lw[l] + 1u) / 2u;
        m->lh[l + 1] = (m->lh[l] + 1u) / 2u;
        m->loff[l + 1] = total;
        total += (size_t)m->lw[l + 1] * m->lh[l + 1];
        ++l;
    }
    m->levels = l + 1;
    if (m->chain && m->cw == w && m->ch == h) return 0;
    free(m->chain);
    m->chain = (float *)malloc(sizeof(float) * (total ? total : 1u));
    m->chain_floats = total;
    m->cw = w;
    m->ch = h;
    return m->chain ? 0 : -1;
}

typedef struct hiz_rows {
    const float *src;
    float *dst;
    uint32_t sw, sh, dw;
    int src_is_depth;
} hiz_rows;

static void hiz_reduce_rows(void *ctx, size_t first, size_t end)
{
    const hiz_rows *q = (const hiz_rows *)ctx;
    size_t y, x;
    for (y = first; y < end; ++y) {
        const size_t y0 = 2 * y, y1 = 2 * y + 1 < q->sh ? 2 * y + 1 : 2 * y;
        const float *r0 = q->src + y0 * q->sw, *r1 = q->src + y1 * q->sw;
        float *out = q->dst + y * q->dw;
        for (x = 0; x < q->dw; ++x) {
            const size_t x0 = 2 * x, x1 = 2 * x + 1 < q->sw ? 2 * x + 1 : 2 * x;
            float a = r0[x0], b = r0[x1], c = r1[x0], d = r1[x1];
            if (q->src_is_depth) {
                a = march_depth(a);
                b = march_depth(b);
                c = march_depth(c);
                d = march_depth(d);
            }
            a = b < a ? b : a;
            c = d < c ? d : c;
            out[x] = c < a ? c : a;
        }
    }
}

static int hiz_build_chain(march *m, const bench_scene *sc, double *ms, char *why, size_t n)
{
    double t0 = bench_now_ms();
    int l;
    if (hiz_layout(m, sc->width, sc->height)) {
        bmc_why(why, n, "out of memory for the Hi-Z mip chain");
        return 1;
    }
    for (l = 1; l < m->levels; ++l) {
        hiz_rows q;
        q.src = l == 1 ? sc->depth : m->chain + m->loff[l - 1];
        q.dst = m->chain + m->loff[l];
        q.sw = m->lw[l - 1];
        q.sh = m->lh[l - 1];
        q.dw = m->lw[l];
        q.src_is_depth = l == 1;
        /* threads only where a level is big enough to pay for them */
        (void)bmc_parallel(hiz_reduce_rows, &q, m->lh[l], (size_t)m->lw[l] * m->lh[l] >= 65536u ? m->threads : 1);
    }
    *ms = bench_now_ms() - t0;
    return 0;
}

/* ---- bench_method glue ------------------------------------------------------------------ */
static void march_range(void *ctx, size_t first, size_t end)
{
    const march_job *jb = (const march_job *)ctx;
    size_t q;
    switch (jb->m->kind) {
    case MARCH_LINEAR:
        for (q = first; q < end; ++q) linear_one(jb, &jb->rays[q], &jb->hits[q]);
        break;
    case MARCH_DDA:
        for (q = first; q < end; ++q) dda_one(jb, &jb->rays[q], &jb->hits[q]);
        break;
    default:
        for (q = first; q < end; ++q) hiz_one(jb, &jb->rays[q], &jb->hits[q]);
        break;
    }
}

static int march_open(bench_method *bm, uint32_t w, uint32_t h, int threads, char *why, size_t n)
{
    march *m = (march *)bm->impl;
    (void)w;
    (void)h;
    (void)why;
    (void)n;
    m->threads = threads < 1 ? 1 : threads > BMC_MAX_THREADS ? BMC_MAX_THREADS : threads;
    return 0;
}

static int march_build(bench_method *bm, const bench_scene *sc, double *ms, char *why, size_t n)
{
    march *m = (march *)bm->impl;
    *ms = 0.0;
    if (m->kind == MARCH_HIZ) return hiz_build_chain(m, sc, ms, why, n);
    return 0; /* nothing to build: the march reads the depth map itself */
}

static int march_update(bench_method *bm, const bench_scene *sc, double *ms, char *why, size_t n)
{
    return march_build(bm, sc, ms, why, n);
}

static int march_trace(bench_method *bm, const bench_scene *sc, const bench_rays *rs, lrt_hit *hits, double *ms,
                       char *why, size_t n)
{
    march *m = (march *)bm->impl;
    march_job jb;
    double t0;
    if (m->kind == MARCH_HIZ && (!m->chain || m->cw != sc->width || m->ch != sc->height)) {
        bmc_why(why, n, "Hi-Z: trace before build, or the scene changed size");
        return 1;
    }
    march_job_init(&jb, m, sc, rs->rays, hits);
    /* any-hit rays (BENCH_ANY_HIT) take the same walk: the first hit is one */
    t0 = bench_now_ms();
    (void)bmc_parallel(march_range, &jb, rs->count, m->threads);
    *ms = bench_now_ms() - t0;
    return 0;
}

static size_t march_memory(bench_method *bm)
{
    const march *m = (const march *)bm->impl;
    /* Hi-Z: the levels it allocates (level 0 is the depth map itself, read in
       place); the marches have no structure */
    return m->kind == MARCH_HIZ ? m->chain_floats * sizeof(float) : 0u;
}

static void march_close(bench_method *bm)
{
    march *m = (march *)bm->impl;
    if (m) free(m->chain);
    free(m);
    bm->impl = NULL;
}

int bench_add_march_cpu(bench_method *out, int max)
{
    static const struct {
        const char *name;
        march_kind kind;
        int param;
    } defs[] = {
        {"march16 cpu", MARCH_LINEAR, 16}, {"march32 cpu", MARCH_LINEAR, 32}, {"march64 cpu", MARCH_LINEAR, 64},
        {"march128 cpu", MARCH_LINEAR, 128}, {"dda cpu", MARCH_DDA, 1}, {"dda stride4 cpu", MARCH_DDA, 4},
        {"hiz64 cpu", MARCH_HIZ, 64}, {"hiz128 cpu", MARCH_HIZ, 128},
    };
    int i, count = 0;
    for (i = 0; i < (int)(sizeof defs / sizeof defs[0]) && count < max; ++i) {
        march *m = (march *)calloc(1, sizeof *m);
        if (!m) break;
        m->kind = defs[i].kind;
        m->param = defs[i].param;
        m->threads = 1;
        memset(&out[count], 0, sizeof out[count]);
        out[count].name = defs[i].name;
        out[count].device = "cpu";
        out[count].exact = 0;
        out[count].impl = m;
        BENCH_METHOD_FUNCTIONS(out[count], march);
        ++count;
    }
    return count;
}
