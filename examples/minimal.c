/* minimal.c - the least code that uses linear_rt: a depth array in, a few
   rays traced, hits printed. CPU only, no other file needed.
   cc -std=c99 -O2 examples/minimal.c -lm && ./a.out */
#define LINEAR_RT_IMPLEMENTATION
#include "../linear_rt.h"
#include <stdio.h>

int main(void)
{
    enum { W = 64, H = 48 };
    static float depth[H][W];
    int x, y, k;
    for (y = 0; y < H; ++y) /* a floor sloping away, and a wall at x = 40 */
        for (x = 0; x < W; ++x) depth[y][x] = x >= 40 && x < 44 ? 0.3f : 0.9f - 0.5f * (float)y / H;

    lrt_depth map = {depth, W, H, 0, LRT_FORMAT_FLOAT32, 0, NULL};
    lrt_bvh bvh = {0};
    lrt_result r = lrt_bvh_build(&bvh, &map, NULL, NULL);
    if (r != LRT_SUCCESS) {
        printf("build failed: %s\n", lrt_result_string(r));
        return 1;
    }
    /* origin (x, y, depth), tmin, direction, tmax: screen space, docs/MODEL.md */
    lrt_ray rays[3] = {
        {{10.5f, 20.5f, 0.0f}, 0.0f, {0.0f, 0.0f, 1.0f}, 1.0f},    /* straight into the screen */
        {{10.5f, 20.5f, 0.5f}, 0.0f, {50.0f, 0.0f, 0.0f}, 1.0f},   /* across, into the wall */
        {{10.5f, 20.5f, 0.2f}, 0.0f, {0.0f, -30.0f, 0.0f}, 1.0f},  /* up, over the floor */
    };
    lrt_hit hits[3];
    lrt_trace(&bvh, &map, rays, hits, 3, 0);
    for (k = 0; k < 3; ++k) {
        if (hits[k].kind == LRT_HIT)
            printf("ray %d: hit texel (%u, %u) at t = %g\n", k, hits[k].x, hits[k].y, hits[k].t);
        else
            printf("ray %d: miss (%s)\n", k, hits[k].kind == LRT_MISS_OFF_SCREEN ? "left the screen" : "reached tmax");
    }
    lrt_bvh_destroy(&bvh);
    return 0;
}
