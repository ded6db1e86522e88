/* bench/scenes.h - the depth maps of the benchmark's five scenes, in float,
   0 near: 0 "yard" (examples/scene.h's scene from its default camera),
   1 "poles" (thin features), 2 "terraces" (8-bit steps facing the camera),
   3 "noise" (the worst case for culling), 4 "yard back" (the yard, and in
   *back its back-face depth: the back-map thickness model). bench/main.c
   measures on them; tests/test_paths.c holds every build of linear_rt.h
   (compiler, flags, language) to the same answers on them. Include after
   examples/scene.h. rnd01 draws the noise, so that the benchmark's maps stay
   those of its published runs. */
#ifndef LINEAR_RT_BENCH_SCENES_H
#define LINEAR_RT_BENCH_SCENES_H

#include <math.h>
#include <stdint.h>

#define BENCH_SCENE_COUNT 5
static const char *const bench_scene_names[BENCH_SCENE_COUNT] = {"yard", "poles", "terraces", "noise", "yard back"};

/* depth: w * h floats; back: the same for the yard back (kind 4), else unused */
static void bench_scene_depth(int kind, uint32_t w, uint32_t h, float *depth, float *back, float (*rnd01)(void))
{
    uint32_t i, j;
    if (kind == 0 || kind == 4) {
        scene_camera cam = scene_default_camera();
        scene_render((int)w, (int)h, &cam, depth, NULL);
        if (kind == 4) scene_render_back((int)w, (int)h, &cam, back);
        return;
    }
    for (j = 0; j < h; ++j)
        for (i = 0; i < w; ++i) {
            float floor_d = 0.55f + 0.44f * (float)j / (float)h, d = floor_d;
            if (kind == 1) { /* 1-texel poles on a floor, and a few 2-texel ones */
                if (i % 37u == 11u && j < h * 3u / 4u) d = 0.35f + 0.1f * (float)(i % 5u) / 5.0f;
                if (i % 53u >= 20u && i % 53u <= 21u && j < h / 2u) d = 0.25f;
            } else if (kind == 2) { /* camera-facing terraces of 8-bit depth */
                d = floorf((0.4f + 0.5f * (float)((i / 24u + j / 16u) % 9u) / 9.0f) * 255.0f) / 255.0f;
            } else {
                d = 0.3f + 0.7f * rnd01();
            }
            depth[j * w + i] = d;
        }
}

#endif
