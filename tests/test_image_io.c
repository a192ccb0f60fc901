/* Image files through the OpenImageIO bridge: round trips in every format, the encodings,
   metadata, atomic writes, writes cut short, and files that cannot be read. */
#include <criterion/criterion.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "image/image_io.h"
#include "support.h"

static double srgb_decode(double v)
{
    return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
}

static void fill_rgb(float *rgb, int n, float value)
{
    for (int i = 0; i < 3 * n; i++)
        rgb[i] = value;
}

Test(image_io, exr_round_trip)
{
    const char *dir = test_tmpdir();
    const char *path = tmp_path(dir, "a.exr");
    const float rgb[3 * 6] = {0.123456789f, 1.0f, 0.0f, 3.75f, 1e-3f, 250.0f,
                              0.5f, 0.25f, 0.2f, 1e-2f, 7.0f, 0.999f,
                              2.0f, 0.3f, 0.4f, 0.6f, 0.7f, 0.8f};
    l2p_error err = {0, ""};
    cr_assert_eq(image_write_rgb(path, 3, 2, rgb, NULL, 0, &err), L2P_OK, "%s", err.text);
    int w, h;
    float *px;
    cr_assert_eq(image_read_rgba(path, &w, &h, &px, &err), L2P_OK, "%s", err.text);
    cr_assert(w == 3 && h == 2);
    for (int i = 0; i < 6; i++) {
        for (int c = 0; c < 3; c++)
            cr_assert_float_eq(px[4 * i + c], rgb[3 * i + c], 1e-3 * fabsf(rgb[3 * i + c]),
                               "pixel %d channel %d: %g", i, c, px[4 * i + c]);
        cr_assert_eq(px[4 * i + 3], 1.0f);
    }
    free(px);
}

/* Linear 0.5 is stored as sRGB code 188 (0.7354 * 255 = 187.5), read back as its decoding. */
Test(image_io, png_srgb_encoding)
{
    const char *dir = test_tmpdir();
    const char *path = tmp_path(dir, "a.PNG");   /* the extension is matched case-insensitively */
    const float rgb[3 * 2] = {0.5f, 0.0f, 1.0f, 2.0f, -1.0f, 0.002f};
    l2p_error err = {0, ""};
    cr_assert_eq(image_write_rgb(path, 2, 1, rgb, NULL, 0, &err), L2P_OK, "%s", err.text);
    int w, h;
    float *px;
    cr_assert_eq(image_read_rgba(path, &w, &h, &px, &err), L2P_OK, "%s", err.text);
    cr_assert(w == 2 && h == 1);
    /* codes: 188, 0, 255 | clipped 255, clipped 0, linear toe 12.92 * 0.002 * 255 = 6.6 -> 7 */
    const int codes[6] = {188, 0, 255, 255, 0, 7};
    const int at[6] = {0, 1, 2, 4, 5, 6};
    for (int i = 0; i < 6; i++)
        cr_assert_float_eq(px[at[i]], srgb_decode(codes[i] / 255.0), 1e-6, "value %d: %.7g", i,
                           px[at[i]]);
    cr_assert_eq(px[3], 1.0f);
    free(px);
}

Test(image_io, tiff_16bit_round_trip)
{
    const char *dir = test_tmpdir();
    const char *path = tmp_path(dir, "a.tiff");
    float rgb[3 * 4];
    fill_rgb(rgb, 4, 0.5f);
    rgb[4] = 0.01f;
    const image_attribute attrs[] = {{"lens2pov:lens", "Fisheye"}, {"FNumber", "5.6"}};
    l2p_error err = {0, ""};
    cr_assert_eq(image_write_rgb(path, 2, 2, rgb, attrs, 2, &err), L2P_OK, "%s", err.text);
    int w, h;
    float *px;
    cr_assert_eq(image_read_rgba(path, &w, &h, &px, &err), L2P_OK, "%s", err.text);
    cr_assert_float_eq(px[0], 0.5f, 2e-5);
    cr_assert_float_eq(px[5], 0.01f, 5e-6);
    free(px);
    char value[64];
    /* TIFF keeps no attributes of our own: they come back from ImageDescription */
    expect_attribute(path, "lens2pov:lens", "Fisheye");
    cr_assert_eq(image_get_attribute(path, "FNumber", value, sizeof value), L2P_OK);
    cr_assert_float_eq(atof(value), 5.6, 1e-6);
}

Test(image_io, png_metadata)
{
    const char *dir = test_tmpdir();
    const char *path = tmp_path(dir, "m.png");
    float rgb[3];
    fill_rgb(rgb, 1, 0.25f);
    const image_attribute attrs[] = {{"lens2pov:lens", "Wide\nangle"}, {"Software", "lens2pov"},
                                     {"FNumber", "2.8"}, {"lens2pov:pupil", ""}};
    l2p_error err = {0, ""};
    cr_assert_eq(image_write_rgb(path, 1, 1, rgb, attrs, 4, &err), L2P_OK, "%s", err.text);
    char value[64];
    expect_attribute(path, "lens2pov:pupil", "");
    expect_attribute(path, "lens2pov:lens", "Wide angle");
    expect_attribute(path, "Software", "lens2pov");
    cr_assert_eq(image_get_attribute(path, "FNumber", value, sizeof value), L2P_OK);
    cr_assert_float_eq(atof(value), 2.8, 1e-6);
    cr_assert_eq(image_get_attribute(path, "lens2pov:absent", value, sizeof value), L2P_FAILED);
    cr_assert_eq(image_get_attribute(tmp_path(dir, "none.png"), "x", value, sizeof value),
                 L2P_FAILED);
    /* truncation to the buffer */
    char small[5];
    cr_assert_eq(image_get_attribute(path, "Software", small, sizeof small), L2P_OK);
    cr_assert_str_eq(small, "lens");
}

Test(image_io, unknown_extension_refused)
{
    const char *dir = test_tmpdir();
    float rgb[3] = {0};
    l2p_error err = {0, ""};
    const char *path = tmp_path(dir, "a.xyz");
    cr_assert_eq(image_write_rgb(path, 1, 1, rgb, NULL, 0, &err), L2P_BAD_INPUT);
    cr_assert(strstr(err.text, path), "%s", err.text);
    cr_assert(strstr(err.text, "unknown image type '.xyz' (use .png, .exr or .tif)"), "%s",
              err.text);
    cr_assert_eq(image_write_rgb(tmp_path(dir, "noext"), 1, 1, rgb, NULL, 0, &err), L2P_BAD_INPUT);
    cr_assert_eq(image_write_rgb(tmp_path(dir, "a.png.d/x"), 1, 1, rgb, NULL, 0, &err),
                 L2P_BAD_INPUT);
    cr_assert_eq(count_entries(dir, NULL, NULL, 0), 0);
}

Test(image_io, missing_folder_fails_cleanly)
{
    const char *dir = test_tmpdir();
    float rgb[3] = {0};
    l2p_error err = {0, ""};
    const char *path = tmp_path(dir, "no/such/folder/a.png");
    const int st = image_write_rgb(path, 1, 1, rgb, NULL, 0, &err);
    cr_assert_neq(st, L2P_OK);
    cr_assert_eq(st, L2P_BAD_INPUT, "%s", err.text);
    cr_assert(strstr(err.text, path), "%s", err.text);
    cr_assert_eq(count_entries(dir, NULL, NULL, 0), 0);
}

/* A write that fails at the rename (the final name is a folder) leaves no temporary file. */
Test(image_io, failed_write_leaves_nothing)
{
    const char *dir = test_tmpdir();
    const char *path = tmp_path(dir, "taken.exr");
    cr_assert_eq(mkdir(path, 0755), 0);
    float rgb[3] = {0.5f, 0.5f, 0.5f};
    l2p_error err = {0, ""};
    cr_assert_eq(image_write_rgb(path, 1, 1, rgb, NULL, 0, &err), L2P_FAILED);
    cr_assert(strstr(err.text, path), "%s", err.text);
    cr_assert_eq(count_entries(dir, NULL, NULL, 0), 1);
    rmdir(path);
}

/* A write cut short (here by a file size limit, as a full disk cuts it) fails in every format
   and leaves the earlier picture as it was, with no temporary file. OpenImageIO's PNG writer
   reports nothing then: the file's end is checked. */
Test(image_io, a_write_cut_short_keeps_the_earlier_picture)
{
    const char *dir = test_tmpdir();
    enum { W = 96, H = 64 };
    static float rgb[3 * W * H];
    uint32_t x = 1;
    for (int i = 0; i < 3 * W * H; i++) {   /* noise: tens of kilobytes in any format */
        x = x * 1664525u + 1013904223u;
        rgb[i] = (float)(x >> 8) * 0x1.0p-24f;
    }
    const char *const names[] = {"cut.png", "cut.exr", "cut.tif"};
    signal(SIGXFSZ, SIG_IGN);   /* the write fails with EFBIG instead of killing the test */
    for (int k = 0; k < 3; k++) {
        const char *path = tmp_path(dir, names[k]);
        l2p_error err = {0, ""};
        float one[3] = {0.5f, 0.5f, 0.5f};
        cr_assert_eq(image_write_rgb(path, 1, 1, one, NULL, 0, &err), L2P_OK, "%s", err.text);
        size_t before_size;
        char *before = read_text(path, &before_size);
        struct rlimit old, limit;
        cr_assert_eq(getrlimit(RLIMIT_FSIZE, &old), 0);
        limit = old;
        limit.rlim_cur = 4096;
        cr_assert_eq(setrlimit(RLIMIT_FSIZE, &limit), 0);
        const int st = image_write_rgb(path, W, H, rgb, NULL, 0, &err);
        cr_assert_eq(setrlimit(RLIMIT_FSIZE, &old), 0);
        cr_expect_eq(st, L2P_FAILED, "%s: %s", names[k], err.text);
        size_t after_size;
        char *after = read_text(path, &after_size);
        cr_expect(after_size == before_size && !memcmp(before, after, before_size),
                  "%s was replaced", names[k]);
        cr_expect_eq(count_entries(dir, ".", NULL, 0), 0, "a temporary file was left");
        free(before), free(after);
    }
}

/* An EXR keeps its values: half floats when they hold them, else 32-bit floats, so that
   physical weights through a tiny stop (1e-8) and bright ones (1e6) are not lost. */
Test(image_io, an_exr_keeps_values_half_floats_cannot)
{
    const char *path = tmp_path(test_tmpdir(), "range.exr");
    const float rgb[6] = {6.517e-8f, 1e-5f, 0.25f, 1e6f, 3.0f, 0.0f};
    l2p_error err = {0, ""};
    cr_assert_eq(image_write_rgb(path, 2, 1, rgb, NULL, 0, &err), L2P_OK, "%s", err.text);
    int w, h;
    float *px;
    cr_assert_eq(image_read_rgba(path, &w, &h, &px, &err), L2P_OK, "%s", err.text);
    for (int i = 0; i < 2; i++)
        for (int c = 0; c < 3; c++)
            cr_expect_eq(px[4 * i + c], rgb[3 * i + c], "pixel %d channel %d: %g, written %g", i,
                         c, px[4 * i + c], rgb[3 * i + c]);
    free(px);
}

Test(image_io, atomic_write_leaves_no_temp)
{
    const char *dir = test_tmpdir();
    const char *path = tmp_path(dir, "pic.png");
    float rgb[3 * 4];
    fill_rgb(rgb, 4, 0.25f);
    l2p_error err = {0, ""};
    cr_assert_eq(image_write_rgb(path, 2, 2, rgb, NULL, 0, &err), L2P_OK, "%s", err.text);
    fill_rgb(rgb, 4, 1.0f);   /* overwriting replaces the file */
    cr_assert_eq(image_write_rgb(path, 2, 2, rgb, NULL, 0, &err), L2P_OK, "%s", err.text);
    cr_assert_eq(count_entries(dir, NULL, NULL, 0), 1);
    cr_assert_eq(count_entries(dir, ".", NULL, 0), 0);
    cr_assert(file_exists(path));
    int w, h;
    float *px;
    cr_assert_eq(image_read_rgba(path, &w, &h, &px, &err), L2P_OK, "%s", err.text);
    cr_assert_eq(px[0], 1.0f);
    free(px);
}

/* An output named by a symbolic link (here a relative one, to a folder beside it) is written
   through it: the link stays a link and its target gets the picture. A link loop is refused
   by name. */
Test(image_io, an_output_named_by_a_link_is_written_through_it)
{
    const char *dir = test_tmpdir();
    char *sub = strdup(tmp_path(dir, "pictures"));
    cr_assert_eq(mkdir(sub, 0755), 0);
    char *link = strdup(tmp_path(dir, "latest.png"));
    cr_assert_eq(symlink("pictures/shot.png", link), 0);
    float rgb[3 * 4];
    fill_rgb(rgb, 4, 0.25f);
    l2p_error err = {0, ""};
    cr_assert_eq(image_write_rgb(link, 2, 2, rgb, NULL, 0, &err), L2P_OK, "%s", err.text);
    struct stat sb;
    cr_assert_eq(lstat(link, &sb), 0);
    cr_assert(S_ISLNK(sb.st_mode), "the link was replaced");
    cr_assert(file_exists(tmp_path(dir, "pictures/shot.png")));
    cr_assert_eq(count_entries(sub, ".", NULL, 0), 0, "a temporary file was left");

    char *loop = strdup(tmp_path(dir, "loop.png"));
    cr_assert_eq(symlink("loop.png", loop), 0);
    cr_assert_eq(image_write_rgb(loop, 2, 2, rgb, NULL, 0, &err), L2P_BAD_INPUT);
    cr_assert(strstr(err.text, loop) && strstr(err.text, "symbolic links"), "%s", err.text);
    free(sub), free(link), free(loop);
}

Test(image_io, read_errors)
{
    const char *dir = test_tmpdir();
    int w, h;
    float *px = NULL;
    l2p_error err = {0, ""};
    const char *missing = tmp_path(dir, "missing.exr");
    cr_assert_eq(image_read_rgba(missing, &w, &h, &px, &err), L2P_BAD_INPUT);
    cr_assert(strstr(err.text, missing), "%s", err.text);
    const char *junk = tmp_path(dir, "junk.exr");
    FILE *fp = fopen(junk, "wb");
    fputs("not an image\n", fp);
    fclose(fp);
    cr_assert_eq(image_read_rgba(junk, &w, &h, &px, &err), L2P_BAD_INPUT);
    cr_assert(strstr(err.text, junk), "%s", err.text);
    cr_assert_null(strchr(err.text, '\n'), "%s", err.text);
    cr_assert_null(px);
    /* a picture cut short: its header reads, its pixels do not */
    const char *cut = tmp_path(dir, "cut.exr");
    float rgb[3 * 64 * 64];
    for (int i = 0; i < 3 * 64 * 64; i++)   /* noise, so that compression leaves bytes to cut */
        rgb[i] = (float)((i * 7919) % 1000) / 1000.0f;
    cr_assert_eq(image_write_rgb(cut, 64, 64, rgb, NULL, 0, &err), L2P_OK, "%s", err.text);
    struct stat sb;
    cr_assert_eq(stat(cut, &sb), 0);
    cr_assert_eq(truncate(cut, sb.st_size / 2), 0);
    cr_assert_eq(image_read_rgba(cut, &w, &h, &px, &err), L2P_BAD_INPUT);
    cr_assert(strstr(err.text, cut), "%s", err.text);
    cr_assert_null(px);
}

/* Reads an 8-bit netpbm file of w x h pixels (P5: grey, P6: RGB) written from bytes. */
static float *read_netpbm(const char *name, const char *magic, int w, int h,
                          const unsigned char *bytes, size_t n)
{
    const char *path = tmp_path(test_tmpdir(), name);
    FILE *fp = fopen(path, "wb");
    cr_assert_not_null(fp);
    fprintf(fp, "%s\n%d %d\n255\n", magic, w, h);
    fwrite(bytes, 1, n, fp);
    fclose(fp);
    int rw, rh;
    float *px;
    l2p_error err = {0, ""};
    cr_assert_eq(image_read_rgba(path, &rw, &rh, &px, &err), L2P_OK, "%s", err.text);
    cr_assert(rw == w && rh == h);
    return px;
}

/* A one-channel 8-bit file (PGM) is grey with alpha 1, sRGB-decoded. */
Test(image_io, grey_file_read_as_rgba)
{
    const unsigned char grey[3] = {0, 188, 255};
    float *px = read_netpbm("g.pgm", "P5", 3, 1, grey, sizeof grey);
    const double want[3] = {0.0, srgb_decode(188 / 255.0), 1.0};
    for (int i = 0; i < 3; i++) {
        for (int c = 0; c < 3; c++)
            cr_assert_float_eq(px[4 * i + c], want[i], 1e-6);
        cr_assert_eq(px[4 * i + 3], 1.0f);
    }
    free(px);
}

/* A three-channel file (PPM) of distinct values: each pixel's channels land in its own RGBA,
   in order (the reader converts in place, last pixel first). */
Test(image_io, rgb_file_read_as_rgba_pixel_by_pixel)
{
    unsigned char rgb[18];
    for (int i = 0; i < 18; i++)
        rgb[i] = (unsigned char)(10 * i + 3);
    float *px = read_netpbm("c.ppm", "P6", 3, 2, rgb, sizeof rgb);
    for (int i = 0; i < 6; i++) {
        for (int c = 0; c < 3; c++)
            cr_assert_float_eq(px[4 * i + c], srgb_decode((10 * (3 * i + c) + 3) / 255.0), 1e-6,
                               "pixel %d channel %d", i, c);
        cr_assert_eq(px[4 * i + 3], 1.0f);
    }
    free(px);
}

