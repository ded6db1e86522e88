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

/* An orthonormal tangent frame (t, b) around the unit normal n: the
   hemisphere of ambient occlusion's rays (examples/ao.c, bench/main.c). */
static inline void surface_frame(const float n[3], float t[3], float b[3])
{
    float a[3] = {0.0f, 0.0f, 0.0f};
    a[fabsf(n[0]) < 0.6f ? 0 : 1] = 1.0f;
    t[0] = a[1] * n[2] - a[2] * n[1];
    t[1] = a[2] * n[0] - a[0] * n[2];
    t[2] = a[0] * n[1] - a[1] * n[0];
    surface_normalize(t);
    b[0] = n[1] * t[2] - n[2] * t[1];
    b[1] = n[2] * t[0] - n[0] * t[2];
    b[2] = n[0] * t[1] - n[1] * t[0];
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

/* The depth step to take into THE LIFT on one side: the step to the
   neighbour and how much it changes to the next one (the second
   difference, at most the step itself): on a curved surface the texel
   tops further along stand out more than the first step says, on a plane
   it adds nothing. */
static inline float surface__lift_step(float step, float change) { return step + (change < step ? change : step); }

/* One axis of texel k (stride: 1 for x, w for y; at: the texel's index on
   that axis, of n): which neighbour lies on the texel's own surface (-1,
   +1, or 0 for none: sky or the edge) and, in *lift_step, the depth step to
   take into THE LIFT. Of two neighbours, the one whose line through the next
   texel beyond it passes nearer the texel's depth: at a contact (a box on
   the ground, its base a hair behind) the smaller step would take the other
   surface, and a ray would leave along the wrong normal. Where both
   neighbours lie on the surface (each line passes within a tenth of its own
   step, curved or flat), the lift takes the larger side's: a curved
   surface's flat texel tops stand out more on its steeper side. */
static inline int surface__side(const float *depth, size_t k, size_t stride, uint32_t at, uint32_t n, float *lift_step)
{
    const float d = depth[k];
    const int minus = at > 0 && depth[k - stride] < 1.0f, plus = at + 1 < n && depth[k + stride] < 1.0f;
    float sm = 0.0f, sp = 0.0f, em = 1.0f, ep = 1.0f; /* steps, and how far each side's line misses d */
    *lift_step = 0.0f;
    if (minus) {
        sm = fabsf(d - depth[k - stride]);
        em = at > 1 && depth[k - 2 * stride] < 1.0f ? fabsf(2.0f * depth[k - stride] - depth[k - 2 * stride] - d) : sm;
    }
    if (plus) {
        sp = fabsf(depth[k + stride] - d);
        ep = at + 2 < n && depth[k + 2 * stride] < 1.0f ? fabsf(2.0f * depth[k + stride] - depth[k + 2 * stride] - d) : sp;
    }
    if (minus && plus && em <= 0.1f * sm + 1e-7f && ep <= 0.1f * sp + 1e-7f) {
        const float lm = surface__lift_step(sm, em), lp = surface__lift_step(sp, ep);
        *lift_step = lm > lp ? lm : lp;
        return em <= ep ? -1 : 1;
    }
    if (minus && (!plus || em < ep || (em == ep && sm <= sp))) {
        *lift_step = surface__lift_step(sm, em);
        return -1;
    }
    if (plus) *lift_step = surface__lift_step(sp, ep);
    return plus;
}

/* Row j of the normals and lifts, from positions of rows j-1..j+1.
   The normal is the cross product of one horizontal and one vertical
   difference of positions, each towards the neighbour on the texel's own
   surface (surface__side). The lift is THE LIFT of linear_rt.h,
   lrt_surface_lift of the depth steps surface__side gives;
   lrt_camera_surface_ray applies it (and lifts more where the ray itself
   sinks into its own texel). */
static inline void surface_normals_row(const float *depth, const float *pos, uint32_t w, uint32_t h, uint32_t j,
                                       float *nrm, float *lift)
{
    uint32_t i;
    for (i = 0; i < w; ++i) {
        size_t k = (size_t)j * w + i;
        float d = depth[k], dx, dy, ex[3] = {0, 0, 0}, ey[3] = {0, 0, 0}, *n = &nrm[3 * k];
        int sx, sy, c;
        n[0] = n[1] = n[2] = 0.0f;
        lift[k] = 0.0f;
        if (d >= 1.0f) continue;
        sx = surface__side(depth, k, 1, i, w, &dx);
        sy = surface__side(depth, k, w, j, h, &dy);
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
