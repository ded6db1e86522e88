/* tests/fuzz/fuzz_files.c - libFuzzer harness of the examples' file reader
   (examples/depth_file.h: PNG 8/16-bit, PFM, raw floats; colour PNG).

   The first bytes pick the kind, reversed Z, the raw size, the colour
   size and the size of the reason buffer; the rest is the file. Checked:
   - success: 1..16384 texels each way, every depth in [0,1] (no NaN), no
     reason; the same file with reversed Z gives 1 - d wherever d was not
     clamped (PNG: everywhere); PNG depth is v/255 or v/65535; PFM and raw
     depth is the file's floats, read here by a parser of their own (PFM:
     rows bottom-up, first channel, byte order from the scale's sign);
   - failure: a one-line reason, not empty, inside the buffer given; *out
     zeroed;
   - colour: on success an RGB buffer of exactly width x height x 3 bytes
     (every byte read, so ASan sees a short one), else NULL and a reason. */
#include "../../examples/depth_file.h"
#include "fuzz_common.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FAIL(...) (fprintf(stderr, "fuzz_files: " __VA_ARGS__), fputc('\n', stderr), abort())

/* a reason: NUL-terminated inside why_size bytes, one line, not empty */
static void check_reason(const char *what, const char *why, size_t why_size)
{
    const char *end = (const char *)memchr(why, 0, why_size);
    size_t n = end ? (size_t)(end - why) : why_size;
    if (n == why_size) FAIL("%s: the reason is not terminated inside its %zu bytes", what, why_size);
    if (n == 0 && why_size > 1) FAIL("%s: failed without a reason", what);
    if (memchr(why, '\n', n) || memchr(why, '\r', n)) FAIL("%s: the reason is more than one line: %s", what, why);
}

static float clamp01(float d) { return !(d <= 1.0f) ? 1.0f : d < 0.0f ? 0.0f : d; }

static float le_float(const unsigned char *p, int little)
{
    uint32_t u = little ? (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24
                        : (uint32_t)p[3] | (uint32_t)p[2] << 8 | (uint32_t)p[1] << 16 | (uint32_t)p[0] << 24;
    float f;
    memcpy(&f, &u, 4);
    return f;
}

/* The PFM's data as this harness reads the format: "Pf" or "PF", width,
   height and scale separated by whitespace, one whitespace byte, then
   floats. Returns the data's offset, or 0 when it does not parse. */
static size_t pfm_data(const unsigned char *b, size_t n, uint32_t *w, uint32_t *h, int *channels, int *little)
{
    char tok[3][32];
    size_t at = 2;
    int k;
    if (n < 3 || b[0] != 'P' || (b[1] != 'f' && b[1] != 'F')) return 0;
    for (k = 0; k < 3; ++k) {
        size_t len = 0;
        while (at < n && strchr(" \t\r\n", b[at]) && b[at]) ++at;
        while (at < n && b[at] > ' ' && b[at] < 127 && len < 31) tok[k][len++] = (char)b[at++];
        tok[k][len] = 0;
        if (!len || at >= n) return 0;
    }
    *w = (uint32_t)strtoul(tok[0], NULL, 10);
    *h = (uint32_t)strtoul(tok[1], NULL, 10);
    *channels = b[1] == 'F' ? 3 : 1;
    *little = strtod(tok[2], NULL) < 0.0;
    return at + 1;
}

static void check_image(const char *what, const depth_file_image *img)
{
    size_t i, n;
    if (img->width < 1 || img->height < 1 || img->width > 16384 || img->height > 16384 || !img->depth)
        FAIL("%s: success with a %ux%u image at %p", what, img->width, img->height, (void *)img->depth);
    n = (size_t)img->width * img->height;
    for (i = 0; i < n; ++i)
        if (!(img->depth[i] >= 0.0f && img->depth[i] <= 1.0f)) FAIL("%s: depth[%zu] = %g", what, i, img->depth[i]);
}

/* PNG sizes are capped here: a 30-byte file may claim 16384 x 16384 (a
   valid size) and make the reader allocate gigabytes, which is no bug. (A
   chunk that claims more bytes than the file has is depth_file.h's to refuse
   before stb_image allocates it: crashes-found/files-stb-idat-length-2gib-alloc.) */
static int png_too_big(const unsigned char *b, size_t n)
{
    int w, h, c;
    return n <= 0x7fffffff && stbi_info_from_memory(b, (int)n, &w, &h, &c) && (double)w * h > 4e6;
}

/* decodes by kind (PNG, PFM, raw, other) that succeeded or failed, and
   colour PNGs read, printed when a run ends */
static unsigned long g_ok[4], g_refused[4], g_colour;
static void fuzz_print_counts(void)
{
    fprintf(stderr, "fuzz_files: decoded PNG %lu (refused %lu), PFM %lu (%lu), raw %lu (%lu), bad kind refused %lu; colour %lu\n",
            g_ok[0], g_refused[0], g_ok[1], g_refused[1], g_ok[2], g_refused[2], g_refused[3], g_colour);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const size_t why_sizes[4] = {256, 1, 7, 40};
    uint8_t sel, rw, rh;
    const unsigned char *file;
    size_t n, why_size;
    int kind;
    uint32_t raw_w, raw_h;
    char *why;
    depth_file_image img, rev;

    if (size < 4) return 0;
    sel = data[0], rw = data[1], rh = data[2];
    file = data + 4;
    n = size - 4;
    /* kind: PNG, PFM, raw, or a bad kind; the file itself decides the rest */
    kind = (sel & 3) == 0 ? DEPTH_FILE_PNG : (sel & 3) == 1 ? DEPTH_FILE_PFM : (sel & 3) == 2 ? DEPTH_FILE_RAW : 7 + data[3];
    /* raw size: mostly one that fits the bytes (w from the input, h from the size) */
    raw_w = 1u + rw % 64u;
    raw_h = (sel & 0x10) ? 1u + rh : (uint32_t)(n / 4u / raw_w);
    if ((sel & 0x60) == 0x60) raw_w = 16385u, raw_h = 1;
    why_size = why_sizes[(sel >> 2) & 3];
    why = (char *)malloc(why_size); /* exactly its size: ASan sees a write past it */
    if (!why) return 0;
    memset(why, 'x', why_size);
    if (kind == DEPTH_FILE_PNG && png_too_big(file, n)) {
        free(why);
        return 0;
    }

    memset(&img, 0x5a, sizeof img);
    if (depth_file_decode(file, n, kind, 0, raw_w, raw_h, &img, why, why_size) != 0) {
        ++g_refused[sel & 3];
        check_reason("depth_file_decode", why, why_size);
        if (img.width || img.height || img.depth) FAIL("depth_file_decode failed and left a %ux%u image", img.width, img.height);
        if (kind == DEPTH_FILE_PNG && (sel & 0x80)) { /* the colour reader on the same bytes */
            uint8_t *rgb = (uint8_t *)1;
            memset(why, 'x', why_size);
            if (color_file_decode(file, n, 1u + rw, 1u + rh, &rgb, why, why_size) == 0) FAIL("colour from a file that is no depth PNG");
            check_reason("color_file_decode", why, why_size);
            if (rgb) FAIL("color_file_decode failed and left a buffer");
        }
        free(why);
        return 0;
    }
    if (why_size > 1 && why[0] != 0) FAIL("depth_file_decode succeeded with a reason: %.*s", (int)why_size, why);
    check_image("depth_file_decode", &img);
    ++g_ok[sel & 3];

    /* reversed Z: 1 - d in float wherever d was not clamped */
    if (depth_file_decode(file, n, kind, 1, raw_w, raw_h, &rev, why, why_size) != 0)
        FAIL("reversed Z refused a file: %s", why);
    check_image("depth_file_decode (reversed)", &rev);
    if (rev.width != img.width || rev.height != img.height) FAIL("reversed Z changed the size");
    {
        size_t i, count = (size_t)img.width * img.height;
        for (i = 0; i < count; ++i) {
            float d = img.depth[i];
            if ((kind == DEPTH_FILE_PNG || (d > 0.0f && d < 1.0f)) && rev.depth[i] != 1.0f - d)
                FAIL("texel %zu: %a, reversed %a", i, d, rev.depth[i]);
        }
    }

    /* the values, from this harness's own reading of the file */
    {
        size_t i, count = (size_t)img.width * img.height;
        if (kind == DEPTH_FILE_PNG) {
            for (i = 0; i < count; ++i) {
                float d = img.depth[i];
                float k8 = roundf(d * 255.0f), k16 = roundf(d * 65535.0f);
                if (k8 / 255.0f != d && k16 / 65535.0f != d) FAIL("PNG texel %zu is %a: no v/255 or v/65535", i, d);
            }
        } else if (kind == DEPTH_FILE_RAW) {
            if (img.width != raw_w || img.height != raw_h || n != count * 4u) FAIL("raw size %ux%u from %zu bytes", img.width, img.height, n);
            for (i = 0; i < count; ++i)
                if (img.depth[i] != clamp01(le_float(file + 4 * i, 1))) FAIL("raw texel %zu", i);
        } else {
            uint32_t w = 0, h = 0, x, y;
            int ch = 1, little = 0;
            size_t at = pfm_data(file, n, &w, &h, &ch, &little);
            if (!at || w != img.width || h != img.height || n - at < count * (size_t)ch * 4u)
                FAIL("PFM read as %ux%u, here as %ux%u with data at %zu of %zu", img.width, img.height, w, h, at, n);
            for (y = 0; y < h; ++y)
                for (x = 0; x < w; ++x) {
                    float f = clamp01(le_float(file + at + (((size_t)(h - 1 - y) * w + x) * (size_t)ch) * 4u, little));
                    if (img.depth[(size_t)y * w + x] != f) FAIL("PFM texel (%u,%u): %a, the file has %a", x, y, img.depth[(size_t)y * w + x], f);
                }
        }
    }

    /* colour of the depth's size (PNG) or of another size */
    if (kind == DEPTH_FILE_PNG) {
        uint8_t *rgb = NULL;
        uint32_t cw = (sel & 0x80) ? 1u + rw : img.width, ch = img.height;
        memset(why, 'x', why_size);
        if (color_file_decode(file, n, cw, ch, &rgb, why, why_size) == 0) {
            size_t i, sum = 0;
            if (cw != img.width || !rgb) FAIL("colour of %ux%u from a %ux%u PNG", cw, ch, img.width, img.height);
            if (why_size > 1 && why[0] != 0) FAIL("color_file_decode succeeded with a reason");
            for (i = 0; i < (size_t)cw * ch * 3u; ++i) sum += rgb[i]; /* all of it readable */
            if (sum == (size_t)-1) abort();
            ++g_colour;
            free(rgb);
        } else {
            check_reason("color_file_decode", why, why_size);
            if (cw == img.width) FAIL("a PNG that is depth is refused as colour: %s", why);
            if (rgb) FAIL("color_file_decode failed and left a buffer");
        }
    }
    depth_file_free(&img);
    depth_file_free(&rev);
    if (img.depth || img.width) FAIL("depth_file_free left the image");
    free(why);
    return 0;
}
