/* The command line: options common to the commands, parsed strictly. Every bad value is
   refused with L2P_BAD_INPUT and a message naming the option. */
#ifndef LENS2POV_CLI_H
#define LENS2POV_CLI_H

#include <stdbool.h>
#include <stdio.h>
#include "camera/camera.h"
#include "base/error.h"

enum { CLI_MAX_POSITIONAL = 256 };

typedef struct cli {
    camera_options cam;
    const char *positional[CLI_MAX_POSITIONAL];
    int positional_count;
    const char *output;          /* -o */
    const char *rays_csv;        /* --rays */
    const char *keep_temp;       /* --keep-temp */
    int jobs;                    /* --jobs, 0: the number of cores */
    double memory_mb;            /* --memory-mb: POV-Ray memory budget per process (chunks) */
    bool json;                   /* --json */
    bool quiet;                  /* --quiet: no progress bar */
    bool no_size_check;          /* --no-size-check: trace even what seems not to fit */
    bool film_given;             /* a camera option was given (info prints the camera) */
    bool placed;                 /* --location, --look-at or --sky: the scene's camera is not used */
    const char *what;            /* plot --what: distortion or vignetting */
    const char *scene;           /* trace --scene: the scene whose camera places the lens */
    double angle_deg;            /* --angle: the horizontal field of view; NAN: not given */
    bool angle_scene;            /* --angle scene: the scene camera's */
    bool diagonal_given;         /* --film-diagonal (it contradicts --angle) */
    char *const *povray_args;    /* render: POV-Ray's own options, after "--" */
    int povray_arg_count;
    bool field_sampling;         /* --sampling field (docs/fields.md); render's default */
    bool sampling_chosen;        /* --sampling or --field-tolerance given: render keeps to it */
    bool tolerance_given;        /* --field-tolerance: refused with pixel sampling */
    double field_tolerance;      /* --field-tolerance, pixels [0.05] */
    bool adaptive;               /* --adaptive: a field still in two rounds */
} cli;

/* Parses argv[first..argc-1] for the command argv[first-1] (info, trace, develop, render, diagram, plot): an
   option that command does not take is refused, naming both. */
int cli_parse(cli *c, int argc, char **argv, int first, l2p_error *err);

/* The lines of COMMAND --help that list its options: the same table the parser accepts. */
void cli_print_options(FILE *out, const char *command);

/* Warns on stderr about choices that give a picture the user may not expect (warnings.c): a
   rim that limits the axial beam more than the stop, --blade-rotation without blades, a film
   distance that puts the focus behind the camera, and for a command that makes a picture
   (trace and render), --pupil stop (biased on purpose), a stop where diffraction would show,
   and a lens that passes few of the samples. */
void cli_warn(const cli *c, const camera *cam, bool picture);
/* Warns that --wavelength changes nothing on a lens without Abbe numbers (glass false). */
void cli_warn_wavelength(const cli *c, const char *lens_path, bool glass);

/* L2P_BAD_INPUT unless c has exactly `positional` arguments and, when output, a -o. */
int cli_expect_arguments(const cli *c, int positional, bool output, l2p_error *err);

#endif
