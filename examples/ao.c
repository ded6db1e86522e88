/* ao.c - screen-space ambient occlusion traced with linear_rt.

   For each texel, AO_RAYS short rays (AO_RADIUS view-space units) over the
   hemisphere of its normal, cosine-weighted, the pattern turned per texel
   by a 4x4 dither; any hit occludes (the tracer stops at its first hit,
   the closest). The occluded share, smoothed over 4x4 texels
   of similar depth, is the picture: white open, dark occluded.

   build/ao [--size N] [--depth FILE ...] [--radius R]   writes out/ao.png */
#include "example.h"

#define AO_RAYS 16
#define AO_RADIUS 0.6f

static void ao__rays_row(void *ctx, uint32_t j)
{
    static const uint8_t dither[16] = {0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5};
    const example_rays_job *job = (const example_rays_job *)ctx; /* AO_RAYS rays a texel; length: the radius */
    const example_frame *f = job->f;
    const float golden = 2.39996323f, pi = 3.14159265358979f;
    float disc[4][AO_RAYS][3]; /* the 4 turns of this row's dither, each a spiral of AO_RAYS points */
    uint32_t i;
    int s, q;
    for (q = 0; q < 4; ++q) {
        float turn = 2.0f * pi * (float)dither[(j & 3) * 4 + (uint32_t)q] / 16.0f;
        for (s = 0; s < AO_RAYS; ++s) {
            /* a spiral over the disc, lifted onto the hemisphere: cosine-weighted */
            float u = ((float)s + 0.5f) / (float)AO_RAYS, r = sqrtf(u), phi = (float)s * golden + turn;
            disc[q][s][0] = r * cosf(phi);
            disc[q][s][1] = r * sinf(phi);
            disc[q][s][2] = sqrtf(1.0f - u);
        }
    }
    for (i = 0; i < f->w; ++i) {
        size_t k = (size_t)j * f->w + i;
        const float *p = &f->pos[3 * k], *n = &f->nrm[3 * k];
        lrt_ray *rays = &job->rays[k * AO_RAYS];
        float t[3], b[3];
        if (f->depth[k] >= 1.0f) {
            for (s = 0; s < AO_RAYS; ++s) lrt_camera_segment(NULL, NULL, NULL, &rays[s]);
            continue;
        }
        surface_frame(n, t, b);
        for (s = 0; s < AO_RAYS; ++s) {
            const float *d = disc[i & 3][s];
            float to[3];
            int c;
            for (c = 0; c < 3; ++c) to[c] = p[c] + job->length * (d[0] * t[c] + d[1] * b[c] + d[2] * n[c]);
            lrt_camera_surface_ray(&f->camera, p, n, to, f->lift[k], &rays[s]);
        }
    }
}

/* AO_RAYS rays per texel, texel by texel in row order. */
EXAMPLE_FN void ao_make_rays(const example_frame *f, lrt_ray *rays, float radius, int threads)
{
    example_make_rays(f, rays, radius, threads, ao__rays_row);
}

/* Occlusion of each texel (0 open .. 1 closed) before smoothing; -1 for sky. */
EXAMPLE_FN void ao_occlusion(const example_frame *f, const lrt_hit *hits, float *occ)
{
    size_t k, n = (size_t)f->w * f->h;
    int s;
    for (k = 0; k < n; ++k) {
        int hit = 0;
        if (f->depth[k] >= 1.0f) {
            occ[k] = -1.0f;
            continue;
        }
        for (s = 0; s < AO_RAYS; ++s) hit += hits[k * AO_RAYS + (size_t)s].kind == LRT_HIT;
        occ[k] = (float)hit / (float)AO_RAYS;
    }
}

/* The picture: 1 - occlusion averaged over the 4x4 texels around (which the
   dither spreads one pattern over) that lie within 5% of this texel's
   view distance, so edges stay sharp. */
EXAMPLE_FN void ao_picture(const example_frame *f, const float *occ, uint8_t *grey)
{
    uint32_t i, j;
    int dx, dy;
    for (j = 0; j < f->h; ++j)
        for (i = 0; i < f->w; ++i) {
            size_t k = (size_t)j * f->w + i;
            float sum = 0.0f, z = f->pos[3 * k + 2], cnt = 0.0f;
            if (occ[k] < 0.0f) {
                grey[k] = 255;
                continue;
            }
            for (dy = -2; dy <= 1; ++dy)
                for (dx = -2; dx <= 1; ++dx) {
                    long x = (long)i + dx, y = (long)j + dy;
                    size_t q;
                    if (x < 0 || y < 0 || x >= (long)f->w || y >= (long)f->h) continue;
                    q = (size_t)y * f->w + (size_t)x;
                    if (occ[q] < 0.0f || fabsf(f->pos[3 * q + 2] - z) > 0.05f * fabsf(z)) continue;
                    sum += occ[q];
                    cnt += 1.0f;
                }
            grey[k] = example_to_byte(1.0f - sum / cnt);
        }
}

#ifndef EXAMPLE_NO_MAIN
int main(int argc, char **argv)
{
    example_run r;
    float *occ, radius = AO_RADIUS;
    size_t n;
    int rc = example_start(&r, argc, argv, "--radius", &radius, AO_RAYS, ao__rays_row, "ao trace", 1);
    if (rc != EXAMPLE_EXIT_OK) return rc;
    n = (size_t)r.f.w * r.f.h;
    if (!(occ = (float *)malloc(n * sizeof *occ))) {
        fprintf(stderr, "out of memory\n");
        return EXAMPLE_EXIT_FAILED;
    }
    ao_occlusion(&r.f, r.hits, occ);
    ao_picture(&r.f, occ, r.picture);
    printf("ao: %ux%u, %zu rays (%d per texel, radius %g): set-up %.1f ms, trace %.1f ms on %d threads\n", r.f.w, r.f.h,
           n * AO_RAYS, AO_RAYS, (double)radius, r.setup_ms, r.trace_ms, r.o.threads);
    rc = example_write_png(r.o.out_dir, "ao.png", r.f.w, r.f.h, 1, r.picture) ? EXAMPLE_EXIT_FAILED : EXAMPLE_EXIT_OK;
    free(occ);
    example_end(&r);
    return rc;
}
#endif
