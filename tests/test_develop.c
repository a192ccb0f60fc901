/* Sample maps and developing, without POV-Ray: synthetic maps and renders whose every output
   pixel is checked against an independent computation (image files: test_image_io.c). */
#include <criterion/criterion.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "image/develop.h"
#include "image/image_io.h"
#include "image/samplemap.h"
#include "optics/spectrum.h"
#include "support.h"

/* ---- a synthetic layout ----
   Film 7x5, crop x 2..5, y 1..3 (4x3 = 12 pixels), spp 2, packed width 5, chunks of 10 faces
   (2 rows), 23 faces: chunk 0 and 1 full, chunk 2 one partial row of 3 faces. */
enum { FW = 7, FH = 5, CX0 = 2, CY0 = 1, CX1 = 6, CY1 = 4, PW = 5, CHUNK = 10, FACES = 23 };
enum { CW = CX1 - CX0, CH = CY1 - CY0 };

static void fill_header(samplemap_header *h)
{
    memset(h, 0, sizeof *h);
    h->film_width = FW;
    h->film_height = FH;
    h->spp = 2;
    h->crop_x0 = CX0;
    h->crop_y0 = CY0;
    h->crop_x1 = CX1;
    h->crop_y1 = CY1;
    h->packed_width = PW;
    h->faces = FACES;
    h->chunk_faces = CHUNK;
    snprintf(h->lens, sizeof h->lens, "Double Gauss 50mm f/2");
    snprintf(h->pupil, sizeof h->pupil, "stop-image");
    snprintf(h->trace, sizeof h->trace, "full");
    snprintf(h->weighting, sizeof h->weighting, "normalized");
    h->f_number = 2.8;
    h->aperture_diameter_mm = 17.5;
    h->focus_distance_units = 3.25;
    h->film_distance_mm = 38.125;
    h->film_diagonal_mm = 35;
    h->unit_mm = 1000;
}

/* Face k goes to crop pixel (5k mod 12), so pixels get 1 to 3 samples from different chunks;
   weights are exact binary fractions. */
static samplemap_record face_record(int k)
{
    const int c = (5 * k) % (CW * CH);
    samplemap_record r;
    r.film_pixel = (uint32_t)((CY0 + c / CW) * FW + CX0 + c % CW);
    r.offset_x = 0.125f * (float)(k % 8);
    r.offset_y = 0.0625f * (float)(k % 16);
    r.weight = 0.25f * (float)(k % 4 + 1);
    return r;
}

static void make_map(samplemap *m)
{
    fill_header(&m->header);
    m->records = malloc(sizeof *m->records * FACES);
    m->band = NULL;
    for (int k = 0; k < FACES; k++)
        m->records[k] = face_record(k);
}

/* What POV-Ray renders for face k (exact in half float too). */
static void face_colour(int k, float rgb[3])
{
    rgb[0] = (float)k + 0.5f;
    rgb[1] = 2.0f * (float)k;
    rgb[2] = 100.0f - (float)k;
}

/* Chunk k's render, RGBA, with the row work-around: image row y >= 1 shows face row y - 1.
   Row 0 holds garbage that must never be read; the slots past the last face are black, as
   POV-Ray leaves them (develop checks that). */
static float *make_render(int chunk, int *width, int *height)
{
    const int rows = chunk < 2 ? 2 : 1;
    *width = PW;
    *height = rows + 1;
    float *px = malloc(sizeof *px * 4 * PW * (size_t)(rows + 1));
    for (int y = 0; y <= rows; y++)
        for (int x = 0; x < PW; x++) {
            float *p = px + 4 * (y * PW + x);
            const int face = chunk * CHUNK + (y - 1) * PW + x;
            if (face >= FACES && y > 0) {
                p[0] = p[1] = p[2] = p[3] = 0.0f;
            } else if (y == 0) {
                p[0] = NAN;
                p[1] = 1e30f;
                p[2] = -7.0f;
                p[3] = 0.0f;
            } else {
                face_colour(face, p);
                p[3] = 1.0f;
            }
        }
    return px;
}

/* The answer, computed face by face without any chunk or row logic. */
static void expected_picture(float *rgb)
{
    double sums[3 * CW * CH] = {0};
    for (int k = 0; k < FACES; k++) {
        const samplemap_record r = face_record(k);
        const int x = (int)(r.film_pixel % FW) - CX0, y = (int)(r.film_pixel / FW) - CY0;
        float c[3];
        face_colour(k, c);
        for (int i = 0; i < 3; i++)
            sums[3 * (y * CW + x) + i] += (double)r.weight * (double)c[i];
    }
    for (int i = 0; i < 3 * CW * CH; i++)
        rgb[i] = (float)(sums[i] / 2.0);
}

/* ---- chunk layout ---- */

Test(samplemap, chunk_count_and_rows)
{
    samplemap_header h;
    fill_header(&h);
    cr_assert_eq(samplemap_chunk_count(&h), 3);
    cr_assert_eq(samplemap_chunk_rows(&h, 0), 2);
    cr_assert_eq(samplemap_chunk_rows(&h, 1), 2);
    cr_assert_eq(samplemap_chunk_rows(&h, 2), 1);
    cr_assert_eq(samplemap_chunk_rows(&h, 3), 0);
    cr_assert_eq(samplemap_chunk_rows(&h, -1), 0);
    h.faces = 20;   /* an exact multiple: no empty trailing chunk */
    cr_assert_eq(samplemap_chunk_count(&h), 2);
    cr_assert_eq(samplemap_chunk_rows(&h, 1), 2);
    h.faces = 21;
    cr_assert_eq(samplemap_chunk_count(&h), 3);
    cr_assert_eq(samplemap_chunk_rows(&h, 2), 1);
    h.faces = 0;    /* nothing passed the lens: one chunk of one (dummy) row */
    cr_assert_eq(samplemap_chunk_count(&h), 1);
    cr_assert_eq(samplemap_chunk_rows(&h, 0), 1);
}

/* ---- developing ---- */

/* The three synthetic renders developed through the synthetic map into rgb. */
static void develop_synthetic(float *rgb)
{
    samplemap m;
    make_map(&m);
    double *sums = calloc(3 * CW * CH, sizeof *sums);
    l2p_error err = {0, ""};
    for (int k = 0; k < 3; k++) {
        int w, h;
        float *px = make_render(k, &w, &h);
        cr_assert_eq(develop_accumulate(&m, k, px, w, h, sums, &err), L2P_OK, "%s", err.text);
        free(px);
    }
    develop_finish(&m, sums, rgb);
    free(sums);
    samplemap_free(&m);
}

Test(develop, every_pixel_exact)
{
    float got[3 * CW * CH], want[3 * CW * CH];
    develop_synthetic(got);
    expected_picture(want);
    for (int i = 0; i < 3 * CW * CH; i++)
        cr_assert_eq(got[i], want[i], "value %d: %.9g != %.9g", i, got[i], want[i]);

}

/* Two literal pixels, worked by hand: crop pixel (0, 0) (film 2,1) gets faces 0 (w 0.25,
   colour 0.5,0,100), 12 (w 0.25, colour 12.5,24,88) and 24 (no such face); crop pixel (1, 0)
   gets face 5 (w 0.5, colour 5.5,10,95) and face 17 (w 0.5, colour 17.5,34,83). */
Test(develop, hand_computed_pixels)
{
    float rgb[3 * CW * CH];
    develop_synthetic(rgb);
    cr_assert_eq(rgb[0], (0.25f * 0.5f + 0.25f * 12.5f) / 2);
    cr_assert_eq(rgb[1], (0.25f * 24.0f) / 2);
    cr_assert_eq(rgb[2], (0.25f * 100.0f + 0.25f * 88.0f) / 2);
    cr_assert_eq(rgb[3], (0.5f * 5.5f + 0.5f * 17.5f) / 2);
    cr_assert_eq(rgb[4], (0.5f * 10.0f + 0.5f * 34.0f) / 2);
    cr_assert_eq(rgb[5], (0.5f * 95.0f + 0.5f * 83.0f) / 2);
}

Test(develop, wrong_render_size_refused)
{
    samplemap m;
    make_map(&m);
    double sums[3 * CW * CH] = {0};
    float px[4 * PW * 4] = {0};
    l2p_error err = {0, ""};
    /* chunk 0 needs 5x3: without the duplicate row, or one row too many, it is refused */
    cr_assert_eq(develop_accumulate(&m, 0, px, PW, 2, sums, &err), L2P_BAD_INPUT);
    cr_assert(strstr(err.text, "5x2") && strstr(err.text, "expected 5x3"), "%s", err.text);
    cr_assert_neq(develop_accumulate(&m, 2, px, PW, 3, sums, &err), L2P_OK);
    cr_assert_eq(develop_accumulate(&m, 0, px, 4, 3, sums, &err), L2P_BAD_INPUT);
    cr_assert_eq(develop_accumulate(&m, 3, px, PW, 2, sums, &err), L2P_FAILED);
    for (int i = 0; i < 3 * CW * CH; i++)
        cr_assert_eq(sums[i], 0.0);
    samplemap_free(&m);
}

/* The whole step through files: renders as EXR (their values are exact in half float), the
   picture as EXR with its metadata. */
Test(develop, files_end_to_end)
{
    const char *dir = test_tmpdir();
    samplemap m;
    make_map(&m);
    char paths[3][512];
    const char *renders[3];
    l2p_error err = {0, ""};
    for (int k = 0; k < 3; k++) {
        int w, h;
        float *px = make_render(k, &w, &h), *rgb = malloc(sizeof *rgb * 3 * (size_t)(w * h));
        for (int i = 0; i < w * h; i++)   /* RGB only: half float would keep NaN, 1e30 as inf */
            for (int c = 0; c < 3; c++)
                rgb[3 * i + c] = isfinite(px[4 * i + c]) && fabsf(px[4 * i + c]) < 1e4f
                                     ? px[4 * i + c] : 65504.0f;
        snprintf(paths[k], sizeof paths[k], "%s/chunk%d.exr", dir, k);
        renders[k] = paths[k];
        cr_assert_eq(image_write_rgb(paths[k], w, h, rgb, NULL, 0, &err), L2P_OK, "%s", err.text);
        free(px);
        free(rgb);
    }
    const char *out = tmp_path(dir, "picture.exr");
    cr_assert_eq(develop_files(&m, renders, 3, out, &err), L2P_OK, "%s", err.text);
    int w, h;
    float *got, want[3 * CW * CH];
    cr_assert_eq(image_read_rgba(out, &w, &h, &got, &err), L2P_OK, "%s", err.text);
    cr_assert(w == CW && h == CH, "%dx%d", w, h);
    expected_picture(want);
    for (int i = 0; i < CW * CH; i++)
        for (int c = 0; c < 3; c++)
            cr_assert_float_eq(got[4 * i + c], want[3 * i + c],
                               1e-3 * fabsf(want[3 * i + c]) + 1e-6);
    free(got);
    char value[256];
    expect_attribute(out, "lens2pov:lens", "Double Gauss 50mm f/2");
    expect_attribute(out, "lens2pov:spp", "2");
    expect_attribute(out, "lens2pov:focus_distance", "3.25");
    expect_attribute(out, "Software", "lens2pov");
    cr_assert_eq(image_get_attribute(out, "Exif:FNumber", value, sizeof value), L2P_OK);
    cr_assert_float_eq(atof(value), 2.8, 1e-6);
    samplemap_free(&m);
}

/* One file given as two renders (the other's place taken) is refused before any is read: one
   chunk would be developed twice and another never. */
Test(develop, a_render_given_twice_is_refused)
{
    const char *dir = test_tmpdir();
    samplemap m;
    make_map(&m);
    const char *a = tmp_path(dir, "a.exr"), *b = tmp_path(dir, "b.exr");
    write_text(a, "not read");
    write_text(b, "not read");
    char via_dot[600];
    snprintf(via_dot, sizeof via_dot, "%s/./a.exr", dir);
    const char *renders[3] = {a, b, via_dot};
    l2p_error err = {0, ""};
    cr_assert_eq(develop_files(&m, renders, 3, tmp_path(dir, "out.png"), &err), L2P_BAD_INPUT);
    cr_expect(strstr(err.text, "render 0 and as render 2"), "%s", err.text);
    cr_expect_not(file_exists(tmp_path(dir, "out.png")));
    samplemap_free(&m);
}

Test(develop, render_count_must_match_chunks)
{
    samplemap m;
    make_map(&m);
    const char *renders[1] = {"/nonexistent.exr"};
    l2p_error err = {0, ""};
    cr_assert_eq(develop_files(&m, renders, 1, "/tmp/never.png", &err), L2P_BAD_INPUT);
    cr_assert(strstr(err.text, "3 chunks"), "%s", err.text);
    samplemap_free(&m);
}

Test(develop, missing_render_names_file)
{
    samplemap m;
    make_map(&m);
    m.header.faces = 3;   /* one chunk */
    const char *dir = test_tmpdir();
    const char *renders[1] = {tmp_path(dir, "missing.exr")};
    l2p_error err = {0, ""};
    cr_assert_eq(develop_files(&m, renders, 1, tmp_path(dir, "out.png"), &err), L2P_BAD_INPUT);
    cr_assert(strstr(err.text, "missing.exr"), "%s", err.text);
    cr_assert_eq(count_entries(dir, NULL, NULL, 0), 0);
    samplemap_free(&m);
}

/* ---- sample map files ---- */

static void write_map_file(const char *path, const samplemap_header *h,
                           const samplemap_record *records, size_t count)
{
    FILE *fp = fopen(path, "wb");
    cr_assert_not_null(fp);
    cr_assert_eq(samplemap_begin(fp), L2P_OK);
    cr_assert_eq(samplemap_append(fp, records, NULL, count), L2P_OK);
    cr_assert_eq(samplemap_finish(fp, h), L2P_OK);
    cr_assert_eq(fclose(fp), 0);
}

static const char *write_test_map(const char *dir)
{
    samplemap m;
    make_map(&m);
    const char *path = tmp_path(dir, "rays.map");
    write_map_file(path, &m.header, m.records, FACES);
    samplemap_free(&m);
    return path;
}

Test(samplemap, round_trip_exact)
{
    const char *dir = test_tmpdir();
    samplemap m;
    make_map(&m);
    /* values whose bits must survive: tiny, huge, just below 1, a newline in the lens name */
    m.records[3].weight = 1e-40f;
    m.records[4].weight = 3.0e38f;
    m.records[5].offset_x = nextafterf(1.0f, 0.0f);
    m.records[6].weight = 0.1f;
    snprintf(m.header.lens, sizeof m.header.lens, "Tessar\nf/3.5\r!");
    m.header.focus_distance_units = INFINITY;
    m.header.f_number = 0.1;
    const char *path = tmp_path(dir, "rays.map");
    write_map_file(path, &m.header, m.records, FACES);
    struct stat st;
    cr_assert_eq(stat(path, &st), 0);
    cr_assert_eq(st.st_size, SAMPLEMAP_HEADER_BYTES + 16 * FACES);

    samplemap r;
    l2p_error err = {0, ""};
    cr_assert_eq(samplemap_read(path, &r, &err), L2P_OK, "%s", err.text);
    const samplemap_header *a = &r.header, *b = &m.header;
    cr_assert(a->film_width == b->film_width && a->film_height == b->film_height);
    cr_assert_eq(a->spp, b->spp);
    cr_assert(a->crop_x0 == CX0 && a->crop_y0 == CY0 && a->crop_x1 == CX1 && a->crop_y1 == CY1);
    cr_assert(a->packed_width == PW && a->faces == FACES && a->chunk_faces == CHUNK);
    cr_assert_str_eq(a->lens, "Tessar f/3.5 !");
    cr_assert_str_eq(a->pupil, "stop-image");
    cr_assert_str_eq(a->trace, "full");
    cr_assert_str_eq(a->weighting, "normalized");
    cr_assert_eq(a->f_number, 0.1);
    cr_assert_eq(a->aperture_diameter_mm, 17.5);
    cr_assert(isinf(a->focus_distance_units) && a->focus_distance_units > 0);
    cr_assert_eq(a->film_distance_mm, 38.125);
    cr_assert_eq(a->film_diagonal_mm, 35.0);
    cr_assert_eq(a->unit_mm, 1000.0);
    cr_assert_eq(memcmp(r.records, m.records, sizeof *m.records * FACES), 0);
    samplemap_free(&r);
    samplemap_free(&m);
}

/* The on-disk bytes are little-endian whatever the machine, and the header is text. */
Test(samplemap, file_layout)
{
    const char *dir = test_tmpdir();
    samplemap_header h;
    fill_header(&h);
    h.faces = 1;
    const samplemap_record rec = {0x01020304u, 0.5f, 0.25f, 1.0f};
    const char *path = tmp_path(dir, "one.map");
    write_map_file(path, &h, &rec, 1);
    FILE *fp = fopen(path, "rb");
    unsigned char buf[SAMPLEMAP_HEADER_BYTES + 16];
    cr_assert_eq(fread(buf, 1, sizeof buf, fp), sizeof buf);
    fclose(fp);
    char text[SAMPLEMAP_HEADER_BYTES + 1];
    memcpy(text, buf, SAMPLEMAP_HEADER_BYTES);
    text[SAMPLEMAP_HEADER_BYTES] = '\0';
    cr_assert_eq(memcmp(text, "lens2pov-samplemap 1\nfilm_width 7\n", 34), 0);
    cr_assert_not_null(strstr(text, "\nunit_mm 1000\nend\n "));
    cr_assert_eq(buf[SAMPLEMAP_HEADER_BYTES - 1], ' ');
    const unsigned char want[16] = {4, 3, 2, 1, 0, 0, 0, 0x3f, 0, 0, 0x80, 0x3e, 0, 0, 0x80, 0x3f};
    cr_assert_eq(memcmp(buf + SAMPLEMAP_HEADER_BYTES, want, 16), 0);
}

Test(samplemap, empty_table)
{
    const char *dir = test_tmpdir();
    samplemap_header h;
    fill_header(&h);
    h.faces = 0;
    h.chunk_faces = PW;
    const char *path = tmp_path(dir, "empty.map");
    write_map_file(path, &h, NULL, 0);
    samplemap r;
    l2p_error err = {0, ""};
    cr_assert_eq(samplemap_read(path, &r, &err), L2P_OK, "%s", err.text);
    cr_assert_eq(r.header.faces, 0);
    cr_assert_eq(samplemap_chunk_count(&r.header), 1);
    samplemap_free(&r);
}

Test(samplemap, finish_checks_record_count)
{
    const char *dir = test_tmpdir();
    samplemap m;
    make_map(&m);
    FILE *fp = fopen(tmp_path(dir, "short.map"), "wb");
    cr_assert_eq(samplemap_begin(fp), L2P_OK);
    cr_assert_eq(samplemap_append(fp, m.records, NULL, FACES - 1), L2P_OK);
    cr_assert_eq(samplemap_finish(fp, &m.header), L2P_FAILED);
    fclose(fp);
    samplemap_free(&m);
}

static void expect_refused(const char *path, const char *fragment)
{
    samplemap r;
    l2p_error err = {0, ""};
    cr_assert_eq(samplemap_read(path, &r, &err), L2P_BAD_INPUT, "accepted: %s", path);
    cr_assert(strstr(err.text, path), "no file name in: %s", err.text);
    cr_assert(strstr(err.text, fragment), "'%s' not in: %s", fragment, err.text);
    cr_assert_null(r.records);
}

Test(samplemap, truncated_refused)
{
    const char *dir = test_tmpdir();
    const char *path = write_test_map(dir);
    cr_assert_eq(truncate(path, SAMPLEMAP_HEADER_BYTES + 16 * FACES - 5), 0);
    expect_refused(path, "truncated");
    cr_assert_eq(truncate(path, 100), 0);
    expect_refused(path, "header");
    cr_assert_eq(truncate(path, 0), 0);
    expect_refused(path, "header");
}

Test(samplemap, trailing_bytes_refused)
{
    const char *dir = test_tmpdir();
    const char *path = write_test_map(dir);
    FILE *fp = fopen(path, "ab");
    fputc(0, fp);
    fclose(fp);
    expect_refused(path, "faces");
}

static void patch(const char *path, long offset, const char *bytes)
{
    FILE *fp = fopen(path, "r+b");
    cr_assert_not_null(fp);
    fseek(fp, offset, SEEK_SET);
    fwrite(bytes, 1, strlen(bytes), fp);
    fclose(fp);
}

Test(samplemap, wrong_magic_refused)
{
    const char *dir = test_tmpdir();
    const char *path = write_test_map(dir);
    patch(path, 0, "lens2pov-samplemap 2");
    expect_refused(path, "not a lens2pov sample map");
    patch(path, 0, "LENS2POV");
    expect_refused(path, "not a lens2pov sample map");
    expect_refused(tmp_path(dir, "absent.map"), "No such file");
}

/* A header written by hand: every key, one at a time, replaced by a bad line. */
static const char *hand_map(const char *dir, const char *replace_key, const char *line)
{
    static const char *lines[] = {
        "film_width 7", "film_height 5", "spp 2", "crop_x0 2", "crop_y0 1", "crop_x1 6",
        "crop_y1 4", "packed_width 5", "faces 1", "chunk_faces 10", "lens Some lens",
        "pupil rear", "trace full", "weighting physical", "f_number 4", "aperture_diameter_mm 9",
        "focus_distance_units inf", "film_distance_mm 50", "film_diagonal_mm 35", "unit_mm 1000"};
    char text[SAMPLEMAP_HEADER_BYTES + 1] = "lens2pov-samplemap 1\n";
    for (size_t i = 0; i < sizeof lines / sizeof lines[0]; i++) {
        const int match = replace_key && strncmp(lines[i], replace_key, strlen(replace_key)) == 0 &&
                          lines[i][strlen(replace_key)] == ' ';
        const char *l = match ? line : lines[i];
        if (l && *l) {
            strcat(text, l);
            strcat(text, "\n");
        }
    }
    strcat(text, "end\n");
    memset(text + strlen(text), ' ', SAMPLEMAP_HEADER_BYTES - strlen(text));
    text[SAMPLEMAP_HEADER_BYTES] = '\0';
    const char *path = tmp_path(dir, "hand.map");
    FILE *fp = fopen(path, "wb");
    fwrite(text, 1, SAMPLEMAP_HEADER_BYTES, fp);
    const unsigned char rec[16] = {2 + 7, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x80, 0x3f};
    fwrite(rec, 1, 16, fp);
    fclose(fp);
    return path;
}

Test(samplemap, hand_written_header)
{
    const char *dir = test_tmpdir();
    samplemap r;
    l2p_error err = {0, ""};
    cr_assert_eq(samplemap_read(hand_map(dir, NULL, NULL), &r, &err), L2P_OK, "%s", err.text);
    cr_assert_eq(r.records[0].film_pixel, 9u);
    cr_assert_eq(r.records[0].weight, 1.0f);
    cr_assert_str_eq(r.header.lens, "Some lens");
    samplemap_free(&r);
    /* unknown keys are skipped */
    cr_assert_eq(samplemap_read(hand_map(dir, "lens", "lens x\nnew_key 3"), &r, &err), L2P_OK,
                 "%s", err.text);
    samplemap_free(&r);
}

Test(samplemap, bad_headers_refused)
{
    const char *dir = test_tmpdir();
    expect_refused(hand_map(dir, "spp", ""), "no 'spp'");
    expect_refused(hand_map(dir, "spp", "spp 2\nspp 2"), "twice");
    expect_refused(hand_map(dir, "spp", "spp two"), "bad value for spp");
    expect_refused(hand_map(dir, "spp", "spp 0"), "spp");
    expect_refused(hand_map(dir, "film_width", "film_width 99999999999"), "film_width");
    expect_refused(hand_map(dir, "chunk_faces", "chunk_faces 12"), "multiple of packed_width");
    expect_refused(hand_map(dir, "chunk_faces", "chunk_faces 0"), "multiple of packed_width");
    expect_refused(hand_map(dir, "packed_width", "packed_width 0"), "packed_width");
    expect_refused(hand_map(dir, "crop_x1", "crop_x1 8"), "crop");
    expect_refused(hand_map(dir, "crop_y0", "crop_y0 4"), "crop");
    expect_refused(hand_map(dir, "faces", "faces 2"), "truncated");
    expect_refused(hand_map(dir, "f_number", "f_number 4x"), "f_number");
    expect_refused(hand_map(dir, "pupil", "pupil 0123456789012345678901234567890123"), "pupil");
}

static const char *map_with_record(const char *dir, samplemap_record rec)
{
    samplemap_header h;
    fill_header(&h);
    h.faces = 1;
    const char *path = tmp_path(dir, "rec.map");
    write_map_file(path, &h, &rec, 1);
    return path;
}

Test(samplemap, bad_records_refused)
{
    const char *dir = test_tmpdir();
    typedef samplemap_record rec;
    const uint32_t inside = CY0 * FW + CX0;
    expect_refused(map_with_record(dir, (rec){inside - 1, 0, 0, 1}), "outside the crop");
    expect_refused(map_with_record(dir, (rec){CY1 * FW + CX0, 0, 0, 1}), "outside the crop");
    expect_refused(map_with_record(dir, (rec){UINT32_MAX, 0, 0, 1}), "outside the crop");
    expect_refused(map_with_record(dir, (rec){inside, 0, 0, NAN}), "weight");
    expect_refused(map_with_record(dir, (rec){inside, 0, 0, INFINITY}), "weight");
    expect_refused(map_with_record(dir, (rec){inside, 0, 0, -1}), "weight");
    expect_refused(map_with_record(dir, (rec){inside, 1.5f, 0, 1}), "offset");
    expect_refused(map_with_record(dir, (rec){inside, 0, NAN, 1}), "offset");
    samplemap r;
    l2p_error err = {0, ""};
    cr_assert_eq(samplemap_read(map_with_record(dir, (rec){inside, 1, 1, 0}), &r, &err), L2P_OK,
                 "%s", err.text);
    samplemap_free(&r);
}

/* ---- dispersion: bands in the map, colour in developing ---- */

static void write_band_map(const char *path, const samplemap *m, const uint32_t *band)
{
    FILE *fp = fopen(path, "wb");
    cr_assert_not_null(fp);
    cr_assert_eq(samplemap_begin(fp), L2P_OK);
    cr_assert_eq(samplemap_append(fp, m->records, band, FACES), L2P_OK);
    cr_assert_eq(samplemap_finish(fp, &m->header), L2P_OK);
    cr_assert_eq(fclose(fp), 0);
}

/* With wavelength bands every record carries one (4 bytes more), the header says how many,
   and they come back as written; a band outside them, or a band count other than spp, is
   refused. */
Test(samplemap, bands_round_trip_and_are_checked)
{
    const char *dir = test_tmpdir();
    samplemap m;
    make_map(&m);
    m.header.wavelength_bands = m.header.spp;
    uint32_t band[FACES];
    for (int k = 0; k < FACES; k++)
        band[k] = (uint32_t)(k % m.header.spp);
    const char *path = tmp_path(dir, "bands.map");
    write_band_map(path, &m, band);
    struct stat st;
    cr_assert_eq(stat(path, &st), 0);
    cr_assert_eq(st.st_size, SAMPLEMAP_HEADER_BYTES + 20 * FACES);
    samplemap r;
    l2p_error err = {0, ""};
    cr_assert_eq(samplemap_read(path, &r, &err), L2P_OK, "%s", err.text);
    cr_assert_eq(r.header.wavelength_bands, m.header.spp);
    cr_assert_not_null(r.band);
    cr_assert_eq(memcmp(r.band, band, sizeof band), 0);
    cr_assert_eq(memcmp(r.records, m.records, sizeof *m.records * FACES), 0);
    samplemap_free(&r);

    band[FACES - 1] = (uint32_t)m.header.spp;   /* one past the last band */
    write_band_map(path, &m, band);
    cr_assert_eq(samplemap_read(path, &r, &err), L2P_BAD_INPUT);
    cr_assert(strstr(err.text, "band"), "%s", err.text);

    m.header.wavelength_bands = m.header.spp + 1;
    band[FACES - 1] = 0;
    write_band_map(path, &m, band);
    cr_assert_eq(samplemap_read(path, &r, &err), L2P_BAD_INPUT);
    cr_assert(strstr(err.text, "wavelength_bands"), "%s", err.text);
    samplemap_free(&m);
}

/* Developing with bands, worked by hand: a pixel's channel is (sum of weights) / spp times its
   radiances averaged with weight x band weight; where that denominator falls below a quarter
   of the weights, the plain weighted mean. */
Test(develop, dispersion_renormalizes_the_band_weights)
{
    samplemap_header h;
    memset(&h, 0, sizeof h);
    h.film_width = 2, h.film_height = 1, h.spp = 4, h.crop_x1 = 2, h.crop_y1 = 1;
    h.wavelength_bands = 4;
    samplemap m = {.header = h};
    double colour[4][3];
    for (int b = 0; b < 4; b++)
        spectrum_band_weights(b, 4, colour[b]);
    double sums[2 * 10] = {0};
    /* pixel 0: bands 0, 1, 3 pass with weights 1, 0.5, 2 and colours (1, 1, 1), (0, 2, 4),
       (3, 0, 1); band 2 is blocked */
    const float rgba[3][4] = {{1, 1, 1, 1}, {0, 2, 4, 1}, {3, 0, 1, 1}};
    const int bands[3] = {0, 1, 3};
    const double weights[3] = {1, 0.5, 2};
    for (int k = 0; k < 3; k++)
        develop_add(sums, colour[bands[k]], weights[k], rgba[k]);
    /* pixel 1: a white sample in band 1 alone */
    develop_add(sums + 10, colour[1], 1.0, rgba[0]);
    float rgb[6];
    develop_finish(&m, sums, rgb);
    for (int c = 0; c < 3; c++) {
        double num = 0, den = 0, plain = 0;
        for (int k = 0; k < 3; k++) {
            num += weights[k] * colour[bands[k]][c] * rgba[k][c];
            den += weights[k] * colour[bands[k]][c];
            plain += weights[k] * rgba[k][c];
        }
        const double radiance = den >= 0.25 * 3.5 ? num / den : plain / 3.5;
        cr_expect(fabs(rgb[c] - 3.5 / 4 * radiance) < 1e-6 * fabs(radiance) + 1e-7,
                  "channel %d: %g, by hand %g", c, rgb[c], 3.5 / 4 * radiance);
        cr_expect(fabs(rgb[3 + c] - 0.25f) < 1e-7, "a white sample alone stays white: %g", rgb[3 + c]);
    }
}
