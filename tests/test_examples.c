/* tests/test_examples.c - the examples are tests too.

   - the camera helpers of linear_rt.h (lrt_perspective, lrt_camera_*):
     round trips, near/far clipping, reversed Z, bad matrices;
   - examples/ssr.c, ao.c, shadows.c on a small embedded scene: every
     reflection and shadow ray agrees with the exact reference
     (tests/support/reference.h), the AO of an open floor is near zero and of the
     corner where a box meets the floor is not;
   - the example programs themselves (build/ssr, ao, shadows, minimal): the
     pictures they write have the frame's size; a user's depth file that is
     missing, truncated, of the wrong size or corrupt gives the one-line
     message and exit code 2; a good PFM and raw file work.
   Run from the repository root (make test-examples). */
#include "../examples/example.h"
#define EXAMPLE_NO_MAIN
#include "../examples/ao.c"
#include "../examples/shadows.c"
#include "../examples/ssr.c"
#include "support/check.h"
#include "support/reference.h"

#define SIZE 96u
#define DIR "build/examples_test"

/* Every ray of a batch against the reference; returns the disagreements. */
static size_t judge(const example_frame *f, const lrt_ray *rays, const lrt_hit *hits, size_t n, int any_hit,
                    const char *what)
{
    ref_map m;
    size_t k, bad = 0;
    if (ref_map_from_raw(&m, f->depth, (int)f->w, (int)f->h, 0, REF_FORMAT_FLOAT32, 0) != 0) return n;
    if ((f->back && ref_map_set_back_from_raw(&m, f->back, 0, REF_FORMAT_FLOAT32, 0) != 0) ||
        (f->options.thickness == LRT_THICKNESS_CONSTANT &&
         ref_map_set_back_constant(&m, f->options.thickness_value, f->options.near_z, f->options.far_z) != 0) ||
        (f->options.thickness == LRT_THICKNESS_RELATIVE &&
         ref_map_set_back_relative(&m, f->options.thickness_value, f->options.near_z, f->options.far_z) != 0)) {
        ref_map_free(&m);
        return n;
    }
    for (k = 0; k < n; ++k) {
        ref_ray q = ref_ray_of(&rays[k]);
        ref_answer a;
        char why[256];
        a.kind = (int)hits[k].kind;
        a.t = hits[k].t;
        a.x = (int)hits[k].x;
        a.y = (int)hits[k].y;
        a.face = (int)hits[k].face;
        if (!ref_check(&m, &q, &a, any_hit, why, sizeof why)) {
            if (bad++ < 3) printf("  %s ray %lu: %s\n", what, (unsigned long)k, why);
        }
    }
    ref_map_free(&m);
    return bad;
}

static void test_camera(void)
{
    const float pi = 3.14159265358979f;
    float proj[16], rproj[16], sing[16], v[3], s[3], s2[3], back[3];
    lrt_camera cam, rcam;
    lrt_ray ray;
    lrt_hit hit;
    lrt_bvh bvh = {0};
    float depth[4] = {0.5f, 0.5f, 0.5f, 0.5f};
    lrt_depth map = {depth, 2, 2, 0, LRT_FORMAT_FLOAT32, 0, NULL};
    int k;
    lrt_perspective(proj, 60.0f * pi / 180.0f, 1.5f, 0.1f, 100.0f, 0);
    lrt_perspective(rproj, 60.0f * pi / 180.0f, 1.5f, 0.1f, 100.0f, LRT_DEPTH_REVERSED_Z);
    CHECK(lrt_camera_init(&cam, proj, 300, 200, 0) == LRT_SUCCESS, "camera init");
    CHECK(lrt_camera_init(&rcam, rproj, 300, 200, LRT_DEPTH_REVERSED_Z) == LRT_SUCCESS, "reversed camera init");

    /* the near plane is depth 0, the far plane 1; the view axis is the centre */
    v[0] = 0.0f; v[1] = 0.0f; v[2] = -0.1f;
    CHECK(lrt_camera_project(&cam, v, s) && fabsf(s[0] - 150.0f) < 1e-3f && fabsf(s[1] - 100.0f) < 1e-3f &&
              fabsf(s[2]) < 1e-6f, "near point projects to (150, 100, 0): %g %g %g", s[0], s[1], s[2]);
    v[2] = -100.0f;
    CHECK(lrt_camera_project(&cam, v, s) && fabsf(s[2] - 1.0f) < 1e-6f, "far point at depth 1: %g", s[2]);
    /* view y up is screen row 0 up; x right is column right */
    v[0] = 1.0f; v[1] = 1.0f; v[2] = -5.0f;
    CHECK(lrt_camera_project(&cam, v, s) && s[0] > 150.0f && s[1] < 100.0f, "up-right is up-right: %g %g", s[0], s[1]);
    /* reversed Z gives the same screen point (z is always 0 near) */
    CHECK(lrt_camera_project(&rcam, v, s2) && fabsf(s2[0] - s[0]) < 1e-3f && fabsf(s2[1] - s[1]) < 1e-3f &&
              fabsf(s2[2] - s[2]) < 1e-5f, "reversed Z projects alike: %g vs %g", s2[2], s[2]);
    CHECK(lrt_camera_unproject(&cam, s, back) && fabsf(back[0] - 1.0f) < 1e-4f && fabsf(back[1] - 1.0f) < 1e-4f &&
              fabsf(back[2] + 5.0f) < 1e-3f, "unproject(project(p)) = p: %g %g %g", back[0], back[1], back[2]);
    CHECK(lrt_camera_unproject(&rcam, s2, back) && fabsf(back[2] + 5.0f) < 1e-3f, "reversed round trip: %g", back[2]);
    v[2] = 3.0f;
    CHECK(!lrt_camera_project(&cam, v, s), "a point behind the eye does not project");

    /* a segment from in front to behind the eye is clipped at the near plane */
    {
        float from[3] = {0.0f, 0.0f, -2.0f}, to[3] = {0.0f, 0.0f, 2.0f};
        CHECK(lrt_camera_segment(&cam, from, to, &ray) == 1, "clipped segment");
        CHECK(fabsf(ray.origin[2] + ray.dir[2]) < 1e-6f && ray.tmin == 0.0f && ray.tmax == 1.0f,
              "clipped end at depth 0: %g", ray.origin[2] + ray.dir[2]);
        from[2] = 1.0f;
        CHECK(lrt_camera_segment(&cam, from, to, &ray) == 0 && ray.origin[0] != ray.origin[0],
              "wholly behind the eye: 0 and a NaN ray");
        CHECK(lrt_bvh_build(&bvh, &map, NULL, NULL) == LRT_SUCCESS, "build 2x2");
        CHECK(lrt_trace(&bvh, &map, &ray, &hit, 1, 0) == LRT_SUCCESS && hit.kind == LRT_MISS_INVALID_RAY,
              "the NaN ray is an invalid ray");
        lrt_bvh_destroy(&bvh);
        from[2] = -50.0f;
        to[2] = -500.0f;
        CHECK(lrt_camera_segment(&cam, from, to, &ray) == 1 && fabsf(ray.origin[2] + ray.dir[2] - 1.0f) < 1e-6f,
              "clipped at the far plane: %g", ray.origin[2] + ray.dir[2]);
        from[0] = NAN;
        CHECK(lrt_camera_segment(&cam, from, to, &ray) == 0, "NaN input: no ray");
    }
    /* bad cameras get result codes */
    memset(sing, 0, sizeof sing);
    CHECK(lrt_camera_init(&cam, sing, 4, 4, 0) == LRT_ERROR_INVALID_CAMERA, "singular matrix");
    memcpy(sing, proj, sizeof sing);
    sing[5] = NAN;
    CHECK(lrt_camera_init(&cam, sing, 4, 4, 0) == LRT_ERROR_INVALID_CAMERA, "NaN matrix");
    CHECK(lrt_camera_init(NULL, proj, 4, 4, 0) == LRT_ERROR_NULL_POINTER, "NULL camera");
    CHECK(lrt_camera_init(&cam, NULL, 4, 4, 0) == LRT_ERROR_NULL_POINTER, "NULL matrix");
    CHECK(lrt_camera_init(&cam, proj, 0, 4, 0) == LRT_ERROR_INVALID_SIZE, "zero width");
    CHECK(lrt_camera_init(&cam, proj, 4, LINEAR_RT_MAX_DIM + 1, 0) == LRT_ERROR_INVALID_SIZE, "height too large");
    CHECK(lrt_camera_init(&cam, proj, 4, 4, 2) == LRT_ERROR_INVALID_OPTION, "unknown flag");
    CHECK(!lrt_camera_segment(NULL, NULL, NULL, &ray) && !lrt_camera_project(NULL, v, s) &&
              !lrt_camera_unproject(NULL, s, v), "NULL camera: nothing");
    for (k = 0; k < 16; ++k) rproj[k] = (float)(k == 0 || k == 5 || k == 10 || k == 15); /* identity: orthographic */
    CHECK(lrt_camera_init(&cam, rproj, 10, 10, 0) == LRT_SUCCESS, "orthographic camera");
    v[0] = 0.0f; v[1] = 0.0f; v[2] = 0.25f;
    CHECK(lrt_camera_project(&cam, v, s) && fabsf(s[0] - 5.0f) < 1e-6f && fabsf(s[2] - 0.25f) < 1e-6f,
          "orthographic projection");
}

/* The scene's texel centres unproject to view points that project back. */
static void test_frame(const example_frame *f)
{
    size_t k, n = (size_t)f->w * f->h, worst = 0, floor_up = 0, floor = 0;
    float err = 0.0f;
    float up[3] = {f->view_from_world[1], f->view_from_world[4], f->view_from_world[7]};
    for (k = 0; k < n; ++k) {
        float s[3];
        if (f->depth[k] >= 1.0f) continue;
        if (lrt_camera_project(&f->camera, &f->pos[3 * k], s)) {
            float e = fabsf(s[0] - ((float)(k % f->w) + 0.5f)) + fabsf(s[1] - ((float)(k / f->w) + 0.5f));
            if (e > err) { err = e; worst = k; }
        }
        /* the floor: rows in the bottom quarter are floor in the embedded scene's open middle */
        if (k / f->w > f->h * 7 / 8) {
            ++floor;
            floor_up += surface_dot(&f->nrm[3 * k], up) > 0.99f;
        }
    }
    CHECK(err < 1e-2f, "positions project back to texel centres (worst %g texels at %lu)", err, (unsigned long)worst);
    CHECK(floor > 0 && floor_up * 10 >= floor * 8, "bottom rows' normals face up: %lu of %lu", (unsigned long)floor_up,
          (unsigned long)floor);
}

/* texel of a world point of the embedded scene */
static size_t texel_of(const example_frame *f, float x, float y, float z)
{
    scene_camera cam = scene_default_camera();
    float p[3] = {x, y - cam.height, z}, v[3], s[3];
    int r;
    for (r = 0; r < 3; ++r) v[r] = f->view_from_world[3 * r] * p[0] + f->view_from_world[3 * r + 1] * p[1] + f->view_from_world[3 * r + 2] * p[2];
    if (!lrt_camera_project(&f->camera, v, s)) return (size_t)-1;
    return (size_t)s[1] * f->w + (size_t)s[0];
}

/* returns how many reflection rays hit (infinite thickness) */
static size_t test_effects(const example_frame *f)
{
    size_t n = (size_t)f->w * f->h, k, hit = 0, open, corner;
    lrt_ray *rays = (lrt_ray *)malloc(n * AO_RAYS * sizeof *rays);
    lrt_hit *hits = (lrt_hit *)malloc(n * AO_RAYS * sizeof *hits);
    float *occ = (float *)malloc(n * sizeof *occ);
    uint8_t *img = (uint8_t *)malloc(n * 3);
    if (!rays || !hits || !occ || !img) {
        CHECK(0, "out of memory");
        return 0;
    }
    ssr_make_rays(f, rays, 2);
    example_trace(f, rays, hits, f->w, 0, 2, NULL);
    for (k = 0; k < n; ++k) hit += hits[k].kind == LRT_HIT;
    CHECK(judge(f, rays, hits, n, 0, "reflection") == 0, "every reflection ray agrees with the reference");
    CHECK(hit * 10 > n, "reflections hit something: %lu of %lu", (unsigned long)hit, (unsigned long)n);
    ssr_shade(f, hits, img);

    shadows_make_rays(f, rays, SHADOW_LENGTH, 2);
    example_trace(f, rays, hits, f->w, 0, 2, NULL);
    CHECK(judge(f, rays, hits, n, 1, "shadow") == 0, "every shadow ray agrees with the reference (any hit)");

    ao_make_rays(f, rays, AO_RADIUS, 2);
    example_trace(f, rays, hits, (size_t)f->w * AO_RAYS, 0, 2, NULL);
    CHECK(judge(f, rays, hits, n * AO_RAYS, 1, "ao") == 0, "every AO ray agrees with the reference (any hit)");
    ao_occlusion(f, hits, occ);
    /* open floor: nothing within the AO radius; the corner: the floor just
       in front of the foot of the red box (x -3 .. -1.2, front face z = -7) */
    open = texel_of(f, 1.0f, 0.0f, -3.0f);
    corner = texel_of(f, -2.1f, 0.0f, -6.93f);
    CHECK(open < n && occ[open] >= 0.0f && occ[open] < 0.1f, "open floor AO near 0: %g",
          open < n ? (double)occ[open] : -1.0);
    CHECK(corner < n && occ[corner] > 0.25f, "the box's foot is occluded: %g", corner < n ? (double)occ[corner] : -1.0);
    free(rays);
    free(hits);
    free(occ);
    free(img);
    return hit;
}

/* ---- the programs ------------------------------------------------------------------ */
static int run(const char *cmd, char *out, size_t out_size)
{
    char line[1024];
    FILE *f;
    int rc;
    snprintf(line, sizeof line, "%s > " DIR "/stdout.txt 2>&1", cmd);
    rc = system(line);
    rc = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
    out[0] = 0;
    if ((f = fopen(DIR "/stdout.txt", "rb")) != NULL) {
        size_t got = fread(out, 1, out_size - 1, f);
        out[got] = 0;
        fclose(f);
    }
    return rc;
}

static void write_file(const char *path, const void *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (f) {
        fwrite(data, 1, size, f);
        fclose(f);
    }
}

static int png_size(const char *path, int *w, int *h)
{
    unsigned char *bytes;
    size_t size;
    char why[256];
    int c, ok;
    if (depth_file_read(path, &bytes, &size, why, sizeof why)) return 0;
    ok = stbi_info_from_memory(bytes, (int)size, w, h, &c);
    free(bytes);
    return ok;
}

/* Reflections in a thick depth layer (a constant thickness, the scene's
   back faces, a relative thickness): every ray exact against the reference
   with the same model, and fewer hits than with infinite thickness, as
   rays now pass behind objects. */
static void test_thickness(size_t infinite_hits)
{
    static const char *names[3] = {"0.3 m", "back faces", "5%"};
    int mode;
    for (mode = 0; mode < 3; ++mode) {
        example_options o;
        example_frame f;
        size_t n, k, hit = 0, top = 0;
        lrt_ray *rays;
        lrt_hit *hits;
        example_default_options(&o);
        o.size = SIZE;
        if (mode == 1) o.thickness_back = 1;
        else o.thickness = mode ? 0.05f : 0.3f;
        o.thickness_relative = mode == 2;
        if (example_frame_load(&f, &o) != EXAMPLE_EXIT_OK) {
            CHECK(0, "thickness %d: frame", mode);
            continue;
        }
        n = (size_t)f.w * f.h;
        rays = (lrt_ray *)malloc(n * sizeof *rays);
        hits = (lrt_hit *)malloc(n * sizeof *hits);
        if (rays && hits) {
            static const uint32_t models[3] = {LRT_THICKNESS_CONSTANT, LRT_THICKNESS_BACK_MAP, LRT_THICKNESS_RELATIVE};
            size_t back = 0;
            CHECK(f.bvh.layout.thickness == models[mode], "%s: built with model %u", names[mode], f.bvh.layout.thickness);
            for (k = 0; mode == 1 && k < n; ++k) back += f.back[k] < 1.0f && f.back[k] > f.depth[k];
            CHECK(mode != 1 || back > n / 20, "back faces: a back map with depth in it (%lu texels)", (unsigned long)back);
            ssr_make_rays(&f, rays, 2);
            example_trace(&f, rays, hits, f.w, 0, 2, NULL);
            for (k = 0; k < n; ++k) {
                hit += hits[k].kind == LRT_HIT;
                top += hits[k].kind == LRT_HIT && hits[k].face == LRT_FACE_TOP;
            }
            CHECK(judge(&f, rays, hits, n, 0, names[mode]) == 0,
                  "%s: every reflection ray in a thick layer agrees with the reference", names[mode]);
            CHECK(hit < infinite_hits && top > 0, "%s: %lu hits (%lu on a top face), fewer than infinite thickness's %lu",
                  names[mode], (unsigned long)hit, (unsigned long)top, (unsigned long)infinite_hits);
        }
        free(rays);
        free(hits);
        example_frame_free(&f);
    }
    { /* a back-face depth exists for the embedded scene only */
        char out[512];
        int rc = run("build/ssr --depth " DIR "/good.pfm --thickness back --out " DIR "/pics", out, sizeof out);
        CHECK(rc == EXAMPLE_EXIT_BAD_INPUT && strstr(out, "--thickness back"), "--thickness back with a file: exit %d: %s",
              rc, out);
        rc = run("build/ssr --size 40 --thickness -1 --out " DIR "/pics", out, sizeof out);
        CHECK(rc == EXAMPLE_EXIT_BAD_INPUT && strstr(out, "--thickness: bad value"), "a negative thickness: exit %d: %s",
              rc, out);
        rc = run("build/ssr --size 40 --thickness x% --out " DIR "/pics", out, sizeof out);
        CHECK(rc == EXAMPLE_EXIT_BAD_INPUT && strstr(out, "--thickness: bad value"), "a bad share: exit %d: %s", rc, out);
    }
}

static void test_programs(void)
{
    char out[4096], cmd[512];
    int w = 0, h = 0, rc;
    float pfm_data[32 * 24];
    char header[64];
    unsigned char pfm[sizeof header + sizeof pfm_data];
    size_t k, hl;
    const char *progs[3] = {"ssr", "ao", "shadows"}, *pics[3] = {"ssr.png", "ao.png", "shadows.png"};

    rc = run("build/minimal", out, sizeof out);
    CHECK(rc == 0 && strstr(out, "ray 1: hit texel (40, 20)") && strstr(out, "ray 2: miss (left the screen)"),
          "minimal prints its hits: rc %d: %s", rc, out);
    for (k = 0; k < 3; ++k) {
        snprintf(cmd, sizeof cmd, "build/%s --size 40 --out " DIR "/pics40", progs[k]);
        rc = run(cmd, out, sizeof out);
        snprintf(cmd, sizeof cmd, DIR "/pics40/%s", pics[k]);
        CHECK(rc == 0 && png_size(cmd, &w, &h) && w == 40 && h == 40, "%s writes a 40x40 picture: rc %d, %dx%d: %s",
              progs[k], rc, w, h, out);
    }

    /* a good PFM (32x24, a floor) and the same as raw floats */
    for (k = 0; k < 32 * 24; ++k) pfm_data[k] = 0.5f + 0.4f * (float)(k / 32) / 24.0f;
    hl = (size_t)snprintf(header, sizeof header, "Pf\n32 24\n-1.0\n");
    memcpy(pfm, header, hl);
    memcpy(pfm + hl, pfm_data, sizeof pfm_data); /* little-endian host assumed, as the -1.0 scale says */
    write_file(DIR "/good.pfm", pfm, hl + sizeof pfm_data);
    rc = run("build/ssr --depth " DIR "/good.pfm --out " DIR "/pics", out, sizeof out);
    CHECK(rc == 0 && png_size(DIR "/pics/ssr.png", &w, &h) && w == 32 && h == 24, "a PFM frame: rc %d, %dx%d: %s", rc, w,
          h, out);
    write_file(DIR "/good.raw", pfm_data, sizeof pfm_data);
    rc = run("build/ao --depth " DIR "/good.raw --width 32 --height 24 --reversed-z --out " DIR "/pics", out, sizeof out);
    CHECK(rc == 0, "a raw float frame, reversed Z: rc %d: %s", rc, out);

    /* bad files: exit 2 and one line naming the file and the problem */
    {
        static const struct {
            const char *args, *expect;
        } bad[] = {
            {"--depth " DIR "/missing.png", DIR "/missing.png: cannot open"},
            {"--depth " DIR "/short.pfm", DIR "/short.pfm: truncated PFM: 32x24 needs 3072 bytes of data, has 100"},
            {"--depth " DIR "/good.raw --width 33 --height 24", DIR "/good.raw: wrong size for 33x24 raw floats"},
            {"--depth " DIR "/good.raw", DIR "/good.raw: raw float depth needs --width and --height"},
            {"--depth " DIR "/corrupt.png", DIR "/corrupt.png: "},
            {"--depth " DIR "/bad.pfm", DIR "/bad.pfm: PFM width missing or outside 1..16384"},
            {"--depth " DIR "/good.pfm --color " DIR "/pics40/ssr.png", DIR "/pics40/ssr.png: colour is 40x40, the depth 32x24"},
            {"--size 0", "--size: bad value '0'"},
        };
        unsigned char png_head[64] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R',
                                      0, 0, 0, 8, 0, 0, 0, 8, 8, 0, 0, 0, 0};
        write_file(DIR "/short.pfm", pfm, hl + 100);
        write_file(DIR "/corrupt.png", png_head, sizeof png_head);
        write_file(DIR "/bad.pfm", "Pf\n0 24\n-1.0\n", 14);
        for (k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
            char *nl;
            snprintf(cmd, sizeof cmd, "build/ssr %s --out " DIR "/pics", bad[k].args);
            rc = run(cmd, out, sizeof out);
            nl = strchr(out, '\n');
            CHECK(rc == EXAMPLE_EXIT_BAD_INPUT && strncmp(out, bad[k].expect, strlen(bad[k].expect)) == 0 && nl &&
                      nl[1] == 0,
                  "bad input '%s': exit %d, one line starting '%s': got '%s'", bad[k].args, rc, bad[k].expect, out);
        }
    }
}

int main(int argc, char **argv)
{
    example_options o;
    example_frame f;
    size_t refl_hits = 0;
    check_select(argc, argv);
    mkdir("build", 0777);
    mkdir(DIR, 0777);
    RUN_TEST(test_camera);
    { /* test_frame and test_effects need the embedded frame, test_thickness its reflections' hits */
        const int frame = check_wanted("test_frame"), effects = check_wanted("test_effects");
        const int thick = check_wanted("test_thickness");
        if (frame || effects || thick) {
            example_default_options(&o);
            o.size = SIZE;
            CHECK(example_frame_load(&f, &o) == EXAMPLE_EXIT_OK, "embedded scene frame");
            if (frame) test_frame(&f);
            refl_hits = test_effects(&f);
            example_frame_free(&f);
        }
        RUN_TEST(test_programs);
        if (thick) test_thickness(refl_hits);
    }
    return check_summary();
}
