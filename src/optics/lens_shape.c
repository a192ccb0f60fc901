/* A lens once read: where its surfaces stand for a film distance, their shapes, the index of
   their glass at a wavelength, and the stop's blades. */
#include "optics/lens.h"

#include <math.h>
#include <string.h>

/* From the film forward: the rear vertex sits at the film distance, and each surface in front
   of it one thickness further. The last row's own thickness is not used. */
void lens_set_film_distance(lens *l, double film_distance_mm)
{
    l->film_distance_mm = film_distance_mm;
    double z = film_distance_mm;
    for (int i = l->count - 1; i >= 0; i--) {
        if (i < l->count - 1)
            z += l->surface[i].thickness_mm;
        l->surface[i].vertex_z_mm = z;
    }
}

double lens_total_length_mm(const lens *l)
{
    double length = 0.0;
    for (int i = 0; i < l->count - 1; i++)
        length += l->surface[i].thickness_mm;
    return length;
}

/* The two-term Cauchy fit n(lambda) = A + B / lambda^2 through n_d with the principal
   dispersion the Abbe number defines, V_d = (n_d - 1) / (n_F - n_C):
     n_F - n_C = B (1/lambda_F^2 - 1/lambda_C^2) = (n_d - 1) / V_d
         gives B = (n_d - 1) / (V_d (1/lambda_F^2 - 1/lambda_C^2)),
     n(lambda_d) = n_d
         gives A = n_d - B / lambda_d^2. */
void lens_cauchy(const lens_surface *s, double *a, double *b_nm2)
{
    *a = s->ior;
    *b_nm2 = 0.0;
    if (s->abbe == 0.0)
        return;
    const double inv_f2 = 1.0 / (WAVELENGTH_F_NM * WAVELENGTH_F_NM);
    const double inv_c2 = 1.0 / (WAVELENGTH_C_NM * WAVELENGTH_C_NM);
    *b_nm2 = (s->ior - 1.0) / (s->abbe * (inv_f2 - inv_c2));
    *a = s->ior - *b_nm2 / (WAVELENGTH_D_NM * WAVELENGTH_D_NM);
}

/* As the lane tracer computes it (trace_lanes.h): A + B x with x = 1 / lambda^2. */
double lens_index_at(const lens_surface *s, double wavelength_nm)
{
    if (s->abbe == 0.0)
        return s->ior;
    double a, b;
    lens_cauchy(s, &a, &b);
    return a + b * lens_inverse_square(wavelength_nm);
}

void lens_at_wavelength(lens *l, double wavelength_nm)
{
    for (int i = 0; i < l->count; i++) {
        l->surface[i].ior = lens_index_at(&l->surface[i], wavelength_nm);
        l->surface[i].abbe = 0.0;
    }
}

int lens_has_abbe(const lens *l)
{
    for (int i = 0; i < l->count; i++)
        if (l->surface[i].abbe > 0.0)
            return 1;
    return 0;
}

/* A sphere of curvature c through the vertex, centre at vertex_z - 1/c, satisfies
   c (rho^2 + s^2) + 2 s = 0 for the axial offset s. The root on the vertex's cap is
   s = -c rho^2 / (1 + sqrt(1 - c^2 rho^2)): the textbook R - sqrt(R^2 - rho^2) loses every digit
   when R >> rho, this form none. For c > 0 the rim lies toward the film (s < 0). Returns NaN
   beyond |radius|, where the sphere has no point; validated apertures never get there. */
double lens_sag_mm(const lens_surface *s, double rho_mm)
{
    const double c = s->curvature_per_mm;
    if (c == 0.0)
        return 0.0;
    const double c_rho2 = c * rho_mm * rho_mm;
    double root = 1.0 - c * c_rho2;
    /* Defensive: at the rim of a hemisphere (aperture = 2|R|, allowed) rounding of 1/R must
       not turn the root negative and the sag into NaN. No such case is known. */
    if (root < 0.0 && fabs(rho_mm) <= fabs(s->radius_mm))
        root = 0.0;
    return -c_rho2 / (1.0 + sqrt(root));
}

/* Surface i's vertex stands thickness_i in front of surface i + 1's; at height rho their
   points are s_i(rho) and s_i+1(rho) from those vertices, so the glass or air between them is
   gap(rho) = thickness_i + s_i(rho) - s_i+1(rho) thick there. Since ds/drho =
   -c rho / sqrt(1 - c^2 rho^2) falls as c grows, gap' has the sign of c_i+1 - c_i at every
   height: the gap is least on the axis (thickness_i >= 0) or at the rim of the smaller
   aperture, and the rim alone need be checked. */
int lens_crossing(const lens *l, double *rho_mm, double *gap_mm)
{
    for (int i = 0; i + 1 < l->count; i++) {
        const lens_surface *a = &l->surface[i], *b = &l->surface[i + 1];
        const double rho = 0.5 * fmin(a->aperture_diameter_mm, b->aperture_diameter_mm);
        const double gap = a->thickness_mm + lens_sag_mm(a, rho) - lens_sag_mm(b, rho);
        if (gap < -1e-9 * (a->thickness_mm + rho)) {
            *rho_mm = rho;
            *gap_mm = gap;
            return i;
        }
    }
    return -1;
}

/* Edge k joins the corners at rotation + 2 pi k / N and rotation + 2 pi (k + 1) / N: its
   outward normal points halfway between them, at distance R cos(pi / N) from the centre. */
void lens_set_blades(lens *l, int count, double rotation_rad)
{
    lens_blades *b = &l->blades;
    memset(b, 0, sizeof *b);
    if (count < 3 || count > LENS_MAX_BLADES)
        return;
    b->count = count;
    b->apothem_ratio = cos(M_PI / count);
    for (int k = 0; k < count; k++) {
        const double angle = rotation_rad + (2 * k + 1) * M_PI / count;
        b->normal_x[k] = cos(angle);
        b->normal_y[k] = sin(angle);
    }
}

double lens_stop_reach_mm(const lens *l, double ux, double uy)
{
    const double a = lens_semi_aperture_mm(l, l->stop);
    const lens_blades *b = &l->blades;
    if (!b->count)
        return a;
    double far = -INFINITY;
    for (int k = 0; k < b->count; k++)
        far = fmax(far, b->normal_x[k] * ux + b->normal_y[k] * uy);
    return a * b->apothem_ratio / far;
}
