/* Field angles (fieldangle.h). */
#include "camera/fieldangle.h"

#include <math.h>
#include <string.h>

int field_angles_open(field_angles *f, const camera *c)
{
    memset(f, 0, sizeof *f);
    f->camera = c;
    f->thick = c->trace == TRACE_KIND_THICK;
    return f->thick ? L2P_OK : chief_lens_open(&f->chief, &c->lens);
}

void field_angles_close(field_angles *f)
{
    chief_lens_close(&f->chief);
}

bool field_angles_ray(const field_angles *f, double rho_mm, double *theta_rad)
{
    if (!f->thick)
        return chief_angle(&f->chief, rho_mm, theta_rad);
    ray r;
    double w;
    if (!camera_trace(f->camera, v3(rho_mm, 0, 0), 0.5, 0.5, &r, &w))
        return false;
    *theta_rad = atan2(hypot(r.d.x, r.d.y), r.d.z);
    return true;
}

double field_angles_half_deg(const field_angles *f, double rho_mm)
{
    const double rho = fmin(rho_mm, f->camera->pupil.reach_mm);
    double theta;
    if (!field_angles_ray(f, rho, &theta)) {
        if (!field_angles_ray(f, 0.0, &theta))
            return NAN;
        double in = 0.0, out = rho;
        for (int k = 0; k < 60; k++) {
            const double mid = 0.5 * (in + out);
            *(field_angles_ray(f, mid, &theta) ? &in : &out) = mid;
        }
        field_angles_ray(f, in, &theta);
    }
    return theta * 180.0 / M_PI;
}
