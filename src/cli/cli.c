#include "cli/cli.h"

#include "base/outfile.h"
#include "cli/values.h"
#include "field/field_render.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Limits of option values (see where they are used). */
#define UNIT_MM_LEAST 1e-3
#define UNIT_MM_MOST 1e9
#define JOBS_MOST 256
#define MEMORY_MB_MOST 1073741824.0
#define FILM_PIXELS_MOST 4294967296LL

/* The commands, as bits of the option table. */
enum { CMD_INFO = 1, CMD_TRACE = 2, CMD_DEVELOP = 4, CMD_RENDER = 8, CMD_DIAGRAM = 16,
       CMD_PLOT = 32 };
enum { CMD_CAMERA = CMD_INFO | CMD_TRACE | CMD_RENDER | CMD_DIAGRAM | CMD_PLOT,
       CMD_SAMPLES = CMD_TRACE | CMD_RENDER };

static unsigned command_bit(const char *name)
{
    static const char *const names[] = {"info", "trace", "develop", "render", "diagram", "plot"};
    for (unsigned i = 0; i < sizeof names / sizeof names[0]; i++)
        if (!strcmp(name, names[i]))
            return 1u << i;
    return 0;
}

/* Every option, the commands that take it and its line in COMMAND --help: the parser accepts
   exactly what the help lists. An option whose help differs between commands has a row for
   each; a row without help is on the line of the row before (--height on --width's). info
   takes only the camera options that change what it prints. */
typedef struct cli_option {
    const char *name, *alias;
    unsigned commands;
    bool flag;     /* takes no value */
    bool camera;   /* listed under "camera options"; info then prints the camera too */
    const char *help;
} cli_option;

static const cli_option OPTIONS[] = {
    {"--json", NULL, CMD_INFO, true, false,
     "  --json                        JSON instead of text [text]\n"},
    {"--wavelength", NULL, CMD_INFO, false, false,
     "  --wavelength NM               the lens at one wavelength, 300 to 1100 nm\n"
     "                                [the file's n_d, 587.56 nm]\n"},
    {"--output", "-o", CMD_TRACE, false, false,
     "  -o, --output PREFIX           (required)\n"},
    {"--output", "-o", CMD_DEVELOP, false, false,
     "  -o, --output IMAGE            (required)\n"},
    {"--output", "-o", CMD_RENDER, false, false,
     "  -o, --output IMAGE            .png, .exr or .tif (required)\n"},
    {"--output", "-o", CMD_DIAGRAM, false, false,
     "  -o, --output FILE.svg         (required)\n"},
    {"--output", "-o", CMD_PLOT, false, false,
     "  -o, --output FILE.png         (required)\n"},
    {"--what", NULL, CMD_PLOT, false, false,
     "  --what distortion|vignetting  (required)\n"},
    {"--jobs", NULL, CMD_RENDER, false, false,
     "  --jobs N                      POV-Ray processes at once [the cores]\n"},
    {"--memory-mb", NULL, CMD_TRACE, false, false,
     "  --memory-mb MB                split into chunks that fit a POV-Ray process of\n"
     "                                this size (--sampling pixel) [one include]\n"},
    {"--memory-mb", NULL, CMD_RENDER, false, false,
     "  --memory-mb MB                POV-Ray memory a process, --sampling pixel [1024]\n"},
    {"--rays", NULL, CMD_TRACE, false, false,
     "  --rays FILE.csv               every ray sent to POV-Ray [none]\n"},
    {"--rays", NULL, CMD_RENDER, false, false,
     "  --rays FILE.csv               every ray sent to POV-Ray; field sampling: every\n"
     "                                rendered pixel's exact ray and its render pixel [none]\n"},
    {"--scene", NULL, CMD_TRACE, false, false,
     "  --scene SCENE.pov             place the lens as this scene's camera [none];\n"
     "                                POV-Ray options it needs after --: +L, Declare=, ...\n"},
    {"--sampling", NULL, CMD_TRACE, false, false,
     "  --sampling pixel|field        exact rays, or ray fields: spp sub-images of shared\n"
     "                                samples drawn by coarse meshes [pixel]\n"},
    {"--sampling", NULL, CMD_RENDER, false, false,
     "  --sampling field|pixel        ray fields: spp sub-images of shared samples drawn\n"
     "                                by coarse meshes, or exact rays [field]\n"},
    {"--field-tolerance", NULL, CMD_SAMPLES, false, false,
     "  --field-tolerance PX          field rays' largest error, in pixels [0.05]\n"},
    {"--adaptive", NULL, CMD_RENDER, true, false,
     "  --adaptive                    field sampling of a still in two rounds: a quarter\n"
     "                                of the samples, then more where the error is; spp\n"
     "                                is the mean [off]\n"},
    {"--keep-temp", NULL, CMD_RENDER, false, false,
     "  --keep-temp DIR               keep the ray tables, renders and logs [removed]\n"},
    {"--quiet", "-q", CMD_TRACE, true, false,
     "  -q, --quiet                   no progress or summary on stderr\n"},
    {"--quiet", "-q", CMD_RENDER, true, false,
     "  -q, --quiet                   no progress on stderr\n"},
    {"--no-size-check", NULL, CMD_SAMPLES, true, false,
     "  --no-size-check               go on when the outputs seem not to fit the disk\n"
     "                                or memory [refuse, naming the estimate]\n"},
    {"--width", NULL, CMD_CAMERA, false, true,
     "  --width N --height N          film pixels [640 x 480]\n"},
    {"--height", NULL, CMD_CAMERA, false, true, NULL},
    {"--spp", NULL, CMD_SAMPLES, false, true,
     "  --spp N                       samples per pixel [16]\n"},
    {"--film-diagonal", NULL, CMD_CAMERA, false, true,
     "  --film-diagonal MM            [35]\n"},
    {"--angle", NULL, CMD_SAMPLES, false, true,
     "  --angle DEG|scene             film width for this horizontal field of view, traced\n"
     "                                (scene: the scene camera's angle) [--film-diagonal]\n"},
    {"--angle", NULL, CMD_CAMERA & ~CMD_SAMPLES, false, true,
     "  --angle DEG                   film width for this horizontal field of view, traced\n"
     "                                [--film-diagonal]\n"},
    {"--crop", NULL, CMD_SAMPLES, false, true,
     "  --crop X0,Y0,X1,Y1            a region of the film (X1, Y1 exclusive) [the whole film]\n"},
    {"--film-distance", NULL, CMD_CAMERA, false, true,
     "  --film-distance MM | --focus-distance UNITS|inf\n"
     "                                [focus on the look-at point]\n"},
    {"--focus-distance", NULL, CMD_CAMERA, false, true, NULL},
    {"--aperture-diameter", NULL, CMD_CAMERA, false, true,
     "  --aperture-diameter MM | --f-number N   [the stop's full opening]\n"},
    {"--f-number", NULL, CMD_CAMERA, false, true, NULL},
    {"--aperture-blades", NULL, CMD_CAMERA, false, true,
     "  --aperture-blades N           straight blades, 3 to 32: a polygon inscribed in the\n"
     "                                stop's opening [0: round]\n"},
    {"--blade-rotation", NULL, CMD_CAMERA, false, true,
     "  --blade-rotation DEG          a corner's angle from the lens's +x axis [0]\n"},
    {"--pupil", NULL, CMD_CAMERA, false, true,
     "  --pupil stop-image|rear|stop  [stop-image; stop is a biased diagnostic]\n"},
    {"--trace", NULL, CMD_CAMERA, false, true,
     "  --trace full|thick            [full]\n"},
    {"--weighting", NULL, CMD_SAMPLES, false, true,
     "  --weighting normalized|physical   [normalized]\n"},
    {"--dispersion", NULL, CMD_SAMPLES, false, true,
     "  --dispersion on|off           each sample at its own wavelength, its colour\n"
     "                                weighted by the CIE 1931 observer [on when the\n"
     "                                lens gives Abbe numbers and --trace is full]\n"},
    {"--wavelength", NULL, CMD_CAMERA & ~CMD_INFO, false, true,
     "  --wavelength NM               the lens at one wavelength, 300 to 1100 nm\n"
     "                                [the file's n_d, 587.56 nm]\n"},
    {"--location", NULL, CMD_CAMERA, false, true,
     "  --location X,Y,Z [0,0,0]  --look-at X,Y,Z [0,0,1]  --sky X,Y,Z [0,1,0]\n"
     "                                [with a scene: the scene's camera]\n"},
    {"--look-at", NULL, CMD_CAMERA, false, true, NULL},
    {"--sky", NULL, CMD_CAMERA, false, true, NULL},
    {"--unit-mm", NULL, CMD_CAMERA, false, true,
     "  --unit-mm MM                  millimetres in a scene unit [1000]\n"},
    {"--seed", NULL, CMD_SAMPLES, false, true,
     "  --seed N                      the sample pattern's seed [0]\n"},
};

static int film_option(cli *c, const char *opt, const char *v, l2p_error *err)
{
    camera_options *o = &c->cam;
    if (!strcmp(opt, "--width"))
        return value_positive_int(opt, v, &o->width, err);
    if (!strcmp(opt, "--height"))
        return value_positive_int(opt, v, &o->height, err);
    if (!strcmp(opt, "--spp"))
        return value_positive_int(opt, v, &o->spp, err);
    if (!strcmp(opt, "--film-diagonal")) {
        c->diagonal_given = true;
        return value_positive_double(opt, v, &o->film_diagonal_mm, err);
    }
    if (!strcmp(opt, "--angle")) {   /* the film width: framing.c */
        c->angle_scene = !strcmp(v, "scene");
        if (c->angle_scene)
            return L2P_OK;
        if (!value_double(v, &c->angle_deg) || !(c->angle_deg > 0.0 && c->angle_deg < 360.0))
            return value_bad(err, opt, "degrees (more than 0, less than 360) or 'scene'", v);
        return L2P_OK;
    }
    if (!strcmp(opt, "--film-distance")) {
        if (!value_double(v, &o->film_distance_mm) || o->film_distance_mm < 0.0)
            return value_bad(err, opt, "a distance in mm, 0 or more", v);
        return L2P_OK;
    }
    if (!strcmp(opt, "--focus-distance")) {
        if (!strcmp(v, "inf") || !strcmp(v, "infinity")) {
            o->focus_distance_units = INFINITY;
            return L2P_OK;
        }
        return value_positive_double(opt, v, &o->focus_distance_units, err);
    }
    if (!strcmp(opt, "--crop")) {
        int crop[4];
        if (!value_crop(v, crop))
            return value_bad(err, opt, "X0,Y0,X1,Y1 with X1 > X0 >= 0 and Y1 > Y0 >= 0", v);
        o->crop_x0 = crop[0];
        o->crop_y0 = crop[1];
        o->crop_x1 = crop[2];
        o->crop_y1 = crop[3];
        return L2P_OK;
    }
    return -1;
}

static int lens_option(cli *c, const char *opt, const char *v, l2p_error *err)
{
    camera_options *o = &c->cam;
    if (!strcmp(opt, "--aperture-diameter"))
        return value_positive_double(opt, v, &o->aperture_diameter_mm, err);
    if (!strcmp(opt, "--f-number"))
        return value_positive_double(opt, v, &o->f_number, err);
    if (!strcmp(opt, "--aperture-blades")) {
        if (!value_int(v, &o->aperture_blades) || o->aperture_blades < 0 ||
            (o->aperture_blades > 0 && o->aperture_blades < 3) ||
            o->aperture_blades > LENS_MAX_BLADES)
            return value_bad(err, opt, "0 (round) or a whole number from 3 to 32", v);
        return L2P_OK;
    }
    if (!strcmp(opt, "--blade-rotation"))
        return value_double_in(opt, v, -360.0, 360.0, &o->blade_rotation_deg, err);
    if (!strcmp(opt, "--pupil"))
        return pupil_kind_parse(v, &o->pupil) ? value_bad(err, opt, "stop, rear or stop-image", v) : 0;
    if (!strcmp(opt, "--trace")) {
        if (strcmp(v, "full") && strcmp(v, "thick"))
            return value_bad(err, opt, "full or thick", v);
        o->trace = strcmp(v, "thick") ? TRACE_KIND_FULL : TRACE_KIND_THICK;
        return L2P_OK;
    }
    if (!strcmp(opt, "--weighting")) {
        if (strcmp(v, "normalized") && strcmp(v, "physical"))
            return value_bad(err, opt, "normalized or physical", v);
        o->weighting = strcmp(v, "physical") ? WEIGHTING_NORMALIZED : WEIGHTING_PHYSICAL;
        return L2P_OK;
    }
    if (!strcmp(opt, "--dispersion")) {
        if (strcmp(v, "on") && strcmp(v, "off"))
            return value_bad(err, opt, "on or off", v);
        o->dispersion = strcmp(v, "on") ? DISPERSION_OFF : DISPERSION_ON;
        return L2P_OK;
    }
    /* The Cauchy fit through n_d, n_F and n_C holds for visible light and a little beyond. */
    if (!strcmp(opt, "--wavelength"))
        return value_double_in(opt, v, 300.0, 1100.0, &o->wavelength_nm, err);
    if (!strcmp(opt, "--seed")) {
        char *end;
        errno = 0;
        unsigned long long s = strtoull(v, &end, 10);
        if (end == v || *end || errno || v[0] == '-')
            return value_bad(err, opt, "a whole number, 0 or more", v);
        o->seed = s;
        return L2P_OK;
    }
    return -1;
}

static int place_option(cli *c, const char *opt, const char *v, l2p_error *err)
{
    camera_options *o = &c->cam;
    c->placed |= !strcmp(opt, "--location") || !strcmp(opt, "--look-at") || !strcmp(opt, "--sky");
    if (!strcmp(opt, "--location"))
        return value_vec3(v, &o->location) ? 0 : value_bad(err, opt, "x,y,z", v);
    if (!strcmp(opt, "--look-at"))
        return value_vec3(v, &o->look_at) ? 0 : value_bad(err, opt, "x,y,z", v);
    if (!strcmp(opt, "--sky"))
        return value_vec3(v, &o->sky) ? 0 : value_bad(err, opt, "x,y,z", v);
    /* Millimetres in a scene unit: from a micrometre to a thousand kilometres. Beyond, the
       ray table's triangles (a lens aperture in scene units) leave float32, which is how
       POV-Ray stores mesh vertices: they overflow to infinity or collapse to a point. */
    if (!strcmp(opt, "--unit-mm"))
        return value_double_in(opt, v, UNIT_MM_LEAST, UNIT_MM_MOST, &o->unit_mm, err);
    return -1;
}

static int run_option(cli *c, const char *opt, const char *v, l2p_error *err)
{
    if (!strcmp(opt, "--output"))
        c->output = v;
    else if (!strcmp(opt, "--rays"))
        c->rays_csv = v;
    else if (!strcmp(opt, "--keep-temp"))
        c->keep_temp = v;
    else if (!strcmp(opt, "--scene"))
        c->scene = v;
    else if (!strcmp(opt, "--sampling")) {
        if (strcmp(v, "pixel") && strcmp(v, "field"))
            return value_bad(err, opt, "pixel or field", v);
        c->field_sampling = !strcmp(v, "field");
        c->sampling_chosen = true;
    } else if (!strcmp(opt, "--field-tolerance")) {
        if (!value_double(v, &c->field_tolerance) || !(c->field_tolerance > 0))
            return value_bad(err, opt, "pixels above 0 (for exact rays: --sampling pixel)", v);
        c->sampling_chosen = c->tolerance_given = true;
    } else if (!strcmp(opt, "--what")) {   /* plot: the command checks the name */
        c->what = v;
        return L2P_OK;
    } else if (!strcmp(opt, "--jobs"))   /* cleanup.c stops at most 256 children on a signal */
        return value_int_up_to(opt, v, JOBS_MOST, &c->jobs, err);
    else if (!strcmp(opt, "--memory-mb"))  /* up to 1 PiB: render converts it to a face count */
        return value_positive_double(opt, v, &c->memory_mb, err) ? L2P_BAD_INPUT
               : c->memory_mb > MEMORY_MB_MOST ? value_bad(err, opt, "a positive number up to 1073741824", v)
                                               : L2P_OK;
    else
        return -1;
    if (!*v)
        return value_bad(err, opt, "a file name", v);
    return L2P_OK;
}

static int value_option(cli *c, const char *opt, const char *v, l2p_error *err)
{
    int st = film_option(c, opt, v, err);
    if (st < 0)
        st = lens_option(c, opt, v, err);
    if (st < 0)
        st = place_option(c, opt, v, err);
    if (st < 0)
        st = run_option(c, opt, v, err);
    if (st < 0)
        st = l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "unknown option '%s' (see lens2pov --help)", opt);
    return st;
}

/* --rays naming one of the other outputs (the table, its chunks, a field's renders, or the
   pictures POV-Ray is to write for them): both would be renamed into place, the last wins. */
static bool same_output(const char *rays, const char *output)
{
    static const char *const ext[] = {".inc", ".ini", ".map", ".exr"};
    const size_t n = strlen(output);
    if (strncmp(rays, output, n))
        return false;
    const char *rest = rays + n;
    if (!*rest)
        return true;
    /* a chunk's or a field render's files: PREFIX.cNNN.EXT, PREFIX.fNNN.EXT */
    if (rest[0] == '.' && (rest[1] == 'c' || rest[1] == 'f') && isdigit((unsigned char)rest[2]))
        for (rest += 2; isdigit((unsigned char)*rest); rest++)
            continue;
    for (int i = 0; i < 4; i++)
        if (!strcmp(rest, ext[i]))
            return true;
    return false;
}

/* What positional argument i of command is, for a message. */
static const char *input_role(const char *command, int i)
{
    if (!strcmp(command, "render"))
        return i == 0 ? "the scene" : "the lens";
    if (!strcmp(command, "develop"))
        return i == 0 ? "the ray table" : "a render";
    return "the lens";
}

/* Output out must not be an input: the positional files (lens, scene, renders), --scene. */
static int check_not_input(const cli *c, const char *command, const char *out, l2p_error *err)
{
    int st = L2P_OK;
    for (int i = 0; !st && i < c->positional_count; i++)
        st = outfile_check_not_input(out, c->positional[i], input_role(command, i), err);
    if (!st && c->scene)
        st = outfile_check_not_input(out, c->scene, "the scene", err);
    return st;
}

/* No output may be an input: -o (for trace a prefix of PREFIX.inc, .ini and .map) and --rays. */
static int check_outputs_not_inputs(const cli *c, const char *command, l2p_error *err)
{
    int st = c->rays_csv ? check_not_input(c, command, c->rays_csv, err) : L2P_OK;
    if (st || !c->output)
        return st;
    if (strcmp(command, "trace"))
        return check_not_input(c, command, c->output, err);
    static const char *const ext[] = {".inc", ".ini", ".map"};
    char *out = malloc(strlen(c->output) + 5);
    if (!out)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int k = 0; !st && k < 3; k++) {
        sprintf(out, "%s%s", c->output, ext[k]);
        st = check_not_input(c, command, out, err);
    }
    free(out);
    return st;
}

static int check_contradictions(const cli *c, l2p_error *err)
{
    const camera_options *o = &c->cam;
    /* The sample map numbers film pixels y * width + x in 32 bits. */
    if ((long long)o->width * o->height > FILM_PIXELS_MOST)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                        "--width %d x --height %d is %lld pixels: at most %lld (2^32)", o->width,
                        o->height, (long long)o->width * o->height, FILM_PIXELS_MOST);
    if (c->rays_csv && c->output && same_output(c->rays_csv, c->output))
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                        "--rays %s would overwrite an output of -o %s: give another file",
                        c->rays_csv, c->output);
    if (!isnan(o->film_distance_mm) && !isnan(o->focus_distance_units))
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                        "--film-distance and --focus-distance both set the focus: give one");
    if ((c->angle_scene || !isnan(c->angle_deg)) && c->diagonal_given)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                        "--angle and --film-diagonal both set the film's size: give one");
    if (!isnan(o->aperture_diameter_mm) && !isnan(o->f_number))
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                        "--aperture-diameter and --f-number both set the aperture: give one");
    if (c->tolerance_given && !c->field_sampling)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--field-tolerance is for --sampling field; "
                        "pixel sampling traces every ray exactly");
    if (c->adaptive && !c->field_sampling)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--adaptive is for --sampling field");
    if (o->crop_x1 && (o->crop_x1 > o->width || o->crop_y1 > o->height))
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                        "--crop %d,%d,%d,%d reaches outside the %dx%d film (X1, Y1 exclusive)",
                        o->crop_x0, o->crop_y0, o->crop_x1, o->crop_y1, o->width, o->height);
    return L2P_OK;
}

/* A flag of the table (no value). */
static void set_flag(cli *c, const cli_option *o)
{
    if (!strcmp(o->name, "--json"))
        c->json = true;
    else if (!strcmp(o->name, "--quiet"))
        c->quiet = true;
    else if (!strcmp(o->name, "--no-size-check"))
        c->no_size_check = true;
    else if (!strcmp(o->name, "--adaptive"))
        c->adaptive = true;
}

/* The option a word names, for this command; NULL with the error set when the command does not
   take it or no command does. */
static const cli_option *find_option(unsigned command, const char *cmd_name, const char *opt,
                                     l2p_error *err)
{
    bool known = false;
    for (size_t i = 0; i < sizeof OPTIONS / sizeof OPTIONS[0]; i++) {
        const cli_option *o = &OPTIONS[i];
        if (strcmp(opt, o->name) && !(o->alias && !strcmp(opt, o->alias)))
            continue;
        if (o->commands & command)
            return o;
        known = true;
    }
    if (known)
        l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "%s does not take %s (see lens2pov %s --help)",
                 cmd_name, opt, cmd_name);
    else
        l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "unknown option '%s' (see lens2pov --help)", opt);
    return NULL;
}

/* No value starts with "--", and "-o" or "-q" after an option that wants a value is the next
   option, the value forgotten; "-5" is a number. */
static bool looks_like_option(const char *v)
{
    return (v[0] == '-' && v[1] == '-') || (v[0] == '-' && isalpha((unsigned char)v[1]) && !v[2]);
}

int cli_parse(cli *c, int argc, char **argv, int first, l2p_error *err)
{
    memset(c, 0, sizeof *c);
    camera_options_default(&c->cam);
    c->angle_deg = NAN;
    c->field_tolerance = FIELD_DEFAULT_TOLERANCE_PX;
    const char *cmd_name = first > 0 ? argv[first - 1] : "";
    const unsigned command = command_bit(cmd_name);
    /* render: field sampling gives less error in the same time at the default film and spp
       (docs/benchmarks.md); trace: one exact include to render as it is */
    c->field_sampling = command == CMD_RENDER;
    if (!command)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "unknown command '%s' (see --help)", cmd_name);
    for (int i = first; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--")) {   /* the rest is POV-Ray's (render checks it) */
            c->povray_args = argv + i + 1;
            c->povray_arg_count = argc - i - 1;
            break;
        }
        if (a[0] != '-' || a[1] == '\0') {
            if (c->positional_count == CLI_MAX_POSITIONAL)
                return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "unexpected argument '%s'", a);
            c->positional[c->positional_count++] = a;
            continue;
        }
        const char *eq = strchr(a, '=');
        char opt[64];
        const char *value = NULL;
        if (eq && a[1] == '-' && (size_t)(eq - a) < sizeof opt) {
            memcpy(opt, a, (size_t)(eq - a));
            opt[eq - a] = '\0';
            value = eq + 1;
        } else {
            snprintf(opt, sizeof opt, "%s", a);
        }
        const cli_option *o = find_option(command, cmd_name, opt, err);
        if (!o)
            return L2P_BAD_INPUT;
        if (o->flag) {
            if (value)
                return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "%s takes no value", opt);
            set_flag(c, o);
            continue;
        }
        if (!value) {
            if (i + 1 >= argc)
                return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "%s needs a value", opt);
            value = argv[++i];
            if (looks_like_option(value))
                return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "%s needs a value, not the option %s",
                                opt, value);
        }
        c->film_given |= o->camera;   /* info prints the camera only when asked for one */
        int st = value_option(c, o->name, value, err);
        if (st)
            return st;
    }
    int st = check_contradictions(c, err);
    return st ? st : check_outputs_not_inputs(c, argv[first - 1], err);
}

void cli_print_options(FILE *out, const char *command)
{
    const unsigned bit = command_bit(command);
    bool camera_header = false;
    for (size_t i = 0; i < sizeof OPTIONS / sizeof OPTIONS[0]; i++) {
        const cli_option *o = &OPTIONS[i];
        if (!(o->commands & bit) || !o->help)
            continue;
        if (o->camera && !camera_header) {
            fputs("camera options (defaults in brackets):\n", out);
            camera_header = true;
        }
        fputs(o->help, out);
    }
}

int cli_expect_arguments(const cli *c, int positional, bool output, l2p_error *err)
{
    if (c->positional_count != positional)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "expected %d argument%s, got %d (see --help)",
                        positional, positional == 1 ? "" : "s", c->positional_count);
    if (output && !c->output)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "-o is required");
    return L2P_OK;
}
