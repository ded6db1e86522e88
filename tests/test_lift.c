/* tests/test_lift.c - THE LIFT of linear_rt.h: rays that leave a visible
   surface never meet that surface again, whatever gave them their normal.

   The embedded scene (examples/scene.h: a ground plane, boxes standing on
   it, spheres, poles), rendered at a few sizes. From every texel of a
   surface, rays leave along three kinds of normal:
   - depth: the examples' normals from depth (examples/surface.h);
   - analytic: the scene's own (scene_render_normals), as a renderer knows them;
   - G-buffer: those stored in 8-bit unorm per component and read back.
   Each texel sends its reflection of the view ray and 4 directions of the
   hemisphere (AO), lifted by the recipe of THE LIFT: lrt_surface_lift of the
   depth steps to the texel's neighbours and their change (examples/surface.h),
   whatever the normal came from, and that normal, through
   lrt_camera_surface_ray. Every surface is convex (a box, a sphere, a pole)
   or a plane (the ground), so a ray that leaves it, above the tangent plane
   of its true (analytic) normal, cannot meet it again: a hit on a texel of
   that surface is a self-hit, and there must be none. Counted on the whole
   frame and on the texels where two surfaces meet (joints: a box on the
   ground, a pole's edge). A ray whose normal is wrong enough to send it into
   its true surface (depth normals at an edge, a quantised normal at a
   grazing angle) meets it, rightly: those are counted and printed apart.
   None may hit its own texel. It also checks that a lifted ray towards the
   sky reaches the far plane: its hit is the sky texel's top at depth 1
   (docs/MODEL.md), not a miss at tmax.
   Prints the counts and ends with "N passed, M failed". */
#include "../examples/example.h"
#define EXAMPLE_NO_MAIN
#include "../examples/ao.c"
#include "support/check.h"

enum { SRC_DEPTH, SRC_ANALYTIC, SRC_GBUFFER, SRC_COUNT };
static const char *src_names[SRC_COUNT] = {"depth", "analytic", "G-buffer"};

/* deterministic: the C library's generator, seeded in main */
static float rnd01(void) { return (float)rand() / ((float)RAND_MAX + 1.0f); }

static float dot3(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* a direction of the hemisphere around n, cosine-weighted, in examples/ao.c's frame (surface_frame) */
static void hemisphere(const float n[3], float out[3])
{
    float t[3], b[3], u = rnd01(), phi = 6.2831853f * rnd01(), r = sqrtf(u), z = sqrtf(1.0f - u);
    int k;
    surface_frame(n, t, b);
    for (k = 0; k < 3; ++k) out[k] = r * cosf(phi) * t[k] + r * sinf(phi) * b[k] + z * n[k];
}

typedef struct counts {
    size_t rays, self, joint_rays, joint_self, own_texel, entering, entering_self;
} counts;

/* truth: the analytic normals, which tell a ray that leaves its surface from one a wrong normal sends into it */
static void frame_rays(const example_frame *f, const int *id, const float *normals, const float *truth, counts *c)
{
    const uint32_t w = f->w, h = f->h;
    lrt_ray *rays = (lrt_ray *)malloc(sizeof(lrt_ray) * (size_t)w * h * 5);
    lrt_hit *hits = (lrt_hit *)malloc(sizeof(lrt_hit) * (size_t)w * h * 5);
    size_t *from = (size_t *)malloc(sizeof(size_t) * (size_t)w * h * 5), n = 0, q;
    unsigned char *enters = (unsigned char *)malloc((size_t)w * h * 5);
    uint32_t i, j;
    int a;
    if (!rays || !hits || !from || !enters) exit(2);
    for (j = 0; j < h; ++j)
        for (i = 0; i < w; ++i) {
            const size_t k = (size_t)j * w + i;
            const float *p = &f->pos[3 * k], *nm = &normals[3 * k];
            float v[3], d[3], to[3], vn;
            if (id[k] < 0 || f->depth[k] >= 1.0f || dot3(nm, nm) == 0.0f) continue;
            v[0] = p[0], v[1] = p[1], v[2] = p[2];
            surface_normalize(v);
            vn = dot3(v, nm);
            for (a = 0; a < 5; ++a) {
                int m;
                if (a == 0) { /* the view ray's reflection */
                    for (m = 0; m < 3; ++m) d[m] = v[m] - 2.0f * vn * nm[m];
                } else {
                    hemisphere(nm, d);
                }
                if (!(dot3(d, nm) > 1e-3f)) continue; /* a grazing ray leaves along its surface */
                for (m = 0; m < 3; ++m) to[m] = p[m] + d[m] * (a == 0 ? 1e4f : 2.0f);
                if (!lrt_camera_surface_ray(&f->camera, p, nm, to, f->lift[k], &rays[n])) continue;
                enters[n] = !(dot3(d, &truth[3 * k]) > 0.0f);
                from[n++] = k;
            }
        }
    if (lrt_trace(&f->bvh, &f->lrt[0], rays, hits, n, 0) != LRT_SUCCESS) exit(2);
    for (q = 0; q < n; ++q) {
        const size_t k = from[q];
        const uint32_t i0 = (uint32_t)(k % w), j0 = (uint32_t)(k / w);
        int joint = 0, di, dj, self;
        for (dj = -1; dj <= 1; ++dj)
            for (di = -1; di <= 1; ++di) {
                const int x = (int)i0 + di, y = (int)j0 + dj;
                if (x >= 0 && y >= 0 && x < (int)w && y < (int)h && id[(size_t)y * w + (size_t)x] >= 0 &&
                    id[(size_t)y * w + (size_t)x] != id[k])
                    joint = 1;
            }
        self = hits[q].kind == LRT_HIT && id[(size_t)hits[q].y * w + hits[q].x] == id[k];
        c->own_texel += (size_t)(hits[q].kind == LRT_HIT && hits[q].x == i0 && hits[q].y == j0);
        if (enters[q]) {
            ++c->entering;
            c->entering_self += (size_t)self;
            continue;
        }
        ++c->rays;
        c->joint_rays += (size_t)joint;
        c->self += (size_t)self;
        c->joint_self += (size_t)(self && joint);
    }
    free(rays);
    free(hits);
    free(from);
    free(enters);
}

static void test_no_self_hit(void)
{
    static const uint32_t sizes[] = {160, 256, 397};
    size_t s;
    counts total[SRC_COUNT];
    int src;
    memset(total, 0, sizeof total);
    for (s = 0; s < sizeof sizes / sizeof sizes[0]; ++s) {
        example_options o;
        example_frame f;
        scene_camera cam = scene_default_camera();
        float *an, *gb;
        int *id;
        size_t n, k;
        int m;
        example_default_options(&o);
        o.size = sizes[s];
        if (example_frame_load(&f, &o) != EXAMPLE_EXIT_OK) exit(2);
        n = (size_t)f.w * f.h;
        an = (float *)malloc(sizeof(float) * n * 3);
        gb = (float *)malloc(sizeof(float) * n * 3);
        id = (int *)malloc(sizeof(int) * n);
        if (!an || !gb || !id) exit(2);
        scene_render_normals((int)f.w, (int)f.h, &cam, an, id);
        for (k = 0; k < n; ++k) { /* 8-bit unorm per component, as an RGB8 G-buffer stores them */
            for (m = 0; m < 3; ++m) {
                const float b = floorf((an[3 * k + (size_t)m] * 0.5f + 0.5f) * 255.0f + 0.5f);
                gb[3 * k + (size_t)m] = b / 255.0f * 2.0f - 1.0f;
            }
            surface_normalize(&gb[3 * k]);
        }
        for (src = 0; src < SRC_COUNT; ++src)
            frame_rays(&f, id, src == SRC_DEPTH ? f.nrm : src == SRC_ANALYTIC ? an : gb, an, &total[src]);
        free(an);
        free(gb);
        free(id);
        example_frame_free(&f);
    }
    for (src = 0; src < SRC_COUNT; ++src) {
        const counts *c = &total[src];
        printf("  %-8s normals: %zu rays leave their surface, %zu meet it again (%zu of them at joints, of %zu rays "
               "there); %zu go into it along a wrong normal, %zu of them meet it; %zu hit their own texel\n",
               src_names[src], c->rays, c->self, c->joint_self, c->joint_rays, c->entering, c->entering_self,
               c->own_texel);
        CHECK(c->rays > 100000 && c->joint_rays > 1000, "%s normals: too few rays to tell", src_names[src]);
        CHECK(c->own_texel == 0, "%s normals: %zu rays hit their own texel", src_names[src], c->own_texel);
        CHECK(c->self == 0, "%s normals: %zu of %zu rays that leave their surface meet it again", src_names[src],
              c->self, c->rays);
    }
}

/* A lifted ray to the sky reaches the far plane: the sky texel's top. From
   the ground texels of the bottom row towards the sky texels of the top row,
   each ray's end beyond the far plane (clipped there, depth 1). */
static void test_sky(void)
{
    example_options o;
    example_frame f;
    size_t sky = 0, reached = 0;
    uint32_t i;
    example_default_options(&o);
    o.size = 128;
    if (example_frame_load(&f, &o) != EXAMPLE_EXIT_OK) exit(2);
    for (i = 0; i < f.w; ++i) {
        const size_t k = (size_t)(f.h - 1) * f.w + i, top = (i * 7u) % f.w;
        const float *p = &f.pos[3 * k], far_point[3] = {(float)top + 0.5f, 0.5f, 1.0f};
        float to[3];
        lrt_ray ray;
        lrt_hit hit;
        if (f.depth[k] >= 1.0f || f.depth[top] < 1.0f || !lrt_camera_unproject(&f.camera, far_point, to)) continue;
        to[0] *= 3.0f, to[1] *= 3.0f, to[2] *= 3.0f; /* past the far plane: clipped onto it */
        if (!lrt_camera_surface_ray(&f.camera, p, &f.nrm[3 * k], to, f.lift[k], &ray)) continue;
        if (lrt_trace(&f.bvh, &f.lrt[0], &ray, &hit, 1, 0) != LRT_SUCCESS) exit(2);
        if (hit.kind == LRT_HIT && f.depth[(size_t)hit.y * f.w + hit.x] < 1.0f) continue; /* an object on the way */
        ++sky;
        reached += hit.kind == LRT_HIT && hit.face == LRT_FACE_TOP; /* (a sky texel: the objects left above) */
    }
    printf("  %zu lifted rays towards the sky, %zu of them hit a sky texel's top (depth 1)\n", sky, reached);
    CHECK(sky > 10 && reached == sky, "%zu of %zu lifted sky rays end short of the far plane", sky - reached, sky);
    example_frame_free(&f);
}

int main(int argc, char **argv)
{
    check_select(argc, argv);
    srand(20261202u);
    RUN_TEST(test_no_self_hit);
    RUN_TEST(test_sky);
    return check_summary();
}
