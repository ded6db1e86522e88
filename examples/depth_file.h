/* depth_file.h - the examples' reader of a user's depth (and colour) files.

   Depth: PNG 8- or 16-bit (the first channel; v / 255 or v / 65535), PFM
   (Pf greyscale, or PF colour: the first channel; either byte order), or raw
   little-endian 32-bit floats (its size must be given). Colour: PNG, 8-bit
   RGB(A) or grey, of the depth's size. Every problem is a nonzero return and
   a one-line reason; nothing is read outside the bytes given.

   The depth comes out as docs/MODEL.md wants it: floats, row 0 at the top, 0 near,
   NaN and values above 1 as 1, below 0 as 0 (after the reversed-Z flip).

   Header-only; include it in ONE file of a program: it compiles stb_image
   (Debian's libstb-dev; PNG only) with external linkage. Its own functions
   are static. */
#ifndef DEPTH_FILE_H
#define DEPTH_FILE_H

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* every function is static to the including file; unused ones stay quiet */
#if defined(__GNUC__)
#define DEPTH_FILE_FN static __attribute__((unused))
#else
#define DEPTH_FILE_FN static
#endif

#define STBI_ONLY_PNG
#define STBI_NO_STDIO
/* stb_image is compiled here, with external linkage: include this header in one file of a program */
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

#define DEPTH_FILE_MAX_DIM 16384u /* linear_rt's LINEAR_RT_MAX_DIM */

enum { DEPTH_FILE_AUTO = 0, DEPTH_FILE_PNG = 1, DEPTH_FILE_PFM = 2, DEPTH_FILE_RAW = 3 };

typedef struct depth_file_image {
    uint32_t width, height;
    float *depth; /* width * height, malloc'ed */
} depth_file_image;

DEPTH_FILE_FN int depth_file__fail(char *why, size_t why_size, const char *text)
{
    if (why && why_size) snprintf(why, why_size, "%s", text);
    return 1;
}

/* The kind a file name suggests: .png, .pfm, anything else raw. */
DEPTH_FILE_FN int depth_file_kind_of(const char *path)
{
    size_t n = strlen(path);
    if (n >= 4 && (!strcmp(path + n - 4, ".png") || !strcmp(path + n - 4, ".PNG"))) return DEPTH_FILE_PNG;
    if (n >= 4 && (!strcmp(path + n - 4, ".pfm") || !strcmp(path + n - 4, ".PFM"))) return DEPTH_FILE_PFM;
    return DEPTH_FILE_RAW;
}

DEPTH_FILE_FN float depth_file__clamp(float d, int reversed_z)
{
    if (reversed_z) d = 1.0f - d;
    return !(d <= 1.0f) ? 1.0f : d < 0.0f ? 0.0f : d;
}

/* stb_image's reason for a failure, as one printable line: its text may
   quote a chunk name from the file (any 4 bytes, a newline among them) */
DEPTH_FILE_FN void depth_file__stb_reason(char *text, size_t size)
{
    const char *r = stbi_failure_reason();
    size_t k;
    snprintf(text, size, "corrupt PNG (%s)", r ? r : "unknown");
    for (k = 0; text[k]; ++k)
        if ((unsigned char)text[k] < 0x20 || (unsigned char)text[k] > 0x7e) text[k] = '?';
}

/* Walks the PNG's chunks before stb_image sees them: a chunk that claims
   more bytes than the file has left is refused here (stb_image would first
   allocate what it claims, up to 2 GiB, then fail). */
DEPTH_FILE_FN int depth_file__png_chunks(const unsigned char *b, size_t size, char *why, size_t why_size)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    size_t at = 8;
    char text[160];
    if (size < 8 || memcmp(b, sig, 8) != 0) return depth_file__fail(why, why_size, "not a PNG (no PNG signature)");
    while (at < size) {
        uint32_t len;
        int k, iend;
        if (size - at < 12) return depth_file__fail(why, why_size, "truncated PNG (a chunk header is cut off)");
        len = (uint32_t)b[at] << 24 | (uint32_t)b[at + 1] << 16 | (uint32_t)b[at + 2] << 8 | (uint32_t)b[at + 3];
        iend = memcmp(b + at + 4, "IEND", 4) == 0;
        if (len > size - at - 12) {
            char name[5];
            for (k = 0; k < 4; ++k) name[k] = b[at + 4 + (size_t)k] >= 0x20 && b[at + 4 + (size_t)k] <= 0x7e ? (char)b[at + 4 + (size_t)k] : '?';
            name[4] = 0;
            snprintf(text, sizeof text, "truncated PNG: chunk %s claims %lu bytes, %lu are left", name,
                     (unsigned long)len, (unsigned long)(size - at - 12));
            return depth_file__fail(why, why_size, text);
        }
        at += 12 + (size_t)len;
        if (iend) return 0;
    }
    return depth_file__fail(why, why_size, "truncated PNG (no IEND chunk)");
}

DEPTH_FILE_FN int depth_file__size_ok(int w, int h)
{
    return w >= 1 && h >= 1 && (unsigned)w <= DEPTH_FILE_MAX_DIM && (unsigned)h <= DEPTH_FILE_MAX_DIM;
}

DEPTH_FILE_FN int depth_file__png(const unsigned char *bytes, size_t size, int reversed_z, depth_file_image *out,
                           char *why, size_t why_size)
{
    int w, h, c, is16;
    size_t i, n;
    if (size > 0x7fffffffu) return depth_file__fail(why, why_size, "too large for a PNG");
    if (depth_file__png_chunks(bytes, size, why, why_size)) return 1;
    if (!stbi_info_from_memory(bytes, (int)size, &w, &h, &c))
        return depth_file__fail(why, why_size, "not a PNG (or a corrupt one)");
    if (!depth_file__size_ok(w, h)) return depth_file__fail(why, why_size, "image size outside 1..16384");
    is16 = stbi_is_16_bit_from_memory(bytes, (int)size);
    n = (size_t)w * (size_t)h;
    out->depth = (float *)malloc(n * sizeof(float));
    if (!out->depth) return depth_file__fail(why, why_size, "out of memory");
    if (is16) {
        stbi_us *p = stbi_load_16_from_memory(bytes, (int)size, &w, &h, &c, 0);
        if (!p) goto corrupt;
        for (i = 0; i < n; ++i) out->depth[i] = depth_file__clamp((float)p[i * (size_t)c] / 65535.0f, reversed_z);
        stbi_image_free(p);
    } else {
        stbi_uc *p = stbi_load_from_memory(bytes, (int)size, &w, &h, &c, 0);
        if (!p) goto corrupt;
        for (i = 0; i < n; ++i) out->depth[i] = depth_file__clamp((float)p[i * (size_t)c] / 255.0f, reversed_z);
        stbi_image_free(p);
    }
    out->width = (uint32_t)w;
    out->height = (uint32_t)h;
    return 0;
corrupt:
    free(out->depth);
    out->depth = NULL;
    {
        char text[160];
        depth_file__stb_reason(text, sizeof text);
        return depth_file__fail(why, why_size, text);
    }
}

/* A PFM header token: an unsigned decimal integer, or for the scale any
   float; skips whitespace before it; returns the offset past it or 0. */
DEPTH_FILE_FN size_t depth_file__token(const unsigned char *b, size_t size, size_t at, char *tok, size_t tok_size)
{
    size_t k = 0;
    while (at < size && (b[at] == ' ' || b[at] == '\t' || b[at] == '\r' || b[at] == '\n')) ++at;
    while (at < size && k + 1 < tok_size && b[at] > ' ' && b[at] < 127) tok[k++] = (char)b[at++];
    tok[k] = 0;
    if (k == 0 || k + 1 >= tok_size || at >= size) return 0;
    return at;
}

DEPTH_FILE_FN int depth_file__dim(const char *tok, uint32_t *v)
{
    unsigned long x;
    char *end;
    if (tok[0] < '0' || tok[0] > '9') return 0;
    errno = 0;
    x = strtoul(tok, &end, 10);
    if (*end || errno || x < 1 || x > DEPTH_FILE_MAX_DIM) return 0;
    *v = (uint32_t)x;
    return 1;
}

DEPTH_FILE_FN int depth_file__pfm(const unsigned char *b, size_t size, int reversed_z, depth_file_image *out,
                           char *why, size_t why_size)
{
    char tok[32];
    size_t at, need, i, channels, n;
    uint32_t w, h, x, y;
    double scale;
    char *end;
    int little;
    if (size < 3 || b[0] != 'P' || (b[1] != 'f' && b[1] != 'F'))
        return depth_file__fail(why, why_size, "not a PFM (no Pf or PF signature)");
    channels = b[1] == 'F' ? 3 : 1;
    at = depth_file__token(b, size, 2, tok, sizeof tok);
    if (!at || !depth_file__dim(tok, &w)) return depth_file__fail(why, why_size, "PFM width missing or outside 1..16384");
    at = depth_file__token(b, size, at, tok, sizeof tok);
    if (!at || !depth_file__dim(tok, &h)) return depth_file__fail(why, why_size, "PFM height missing or outside 1..16384");
    at = depth_file__token(b, size, at, tok, sizeof tok);
    scale = at ? strtod(tok, &end) : 0.0;
    if (!at || *end || !(scale == scale) || scale == 0.0) return depth_file__fail(why, why_size, "PFM scale missing or zero");
    ++at; /* the single whitespace character that ends the header */
    little = scale < 0.0;
    n = (size_t)w * (size_t)h;
    need = n * channels * 4u;
    if (size < at || size - at < need) {
        char text[160];
        snprintf(text, sizeof text, "truncated PFM: %ux%u needs %zu bytes of data, has %zu", w, h, need,
                 size < at ? (size_t)0 : size - at);
        return depth_file__fail(why, why_size, text);
    }
    out->depth = (float *)malloc(n * sizeof(float));
    if (!out->depth) return depth_file__fail(why, why_size, "out of memory");
    for (y = 0; y < h; ++y) /* PFM rows run bottom to top */
        for (x = 0; x < w; ++x) {
            const unsigned char *p = b + at + (((size_t)(h - 1 - y) * w + x) * channels) * 4u;
            uint32_t u = little ? (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24
                                : (uint32_t)p[3] | (uint32_t)p[2] << 8 | (uint32_t)p[1] << 16 | (uint32_t)p[0] << 24;
            float f;
            memcpy(&f, &u, 4);
            i = (size_t)y * w + x;
            out->depth[i] = depth_file__clamp(f, reversed_z);
        }
    out->width = w;
    out->height = h;
    return 0;
}

DEPTH_FILE_FN int depth_file__raw(const unsigned char *b, size_t size, int reversed_z, uint32_t w, uint32_t h,
                           depth_file_image *out, char *why, size_t why_size)
{
    size_t n, i;
    char text[160];
    if (w < 1 || h < 1 || w > DEPTH_FILE_MAX_DIM || h > DEPTH_FILE_MAX_DIM)
        return depth_file__fail(why, why_size, "raw float depth needs --width and --height (1..16384)");
    n = (size_t)w * h;
    if (size != n * 4u) {
        snprintf(text, sizeof text, "wrong size for %ux%u raw floats: %zu bytes, expected %zu", w, h, size, n * 4u);
        return depth_file__fail(why, why_size, text);
    }
    out->depth = (float *)malloc(n * sizeof(float));
    if (!out->depth) return depth_file__fail(why, why_size, "out of memory");
    for (i = 0; i < n; ++i) { /* little-endian, whatever the host */
        const unsigned char *p = b + i * 4u;
        uint32_t u = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
        float f;
        memcpy(&f, &u, 4);
        out->depth[i] = depth_file__clamp(f, reversed_z);
    }
    out->width = w;
    out->height = h;
    return 0;
}

/* Decodes depth from memory; kind DEPTH_FILE_PNG, _PFM or _RAW (raw needs
   raw_width, raw_height). 0 on success, else nonzero, *out zeroed and a
   one-line reason in why. */
DEPTH_FILE_FN int depth_file_decode(const unsigned char *bytes, size_t size, int kind, int reversed_z, uint32_t raw_width,
                             uint32_t raw_height, depth_file_image *out, char *why, size_t why_size)
{
    int r;
    if (why && why_size) why[0] = 0;
    if (!out) return depth_file__fail(why, why_size, "no output image");
    memset(out, 0, sizeof *out);
    if (!bytes && size) return depth_file__fail(why, why_size, "no data");
    if (size == 0) return depth_file__fail(why, why_size, "empty file");
    if (kind == DEPTH_FILE_PNG) r = depth_file__png(bytes, size, reversed_z, out, why, why_size);
    else if (kind == DEPTH_FILE_PFM) r = depth_file__pfm(bytes, size, reversed_z, out, why, why_size);
    else if (kind == DEPTH_FILE_RAW) r = depth_file__raw(bytes, size, reversed_z, raw_width, raw_height, out, why, why_size);
    else r = depth_file__fail(why, why_size, "unknown depth file kind");
    if (r) memset(out, 0, sizeof *out);
    return r;
}

/* Decodes an 8-bit colour PNG of exactly width x height into malloc'ed RGB. */
DEPTH_FILE_FN int color_file_decode(const unsigned char *bytes, size_t size, uint32_t width, uint32_t height, uint8_t **rgb,
                             char *why, size_t why_size)
{
    int w, h, c;
    stbi_uc *p;
    char text[160];
    if (why && why_size) why[0] = 0;
    if (!rgb) return depth_file__fail(why, why_size, "no output image");
    *rgb = NULL;
    if (!bytes || size == 0) return depth_file__fail(why, why_size, "empty file");
    if (size > 0x7fffffffu) return depth_file__fail(why, why_size, "too large for a PNG");
    if (depth_file__png_chunks(bytes, size, why, why_size)) return 1;
    if (!stbi_info_from_memory(bytes, (int)size, &w, &h, &c))
        return depth_file__fail(why, why_size, "not a PNG (or a corrupt one)");
    if ((uint32_t)w != width || (uint32_t)h != height) {
        snprintf(text, sizeof text, "colour is %dx%d, the depth %ux%u", w, h, width, height);
        return depth_file__fail(why, why_size, text);
    }
    p = stbi_load_from_memory(bytes, (int)size, &w, &h, &c, 3);
    if (!p) {
        depth_file__stb_reason(text, sizeof text);
        return depth_file__fail(why, why_size, text);
    }
    *rgb = (uint8_t *)p; /* stb_image allocates with malloc (STBI_MALLOC default): free() releases it */
    return 0;
}

DEPTH_FILE_FN void depth_file_free(depth_file_image *img)
{
    if (!img) return;
    free(img->depth);
    img->depth = NULL;
    img->width = img->height = 0;
}

/* Reads a whole file: 0 and malloc'ed bytes, or nonzero and "PATH: reason". */
DEPTH_FILE_FN int depth_file_read(const char *path, unsigned char **bytes, size_t *size, char *why, size_t why_size)
{
    FILE *f = fopen(path, "rb");
    long len;
    char text[512];
    *bytes = NULL;
    *size = 0;
    if (!f) {
        snprintf(text, sizeof text, "%s: cannot open (%s)", path, strerror(errno));
        return depth_file__fail(why, why_size, text);
    }
    if (fseek(f, 0, SEEK_END) != 0 || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        snprintf(text, sizeof text, "%s: not a regular file", path);
        return depth_file__fail(why, why_size, text);
    }
    *bytes = (unsigned char *)malloc(len ? (size_t)len : 1u);
    if (!*bytes || fread(*bytes, 1, (size_t)len, f) != (size_t)len) {
        fclose(f);
        free(*bytes);
        *bytes = NULL;
        snprintf(text, sizeof text, "%s: read error", path);
        return depth_file__fail(why, why_size, text);
    }
    fclose(f);
    *size = (size_t)len;
    return 0;
}

/* depth_file_read + depth_file_decode (kind DEPTH_FILE_AUTO: by the name);
   why is "PATH: reason". */
DEPTH_FILE_FN int depth_file_load(const char *path, int kind, int reversed_z, uint32_t raw_width, uint32_t raw_height,
                           depth_file_image *out, char *why, size_t why_size)
{
    unsigned char *bytes;
    size_t size;
    char reason[256];
    int r;
    if (depth_file_read(path, &bytes, &size, why, why_size)) return 1;
    r = depth_file_decode(bytes, size, kind ? kind : depth_file_kind_of(path), reversed_z, raw_width, raw_height, out,
                          reason, sizeof reason);
    free(bytes);
    if (r && why && why_size) snprintf(why, why_size, "%s: %s", path, reason);
    return r;
}

DEPTH_FILE_FN int color_file_load(const char *path, uint32_t width, uint32_t height, uint8_t **rgb, char *why, size_t why_size)
{
    unsigned char *bytes;
    size_t size;
    char reason[256];
    int r;
    *rgb = NULL;
    if (depth_file_read(path, &bytes, &size, why, why_size)) return 1;
    r = color_file_decode(bytes, size, width, height, rgb, reason, sizeof reason);
    free(bytes);
    if (r && why && why_size) snprintf(why, why_size, "%s: %s", path, reason);
    return r;
}

#endif
