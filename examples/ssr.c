/* ssr.c - screen-space reflections traced with linear_rt.

   For each texel: its view-space position and normal (rebuilt from depth by
   example.h), the view ray reflected about the normal, clipped to the near
   and far planes and projected to a screen-space segment
   and lifted off its own surface (lrt_camera_surface_ray), traced to the closest
   hit; shaded from the colour buffer at the hit texel, or from the sky when
   the ray leaves the screen or reaches the far plane unblocked.

   build/ssr [--size N] [--depth FILE ...]    writes out/ssr.png and out/ssr_faces.png
   build/ssr --thickness 0.3                  a 0.3 m thick depth layer: ssr_thick.png, ssr_thick_faces.png
   build/ssr --thickness 5%                   a layer 5% of its distance thick: ssr_relative*.png
   build/ssr --thickness back                 the scene's back faces: ssr_back.png, ssr_back_faces.png
   (make examples builds it; example.h lists the options.) The faces picture
   shows which face of its texel each reflection hit: the top (a surface the
   camera sees) green, a side orange, the back red, inside blue; misses grey.

   The demo and the tests include this file with EXAMPLE_NO_MAIN defined and
   call ssr_make_rays / ssr_shade themselves. */
#include "example.h"

/* How much a texel reflects: floor-like surfaces (normal near world up) are
   polished stone, the rest follows Schlick's Fresnel from a dull 4%. */
static float ssr__reflectivity(const example_frame *f, const float n[3], const float view_dir[3])
{
    float up[3] = {f->view_from_world[1], f->view_from_world[4], f->view_from_world[7]};
    float c = -surface_dot(n, view_dir), m;
    c = c < 0.0f ? 0.0f : c > 1.0f ? 1.0f : c;
    m = (1.0f - c) * (1.0f - c) * (1.0f - c) * (1.0f - c) * (1.0f - c);
    if (surface_dot(n, up) > 0.95f) return 0.35f + 0.45f * m;
    return 0.04f + 0.5f * m;
}

/* The reflection direction at texel k (view space), and whether it has one. */
static int ssr__reflect(const example_frame *f, size_t k, float r[3], float v[3])
{
    const float *p = &f->pos[3 * k], *n = &f->nrm[3 * k];
    float d;
    if (f->depth[k] >= 1.0f || (n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f)) return 0;
    v[0] = p[0];
    v[1] = p[1];
    v[2] = p[2];
    surface_normalize(v); /* the eye is at the origin of view space */
    d = surface_dot(v, n);
    r[0] = v[0] - 2.0f * d * n[0];
    r[1] = v[1] - 2.0f * d * n[1];
    r[2] = v[2] - 2.0f * d * n[2];
    return 1;
}

static void ssr__rays_row(void *ctx, uint32_t j)
{
    const example_rays_job *job = (const example_rays_job *)ctx;
    const example_frame *f = job->f;
    uint32_t i;
    for (i = 0; i < f->w; ++i) {
        size_t k = (size_t)j * f->w + i;
        lrt_ray *ray = &job->rays[k];
        float r[3], v[3], to[3];
        const float *p = &f->pos[3 * k];
        /* sky texels and degenerate ones get lrt_camera_segment's invalid
           ray (NaN origin): the tracer skips it at once */
        if (!ssr__reflect(f, k, r, v)) {
            lrt_camera_segment(NULL, NULL, NULL, ray);
            continue;
        }
        /* far enough to cross the whole view; the far plane clips it */
        to[0] = p[0] + r[0] * 1e4f;
        to[1] = p[1] + r[1] * 1e4f;
        to[2] = p[2] + r[2] * 1e4f;
        lrt_camera_surface_ray(&f->camera, p, &f->nrm[3 * k], to, f->lift[k], ray);
    }
}

/* One reflection ray per texel, row by row (rays[j * w + i]). */
EXAMPLE_FN void ssr_make_rays(const example_frame *f, lrt_ray *rays, int threads)
{
    example_make_rays(f, rays, 0.0f, threads, ssr__rays_row);
}

/* The frame's colour with the reflections the hits found mixed in. */
EXAMPLE_FN void ssr_shade(const example_frame *f, const lrt_hit *hits, uint8_t *out)
{
    size_t k, n = (size_t)f->w * f->h;
    for (k = 0; k < n; ++k) {
        float r[3], v[3], refl[3], kr;
        int c;
        if (!ssr__reflect(f, k, r, v)) {
            memcpy(&out[3 * k], &f->rgb[3 * k], 3);
            continue;
        }
        /* every hit takes its texel's colour, whatever its face: on a
           steep slope the sides of the texels' stairs are the surface too
           (falling back on side hits striped the spheres' reflections) */
        if (hits[k].kind == LRT_HIT) {
            size_t q = (size_t)hits[k].y * f->w + hits[k].x;
            for (c = 0; c < 3; ++c) refl[c] = (float)f->rgb[3 * q + (size_t)c] / 255.0f;
        } else {
            example_sky(f, r, refl);
        }
        kr = ssr__reflectivity(f, &f->nrm[3 * k], v);
        for (c = 0; c < 3; ++c)
            out[3 * k + (size_t)c] = example_to_byte((1.0f - kr) * (float)f->rgb[3 * k + (size_t)c] / 255.0f + kr * refl[c]);
    }
}

/* The face of each texel's reflection hit as a colour (see the top). */
EXAMPLE_FN void ssr_faces(const example_frame *f, const lrt_hit *hits, uint8_t *out)
{
    static const uint8_t colours[5][3] = {{96, 96, 96}, {60, 170, 75}, {235, 140, 40}, {210, 40, 40}, {60, 90, 220}};
    size_t k, n = (size_t)f->w * f->h;
    for (k = 0; k < n; ++k) {
        const uint32_t face = hits[k].kind == LRT_HIT && hits[k].face <= LRT_FACE_INSIDE ? hits[k].face : 0u;
        memcpy(&out[3 * k], f->depth[k] >= 1.0f ? f->rgb + 3 * k : colours[face], 3);
    }
}

#ifndef EXAMPLE_NO_MAIN
int main(int argc, char **argv)
{
    example_run r;
    uint8_t *out;
    size_t n, k, hit_count = 0, top_count = 0;
    int rc = example_start(&r, argc, argv, NULL, NULL, 1, ssr__rays_row, "ssr trace", 3);
    if (rc != EXAMPLE_EXIT_OK) return rc;
    n = (size_t)r.f.w * r.f.h;
    out = r.picture;
    ssr_shade(&r.f, r.hits, out);
    for (k = 0; k < n; ++k) {
        hit_count += r.hits[k].kind == LRT_HIT;
        top_count += r.hits[k].kind == LRT_HIT && r.hits[k].face == LRT_FACE_TOP;
    }
    printf("ssr: %ux%u, %zu reflection rays: set-up %.1f ms, trace %.1f ms on %d threads, %.1f%% hit (%.1f%% on a top face)\n",
           r.f.w, r.f.h, n, r.setup_ms, r.trace_ms, r.o.threads, 100.0 * (double)hit_count / (double)n,
           100.0 * (double)top_count / (double)n);
    {
        const char *tag = r.o.thickness_back ? "_back" : r.o.thickness_relative ? "_relative" : r.o.thickness > 0.0f ? "_thick" : "";
        char name[32];
        snprintf(name, sizeof name, "ssr%s.png", tag);
        rc = example_write_png(r.o.out_dir, name, r.f.w, r.f.h, 3, out) ? EXAMPLE_EXIT_FAILED : EXAMPLE_EXIT_OK;
        ssr_faces(&r.f, r.hits, out);
        snprintf(name, sizeof name, "ssr%s_faces.png", tag);
        if (rc == EXAMPLE_EXIT_OK && example_write_png(r.o.out_dir, name, r.f.w, r.f.h, 3, out)) rc = EXAMPLE_EXIT_FAILED;
    }
    example_end(&r);
    return rc;
}
#endif
