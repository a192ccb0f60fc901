/* lens2pov render with the real POV-Ray (issue 3): the picture is upright and unmirrored, agrees
   with POV-Ray's own perspective camera, the physical weights do not depend on the pupil that is
   sampled, failures leave nothing behind, a crop is a region of the whole picture, old and new
   scenes come out as POV-Ray shows them, and chunks do not change a pixel.
   Every scene is written at run time into a fresh folder, removed at the end. The pictures are
   small (64x48 or less): each test takes 1-3.5 s on two idle cores, mostly start-up: about
   0.5 s for each lens2pov process (loading OpenImageIO) and 0.7 s for each POV-Ray process.
   No .timeout (see test_povray.c: it leaks under AddressSanitizer with --jobs 2). */
#include <criterion/criterion.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "image/image_io.h"
#include "support.h"

#define DGAUSS LENS_DIR "dgauss.50mm.dat"
#define L2P(out, errtext, ...) run_lens2pov(out, errtext, __VA_ARGS__, (char *)NULL)

/* A linear, gamma-1 scene (POV-Ray 3.7's own convention). */
#define MODERN "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"

/* ---------------------------------------------------------------- helpers */

typedef struct image {
    int w, h;
    float *p;   /* RGBA, linear */
} image;

static image load(const char *path)
{
    image im = {0, 0, NULL};
    l2p_error err;
    cr_assert_eq(image_read_rgba(path, &im.w, &im.h, &im.p, &err), 0, "%s: %s", path, err.text);
    return im;
}

/* The values (RGBA) in which two pictures of w x h differ. */
static int values_differing(const char *path_a, const char *path_b, int w, int h)
{
    image a = load(path_a), b = load(path_b);
    cr_assert(a.w == b.w && a.h == b.h && a.w == w && a.h == h, "%dx%d and %dx%d", a.w, a.h,
              b.w, b.h);
    int differ = 0;
    for (size_t i = 0; i < 4 * (size_t)a.w * (size_t)a.h; i++)
        differ += a.p[i] != b.p[i];
    free(a.p);
    free(b.p);
    return differ;
}

static float at(const image *im, int x, int y, int c)
{
    return im->p[4 * ((size_t)y * (size_t)im->w + (size_t)x) + (size_t)c];
}

static bool exists(const char *path)
{
    struct stat s;
    return stat(path, &s) == 0;
}

/* A fresh folder (test_tmpdir's buffer is reused by its next call) and paths in it. */
#define NEW_DIR(d) char d[64]; snprintf(d, sizeof d, "%s", test_tmpdir())
#define PATH(var, dir, name) char var[512]; snprintf(var, sizeof var, "%s/%s", dir, name)

/* POV-Ray on its own: `povray +Iscene +Oout ...` run in dir, messages to dir/povray.log. */
static void run_povray(const char *dir, const char *scene, const char *out, int w, int h,
                       const char *extra)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd,
             "cd '%s' && povray +I%s +O%s +W%d +H%d -A -D -V -GA %s >povray.log 2>&1", dir,
             scene, out, w, h, extra);
    const int st = system_povray(cmd);
    PATH(log_path, dir, "povray.log");
    char *log = read_text(log_path, NULL);
    cr_assert_eq(st, 0, "%s failed:\n%s", cmd, log ? log : "(no log)");
    free(log);
}

/* The camera of most tests: 3 m from a subject at the origin, looking along +z. */
#define PLACE "--location", "0,0,-3", "--look-at", "0,0,0"

/* ---------------------------------------------------------------- orientation */

/* Centroid (pixel centres at x + 0.5) of the pixels of channel c brighter than half its peak. */
static void centroid(const image *im, int c, double *cx, double *cy, float *peak)
{
    float top = 0;
    for (int y = 0; y < im->h; y++)
        for (int x = 0; x < im->w; x++)
            top = fmaxf(top, at(im, x, y, c));
    double sx = 0, sy = 0, s = 0;
    for (int y = 0; y < im->h; y++)
        for (int x = 0; x < im->w; x++) {
            const float v = at(im, x, y, c);
            if (v > 0.5f * top)
                sx += v * (x + 0.5), sy += v * (y + 0.5), s += v;
        }
    *peak = top;
    *cx = s > 0 ? sx / s : -1;
    *cy = s > 0 ? sy / s : -1;
}

/* A red light up and to the right, a green one down and to the left, a blue one in the middle,
   4 m in front of the camera: x right, y up in the scene must be right and up in the picture
   (row 0 at the top). One colour each, so that a mirrored or upside-down picture cannot pass
   by swapping them. f/8, focused on them (the look-at point). */
Test(render, picture_is_upright_and_unmirrored)
{
    NEW_DIR(dir);
    PATH(scene, dir, "lights.pov");
    PATH(out, dir, "lights.exr");
    write_text(scene, MODERN
               "background { rgb 0 }\n"
               "#declare Glow = finish { emission 1 diffuse 0 ambient 0 }\n"
               "sphere { < 0.6,  0.4, 0>, 0.12 pigment { rgb <1, 0, 0> } finish { Glow } }\n"
               "sphere { <-0.6, -0.4, 0>, 0.12 pigment { rgb <0, 1, 0> } finish { Glow } }\n"
               "sphere { < 0,    0,   0>, 0.12 pigment { rgb <0, 0, 1> } finish { Glow } }\n");
    run_lens2pov_ok("render", "render", scene, DGAUSS, "--width", "64", "--height", "48",
                 "--spp", "8", "--f-number", "8", "--location", "0,0,-4", "--look-at", "0,0,0",
                 "--quiet", "-o", out, NULL);
    image im = load(out);
    cr_assert_eq(im.w, 64);
    cr_assert_eq(im.h, 48);
    double cx[3], cy[3];
    float peak[3];
    for (int c = 0; c < 3; c++) {
        centroid(&im, c, &cx[c], &cy[c], &peak[c]);
        cr_assert_gt(peak[c], 0.3f, "channel %d: no light seen (peak %g)", c, peak[c]);
    }
    /* Red: right and top, well away from the middle (expected near x = 32 + 32 * (0.6 / 4) /
       tan(hfov / 2 = 15.4 deg) = 49.5, y = 24 - 24 * (0.4 / 4) / tan(vfov / 2 = 11.6 deg) = 12.3);
       green: the mirror image of that about the centre. */
    cr_expect_gt(cx[0], 40, "red (up-right) light at x %.1f", cx[0]);
    cr_expect_lt(cy[0], 18, "red (up-right) light at y %.1f (row 0 is the top)", cy[0]);
    cr_expect_lt(cx[1], 24, "green (down-left) light at x %.1f", cx[1]);
    cr_expect_gt(cy[1], 30, "green (down-left) light at y %.1f", cy[1]);
    cr_expect(fabs(cx[2] - 32) < 1.0 && fabs(cy[2] - 24) < 1.0,
              "blue (middle) light at %.2f, %.2f, not at the centre 32, 24", cx[2], cy[2]);
    /* Point symmetry of the two outer lights about the centre (a rotationally symmetric lens). */
    cr_expect(fabs(cx[0] + cx[1] - 64) < 1.0 && fabs(cy[0] + cy[1] - 48) < 1.0,
              "red %.2f,%.2f and green %.2f,%.2f are not symmetric about the centre", cx[0],
              cy[0], cx[1], cy[1]);
    free(im.p);
    remove_tree(dir);
}

/* ---------------------------------------------------------------- POV-Ray's own camera */

/* Large, smooth content: a backdrop whose red grows with x and green with y (0 to 1 over 4 m,
   so a picture shifted or scaled by one pixel differs everywhere), and a matte sphere shaded by
   one light, in front of it. */
static const char SMOOTH_SCENE[] = MODERN
    "background { rgb 0 }\n"
    "light_source { <-3, 4, -5>, rgb 1 }\n"
    "plane { z, 0\n"
    "  pigment { average pigment_map {\n"
    "    [1 gradient x color_map { [0 rgb <0, 0, 0.4>] [1 rgb <2, 0, 0.4>] }\n"
    "       scale 4 translate -2*x]\n"
    "    [1 gradient y color_map { [0 rgb <0, 0, 0.4>] [1 rgb <0, 2, 0.4>] }\n"
    "       scale 4 translate -2*y]\n"
    "  } }\n"
    "  finish { emission 1 diffuse 0 ambient 0 } }\n"
    "sphere { <0.25, -0.1, -0.6>, 0.35 pigment { rgb <0.9, 0.8, 0.6> }\n"
    "  finish { diffuse 0.9 ambient 0 } }\n";

/* Mean over the central half (in x and in y) of |lens - reference|, all three channels; the
   reference is SS x SS times larger and averaged down box by box, shifted by dx whole pixels. */
static double central_mad(const image *lens, const image *flat, const image *ref, int ss, int dx)
{
    double sum = 0;
    int n = 0;
    for (int y = lens->h / 4; y < 3 * lens->h / 4; y++)
        for (int x = lens->w / 4; x < 3 * lens->w / 4; x++)
            for (int c = 0; c < 3; c++) {
                double r = 0;
                for (int j = 0; j < ss; j++)
                    for (int i = 0; i < ss; i++)
                        r += at(ref, (x + dx) * ss + i, y * ss + j, c);
                r /= ss * ss;
                sum += fabs(at(lens, x, y, c) / at(flat, x, y, c) - r);
                n++;
            }
    return sum / n;
}

/* The lens stopped down to f/11 and focused on the backdrop, divided by a flat field (the same
   rays on a white background: this takes out vignetting and the cos^4 falloff, and makes each
   pixel the weighted mean of its samples' radiance) against POV-Ray's perspective camera with
   the lens's field of view (`info --json` hfov_deg for the same film and focus), put at the
   lens's entrance pupil (the centre of perspective of a real lens: location + (film distance
   + entrance pupil from the rear vertex) along the axis). POV-Ray renders at 4x4 the size and
   is averaged down, as the lens's samples are spread over each pixel. */
Test(render, agrees_with_povray_perspective_camera)
{
    NEW_DIR(dir);
    PATH(scene, dir, "smooth.pov");
    PATH(white, dir, "white.pov");
    PATH(lens_exr, dir, "lens.exr");
    PATH(flat_exr, dir, "flat.exr");
    PATH(own_pov, dir, "own.pov");
    PATH(own_exr, dir, "own.exr");
    write_text(scene, SMOOTH_SCENE);
    write_text(white, MODERN "background { rgb 1 }\n");
    char *json, *errtext;
    int st = L2P(&json, &errtext, "info", DGAUSS, "--json", "--width", "64", "--height", "48",
                 "--f-number", "11", PLACE);
    cr_assert_eq(st, 0, "info: %s", errtext);
    free(errtext);
    const double hfov = json_number(json, "hfov_deg");
    const double pupil_z_mm = json_number(json, "film_distance_mm") +
                              json_number(json, "entrance_pupil_mm");
    free(json);
    cr_assert(hfov > 25 && hfov < 35, "hfov %g", hfov);

    const char *outs[2] = {lens_exr, flat_exr}, *scenes[2] = {scene, white};
    for (int k = 0; k < 2; k++) {
        st = L2P(NULL, &errtext, "render", scenes[k], DGAUSS, "--width", "64", "--height", "48",
                 "--spp", "16", "--f-number", "11", PLACE, "--seed", "11", "--quiet", "-o",
                 outs[k]);
        cr_assert_eq(st, 0, "render %s: %s", scenes[k], errtext);
        free(errtext);
    }
    char own[512];
    snprintf(own, sizeof own,
             "#include \"smooth.pov\"\n"
             "camera { perspective location <0, 0, %.9f> look_at <0, 0, 0>\n"
             "  right x * 64 / 48 up y angle %.9f }\n",
             -3.0 + pupil_z_mm / 1000.0, hfov);
    write_text(own_pov, own);
    run_povray(dir, "own.pov", "own.exr", 256, 192, "+FE -UA");

    image lens = load(outs[0]), flat = load(outs[1]), ref = load(own_exr);
    cr_assert(lens.w == 64 && lens.h == 48 && flat.w == 64 && flat.h == 48);
    cr_assert(ref.w == 256 && ref.h == 192);
    for (int y = lens.h / 4; y < 3 * lens.h / 4; y++)
        for (int x = lens.w / 4; x < 3 * lens.w / 4; x++)
            cr_assert_gt(at(&flat, x, y, 0), 0.5f, "flat field dark at %d,%d", x, y);
    /* Tolerance 0.003 (values are 0-1). The division by the flat field leaves in each pixel
       the weight-averaged radiance of its 16 samples, spread over the pixel as POV-Ray's 4x4
       are: on the ramps of the backdrop both are the mean of the same linear function. What
       remains: the sphere's outline (16 stratified samples against a regular 4x4: about
       contrast / 10 on the ~40 outline pixels among the 768 central ones), the distortion of
       the double Gauss (hfov is the chief ray of the frame's edge; the central half's scale
       differs from it by a few tenths of a percent, a tenth of a pixel at a ramp slope of 0.012
       a pixel), half-float output (< 0.0005) and the depth of field at f/11 (a blur circle of
       0.02 mm on the sphere, 1/20 pixel). Measured: 0.0009 with seed 11. For scale: the
       reference moved by one pixel gives 0.0116, POV-Ray's camera at the film centre instead of
       the entrance pupil 0.0044, a 1% wider field 0.0025. */
    const double mad = central_mad(&lens, &flat, &ref, 4, 0);
    const double mad_shifted = central_mad(&lens, &flat, &ref, 4, 1);
    cr_log_info("mean |lens/flat - povray| over the central half: %.5f (shifted a pixel: %.5f)",
                mad, mad_shifted);
    cr_expect_lt(mad, 0.003, "lens / flat field differs from POV-Ray's camera by %.4f on average "
                 "in the central half (shifted by a pixel: %.4f)", mad, mad_shifted);
    cr_expect_gt(mad_shifted, 0.009, "the scene is too flat to tell a shift of a pixel (%.4f)",
                 mad_shifted);
    free(lens.p);
    free(flat.p);
    free(ref.p);
    remove_tree(dir);
}

/* ---------------------------------------------------------------- physical weights */

enum { RINGS = 10, RING_PX = 4 };

typedef struct profile {
    double sum[RINGS], sum2[RINGS];
    int n[RINGS];
} profile;

/* Radial profile of the green channel (a white picture: all three are the same) in rings
   RING_PX pixels wide around the centre. */
static void radial_profile(const image *im, profile *p)
{
    memset(p, 0, sizeof *p);
    for (int y = 0; y < im->h; y++)
        for (int x = 0; x < im->w; x++) {
            const double r = hypot(x + 0.5 - im->w / 2.0, y + 0.5 - im->h / 2.0);
            const int k = (int)(r / RING_PX);
            if (k >= RINGS)
                continue;
            const double v = at(im, x, y, 1);
            p->sum[k] += v, p->sum2[k] += v * v, p->n[k]++;
        }
}

static double ring_mean(const profile *p, int k) { return p->sum[k] / p->n[k]; }

/* Standard error of a ring's mean, from the scatter of its pixels (noise, and the small change
   of the true falloff across the ring, which only makes the bound looser). */
static double ring_error(const profile *p, int k)
{
    const double m = ring_mean(p, k);
    const double var = fmax(0.0, p->sum2[k] / p->n[k] - m * m);
    return sqrt(var / (p->n[k] - 1));
}

/* With --weighting physical each sample carries A cos^4(theta) / Z^2 for its own pupil disk,
   which makes the mean over the samples an unbiased estimate of the film irradiance whatever
   disk is sampled, as long as it holds every ray that gets through (blocked samples count as
   0). The rear element's disk and the stop's image must then give the same profile of a white
   background, at full aperture (where the vignetting is strongest and the two disks differ
   most). EXR: physical weights are not normalized to 1 and PNG would clip them. */
Test(render, physical_weights_do_not_depend_on_the_pupil)
{
    NEW_DIR(dir);
    PATH(white, dir, "white.pov");
    PATH(rear_exr, dir, "rear.exr");
    PATH(stop_exr, dir, "stop-image.exr");
    write_text(white, MODERN "background { rgb 1 }\n");
    const char *pupils[2] = {"rear", "stop-image"}, *outs[2] = {rear_exr, stop_exr};
    profile prof[2];
    for (int k = 0; k < 2; k++) {
        char *errtext;
        int st = L2P(NULL, &errtext, "render", white, DGAUSS, "--sampling", "pixel",
                     "--width", "64", "--height", "48",
                     "--spp", "32", "--pupil", pupils[k], "--weighting", "physical", PLACE,
                     "--seed", "5", "--quiet", "-o", outs[k]);
        cr_assert_eq(st, 0, "render --pupil %s: %s", pupils[k], errtext);
        free(errtext);
        image im = load(outs[k]);
        cr_assert(im.w == 64 && im.h == 48);
        radial_profile(&im, &prof[k]);
        free(im.p);
    }
    const double centre = ring_mean(&prof[1], 0);
    cr_assert_gt(centre, 0, "the stop-image picture is black in the middle");
    cr_assert_gt(ring_mean(&prof[0], 0), 0, "the rear-pupil picture is black in the middle");
    /* Tolerance: 4 standard errors of the ratio of the ring means (each from its pixels'
       scatter: with 32 samples a pixel, the rear disk lets through roughly 40-95% of them, a
       pixel's relative noise is up to sqrt((1 - p) / (p * 32)) ~ 0.2, and a ring averages
       50-500 pixels: 0.4-0.6% for most rings, 1.7% for the corners), plus 0.5% for the
       half-float output and the stratification's leftover correlation. A disk too small for
       the real bundle (the paraxial image of the stop, where pupil aberration makes the real
       bundle wider) misses light and shows as a ratio rear / stop-image above 1. */
    int compared = 0;
    for (int k = 0; k < RINGS; k++) {
        const double a = ring_mean(&prof[0], k), b = ring_mean(&prof[1], k);
        if (prof[0].n[k] < 20 || a < 0.02 * centre || b < 0.02 * centre)
            continue;   /* black (or nearly): nothing to compare */
        const double ea = ring_error(&prof[0], k) / a, eb = ring_error(&prof[1], k) / b;
        const double sigma = sqrt(ea * ea + eb * eb);
        cr_log_info("ring %d (r %d-%d px, %d px): rear %.5g stop-image %.5g ratio %.4f +- %.4f",
                    k, k * RING_PX, (k + 1) * RING_PX, prof[0].n[k], a, b, a / b, sigma);
        cr_expect_lt(fabs(a / b - 1), 4 * sigma + 0.005,
                     "ring %d (%d-%d px from the centre): rear %.5g, stop-image %.5g: ratio %.4f, "
                     "noise %.4f", k, k * RING_PX, (k + 1) * RING_PX, a, b, a / b, sigma);
        compared++;
    }
    cr_expect_geq(compared, 8, "only %d rings to compare", compared);
    remove_tree(dir);
}

/* ---------------------------------------------------------------- failures */

/* A fresh folder as TMPDIR for lens2pov (each Criterion test runs in its own process). */
static const char *fresh_tmpdir(void)
{
    static char tmp[64];
    snprintf(tmp, sizeof tmp, "%s", test_tmpdir());
    cr_assert_eq(setenv("TMPDIR", tmp, 1), 0);
    return tmp;
}

/* After a failed render: no output, nothing in TMPDIR, and only the files that were there
   before (beside of them) in the scene's folder. */
static void expect_nothing_left(const char *tmp, const char *dir, const char *out, int beside)
{
    cr_expect_not(exists(out), "an output was written");
    char listing[2048];
    cr_expect_eq(count_entries(tmp, NULL, listing, sizeof listing), 0,
                 "temporary files left in TMPDIR: %s", listing);
    cr_expect_eq(count_entries(dir, NULL, listing, sizeof listing), beside,
                 "files left beside the scene: %s", listing);
}

/* Runs a scene that POV-Ray rejects: exit 2 (bad input), nothing written, nothing left in TMPDIR or beside
   the scene; returns stderr. */
static char *render_bad_scene(const char *dir, const char *scene)
{
    const char *tmp = fresh_tmpdir();
    PATH(out, dir, "bad.png");
    char *errtext;
    const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, "--width", "32", "--height",
                       "24", "--spp", "2", PLACE, "--quiet", "-o", out);
    cr_expect_eq(st, 2, "exit status %d for a scene with a syntax error: %s", st, errtext);
    expect_nothing_left(tmp, dir, out, 1);
    return errtext;
}

/* A misspelt keyword on line 4: POV-Ray's message, with the scene's file and line. */
Test(render, syntax_error_fails_cleanly)
{
    NEW_DIR(dir);
    PATH(scene, dir, "typo.pov");
    write_text(scene, MODERN "background { rgb 1 }\n"
                             "sphere { <0, 0, 0>, 1 pigmnt { rgb 1 } }\n"
                             "light_source { <0, 5, -5>, rgb 1 }\n");
    char *errtext = render_bad_scene(dir, scene);
    char where[600];
    snprintf(where, sizeof where, "%s:4:", scene);
    cr_expect_not_null(strstr(errtext, where), "stderr does not name %s:\n%s", where, errtext);
    cr_expect_not_null(strstr(errtext, "pigmnt"), "POV-Ray's message is missing:\n%s", errtext);
    cr_expect_eq(strncmp(errtext, "lens2pov: ", 10), 0, "stderr: %s", errtext);
    free(errtext);
    remove_tree(getenv("TMPDIR"));
    remove_tree(dir);
}

/* POV-Ray fails on the first chunk while the writer is still on the others (--jobs 1, 32
   chunks): the writer stops, nothing is left in TMPDIR or beside the scene, and the --rays
   file that was there before is untouched (the CSV is only handed over when the render
   succeeds). */
Test(render, failure_while_the_table_is_written_loses_nothing)
{
    NEW_DIR(dir);
    PATH(scene, dir, "typo.pov");
    PATH(csv, dir, "rays.csv");
    PATH(out, dir, "bad.png");
    write_text(scene, MODERN "sphere { <0, 0, 0>, 1 pigmnt { rgb 1 } }\n");
    write_text(csv, "an older file\n");
    const char *tmp = fresh_tmpdir();
    char *errtext;
    const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, "--width", "128", "--height",
                       "96", "--spp", "16", PLACE, "--jobs", "1", "--memory-mb", "1",
                       "--rays", csv, "--quiet", "-o", out);
    cr_expect_eq(st, 2, "exit status %d: %s", st, errtext);
    cr_expect_not_null(strstr(errtext, "pigmnt"), "POV-Ray's message is missing:\n%s", errtext);
    free(errtext);
    char *old = read_text(csv, NULL);
    cr_expect_str_eq(old, "an older file\n", "the --rays file was replaced");
    free(old);
    expect_nothing_left(tmp, dir, out, 2);
    remove_tree(tmp);
    remove_tree(dir);
}

/* A scene whose last block is never closed: POV-Ray only notices it in the text that follows,
   which is lens2pov's camera include (deleted by then). The message must still send the user
   to the scene, not to a temporary file of lens2pov's. */
Test(render, unclosed_block_is_reported_in_the_scene)
{
    NEW_DIR(dir);
    PATH(scene, dir, "open.pov");
    write_text(scene, MODERN "background { rgb 1 }\n"
                             "sphere { <0, 0, 0>, 1 pigment { rgb 1 }\n");
    char *errtext = render_bad_scene(dir, scene);
    char where[600];
    snprintf(where, sizeof where, "lens2pov: %s:", scene);
    cr_expect_not_null(strstr(errtext, where), "stderr does not name the scene %s:\n%s", scene,
                       errtext);
    cr_expect_null(strstr(errtext, ".inc:"), "stderr names lens2pov's own temporary include "
                   "instead of the scene:\n%s", errtext);
    cr_expect_not_null(strstr(errtext, "No matching }"), "POV-Ray's message is missing:\n%s",
                       errtext);
    free(errtext);
    remove_tree(getenv("TMPDIR"));
    remove_tree(dir);
}

Test(render, missing_scene_or_lens_is_bad_input)
{
    NEW_DIR(dir);
    const char *tmp = fresh_tmpdir();
    PATH(scene, dir, "there.pov");
    PATH(missing, dir, "not-there.pov");
    PATH(lens, dir, "not-there.dat");
    PATH(out, dir, "out.png");
    write_text(scene, MODERN "background { rgb 1 }\n");
    char *errtext;
    int st = L2P(NULL, &errtext, "render", missing, DGAUSS, "--width", "16", "--height", "12",
                 "--quiet", "-o", out);
    cr_expect_eq(st, 2, "missing scene: exit status %d: %s", st, errtext);
    cr_expect_not_null(strstr(errtext, missing), "stderr does not name %s:\n%s", missing, errtext);
    free(errtext);
    st = L2P(NULL, &errtext, "render", scene, lens, "--width", "16", "--height", "12", "--quiet",
             "-o", out);
    cr_expect_eq(st, 2, "missing lens: exit status %d: %s", st, errtext);
    cr_expect_not_null(strstr(errtext, lens), "stderr does not name %s:\n%s", lens, errtext);
    free(errtext);
    char listing[2048];
    cr_expect_not(exists(out), "an output was written");
    cr_expect_eq(count_entries(dir, NULL, listing, sizeof listing), 1, "files written: %s",
                 listing);
    cr_expect_eq(count_entries(tmp, NULL, listing, sizeof listing), 0,
                 "temporary files left in TMPDIR: %s", listing);
    remove_tree(tmp);
    remove_tree(dir);
}

/* An animation's output in a folder that does not exist is refused for what it is, not by the
   disk check: the check once compared the free space of a folder it could not measure. */
Test(render, an_animation_into_a_missing_folder_is_refused_by_name)
{
    NEW_DIR(dir);
    PATH(scene, dir, "there.pov");
    PATH(out, dir, "nodir/x.png");
    write_text(scene, MODERN "background { rgb 1 }\n");
    char *errtext;
    const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, "--width", "8", "--height", "6",
                       "--spp", "1", PLACE, "--quiet", "-o", out, "--", "+KFI1", "+KFF2");
    cr_expect_eq(st, 2, "exit status %d: %s", st, errtext);
    cr_expect_not_null(strstr(errtext, "nodir/x1.png: cannot write"), "%s", errtext);
    cr_expect_null(strstr(errtext, "bytes"), "%s", errtext);
    free(errtext);
    remove_tree(dir);
}

/* A --keep-temp folder another render holds (its lock, taken here) is refused: the two would
   write and remove each other's files. Once free, the same folder is taken. */
Test(render, a_kept_folder_in_use_is_refused)
{
    NEW_DIR(dir);
    PATH(scene, dir, "there.pov");
    PATH(keep, dir, "work");
    PATH(out, dir, "out.png");
    write_text(scene, MODERN "background { rgb 1 }\n");
    cr_assert_eq(mkdir(keep, 0777), 0);
    const int fd = open(keep, O_RDONLY | O_DIRECTORY);
    cr_assert(fd >= 0 && flock(fd, LOCK_EX | LOCK_NB) == 0);
    char *errtext;
    int st = L2P(NULL, &errtext, "render", scene, DGAUSS, "--width", "8", "--height", "6",
                 "--spp", "1", PLACE, "--keep-temp", keep, "--quiet", "-o", out);
    cr_expect_eq(st, 2, "exit status %d: %s", st, errtext);
    cr_expect_not_null(strstr(errtext, "another lens2pov render is using this --keep-temp "
                                       "folder"), "%s", errtext);
    cr_expect_not(exists(out), "an output was written");
    free(errtext);
    close(fd);
    st = L2P(NULL, &errtext, "render", scene, DGAUSS, "--width", "8", "--height", "6", "--spp",
             "1", PLACE, "--keep-temp", keep, "--quiet", "-o", out);
    cr_expect_eq(st, 0, "exit status %d: %s", st, errtext);
    free(errtext);
    remove_tree(dir);
}

/* ---------------------------------------------------------------- crops and chunks */

/* --crop renders only its region, with the samples the whole film would use there: the same
   pixels as the whole picture's, up to half-float rounding (1 unit in the last place). */
Test(render, crop_is_a_region_of_the_whole_picture)
{
    NEW_DIR(dir);
    PATH(scene, dir, "smooth.pov");
    PATH(full, dir, "full.exr");
    PATH(crop, dir, "crop.exr");
    PATH(csv, dir, "crop.csv");
    write_text(scene, SMOOTH_SCENE);
    run_lens2pov_ok("full", "render", scene, DGAUSS, "--sampling", "pixel",
                    "--width", "64", "--height", "48",
                 "--spp", "4", "--f-number", "8", PLACE, "--seed", "3", "--quiet", "-o", full, NULL);
    const int x0 = 7, y0 = 5, x1 = 40, y1 = 29;
    run_lens2pov_ok("crop", "render", scene, DGAUSS, "--sampling", "pixel",
                    "--width", "64", "--height", "48", "--spp",
             "4", "--f-number", "8", PLACE, "--seed", "3", "--crop", "7,5,40,29", "--rays", csv,
             "--quiet", "-o", crop, NULL);
    /* Only the region's rays went to POV-Ray: at most 4 a pixel (the lens blocks a few toward
       the crop's outer corner even at f/8), all inside it. */
    size_t n;
    csv_ray *rays = read_rays_csv(csv, &n);
    const size_t samples = (size_t)(x1 - x0) * (size_t)(y1 - y0) * 4;
    cr_expect(n <= samples && n > samples * 0.95, "%zu rays for %zu samples", n, samples);
    int outside = 0;
    for (size_t i = 0; i < n; i++)
        outside += rays[i].raster_x < x0 || rays[i].raster_x >= x1 || rays[i].raster_y < y0 ||
                   rays[i].raster_y >= y1;
    cr_expect_eq(outside, 0, "%d rays outside the crop", outside);
    free(rays);
    image a = load(full), b = load(crop);
    cr_assert(a.w == 64 && a.h == 48);
    cr_assert(b.w == x1 - x0 && b.h == y1 - y0, "crop is %dx%d, expected %dx%d", b.w, b.h,
              x1 - x0, y1 - y0);
    int differ = 0, bad = 0;
    double lit = 0;
    for (int y = 0; y < b.h; y++)
        for (int x = 0; x < b.w; x++)
            for (int c = 0; c < 3; c++) {
                const float u = at(&a, x + x0, y + y0, c), v = at(&b, x, y, c);
                lit += v;
                if (u == v)
                    continue;
                differ++;
                if (fabsf(u - v) > ldexpf(fmaxf(fabsf(u), fabsf(v)), -10) + 6e-8f)
                    bad++;
            }
    cr_log_info("crop: %d of %d values not bit-identical", differ, b.w * b.h * 3);
    cr_expect_eq(bad, 0, "%d values of the crop differ from the whole picture by more than "
                 "half-float rounding (%d not bit-identical)", bad, differ);
    cr_expect_gt(lit, 0.1 * b.w * b.h, "the crop is black");
    free(a.p);
    free(b.p);
    remove_tree(dir);
}

/* A memory budget of 0.05 MB gives chunks of about 200 faces: 32x24 pixels of 6 samples make
   some two dozen POV-Ray runs, two at a time. They must give exactly the picture of one run
   with the default budget: same rays, same sums. */
Test(render, chunks_and_jobs_do_not_change_the_picture)
{
    NEW_DIR(dir);
    PATH(scene, dir, "smooth.pov");
    PATH(one, dir, "one.exr");
    PATH(many, dir, "many.exr");
    PATH(keep, dir, "work");
    write_text(scene, SMOOTH_SCENE);
    run_lens2pov_ok("--jobs 1", "render", scene, DGAUSS, "--sampling", "pixel",
                    "--width", "32", "--height", "24",
                 "--spp", "6", "--f-number", "8", PLACE, "--seed", "9", "--jobs", "1", "--quiet",
                 "-o", one, NULL);
    run_lens2pov_ok("--jobs 2 --memory-mb 0.05", "render", scene, DGAUSS, "--sampling", "pixel",
                    "--width", "32", "--height", "24", "--spp",
             "6", "--f-number", "8", PLACE, "--seed", "9", "--jobs", "2", "--memory-mb", "0.05",
             "--keep-temp", keep, "--quiet", "-o", many, NULL);
    const int chunks = count_entries(keep, "rays.c", NULL, 0) / 3;   /* .inc .ini .exr */
    cr_expect_geq(chunks, 5, "only %d chunks", chunks);
    const int differ = values_differing(one, many, 32, 24);
    cr_expect_eq(differ, 0, "%d values differ between 1 chunk and %d chunks", differ, chunks);
    remove_tree(dir);
}

/* A crop set in an ini the user gives after `--` is overridden, not obeyed: every render's own
   ini (after the user's on POV-Ray's command line) sets all four bounds, in both samplings. */
Test(render, a_crop_in_the_users_ini_changes_nothing)
{
    NEW_DIR(dir);
    PATH(scene, dir, "smooth.pov");
    PATH(ini, dir, "crop.ini");
    PATH(plain, dir, "plain.exr");
    PATH(cropped, dir, "cropped.exr");
    write_text(scene, SMOOTH_SCENE);
    write_text(ini, "Start_Row=0.5\nStart_Column=0.5\nEnd_Row=0.9\nEnd_Column=0.8\n");
    static const char *const samplings[] = {"pixel", "field"};
    for (int k = 0; k < 2; k++) {
        run_lens2pov_ok("no ini", "render", scene, DGAUSS, "--sampling", samplings[k], "--width",
                        "32", "--height", "24", "--spp", "4", PLACE, "--quiet", "-o", plain, NULL);
        run_lens2pov_ok("a crop in an ini", "render", scene, DGAUSS, "--sampling", samplings[k],
                        "--width", "32", "--height", "24", "--spp", "4", PLACE, "--quiet", "-o",
                        cropped, "--", ini, NULL);
        const int differ = values_differing(plain, cropped, 32, 24);
        cr_expect_eq(differ, 0, "%s sampling: %d values differ", samplings[k], differ);
    }
    remove_tree(dir);
}

/* POV-Ray starts on the first chunk while the writer is still on the others: the first
   chunk's wrapper (written just before its POV-Ray starts) is older than the last chunk's
   include (renamed into place when complete). The second of two chunks of 196,608 samples
   with their CSV takes the writer a tenth of a second; starting the first POV-Ray takes
   milliseconds. */
Test(render, povray_starts_on_a_chunk_while_the_rest_are_written)
{
    NEW_DIR(dir);
    PATH(scene, dir, "flat.pov");
    PATH(out, dir, "flat.exr");
    PATH(csv, dir, "rays.csv");
    PATH(keep, dir, "work");
    write_text(scene, MODERN "background { rgb 0.5 }\n");
    char *errtext = NULL;
    cr_assert_eq(run_lens2pov(NULL, &errtext, "render", scene, DGAUSS, "--sampling", "pixel",
                              "--width", "128",
                              "--height", "96", "--spp", "16", PLACE, "--jobs", "2", "--rays", csv,
                              "--keep-temp", keep, "--quiet", "-o", out, NULL), 0, "%s", errtext);
    /* A chunk that POV-Ray failed to start (it timed out starting its threads) is started
       again, its wrapper written anew: the wrapper's time then says nothing of the first. */
    const bool restarted = errtext && strstr(errtext, "starting it again");
    free(errtext);
    if (restarted) {
        cr_log_warn("POV-Ray was started again on a chunk: the start times cannot be compared");
        remove_tree(dir);
        return;
    }
    const int chunks = count_entries(keep, "rays.c", NULL, 0) / 3;   /* .inc .ini .exr */
    cr_assert_eq(chunks, 2, "%d chunks", chunks);
    char first[600], last[600];
    snprintf(first, sizeof first, "%s/povray.c000.pov", keep);
    snprintf(last, sizeof last, "%s/rays.c%03d.inc", keep, chunks - 1);
    struct stat a, b;
    cr_assert_eq(stat(first, &a), 0, "%s", first);
    cr_assert_eq(stat(last, &b), 0, "%s", last);
    const double started = (double)a.st_mtim.tv_sec + 1e-9 * (double)a.st_mtim.tv_nsec;
    const double written = (double)b.st_mtim.tv_sec + 1e-9 * (double)b.st_mtim.tv_nsec;
    cr_expect_lt(started, written, "POV-Ray started %.3f s after the table was complete",
                 started - written);
    remove_tree(dir);
}

/* ---------------------------------------------------------------- old and new scenes */

static double srgb_code(double linear)
{
    const double v = linear <= 0.0031308 ? 12.92 * linear : 1.055 * pow(linear, 1 / 2.4) - 0.055;
    return 255.0 * fmin(1.0, fmax(0.0, v));
}

/* Mean sRGB code (0-255) of each channel over the central 16x12 pixels. */
static void centre_codes(const image *im, double code[3])
{
    for (int c = 0; c < 3; c++) {
        double s = 0;
        for (int y = im->h / 2 - 6; y < im->h / 2 + 6; y++)
            for (int x = im->w / 2 - 8; x < im->w / 2 + 8; x++)
                s += srgb_code(at(im, x, y, c));
        code[c] = s / (16 * 12);
    }
}

/* A flat colour filling the view (ambient only: no light, no shading, so defocus and the
   lens's geometry do not matter), rendered through the lens to PNG and by POV-Ray alone to PNG
   with its own camera: the centres agree within 2/255, whatever the scene's gamma handling.
   2/255: the weights are normalized so that the film centre has mean weight 1; over the
   central 16x12 pixels (up to 5.6 degrees off the axis) the cos^4 falloff darkens by 1% on
   average (0.3-0.6/255 at these codes; the vignetting at f/8 is nil there), and each PNG rounds
   to whole codes (up to 0.5 each, which can add up to 1 when the exact value is near a half,
   as 0.3 * 255 = 76.5 is); pov/README.md measured 0.5/255 through the camera include alone. */
static void expect_same_as_povray(const char *header, double expected_code)
{
    NEW_DIR(dir);
    PATH(scene, dir, "flat.pov");
    PATH(lens_png, dir, "lens.png");
    PATH(own_png, dir, "own.png");
    char text[1024];
    snprintf(text, sizeof text,
             "%s"
             "camera { location <0, 0, -3> look_at <0, 0, 0> }\n"
             "plane { z, 0 pigment { rgb <0.3, 0.5, 0.1> } finish { ambient 1 diffuse 0 } }\n",
             header);
    write_text(scene, text);
    run_lens2pov_ok("render", "render", scene, DGAUSS, "--width", "64",
                 "--height", "48", "--spp", "4", "--f-number", "8", PLACE, "--quiet", "-o",
                 lens_png, NULL);
    run_povray(dir, "flat.pov", "own.png", 64, 48, "+FN");
    image lens = load(lens_png), own = load(own_png);
    cr_assert(lens.w == 64 && lens.h == 48 && own.w == 64 && own.h == 48);
    double a[3], b[3];
    centre_codes(&lens, a);
    centre_codes(&own, b);
    for (int c = 0; c < 3; c++) {
        cr_log_info("channel %d: lens %.2f povray %.2f /255", c, a[c], b[c]);
        cr_expect_lt(fabs(a[c] - b[c]), 2.0, "channel %d: the lens gives %.2f/255, POV-Ray's own "
                     "camera %.2f/255", c, a[c], b[c]);
    }
    /* And POV-Ray did what pov/README.md says for this header (the test tests what it means). */
    cr_expect_lt(fabs(b[0] - expected_code), 1.0, "POV-Ray's own red is %.2f/255, expected %.1f",
                 b[0], expected_code);
    free(lens.p);
    free(own.p);
    remove_tree(dir);
}

/* An old scene: gamma handling off, colours are gamma-2.2 encoded: 0.3 -> 0.3^2.2 linear. */
Test(render, old_scene_with_assumed_gamma_2_2)
{
    expect_same_as_povray("#version 3.6;\nglobal_settings { assumed_gamma 2.2 }\n",
                          srgb_code(pow(0.3, 2.2)));
}

/* A modern scene: colours are linear; POV-Ray's PNG holds sRGB(0.3). */
Test(render, modern_scene_with_assumed_gamma_1)
{
    expect_same_as_povray(MODERN, srgb_code(0.3));
}

/* No #version at all: a 3.62 scene with gamma handling off; POV-Ray's PNG holds 0.3 * 255. */
Test(render, scene_without_version)
{
    expect_same_as_povray("", 0.3 * 255);
}

/* ---------------------------------------------------------------- chunks and jobs */

/* A checkered sphere on a checkered floor. */
static const char TINY_SCENE[] =
    "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
    "background { rgb <0.1, 0.2, 0.3> }\n"
    "light_source { <-3, 5, -4> color rgb 1 }\n"
    "sphere { <0, 0, 3>, 0.5 pigment { checker rgb <1,0.2,0.2> rgb <0.2,1,0.2> scale 0.1 } }\n"
    "plane { y, -0.5 pigment { checker rgb 0.9 rgb 0.1 } }\n";

/* Faces in a chunk's include ("face_indices { N"). */
static long long faces_in(const char *include_path)
{
    char *text = read_text(include_path, NULL);
    cr_assert_not_null(text, "%s", include_path);
    const char *at = strstr(text, "face_indices {");
    cr_assert_not_null(at, "%s has no face_indices", include_path);
    const long long n = atoll(at + strlen("face_indices {"));
    free(text);
    return n;
}

/* The wide angle vignettes: cutting by samples would give the corner rows' chunk fewer faces.
   Two jobs get two chunks that together hold every ray the lens passes (the CSV of the same
   trace); the first is half of them rounded up to whole packed rows by less than a face a row
   (about 19,400 faces: 10 rows), so the two differ by at most 2 x 9 + 1 faces (cutting by
   samples gave 12,288 and 7,129 faces; by rows of 1024, 10,240 and 9,177). */
Test(render, chunks_share_the_faces_equally_between_jobs)
{
    const char *dir = test_tmpdir();
    char scene[512], image[512], keep[512], csv[512], prefix[512];
    snprintf(scene, sizeof scene, "%s/tiny.pov", dir);
    snprintf(image, sizeof image, "%s/two.exr", dir);
    snprintf(keep, sizeof keep, "%s/keep", dir);
    snprintf(csv, sizeof csv, "%s/rays.csv", dir);
    snprintf(prefix, sizeof prefix, "%s/rays", dir);
    write_text(scene, TINY_SCENE);
    /* The rear pupil, so that rows differ much in the rays they pass. */
    const char *camera[] = {"--width", "96", "--height", "64", "--spp", "4", "--look-at", "0,0,3",
                            "--pupil", "rear"};
    run_lens2pov_ok("render", "render", scene, LENS_DIR "wide.22mm.dat", "--sampling", "pixel",
                    camera[0],
                          camera[1], camera[2], camera[3], camera[4], camera[5], camera[6],
                          camera[7], camera[8], camera[9], "--jobs", "2", "--keep-temp", keep,
                          "-o", image, "--quiet", NULL);
    run_lens2pov_ok("trace", "trace", LENS_DIR "wide.22mm.dat", camera[0], camera[1],
                      camera[2], camera[3], camera[4], camera[5], camera[6], camera[7], camera[8],
                      camera[9], "--rays", csv, "-o", prefix, "--quiet", NULL);
    size_t passed;
    free(read_rays_csv(csv, &passed));
    cr_assert_eq(count_entries(keep, "rays.c", NULL, 0) / 3, 2, "one chunk per job (.inc, .ini, .exr each)");
    const long long a = faces_in(tmp_path(keep, "rays.c000.inc"));
    const long long b = faces_in(tmp_path(keep, "rays.c001.inc"));
    cr_assert_eq(a + b, (long long)passed, "%lld + %lld faces, %zu rays pass", a, b, passed);
    cr_assert(passed < 96 * 64 * 4 * 0.9, "the lens vignettes: %zu of %d pass", passed, 96 * 64 * 4);
    cr_assert(a >= b && a - b <= 19, "chunks of %lld and %lld faces", a, b);
}
