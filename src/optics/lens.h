/* A lens prescription in pbrt's format: reading, validating and querying it.

   One row a surface, from the scene side to the film side, millimetres:
   radius (positive: centre of curvature on the film side; 0: the aperture stop),
   thickness to the next surface, index of refraction behind the surface (n_d; 0 on the stop
   row means air), clear aperture diameter, and optionally the Abbe number V_d of the medium
   behind the surface (0 or absent for air; every glass row gives one or none does). Camera
   space puts the film at z = 0 and the lens toward +z; surface i has its vertex at
   z = film_distance + sum of thicknesses of rows i .. n-2. */
#ifndef LENS2POV_LENS_H
#define LENS2POV_LENS_H

#include <stddef.h>
#include "base/error.h"

typedef struct lens_surface {
    double radius_mm;        /* signed radius of curvature; 0 on the stop row */
    double curvature_per_mm; /* 1 / radius, 0 for the stop */
    double thickness_mm;     /* axial distance to the next surface toward the film */
    double ior;              /* index of the medium behind this surface; 1 where the file says 0 */
    double aperture_diameter_mm;  /* clear aperture (the stop: its largest opening) */
    double abbe;             /* V_d of the medium behind; 0 for air or when the file gives none */
    double vertex_z_mm;      /* camera space; set by lens_set_film_distance */
    int line;                /* line of the file that gave this row */
} lens_surface;

/* The stop's blades: a regular polygon of `count` corners inscribed in the stop's circle
   (its corners on the circle of the current opening), or a round stop when count is 0. */
enum { LENS_MAX_BLADES = 32 };
typedef struct lens_blades {
    int count;                          /* 0, or 3 .. LENS_MAX_BLADES */
    double apothem_ratio;               /* cos(pi / count): an edge's distance over the radius */
    double normal_x[LENS_MAX_BLADES];   /* each edge's outward unit normal */
    double normal_y[LENS_MAX_BLADES];
} lens_blades;

typedef struct lens {
    char *path;              /* as given by the user, for messages */
    char *name;              /* file name without folders and without ".dat" */
    lens_surface *surface;   /* surface[0] faces the scene, surface[count-1] the film */
    int count;
    int stop;                /* index of the aperture stop row */
    double stop_diameter_mm; /* current opening, at most surface[stop].aperture_diameter_mm */
    double film_distance_mm; /* rear vertex to film */
    lens_blades blades;      /* the stop's shape (set by lens_set_blades; round at first) */
} lens;

/* Limits of lens_read and lens_parse, far above any real lens: they stop a wrong file (an
   image, a log) from taking the memory before the parser refuses it. */
enum { LENS_MAX_FILE_BYTES = 16 * 1024 * 1024, LENS_MAX_SURFACES = 10000 };

/* Reads and validates a lens file. On failure returns L2P_BAD_INPUT with "FILE:LINE: what is
   wrong" in err and leaves *out empty. The film distance starts at 0 (call
   lens_set_film_distance) and the stop at its full opening. */
int lens_read(const char *path, lens *out, l2p_error *err);

/* The same from text already in memory; name is used in messages as the file name. */
int lens_parse(const char *text, size_t length, const char *name, lens *out, l2p_error *err);

void lens_free(lens *l);

/* Deep copy (for tracing variants side by side). */
int lens_copy(lens *dst, const lens *src);

/* Places the surfaces in camera space for this rear-vertex-to-film distance. */
void lens_set_film_distance(lens *l, double film_distance_mm);

/* Index of refraction in front of surface i (scene side) and behind it (film side). */
static inline double lens_ior_front(const lens *l, int i) { return i == 0 ? 1.0 : l->surface[i - 1].ior; }
static inline double lens_ior_behind(const lens *l, int i) { return l->surface[i].ior; }

/* Semi-aperture of surface i, the stop's current opening for the stop. */
static inline double lens_semi_aperture_mm(const lens *l, int i)
{
    return i == l->stop ? 0.5 * l->stop_diameter_mm : 0.5 * l->surface[i].aperture_diameter_mm;
}

/* Gives the stop `count` straight blades (0: round), one corner at rotation_rad from the +x
   axis toward +y. */
void lens_set_blades(lens *l, int count, double rotation_rad);

/* How far the stop's opening reaches from the axis in the unit direction (ux, uy): its
   semi-aperture when round; with blades, the distance to the polygon's edge that way,
   apothem / max over the edges of (outward normal . u). */
double lens_stop_reach_mm(const lens *l, double ux, double uy);

/* The blades of surface i: the stop's when it has blades, else NULL (a round opening). */
static inline const lens_blades *lens_blades_of(const lens *l, int i)
{
    return i == l->stop && l->blades.count ? &l->blades : NULL;
}

/* Standard wavelengths of the Abbe number, nm: helium d, hydrogen F and C lines. */
#define WAVELENGTH_D_NM 587.5618
#define WAVELENGTH_F_NM 486.1327
#define WAVELENGTH_C_NM 656.2725

/* The medium behind surface s as n(lambda) = a + b / lambda^2 (lambda in nm): the Cauchy fit
   through n_d and V_d (lens_shape.c, docs/lenses.md); a = ior and b = 0 where the file gives
   no Abbe number. */
void lens_cauchy(const lens_surface *s, double *a, double *b_nm2);

/* 1 / lambda^2, the variable the Cauchy fit is linear in. */
static inline double lens_inverse_square(double wavelength_nm)
{
    return 1.0 / (wavelength_nm * wavelength_nm);
}

/* Index of the medium behind surface s at this wavelength (nm): a + b / lambda^2. */
double lens_index_at(const lens_surface *s, double wavelength_nm);

/* Gives every surface its index at this wavelength, and no Abbe number: the lens as a light
   of one wavelength sees it (for first-order properties and pupils at that wavelength). */
void lens_at_wavelength(lens *l, double wavelength_nm);

/* 1 when the file gave Abbe numbers (its glass rows have a fifth column), else 0. */
int lens_has_abbe(const lens *l);

/* Front vertex to rear vertex: the sum of the thicknesses of rows 0 .. n-2. */
double lens_total_length_mm(const lens *l);

/* Sag of surface i at height rho: the axial offset of the surface from its vertex, positive
   toward the scene (+z). 0 for the stop. */
double lens_sag_mm(const lens_surface *s, double rho_mm);

/* The first two neighbouring surfaces that cross inside both clear apertures: at the smaller
   semi-aperture rho the rear one stands in front of the front one. Returns the index i of the
   front one (surfaces i and i + 1), with rho and the axial gap there (< 0), or -1. */
int lens_crossing(const lens *l, double *rho_mm, double *gap_mm);

#endif
