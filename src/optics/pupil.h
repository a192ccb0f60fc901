/* Exit pupils (Kolb, Mitchell and Hanrahan 1995): the region of a plane on the film side
   toward which film rays are aimed, and sampling it. */
#ifndef LENS2POV_PUPIL_H
#define LENS2POV_PUPIL_H

#include <math.h>
#include <stdbool.h>
#include "base/error.h"
#include "optics/lens.h"
#include "base/vec3.h"

typedef enum pupil_kind {
    PUPIL_STOP,        /* the aperture stop itself: misses rays the lens would pass (diagnostic) */
    PUPIL_REAR,        /* the rear element's rim: passes many rays the lens then blocks */
    PUPIL_STOP_IMAGE   /* the paraxial image of the stop through the stop-to-film surfaces */
} pupil_kind;

/* The region sampled for one film radius, in the frame where the film point lies on the +x
   axis: the points (centre_mm, 0) + rho (cos phi, sin phi) with rho <= R(phi), R linear in
   cos(phi) between radius_mm[i] at cos(phi) = 1 - 2 i / PUPIL_KNOTS, and R(-phi) = R(phi)
   (the region is symmetric about the x axis). A region shaped like a star about its centre:
   the image of the stop cut by the images of the element rims. The lens is rotationally
   symmetric, so the film point (r cos t, r sin t) samples this region turned by t. */
enum { PUPIL_KNOTS = 32 };

typedef struct pupil_shape {
    double centre_mm;
    double radius_mm[PUPIL_KNOTS + 1];
} pupil_shape;

/* Film radii at which the shapes are tabulated, from 0 to the largest film radius, and the
   chief ray's crossings (PUPIL_CHIEF_SAMPLES / PUPIL_NODES of them a node). */
enum { PUPIL_NODES = 32, PUPIL_CHIEF_SAMPLES = 4096 };

typedef struct pupil {
    pupil_kind kind;
    double z_mm;        /* plane of the sampled region, camera space; may lie behind the film */
    double radius_mm;   /* the model's disk: the stop, the rear rim or the stop's paraxial image */
    /* With node_spacing_mm = 0 every film point samples the model's disk. Otherwise film radius
       r samples the shape interpolated linearly between node[j] and node[j + 1], j = r /
       node_spacing_mm (the last node beyond), and a film point farther out than reach_mm
       samples nothing: no ray from it gets through the lens. */
    double node_spacing_mm, reach_mm;
    pupil_shape node[PUPIL_NODES + 1];
    /* Where the chief ray of film radius i * chief_spacing_mm crosses the pupil plane (x, mm),
       for stop-image's fit (chief_spacing_mm = 0: none). The region's centre at film radius r
       is this, interpolated as a cubic, plus the nodes' offsets from it interpolated linearly:
       the centre moves with r faster than linearly (pupil aberration), and a region smaller
       than linear interpolation's error between nodes, a tiny stop's, would be missed. */
    double chief_spacing_mm;
    double chief_x_mm[PUPIL_CHIEF_SAMPLES + 1];
} pupil;

/* Name as used on the command line: "stop", "rear", "stop-image". */
const char *pupil_kind_name(pupil_kind k);
int pupil_kind_parse(const char *name, pupil_kind *k);

/* The paraxial image of the stop (centre and rim conjugates) through the surfaces behind it
   (toward_film: the exit pupil) or in front of it (the entrance pupil, seen from the scene). */
int pupil_stop_image(const lens *l, bool toward_film, double *z_mm, double *radius_mm,
                     l2p_error *err);

/* Builds the pupil for the lens at its current film distance and stop opening: every film
   point samples the model's disk. */
int pupil_make(const lens *l, pupil_kind kind, pupil *out, l2p_error *err);

/* Fits the sampled region to the rays the lens passes (full simulation), for every film
   radius up to film_radius_mm. For each node the passing region of the pupil plane is found
   by bisecting its boundary in many directions; stop-image then samples the star-shaped
   region through that boundary, rear the disk about the axis that holds it and the rear rim. Between nodes the
   interpolated shape is checked against the region at intermediate radii and grown where it
   falls short; every shape finally gets a small margin (pupil_fit.c says why it is enough).
   A region sampled larger than the passing one costs blocked samples, never bias: the weight
   divides by the sampling density. */
void pupil_fit(pupil *pu, const lens *l, double film_radius_mm);

/* The growth every fitted shape gets last (pupil_fit.c says why). */
#define PUPIL_FIT_MARGIN 1.004

/* The chief ray's crossing at node j's film radius (pupil.h's table), 0 without the table. */
static inline double pupil_chief_at_node(const pupil *pu, int j)
{
    return pu->chief_spacing_mm > 0.0 ? pu->chief_x_mm[j * (PUPIL_CHIEF_SAMPLES / PUPIL_NODES)] : 0.0;
}

/* Whether pu was fitted (pupil_fit). */
static inline bool pupil_is_fitted(const pupil *pu) { return pu->node_spacing_mm > 0.0; }

/* The radius of sample (u, v)'s point on the unit disk (the concentric map sends the square's
   ring max(|2u - 1|, |2v - 1|) = r onto the circle of radius r). */
static inline double pupil_disk_radius(double u, double v)
{
    return fmax(fabs(2.0 * u - 1.0), fabs(2.0 * v - 1.0));
}

/* The sample (u, v) whose point on the unit disk is (x, y): the concentric map's inverse, for
   samplers that place points on the disk themselves (field sampling's strata). */
void pupil_square_of_disk(double x, double y, double *u, double *v);

/* Grows a fitted pupil so that it also holds every ray that lens l passes: l is the same lens
   at another wavelength (lens_at_wavelength), whose passing regions are those of the fit
   moved and scaled a little. Each node, and each point the fit checks between nodes, grows
   by what it falls short, with the fit's margin; the reach moves out where l passes rays
   beyond it. Does nothing to a pupil that was not fitted. */
void pupil_cover(pupil *pu, const lens *l);

/* The shape sampled for a film point at film radius r_mm (the frame of pupil_shape); false
   when no ray from there gets through the lens. */
bool pupil_shape_at(const pupil *pu, double r_mm, pupil_shape *out);

/* Whether film point p samples anything: false beyond the lens's reach (no ray from p gets
   through), where a sample would only be traced to be blocked. */
static inline bool pupil_reaches(const pupil *pu, vec3 film_point)
{
    return film_point.x * film_point.x + film_point.y * film_point.y <= pu->reach_mm * pu->reach_mm;
}

/* Whether point (x, y) of the pupil plane lies in the region sampled for film point p. */
bool pupil_contains(const pupil *pu, vec3 film_point, double x_mm, double y_mm);

/* The film ray from film point p toward the pupil point of sample (u, v), and its weight
   cos^4(theta) / (Z^2 q) (Z: axial distance from the film to the pupil plane, q: the density
   of the pupil point, 1 / A for the seed's uniform disk of area A). The unit square maps onto
   the unit disk by the concentric map, and the disk's point d onto centre + R(phi) d: the
   density is 1 / (pi R(phi)^2), uniform where R is constant (a disk).
   Returns the weight; 0 when the pupil lies in the film plane or p is beyond the reach. */
double pupil_film_ray(const pupil *pu, vec3 film_point, double u, double v, vec3 *direction);

/* The same for n film samples at once, faster: directions[k] and weights[k] are what
   pupil_film_ray gives for film_points[k], u[k] and v[k], bit for bit. */
void pupil_film_rays(const pupil *pu, int n, const vec3 *film_points, const double *u,
                     const double *v, vec3 *directions, double *weights);

/* The unit direction from film point p toward point (x, y) of the pupil plane. */
vec3 pupil_direction(const pupil *pu, vec3 film_point, double x_mm, double y_mm);

/* The pupil-plane point of sample (u, v) for film point p, the inverse of its density
   (pi R(phi)^2, in mm^2), and whether p samples anything. */
bool pupil_point(const pupil *pu, vec3 film_point, double u, double v, double *x_mm,
                 double *y_mm, double *inverse_density_mm2);

/* R of shape e for a direction at cos(phi) = cos_phi from its centre. */
double pupil_shape_radius_mm(const pupil_shape *e, double cos_phi);

#endif
