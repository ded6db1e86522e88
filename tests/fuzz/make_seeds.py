#!/usr/bin/env python3
"""tests/fuzz/make_seeds.py - writes the hand-made seeds of tests/fuzz/corpus/
(standard library only; deterministic). Run from the repository root:
    python3 tests/fuzz/make_seeds.py
Each seed is an input in the layout its harness reads (see the harness's
source); the fuzzers grow their own corpora from these in build/fuzz/."""
import os
import random
import struct
import zlib

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")
rng = random.Random(1234)


def write(harness, name, data):
    d = os.path.join(ROOT, harness)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(bytes(data))


# ---- fuzz_core: 16 header bytes, rays, then depth bytes ------------------------
def core(size_sel, wb, hb, fmt_sel, flag_sel, stride_sel, bits_sel, depth_mode, nrays, trace_sel, rect_sel, misc,
         rect, rays, depth, thickness=0, model=None):
    """thickness: fuzz_core.c's byte 16 (0: the infinite model, as before it existed).
    model: the CONSTANT or RELATIVE model instead (byte 16 is then made here), either
    (kind, value, near, far[, back]) with kind "constant" or "relative", the three floats
    written raw (far = inf: the INFINITY kind) and back True for a back map (a mismatch),
    or (byte16, [bytes]) for an encoding of one's own (read_model in fuzz_core.c)."""
    head = [size_sel, wb, hb, fmt_sel, flag_sel, stride_sel, bits_sel, depth_mode, nrays, trace_sel, rect_sel, misc]
    params = []
    if model is not None:
        assert bits_sel % 4 != 3, "node_bits_raw would come before the model's bytes"
        if isinstance(model[0], int):
            thickness, params = model[0], list(model[1])
        else:
            kind, value, near, far = model[:4]
            back = len(model) > 4 and model[4]
            thickness = 7 | (0x08 if kind == "relative" else 0) | (0x20 if back else 0) | 0x80  # any parameters
            far_inf = far == float("inf")
            pk = 3 | (3 << 2) | ((3 if far_inf else 5) << 4)  # value, near raw; far INFINITY or raw
            params = [pk] + floats([value, near] + ([] if far_inf else [far]))
    return head + list(rect) + [thickness] + params + rays + depth


def structured_rays(n, r=rng):
    out = []
    for _ in range(n):
        out += [0] + [r.randrange(256) for _ in range(8)]  # mask 0: eight one-byte components
    return out


def primary_rays(n, w, h, r=rng):
    """(i+0.5, j+0.5, 0) + t (0, 0, 1), t in [0, 1]: the headline workload"""
    out = []
    for _ in range(n):
        i, j = r.randrange(w), r.randrange(h)
        x = (4 * i + 2 + 4) * 256 // (4 * (w + 2))  # the harness maps b to quarter texels
        y = (4 * j + 2 + 4) * 256 // (4 * (h + 2))
        out += [0, x, y, 0, 0, 0, 0, 32, 16]  # z 0, tmin 0, v (0, 0, 32/256 ... ) tmax tmin + 1
    return out


def raw_rays(n, r=rng):
    out = []
    for _ in range(n):
        vals = [r.uniform(-10, 70), r.uniform(-10, 70), r.uniform(-0.5, 1.2), 0.0,
                r.uniform(-40, 40), r.uniform(-40, 40), r.uniform(-1, 1), r.choice([1.0, 3.0, 1e30])]
        out += [0xff] + list(struct.pack("<8f", *vals))
    return out


def floats(values):
    return list(struct.pack("<%df" % len(values), *values))


write("fuzz_core", "float-8x6-palette",
      core(0, 7, 5, 2, 0, 0, 0, 0x0e, 24, 0, 0x00, 0, (1, 1, 3, 2), structured_rays(24),
           floats([0.25, 0.5, 0.75, 1.0, 0.125, 0.9, 0.0, 0.6])))
write("fuzz_core", "unorm8-33x20-reversed-strided-anyhit",
      core(0, 32, 19, 0, 1, 4 | (5 << 3), 1, 0x01, 40, 1, 0x05, 1, (4, 3, 20, 9), structured_rays(40),
           [rng.randrange(256) for _ in range(700)]))
write("fuzz_core", "unorm16-64x64-whole-update",
      core(0, 63, 63, 1, 0, 0, 2, 0x1c, 32, 0, 0xc0, 2, (0, 0, 0, 0), primary_rays(16, 64, 64) + structured_rays(16),
           list(struct.pack("<16H", *[rng.randrange(65536) for _ in range(16)]))))
write("fuzz_core", "float-raw-rays-nan-depth",
      core(0, 20, 11, 2, 0, 5, 0, 0x03, 12, 0, 0x10, 3, (2, 2, 5, 5), raw_rays(12),
           floats([0.3, float("nan"), 1.5, -0.25, float("inf"), 0.7, 0.999999, 1e-30])))
write("fuzz_core", "wide-200x3-16bit-nodes",
      core(7, 159, 2, 2, 0, 0, 2, 0x0a, 30, 1, 0x03, 0, (10, 0, 100, 3), structured_rays(30),
           floats([0.1, 0.4, 0.8, 1.0, 0.55, 0.2])))
write("fuzz_core", "invalid-format-and-flags",
      core(0, 9, 9, 0xf3, 0x85, 6 | (3 << 3), 3, 0, 4, 0xd3, 0x20, 0xfc, (200, 7, 0x90, 1),
           [12, 0, 0, 0] + structured_rays(4), [1, 2, 3]))
write("fuzz_core", "size-limit-one-row",
      core(0xc0, 1, 0, 0, 0, 0, 0, 0x02, 8, 0, 0, 0, (0, 0, 0, 0), structured_rays(8), [0, 128, 255]))

# the constant and relative thickness models (their own random stream: the seeds
# above and below stay as they were)
mrng = random.Random(5678)
write("fuzz_core", "model-constant-float-24x16-palette",
      core(0, 23, 15, 2, 0, 0, 0, 0x0e, 48, 0, 0x00, 0, (2, 3, 10, 6),
           primary_rays(16, 24, 16, mrng) + structured_rays(24, mrng) + raw_rays(8, mrng),
           floats([0.9, 0.95, 0.99, 0.999, 0.5, 0.97, 1.0, 0.98]), model=("constant", 0.3, 0.1, 100.0)))
write("fuzz_core", "model-relative-unorm16-40x30-reversed-infinite-far-anyhit",
      core(0, 39, 29, 1, 1, 4 | (5 << 3), 2, 0x01, 40, 1, 0x05, 1, (4, 3, 20, 9),
           structured_rays(32, mrng) + raw_rays(8, mrng),
           list(struct.pack("<1400H", *[mrng.randrange(6000) for _ in range(1400)])),
           model=("relative", 0.1, 0.5, float("inf"))))
write("fuzz_core", "model-constant-unorm8-33x20-tight-planes-whole-update",
      core(0, 32, 19, 0, 0, 0, 1, 0x01, 40, 0, 0xc0, 2, (0, 0, 0, 0), primary_rays(8, 33, 20, mrng) + structured_rays(32, mrng),
           [mrng.randrange(256) for _ in range(900)], model=("constant", 2e-5, 1.0, 1.0001)))
# byte 16: relative (bit 3), a back map (bit 5), any parameters (bits 6-7 = 3); then the
# kinds: value wild (1.7e38: k f / (f - n) overflows float), near on the grid, far one float above near
write("fuzz_core", "model-relative-wild-value-with-back-map",
      core(0, 11, 8, 2, 0, 0, 0, 0x06, 12, 0, 0x02, 0, (1, 1, 4, 4), structured_rays(12, mrng),
           floats([0.4, 0.8, 0.85, 1.0]), model=(0xef, [2 | (1 << 2) | (6 << 4), 11, 128, 1])))

# ---- fuzz_vk_args: device bytes, desc bytes, then calls ----------------------------
# device a b c: a = 0 (Vulkan 1.2, nothing missing), b = 3 << 3 (alignment 8), c = 0x1f
# (range 2^31-1 via b>>6 == 0, group counts 65535); desc byte 0x03 (get_device_proc_addr, vk_result)
DEV = [0x00, 0x18, 0x7f]
create = [0x01, 0x00, 8, 6, 2]                 # op 1: bvh 0, 9x7 float, auto node bits
create16 = [0x11, 0x02, 40, 30, 0]             # op 1: bvh 1, 41x31 unorm8, 16-bit nodes
build = [0x03, 0x00, 2, 0]                     # op 3: build bvh 0 from a float buffer at offset 0
update = [0x05, 0x00, 2, 0x04, 0x00, 1, 1, 4, 3]  # op 5: update bvh 0 from offset 1024, rect (1,1) 4x3
image = [0x15, 0x06, 0x00, 0x01, 0x00, 0, 2, 2, 9]  # op 5: update bvh 1 from an image view (GENERAL)
trace = [0x06, 0x00, 2, 0, 0x00, 3, 1, 1, 200]  # op 6: 200 rays 3 rays past aligned offsets
sizes = [0x00, 9, 9, 2, 0]                     # op 0: buffer sizes
write("fuzz_vk_args", "create-build-update-trace", DEV + [0x03] + create + build + update + trace + sizes)
write("fuzz_vk_args", "two-bvhs-image", DEV + [0x01] + create + create16 + image + build + trace)
write("fuzz_vk_args", "callbacks-alloc-fails", DEV + [0x23, 0x18 | (1 << 5)] + create + build)
write("fuzz_vk_args", "old-device-no-extension", [0x87, 0x18, 0x7f, 1, 0x02] + create + build + trace)
write("fuzz_vk_args", "caller-buffers-4k-range",
      [0x00, 0xe8, 0x7f, 0x00, 0x10, 0x00, 0x00, 0x01, 0x01, 0x30, 8, 6, 2, 0x01, 0x02] + build + trace)


# ---- fuzz_files: 4 selector bytes, then the file ---------------------------------
def png(w, h, bits, color_type, pixels):
    """a PNG with filter 0 rows; pixels: bytes of the rows, unfiltered"""
    def chunk(tag, body):
        return struct.pack(">I", len(body)) + tag + body + struct.pack(">I", zlib.crc32(tag + body) & 0xffffffff)
    channels = {0: 1, 2: 3, 4: 2, 6: 4}[color_type]
    row = w * channels * bits // 8
    raw = b"".join(b"\x00" + pixels[y * row:(y + 1) * row] for y in range(h))
    ihdr = struct.pack(">IIBBBBB", w, h, bits, color_type, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")


grey8 = bytes((x * 16 + y * 5) & 0xff for y in range(6) for x in range(8))
write("fuzz_files", "png-grey8-8x6", b"\x00\x07\x05\x00" + png(8, 6, 8, 0, grey8))
grey16 = b"".join(struct.pack(">H", (x * 4000 + y * 900) & 0xffff) for y in range(5) for x in range(7))
write("fuzz_files", "png-grey16-7x5-reversed-colour", b"\x80\x06\x04\x00" + png(7, 5, 16, 0, grey16))
rgb = bytes(rng.randrange(256) for _ in range(4 * 3 * 3))
write("fuzz_files", "png-rgb8-4x3-colour", b"\x80\x03\x02\x00" + png(4, 3, 8, 2, rgb))
pfm_le = b"Pf\n5 3\n-1.0\n" + struct.pack("<15f", *[i / 14.0 for i in range(14)] + [float("nan")])
write("fuzz_files", "pfm-grey-le-5x3", b"\x01\x00\x00\x00" + pfm_le)
pfm_be = b"PF 2 2 1.0 " + struct.pack(">12f", 0.1, 9, 9, 0.2, 9, 9, -3.0, 9, 9, 1.5, 9, 9)
write("fuzz_files", "pfm-colour-be-2x2", b"\x05\x00\x00\x00" + pfm_be)
write("fuzz_files", "raw-6x4", b"\x02\x05\x00\x00" + struct.pack("<24f", *[i / 23.0 for i in range(24)]))
write("fuzz_files", "raw-wrong-size", b"\x12\x05\x03\x00" + struct.pack("<5f", 0.5, 0.25, 2.0, -1.0, 0.75))
