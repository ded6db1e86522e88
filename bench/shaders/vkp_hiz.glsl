// vkp_hiz.glsl - the Hi-Z chain: levels 1.. in aux at pc.offsets[k], level 0
// the depth map itself.
layout(set = 0, binding = 4, std430) buffer VkpMips { float f[]; } vkp_mips;

uint vkp_level_width(uint k) { return (pc.width + (1u << k) - 1u) >> k; }
uint vkp_level_height(uint k) { return (pc.height + (1u << k) - 1u) >> k; }

float vkp_hiz_at(uint k, uint x, uint y)
{
    if (k == 0u) return vkp_depth_at(x, y);
    return vkp_mips.f[pc.offsets[k] + y * vkp_level_width(k) + x];
}
