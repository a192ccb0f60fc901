/* The up-front size estimate of a field render (src/cli/sizecheck.c) against what a real one
   writes and what POV-Ray takes to render it, and the sizes of its renders. */
#include <criterion/criterion.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include "cli/sizecheck.h"
#include "support.h"

/* The estimate of render's command line (after "render"), for jobs POV-Ray processes. */
static size_estimate estimate_of(char **args, int n, int jobs)
{
    char *argv[64] = {"lens2pov", "render"};
    cr_assert(n + 2 <= 64);
    memcpy(argv + 2, args, sizeof *args * (size_t)n);
    cli c;
    l2p_error err;
    cr_assert_eq(cli_parse(&c, n + 2, argv, 2, &err), 0, "%s", err.text);
    return size_estimate_of(&c, jobs);
}

/* Every file in dir: their bytes, and the faces of the distribution-3 includes among them. */
static void workspace_size(const char *dir, double *bytes, double *faces)
{
    *bytes = *faces = 0;
    DIR *d = opendir(dir);
    cr_assert_not_null(d, "%s", dir);
    for (struct dirent *e; (e = readdir(d)) != NULL;) {
        char path[2048];
        struct stat sb;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        if (stat(path, &sb) != 0 || !S_ISREG(sb.st_mode))
            continue;
        *bytes += (double)sb.st_size;
        const size_t n = strlen(e->d_name);
        if (n > 4 && !strcmp(e->d_name + n - 4, ".inc")) {
            char *text = read_text(path, NULL);
            const char *p = text ? strstr(text, "face_indices {") : NULL;
            cr_assert_not_null(p, "%s has no faces", path);
            *faces += strtod(p + 14, NULL);
            free(text);
        }
    }
    closedir(d);
}

/* Has every POV-Ray process that lens2pov starts note its start on a line of dir/starts and
   write its peak resident size, in kilobytes (GNU time), on a line of dir/peaks. lens2pov
   kills a process once its pictures are in, with its process group, so GNU time runs in a
   session of its own (setsid) in the background of the script it kills, and notes the peak
   when POV-Ray has wound down (wait_for_peaks). */
static void record_povray_peaks(const char *dir)
{
    char script[1200], text[2600];
    snprintf(script, sizeof script, "%s/timepov", dir);
    snprintf(text, sizeof text,
             "#!/bin/sh\necho s >> '%s/starts'\n"
             "setsid /usr/bin/time -a -o '%s/peaks' -f '%%M' povray \"$@\" &\nwait $!\n",
             dir, dir);
    write_text(script, text);
    chmod(script, 0755);
    setenv("LENS2POV_POVRAY", script, 1);
}

static int count_lines(const char *text)
{
    int lines = 0;
    for (const char *p = text; p && (p = strchr(p, '\n')) != NULL; p++)
        lines++;
    return lines;
}

/* dir/peaks once it has a line for every start in dir/starts, or after 30 s. */
static char *wait_for_peaks(const char *dir)
{
    for (int waited = 0;; waited += 50) {
        char *peaks = read_text(tmp_path(dir, "peaks"), NULL);
        char *starts = read_text(tmp_path(dir, "starts"), NULL);
        const bool all = count_lines(peaks) >= count_lines(starts);
        free(starts);
        if (all || waited >= 30000)
            return peaks;
        free(peaks);
        nanosleep(&(struct timespec){0, 50000000L}, NULL);
    }
}

/* A field render of the fisheye (whose image circle's edge takes the most faces) with --rays
   and extra (--adaptive, or nothing): its includes' faces, its workspace (includes, inis,
   weights, renders, wrapper scenes, logs), its CSV and every POV-Ray process's peak memory
   (all the frames it rendered) stay within the estimate made before it; so does the largest
   peak of lens2pov and its processes (RUSAGE_CHILDREN: the test's child and what it waited
   for), without AddressSanitizer, whose shadow is most of a peak. */
static void expect_within_the_estimate(const char *width, const char *height, const char *spp,
                                       const char *extra, int processes_wanted)
{
    const char *dir = test_tmpdir();
    char scene[1024], work[1024], csv[1024], out[1024];
    snprintf(scene, sizeof scene, "%s/scene.pov", dir);
    snprintf(work, sizeof work, "%s/work", dir);
    snprintf(csv, sizeof csv, "%s/rays.csv", dir);
    snprintf(out, sizeof out, "%s/out.exr", dir);
    write_text(scene, "#version 3.7;\nbackground { rgb <0.2, 0.4, 0.8> }\n"
                      "sphere { <0.3, 1, 0>, 0.5 pigment { rgb 1 } finish { ambient 1 } }\n");
    char *args[] = {scene, LENS_DIR "fisheye.10mm.dat", "--width", (char *)width, "--height", (char *)height, "--spp", (char *)spp,
                    "--location", "0,1,-4", "--look-at", "0,1,0", "--sampling", "field", "--jobs", "2",
                    "--keep-temp", work, "--rays", csv, "--quiet", "-o", out, (char *)extra};
    const int n = sizeof args / sizeof args[0] - (extra ? 0 : 1);
    const size_estimate e = estimate_of(args, n, 2);
    char *argv[64] = {"render"};
    memcpy(argv + 1, args, sizeof args);
    char *errtext = NULL;
    record_povray_peaks(dir);
    const int st = run_lens2pov_argv(NULL, &errtext, argv);
    unsetenv("LENS2POV_POVRAY");
    cr_assert_eq(st, 0, "%s", errtext ? errtext : "");
    free(errtext);
    double bytes, faces;
    workspace_size(work, &bytes, &faces);
    struct stat sb;
    cr_assert_eq(stat(csv, &sb), 0);
    cr_log_info("faces %.0f (estimate %.0f), workspace %.0f bytes (%.0f), CSV %.0f (%.0f)", faces, e.faces, bytes,
                e.table_bytes + e.renders_bytes, (double)sb.st_size, e.csv_bytes);
    cr_expect_leq(faces, e.faces);
    cr_expect_leq(bytes, e.table_bytes + e.renders_bytes);
    cr_expect_leq((double)sb.st_size, e.csv_bytes);
    char *peaks = wait_for_peaks(dir);
    cr_assert_not_null(peaks, "no POV-Ray process noted its peak");
    int processes = 0;
    for (char *p = peaks, *end; *p; p = end, processes++) {
        const double peak = strtod(p, &end) * 1024.0;
        if (end == p)
            break;
        cr_log_info("process %d: POV-Ray peak %.1f MB (estimate %.1f MB)", processes, peak / 1e6,
                    e.povray_process_bytes / 1e6);
        cr_expect_leq(peak, e.povray_process_bytes, "POV-Ray took %.0f bytes", peak);
    }
    free(peaks);
    cr_expect_eq(processes, processes_wanted);
    cr_expect_leq(e.povray_process_bytes, e.memory_bytes);
#ifndef __SANITIZE_ADDRESS__
    struct rusage ru;
    cr_assert_eq(getrusage(RUSAGE_CHILDREN, &ru), 0);
    const double peak = (double)ru.ru_maxrss * 1024.0;
    cr_log_info("largest peak %.1f MB, estimate %.1f MB", peak / 1e6, e.memory_bytes / 1e6);
    cr_expect_leq(peak, e.memory_bytes, "a process took %.0f bytes", peak);
#endif
}

Test(sizecheck, a_field_render_stays_within_its_estimate)
{
    expect_within_the_estimate("320", "240", "4", NULL, 2);
}

/* --adaptive's two rounds, the second of pieces (more faces a pixel than whole sub-images,
   each piece a sub-image with its mesh and weights), with the uniform render's estimate:
   two POV-Ray processes a round. */
Test(sizecheck, an_adaptive_render_stays_within_the_estimate)
{
    expect_within_the_estimate("160", "120", "32", "--adaptive", 4);
}

/* Many sub-images of a tiny film: lens2pov's own peak memory (trace: no POV-Ray; the test
   process's only child, so RUSAGE_CHILDREN's largest) stays within the estimate of a render
   with the same options. Each sub-image's mesh was kept with room for 1024 vertices and
   faces, 556 MB here (28 kB a sub-image) against an estimate of 60 MB. */
Test(sizecheck, many_sub_images_of_a_tiny_film_stay_within_the_estimate)
{
#ifdef __SANITIZE_ADDRESS__
    /* AddressSanitizer's shadow and its quarantine of freed blocks are most of the peak */
    cr_skip_test("memory is measured in the build without AddressSanitizer");
#endif
    const char *dir = test_tmpdir();
    char prefix[1024];
    snprintf(prefix, sizeof prefix, "%s/tiny", dir);
    char *args[] = {"s.pov", LENS_DIR "dgauss.50mm.dat", "--width", "2", "--height", "2", "--spp", "20000",
                    "--location", "0,1,-4", "--look-at", "0,1,0", "--sampling", "field", "--jobs", "2",
                    "-o", "x.exr"};
    const size_estimate e = estimate_of(args, sizeof args / sizeof args[0], 2);
    run_lens2pov_ok("trace", "trace", LENS_DIR "dgauss.50mm.dat", "--width", "2", "--height", "2", "--spp",
                    "20000", "--location", "0,1,-4", "--look-at", "0,1,0", "--sampling", "field", "--quiet",
                    "-o", prefix, NULL);
    struct rusage ru;
    cr_assert_eq(getrusage(RUSAGE_CHILDREN, &ru), 0);
    const double peak = (double)ru.ru_maxrss * 1024.0;
    cr_log_info("trace: peak %.1f MB, estimate %.1f MB", peak / 1e6, e.memory_bytes / 1e6);
    cr_expect_leq(peak, e.memory_bytes, "lens2pov took %.0f bytes", peak);
}

/* A render's picture is bounded by FIELD_PIXELS_PER_RENDER, not by the faces its sub-images
   need at least (cells of 128 pixels, or none where the lens blocks everything): a 1920x1080
   film at 256 spp (2048 x 2048 pixels a sub-image's render) is estimated at four sub-images a
   POV-Ray picture, as field_render packs it, not seventy-four (12 GB a POV-Ray process). */
Test(sizecheck, a_renders_picture_is_bounded_by_pixels)
{
    char *args[] = {"s.pov", LENS_DIR "telephoto.250mm.dat", "--width", "1920", "--height", "1080", "--spp",
                    "256", "--sampling", "field", "--jobs", "2", "-o", "x.exr"};
    const size_estimate e = estimate_of(args, sizeof args / sizeof args[0], 2);
    const double picture = 4 * 2048.0 * 2048.0 * SIZE_POVRAY_BYTES_PER_PIXEL;
    cr_log_info("a POV-Ray process: %.0f MB", e.povray_process_bytes / 1e6);
    cr_expect_leq(e.povray_process_bytes, picture + 200e6, "%.0f bytes", e.povray_process_bytes);
    cr_expect_geq(e.povray_process_bytes, picture, "%.0f bytes", e.povray_process_bytes);
}

/* The smallest power of two above n: POV-Ray's side of a render whose final side holds n. */
static double render_side(int n)
{
    double p = 1;
    while (p < n + 1)
        p *= 2;
    return p;
}

/* Each sub-image's render is its own size: (2^a) x (2^b) pixels, the final picture 2^a - 1 by
   2^b - 1 holding the crop (docs/fields.md), 8 bytes a pixel, whatever the film around the
   crop, plus POV-Ray's state files of the renders at once: the disk counts whole sub-images'
   renders, at least the two pictures a process holds; and the faces are not pixel sampling's
   one a sample. */
Test(sizecheck, field_renders_are_estimated_at_their_own_size)
{
    static const int sides[][2] = {{511, 255}, {512, 256}, {100, 700}, {1, 1}};
    for (size_t i = 0; i < sizeof sides / sizeof sides[0]; i++) {
        char w[16], h[16], crop[64];
        snprintf(w, sizeof w, "%d", sides[i][0] + 40);
        snprintf(h, sizeof h, "%d", sides[i][1] + 30);
        snprintf(crop, sizeof crop, "40,30,%d,%d", sides[i][0] + 40, sides[i][1] + 30);
        char *field[] = {"s.pov", "dgauss.50mm", "--width", w, "--height", h, "--crop", crop, "--spp", "64",
                         "--sampling", "field", "-o", "x.png"};
        char *pixel[] = {"s.pov", "dgauss.50mm", "--width", w, "--height", h, "--crop", crop, "--spp", "64",
                         "-o", "x.png"};
        const size_estimate f = estimate_of(field, 14, 2), p = estimate_of(pixel, 12, 2);
        const double own = render_side(sides[i][0]) * render_side(sides[i][1]);
        const double all = 64 * own * SIZE_EXR_BYTES_PER_FACE;
        /* and the state files of the two renders at once, each at most 2^24 pixels here */
        const double most_state = 2 * 16777216.0 * SIZE_POVRAY_STATE_BYTES_PER_PIXEL;
        /* pictures (two a process, of at least one sub-image each) and state files of whole
           sub-images' renders */
        cr_expect(f.renders_bytes >= 4 * own * SIZE_EXR_BYTES_PER_FACE &&
                  f.renders_bytes <= all + most_state && fmod(f.renders_bytes, own) == 0.0,
                  "crop %dx%d: %.0f bytes of renders, not whole renders of %.0f pixels (all: %.0f "
                  "bytes)", sides[i][0], sides[i][1], f.renders_bytes, own, all);
        cr_expect_leq(f.faces, p.faces, "crop %dx%d: %.0f faces against %.0f", sides[i][0], sides[i][1], f.faces,
                     p.faces);
    }
}

/* A render's picture goes once it is developed, unless the work folder is kept or POV-Ray's own
   options make each frame wait for all its renders: a 4000 x 3000 crop at 256 spp is one
   sub-image a render of 4096 x 4096 pixels, and two processes hold about two of them each, not
   all 256. */
Test(sizecheck, developed_field_pictures_are_not_counted_at_once)
{
    char *keep[] = {"s.pov", "dgauss.50mm", "--width", "4000", "--height", "3000", "--spp", "256",
                    "--sampling", "field", "-o", "x.png", "--keep-temp", "w"};
    char *povray[] = {"s.pov", "dgauss.50mm", "--width", "4000", "--height", "3000", "--spp", "256",
                      "--sampling", "field", "-o", "x.png", "--", "+KFI1"};
    const size_estimate gone = estimate_of(keep, 12, 2), kept = estimate_of(keep, 14, 2),
                        frames = estimate_of(povray, 14, 2);
    const double picture = 4096.0 * 4096.0 * SIZE_EXR_BYTES_PER_FACE;
    const double state = 2 * 4096.0 * 4096.0 * SIZE_POVRAY_STATE_BYTES_PER_PIXEL;
    cr_expect(gone.renders_bytes >= 4 * picture && gone.renders_bytes <= 4 * picture + state,
              "%.0f bytes of renders, expected %.0f and the state files", gone.renders_bytes,
              4 * picture);
    cr_expect_geq(kept.renders_bytes, 256 * picture, "%.0f", kept.renders_bytes);
    cr_expect_geq(frames.renders_bytes, 256 * picture, "%.0f", frames.renders_bytes);
}

/* The field map's weights, a float a pixel and sample, are on disk only in trace's map and in
   a kept work folder's: render makes them again where the pixels pass (fieldpass.h). */
Test(sizecheck, field_weights_are_counted_where_they_are_written)
{
    char *args[] = {"s.pov", "dgauss.50mm", "--width", "4000", "--height", "3000", "--spp", "256",
                    "--sampling", "field", "-o", "x.png", "--keep-temp", "w"};
    const size_estimate gone = estimate_of(args, 12, 2), kept = estimate_of(args, 14, 2),
                        traced = estimate_of(args, 12, 0);
    const double weights = 256 * 4000.0 * 3000.0 * sizeof(float);
    cr_expect(fabs(kept.table_bytes - gone.table_bytes - weights) < 1, "%.0f against %.0f",
              kept.table_bytes - gone.table_bytes, weights);
    cr_expect(fabs(traced.table_bytes - kept.table_bytes) < 1, "%.0f against %.0f",
              traced.table_bytes, kept.table_bytes);
}

/* POV-Ray keeps a .pov-state file beside a render in progress, 20 bytes a rendered pixel: a
   3000 x 2000 render at 1 spp (one process) needs its EXR and that file, 118 MB
   measured, which the estimate once left out, so that a disk passed the check and POV-Ray
   aborted when it filled. */
Test(sizecheck, povrays_state_file_is_counted)
{
    char *pixel[] = {"s.pov", "dgauss.50mm", "--width", "3000", "--height", "2000", "--spp", "1",
                     "--sampling", "pixel", "-o", "x.png"};
    char *field[] = {"s.pov", "dgauss.50mm", "--width", "3000", "--height", "2000", "--spp", "1",
                     "--sampling", "field", "-o", "x.png"};
    const size_estimate p = estimate_of(pixel, 12, 1), f = estimate_of(field, 12, 1);
    /* pixel sampling: the EXRs, and the state of the chunk rendering (millions of faces) */
    cr_expect_geq(p.renders_bytes, 6e6 * SIZE_EXR_BYTES_PER_FACE + 1e6 * 20.0, "%.0f", p.renders_bytes);
    cr_expect_geq(f.renders_bytes, 6e6 * 20.0, "%.0f", f.renders_bytes);
}

/* In memory, render counts the weights while they fit LENS2POV_FIELD_WEIGHTS_MB (default 256
   MB) and four runs a row beyond: 160x120 at 256 spp is 19.7 MB of floats, counted by
   default, 256 x 4 x 120 runs of 16 bytes with the bound at 0. */
Test(sizecheck, field_weights_in_memory_are_counted_within_the_bound)
{
    char *args[] = {"s.pov", "dgauss.50mm", "--width", "160", "--height", "120", "--spp", "256",
                    "--sampling", "field", "-o", "x.png"};
    const size_estimate floats = estimate_of(args, 12, 2);
    setenv("LENS2POV_FIELD_WEIGHTS_MB", "0", 1);
    const size_estimate runs = estimate_of(args, 12, 2);
    unsetenv("LENS2POV_FIELD_WEIGHTS_MB");
    const double want = 256 * 160.0 * 120.0 * sizeof(float) - 256 * 4 * 120.0 * 16;
    cr_expect(fabs(floats.memory_bytes - runs.memory_bytes - want) < 1, "%.0f against %.0f",
              floats.memory_bytes - runs.memory_bytes, want);
}
