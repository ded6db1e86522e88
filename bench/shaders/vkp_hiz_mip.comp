#version 460
#extension GL_GOOGLE_include_directive : require
// vkp_hiz_mip.comp - one level of the Hi-Z chain: level k texel (x, y) is the
// minimum (nearest) depth of level k-1's texels (2x..2x+1, 2y..2y+1) that
// exist; level k is ceil(W / 2^k) x ceil(H / 2^k), level 0 the depth map.
// One invocation per texel of level pc.level (pc.ray_count of them).
#include "vkp_common.glsl"
#include "vkp_hiz.glsl"

void main()
{
    uint k = pc.level;
    uint idx = gl_GlobalInvocationID.x;
    if (idx >= pc.ray_count) return;
    uint w = vkp_level_width(k), x = idx % w, y = idx / w;
    uint ws = vkp_level_width(k - 1u), hs = vkp_level_height(k - 1u);
    uint x0 = 2u * x, y0 = 2u * y, x1 = min(x0 + 1u, ws - 1u), y1 = min(y0 + 1u, hs - 1u);
    float m = min(min(vkp_hiz_at(k - 1u, x0, y0), vkp_hiz_at(k - 1u, x1, y0)),
                  min(vkp_hiz_at(k - 1u, x0, y1), vkp_hiz_at(k - 1u, x1, y1)));
    vkp_mips.f[pc.offsets[k] + idx] = m;
}
