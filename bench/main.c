/* bench/main.c - `make bench`: linear_rt against the methods an engine
   programmer would use instead, speed against accuracy, on the same rays.

   For every scene (several embedded ones, or --depth FILE) and every ray set
   (the design's headline one ray per texel from the camera, reflection
   rays, short ambient-occlusion rays, shadow rays, random segments) each
   method builds, updates and traces, timed by itself (medians after a
   warm-up; a run of a short set traces it again until 20 ms have passed
   and keeps the mean; GPU timestamps on Vulkan; the methods of one device
   take their runs of a set in turn, run_methods), and is scored against the exact
   reference of the tests (tests/support/reference.h) on a fixed sample of the rays:
   exact methods by docs/MODEL.md's rule, approximate ones by the share of rays
   with the right hit/miss and texel, false hits, false misses and the mean
   distance from the right hit. Then the stability suite: small named cases
   built to break someone. Writes results.csv, results.md and
   speed_vs_accuracy.png (gnuplot) under build/bench-results/ (--out DIR;
   `make bench-publish` copies them into bench/), and prints the tables.

   The embedded scenes' reflection, AO and shadow rays are built in screen
   space from the depth gradient (the committed results' rays). A --depth
   FILE gets a perspective camera (--fov, --near, --far) instead, and those
   three sets are built as examples/ssr.c, ao.c and shadows.c build theirs:
   view-space segments from each texel's position and normal, through
   lrt_camera_segment, origins lifted by the examples' policy. */
#define _POSIX_C_SOURCE 200809L
#include "bench.h"
#include "../tests/support/reference.h"
#include "../examples/scene.h"
#include "scenes.h"
#include "../examples/depth_file.h"
#include "../examples/surface.h"
#include "../examples/march.h" /* march_miss_kind: the kind of miss a march tells, for a finish's budget miss */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* ---- options ----------------------------------------------------------------- */
typedef struct options {
    uint32_t size;       /* embedded scenes: size x size */
    int threads;         /* CPU threads for every CPU method */
    int runs;            /* timed runs after one warm-up: the median is kept */
    size_t sample;       /* rays per set scored against the reference */
    int quick;           /* small and fast: for make test */
    const char *depth_file, *format;
    uint32_t file_w, file_h;
    int reversed;
    float fov_deg, near_z, far_z; /* --depth FILE: its perspective projection */
    int camera_given;             /* --fov, --near or --far was given */
    const char *out_dir;
    const char *only;    /* run only methods whose name contains this */
    int chart_only;      /* redraw the chart from out_dir's points.dat, run nothing */
    int only_counts;     /* the scenes' sets and what a wave pays (counting), no method timed */
    const char *weights; /* make gpu-stats --weights FILE: the estimate's instructions and loads per step */
} options;

/* ---- deterministic random numbers -------------------------------------------- */
static uint64_t g_rng = 0x2545f4914f6cdd1dull;
static float rnd01(void)
{
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 7;
    g_rng ^= g_rng << 17;
    return (float)(g_rng >> 40) / 16777216.0f;
}

/* ---- scenes ---------------------------------------------------------------- */
typedef struct scene {
    bench_scene s;
    float *depth;
    float *back;              /* "yard back": the yard's back-face depth (thickness), else NULL */
    ref_map ref;
    /* A scene with a camera (--depth FILE): its reflection, ao and shadow
       rays are view-space segments built as examples/ssr.c, ao.c and
       shadows.c build them. The embedded scenes have none here: their ray
       sets are the screen-space ones of the committed results. */
    int has_camera;
    lrt_camera camera;
    float view_from_world[9]; /* rotation of the camera (identity for a file) */
    float *pos;               /* w * h * 3: view-space position of each texel's centre */
    float *nrm;               /* w * h * 3: view-space normal facing the eye; 0 0 0 for the sky */
    float *lift;              /* w * h: screen-space z by which a ray from this texel is lifted */
} scene;

static void scene_finish(scene *sc, const char *name, uint32_t w, uint32_t h)
{
    sc->s.name = name;
    sc->s.width = w;
    sc->s.height = h;
    sc->s.depth = sc->depth;
    memset(&sc->s.lrt, 0, sizeof sc->s.lrt);
    sc->s.lrt.data = sc->depth;
    sc->s.lrt.width = w;
    sc->s.lrt.height = h;
    sc->s.lrt.format = LRT_FORMAT_FLOAT32;
    if (ref_map_from_raw(&sc->ref, sc->depth, (int)w, (int)h, 0, REF_FORMAT_FLOAT32, 0) != 0) {
        fprintf(stderr, "bench: out of memory\n");
        exit(2);
    }
    if (sc->back) { /* every method, the reference included, runs this scene under the back-map model */
        sc->s.back = sc->back;
        sc->s.pair[0] = sc->s.lrt;
        sc->s.pair[1] = sc->s.lrt;
        sc->s.pair[1].data = sc->back;
        sc->s.pair[0].back = &sc->s.pair[1];
        if (ref_map_set_back_from_raw(&sc->ref, sc->back, 0, REF_FORMAT_FLOAT32, 0) != 0) {
            fprintf(stderr, "bench: out of memory\n");
            exit(2);
        }
    }
}

static int scene_set_camera(scene *sc, float fov_deg, float near_z, float far_z, const float view_from_world[9],
                            char *why, size_t why_size);

/* kind: a scene of bench/scenes.h. The yard has a camera: its reflection,
   AO and shadow rays are built as the examples build them; the maps without
   one (poles, terraces, noise) get secondary rays from screen-space normals */
static void scene_make(scene *sc, int kind, uint32_t w, uint32_t h)
{
    memset(sc, 0, sizeof *sc);
    sc->depth = (float *)malloc(sizeof(float) * w * h);
    if (!sc->depth) exit(2);
    if (kind == 4 && !(sc->back = (float *)malloc(sizeof(float) * w * h))) exit(2);
    bench_scene_depth(kind, w, h, sc->depth, sc->back, rnd01);
    scene_finish(sc, bench_scene_names[kind], w, h);
    if (kind == 0 || kind == 4) { /* the yard has a camera: its reflection, AO and shadow rays are the examples' */
        scene_camera cam = scene_default_camera();
        float view_from_world[9];
        char why[256];
        scene_view_from_world(&cam, view_from_world);
        if (scene_set_camera(sc, cam.fov_y_deg, cam.near_z, cam.far_z, view_from_world, why, sizeof why)) {
            fprintf(stderr, "bench: yard: %s\n", why);
            exit(2);
        }
    }
}

static void scene_free(scene *sc)
{
    free(sc->depth);
    free(sc->back);
    free(sc->pos);
    free(sc->nrm);
    free(sc->lift);
    ref_map_free(&sc->ref);
}

/* ---- a scene's camera: the examples' view-space set-up ---------------------------
   Positions, normals and lifts per texel: examples/surface.h, as the
   examples compute them. */
/* Gives the scene a perspective camera (example_frame_load's, for a file:
   aspect = width / height, standard Z, reversed input already flipped) and
   its positions, normals and lifts. 0 on success, else a one-line reason. */
static int scene_set_camera(scene *sc, float fov_deg, float near_z, float far_z, const float view_from_world[9],
                            char *why, size_t why_size)
{
    const float pi = 3.14159265358979f;
    const size_t n = (size_t)sc->s.width * sc->s.height;
    float proj[16];
    lrt_result r;
    uint32_t j;
    lrt_perspective(proj, fov_deg * pi / 180.0f, (float)sc->s.width / (float)sc->s.height, near_z, far_z, 0);
    if ((r = lrt_camera_init(&sc->camera, proj, sc->s.width, sc->s.height, 0)) != LRT_SUCCESS) {
        snprintf(why, why_size, "camera: %s", lrt_result_string(r));
        return 1;
    }
    memcpy(sc->view_from_world, view_from_world, sizeof sc->view_from_world);
    sc->pos = (float *)malloc(n * 3 * sizeof(float));
    sc->nrm = (float *)malloc(n * 3 * sizeof(float));
    sc->lift = (float *)malloc(n * sizeof(float));
    if (!sc->pos || !sc->nrm || !sc->lift) {
        snprintf(why, why_size, "out of memory for the camera of a %ux%u map", sc->s.width, sc->s.height);
        return 1;
    }
    for (j = 0; j < sc->s.height; ++j) surface_positions_row(&sc->camera, sc->depth, sc->s.width, j, sc->pos);
    for (j = 0; j < sc->s.height; ++j)
        surface_normals_row(sc->depth, sc->pos, sc->s.width, sc->s.height, j, sc->nrm, sc->lift);
    sc->has_camera = 1;
    return 0;
}

/* ---- the user's own depth: PNG 8/16-bit, PFM, raw float ----------------------- */
/* examples/depth_file.h reads it (the examples' reader: one-line reasons,
   the model's clamp, reversed Z flipped) */
static int scene_load(scene *sc, const options *o)
{
    depth_file_image img;
    char why[512];
    int kind = DEPTH_FILE_AUTO;
    static const float identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    memset(sc, 0, sizeof *sc);
    if (o->format) {
        kind = !strcmp(o->format, "png") ? DEPTH_FILE_PNG : !strcmp(o->format, "pfm") ? DEPTH_FILE_PFM : DEPTH_FILE_RAW;
    }
    if (depth_file_load(o->depth_file, kind, o->reversed, o->file_w, o->file_h, &img, why, sizeof why)) {
        fprintf(stderr, "bench: %s\n", why);
        return 1;
    }
    sc->depth = img.depth;
    scene_finish(sc, "file", img.width, img.height);
    if (scene_set_camera(sc, o->fov_deg, o->near_z, o->far_z, identity, why, sizeof why)) {
        fprintf(stderr, "bench: %s: %s\n", o->depth_file, why);
        return 1;
    }
    return 0;
}

/* ---- ray sets ----------------------------------------------------------------- */
typedef struct ray_set {
    bench_rays r;
    lrt_ray *rays;
    size_t sample_stride; /* rays i * stride are scored */
    ref_result *ref;      /* reference answers of the sample */
    size_t sample_count;
} ray_set;

enum { SET_PRIMARY, SET_REFLECT, SET_AO, SET_SHADOW, SET_SEGMENTS, SET_COUNT };
static const char *set_names[SET_COUNT] = {"primary", "reflection", "ao", "shadow", "segments"};

static float depth_at(const scene *sc, int i, int j)
{
    int w = (int)sc->s.width, h = (int)sc->s.height;
    i = i < 0 ? 0 : i >= w ? w - 1 : i;
    j = j < 0 ? 0 : j >= h ? h - 1 : j;
    return sc->depth[(size_t)j * (size_t)w + (size_t)i];
}

/* A screen-space normal from the depth gradient, z scaled by the map's size
   so that the solid's slopes read as they look. */
static void normal_at(const scene *sc, int i, int j, float n[3])
{
    float k = (float)(sc->s.width > sc->s.height ? sc->s.width : sc->s.height);
    float dx = (depth_at(sc, i + 1, j) - depth_at(sc, i - 1, j)) * 0.5f * k;
    float dy = (depth_at(sc, i, j + 1) - depth_at(sc, i, j - 1)) * 0.5f * k;
    float l = sqrtf(dx * dx + dy * dy + 1.0f);
    n[0] = dx / l;
    n[1] = dy / l;
    n[2] = -1.0f / l; /* towards the camera */
}

/* ao.c's AO_RADIUS and shadows.c's SHADOW_LENGTH (view-space units), and
   shadows.c's light (towards it, world space: x right, y up, z towards the eye) */
#define CAMERA_AO_RADIUS 0.6f
#define CAMERA_SHADOW_LENGTH 0.6f
static const float camera_light_world[3] = {0.55f, 0.6f, 0.35f};

/* Texel k's ray of a set, as the examples build it from a camera: a
   view-space segment from the texel's position, clipped and projected by
   lrt_camera_surface_ray ([tmin, tmax] = [0, 1]), its origin lifted by the
   texel's lift. 0 when the texel has none (the sky, no normal, a surface
   facing away from the light, no part of the segment between the planes):
   the examples give those an invalid ray; the benchmark leaves them out.
   - reflection (ssr.c): the view ray reflected about the normal, 1e4 long
     (the far plane clips it), closest hit;
   - ao (ao.c): CAMERA_AO_RADIUS long, cosine-weighted over the normal's
     hemisphere in ao.c's tangent frame, one random ray per texel where
     ao.c traces 16 in a dithered spiral; any hit;
   - shadow (shadows.c): CAMERA_SHADOW_LENGTH towards the light, any hit. */
static int camera_ray(const scene *sc, int kind, size_t k, lrt_ray *ray)
{
    const float *p = &sc->pos[3 * k], *n = &sc->nrm[3 * k];
    float to[3];
    int c;
    if (sc->depth[k] >= 1.0f || (n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f)) return 0;
    if (kind == SET_REFLECT) {
        float v[3] = {p[0], p[1], p[2]}, d;
        surface_normalize(v); /* the eye is at the origin of view space */
        d = surface_dot(v, n);
        for (c = 0; c < 3; ++c) to[c] = p[c] + (v[c] - 2.0f * d * n[c]) * 1e4f;
    } else if (kind == SET_AO) {
        float t[3], b[3];
        float u = rnd01(), r = sqrtf(u), phi = 6.2831853f * rnd01();
        float e[3];
        e[0] = r * cosf(phi);
        e[1] = r * sinf(phi);
        e[2] = sqrtf(1.0f - u);
        surface_frame(n, t, b); /* the frame of examples/ao.c */
        for (c = 0; c < 3; ++c) to[c] = p[c] + CAMERA_AO_RADIUS * (e[0] * t[c] + e[1] * b[c] + e[2] * n[c]);
    } else { /* SET_SHADOW */
        const float *m = sc->view_from_world;
        float l[3];
        for (c = 0; c < 3; ++c)
            l[c] = m[3 * c] * camera_light_world[0] + m[3 * c + 1] * camera_light_world[1] + m[3 * c + 2] * camera_light_world[2];
        surface_normalize(l);
        if (surface_dot(n, l) <= 0.0f) return 0; /* shadowed by itself */
        for (c = 0; c < 3; ++c) to[c] = p[c] + CAMERA_SHADOW_LENGTH * l[c];
    }
    return lrt_camera_surface_ray(&sc->camera, p, n, to, sc->lift[k], ray);
}

static void make_set(ray_set *rs, const scene *sc, int kind, size_t sample)
{
    const uint32_t w = sc->s.width, h = sc->s.height;
    const size_t n = (size_t)w * h;
    const float k = (float)(w > h ? w : h);
    /* a scene with a camera builds these three as the examples do */
    const int camera = sc->has_camera && (kind == SET_REFLECT || kind == SET_AO || kind == SET_SHADOW);
    size_t q, count = n;
    memset(rs, 0, sizeof *rs);
    rs->rays = (lrt_ray *)malloc(sizeof(lrt_ray) * n);
    if (!rs->rays) exit(2);
    if (camera) {
        count = 0;
        for (q = 0; q < n; ++q) count += (size_t)camera_ray(sc, kind, q, &rs->rays[count]);
    }
    for (q = 0; !camera && q < n; ++q) {
        int i = (int)(q % w), j = (int)(q / w);
        float d = sc->depth[q], nrm[3];
        lrt_ray *r = &rs->rays[q];
        memset(r, 0, sizeof *r);
        r->origin[0] = (float)i + 0.5f;
        r->origin[1] = (float)j + 0.5f;
        r->tmax = 1.0f;
        if (kind == SET_PRIMARY) {
            r->dir[2] = 1.0f;
            continue;
        }
        r->origin[2] = d;
        normal_at(sc, i, j, nrm);
        if (kind == SET_REFLECT || kind == SET_SEGMENTS) {
            if (kind == SET_REFLECT) { /* the view ray (0,0,1), z scaled by k, reflected about the normal */
                float dot = nrm[2], rx = -2.0f * dot * nrm[0], ry = -2.0f * dot * nrm[1], rz = 1.0f - 2.0f * dot * nrm[2];
                float len = sqrtf(rx * rx + ry * ry) + 1e-6f, s = k / len; /* across the screen */
                r->dir[0] = rx * s;
                r->dir[1] = ry * s;
                r->dir[2] = rz / k * s;
            } else { /* a random segment ending a little behind the surface there */
                int i1 = (int)(rnd01() * (float)w), j1 = (int)(rnd01() * (float)h);
                r->origin[0] = (float)i + rnd01();
                r->origin[1] = (float)j + rnd01();
                r->origin[2] = d * rnd01();
                r->dir[0] = (float)i1 + rnd01() - r->origin[0];
                r->dir[1] = (float)j1 + rnd01() - r->origin[1];
                r->dir[2] = depth_at(sc, i1, j1) + 0.05f * rnd01() - r->origin[2];
            }
        } else if (kind == SET_AO) { /* short rays around the normal, 8 texels */
            float a = 6.2831853f * rnd01(), c = rnd01(), s = sqrtf(1.0f - c * c);
            float v[3] = {cosf(a) * s + nrm[0], sinf(a) * s + nrm[1], -c + nrm[2]};
            float len = sqrtf(v[0] * v[0] + v[1] * v[1]) + 1e-6f;
            r->dir[0] = v[0] / len * 8.0f;
            r->dir[1] = v[1] / len * 8.0f;
            r->dir[2] = v[2] / len * 8.0f / k;
            if (r->dir[2] > 0.0f) r->dir[2] = -r->dir[2];
        } else { /* shadow: towards a light up, left and nearer the camera */
            r->dir[0] = -0.6f * k;
            r->dir[1] = -0.8f * k;
            r->dir[2] = -0.25f;
        }
        /* leave the own texel before testing (docs/MODEL.md: the set-up's policy; this
           screen-space one starts 0.75 texel out, the camera sets lift instead) */
        {
            float m = fabsf(r->dir[0]) > fabsf(r->dir[1]) ? fabsf(r->dir[0]) : fabsf(r->dir[1]);
            r->tmin = m > 0.0f ? 0.75f / m : 0.0f;
            if (r->tmin > r->tmax) r->tmin = r->tmax;
        }
    }
    rs->r.name = set_names[kind];
    rs->r.rays = rs->rays;
    rs->r.count = count;
    rs->r.flags = (kind == SET_AO || kind == SET_SHADOW) ? BENCH_ANY_HIT : 0u;
    rs->sample_stride = count / sample > 1 ? count / sample : 1;
    rs->sample_count = (count + rs->sample_stride - 1) / rs->sample_stride;
    rs->ref = (ref_result *)malloc(sizeof(ref_result) * rs->sample_count);
    for (q = 0; q < rs->sample_count; ++q) {
        ref_ray rr = ref_ray_of(&rs->rays[q * rs->sample_stride]);
        rs->ref[q] = ref_trace_ray(&sc->ref, &rr);
    }
}

static void set_free(ray_set *rs)
{
    free(rs->rays);
    free(rs->ref);
}

/* ---- scoring ------------------------------------------------------------------------ */
typedef struct score {
    size_t n, right, false_hits, false_misses, both_hit;
    double dist_sum; /* texels, between the method's hit point and the reference's */
} score;

/* exact: 1 docs/MODEL.md's rule; 2 the same, but a budget miss (LRT_MISS_BUDGET) is wrong (a
   budgeted linear_rt); 3 a budget with a finish: an estimate (LRT_HIT_ESTIMATE) and a budget
   miss, read as the miss its ray's point at tmax tells (march_miss_kind, as a march that runs out
   says), are plain answers, the rest by the rule; 0 the plain answer */
static void score_set(const scene *sc, const ray_set *rs, const lrt_hit *hits, int exact, score *s)
{
    size_t q;
    memset(s, 0, sizeof *s);
    for (q = 0; q < rs->sample_count; ++q) {
        const size_t i = q * rs->sample_stride;
        const lrt_ray *r = &rs->rays[i];
        const lrt_hit *a = &hits[i];
        const ref_result *e = &rs->ref[q];
        const int any = (rs->r.flags & BENCH_ANY_HIT) != 0;
        lrt_hit guess;
        int ok;
        ++s->n;
        if (exact == 3 && (a->kind == LRT_HIT_ESTIMATE || a->kind == LRT_MISS_BUDGET)) {
            guess = *a;
            guess.kind = (uint16_t)(a->kind == LRT_HIT_ESTIMATE ? (uint32_t)LRT_HIT : march_miss_kind(r, sc->s.width, sc->s.height));
            a = &guess;
            ok = (int)a->kind == e->kind && (any || e->kind != REF_HIT || ((int)a->x == e->x && (int)a->y == e->y));
        } else if (exact == 2 && a->kind == LRT_MISS_BUDGET) {
            ok = 0;
        } else if (exact) { /* docs/MODEL.md's rule, perturbations and all */
            ref_ray rr = ref_ray_of(r);
            ref_answer an;
            an.kind = (int)a->kind;
            an.t = a->t;
            an.x = (int)a->x;
            an.y = (int)a->y;
            an.face = REF_FACE_ANY; /* scored: hit or miss, texel, point; the face is tested in tests/ */
            ok = ref_check(&sc->ref, &rr, &an, any, NULL, 0);
        } else { /* the plain answer: kind, and for a closest hit the texel */
            ok = (int)a->kind == e->kind && (any || e->kind != REF_HIT || ((int)a->x == e->x && (int)a->y == e->y));
        }
        s->right += ok != 0;
        s->false_hits += a->kind == LRT_HIT && e->kind != REF_HIT;
        s->false_misses += a->kind != LRT_HIT && e->kind == REF_HIT;
        if (a->kind == LRT_HIT && e->kind == REF_HIT && !any) {
            double dx = (double)r->origin[0] + (double)a->t * r->dir[0] - ((double)r->origin[0] + e->t * r->dir[0]);
            double dy = (double)r->origin[1] + (double)a->t * r->dir[1] - ((double)r->origin[1] + e->t * r->dir[1]);
            s->dist_sum += sqrt(dx * dx + dy * dy);
            ++s->both_hit;
        }
    }
}

/* ---- results -------------------------------------------------------------------------- */
typedef struct result {
    const char *method, *device, *scene, *set;
    int exact, threads, ok;
    double build_ms, update_ms, trace_ms, bytes_per_texel;
    size_t rays;
    score sc;
    char why[160];
} result;

#define MAX_RESULTS 4096
static result g_res[MAX_RESULTS];
static int g_nres;

/* what linear_rt's walk costs per ray on each set, by node width: node
   tests per ray at level 0, level 1 and above, and the exact tests of the
   texels the level-1 codes let through (bench_visits) */
typedef struct visits_row {
    const char *scene, *set;
    uint32_t node_bits;
    double per_ray[4];
} visits_row;
#define MAX_VISITS 256
static visits_row g_visits[MAX_VISITS];
static int g_nvisits;

/* a scene with a back map: each set's node tests, thick against infinite
   (bench_visits_thickness) */
typedef struct thick_row {
    const char *scene, *set;
    double v[6];
} thick_row;
static thick_row g_thick[MAX_VISITS];
static int g_nthick;

static void count_visits(const scene *sc, const ray_set *sets, int nsets)
{
    static const uint32_t bits[2] = {16u, 8u};
    int s, b;
    for (s = 0; s < nsets && sc->s.back; ++s)
        if (strcmp(sets[s].r.name, "primary") != 0 && g_nthick < MAX_VISITS &&
            bench_visits_thickness(&sc->s, &sets[s].r, g_thick[g_nthick].v) == 0) {
            g_thick[g_nthick].scene = sc->s.name;
            g_thick[g_nthick++].set = sets[s].r.name;
        }
    for (s = 0; s < nsets; ++s)
        for (b = 0; b < 2 && g_nvisits < MAX_VISITS; ++b) {
            visits_row *v = &g_visits[g_nvisits];
            v->scene = sc->s.name;
            v->set = sets[s].r.name;
            v->node_bits = bits[b];
            if (bench_visits(&sc->s, &sets[s].r, bits[b], v->per_ray) == 0) ++g_nvisits;
        }
}

/* ---- what a wave pays --------------------------------------------------------------
   A GPU runs rays in groups that step together: 32 lanes (an NVIDIA warp,
   an RDNA wave32) or 64 (GCN, and RDNA as RADV compiles these kernels); a
   group pays for its slowest ray. Each Vulkan method's steps per ray on
   each set (bench/visits.c, bench/wave.c: counted, never timed), their mean
   and the mean over groups of 32 and of 64 consecutive rays (the dispatch
   order) of the group's most. The ray-query peers are not counted: their
   traversal is the hardware's. */
#define WAVE_LANES 32u
#define WAVE_LANES_WIDE 64u
typedef struct wave_weight {
    const char *method;
    const char *pipeline; /* make gpu-stats' row whose loops weigh the method's step */
    int split;            /* 1: the loop's inner loop is a texel test, weighed apart (the 8-child walk) */
    double per_loop;      /* steps one trip round the loop takes (the march: a sample, 8 bisection steps) */
    /* read from the weights file: instructions and loads per step, and per texel test */
    double node, texel, node_loads, texel_loads;
    double loop, exits; /* the loop body's instructions, and of them its exit blocks (a lane's last trip) */
    double aside;       /* the largest loading loop beside the walk's, its body: a budget's finish, a sample a trip */
    int waves;          /* waves per SIMD the registers allow */
    int read;
} wave_weight;
/* Which compiled loop weighs which method's step. Every figure comes from
   make gpu-stats --weights (bench/gpu_stats.c: RADV's ACO for RDNA3, the
   static instructions and loads of each kernel's outermost loop body and of
   the largest loop inside it; bench --weights FILE). linear_rt's exact
   ordinary pass of an infinite tree, exact or budgeted, is the cell walk: a
   step tests one cell or one texel, its loop body holds both tests and the
   move. A thickness tree's is the 8-child walk, whose loop holds the
   level-1 texel loop: the walk's own part (body - inner) is a node test's
   weight, the texel loop's a texel test's. The 64-step march's loop body
   holds its sample and its 8 bisection steps unrolled
   (bench/shaders/vkp_march64.comp): a ninth of it a step. DDA: a column;
   Hi-Z: an iteration. Static counts of a body: a wave whose lanes take
   different branches issues them all, one that agrees issues fewer, so
   this weighs divergent waves; but a kernel whose lanes leave the loop
   from inside (gpu_stats' loop_exits: the blocks that store an answer)
   runs those blocks once per trip in which some lane leaves
   (bench_wave_exits, bench_wave_march_blocks), which the estimate counts. */
static wave_weight wave_weights[] = {
    {"linear_rt vulkan 16", "linear_rt trace buffer", 0, 1.0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {"linear_rt vulkan 8", "linear_rt trace buffer", 0, 1.0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {"linear_rt vulkan 16 back", "linear_rt trace buffer, back 16-bit", 1, 1.0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {"linear_rt vulkan 8 back", "linear_rt trace buffer, back 8-bit", 1, 1.0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {"linear_rt vulkan 16 budget", "linear_rt trace buffer, budgeted", 0, 1.0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {"linear_rt vulkan 16 budget back", "linear_rt trace buffer, budgeted, back 16-bit", 1, 1.0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    /* the 8-child walk uncut, as the one-pass kernel the H200 ran walked every ray */
    {"linear_rt vulkan 16 8-child", "linear_rt trace buffer, one pass", 1, 1.0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {"linear_rt vulkan 16 8-child back", "linear_rt trace buffer, one pass, back 16-bit", 1, 1.0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {"march64 vulkan", "bench march64", 0, 9.0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {"dda vulkan", "bench dda", 0, 1.0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {"hiz64 vulkan", "bench hiz64", 0, 1.0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
};
#define WAVE_WEIGHTS ((int)(sizeof wave_weights / sizeof wave_weights[0]))
static int g_have_weights;

/* make gpu-stats --weights FILE's rows of one GPU (navi31: RDNA3) into
   wave_weights; 0 when every method found its pipeline */
static int load_weights(const char *path, const char *gpu)
{
    FILE *f = fopen(path, "r");
    char line[512];
    int k, missing = 0;
    if (!f) return 1;
    while (fgets(line, sizeof line, f)) {
        char g[32], name[128];
        unsigned long long instr, vgprs, waves;
        unsigned body, inner, loads, inner_loads, skippable = 0, exits = 0, aside = 0;
        char *tab = strchr(line, '\t'), *tab2;
        if (line[0] == '#' || !tab || (size_t)(tab - line) >= sizeof g) continue;
        memcpy(g, line, (size_t)(tab - line));
        g[tab - line] = 0;
        tab2 = strchr(tab + 1, '\t');
        if (!tab2 || (size_t)(tab2 - tab - 1) >= sizeof name || strcmp(g, gpu)) continue;
        memcpy(name, tab + 1, (size_t)(tab2 - tab - 1));
        name[tab2 - tab - 1] = 0;
        if (sscanf(tab2 + 1, "%llu %llu %llu %u %u %u %u %u %u %u", &instr, &vgprs, &waves, &body, &inner, &loads,
                   &inner_loads, &skippable, &exits, &aside) < 7)
            continue;
        for (k = 0; k < WAVE_WEIGHTS; ++k) {
            wave_weight *w = &wave_weights[k];
            if (strcmp(w->pipeline, name)) continue;
            w->node = (double)(w->split ? body - inner : body) / w->per_loop;
            w->texel = w->split ? (double)inner : 0.0;
            w->node_loads = (double)(w->split ? loads - inner_loads : loads) / w->per_loop;
            w->texel_loads = w->split ? (double)inner_loads : 0.0;
            w->loop = (double)body;
            w->exits = w->split ? 0.0 : (double)exits;
            w->aside = (double)aside;
            w->waves = (int)waves;
            w->read = body > 0;
        }
    }
    fclose(f);
    for (k = 0; k < WAVE_WEIGHTS; ++k)
        if (!wave_weights[k].read) {
            fprintf(stderr, "bench: %s: no loop of '%s' for %s\n", path, wave_weights[k].pipeline, wave_weights[k].method);
            ++missing;
        }
    return missing != 0;
}
/* Waves per SIMD at or above this hide a step's latency alike: below it, a
   step costs WAVE_FULL / waves times more (an assumption; RDNA3's kernels
   here are all above it) */
#define WAVE_FULL 16

typedef struct wave_row {
    const char *scene, *set, *method;
    double mean, wave, wave64, texels, estimate; /* texels: linear_rt's texel tests per node test */
    double trips, refine_trips; /* a wave32's loop trips, and trips in which a lane left (the march: refined) */
    double finish_trips;        /* a budget's finish: a wave32's most samples, a trip each of the loop beside */
    double loads;                                /* loads a wave issues per ray (wave32 steps x a step's loads) */
} wave_row;
#define MAX_WAVES 512
static wave_row g_waves[MAX_WAVES];
static int g_nwaves;

static const wave_weight *weight_of(const char *method, int back)
{
    char name[64];
    size_t k;
    snprintf(name, sizeof name, "%s%s", method, back && !strncmp(method, "linear_rt", 9) ? " back" : "");
    for (k = 0; k < (size_t)WAVE_WEIGHTS; ++k)
        if (!strcmp(wave_weights[k].method, name)) return &wave_weights[k];
    return NULL;
}

/* The estimate of a counted row, per ray: wave steps x instructions per
   step (linear_rt's a node test's, and its texel tests' per node test); a
   loop with exit blocks, its trips x the rest of its body and its exit trips
   x those blocks; x WAVE_FULL / waves below WAVE_FULL waves per SIMD. In
   instructions a wave issues per ray it holds, over its lanes: comparable
   between methods. Also the loads a wave issues per ray. */
static void wave_estimate(const wave_weight *ww, wave_row *w)
{
    const double occupancy = ww->waves < WAVE_FULL ? (double)WAVE_FULL / (double)ww->waves : 1.0;
    w->estimate = w->loads = 0.0;
    if (!g_have_weights || !ww->read) return;
    w->estimate = ww->exits > 0.0 ? w->trips * (ww->loop - ww->exits) + w->refine_trips * ww->exits
                                  : w->wave * (ww->node + ww->texel * w->texels);
    w->estimate += w->finish_trips * ww->aside; /* after the walk's loop: a wave's most samples */
    w->estimate *= occupancy;
    w->loads = w->wave * (ww->node_loads + ww->texel_loads * w->texels);
}

/* linear_rt vulkan 16 at each step budget of the benchmark: the budgeted
   pass is the exact pass's walk cut short (an infinite tree's cell walk, a
   thickness tree's 8-child walk), so a ray's steps are min(steps, budget)
   of that walk's (the 8-child walk's texel tests per node test taken as
   the uncut walk's). With a finish (BENCH_FINISH), each stopped ray's
   samples (bench_finish_samples), each a trip of the loop beside the
   walk's (gpu_stats' aside loop), after the walk's loop; none without that
   loop's weight. */
static void budget_waves(const scene *sc, const bench_rays *rs, const uint32_t *steps, double texels)
{
    static const char *const names[4] = {"linear_rt vulkan 16 budget 4", "linear_rt vulkan 16 budget 8",
                                         "linear_rt vulkan 16 budget 16", "linear_rt vulkan 16 budget 32"};
    static const char *const finished[4] = {"linear_rt vulkan 16 budget 4 finish 16", "linear_rt vulkan 16 budget 8 finish 16",
                                            "linear_rt vulkan 16 budget 16 finish 16", "linear_rt vulkan 16 budget 32 finish 16"};
    const wave_weight *ww = weight_of("linear_rt vulkan 16 budget", sc->s.back != NULL);
    uint32_t *capped = (uint32_t *)malloc(sizeof(uint32_t) * rs->count);
    uint32_t *samples = (uint32_t *)malloc(sizeof(uint32_t) * rs->count);
    size_t q;
    int b;
    for (b = 0; capped && ww && b < 4 && g_nwaves < MAX_WAVES; ++b) {
        wave_row *w = &g_waves[g_nwaves++];
        const uint32_t budget = 4u << b;
        for (q = 0; q < rs->count; ++q) capped[q] = steps[q] < budget ? steps[q] : budget;
        w->scene = sc->s.name;
        w->set = rs->name;
        w->method = names[b];
        bench_wave_stats(capped, rs->count, WAVE_LANES, &w->mean, &w->wave);
        bench_wave_stats(capped, rs->count, WAVE_LANES_WIDE, &w->mean, &w->wave64);
        w->texels = texels;
        w->trips = w->wave, w->refine_trips = 0.0;
        wave_estimate(ww, w);
        if (samples && ww->aside > 0.0 && g_nwaves < MAX_WAVES && bench_finish_samples(&sc->s, rs, budget, samples) == 0) {
            wave_row *f = &g_waves[g_nwaves++];
            double mean;
            *f = *w;
            f->method = finished[b];
            bench_wave_stats(samples, rs->count, WAVE_LANES, &mean, &f->finish_trips);
            wave_estimate(ww, f);
        }
    }
    free(capped);
    free(samples);
}

static void make_dirs(const char *dir);

/* --dump-steps DIR: each set's steps per ray of the exact cell walk, as
   DIR/<scene>_<set>.u32 (little-endian uint32 in dispatch order, spaces in
   names as '-'), for bench/compaction.py */
static const char *g_steps_dir;

static void dump_steps(const scene *sc, const char *set, const uint32_t *steps, size_t n)
{
    char path[512];
    FILE *f;
    size_t k, at;
    make_dirs(g_steps_dir);
    at = (size_t)snprintf(path, sizeof path, "%s/", g_steps_dir);
    if (at >= sizeof path || (size_t)snprintf(path + at, sizeof path - at, "%s_%s.u32", sc->s.name, set) >= sizeof path - at) {
        fprintf(stderr, "bench: --dump-steps: the directory's name is too long\n");
        return;
    }
    for (k = at; path[k]; ++k)
        if (path[k] == ' ') path[k] = '-';
    f = fopen(path, "wb");
    if (!f || fwrite(steps, sizeof *steps, n, f) != n) fprintf(stderr, "bench: cannot write %s\n", path);
    if (f) fclose(f);
}

static void count_waves(const scene *sc, const ray_set *sets, int nsets)
{
    static const char *const names[5] = {"linear_rt vulkan 16", "linear_rt vulkan 8", "march64 vulkan", "dda vulkan",
                                         "hiz64 vulkan"};
    int s, k;
    for (s = 0; s < nsets; ++s) {
        const bench_rays *rs = &sets[s].r;
        uint32_t *steps = rs->count ? (uint32_t *)malloc(sizeof(uint32_t) * rs->count) : NULL;
        if (!steps) continue;
        for (k = 0; k < 5 && g_nwaves < MAX_WAVES; ++k) {
            wave_row *w = &g_waves[g_nwaves];
            const wave_weight *ww = weight_of(names[k], sc->s.back != NULL);
            double texels = 0.0;
            /* the exact pass: the cell walk, a thickness tree's the 8-child walk */
            int bad = k < 2 ? (sc->s.back ? bench_wave_linear_rt : bench_wave_cells)(&sc->s, rs, k == 0 ? 16u : 8u, steps, &texels)
                            : bench_wave_march(&sc->s, rs, k - 2, steps);
            if (bad && k < 2) fprintf(stderr, "bench: %s %s: the cell walk's mirror (bench/visits.c) differs from lrt_trace\n",
                                      sc->s.name, rs->name);
            if (bad || !ww) continue;
            w->scene = sc->s.name;
            w->set = rs->name;
            w->method = names[k];
            bench_wave_stats(steps, rs->count, WAVE_LANES, &w->mean, &w->wave);
            bench_wave_stats(steps, rs->count, WAVE_LANES_WIDE, &w->mean, &w->wave64);
            w->texels = w->mean > 0.0 ? texels / ((double)rs->count * w->mean) : 0.0;
            w->trips = w->wave, w->refine_trips = 0.0;
            if (k == 2) bench_wave_march_blocks(steps, rs->count, WAVE_LANES, &w->trips, &w->refine_trips);
            /* the DDA's cap is the larger side (bench/shaders/vkp_dda.comp), Hi-Z's 64 iterations */
            if (k == 3) bench_wave_exits(steps, rs->count, WAVE_LANES, sc->s.width > sc->s.height ? sc->s.width : sc->s.height,
                                         &w->trips, &w->refine_trips);
            if (k == 4) bench_wave_exits(steps, rs->count, WAVE_LANES, 64u, &w->trips, &w->refine_trips);
            wave_estimate(ww, w);
            if (g_steps_dir && k == 0 && !sc->s.back) dump_steps(sc, rs->name, steps, rs->count);
            ++g_nwaves;
            if (k == 0) { /* the budgets cut the exact pass's walk */
                const wave_weight *ww8 = weight_of("linear_rt vulkan 16 8-child", sc->s.back != NULL);
                double mean, wave, tex8 = 0.0;
                if (!sc->s.back) budget_waves(sc, rs, steps, w->texels);
                if (bench_wave_linear_rt(&sc->s, rs, 16u, steps, &tex8) == 0) {
                    bench_wave_stats(steps, rs->count, WAVE_LANES, &mean, &wave);
                    if (sc->s.back) budget_waves(sc, rs, steps, mean > 0.0 ? tex8 / ((double)rs->count * mean) : 0.0);
                    if (g_nwaves < MAX_WAVES) { /* the 8-child walk uncut (the one-pass kernel's, which the H200 ran) */
                        wave_row *e = &g_waves[g_nwaves++];
                        e->scene = sc->s.name;
                        e->set = rs->name;
                        e->method = "linear_rt vulkan 16, 8-child walk";
                        e->mean = mean;
                        e->wave = wave;
                        bench_wave_stats(steps, rs->count, WAVE_LANES_WIDE, &mean, &e->wave64);
                        e->texels = e->mean > 0.0 ? tex8 / ((double)rs->count * e->mean) : 0.0;
                        e->trips = e->wave, e->refine_trips = 0.0;
                        wave_estimate(ww8, e);
                    }
                }
            }
        }
        free(steps);
    }
}

static const wave_row *find_wave(const char *scene_name, const char *set, const char *method)
{
    int i;
    for (i = 0; i < g_nwaves; ++i)
        if (!strcmp(g_waves[i].scene, scene_name) && !strcmp(g_waves[i].set, set) && !strcmp(g_waves[i].method, method))
            return &g_waves[i];
    return NULL;
}

/* The same run's right % of method on scene / set, -1 where it did not run */
static double right_of(const char *method, const char *scene_name, const char *set)
{
    int i;
    for (i = 0; i < g_nres; ++i)
        if (g_res[i].ok && !strcmp(g_res[i].method, method) && !strcmp(g_res[i].scene, scene_name) && !strcmp(g_res[i].set, set))
            return g_res[i].sc.n ? 100.0 * (double)g_res[i].sc.right / (double)g_res[i].sc.n : 0.0;
    return -1.0;
}

/* linear_rt's curve on the GPU estimate: on each scene's secondary sets, is
   every Vulkan march's point (estimate, right %) matched by a linear_rt
   vulkan 16 point (exact, a step budget, or one with a finish) with an estimate no larger and a
   right % no lower? Needs the run's scores (not with --only-counts). */
static void write_wave_dominance(FILE *f)
{
    static const char *const peers[3] = {"march64 vulkan", "dda vulkan", "hiz64 vulkan"};
    static const char *const ours[9] = {"linear_rt vulkan 16",
                                        "linear_rt vulkan 16 budget 4",
                                        "linear_rt vulkan 16 budget 8",
                                        "linear_rt vulkan 16 budget 16",
                                        "linear_rt vulkan 16 budget 32",
                                        "linear_rt vulkan 16 budget 4 finish 16",
                                        "linear_rt vulkan 16 budget 8 finish 16",
                                        "linear_rt vulkan 16 budget 16 finish 16",
                                        "linear_rt vulkan 16 budget 32 finish 16"};
    int i, k, j, rows = 0, won = 0;
    if (!g_have_weights) return; /* no estimate to compare */
    for (i = 0; i < g_nwaves; ++i) {
        const wave_row *a = &g_waves[i];
        int peers_seen = 0, beaten = 0;
        if (strcmp(a->method, ours[0]) || !strcmp(a->set, "primary")) continue;
        for (k = 0; k < 3; ++k) {
            const wave_row *p = find_wave(a->scene, a->set, peers[k]);
            const double pr = right_of(peers[k], a->scene, a->set);
            int by = 0;
            if (!p || pr < 0.0) continue;
            ++peers_seen;
            for (j = 0; j < 9 && !by; ++j) {
                const wave_row *q = find_wave(a->scene, a->set, ours[j]);
                const double qr = right_of(ours[j], a->scene, a->set);
                by = q && qr >= pr && q->estimate <= p->estimate;
            }
            beaten += by;
        }
        if (!peers_seen) continue;
        if (!rows++)
            fprintf(f, "\nlinear_rt's curve on the estimate: each secondary row, \"(yes)\" where every Vulkan march's point "
                       "(estimate, right %%) has a linear_rt vulkan 16 point (exact, a step budget, or one with a finish) with no "
                       "larger an estimate "
                       "and no lower a right %%:\n\n");
        won += beaten == peers_seen;
        fprintf(f, "%s%s / %s", rows > 1 ? ", " : "", a->scene, a->set);
        if (beaten == peers_seen) fprintf(f, " (yes)");
    }
    if (rows) fprintf(f, ".\n\nDominated on the estimate: %d of %d rows.\n", won, rows);
}

/* The tables of what a wave pays, into f (results.md, or the --only-counts
   output) */
static void write_waves(FILE *f)
{
    static const char *const peers[3] = {"march64 vulkan", "dda vulkan", "hiz64 vulkan"};
    int i, k;
    if (!g_nwaves) return;
    fprintf(f, "\n## What a wave pays\n\nA GPU steps %u rays together (a warp, a wave32) and a group pays for its "
               "slowest ray. Steps per ray, counted on the CPU (bench/visits.c, bench/wave.c) as the Vulkan kernels "
               "take them: linear_rt's walk on an infinite tree, exact or with a step budget, its cells and texels "
               "tested (the cell walk); on a thickness tree its node tests at any level (the 8-child walk, always "
               "from the origin's level-1 node); the 64-step march's samples and bisection steps; the DDA's columns; "
               "the Hi-Z walk's iterations. Wave steps: the mean over groups of %u consecutive rays (dispatch order) "
               "of the group's most, for an NVIDIA warp or an RDNA wave32, and for %u lanes, the wave64 RADV compiles "
               "these kernels to. The ray-query peers are not counted (the hardware's traversal). Estimate: wave32 "
               "steps x the kernel's instructions per step (RDNA3, RADV: the static instructions of its loop body, "
               "read by make gpu-stats from the compiled code; the 8-child walk's texel tests added at their own "
               "weight per node test; a loop whose lanes leave it from inside, storing their answer (the peers: "
               "the march by its refinement), runs those exit blocks once for each trip in which some lane of the "
               "wave left, not every trip) x %d / waves per SIMD below %d: instructions a wave issues per ray "
               "(bench/calibrate.py checks it against the H200's peers).%s\n\n",
            WAVE_LANES, WAVE_LANES, WAVE_LANES_WIDE, WAVE_FULL, WAVE_FULL,
            g_have_weights ? "" : " No weights were given (bench --weights FILE, make gpu-stats): no estimate.");
    fprintf(f, "| scene | rays | method | steps per ray | wave steps (%u) | wave / mean | wave steps (%u) | wave / mean "
               "| texel tests per step | estimate |\n|---|---|---|--:|--:|--:|--:|--:|--:|--:|\n",
            WAVE_LANES, WAVE_LANES_WIDE);
    for (i = 0; i < g_nwaves; ++i) {
        const wave_row *w = &g_waves[i];
        fprintf(f, "| %s | %s | %s | %.2f | %.2f | %.2f | %.2f | %.2f |", w->scene, w->set, w->method, w->mean, w->wave,
                w->mean > 0.0 ? w->wave / w->mean : 0.0, w->wave64, w->mean > 0.0 ? w->wave64 / w->mean : 0.0);
        if (!strncmp(w->method, "linear_rt", 9)) fprintf(f, " %.2f |", w->texels);
        else fprintf(f, " |");
        fprintf(f, " %.0f |\n", w->estimate);
    }
    fprintf(f, "\nlinear_rt vulkan 16's estimate over each peer's (below 1: linear_rt estimated faster):\n\n"
               "| scene | rays | / march64 | / dda | / hiz64 |\n|---|---|--:|--:|--:|\n");
    for (i = 0; i < g_nwaves; ++i) {
        const wave_row *a = &g_waves[i];
        if (strcmp(a->method, "linear_rt vulkan 16")) continue;
        fprintf(f, "| %s | %s |", a->scene, a->set);
        for (k = 0; k < 3; ++k) {
            const wave_row *b = find_wave(a->scene, a->set, peers[k]);
            if (b && b->estimate > 0.0) fprintf(f, " %.2f |", a->estimate / b->estimate);
            else fprintf(f, " - |");
        }
        fprintf(f, "\n");
    }
}

/* The counts as tab-separated values (DIR/waves.tsv), for the estimate's
   calibration (bench/calibrate.py): scene, set, method, steps per ray, wave
   steps of 32 and of 64, texel tests per step, the estimate's instructions
   and loads a wave issues per ray. */
static void write_waves_tsv(const char *dir)
{
    char path[600];
    FILE *f;
    int i;
    snprintf(path, sizeof path, "%s/waves.tsv", dir);
    if (!g_nwaves || !(f = fopen(path, "w"))) return;
    fprintf(f, "# scene\tset\tmethod\tmean\twave32\twave64\ttexels_per_step\tinstructions\tloads\ttrips32\t"
               "refine_trips32\n");
    for (i = 0; i < g_nwaves; ++i) {
        const wave_row *w = &g_waves[i];
        fprintf(f, "%s\t%s\t%s\t%.4f\t%.4f\t%.4f\t%.4f\t%.1f\t%.2f\t%.4f\t%.4f\n", w->scene, w->set, w->method, w->mean,
                w->wave, w->wave64, w->texels, w->estimate, w->loads, w->trips, w->refine_trips);
    }
    fclose(f);
}

static double median(double *v, int n)
{
    int i, j;
    for (i = 1; i < n; ++i)
        for (j = i; j > 0 && v[j] < v[j - 1]; --j) {
            double t = v[j];
            v[j] = v[j - 1];
            v[j - 1] = t;
        }
    return n ? v[n / 2] : 0.0;
}

static double pct(size_t a, size_t n) { return n ? 100.0 * (double)a / (double)n : 0.0; }

#define TRACE_MIN_MS 20.0 /* --quick: 0, one trace a run */
#define TRACE_MAX_REPEATS 1000

/* methods on one scene: build, update, every ray set. The methods of one
   device (every CPU method, or every Vulkan one: the columns whose ratios
   the README and the issues read) take their runs of each set in turn, the
   order rotating from run to run, so that this machine's slow and fast
   phases (docs/PERFORMANCE.md, "The machine and its noise") fall on all of
   them alike; each is scored on hits of its own. A method's results come
   out set by set, in the order of the sets, as if it ran alone */
#define GROUP_MAX 24
static void run_methods(bench_method *const *m, int nm, const scene *sc, ray_set *sets, int nsets, const options *o,
                        lrt_hit *hits)
{
    static double upd[GROUP_MAX][16], t[GROUP_MAX][16];
    double build_ms[GROUP_MAX] = {0}, ms;
    int k, s, j, ok[GROUP_MAX], first = g_nres;
    char why[GROUP_MAX][160]; /* nm <= GROUP_MAX: device_group makes no larger group */
    for (j = 0; j < nm; ++j) {
        why[j][0] = '\0';
        ok[j] = !m[j]->build(m[j], &sc->s, &build_ms[j], why[j], sizeof why[j]);
    }
    for (k = 0; k <= o->runs; ++k) /* one warm-up */
        for (j = 0; j < nm; ++j) {
            if (!ok[j]) continue;
            if (m[j]->update(m[j], &sc->s, &ms, why[j], sizeof why[j])) ok[j] = 0;
            else if (k) upd[j][k - 1] = ms;
        }
    for (s = 0; s < nsets; ++s) {
        result *r[GROUP_MAX];
        for (j = 0; j < nm; ++j) {
            const int at = first + j * nsets + s; /* method-major, as a method alone would write them */
            r[j] = &g_res[at < MAX_RESULTS ? at : MAX_RESULTS - 1];
            if (at >= g_nres) g_nres = at + 1 < MAX_RESULTS ? at + 1 : MAX_RESULTS;
            memset(r[j], 0, sizeof *r[j]);
            r[j]->method = m[j]->name;
            r[j]->device = m[j]->device;
            r[j]->scene = sc->s.name;
            r[j]->set = sets[s].r.name;
            r[j]->exact = m[j]->exact;
            r[j]->threads = strcmp(m[j]->device, "cpu") == 0 ? o->threads : 0;
            r[j]->rays = sets[s].r.count;
            r[j]->ok = ok[j];
            snprintf(r[j]->why, sizeof r[j]->why, "%.159s", why[j]);
        }
        for (k = 0; k <= o->runs; ++k)
            for (j = 0; j < nm; ++j) {
                /* a run traces the set again until TRACE_MIN_MS have passed
                   (at most TRACE_MAX_REPEATS times) and keeps the mean: a set
                   of a few thousand rays takes well under a millisecond,
                   where one call's timing is mostly the machine's noise.
                   Passed on the wall clock: a GPU method's time is its
                   timestamps', and on a discrete GPU each call also copies
                   rays and hits over PCIe, many times longer (an H200 spent
                   over 90 s on one method's sets when the loop counted the
                   timestamps). In a group the order rotates */
                const int q = (j + k) % nm;
                const double wall0 = bench_now_ms();
                double total = 0.0;
                int reps = 0;
                if (!r[q]->ok) continue;
                do {
                    if (m[q]->trace(m[q], &sc->s, &sets[s].r, hits, &ms, r[q]->why, sizeof r[q]->why)) {
                        r[q]->ok = 0;
                        break;
                    }
                    total += ms;
                    ++reps;
                } while (!o->quick && bench_now_ms() - wall0 < TRACE_MIN_MS && reps < TRACE_MAX_REPEATS);
                if (k && reps) t[q][k - 1] = total / reps;
            }
        for (j = 0; j < nm; ++j) {
            if (!r[j]->ok) continue;
            /* in a group the hits are the last method's: trace again */
            if (nm > 1 && m[j]->trace(m[j], &sc->s, &sets[s].r, hits, &ms, r[j]->why, sizeof r[j]->why)) {
                r[j]->ok = 0;
                continue;
            }
            r[j]->build_ms = build_ms[j];
            r[j]->update_ms = median(upd[j], o->runs);
            r[j]->trace_ms = median(t[j], o->runs);
            r[j]->bytes_per_texel = (double)m[j]->memory_bytes(m[j]) / ((double)sc->s.width * sc->s.height);
            score_set(sc, &sets[s], hits, m[j]->exact ? 1 : m[j]->budgeted == 2 ? 3 : m[j]->budgeted ? 2 : 0, &r[j]->sc);
        }
    }
}

/* the group of m[k], the first method of its device not yet run: every
   method of that device that runs (not skipped), in the order of m; marks
   them done and returns how many */
static int device_group(bench_method *m, const char *const *skipped, int k, int nm, char *done, bench_method **group)
{
    int j, g = 0;
    for (j = k; j < nm && g < GROUP_MAX; ++j)
        if (!skipped[j] && !done[j] && strcmp(m[j].device, m[k].device) == 0) {
            done[j] = 1;
            group[g++] = &m[j];
        }
    return g;
}

/* results g_res[first..] into the order of m (a method's rows together, as
   when every method ran alone), stable: device groups write theirs device
   by device */
static int method_index(const bench_method *m, int nm, const char *name)
{
    int k;
    for (k = 0; k < nm; ++k)
        if (strcmp(m[k].name, name) == 0) return k;
    return nm;
}
static void order_results(int first, const bench_method *m, int nm)
{
    int i, j;
    for (i = first + 1; i < g_nres; ++i) {
        result r = g_res[i];
        const int key = method_index(m, nm, r.method);
        for (j = i; j > first && method_index(m, nm, g_res[j - 1].method) > key; --j) g_res[j] = g_res[j - 1];
        g_res[j] = r;
    }
}

/* ---- the stability suite: small named cases built to break someone -------------- */
typedef struct stab_case {
    const char *name;
    scene sc;
    ray_set set;
} stab_case;

static void stab_rays(stab_case *c, size_t n, void (*gen)(const scene *, lrt_ray *, size_t))
{
    size_t q;
    ray_set *rs = &c->set;
    memset(rs, 0, sizeof *rs);
    rs->rays = (lrt_ray *)calloc(n, sizeof(lrt_ray));
    for (q = 0; q < n; ++q) gen(&c->sc, &rs->rays[q], q);
    rs->r.name = c->name;
    rs->r.rays = rs->rays;
    rs->r.count = n;
    rs->sample_stride = 1;
    rs->sample_count = n;
    rs->ref = (ref_result *)malloc(sizeof(ref_result) * n);
    for (q = 0; q < n; ++q) {
        ref_ray rr = ref_ray_of(&rs->rays[q]);
        rs->ref[q] = ref_trace_ray(&c->sc.ref, &rr);
    }
}

static void set_ray(lrt_ray *r, float ox, float oy, float oz, float vx, float vy, float vz, float tmin, float tmax)
{
    r->origin[0] = ox;
    r->origin[1] = oy;
    r->origin[2] = oz;
    r->dir[0] = vx;
    r->dir[1] = vy;
    r->dir[2] = vz;
    r->tmin = tmin;
    r->tmax = tmax;
}

/* horizontal rays through a field of 1-texel poles, at the poles' depth band */
static void gen_poles(const scene *sc, lrt_ray *r, size_t q)
{
    float y = 1.0f + rnd01() * (float)(sc->s.height / 2u);
    set_ray(r, 0.5f, y, 0.36f + 0.2f * rnd01(), (float)sc->s.width, 7.0f * (rnd01() - 0.5f), 0.0f, 0.0f, 1.0f);
    (void)q;
}
/* rays skimming a sloped floor from above, within a hair of its depth */
static void gen_grazing(const scene *sc, lrt_ray *r, size_t q)
{
    float x = rnd01() * (float)sc->s.width, y = (float)sc->s.height * (0.6f + 0.3f * rnd01());
    float d = depth_at(sc, (int)x, (int)y);
    set_ray(r, x, y, d - 2e-4f * rnd01(), (rnd01() - 0.5f) * 40.0f, -30.0f * rnd01(), 1e-4f * (rnd01() - 0.7f), 0.0f,
            1.0f);
    (void)q;
}
/* over low ground and out across a screen edge */
static void gen_edges(const scene *sc, lrt_ray *r, size_t q)
{
    float a = 6.2831853f * rnd01(), k = 2.0f * (float)(sc->s.width + sc->s.height);
    set_ray(r, 0.5f * (float)sc->s.width, 0.5f * (float)sc->s.height, 0.1f, cosf(a) * k, sinf(a) * k, 1e-3f, 0.0f, 1.0f);
    (void)q;
}
/* from deep points back towards the camera */
static void gen_towards(const scene *sc, lrt_ray *r, size_t q)
{
    float x = rnd01() * (float)sc->s.width, y = rnd01() * (float)sc->s.height, d = depth_at(sc, (int)x, (int)y);
    set_ray(r, x, y, d - 1e-3f, (rnd01() - 0.5f) * 64.0f, (rnd01() - 0.5f) * 64.0f, -d * rnd01(), 0.0f, 1.0f);
    (void)q;
}
/* just behind the top edge of a near block over a far floor */
static void gen_discontinuity(const scene *sc, lrt_ray *r, size_t q)
{
    float y = (float)sc->s.height * (0.3f + 0.4f * rnd01());
    set_ray(r, 1.0f, y, 0.2501f + 1e-3f * rnd01(), (float)sc->s.width - 2.0f, 0.0f, 0.5f * rnd01(), 0.0f, 1.0f);
    (void)q;
}
/* a reflection starting on its own surface: tmin 0 (hits at tmin by the model) */
static void gen_own(const scene *sc, lrt_ray *r, size_t q)
{
    int i = (int)(rnd01() * (float)sc->s.width), j = (int)(rnd01() * (float)sc->s.height);
    set_ray(r, (float)i + 0.5f, (float)j + 0.5f, depth_at(sc, i, j), 30.0f * (rnd01() - 0.5f), 30.0f * (rnd01() - 0.5f),
            0.01f * rnd01(), 0.0f, 1.0f);
    (void)q;
}
/* flat reflective rays over camera-facing 8-bit steps */
static void gen_quant(const scene *sc, lrt_ray *r, size_t q)
{
    int i = (int)(rnd01() * (float)sc->s.width), j = (int)(rnd01() * (float)sc->s.height);
    float d = depth_at(sc, i, j), a = 6.2831853f * rnd01();
    set_ray(r, (float)i + 0.5f, (float)j + 0.5f, d, cosf(a) * 200.0f, sinf(a) * 200.0f, 0.0f, 0.75f / 200.0f, 1.0f);
    (void)q;
}
/* any rays at all on a tiny or a large map */
static void gen_random(const scene *sc, lrt_ray *r, size_t q)
{
    float x = rnd01() * (float)sc->s.width, y = rnd01() * (float)sc->s.height;
    set_ray(r, x, y, rnd01() * 0.5f, (rnd01() - 0.5f) * 2.0f * (float)sc->s.width,
            (rnd01() - 0.5f) * 2.0f * (float)sc->s.height, rnd01(), 0.0f, 1.0f);
    (void)q;
}

static void stab_scene(scene *sc, const char *name, uint32_t w, uint32_t h, int kind)
{
    uint32_t i, j;
    memset(sc, 0, sizeof *sc);
    sc->depth = (float *)malloc(sizeof(float) * w * h);
    for (j = 0; j < h; ++j)
        for (i = 0; i < w; ++i) {
            float d = 0.5f + 0.45f * (float)j / (float)h; /* a floor rising away from the camera */
            if (kind == 1 && i % 9u == 4u && j < h * 3u / 4u) d = 0.4f;                        /* poles */
            if (kind == 2 && j > h / 4u && j < h * 3u / 4u && i > w / 3u && i < w / 2u) d = 0.25f; /* a block */
            if (kind == 3) d = floorf((0.4f + 0.5f * (float)((i / 7u + j / 5u) % 6u) / 6.0f) * 255.0f) / 255.0f;
            sc->depth[j * w + i] = d;
        }
    if (kind >= 4) { /* thickness: a back map, the floor solid to the far plane */
        sc->back = (float *)malloc(sizeof(float) * w * h);
        for (j = 0; j < h; ++j)
            for (i = 0; i < w; ++i) {
                float d = sc->depth[j * w + i], b = 1.0f;
                if (kind == 4 && i >= w / 3u && i < 2u * w / 3u && j >= h / 4u && j < 3u * h / 4u) { /* a thin floating slab */
                    d = 0.3f;
                    b = 0.32f;
                } else if (kind == 5 && i == w / 2u) { /* a pole, thin in depth too */
                    d = 0.3f;
                    b = 0.305f;
                } else if (kind == 6) { /* a sphere: its front and back */
                    float dx = ((float)i - 0.5f * (float)w) / (0.25f * (float)w), dy = ((float)j - 0.5f * (float)h) / (0.25f * (float)h);
                    float rr = dx * dx + dy * dy;
                    if (rr < 1.0f) {
                        d = 0.5f - 0.2f * sqrtf(1.0f - rr);
                        b = 0.5f + 0.2f * sqrtf(1.0f - rr);
                    }
                }
                sc->depth[j * w + i] = d;
                sc->back[j * w + i] = b;
            }
    }
    scene_finish(sc, name, w, h);
}

#define STAB_CASES 12
/* thickness: level rays under the slab, between its back and the floor */
static void gen_under_slab(const scene *sc, lrt_ray *r, size_t q)
{
    float y = (float)sc->s.height * (0.25f + 0.5f * rnd01());
    set_ray(r, 0.5f, y, 0.33f + 0.15f * rnd01(), (float)sc->s.width, 2.0f * (rnd01() - 0.5f), 0.001f * (rnd01() - 0.5f), 0.0f,
            1.0f);
    (void)q;
}
/* along the pole's length, inside its column, around its back */
static void gen_pole_edge_on(const scene *sc, lrt_ray *r, size_t q)
{
    set_ray(r, (float)(sc->s.width / 2u) + 0.05f + 0.9f * rnd01(), 0.5f, 0.298f + 0.01f * rnd01(), 0.02f * (rnd01() - 0.5f),
            (float)sc->s.height, 0.002f * (rnd01() - 0.5f), 0.0f, 1.0f);
    (void)q;
}
/* level rays just in front of and behind the sphere's back, across its middle */
static void gen_sphere_back(const scene *sc, lrt_ray *r, size_t q)
{
    float y = (float)sc->s.height * (0.4f + 0.2f * rnd01());
    set_ray(r, 0.5f, y, 0.62f + 0.1f * rnd01(), (float)sc->s.width, 0.0f, 0.0005f * (rnd01() - 0.5f), 0.0f, 1.0f);
    (void)q;
}

static int make_stability(stab_case *c, const options *o)
{
    const uint32_t s = o->quick ? 64u : 256u, big = o->quick ? 512u : 2048u;
    const size_t n = o->quick ? 300u : 3000u;
    int k = 0;
    c[k].name = "thin poles"; stab_scene(&c[k].sc, "poles", s, s, 1); stab_rays(&c[k++], n, gen_poles);
    c[k].name = "grazing floor"; stab_scene(&c[k].sc, "floor", s, s, 0); stab_rays(&c[k++], n, gen_grazing);
    c[k].name = "leaving the screen"; stab_scene(&c[k].sc, "floor", s, s, 0); stab_rays(&c[k++], n, gen_edges);
    c[k].name = "towards the camera"; stab_scene(&c[k].sc, "block", s, s, 2); stab_rays(&c[k++], n, gen_towards);
    c[k].name = "depth discontinuity"; stab_scene(&c[k].sc, "block", s, s, 2); stab_rays(&c[k++], n, gen_discontinuity);
    c[k].name = "own surface"; stab_scene(&c[k].sc, "block", s, s, 2); stab_rays(&c[k++], n, gen_own);
    c[k].name = "8-bit quantisation"; stab_scene(&c[k].sc, "steps", s, s, 3); stab_rays(&c[k++], n, gen_quant);
    c[k].name = "tiny map 3x2"; stab_scene(&c[k].sc, "tiny", 3, 2, 2); stab_rays(&c[k++], n, gen_random);
    c[k].name = "large map"; stab_scene(&c[k].sc, "large", big, big, 1); stab_rays(&c[k++], n, gen_random);
    /* thickness (back maps): methods without it are skipped on these */
    c[k].name = "under a thin slab"; stab_scene(&c[k].sc, "slab", s, s, 4); stab_rays(&c[k++], n, gen_under_slab);
    c[k].name = "a pole edge-on"; stab_scene(&c[k].sc, "pole", s, s, 5); stab_rays(&c[k++], n, gen_pole_edge_on);
    c[k].name = "behind a sphere"; stab_scene(&c[k].sc, "sphere", s, s, 6); stab_rays(&c[k++], n, gen_sphere_back);
    return k;
}

/* ---- output ---------------------------------------------------------------------- */
static const result *find(const char *method, const char *scene_name, const char *set)
{
    int i;
    for (i = 0; i < g_nres; ++i)
        if (strcmp(g_res[i].method, method) == 0 && strcmp(g_res[i].scene, scene_name) == 0 &&
            strcmp(g_res[i].set, set) == 0 && g_res[i].ok)
            return &g_res[i];
    return NULL;
}

static double mrays(const result *r) { return r && r->trace_ms > 0 ? (double)r->rays / r->trace_ms / 1e3 : 0.0; }

/* mkdir -p: each folder of dir in turn (those that exist are left alone) */
static void make_dirs(const char *dir)
{
    char path[512];
    size_t k, n = strlen(dir);
    if (n >= sizeof path) return;
    memcpy(path, dir, n + 1);
    for (k = 1; k <= n; ++k) {
        if (path[k] != '/' && path[k] != 0) continue;
        path[k] = 0;
        (void)mkdir(path, 0777);
        path[k] = dir[k];
    }
}

/* results.csv: every row so far (written after each scene too, so that a
   run stopped by a time limit keeps what it measured) */
static void write_csv(const options *o)
{
    char path[512];
    FILE *csv;
    int i;
    make_dirs(o->out_dir);
    snprintf(path, sizeof path, "%s/results.csv", o->out_dir);
    if (!(csv = fopen(path, "w"))) {
        fprintf(stderr, "bench: cannot write into %s\n", o->out_dir);
        exit(1);
    }
    fprintf(csv, "method,device,exact,threads,scene,rays,count,build_ms,update_ms,trace_ms,mrays_per_s,bytes_per_texel,"
                 "scored,right_pct,false_hits_pct,false_misses_pct,mean_dist_texels,ok,why\n");
    for (i = 0; i < g_nres; ++i) {
        const result *r = &g_res[i];
        fprintf(csv, "%s,%s,%d,%d,%s,%s,%zu,%.3f,%.3f,%.3f,%.3f,%.3f,%zu,%.3f,%.3f,%.3f,%.4f,%d,\"%s\"\n", r->method,
                r->device, r->exact, r->threads, r->scene, r->set, r->rays, r->build_ms, r->update_ms, r->trace_ms,
                mrays(r), r->bytes_per_texel, r->sc.n, pct(r->sc.right, r->sc.n), pct(r->sc.false_hits, r->sc.n),
                pct(r->sc.false_misses, r->sc.n), r->sc.both_hit ? r->sc.dist_sum / (double)r->sc.both_hit : 0.0,
                r->ok, r->why);
    }
    fclose(csv);
    if (!g_nvisits) return;
    snprintf(path, sizeof path, "%s/visits.csv", o->out_dir);
    if (!(csv = fopen(path, "w"))) {
        fprintf(stderr, "bench: cannot write into %s\n", o->out_dir);
        exit(1);
    }
    fprintf(csv, "scene,rays,node_bits,level0_per_ray,level1_per_ray,above_per_ray,all_per_ray,texels_per_ray\n");
    for (i = 0; i < g_nvisits; ++i) {
        const visits_row *v = &g_visits[i];
        fprintf(csv, "%s,%s,%u,%.3f,%.3f,%.3f,%.3f,%.3f\n", v->scene, v->set, v->node_bits, v->per_ray[0], v->per_ray[1],
                v->per_ray[2], v->per_ray[0] + v->per_ray[1] + v->per_ray[2], v->per_ray[3]);
    }
    fclose(csv);
}

/* Build and whole-map update of linear_rt's CPU tree on one scene under each
   thickness model (docs/MODEL.md), 16- and 8-bit nodes: medians of o->runs
   after a warm-up, one thread (the library's build and update are). The
   constant and relative models take the scene camera's planes (near 0.1,
   far 100 for a map without one); the back map is the scene's own where it
   has one. results.md's "Build and update by thickness model". */
typedef struct thick_cost { const char *model; uint32_t bits; double build_ms, update_ms; } thick_cost;
static thick_cost g_tcost[16];
static int g_ntcost;
static const char *g_tcost_scene;

static void time_thickness_models(const scene *sc, const options *o)
{
    static const char *names[4] = {"infinite", "back map", "constant 0.3", "relative 5%"};
    float n = 0.1f, f = 100.0f;
    uint32_t model, bits;
    if (sc->has_camera && !lrt_camera_planes(&sc->camera, &n, &f)) n = 0.1f, f = 100.0f;
    g_tcost_scene = sc->s.name;
    for (bits = 16; bits >= 8; bits -= 8) {
        for (model = LRT_THICKNESS_INFINITE; model <= LRT_THICKNESS_RELATIVE; ++model) {
            lrt_build_options opt;
            lrt_depth d = sc->s.lrt, back = sc->s.lrt;
            double b[32], u[32], t0;
            int r, runs = o->runs < 32 ? o->runs : 32;
            if (model == LRT_THICKNESS_BACK_MAP) {
                if (!sc->back) continue;
                back.data = sc->back;
                d.back = &back;
            }
            memset(&opt, 0, sizeof opt);
            opt.node_bits = bits;
            opt.thickness = model;
            opt.thickness_value = model == LRT_THICKNESS_CONSTANT ? 0.3f : 0.05f;
            opt.near_z = n;
            opt.far_z = f;
            for (r = -1; r < runs; ++r) {
                lrt_bvh bvh;
                memset(&bvh, 0, sizeof bvh);
                t0 = bench_now_ms();
                if (lrt_bvh_build(&bvh, &d, &opt, NULL) != LRT_SUCCESS) break;
                if (r >= 0) b[r] = bench_now_ms() - t0;
                t0 = bench_now_ms();
                lrt_bvh_update(&bvh, &d, NULL);
                if (r >= 0) u[r] = bench_now_ms() - t0;
                lrt_bvh_destroy(&bvh);
            }
            if (r < runs || g_ntcost >= 16) continue;
            g_tcost[g_ntcost].model = names[model];
            g_tcost[g_ntcost].bits = bits;
            g_tcost[g_ntcost].build_ms = median(b, runs);
            g_tcost[g_ntcost].update_ms = median(u, runs);
            ++g_ntcost;
        }
    }
}

/* Speed against accuracy, per scene, secondary set and device column: is
   every other method's point dominated by one of linear_rt's (the exact
   walks, the step budgets and the budgets with a finish), at least as right
   and at least as fast?
   A row with nothing else run counts as neither. Returns the rows
   dominated, *rows the rows with a peer; *exact_only those the exact
   walks alone dominate. */
static int is_linear_rt(const char *method) { return strncmp(method, "linear_rt", 9) == 0; }
static int write_dominance(FILE *md, int *rows, int *exact_only)
{
    static const char *const devs[2] = {"cpu", "vulkan"};
    static const char *const sets[4] = {"reflection", "ao", "shadow", "segments"};
    const char *scenes[16];
    int nsc = 0, d, c, s, i, j, won = 0;
    *rows = *exact_only = 0;
    for (i = 0; i < g_nres && nsc < 16; ++i) {
        for (j = 0; j < nsc && strcmp(scenes[j], g_res[i].scene); ++j) {}
        if (j == nsc && strcmp(g_res[i].set, "primary")) scenes[nsc++] = g_res[i].scene;
    }
    fprintf(md, "\n## linear_rt's curve: speed against accuracy, per scene and secondary set\n\n"
                "A row is dominated when every other method's point (M rays/s, right %%) on that device has a linear_rt "
                "point (an exact walk, a step budget, or a budget with a finish) at least as fast and at least as right. "
                "Not dominated: the "
                "peers no linear_rt point reaches, with their M rays/s and right %%.\n\n");
    fprintf(md, "| device | scene | rays | dominated | by the exact walk alone | peers not dominated |\n|---|---|---|---|---|---|\n");
    for (d = 0; d < 2; ++d)
        for (c = 0; c < nsc; ++c)
            for (s = 0; s < 4; ++s) {
                int peers = 0, beaten = 0, beaten_exact = 0;
                char left[400];
                size_t used = 0;
                left[0] = '\0';
                for (i = 0; i < g_nres; ++i) {
                    const result *p = &g_res[i];
                    int by_any = 0, by_exact = 0;
                    if (!p->ok || is_linear_rt(p->method) || strcmp(p->device, devs[d]) || strcmp(p->scene, scenes[c]) ||
                        strcmp(p->set, sets[s]))
                        continue;
                    ++peers;
                    for (j = 0; j < g_nres; ++j) {
                        const result *q = &g_res[j];
                        if (!q->ok || !is_linear_rt(q->method) || strcmp(q->device, devs[d]) || strcmp(q->scene, scenes[c]) ||
                            strcmp(q->set, sets[s]))
                            continue;
                        if (mrays(q) >= mrays(p) && pct(q->sc.right, q->sc.n) >= pct(p->sc.right, p->sc.n)) {
                            by_any = 1;
                            by_exact |= q->exact;
                        }
                    }
                    beaten += by_any;
                    beaten_exact += by_exact;
                    if (!by_any && used + 80 < sizeof left)
                        used += (size_t)snprintf(left + used, sizeof left - used, "%s%s (%.2f, %.1f%%)", used ? ", " : "",
                                                 p->method, mrays(p), pct(p->sc.right, p->sc.n));
                }
                if (!peers) continue;
                ++*rows;
                won += beaten == peers;
                *exact_only += beaten_exact == peers;
                fprintf(md, "| %s | %s | %s | %s | %s | %s |\n", devs[d], scenes[c], sets[s], beaten == peers ? "yes" : "no",
                        beaten_exact == peers ? "yes" : "no", left);
            }
    fprintf(md, "\nDominated: %d of %d rows; by the exact walk alone: %d.\n", won, *rows, *exact_only);
    return won;
}

static void write_outputs(const options *o, bench_method *m, int nm, const char *const *why_skipped,
                          const char *machine, int nstab, const scene *first)
{
    char path[512];
    FILE *md, *dat;
    int i, k, t;
    write_csv(o);
    snprintf(path, sizeof path, "%s/results.md", o->out_dir);
    md = fopen(path, "w");
    snprintf(path, sizeof path, "%s/points.dat", o->out_dir);
    dat = fopen(path, "w");
    if (!md || !dat) {
        fprintf(stderr, "bench: cannot write into %s\n", o->out_dir);
        exit(1);
    }
    fprintf(md, "# linear_rt benchmark\n\n%s\n\n", machine);
    fprintf(md, "Methods skipped here, and why:\n\n");
    for (k = 0; k < nm; ++k)
        if (why_skipped[k]) fprintf(md, "- %s (%s): %s\n", m[k].name, m[k].device, why_skipped[k]);
    if (o->depth_file)
        fprintf(md,
                "\n## Speed and accuracy, scene \"file\" (%s, %u x %u), per ray set\n\nReflection, ao and shadow rays "
                "through a perspective camera (fov %g, near %g, far %g), as the examples build them; sky texels and "
                "surfaces facing away from the light have none.\n\n",
                o->depth_file, first->s.width, first->s.height, (double)o->fov_deg, (double)o->near_z,
                (double)o->far_z);
    else fprintf(md, "\n## Speed and accuracy, scene \"yard\" (%u x %u), per ray set\n\n", o->size, o->size);
    for (k = 0; k < 2; ++k) { /* the yard (or the file), then the yard with thickness */
        if (k == 1) {
            if (o->depth_file) break;
            fprintf(md, "\n## Thickness: scene \"yard back\" (%u x %u), the yard's objects ending at their back faces, "
                        "every method under that model (those without one are skipped)\n\n", o->size, o->size);
        }
        fprintf(md, "| method | device | rays | build ms | update ms | trace ms | M rays/s | bytes/texel | right %% | false hits %% | false misses %% | mean dist (texels) |\n");
        fprintf(md, "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
        for (i = 0; i < g_nres; ++i) {
            const result *r = &g_res[i];
            if (k == 0 ? strcmp(r->scene, "yard") != 0 && strcmp(r->scene, "file") != 0 : strcmp(r->scene, "yard back") != 0)
                continue;
            if (!r->ok) continue;
            fprintf(md, "| %s | %s%s | %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.3f |\n", r->method,
                    r->device, r->threads ? (r->threads == 1 ? " 1t" : " mt") : "", r->set, r->build_ms, r->update_ms,
                    r->trace_ms, mrays(r), r->bytes_per_texel, pct(r->sc.right, r->sc.n), pct(r->sc.false_hits, r->sc.n),
                    pct(r->sc.false_misses, r->sc.n), r->sc.both_hit ? r->sc.dist_sum / (double)r->sc.both_hit : 0.0);
        }
    }
    /* one point per method: secondary rays (reflection + segments) of every
       scene of the infinite layer (a method without thickness has no yard
       back), then of the yard back alone, on the thickness panels (device
       "cpu_thick", "vulkan_thick") */
    fprintf(dat, "# method device mrays_per_s right_pct exact\n");
    for (t = 0; t < 2; ++t) {
        for (k = 0; k < nm; ++k) {
            double ms = 0, right = 0, n = 0, rays = 0;
            for (i = 0; i < g_nres; ++i) {
                const result *r = &g_res[i];
                if (!r->ok || strcmp(r->method, m[k].name) != 0 || (strcmp(r->set, "reflection") && strcmp(r->set, "segments")) ||
                    (strcmp(r->scene, "yard back") == 0) != t)
                    continue;
                ms += r->trace_ms;
                rays += (double)r->rays;
                right += (double)r->sc.right;
                n += (double)r->sc.n;
            }
            if (ms > 0)
                fprintf(dat, "\"%s\" %s%s %.4f %.4f %d\n", m[k].name, m[k].device, t ? "_thick" : "", rays / ms / 1e3,
                        100.0 * right / n, m[k].exact);
        }
    }
    {
        int rows, exact_only, won = write_dominance(md, &rows, &exact_only);
        printf("linear_rt's curve dominates %d of %d rows (scene x secondary set x device); the exact walk alone %d\n", won,
               rows, exact_only);
    }
    fprintf(md, "\n## Stability: every method against every case (%% of rays right; exact methods must be 100)\n\n");
    fprintf(md, "| case |");
    for (k = 0; k < nm; ++k)
        if (!why_skipped[k]) fprintf(md, " %s |", m[k].name);
    fprintf(md, "\n|---|");
    for (k = 0; k < nm; ++k)
        if (!why_skipped[k]) fprintf(md, "---|");
    fprintf(md, "\n");
    {
        const char *prev = NULL;
        for (i = 0; i < g_nres; ++i) {
            const result *r = &g_res[i];
            if (strncmp(r->scene, "stab:", 5) != 0 || (prev && strcmp(prev, r->set) == 0)) continue;
            prev = r->set;
            fprintf(md, "| %s |", r->set);
            for (k = 0; k < nm; ++k) {
                const result *c = NULL;
                int j;
                if (why_skipped[k]) continue;
                for (j = 0; j < g_nres; ++j)
                    if (strcmp(g_res[j].method, m[k].name) == 0 && strcmp(g_res[j].set, r->set) == 0 &&
                        strncmp(g_res[j].scene, "stab:", 5) == 0)
                        c = &g_res[j];
                if (!c || !c->ok) fprintf(md, " - |");
                else if (m[k].exact) fprintf(md, " %s %.1f |", c->sc.right == c->sc.n ? "pass" : "FAIL", pct(c->sc.right, c->sc.n));
                else fprintf(md, " %.1f |", pct(c->sc.right, c->sc.n));
            }
            fprintf(md, "\n");
        }
    }
    if (g_nvisits) {
        fprintf(md, "\n## What linear_rt's walk costs per ray\n\nNode tests per ray (bench/visits.c, one thread): "
                    "level 0 (the one texel of a ray that needs no walk) / level 1 (a level-1 node's 8 texels) / above "
                    "(a node's 8 children), then the exact tests of texels that the level-1 codes let through (as the "
                    "kernels make them; the CPU's AVX2 walk reads float depth instead); the same counts are in "
                    "visits.csv.\n\n");
        fprintf(md, "| scene | rays | 16-bit nodes | 8-bit nodes |\n|---|---|---|---|\n");
        for (i = 0; i < g_nvisits; ++i) { /* each set's 16-bit row, and its 8-bit row where there is one */
            const visits_row *a = &g_visits[i], *b = NULL;
            if (a->node_bits != 16u) continue;
            for (k = 0; k < g_nvisits; ++k)
                if (g_visits[k].node_bits == 8u && !strcmp(g_visits[k].scene, a->scene) && !strcmp(g_visits[k].set, a->set))
                    b = &g_visits[k];
            fprintf(md, "| %s | %s | %.2f / %.2f / %.2f; %.2f |", a->scene, a->set, a->per_ray[0], a->per_ray[1], a->per_ray[2],
                    a->per_ray[3]);
            if (b) fprintf(md, " %.2f / %.2f / %.2f; %.2f |\n", b->per_ray[0], b->per_ray[1], b->per_ray[2], b->per_ray[3]);
            else fprintf(md, " - |\n");
        }
    }
    if (g_ntcost) {
        fprintf(md, "\n## Build and update by thickness model\n\nlinear_rt's CPU tree of scene \"%s\", one thread, medians; "
                    "a thickness model keeps a second code per slot (twice the bytes) and refits both.\n\n"
                    "| model | nodes | build ms | update ms (whole map) | build / infinite | update / infinite |\n"
                    "|---|---|---|---|---|---|\n", g_tcost_scene);
        for (i = 0; i < g_ntcost; ++i) {
            const thick_cost *c = &g_tcost[i], *inf = c;
            for (k = 0; k < g_ntcost; ++k)
                if (g_tcost[k].bits == c->bits && !strcmp(g_tcost[k].model, "infinite")) inf = &g_tcost[k];
            fprintf(md, "| %s | %u-bit | %.3f | %.3f | %.2f | %.2f |\n", c->model, c->bits, c->build_ms, c->update_ms,
                    c->build_ms / inf->build_ms, c->update_ms / inf->update_ms);
        }
    }
    if (g_nthick) {
        fprintf(md, "\n## What thickness costs the walk\n\nNode tests per ray (bench/visits.c, 16-bit nodes, one ray at "
                    "a time), each ray traced with the back-map tree and with the infinite tree of the same depth. On the "
                    "rays both answer alike the two counts are equal, ray by ray (the benchmark fails otherwise); the "
                    "others pass behind an object and go on. So thick / infinite node tests, the last column, bound "
                    "how fast a thick walk can be against the infinite one on the same rays "
                    "([docs/PERFORMANCE.md](../docs/PERFORMANCE.md#what-limits-the-walk)).\n\n");
        fprintf(md, "| scene | rays | answered alike | their tests, thick / infinite | the others' | all: infinite / thick |\n"
                    "|---|---|---|---|---|---|\n");
        for (i = 0; i < g_nthick; ++i) {
            const double *v = g_thick[i].v, a = v[0] / 100.0;
            const double all_thick = a * v[1] + (1.0 - a) * v[3], all_inf = a * v[2] + (1.0 - a) * v[4];
            fprintf(md, "| %s | %s | %.1f%% | %.2f / %.2f | %.2f / %.2f | %.2f |\n", g_thick[i].scene, g_thick[i].set, v[0],
                    v[1], v[2], v[3], v[4], all_thick > 0.0 ? all_inf / all_thick : 1.0);
        }
    }
    write_waves(md);
    write_waves_tsv(o->out_dir);
    write_wave_dominance(md);
    (void)nstab;
    fclose(md);
    fclose(dat);
}

/* ---- the chart: speed against accuracy, one point per method, from DIR/points.dat ---- */
typedef struct chart_point {
    char method[64], device[16];
    double mrays, right;
    int exact;
} chart_point;

#define CHART_MAX 64

/* DIR/points.dat ("name" device mrays_per_s right_pct exact): how many, -1 without the file */
static int chart_read_points(const char *dir, chart_point *p, int max)
{
    char path[512], line[256];
    FILE *f;
    int n = 0;
    snprintf(path, sizeof path, "%s/points.dat", dir);
    if (!(f = fopen(path, "r"))) return -1;
    while (n < max && fgets(line, sizeof line, f))
        if (line[0] == '"' && sscanf(line, "\"%63[^\"]\" %15s %lf %lf %d", p[n].method, p[n].device, &p[n].mrays,
                                     &p[n].right, &p[n].exact) == 5)
            ++n;
    fclose(f);
    return n;
}

/* A colour per family of methods, so that a family reads as one. */
static const char *chart_colour(const char *method)
{
    static const char *const fam[][2] = {{"linear_rt", "#1f77b4"}, {"embree", "#9467bd"}, {"rq ", "#17becf"},
                                         {"march", "#d62728"},     {"dda", "#8c564b"},    {"hiz", "#ff7f0e"}};
    size_t k;
    for (k = 0; k < sizeof fam / sizeof fam[0]; ++k)
        if (!strncmp(method, fam[k][0], strlen(fam[k][0]))) return fam[k][1];
    return "#555555";
}

/* text inside a gnuplot double-quoted string: \\, \" and \n escaped */
static void chart_text(FILE *gp, const char *text)
{
    for (; *text; ++text) {
        if (*text == '\n') fputs("\\n", gp);
        else {
            if (*text == '"' || *text == '\\') fputc('\\', gp);
            fputc(*text, gp);
        }
    }
}

static int chart_by_speed_desc(const void *a, const void *b)
{
    const chart_point *p = (const chart_point *)a, *q = (const chart_point *)b;
    if (p->mrays != q->mrays) return p->mrays < q->mrays ? 1 : -1;
    return p->right < q->right ? 1 : p->right > q->right ? -1 : 0;
}

/* One panel per device, for the infinite layer's scenes (top row) and for
   the yard with thickness (bottom row). No labels on the points (near 100% they crowd into
   each other): a key names every point, with its numbers. Colour says the
   family, the point type the member; filled small and open large points
   alternate within a family, so two methods on one spot (linear_rt's 16-
   and 8-bit nodes often are) show as a dot in a ring. The Pareto front (no
   faster point of the panel is as accurate) is a dashed line. 0 when drawn. */
static int chart(const options *o, const char *machine)
{
    static const int types[] = {7, 6, 5, 4, 9, 8, 13, 12, 15, 14, 11, 10};
    char cmd[2048];
    chart_point pts[CHART_MAX], panel[CHART_MAX], front[CHART_MAX], curve[CHART_MAX];
    FILE *gp;
    double lowest = 100.0;
    int np, i, k, d;
    np = chart_read_points(o->out_dir, pts, CHART_MAX);
    if (np < 0) {
        printf("chart: skipped: no %s/points.dat\n", o->out_dir);
        return 1;
    }
    if (system("command -v gnuplot >/dev/null 2>&1") != 0) {
        printf("chart: skipped: gnuplot is not installed (Debian: gnuplot-nox)\n");
        return 1;
    }
    for (i = 0; i < np; ++i)
        if (pts[i].right < lowest) lowest = pts[i].right;
    snprintf(cmd, sizeof cmd, "gnuplot > %s/gnuplot.log 2>&1", o->out_dir);
    gp = popen(cmd, "w");
    if (!gp) return 1;
    fprintf(gp, "set terminal pngcairo size 1800,1600 font 'sans,11'\n"
                "set output '%s/speed_vs_accuracy.png'\n"
                "set termoption noenhanced\n"
                "set multiplot layout 2,2 title \"Screen-space rays: speed against accuracy, reflection rays and "
                "random segments\\n",
            o->out_dir);
    chart_text(gp, machine);
    fprintf(gp, "\"\n");
    fprintf(gp, "set xlabel 'trace speed (million rays per second, log scale)'\n"
                "set ylabel 'rays answered right, by the exact reference (%%)'\n"
                "set logscale x\nset grid\nset yrange [%.1f:101]\n"
                "set offsets graph 0.1, graph 0.1, 0, 0\n"
                "set key outside right top vertical Left reverse samplen 1 spacing 1.3 width 1 box font 'sans,10'\n",
            lowest > 5.0 ? lowest - 5.0 : 0.0);
    for (d = 0; d < 4; ++d) {
        static const char *const devs[4] = {"cpu", "vulkan", "cpu_thick", "vulkan_thick"};
        static const char *const titles[4] = {
            "every scene of the infinite layer, on the CPU", "every scene of the infinite layer, on Vulkan (lavapipe here: the same CPU cores)",
            "thickness (scene yard back: back faces), on the CPU", "thickness (scene yard back), on Vulkan"};
        const char *dev = devs[d];
        int n = 0, nf = 0, e;
        double best = -1.0;
        /* this device's points, the exact methods first */
        for (e = 1; e >= 0; --e)
            for (i = 0; i < np; ++i)
                if (!strcmp(pts[i].device, dev) && (pts[i].exact != 0) == e) panel[n++] = pts[i];
        memcpy(front, panel, sizeof(chart_point) * (size_t)n);
        qsort(front, (size_t)n, sizeof(chart_point), chart_by_speed_desc);
        for (i = 0, k = 0; i < n; ++i)
            if (k == 0 || front[i].right > best) {
                best = front[i].right;
                front[k++] = front[i];
            }
        nf = k;
        fprintf(gp, "$P%d << EOD\n", d);
        for (i = 0; i < n; ++i) fprintf(gp, "%.6g %.6g\n", panel[i].mrays, panel[i].right);
        fprintf(gp, "EOD\n$F%d << EOD\n", d);
        for (i = nf - 1; i >= 0; --i) fprintf(gp, "%.6g %.6g\n", front[i].mrays, front[i].right);
        /* linear_rt's curve: the front of its 16-bit walk's points (exact, each step budget, each
           with a finish), by speed: each point more right than every faster one */
        fprintf(gp, "EOD\n$L%d << EOD\n", d);
        for (i = nf = 0; i < n; ++i)
            if (!strncmp(panel[i].method, "linear_rt", 9) && strstr(panel[i].method, " 16")) curve[nf++] = panel[i];
        qsort(curve, (size_t)nf, sizeof(chart_point), chart_by_speed_desc);
        for (i = k = 0; i < nf; ++i)
            if (k == 0 || curve[i].right > curve[k - 1].right) curve[k++] = curve[i];
        nf = k;
        for (i = 0; i < nf; ++i) fprintf(gp, "%.6g %.6g\n", curve[i].mrays, curve[i].right);
        fprintf(gp, "EOD\nset title '%s'\n", titles[d]);
        if (!n) { /* nothing ran on this device: an empty panel that says so */
            fprintf(gp, "set xrange [0.1:10]\nplot 1/0 lc rgb '#ffffff' title 'no method ran here'\nset autoscale x\n");
            continue;
        }
        fprintf(gp, "plot $F%d using 1:2 with lines lc rgb '#888888' lw 2 dt 2 title 'Pareto front'", d);
        if (nf > 1)
            fprintf(gp, ", \\\n  $L%d using 1:2 with lines lc rgb '%s' lw 2 title 'linear_rt 16: its front (exact, budgets 4 to 32, with and without a finish)'", d,
                    chart_colour("linear_rt"));
        for (i = 0; i < n; ++i) {
            int member = 0;
            if (i == 0 || panel[i].exact != panel[i - 1].exact)
                fprintf(gp, ", \\\n  keyentry with lines lc rgb '#ffffff' title '%s'",
                        panel[i].exact ? "exact methods:" : "approximate methods:");
            for (k = 0; k < i; ++k) member += chart_colour(panel[k].method) == chart_colour(panel[i].method);
            fprintf(gp, ", \\\n  $P%d every ::%d::%d using 1:2 with points pt %d ps %.1f lc rgb '%s' title \"", d, i,
                    i, types[member % (int)(sizeof types / sizeof types[0])], member % 2 ? 2.6 : 1.5,
                    chart_colour(panel[i].method));
            chart_text(gp, panel[i].method);
            fprintf(gp, "  (%.2f M/s, %.1f%%)\"", panel[i].mrays, panel[i].right);
        }
        fprintf(gp, "\n");
    }
    fprintf(gp, "unset multiplot\n");
    if (pclose(gp) != 0) {
        printf("chart: gnuplot failed, see %s/gnuplot.log\n", o->out_dir);
        return 1;
    }
    printf("chart: %s/speed_vs_accuracy.png\n", o->out_dir);
    return 0;
}

static void usage(void)
{
    printf("usage: bench [--size N] [--threads T] [--runs R] [--sample S] [--quick] [--only TEXT] [--only-counts] [--out DIR]\n"
           "             [--weights FILE]   (make gpu-stats' weights per step: the wave estimate; none without it)\n"
           "             [--dump-steps DIR] (the exact cell walk's steps per ray of each set: bench/compaction.py)\n"
           "             [--depth FILE [--format png|pfm|raw] [--width W --height H] [--reversed]\n"
           "                          [--fov DEG --near N --far F]]\n"
           "       bench --chart-only [--out DIR]   (redraw DIR/speed_vs_accuracy.png from DIR/points.dat)\n"
           "  --only-counts: no method timed; each set's steps per ray and per wave of 32 and 64 as the Vulkan\n"
           "                 kernels take them (counted on the CPU), the tables on stdout and in DIR/waves.md and .tsv\n"
           "  --depth FILE: the file's reflection, ao and shadow rays are built from view-space positions and\n"
           "  normals through a perspective camera, as the examples build them: vertical field of view DEG\n"
           "  (default 60), near and far planes N and F (default 0.1 and 60, the examples' defaults)\n");
}

/* a number in [lo, hi] (strtod's syntax, nothing after it) */
static int parse_number(const char *s, double lo, double hi, float *out)
{
    char *end;
    double x = strtod(s, &end);
    if (end == s || *end || !(x >= lo && x <= hi)) return 0;
    *out = (float)x;
    return 1;
}

int main(int argc, char **argv)
{
    options o;
    bench_method m[64];
    const char *skipped[64];
    char done[sizeof m / sizeof m[0]]; /* methods of this scene already run (device_group) */
    char machine[512], whybuf[64][160];
    scene scenes[5];
    ray_set sets[SET_COUNT];
    stab_case stab[STAB_CASES];
    lrt_hit *hits;
    int nm = 0, ns = 0, k, s, a, g, nstab, nsets, count_walk = 0, first;
    long cores = sysconf(_SC_NPROCESSORS_ONLN);

    memset(&o, 0, sizeof o);
    o.size = 1024;
    o.threads = cores > 0 ? (int)cores : 1;
    o.runs = 5;
    o.sample = 20000;
    o.out_dir = "build/bench-results"; /* committed results change only by make bench-publish */
    o.fov_deg = 60.0f; /* examples/example.h's example_default_options */
    o.near_z = 0.1f;
    o.far_z = 60.0f;
    for (a = 1; a < argc; ++a) {
        const char *v = a + 1 < argc ? argv[a + 1] : NULL;
        if (!strcmp(argv[a], "--size") && v) o.size = (uint32_t)atoi(argv[++a]);
        else if (!strcmp(argv[a], "--threads") && v) o.threads = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--runs") && v) o.runs = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--sample") && v) o.sample = (size_t)atol(argv[++a]);
        else if (!strcmp(argv[a], "--quick")) o.quick = 1;
        else if (!strcmp(argv[a], "--chart-only")) o.chart_only = 1;
        else if (!strcmp(argv[a], "--only-counts")) o.only_counts = 1;
        else if (!strcmp(argv[a], "--weights") && v) o.weights = argv[++a];
        else if (!strcmp(argv[a], "--dump-steps") && v) g_steps_dir = argv[++a];
        else if (!strcmp(argv[a], "--only") && v) o.only = argv[++a];
        else if (!strcmp(argv[a], "--out") && v) o.out_dir = argv[++a];
        else if (!strcmp(argv[a], "--depth") && v) o.depth_file = argv[++a];
        else if (!strcmp(argv[a], "--format") && v) o.format = argv[++a];
        else if (!strcmp(argv[a], "--width") && v) o.file_w = (uint32_t)atoi(argv[++a]);
        else if (!strcmp(argv[a], "--height") && v) o.file_h = (uint32_t)atoi(argv[++a]);
        else if (!strcmp(argv[a], "--reversed")) o.reversed = 1;
        else if ((!strcmp(argv[a], "--fov") || !strcmp(argv[a], "--near") || !strcmp(argv[a], "--far")) && v) {
            const char *k = argv[a++];
            int good = !strcmp(k, "--fov")    ? parse_number(v, 1.0, 179.0, &o.fov_deg)
                       : !strcmp(k, "--near") ? parse_number(v, 1e-6, 1e9, &o.near_z)
                                              : parse_number(v, 1e-6, 1e12, &o.far_z);
            if (!good) {
                fprintf(stderr, "bench: %s: bad value '%s'\n", k, v);
                return 2;
            }
            o.camera_given = 1;
        } else {
            usage();
            return 2;
        }
    }
    if (o.camera_given && !o.depth_file) {
        fprintf(stderr, "bench: --fov, --near and --far describe a --depth FILE; the embedded scenes have their own\n");
        return 2;
    }
    if (!(o.near_z < o.far_z)) {
        fprintf(stderr, "bench: --near must be less than --far\n");
        return 2;
    }
    if (o.chart_only) { /* the run's description is results.md's first line of text */
        char path[512], line[512];
        FILE *f;
        snprintf(path, sizeof path, "%s/results.md", o.out_dir);
        machine[0] = '\0';
        if ((f = fopen(path, "r")) != NULL) {
            while (fgets(line, sizeof line, f))
                if (line[0] != '#' && line[0] != '\n') {
                    line[strcspn(line, "\n")] = '\0';
                    snprintf(machine, sizeof machine, "%s", line);
                    break;
                }
            fclose(f);
        }
        return chart(&o, machine);
    }
    if (o.quick) {
        o.size = 128;
        o.runs = 1;
        o.sample = 2000;
    }
    if (o.runs < 1 || o.runs > 15 || o.threads < 1 || o.size < 1 || o.size > LINEAR_RT_MAX_DIM || o.sample < 1) {
        usage();
        return 2;
    }
    if (o.weights) {
        if (load_weights(o.weights, "navi31")) {
            fprintf(stderr, "bench: %s: no weights for every method (make gpu-stats writes them)\n", o.weights);
            return 2;
        }
        g_have_weights = 1;
    }
#ifdef BENCH_WITH_NATIVE_TWIN
    { /* make bench-plain-vs-native: each CPU method of linear_rt, then its -march=native twin */
        bench_method plain[2], native[2];
        int np = bench_add_linear_rt_cpu(plain, 2), nn = bench_add_linear_rt_cpu_native(native, 2), i;
        for (i = 0; i < np; ++i) {
            m[nm++] = plain[i];
            if (i < nn) m[nm++] = native[i];
        }
    }
#else
    nm += bench_add_linear_rt_cpu(m + nm, 64 - nm);
#endif
    nm += bench_add_linear_rt_vulkan(m + nm, 64 - nm);
    nm += bench_add_embree(m + nm, 64 - nm);
    nm += bench_add_march_cpu(m + nm, 64 - nm);
    nm += bench_add_vulkan_peers(m + nm, 64 - nm);

    if (o.depth_file) {
        if (scene_load(&scenes[0], &o)) return 1;
        ns = 1;
    } else {
        for (k = 0; k < (o.quick ? 2 : 5); ++k) scene_make(&scenes[k], k, o.size, o.size);
        ns = o.quick ? 2 : 5;
    }
    if (o.depth_file)
        snprintf(machine, sizeof machine,
                 "%ld-core machine, %d CPU threads per CPU method, %s %ux%u (fov %g, near %g, far %g), %d timed runs "
                 "(median), linear_rt's CPU walk %s",
                 cores, o.threads, o.depth_file, scenes[0].s.width, scenes[0].s.height, (double)o.fov_deg,
                 (double)o.near_z, (double)o.far_z, o.runs, lrt_cpu_path());
    else
        snprintf(machine, sizeof machine,
                 "%ld-core machine, %d CPU threads per CPU method, size %u, %d timed runs (median), linear_rt's CPU walk %s",
                 cores, o.threads, o.size, o.runs, lrt_cpu_path());
    printf("linear_rt benchmark: %s\n", machine);
    printf("stability cases and reference answers ...\n");
    fflush(stdout);
    nstab = make_stability(stab, &o);
    {
        size_t maxrays = 0;
        for (k = 0; k < ns; ++k)
            if ((size_t)scenes[k].s.width * scenes[k].s.height > maxrays) maxrays = (size_t)scenes[k].s.width * scenes[k].s.height;
        for (k = 0; k < nstab; ++k)
            if (stab[k].set.r.count > maxrays) maxrays = stab[k].set.r.count;
        hits = (lrt_hit *)calloc(maxrays, sizeof(lrt_hit));
        if (!hits) return 2;
    }

    for (k = 0; k < nm; ++k) { /* open every method once, at the largest size */
        skipped[k] = NULL;
        if (o.only_counts) {
            skipped[k] = "not asked for (--only-counts)";
            continue;
        }
        if (o.only && !strstr(m[k].name, o.only)) {
            skipped[k] = "not asked for (--only)";
            continue;
        }
        if (!m[k].open) skipped[k] = "built without its package (see the Makefile's bench dependencies)";
        else if (m[k].open(&m[k], o.size, o.size, o.threads, whybuf[k], sizeof whybuf[k])) skipped[k] = whybuf[k];
        if (skipped[k]) printf("skipped: %-22s %s\n", m[k].name, skipped[k]);
        else if (strncmp(m[k].name, "linear_rt cpu", 13) == 0) count_walk = 1; /* and its node tests, counted */
    }
    if (count_walk) { /* the tree under each thickness model: the scene with a back map, else the first */
        int t = 0;
        for (k = 0; k < ns; ++k)
            if (scenes[k].back) t = k;
        printf("build and update by thickness model, scene %s ...\n", scenes[t].s.name);
        time_thickness_models(&scenes[t], &o);
        for (k = 0; k < g_ntcost; ++k)
            printf("  %-14s %2u-bit  build %8.3f ms  update %8.3f ms\n", g_tcost[k].model, g_tcost[k].bits, g_tcost[k].build_ms,
                   g_tcost[k].update_ms);
    }
    for (s = 0; s < ns; ++s) {
        double t0 = bench_now_ms();
        printf("scene %s %ux%u: reference answers ...", scenes[s].s.name, scenes[s].s.width, scenes[s].s.height);
        fflush(stdout);
        nsets = 0;
        for (k = 0; k < SET_COUNT; ++k) {
            make_set(&sets[nsets], &scenes[s], k, o.sample);
            if (sets[nsets].r.count) ++nsets;
            else set_free(&sets[nsets]); /* a camera set of a map with no texel for it: nothing to time */
        }
        printf(" %.1f s\n", (bench_now_ms() - t0) / 1e3);
        if (scenes[s].has_camera) {
            size_t texels = (size_t)scenes[s].s.width * scenes[s].s.height;
            printf("  rays per set (a camera set has none for the sky, nor a shadow ray for a surface facing away):");
            for (k = 0; k < nsets; ++k)
                printf(" %s %zu (%.1f%%)", sets[k].r.name, sets[k].r.count, pct(sets[k].r.count, texels));
            printf("\n");
        }
        memset(done, 0, sizeof done);
        first = g_nres;
        for (k = 0; k < nm; ++k) {
            bench_method *group[GROUP_MAX];
            int j;
            if (skipped[k] || done[k]) continue;
            g = device_group(m, skipped, k, nm, done, group);
            printf("  %s: %d method%s, each set's runs in turn\n", m[k].device, g, g > 1 ? "s" : "");
            fflush(stdout);
            run_methods(group, g, &scenes[s], sets, nsets, &o, hits);
            for (j = 0; j < g; ++j) {
                const result *r = find(group[j]->name, scenes[s].s.name, "segments");
                const result *p = find(group[j]->name, scenes[s].s.name, "primary");
                printf("  %-22s", group[j]->name);
                if (r && p && r->ok && p->ok)
                    printf(" primary %8.2f M/s %6.2f%% right | segments %8.2f M/s %6.2f%% right | update %.2f ms\n",
                           mrays(p), pct(p->sc.right, p->sc.n), mrays(r), pct(r->sc.right, r->sc.n), p->update_ms);
                else printf(" failed: %s\n", r && !r->ok ? r->why : p && !p->ok ? p->why : g_nres ? g_res[g_nres - 1].why : "?");
            }
        }
        order_results(first, m, nm);
        if (count_walk) count_visits(&scenes[s], sets, nsets);
        t0 = bench_now_ms();
        count_waves(&scenes[s], sets, nsets);
        printf("  what a wave pays: counted in %.1f s\n", (bench_now_ms() - t0) / 1e3);
        for (k = 0; k < nsets; ++k) set_free(&sets[k]);
        if (!o.only_counts) write_csv(&o);
    }
    if (o.only_counts) { /* the counts alone: the tables on stdout and in DIR/waves.md */
        char path[600];
        FILE *f;
        write_waves(stdout);
        make_dirs(o.out_dir);
        write_waves_tsv(o.out_dir);
        snprintf(path, sizeof path, "%s/waves.md", o.out_dir);
        if ((f = fopen(path, "w"))) {
            fprintf(f, "# What a wave pays: %s\n", machine);
            write_waves(f);
            fclose(f);
            printf("wrote %s\n", path);
        }
        for (s = 0; s < ns; ++s) scene_free(&scenes[s]);
        free(hits);
        return 0;
    }
    printf("stability suite:\n");
    for (a = 0; a < nstab; ++a) {
        char label[64];
        snprintf(label, sizeof label, "stab:%s", stab[a].sc.s.name);
        stab[a].sc.s.name = strdup(label);
        memset(done, 0, sizeof done);
        first = g_nres;
        for (k = 0; k < nm; ++k) {
            bench_method *group[GROUP_MAX];
            if (skipped[k] || done[k]) continue;
            g = device_group(m, skipped, k, nm, done, group);
            run_methods(group, g, &stab[a].sc, &stab[a].set, 1, &o, hits);
        }
        order_results(first, m, nm);
        if (count_walk) count_visits(&stab[a].sc, &stab[a].set, 1);
        {
            int j;
            printf("  %-22s", stab[a].name);
            for (j = 0; j < g_nres; ++j)
                if (!strcmp(g_res[j].set, stab[a].name) && g_res[j].ok && g_res[j].exact && g_res[j].sc.right != g_res[j].sc.n)
                    printf(" FAIL(%s)", g_res[j].method);
            printf("\n");
        }
    }
    write_outputs(&o, m, nm, skipped, machine, nstab, &scenes[0]);
    (void)chart(&o, machine); /* says itself why it could not */
    for (k = 0; k < nm; ++k)
        if (!skipped[k] && m[k].close) m[k].close(&m[k]);
    for (s = 0; s < ns; ++s) scene_free(&scenes[s]);
    free(hits);
    printf("wrote %s/results.csv and %s/results.md\n", o.out_dir, o.out_dir);
    {   /* exact methods must be right on every scored ray */
        int bad = 0;
        for (k = 0; k < g_nvisits; ++k) /* and a camera ray is one texel test (the count's own check) */
            if (strcmp(g_visits[k].set, "primary") == 0 &&
                (g_visits[k].per_ray[0] != 1.0 || g_visits[k].per_ray[1] != 0.0 || g_visits[k].per_ray[2] != 0.0)) {
                printf("NODE TESTS WRONG: %s primary rays, %u-bit nodes: %.3f / %.3f / %.3f per ray, not 1 / 0 / 0\n",
                       g_visits[k].scene, g_visits[k].node_bits, g_visits[k].per_ray[0], g_visits[k].per_ray[1],
                       g_visits[k].per_ray[2]);
                bad = 1;
            }
        for (k = 0; k < g_nthick; ++k) /* thickness culls nothing the infinite walk visits on a ray answered alike */
            if (g_thick[k].v[5] != 0.0) {
                printf("NODE TESTS WRONG: %s %s, %.0f rays answered alike by the thick and infinite trees with other node tests\n",
                       g_thick[k].scene, g_thick[k].set, g_thick[k].v[5]);
                bad = 1;
            }
        for (k = 0; k < g_nres; ++k)
            if (g_res[k].ok && g_res[k].exact && g_res[k].sc.right != g_res[k].sc.n) {
                printf("EXACT METHOD WRONG: %s on %s / %s: %zu of %zu right\n", g_res[k].method, g_res[k].scene,
                       g_res[k].set, g_res[k].sc.right, g_res[k].sc.n);
                bad = 1;
            }
        return bad;
    }
}
