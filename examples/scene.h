/* scene.h - the embedded default scene of the examples, demo and tests.

   A deterministic outdoor yard built in code and rasterised on the CPU by
   casting one view ray per pixel: a ground plane, boxes, spheres and thin
   poles under a sky. Gives depth (Vulkan convention, 0 near, 1 far, sky = 1)
   and an optional RGB colour, and the depth of a back-face pass (the
   nearest back face of each pixel: thickness from a back map). No file, no
   randomness, any size.

   Header-only, static functions: include it where it is used. */
#ifndef LRT_SCENE_H
#define LRT_SCENE_H

#include <math.h>
#include <stdint.h>
#include <stddef.h>

typedef struct scene_camera {
    float fov_y_deg;   /* vertical field of view */
    float near_z, far_z;
    float pitch_deg;   /* looking down by this much */
    float height;      /* eye height above the ground */
} scene_camera;

static scene_camera scene_default_camera(void)
{
    scene_camera c;
    c.fov_y_deg = 60.0f;
    c.near_z = 0.1f;
    c.far_z = 60.0f;
    c.pitch_deg = 12.0f;
    c.height = 1.7f;
    return c;
}

typedef struct scene__prim {
    int kind;        /* 0 box, 1 sphere, 2 vertical cylinder (pole) */
    float a[3], b[3];/* box min/max; sphere centre, radius in b[0]; pole base, radius b[0], height b[1] */
    float rgb[3];
} scene__prim;

#define SCENE__PRIMS 17
static const scene__prim scene__prims[SCENE__PRIMS] = {
    {0, {-3.0f, 0.0f, -9.0f}, {-1.2f, 1.6f, -7.0f}, {0.80f, 0.35f, 0.25f}},
    {0, {1.5f, 0.0f, -12.0f}, {4.0f, 3.0f, -10.0f}, {0.30f, 0.45f, 0.80f}},
    {0, {-6.0f, 0.0f, -20.0f}, {-3.5f, 5.0f, -17.0f}, {0.70f, 0.70f, 0.65f}},
    {0, {5.0f, 0.0f, -25.0f}, {9.0f, 2.0f, -21.0f}, {0.55f, 0.75f, 0.40f}},
    {0, {-0.6f, 0.0f, -5.2f}, {0.2f, 0.4f, -4.4f}, {0.90f, 0.80f, 0.30f}},
    {0, {-12.0f, 0.0f, -40.0f}, {12.0f, 8.0f, -38.0f}, {0.60f, 0.55f, 0.50f}},
    {1, {0.8f, 0.7f, -6.0f}, {0.7f, 0, 0}, {0.85f, 0.85f, 0.90f}},
    {1, {-2.2f, 0.5f, -4.5f}, {0.5f, 0, 0}, {0.90f, 0.30f, 0.50f}},
    {1, {3.0f, 1.2f, -15.0f}, {1.2f, 0, 0}, {0.35f, 0.80f, 0.80f}},
    {1, {-1.0f, 2.2f, -14.0f}, {0.6f, 0, 0}, {0.95f, 0.60f, 0.20f}},
    {2, {-0.8f, 0.0f, -3.5f}, {0.02f, 2.5f, 0}, {0.20f, 0.20f, 0.20f}},
    {2, {1.6f, 0.0f, -4.0f}, {0.03f, 3.0f, 0}, {0.20f, 0.20f, 0.20f}},
    {2, {-4.0f, 0.0f, -11.0f}, {0.05f, 4.0f, 0}, {0.25f, 0.25f, 0.25f}},
    {2, {6.0f, 0.0f, -9.0f}, {0.04f, 3.5f, 0}, {0.25f, 0.25f, 0.25f}},
    {2, {0.3f, 0.0f, -2.2f}, {0.01f, 1.2f, 0}, {0.15f, 0.15f, 0.15f}},
    {2, {-2.5f, 0.0f, -16.0f}, {0.06f, 6.0f, 0}, {0.30f, 0.30f, 0.30f}},
    {2, {2.6f, 0.0f, -7.5f}, {0.025f, 2.2f, 0}, {0.20f, 0.20f, 0.20f}},
};

/* Nearest t > 0 of the ray (o, d) on primitive p, or -1. */
static float scene__hit(const scene__prim *p, const float o[3], const float d[3])
{
    if (p->kind == 0) {
        float t0 = -1e30f, t1 = 1e30f;
        int k;
        for (k = 0; k < 3; ++k) {
            float inv = 1.0f / d[k];
            float ta = (p->a[k] - o[k]) * inv, tb = (p->b[k] - o[k]) * inv;
            if (ta > tb) { float x = ta; ta = tb; tb = x; }
            if (d[k] == 0.0f) {
                if (o[k] < p->a[k] || o[k] > p->b[k]) return -1.0f;
                continue;
            }
            t0 = ta > t0 ? ta : t0;
            t1 = tb < t1 ? tb : t1;
        }
        return (t0 <= t1 && t0 > 0.0f) ? t0 : -1.0f;
    } else if (p->kind == 1) {
        float oc[3] = {o[0] - p->a[0], o[1] - p->a[1], o[2] - p->a[2]};
        float b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
        float c = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - p->b[0] * p->b[0];
        float a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        float disc = b * b - a * c;
        float t;
        if (disc < 0.0f) return -1.0f;
        t = (-b - sqrtf(disc)) / a;
        return t > 0.0f ? t : -1.0f;
    } else {
        float ox = o[0] - p->a[0], oz = o[2] - p->a[2];
        float a = d[0] * d[0] + d[2] * d[2], b = ox * d[0] + oz * d[2], c = ox * ox + oz * oz - p->b[0] * p->b[0];
        float disc = b * b - a * c, t, y;
        if (a == 0.0f || disc < 0.0f) return -1.0f;
        t = (-b - sqrtf(disc)) / a;
        y = o[1] + t * d[1];
        return (t > 0.0f && y >= p->a[1] && y <= p->a[1] + p->b[1]) ? t : -1.0f;
    }
}

/* Farthest t > 0 of the ray (o, d) inside primitive p (its back face), or -1.
   Like scene__hit, a pole has no caps. Apart from scene__hit on purpose:
   sharing its code changes how gcc contracts it, and so the yard's pixels
   every committed picture and figure comes from (see scene__pixel_ray). */
static inline float scene__exit(const scene__prim *p, const float o[3], const float d[3])
{
    if (p->kind == 0) {
        float t0 = -1e30f, t1 = 1e30f;
        int k;
        for (k = 0; k < 3; ++k) {
            float inv = 1.0f / d[k];
            float ta = (p->a[k] - o[k]) * inv, tb = (p->b[k] - o[k]) * inv;
            if (ta > tb) { float x = ta; ta = tb; tb = x; }
            if (d[k] == 0.0f) {
                if (o[k] < p->a[k] || o[k] > p->b[k]) return -1.0f;
                continue;
            }
            t0 = ta > t0 ? ta : t0;
            t1 = tb < t1 ? tb : t1;
        }
        return (t0 <= t1 && t1 > 0.0f) ? t1 : -1.0f;
    } else if (p->kind == 1) {
        float oc[3] = {o[0] - p->a[0], o[1] - p->a[1], o[2] - p->a[2]};
        float b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
        float c = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - p->b[0] * p->b[0];
        float a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        float disc = b * b - a * c, t;
        if (disc < 0.0f) return -1.0f;
        t = (-b + sqrtf(disc)) / a;
        return t > 0.0f ? t : -1.0f;
    } else {
        float ox = o[0] - p->a[0], oz = o[2] - p->a[2];
        float a = d[0] * d[0] + d[2] * d[2], b = ox * d[0] + oz * d[2], c = ox * ox + oz * oz - p->b[0] * p->b[0];
        float disc = b * b - a * c, t, y;
        if (a == 0.0f || disc < 0.0f) return -1.0f;
        t = (-b + sqrtf(disc)) / a;
        y = o[1] + t * d[1];
        return (t > 0.0f && y >= p->a[1] && y <= p->a[1] + p->b[1]) ? t : -1.0f;
    }
}

/* The camera's rotation: view = m * (world - eye), m row-major (3x3), eye =
   (0, height, 0). View space is the renderer's camera space: x right, y up,
   looking down -z. */
static inline void scene_view_from_world(const scene_camera *cam, float m[9])
{
    const float pi = 3.14159265358979f;
    float cp = cosf(cam->pitch_deg * pi / 180.0f), sp = sinf(cam->pitch_deg * pi / 180.0f);
    m[0] = 1.0f; m[1] = 0.0f; m[2] = 0.0f;
    m[3] = 0.0f; m[4] = cp;   m[5] = -sp;
    m[6] = 0.0f; m[7] = sp;   m[8] = cp;
}

/* The view ray through screen point (fx, fy) (texels, row 0 at the top) from
   the eye o, in world space (the camera pitched down about x), and the
   cosine factor that turns its t into a distance along the camera's forward
   axis: scene_render's own arithmetic, which keeps its code as it was (gcc
   contracts products differently in another shape of the same code, and
   every committed picture and benchmark figure of the yard comes from that
   depth, bit for bit). */
static inline void scene_view_ray(int w, int h, const scene_camera *cam, float fx, float fy, float o[3], float d[3],
                                  float *forward)
{
    const float pi = 3.14159265358979f;
    float th = tanf(cam->fov_y_deg * pi / 360.0f), aspect = (float)w / (float)h;
    float cp = cosf(cam->pitch_deg * pi / 180.0f), sp = sinf(cam->pitch_deg * pi / 180.0f);
    /* view direction in camera space (x right, y up, -z forward), pitched down */
    float cx = (2.0f * fx / (float)w - 1.0f) * th * aspect;
    float cy = (1.0f - 2.0f * fy / (float)h) * th;
    const float dc[3] = {cx, cy, -1.0f};
    /* rotated about x so that the forward axis is (0, -sin p, -cos p) */
    d[0] = dc[0];
    d[1] = dc[1] * cp + dc[2] * sp;
    d[2] = -dc[1] * sp + dc[2] * cp;
    o[0] = 0.0f;
    o[1] = cam->height;
    o[2] = 0.0f;
    *forward = -d[1] * sp - d[2] * cp;
}

/* Pixel (x, y)'s view ray: through its centre */
static inline void scene__pixel_ray(int w, int h, const scene_camera *cam, int x, int y, float o[3], float d[3], float *forward)
{
    scene_view_ray(w, h, cam, (float)x + 0.5f, (float)y + 0.5f, o, d, forward);
}

/* The perspective depth of a point t along a pixel's ray (1: nothing there) */
static inline float scene__depth(const scene_camera *cam, float t, float forward)
{
    float n = cam->near_z, f = cam->far_z, zview = t * forward, dep;
    if (t >= 1e29f || zview >= f) return 1.0f;
    dep = (f * (zview - n)) / (zview * (f - n));
    return dep < 0.0f ? 0.0f : dep > 1.0f ? 1.0f : dep;
}

/* Renders depth (w*h floats, row 0 = top of the image) and, if rgb is not
   NULL, colour (w*h*3 bytes). */
static void scene_render(int w, int h, const scene_camera *cam, float *depth, uint8_t *rgb)
{
    const float pi = 3.14159265358979f;
    float th = tanf(cam->fov_y_deg * pi / 360.0f), aspect = (float)w / (float)h;
    float cp = cosf(cam->pitch_deg * pi / 180.0f), sp = sinf(cam->pitch_deg * pi / 180.0f);
    float n = cam->near_z, f = cam->far_z;
    int x, y, i;
    for (y = 0; y < h; ++y) {
        for (x = 0; x < w; ++x) {
            /* view direction in camera space (x right, y up, -z forward), pitched down */
            float cx = (2.0f * ((float)x + 0.5f) / (float)w - 1.0f) * th * aspect;
            float cy = (1.0f - 2.0f * ((float)y + 0.5f) / (float)h) * th;
            float dc[3] = {cx, cy, -1.0f};
            /* rotated about x so that the forward axis is (0, -sin p, -cos p) */
            float d[3] = {dc[0], dc[1] * cp + dc[2] * sp, -dc[1] * sp + dc[2] * cp};
            float o[3] = {0.0f, cam->height, 0.0f};
            float best = 1e30f, col[3] = {0.55f, 0.70f, 0.95f}, zview, dep;
            if (d[1] < 0.0f) { /* ground y = 0: a checker */
                float t = -o[1] / d[1];
                float gx = o[0] + t * d[0], gz = o[2] + t * d[2];
                int chk = ((int)floorf(gx) + (int)floorf(gz)) & 1;
                best = t;
                col[0] = chk ? 0.62f : 0.48f;
                col[1] = chk ? 0.60f : 0.46f;
                col[2] = chk ? 0.55f : 0.42f;
            }
            for (i = 0; i < SCENE__PRIMS; ++i) {
                float t = scene__hit(&scene__prims[i], o, d);
                if (t > 0.0f && t < best) {
                    best = t;
                    col[0] = scene__prims[i].rgb[0];
                    col[1] = scene__prims[i].rgb[1];
                    col[2] = scene__prims[i].rgb[2];
                }
            }
            /* distance along the camera's forward axis; perspective depth */
            zview = best * (-d[1] * sp - d[2] * cp);
            if (best >= 1e29f || zview >= f) dep = 1.0f;
            else dep = (f * (zview - n)) / (zview * (f - n));
            if (dep < 0.0f) dep = 0.0f;
            if (dep > 1.0f) dep = 1.0f;
            depth[(size_t)y * (size_t)w + (size_t)x] = dep;
            if (rgb) {
                for (i = 0; i < 3; ++i) rgb[((size_t)y * (size_t)w + (size_t)x) * 3 + (size_t)i] = (uint8_t)(col[i] * 255.0f + 0.5f);
            }
        }
    }
}

/* Renders what a back-face depth pass gives (w*h floats): the depth of the
   nearest back face along each pixel's ray, 1 where there is none (the
   ground is a plane with no back: solid to the far plane). */
static inline void scene_render_back(int w, int h, const scene_camera *cam, float *back)
{
    int x, y, i;
    for (y = 0; y < h; ++y) {
        for (x = 0; x < w; ++x) {
            float o[3], d[3], forward, best = 1e30f;
            scene__pixel_ray(w, h, cam, x, y, o, d, &forward);
            for (i = 0; i < SCENE__PRIMS; ++i) {
                float t = scene__exit(&scene__prims[i], o, d);
                if (t > 0.0f && t < best) best = t;
            }
            back[(size_t)y * (size_t)w + (size_t)x] = scene__depth(cam, best, forward);
        }
    }
}

/* The analytic normals of what scene_render sees (w*h*3 floats, view
   space, unit length; 0 0 0 for the sky) and which surface each pixel shows
   (id: -1 sky, 0 the ground, 1 + the primitive's index), as a G-buffer pass
   would give them: for tests of rays that leave a surface along a normal
   not taken from depth. */
static inline void scene_render_normals(int w, int h, const scene_camera *cam, float *nrm, int *id)
{
    float m[9];
    int x, y, i, k;
    scene_view_from_world(cam, m);
    for (y = 0; y < h; ++y) {
        for (x = 0; x < w; ++x) {
            const size_t q = (size_t)y * (size_t)w + (size_t)x;
            float o[3], d[3], forward, best = 1e30f, p[3], nw[3] = {0, 0, 0}, l;
            int which = -1;
            scene__pixel_ray(w, h, cam, x, y, o, d, &forward);
            if (d[1] < 0.0f) {
                best = -o[1] / d[1];
                which = 0;
            }
            for (i = 0; i < SCENE__PRIMS; ++i) {
                float t = scene__hit(&scene__prims[i], o, d);
                if (t > 0.0f && t < best) {
                    best = t;
                    which = 1 + i;
                }
            }
            if (scene__depth(cam, best, forward) >= 1.0f) which = -1;
            for (k = 0; k < 3; ++k) p[k] = o[k] + best * d[k];
            if (which == 0) {
                nw[1] = 1.0f;
            } else if (which > 0) {
                const scene__prim *pr = &scene__prims[which - 1];
                if (pr->kind == 0) { /* the face the point lies nearest */
                    float dist = 1e30f;
                    for (k = 0; k < 3; ++k) {
                        float da = fabsf(p[k] - pr->a[k]), db = fabsf(p[k] - pr->b[k]);
                        if (da < dist) { dist = da; nw[0] = nw[1] = nw[2] = 0.0f; nw[k] = -1.0f; }
                        if (db < dist) { dist = db; nw[0] = nw[1] = nw[2] = 0.0f; nw[k] = 1.0f; }
                    }
                } else if (pr->kind == 1) {
                    for (k = 0; k < 3; ++k) nw[k] = p[k] - pr->a[k];
                } else {
                    nw[0] = p[0] - pr->a[0];
                    nw[2] = p[2] - pr->a[2];
                }
            }
            l = sqrtf(nw[0] * nw[0] + nw[1] * nw[1] + nw[2] * nw[2]);
            for (k = 0; k < 3; ++k) {
                const float v = m[3 * k] * nw[0] + m[3 * k + 1] * nw[1] + m[3 * k + 2] * nw[2];
                nrm[3 * q + (size_t)k] = l > 0.0f ? v / l : 0.0f;
            }
            if (id) id[q] = which;
        }
    }
}


#endif

/* The demo's workload (examples/demo.c; bench/walk_rays.c times it): one
   primary ray per texel of a size x size float depth map (row by row, into
   prim), then n random segments (into seg), each from a point in front of a
   random texel's surface to a point a little behind another's, drawn from
   the xorshift64 state *rng, one draw after another. Compiled where linear_rt.h was
   included first (outside the include guard above, so that a second
   include after linear_rt.h brings it). */
#if defined(LINEAR_RT_H) && !defined(LRT_SCENE_DEMO_RAYS)
#define LRT_SCENE_DEMO_RAYS
#define SCENE_DEMO_SEED 0x2545f4914f6cdd1dull
static inline float scene_rnd01(uint64_t *rng) /* uniform in [0, 1) */
{
    *rng ^= *rng << 13;
    *rng ^= *rng >> 7;
    *rng ^= *rng << 17;
    return (float)(*rng >> 40) * (1.0f / 16777216.0f);
}

static inline void scene_demo_rays(int size, const float *depth, lrt_ray *prim, lrt_ray *seg, size_t n, uint64_t *rng)
{
    size_t i, j;
    for (j = 0; j < (size_t)size; ++j)
        for (i = 0; i < (size_t)size; ++i) {
            lrt_ray *r = &prim[j * (size_t)size + i];
            r->origin[0] = (float)i + 0.5f;
            r->origin[1] = (float)j + 0.5f;
            r->origin[2] = 0.0f;
            r->dir[0] = r->dir[1] = 0.0f;
            r->dir[2] = 1.0f;
            r->tmin = 0.0f;
            r->tmax = 1.0f;
        }
    for (i = 0; i < n; ++i) {
        uint32_t tx = (uint32_t)(scene_rnd01(rng) * (float)size), ty = (uint32_t)(scene_rnd01(rng) * (float)size);
        float d, end[3];
        lrt_ray *r = &seg[i];
        if (tx >= (uint32_t)size) tx = (uint32_t)size - 1;
        if (ty >= (uint32_t)size) ty = (uint32_t)size - 1;
        d = depth[(size_t)ty * (size_t)size + tx];
        r->origin[0] = (float)tx + scene_rnd01(rng);
        r->origin[1] = (float)ty + scene_rnd01(rng);
        r->origin[2] = d * scene_rnd01(rng);
        end[0] = scene_rnd01(rng) * (float)size;
        end[1] = scene_rnd01(rng) * (float)size;
        end[2] = d + 0.05f * scene_rnd01(rng);
        r->dir[0] = end[0] - r->origin[0];
        r->dir[1] = end[1] - r->origin[1];
        r->dir[2] = end[2] - r->origin[2];
        r->tmin = 0.0f;
        r->tmax = 1.0f;
    }
}
#endif
