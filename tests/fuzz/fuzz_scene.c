/* libFuzzer target: the scene's text as the camera probe reads it.

   The bytes are a scene (inputs holding a NUL byte are skipped: the probe refuses them). Its
   copy (scene_camera_rewrite_file) must have as many lines as the scene, so that POV-Ray's
   messages keep the scene's line numbers, and must equal the scene exactly when
   scene_text_has_camera finds no camera statement. Every #include name scene_text_includes
   gives must lie inside the text, within quotes, on the line it names. What
   scene_camera_literal_log writes must read back (scene_frames_from_log) as a frame whose
   camera is accepted or refused with a message. Built by tests/fuzz/run.sh. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "povray/scenecam.h"

enum { MAX_BYTES = 4096 };

static void fail(const char *what)
{
    fprintf(stderr, "fuzz_scene: %s\n", what);
    abort();
}

static int lines(const char *s, size_t n)
{
    int count = 0;
    for (size_t i = 0; i < n; i++)
        count += s[i] == '\n';
    return count;
}

typedef struct scene_text {
    const char *s;
    size_t n;
} scene_text;

static bool check_include(const char *name, size_t len, int line, void *ctx)
{
    const scene_text *t = ctx;
    if (name <= t->s || name + len >= t->s + t->n || name[-1] != '"' || name[len] != '"')
        fail("an #include name outside the text or its quotes");
    if (line != lines(t->s, (size_t)(name - t->s)) + 1)
        fail("an #include on another line than the one given");
    return true;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > MAX_BYTES || memchr(data, '\0', size))
        return 0;
    char *s = malloc(size + 1);
    if (!s)
        return 0;
    memcpy(s, data, size);
    s[size] = '\0';
    char *copy = scene_camera_rewrite_file(s, size, 3);
    int first = 0;
    const bool camera = scene_text_has_camera(s, size, &first);
    if (copy && lines(copy, strlen(copy)) != lines(s, size))
        fail("the copy has another number of lines than the scene");
    if (copy && !camera && strcmp(copy, s))
        fail("a scene without a camera statement was changed");
    if (camera && (first < 1 || first > lines(s, size) + 1))
        fail("a camera statement on a line the scene does not have");
    free(copy);
    scene_text t = {s, size};
    scene_text_includes(s, size, check_include, &t);
    char *literal = scene_camera_literal_log(s, size);
    if (literal) {
        const char *scene = "fuzz.pov";
        const scene_files files = {&scene, 1};
        scene_frames f;
        l2p_error err;
        const int st = scene_frames_from_log(literal, strlen(literal), &files, &f, &err);
        if (st != L2P_OK && (st != L2P_BAD_INPUT || !err.text[0]))
            fail("a literal camera read back neither accepted nor refused with a message");
        if (st == L2P_OK && f.count < 1)
            fail("a literal camera read back without a frame");
        scene_frames_free(&f);
        free(literal);
    }
    free(s);
    return 0;
}
