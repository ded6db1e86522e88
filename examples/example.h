/* example.h - what ssr.c, ao.c, shadows.c and the demo share, so that each
   of them reads as its own effect and nothing else:
   - the frame: depth, colour and camera, from the embedded scene
     (examples/scene.h) or from the user's files (examples/depth_file.h);
   - per texel: the view-space position and normal rebuilt from depth, and
     how far a ray starting there is lifted off its own surface;
   - a parallel-for over rows with a progress line, PNG output, timing.

   Include it in ONE .c file of a program (it compiles linear_rt.h's
   implementation, stb_image and stb_image_write). C99, pthreads. */
#ifndef EXAMPLE_H
#define EXAMPLE_H

#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#define LINEAR_RT_IMPLEMENTATION
#include "../linear_rt.h"
#include "depth_file.h"
#include "scene.h"
#include "surface.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h> /* isatty: the progress line only on a terminal */
#include <time.h>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

#if defined(__GNUC__)
#define EXAMPLE_FN static __attribute__((unused))
#else
#define EXAMPLE_FN static
#endif

/* Exit codes of every example: 0 done, 1 failed while running, 2 bad
   arguments or a file that cannot be used (one line on stderr says which). */
enum { EXAMPLE_EXIT_OK = 0, EXAMPLE_EXIT_FAILED = 1, EXAMPLE_EXIT_BAD_INPUT = 2 };

typedef struct example_options {
    uint32_t size;                /* embedded scene: size x size texels */
    const char *depth_file;       /* or the user's depth (PNG 8/16, PFM, raw float) */
    const char *color_file;       /* and optional colour (PNG of the same size) */
    uint32_t raw_width, raw_height; /* raw float depth has no header */
    float fov_deg, near_z, far_z; /* the user's perspective projection */
    int reversed_z;
    const char *out_dir;          /* pictures go here */
    int threads;
    /* --thickness T (metres, view space: LRT_THICKNESS_CONSTANT), K% (a
       share of the view distance: LRT_THICKNESS_RELATIVE) or back (the
       embedded scene's back-face depth: a back map); 0: infinite, the default */
    float thickness;
    int thickness_relative;
    int thickness_back;
} example_options;

typedef struct example_frame {
    uint32_t w, h;
    float *depth;        /* w * h, 0 near, row 0 at the top */
    uint8_t *rgb;        /* w * h * 3 */
    lrt_camera camera;
    float view_from_world[9]; /* rotation of the embedded scene's camera (identity for files) */
    float *pos;          /* w * h * 3: view-space position of each texel's centre */
    float *nrm;          /* w * h * 3: view-space normal facing the eye; 0 0 0 for the sky */
    float *lift;         /* w * h: screen-space z by which a ray from this texel is lifted */
    float *back;         /* w * h back depths with --thickness back, else NULL */
    lrt_depth lrt[2];    /* the depth, then its back map (lrt[0].back = &lrt[1] with one) */
    lrt_build_options options; /* what bvh was built with: its thickness model */
    lrt_bvh bvh;
} example_frame;

EXAMPLE_FN double example_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

EXAMPLE_FN void example_default_options(example_options *o)
{
    memset(o, 0, sizeof *o);
    o->size = 1024;
    o->fov_deg = 60.0f;
    o->near_z = 0.1f;
    o->far_z = 60.0f;
    o->out_dir = "out";
    o->threads = 2;
}

EXAMPLE_FN const char *example_options_usage(void)
{
    return "[--size N] [--depth FILE [--color FILE] [--width W --height H] [--fov DEG --near N --far F] "
           "[--reversed-z]] [--thickness METRES|K%|back] [--out DIR] [--threads T]";
}

static int example__number(const char *s, double lo, double hi, double *v)
{
    char *end;
    double x = strtod(s, &end);
    if (end == s || *end || !(x >= lo && x <= hi)) return 0;
    *v = x;
    return 1;
}

/* Parses one shared option at argv[*a]; 1 if it was one (and advances *a),
   0 if it is not a shared option, -1 (after a one-line message) if it is one
   with a bad value. */
EXAMPLE_FN int example_parse_option(example_options *o, int argc, char **argv, int *a)
{
    const char *k = argv[*a], *v = *a + 1 < argc ? argv[*a + 1] : NULL;
    double x;
    int is_value_option = !strcmp(k, "--size") || !strcmp(k, "--depth") || !strcmp(k, "--color") ||
                          !strcmp(k, "--width") || !strcmp(k, "--height") || !strcmp(k, "--fov") ||
                          !strcmp(k, "--near") || !strcmp(k, "--far") || !strcmp(k, "--out") ||
                          !strcmp(k, "--threads") || !strcmp(k, "--thickness");
    if (!strcmp(k, "--reversed-z")) {
        o->reversed_z = 1;
        return 1;
    }
    if (!is_value_option) return 0;
    if (!v) {
        fprintf(stderr, "%s needs a value\n", k);
        return -1;
    }
    ++*a;
    if (!strcmp(k, "--depth")) o->depth_file = v;
    else if (!strcmp(k, "--color")) o->color_file = v;
    else if (!strcmp(k, "--out")) o->out_dir = v;
    else if (!strcmp(k, "--size") && example__number(v, 1, LINEAR_RT_MAX_DIM, &x)) o->size = (uint32_t)x;
    else if (!strcmp(k, "--width") && example__number(v, 1, LINEAR_RT_MAX_DIM, &x)) o->raw_width = (uint32_t)x;
    else if (!strcmp(k, "--height") && example__number(v, 1, LINEAR_RT_MAX_DIM, &x)) o->raw_height = (uint32_t)x;
    else if (!strcmp(k, "--fov") && example__number(v, 1, 179, &x)) o->fov_deg = (float)x;
    else if (!strcmp(k, "--near") && example__number(v, 1e-6, 1e9, &x)) o->near_z = (float)x;
    else if (!strcmp(k, "--far") && example__number(v, 1e-6, 1e12, &x)) o->far_z = (float)x;
    else if (!strcmp(k, "--threads") && example__number(v, 1, 64, &x)) o->threads = (int)x;
    else if (!strcmp(k, "--thickness") && !strcmp(v, "back")) o->thickness_back = 1;
    else if (!strcmp(k, "--thickness") && v[0] && v[strlen(v) - 1] == '%') {
        char share[32];
        size_t len = strlen(v) - 1;
        if (len >= sizeof share) len = sizeof share - 1;
        memcpy(share, v, len);
        share[len] = 0;
        if (!example__number(share, 1e-4, 1e6, &x)) {
            fprintf(stderr, "%s: bad value '%s'\n", k, v);
            return -1;
        }
        o->thickness = (float)(x / 100.0);
        o->thickness_relative = 1;
    } else if (!strcmp(k, "--thickness") && example__number(v, 1e-6, 1e9, &x)) o->thickness = (float)x;
    else {
        fprintf(stderr, "%s: bad value '%s'\n", k, v);
        return -1;
    }
    return 1;
}

/* The command line of an example: the shared options, and optionally one
   positive float of its own (name, e.g. "--radius", into *value). Returns
   EXAMPLE_EXIT_OK, or EXAMPLE_EXIT_BAD_INPUT after a one-line message. */
EXAMPLE_FN int example_parse_args(example_options *o, int argc, char **argv, const char *name, float *value)
{
    int a;
    example_default_options(o);
    for (a = 1; a < argc; ++a) {
        int p = example_parse_option(o, argc, argv, &a);
        if (p == 1) continue;
        if (p == 0 && name && !strcmp(argv[a], name) && a + 1 < argc) {
            double x;
            if (!example__number(argv[a + 1], 1e-9, 1e9, &x)) {
                fprintf(stderr, "%s: bad value '%s'\n", name, argv[a + 1]);
                return EXAMPLE_EXIT_BAD_INPUT;
            }
            *value = (float)x;
            ++a;
            continue;
        }
        if (p == 0)
            fprintf(stderr, "usage: %s %s%s%s%s\n", argv[0], example_options_usage(), name ? " [" : "", name ? name : "",
                    name ? " X]" : "");
        return EXAMPLE_EXIT_BAD_INPUT;
    }
    return EXAMPLE_EXIT_OK;
}

/* ---- rows in parallel, with a progress line past one second ------------------- */
/* The line is redrawn in place with '\r', so it is drawn only when stderr is a
   terminal: in a log it would run into the lines around it. */
typedef void (*example_rows_fn)(void *ctx, uint32_t row);

typedef struct example__pool {
    example_rows_fn fn;
    void *ctx;
    uint32_t rows, next, done;
    const char *what;
    double start, last_print;
    int printed;
    pthread_mutex_t lock;
} example__pool;

static void *example__worker(void *arg)
{
    example__pool *p = (example__pool *)arg;
    for (;;) {
        uint32_t first, end, r;
        double now;
        pthread_mutex_lock(&p->lock);
        first = p->next;
        end = first + 8 < p->rows ? first + 8 : p->rows;
        p->next = end;
        now = example_now_ms();
        if (p->what && now - p->start > 1000.0 && now - p->last_print > 250.0) {
            fprintf(stderr, "\r  %s: %3u%%", p->what, (unsigned)(100.0 * p->done / p->rows));
            p->last_print = now;
            p->printed = 1;
        }
        pthread_mutex_unlock(&p->lock);
        if (first >= end) return NULL;
        for (r = first; r < end; ++r) p->fn(p->ctx, r);
        pthread_mutex_lock(&p->lock);
        p->done += end - first;
        pthread_mutex_unlock(&p->lock);
    }
}

/* fn(ctx, row) for every row in [0, rows) on `threads` threads; `what`
   names the work for the progress line (NULL: none). */
EXAMPLE_FN void example_parallel_rows(uint32_t rows, int threads, const char *what, example_rows_fn fn, void *ctx)
{
    example__pool p;
    pthread_t t[64];
    int k, started = 0;
    memset(&p, 0, sizeof p);
    p.fn = fn;
    p.ctx = ctx;
    p.rows = rows;
    p.what = what;
    p.start = p.last_print = example_now_ms();
    if (!isatty(fileno(stderr))) p.what = NULL;
    else fflush(stdout); /* the heading above the line comes first */
    pthread_mutex_init(&p.lock, NULL);
    if (threads > 64) threads = 64;
    for (k = 1; k < threads; ++k)
        if (pthread_create(&t[started], NULL, example__worker, &p) == 0) ++started;
    example__worker(&p);
    for (k = 0; k < started; ++k) pthread_join(t[k], NULL);
    pthread_mutex_destroy(&p.lock);
    if (p.printed) fprintf(stderr, "\r  %s: 100%%\n", what ? what : "");
}

/* ---- the frame ------------------------------------------------------------------- */
/* examples/surface.h, row by row on the frame (example_parallel_rows) */
static void example__positions_row(void *ctx, uint32_t j)
{
    example_frame *f = (example_frame *)ctx;
    surface_positions_row(&f->camera, f->depth, f->w, j, f->pos);
}

static void example__normals_row(void *ctx, uint32_t j)
{
    example_frame *f = (example_frame *)ctx;
    surface_normals_row(f->depth, f->pos, f->w, f->h, j, f->nrm, f->lift);
}

EXAMPLE_FN void example_frame_free(example_frame *f)
{
    lrt_bvh_destroy(&f->bvh);
    free(f->depth);
    free(f->rgb);
    free(f->pos);
    free(f->nrm);
    free(f->lift);
    free(f->back);
    memset(f, 0, sizeof *f);
}

/* Loads or renders the frame, sets up its camera, positions, normals and
   lifts, and builds its BVH. Returns an EXAMPLE_EXIT_* code; on failure one
   line on stderr says why (for a file: "FILE: problem"). */
EXAMPLE_FN int example_frame_load(example_frame *f, const example_options *o)
{
    const float pi = 3.14159265358979f;
    float proj[16];
    char why[512];
    size_t n, k;
    lrt_build_options build;
    lrt_result r;
    memset(f, 0, sizeof *f);
    if (o->depth_file) {
        depth_file_image img;
        if (depth_file_load(o->depth_file, DEPTH_FILE_AUTO, o->reversed_z, o->raw_width, o->raw_height, &img, why,
                            sizeof why)) {
            fprintf(stderr, "%s\n", why);
            return EXAMPLE_EXIT_BAD_INPUT;
        }
        f->w = img.width;
        f->h = img.height;
        f->depth = img.depth;
        n = (size_t)f->w * f->h;
        if (o->color_file) {
            if (color_file_load(o->color_file, f->w, f->h, &f->rgb, why, sizeof why)) {
                fprintf(stderr, "%s\n", why);
                example_frame_free(f);
                return EXAMPLE_EXIT_BAD_INPUT;
            }
        } else { /* no colour: a grey by depth, so that reflections still show shapes */
            f->rgb = (uint8_t *)malloc(n * 3);
            if (f->rgb)
                for (k = 0; k < n; ++k) f->rgb[3 * k] = f->rgb[3 * k + 1] = f->rgb[3 * k + 2] = (uint8_t)(230.0f - 180.0f * f->depth[k]);
        }
        memset(f->view_from_world, 0, sizeof f->view_from_world);
        f->view_from_world[0] = f->view_from_world[4] = f->view_from_world[8] = 1.0f;
        if (!(o->near_z < o->far_z)) {
            fprintf(stderr, "--near must be less than --far\n");
            example_frame_free(f);
            return EXAMPLE_EXIT_BAD_INPUT;
        }
        lrt_perspective(proj, o->fov_deg * pi / 180.0f, (float)f->w / (float)f->h, o->near_z, o->far_z, 0);
    } else {
        scene_camera cam = scene_default_camera();
        f->w = f->h = o->size;
        n = (size_t)f->w * f->h;
        f->depth = (float *)malloc(n * sizeof(float));
        f->rgb = (uint8_t *)malloc(n * 3);
        if (f->depth && f->rgb) scene_render((int)f->w, (int)f->h, &cam, f->depth, f->rgb);
        scene_view_from_world(&cam, f->view_from_world);
        lrt_perspective(proj, cam.fov_y_deg * pi / 180.0f, 1.0f, cam.near_z, cam.far_z, 0);
    }
    f->pos = (float *)malloc(n * 3 * sizeof(float));
    f->nrm = (float *)malloc(n * 3 * sizeof(float));
    f->lift = (float *)malloc(n * sizeof(float));
    if (!f->depth || !f->rgb || !f->pos || !f->nrm || !f->lift) {
        fprintf(stderr, "out of memory for a %ux%u frame\n", f->w, f->h);
        example_frame_free(f);
        return EXAMPLE_EXIT_FAILED;
    }
    /* the depth is already standard Z (reversed input was flipped on load) */
    if ((r = lrt_camera_init(&f->camera, proj, f->w, f->h, 0)) != LRT_SUCCESS) {
        fprintf(stderr, "camera: %s\n", lrt_result_string(r));
        example_frame_free(f);
        return EXAMPLE_EXIT_BAD_INPUT;
    }
    example_parallel_rows(f->h, o->threads, NULL, example__positions_row, f);
    example_parallel_rows(f->h, o->threads, NULL, example__normals_row, f);
    f->lrt[0].data = f->depth;
    f->lrt[0].width = f->w;
    f->lrt[0].height = f->h;
    f->lrt[0].format = LRT_FORMAT_FLOAT32;
    memset(&build, 0, sizeof build);
    if (o->thickness > 0.0f) { /* the library's constant or relative model, from the camera's planes */
        build.thickness = o->thickness_relative ? LRT_THICKNESS_RELATIVE : LRT_THICKNESS_CONSTANT;
        build.thickness_value = o->thickness;
        if (!lrt_camera_planes(&f->camera, &build.near_z, &build.far_z)) {
            fprintf(stderr, "--thickness: the camera is not a perspective one\n");
            example_frame_free(f);
            return EXAMPLE_EXIT_BAD_INPUT;
        }
    } else if (o->thickness_back) {
        if (o->depth_file) {
            fprintf(stderr, "--thickness back: a back-face depth is made for the embedded scene only\n");
            example_frame_free(f);
            return EXAMPLE_EXIT_BAD_INPUT;
        }
        if (!(f->back = (float *)malloc(n * sizeof(float)))) {
            fprintf(stderr, "out of memory for a %ux%u back map\n", f->w, f->h);
            example_frame_free(f);
            return EXAMPLE_EXIT_FAILED;
        }
        {
            scene_camera cam = scene_default_camera();
            scene_render_back((int)f->w, (int)f->h, &cam, f->back);
        }
        f->lrt[1] = f->lrt[0]; /* the same size, format and flags, no back of its own */
        f->lrt[1].data = f->back;
        f->lrt[0].back = &f->lrt[1];
        build.thickness = LRT_THICKNESS_BACK_MAP;
    }
    f->options = build;
    if ((r = lrt_bvh_build(&f->bvh, f->lrt, &build, NULL)) != LRT_SUCCESS) {
        fprintf(stderr, "lrt_bvh_build: %s\n", lrt_result_string(r));
        example_frame_free(f);
        return EXAMPLE_EXIT_FAILED;
    }
    return EXAMPLE_EXIT_OK;
}

/* ---- tracing a batch on threads ----------------------------------------------------- */
typedef struct example__trace_job {
    const example_frame *f;
    const lrt_ray *rays;
    lrt_hit *hits;
    size_t per_row;
    uint32_t flags;
} example__trace_job;

static void example__trace_row(void *ctx, uint32_t row)
{
    example__trace_job *t = (example__trace_job *)ctx;
    size_t first = (size_t)row * t->per_row;
    lrt_trace_range(&t->f->bvh, t->f->lrt, t->rays, t->hits, first, first + t->per_row, t->flags);
}

/* Traces f->h * per_row rays (per_row for each texel row, in row order). */
EXAMPLE_FN void example_trace(const example_frame *f, const lrt_ray *rays, lrt_hit *hits, size_t per_row,
                              uint32_t flags, int threads, const char *what)
{
    example__trace_job t;
    t.f = f;
    t.rays = rays;
    t.hits = hits;
    t.per_row = per_row;
    t.flags = flags;
    example_parallel_rows(f->h, threads, what, example__trace_row, &t);
}

/* What an effect's rays_row(job, j) gets: the frame, the rays to fill (in
   row order, each texel's together) and the effect's one length (the AO
   radius, the shadow length; reflections have none). */
typedef struct example_rays_job {
    const example_frame *f;
    lrt_ray *rays;
    float length;
} example_rays_job;

/* The frame's rays, row by row on `threads` threads: rays_row fills a row's. */
EXAMPLE_FN void example_make_rays(const example_frame *f, lrt_ray *rays, float length, int threads,
                                  example_rows_fn rays_row)
{
    example_rays_job job;
    job.f = f;
    job.rays = rays;
    job.length = length;
    example_parallel_rows(f->h, threads, NULL, rays_row, &job);
}

/* An example's run up to its shading (example_start), freed by example_end. */
typedef struct example_run {
    example_options o;
    example_frame f;
    lrt_ray *rays; /* each texel's rays together, in row order */
    lrt_hit *hits;
    uint8_t *picture; /* for the shading: its bytes a texel */
    double setup_ms, trace_ms;
} example_run;

/* An example's main up to its shading: its options (its own one, `name`
   into *value, the rays' length; NULL: none), the frame, per_texel rays a
   texel made by rays_row and traced (`what`: the progress line), and a
   picture of picture_bytes a texel. EXAMPLE_EXIT_OK, else the exit code. */
EXAMPLE_FN int example_start(example_run *r, int argc, char **argv, const char *name, float *value, size_t per_texel,
                             example_rows_fn rays_row, const char *what, size_t picture_bytes)
{
    size_t n;
    double t0, t1;
    int rc;
    memset(r, 0, sizeof *r);
    if ((rc = example_parse_args(&r->o, argc, argv, name, value)) != EXAMPLE_EXIT_OK) return rc;
    if ((rc = example_frame_load(&r->f, &r->o)) != EXAMPLE_EXIT_OK) return rc;
    n = (size_t)r->f.w * r->f.h * per_texel;
    r->rays = (lrt_ray *)malloc(n * sizeof *r->rays);
    r->hits = (lrt_hit *)malloc(n * sizeof *r->hits);
    r->picture = (uint8_t *)malloc((size_t)r->f.w * r->f.h * picture_bytes);
    if (!r->rays || !r->hits || !r->picture) {
        fprintf(stderr, "out of memory\n");
        return EXAMPLE_EXIT_FAILED;
    }
    t0 = example_now_ms();
    example_make_rays(&r->f, r->rays, value ? *value : 0.0f, r->o.threads, rays_row);
    t1 = example_now_ms();
    example_trace(&r->f, r->rays, r->hits, (size_t)r->f.w * per_texel, 0, r->o.threads, what);
    r->setup_ms = t1 - t0;
    r->trace_ms = example_now_ms() - t1;
    return EXAMPLE_EXIT_OK;
}

EXAMPLE_FN void example_end(example_run *r)
{
    free(r->rays);
    free(r->hits);
    free(r->picture);
    example_frame_free(&r->f);
}

/* ---- pictures --------------------------------------------------------------------------- */
/* Writes DIR/NAME (a PNG of w x h with 1 or 3 channels); 0 on success. */
EXAMPLE_FN int example_write_png(const char *dir, const char *name, uint32_t w, uint32_t h, int channels,
                                 const uint8_t *pixels)
{
    char path[1024];
    mkdir(dir, 0777); /* fails harmlessly when it exists */
    snprintf(path, sizeof path, "%s/%s", dir, name);
    if (!stbi_write_png(path, (int)w, (int)h, channels, pixels, (int)(w * (uint32_t)channels))) {
        fprintf(stderr, "cannot write %s\n", path);
        return 1;
    }
    printf("  wrote %s (%ux%u)\n", path, w, h);
    return 0;
}

/* The depth as a picture: near bright, far dark, sky black. Perspective
   depth crowds near 1, so the grey follows the log of the view distance
   between the frame's nearest and farthest texels. */
EXAMPLE_FN void example_depth_picture(const example_frame *f, uint8_t *grey)
{
    size_t k, n = (size_t)f->w * f->h;
    float zmin = 3e38f, zmax = 0.0f, span;
    for (k = 0; k < n; ++k) {
        float z = -f->pos[3 * k + 2];
        if (f->depth[k] >= 1.0f || !(z > 0.0f)) continue;
        zmin = z < zmin ? z : zmin;
        zmax = z > zmax ? z : zmax;
    }
    span = zmax > zmin ? logf(zmax / zmin) : 1.0f;
    for (k = 0; k < n; ++k) {
        float z = -f->pos[3 * k + 2];
        grey[k] = f->depth[k] >= 1.0f || !(z > 0.0f) ? 0 : (uint8_t)(40.0f + 215.0f * (1.0f - logf(z / zmin) / span) + 0.5f);
    }
}

EXAMPLE_FN uint8_t example_to_byte(float v) { return v <= 0.0f ? 0 : v >= 1.0f ? 255 : (uint8_t)(v * 255.0f + 0.5f); }

/* The sky seen in direction d (view space): the embedded scene's sky colour,
   a little lighter towards the horizon. */
EXAMPLE_FN void example_sky(const example_frame *f, const float d_view[3], float rgb[3])
{
    /* world up in view space is the second row of view_from_world's columns */
    float up[3] = {f->view_from_world[1], f->view_from_world[4], f->view_from_world[7]};
    float d[3] = {d_view[0], d_view[1], d_view[2]}, s;
    surface_normalize(d);
    s = surface_dot(d, up);
    s = s < 0.0f ? 0.0f : s;
    rgb[0] = 0.75f - 0.20f * s;
    rgb[1] = 0.82f - 0.12f * s;
    rgb[2] = 0.97f - 0.02f * s;
}

#endif
