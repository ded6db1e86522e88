/* surface.h - the visible surface of a depth map, per texel, in view space:
   its position, its normal (facing the eye) and how far a ray leaving it is
   lifted towards the eye (the examples' self-intersection policy). Shared
   by the examples (example.h) and the benchmark (bench/main.c); needs only
   linear_rt.h's camera helpers (lrt_camera_unproject). Row by row, so that
   callers may split rows across threads; all static inline. */
#ifndef SURFACE_H
#define SURFACE_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include "../linear_rt.h"

static inline float surface_dot(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static inline void surface_normalize(float *v)
{
    float l = sqrtf(surface_dot(v, v));
    if (l > 0.0f) {
        v[0] /= l;
        v[1] /= l;
        v[2] /= l;
    }
}

/* Row j: pos[3k..3k+2] = the view-space point at each texel's centre and
   depth (0 0 0 for the sky, depth 1). */
static inline void surface_positions_row(const lrt_camera *cam, const float *depth, uint32_t w, uint32_t j, float *pos)
{
    uint32_t i;
    for (i = 0; i < w; ++i) {
        size_t k = (size_t)j * w + i;
        float s[3];
        s[0] = (float)i + 0.5f;
        s[1] = (float)j + 0.5f;
        s[2] = depth[k];
        if (s[2] >= 1.0f || !lrt_camera_unproject(cam, s, &pos[3 * k])) pos[3 * k] = pos[3 * k + 1] = pos[3 * k + 2] = 0.0f;
    }
}

/* Row j of the normals and lifts, from positions of rows j-1..j+1.
   The normal is the cross product of one horizontal and one vertical
   difference of positions; of the two neighbours on each axis, the one with
   the smaller depth step is used, so that a silhouette does not bend the
   normal of the surface in front of it. The lift is THE LIFT of
   linear_rt.h, lrt_surface_lift of the depth steps to those neighbours;
   lrt_camera_surface_ray applies it. */
static inline void surface_normals_row(const float *depth, const float *pos, uint32_t w, uint32_t h, uint32_t j,
                                       float *nrm, float *lift)
{
    uint32_t i;
    for (i = 0; i < w; ++i) {
        size_t k = (size_t)j * w + i;
        float d = depth[k], dx = 0.0f, dy = 0.0f, ex[3] = {0, 0, 0}, ey[3] = {0, 0, 0}, *n = &nrm[3 * k];
        int sx = 0, sy = 0, c;
        n[0] = n[1] = n[2] = 0.0f;
        lift[k] = 0.0f;
        if (d >= 1.0f) continue;
        if (i + 1 < w && depth[k + 1] < 1.0f) { sx = 1; dx = depth[k + 1] - d; }
        if (i > 0 && depth[k - 1] < 1.0f && (!sx || fabsf(d - depth[k - 1]) < fabsf(dx))) { sx = -1; dx = d - depth[k - 1]; }
        if (j + 1 < h && depth[k + w] < 1.0f) { sy = 1; dy = depth[k + w] - d; }
        if (j > 0 && depth[k - w] < 1.0f && (!sy || fabsf(d - depth[k - w]) < fabsf(dy))) { sy = -1; dy = d - depth[k - w]; }
        for (c = 0; c < 3; ++c) {
            if (sx) ex[c] = sx > 0 ? pos[3 * (k + 1) + c] - pos[3 * k + c] : pos[3 * k + c] - pos[3 * (k - 1) + c];
            if (sy) ey[c] = sy > 0 ? pos[3 * (k + w) + c] - pos[3 * k + c] : pos[3 * k + c] - pos[3 * (k - w) + c];
        }
        if (sx && sy) { /* screen x right, y down: ex x ey points away from the eye for a camera-facing surface */
            n[0] = ey[1] * ex[2] - ey[2] * ex[1];
            n[1] = ey[2] * ex[0] - ey[0] * ex[2];
            n[2] = ey[0] * ex[1] - ey[1] * ex[0];
            surface_normalize(n);
            if (surface_dot(n, &pos[3 * k]) > 0.0f) { n[0] = -n[0]; n[1] = -n[1]; n[2] = -n[2]; }
        } else { /* a lone texel: face the eye */
            n[0] = -pos[3 * k];
            n[1] = -pos[3 * k + 1];
            n[2] = -pos[3 * k + 2];
            surface_normalize(n);
        }
        lift[k] = lrt_surface_lift(dx, dy); /* THE LIFT of linear_rt.h */
    }
}

#endif
