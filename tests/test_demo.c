/* tests/test_demo.c - the demo's CPU answers judged by the exact reference.

   build/demo --dump FILE writes the map it traced, its rays and its CPU's
   hits (the 1-thread trace; the demo itself holds the 2-thread trace and
   the GPU's to those, bit for bit). This program reads FILE and holds the
   hits to tests/support/reference.h (ref_check, closest hit: docs/MODEL.md's
   "Right, and how right"): every primary ray, and a fixed, evenly spread
   sample of SEGMENT_SAMPLE segments (every one of them where there are no
   more; make test-demo's 128x128 has 16384). It also checks that FILE holds
   the demo's workload: the map is examples/scene.h's default scene at that
   size (within rounding), and the primary rays are one per texel centre, straight into the
   depth over [0, 1].
     build/test_demo FILE     (make test-demo runs the demo, then this)
   Ends with "N passed, M failed"; exit 1 on a failure, 2 on a bad file. */
#include "../linear_rt.h"
#include "../examples/scene.h"
#include "support/reference.h"
#include "support/check.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SEGMENT_SAMPLE 20000u

typedef struct answers {
    uint32_t w, h;
    size_t n;
    float *depth;
    lrt_ray *prim, *seg;
    lrt_hit *prim_hits, *seg_hits;
} answers;

static void answers_free(answers *a)
{
    free(a->depth);
    free(a->prim);
    free(a->seg);
    free(a->prim_hits);
    free(a->seg_hits);
    memset(a, 0, sizeof *a);
}

/* Reads the demo's --dump file (examples/demo.c, dump_answers); 0 on success. */
static int answers_load(const char *path, answers *a)
{
    char magic[8];
    uint32_t head[4];
    long end;
    FILE *f = fopen(path, "rb");
    int bad;
    memset(a, 0, sizeof *a);
    if (!f) {
        printf("%s: cannot open\n", path);
        return 1;
    }
    if (fread(magic, 1, 8, f) != 8 || memcmp(magic, "LRTDEMO1", 8) != 0 || fread(head, sizeof head, 1, f) != 1 ||
        head[0] < 1 || head[0] > LINEAR_RT_MAX_DIM || head[1] < 1 || head[1] > LINEAR_RT_MAX_DIM ||
        head[2] != sizeof(lrt_ray) || head[3] != sizeof(lrt_hit)) {
        printf("%s: not a build/demo --dump file of this build\n", path);
        fclose(f);
        return 1;
    }
    a->w = head[0];
    a->h = head[1];
    a->n = (size_t)a->w * a->h;
    a->depth = (float *)malloc(a->n * sizeof *a->depth);
    a->prim = (lrt_ray *)malloc(a->n * sizeof *a->prim);
    a->seg = (lrt_ray *)malloc(a->n * sizeof *a->seg);
    a->prim_hits = (lrt_hit *)malloc(a->n * sizeof *a->prim_hits);
    a->seg_hits = (lrt_hit *)malloc(a->n * sizeof *a->seg_hits);
    bad = !a->depth || !a->prim || !a->seg || !a->prim_hits || !a->seg_hits ||
          fread(a->depth, sizeof *a->depth, a->n, f) != a->n || fread(a->prim, sizeof *a->prim, a->n, f) != a->n ||
          fread(a->prim_hits, sizeof *a->prim_hits, a->n, f) != a->n || fread(a->seg, sizeof *a->seg, a->n, f) != a->n ||
          fread(a->seg_hits, sizeof *a->seg_hits, a->n, f) != a->n;
    end = ftell(f);
    if (!bad && (fseek(f, 0, SEEK_END) != 0 || ftell(f) != end)) bad = 1; /* nothing after the answers */
    fclose(f);
    if (bad) {
        printf("%s: truncated, too long, or out of memory (%ux%u)\n", path, a->w, a->h);
        answers_free(a);
        return 1;
    }
    return 0;
}

/* Is this answer right for this ray, by docs/MODEL.md's rule? */
static int judge(const ref_map *m, const lrt_ray *r, const lrt_hit *h, char *why, size_t why_size)
{
    ref_ray q;
    ref_answer a;
    int c;
    for (c = 0; c < 3; ++c) {
        q.o[c] = r->origin[c];
        q.v[c] = r->dir[c];
    }
    q.tmin = r->tmin;
    q.tmax = r->tmax;
    a.kind = (int)h->kind;
    a.t = h->t;
    a.x = h->kind == LRT_HIT ? (int)h->x : -1;
    a.y = h->kind == LRT_HIT ? (int)h->y : -1;
    a.face = (int)h->face;
    return ref_check(m, &q, &a, 0, why, why_size);
}

/* The rays of a fixed, evenly spread sample (ray k * count / sample) against
   the reference; returns how many agree. */
static size_t check_rays(const ref_map *m, const lrt_ray *rays, const lrt_hit *hits, size_t count, size_t sample,
                         const char *name)
{
    size_t k, agree = 0, shown = 0;
    if (sample > count) sample = count;
    for (k = 0; k < sample; ++k) {
        size_t i = (size_t)(((double)k * (double)count) / (double)sample);
        char why[1024];
        if (judge(m, &rays[i], &hits[i], why, sizeof why)) {
            ++agree;
        } else if (shown++ < 5) {
            printf("  DISAGREE %s ray %lu o=(%.9g %.9g %.9g) d=(%.9g %.9g %.9g) [%.9g, %.9g]: %s\n", name,
                   (unsigned long)i, (double)rays[i].origin[0], (double)rays[i].origin[1], (double)rays[i].origin[2],
                   (double)rays[i].dir[0], (double)rays[i].dir[1], (double)rays[i].dir[2], (double)rays[i].tmin,
                   (double)rays[i].tmax, why);
        }
    }
    return agree;
}

/* The demo's workload: its scene at that size, its primary rays. */
static void check_workload(const answers *a)
{
    scene_camera cam = scene_default_camera();
    float *scene = (float *)malloc(a->n * sizeof *scene);
    size_t i, j, wrong = 0, hits = 0, off = 0;
    CHECK(a->w == a->h, "the demo's map is square: %ux%u", a->w, a->h);
    if (scene && a->w == a->h) {
        /* within rounding: the scene's float maths gives other last bits under
           other flags (-O0, -ffp-contract=fast: 1.3e-6 at most); a texel on a
           silhouette may even see another object */
        scene_render((int)a->w, (int)a->h, &cam, scene, NULL);
        for (i = 0; i < a->n; ++i) off += !(fabsf(scene[i] - a->depth[i]) <= 1e-5f);
        CHECK(off <= a->n / 1000, "the map is not examples/scene.h's scene at %ux%u: %lu texels off by more than 1e-5",
              a->w, a->h, (unsigned long)off);
    }
    free(scene);
    for (j = 0; j < a->h; ++j)
        for (i = 0; i < a->w; ++i) {
            const lrt_ray *r = &a->prim[j * a->w + i];
            wrong += !(r->origin[0] == (float)i + 0.5f && r->origin[1] == (float)j + 0.5f && r->origin[2] == 0.0f &&
                       r->dir[0] == 0.0f && r->dir[1] == 0.0f && r->dir[2] == 1.0f && r->tmin == 0.0f && r->tmax == 1.0f);
        }
    CHECK(wrong == 0, "%lu primary rays are not the demo's (one per texel centre, straight into the depth)",
          (unsigned long)wrong);
    for (i = 0; i < a->n; ++i) hits += a->seg_hits[i].kind == LRT_HIT;
    /* the demo's segments end just behind a texel's depth: most hit */
    CHECK(hits > a->n / 2, "only %lu of %lu segments hit", (unsigned long)hits, (unsigned long)a->n);
}

int main(int argc, char **argv)
{
    answers a;
    ref_map m;
    size_t sample, agree_p, agree_s;
    if (argc != 2) {
        printf("usage: %s FILE   (FILE: build/demo --dump FILE)\n", argv[0]);
        return 2;
    }
    if (answers_load(argv[1], &a) != 0) return 2;
    printf("test_demo: %s: the demo's %ux%u answers\n", argv[1], a.w, a.h);
    check_workload(&a);
    if (ref_map_from_raw(&m, a.depth, (int)a.w, (int)a.h, 0, REF_FORMAT_FLOAT32, 0) != 0) {
        printf("ref_map_from_raw failed\n");
        answers_free(&a);
        return 1;
    }
    sample = a.n < SEGMENT_SAMPLE ? a.n : SEGMENT_SAMPLE;
    printf("agreement with the exact reference (tests/support/reference.h, closest hit)\n");
    agree_p = check_rays(&m, a.prim, a.prim_hits, a.n, a.n, "primary");
    printf("  primary rays, all %lu: agree: %lu / %lu\n", (unsigned long)a.n, (unsigned long)agree_p,
           (unsigned long)a.n);
    agree_s = check_rays(&m, a.seg, a.seg_hits, a.n, sample, "segment");
    printf("  segments, a fixed sample of %lu of %lu (the reference is slow on long segments): agree: %lu / %lu\n",
           (unsigned long)sample, (unsigned long)a.n, (unsigned long)agree_s, (unsigned long)sample);
    CHECK(agree_p == a.n, "%lu of %lu primary rays disagree with the reference", (unsigned long)(a.n - agree_p),
          (unsigned long)a.n);
    CHECK(agree_s == sample, "%lu of %lu sampled segments disagree with the reference",
          (unsigned long)(sample - agree_s), (unsigned long)sample);
    ref_map_free(&m);
    answers_free(&a);
    return check_summary();
}
