/* shadows.c - contact shadows traced with linear_rt.

   One ray per texel towards a directional light (the sun of the embedded
   scene: low, from the right and behind), SHADOW_LENGTH view-space units
   long, any hit: the texel is in shadow. Shaded with a Lambert term and a
   sky ambient, so the picture shows the shadows where a person expects
   them. Screen-space shadows see only what the depth buffer shows: what
   hides behind a visible surface is solid to them (docs/MODEL.md), so a thin
   pole casts the shadow of a wall that runs from it away from the eye.

   build/shadows [--size N] [--depth FILE ...] [--length L]   writes out/shadows.png */
#include "example.h"

#define SHADOW_LENGTH 0.6f

/* The light direction (towards the light) in view space. */
static void shadows__light(const example_frame *f, float l[3])
{
    const float world[3] = {0.55f, 0.6f, 0.35f}; /* x right, y up, z towards the eye */
    const float *m = f->view_from_world;
    int r;
    for (r = 0; r < 3; ++r) l[r] = m[3 * r] * world[0] + m[3 * r + 1] * world[1] + m[3 * r + 2] * world[2];
    surface_normalize(l);
}

static void shadows__rays_row(void *ctx, uint32_t j)
{
    const example_rays_job *job = (const example_rays_job *)ctx;
    const example_frame *f = job->f;
    float l[3];
    uint32_t i;
    shadows__light(f, l);
    for (i = 0; i < f->w; ++i) {
        size_t k = (size_t)j * f->w + i;
        const float *p = &f->pos[3 * k], *n = &f->nrm[3 * k];
        float to[3];
        /* sky, and surfaces facing away from the light (shadowed by themselves) */
        if (f->depth[k] >= 1.0f || surface_dot(n, l) <= 0.0f) {
            lrt_camera_segment(NULL, NULL, NULL, &job->rays[k]);
            continue;
        }
        to[0] = p[0] + job->length * l[0];
        to[1] = p[1] + job->length * l[1];
        to[2] = p[2] + job->length * l[2];
        lrt_camera_surface_ray(&f->camera, p, n, to, f->lift[k], &job->rays[k]);
    }
}

/* One shadow ray per texel, row by row. */
EXAMPLE_FN void shadows_make_rays(const example_frame *f, lrt_ray *rays, float length, int threads)
{
    example_make_rays(f, rays, length, threads, shadows__rays_row);
}

/* Lit colour: albedo * (ambient + sun * max(n.l, 0) * unshadowed). */
EXAMPLE_FN void shadows_shade(const example_frame *f, const lrt_hit *hits, uint8_t *out)
{
    size_t k, n = (size_t)f->w * f->h;
    float l[3];
    shadows__light(f, l);
    for (k = 0; k < n; ++k) {
        float lit, c;
        int ch;
        if (f->depth[k] >= 1.0f) {
            memcpy(&out[3 * k], &f->rgb[3 * k], 3);
            continue;
        }
        c = surface_dot(&f->nrm[3 * k], l);
        lit = 0.35f + 0.9f * (c > 0.0f && hits[k].kind != LRT_HIT ? c : 0.0f);
        for (ch = 0; ch < 3; ++ch) out[3 * k + (size_t)ch] = example_to_byte(lit * (float)f->rgb[3 * k + (size_t)ch] / 255.0f);
    }
}

#ifndef EXAMPLE_NO_MAIN
int main(int argc, char **argv)
{
    example_run r;
    uint8_t *out;
    float length = SHADOW_LENGTH;
    size_t n, k, shadowed = 0;
    int rc = example_start(&r, argc, argv, "--length", &length, 1, shadows__rays_row, "shadow trace", 3);
    if (rc != EXAMPLE_EXIT_OK) return rc;
    n = (size_t)r.f.w * r.f.h;
    out = r.picture;
    shadows_shade(&r.f, r.hits, out);
    for (k = 0; k < n; ++k) shadowed += r.hits[k].kind == LRT_HIT;
    printf("shadows: %ux%u, %zu rays of length %g: set-up %.1f ms, trace %.1f ms on %d threads, %.1f%% in shadow\n",
           r.f.w, r.f.h, n, (double)length, r.setup_ms, r.trace_ms, r.o.threads, 100.0 * (double)shadowed / (double)n);
    rc = example_write_png(r.o.out_dir, "shadows.png", r.f.w, r.f.h, 3, out) ? EXAMPLE_EXIT_FAILED : EXAMPLE_EXIT_OK;
    example_end(&r);
    return rc;
}
#endif
