/* Full simulation, surface by surface: intersections against closed forms, Snell's law,
   and the degenerate cases (flat and near-flat surfaces, the wrong hemisphere, tangent
   rays, total internal reflection, rays on the axis). */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "optics/lens.h"
#include "support.h"
#include "optics/trace.h"

static lens_surface sphere(double radius, double vertex_z)
{
    lens_surface s;
    memset(&s, 0, sizeof s);
    s.radius_mm = radius;
    s.curvature_per_mm = radius == 0.0 ? 0.0 : 1.0 / radius;
    s.vertex_z_mm = vertex_z;
    s.aperture_diameter_mm = 1e300;
    return s;
}

Test(trace, plane_is_hit_where_the_ray_meets_it)
{
    lens_surface s = sphere(0.0, 5.0);
    ray r = {v3(1, 2, 0), v3_normalize(v3(0.3, 0, 1))};
    vec3 n;
    cr_assert_eq(trace_intersect(&s, &r, &n), TRACE_PASSED);
    cr_assert_float_eq(r.o.z, 5.0, 1e-15);
    cr_assert_float_eq(r.o.x, 1.0 + 1.5, 1e-14);
    cr_assert(n.x == 0 && n.y == 0 && n.z == 1);
}

Test(trace, sphere_hit_matches_the_centre_form)
{
    /* Centre at vertex_z - R = -5; the cap near z = 5 at height 3 is z = -5 + sqrt(100 - 9). */
    lens_surface s = sphere(10.0, 5.0);
    ray r = {v3(0, 3, -20), v3(0, 0, 1)};
    vec3 n;
    cr_assert_eq(trace_intersect(&s, &r, &n), TRACE_PASSED);
    cr_assert_float_eq(r.o.z, -5.0 + sqrt(91.0), 1e-13);
    cr_assert_float_eq(v3_length(n), 1.0, 1e-15);
    cr_assert_float_eq(n.y, 0.3, 1e-15, "normal = (P - centre) / R");
}

Test(trace, near_flat_surfaces_keep_their_sag)
{
    /* sag = -rho^2 / (2R) to first order; the centre-form quadratic would lose all of it. */
    for (double R = 1e6; R <= 1e15; R *= 10) {
        lens_surface s = sphere(R, 5.0);
        ray r = {v3(0, 10, -1), v3(0, 0, 1)};
        vec3 n;
        cr_assert_eq(trace_intersect(&s, &r, &n), TRACE_PASSED);
        const double sag = r.o.z - 5.0, expect = -100.0 / (2.0 * R);
        cr_assert(fabs(sag - expect) <= 1e-15 + 1e-6 * fabs(expect), "R=%g sag=%g expect=%g", R, sag, expect);
        cr_assert_float_eq(n.y, 10.0 / R, 1e-12 / R);
    }
}

Test(trace, the_far_hemisphere_is_never_taken)
{
    /* R = 2: centre at -2, far cap near z = -4. A ray from behind crosses the far cap first;
       the lens surface is the cap at z = -2 + sqrt(4 - 0.25). */
    lens_surface s = sphere(2.0, 0.0);
    ray r = {v3(0, 0.5, -10), v3(0, 0, 1)};
    vec3 n;
    cr_assert_eq(trace_intersect(&s, &r, &n), TRACE_PASSED);
    cr_assert_float_eq(r.o.z, -2.0 + sqrt(3.75), 1e-14);
    /* The same for a concave surface (R < 0) met from the scene side. */
    lens_surface c = sphere(-2.0, 0.0);
    ray q = {v3(0, 0.5, 10), v3(0, 0, -1)};
    cr_assert_eq(trace_intersect(&c, &q, &n), TRACE_PASSED);
    cr_assert_float_eq(q.o.z, 2.0 - sqrt(3.75), 1e-14);
}

Test(trace, rays_that_miss_or_graze)
{
    lens_surface s = sphere(2.0, 0.0);
    vec3 n;
    ray miss = {v3(0, 2.5, -10), v3(0, 0, 1)};
    cr_assert_eq(trace_intersect(&s, &miss, &n), TRACE_MISSED);
    /* Tangent at the rim of a full hemisphere: a double root, counted as a miss or met at the
       rim, but never a non-finite number. */
    ray tangent = {v3(0, 2.0, -10), v3(0, 0, 1)};
    trace_status st = trace_intersect(&s, &tangent, &n);
    cr_assert(st == TRACE_MISSED || (st == TRACE_PASSED && v3_isfinite(tangent.o) && v3_isfinite(n)));
    /* A ray behind the surface going away from it. */
    ray away = {v3(0, 0, 1), v3(0, 0, 1)};
    cr_assert_eq(trace_intersect(&s, &away, &n), TRACE_MISSED);
    /* A ray parallel to a plane. */
    lens_surface p = sphere(0.0, 1.0);
    ray parallel = {v3(0, 0, 0), v3(1, 0, 0)};
    cr_assert_eq(trace_intersect(&p, &parallel, &n), TRACE_MISSED);
}

Test(trace, refraction_obeys_snell)
{
    const vec3 n = v3(0, 0, 1);
    for (double deg = 0; deg < 89.5; deg += 7.3) {
        const double a = deg * M_PI / 180.0;
        vec3 d = v3(sin(a), 0, -cos(a));
        cr_assert_eq(trace_refract(n, 1.0, 1.7, &d), TRACE_PASSED);
        cr_assert_float_eq(v3_length(d), 1.0, 1e-15);
        cr_assert_float_eq(1.7 * d.x, sin(a), 1e-15, "n1 sin i = n2 sin t at %g deg", deg);
        cr_assert(d.z < 0, "the ray goes on through the surface");
        vec3 e = v3(sin(a), 0, -cos(a));
        cr_assert_eq(trace_refract(v3(0, 0, -1), 1.0, 1.7, &e), TRACE_PASSED, "either normal");
        cr_assert_float_eq(e.x, d.x, 1e-15);
    }
}

Test(trace, total_internal_reflection_blocks)
{
    /* Glass 1.5 to air: critical angle asin(1/1.5) = 41.81 degrees. */
    const double critical = asin(1.0 / 1.5);
    vec3 below = v3(sin(critical - 1e-6), 0, cos(critical - 1e-6));
    vec3 above = v3(sin(critical + 1e-6), 0, cos(critical + 1e-6));
    cr_assert_eq(trace_refract(v3(0, 0, 1), 1.5, 1.0, &below), TRACE_PASSED);
    cr_assert(below.x > 0.999 && below.x <= 1.0, "near grazing just below the critical angle");
    cr_assert_eq(trace_refract(v3(0, 0, 1), 1.5, 1.0, &above), TRACE_TIR);
}

Test(trace, rays_on_the_axis_stay_on_it)
{
    lens l;
    l2p_error err;
    cr_assert_eq(lens_read(LENS_DIR "dgauss.50mm.dat", &l, &err), 0, "%s", err.text);
    lens_set_film_distance(&l, 36.77);
    ray r = {v3(0, 0, 0), v3(0, 0, 1)};
    cr_assert_eq(trace_toward_scene(&l, 0, l.count - 1, &r, NULL), TRACE_PASSED);
    cr_assert(r.o.x == 0 && r.o.y == 0 && r.d.x == 0 && r.d.y == 0 && r.d.z == 1);
    cr_assert_float_eq(r.o.z, l.surface[0].vertex_z_mm, 1e-12);
    lens_free(&l);
}

Test(trace, apertures_clip)
{
    lens l;
    l2p_error err;
    cr_assert_eq(lens_read(LENS_DIR "dgauss.50mm.dat", &l, &err), 0, "%s", err.text);
    lens_set_film_distance(&l, 36.77);
    l.stop_diameter_mm = 1.0;
    int at = -1;
    ray r = {v3(0, 0, 0), v3_normalize(v3(0, 0.2, 1))};
    cr_assert_eq(trace_toward_scene(&l, 0, l.count - 1, &r, &at), TRACE_CLIPPED);
    cr_assert_eq(at, l.stop, "the small stop blocks it, not a lens element");
    ray behind = {v3(0, 0, 0), v3_normalize(v3(0, 0.2, 1))};
    cr_assert_eq(trace_toward_scene(&l, l.stop + 1, l.count - 1, &behind, NULL), TRACE_PASSED);
    cr_assert(r.o.x == behind.o.x && r.o.y == behind.o.y && r.o.z == behind.o.z,
              "a blocked ray stays on the last surface it crossed");
    lens_free(&l);
}

/* The batch tracer (trace_batch.c, vector code) and the one-ray kernel make the same
   operations in the same order: the same status and bit-identical rays, for every lens and
   batch sizes around the lane counts (8, 16, 32). Rays that come in blocked (every fifth, and
   a whole step of 32 in the full batch) hold NaN and must stay blocked, untouched. */
#include "optics/trace_batch.h"

/* Returns the rays that passed; *traced counts those traced. */
static int check_batch(const lens *l, const char *name, int n, int *traced)
{
    trace_batch b;
    ray single[TRACE_BATCH_MAX];
    bool blocked[TRACE_BATCH_MAX];
    unsigned seed = 12345;
    for (int k = 0; k < n; k++) {
        seed = seed * 1103515245u + 12345u;
        const double fx = ((seed >> 8) % 1000) / 1000.0 - 0.5, fy = ((seed >> 18) % 1000) / 1000.0 - 0.5;
        const vec3 o = v3(20 * fx, 15 * fy, 0);
        const vec3 target = v3(10 * fy, 10 * fx, l->surface[l->count - 1].vertex_z_mm);
        single[k] = (ray){o, v3_normalize(v3_sub(target, o))};
        blocked[k] = k % 5 == 3 || (n == TRACE_BATCH_MAX && k >= 32);
        const ray r = blocked[k] ? (ray){v3(NAN, NAN, NAN), v3(NAN, NAN, NAN)} : single[k];
        b.ox[k] = r.o.x; b.oy[k] = r.o.y; b.oz[k] = r.o.z;
        b.dx[k] = r.d.x; b.dy[k] = r.d.y; b.dz[k] = r.d.z;
        b.status[k] = blocked[k] ? TRACE_MISSED : TRACE_PASSED;
    }
    trace_batch_toward_scene(l, &b, n);
    int passed = 0;
    for (int k = 0; k < n; k++) {
        if (blocked[k]) {
            cr_assert_eq(b.status[k], TRACE_MISSED, "%s, %s n %d ray %d: came in blocked",
                         trace_batch_isa(), name, n, k);
            continue;
        }
        (*traced)++;
        const trace_status st = trace_toward_scene(l, 0, l->count - 1, &single[k], NULL);
        cr_assert_eq(b.status[k], st, "%s, %s n %d ray %d: status %lld against %d",
                     trace_batch_isa(), name, n, k, b.status[k], st);
        if (st != TRACE_PASSED) {
            /* Left on the last surface crossed by both (only passing rays are renormalized). */
            const double got_o[3] = {b.ox[k], b.oy[k], b.oz[k]};
            const double want_o[3] = {single[k].o.x, single[k].o.y, single[k].o.z};
            cr_assert(memcmp(got_o, want_o, sizeof got_o) == 0, "%s, %s n %d blocked ray %d differs",
                      trace_batch_isa(), name, n, k);
            continue;
        }
        passed++;
        const double got[6] = {b.ox[k], b.oy[k], b.oz[k], b.dx[k], b.dy[k], b.dz[k]};
        const double want[6] = {single[k].o.x, single[k].o.y, single[k].o.z,
                                single[k].d.x, single[k].d.y, single[k].d.z};
        cr_assert(memcmp(got, want, sizeof got) == 0, "%s, %s n %d ray %d differs",
                  trace_batch_isa(), name, n, k);
    }
    return passed;
}

static void check_batch_against_kernel(void)
{
    const char *names[] = {"dgauss.50mm", "wide.22mm", "fisheye.10mm", "telephoto.250mm"};
    const double film[] = {36.77, 14.54, 23.192, 123.7439};
    const int sizes[] = {1, 7, 31, 33, 61, TRACE_BATCH_MAX};
    for (int li = 0; li < 4; li++) {
        char path[512];
        snprintf(path, sizeof path, LENS_DIR "%s.dat", names[li]);
        lens l;
        l2p_error err;
        cr_assert_eq(lens_read(path, &l, &err), 0, "%s", err.text);
        lens_set_film_distance(&l, film[li]);
        int passed = 0, traced = 0;
        for (int si = 0; si < 6; si++)
            passed += check_batch(&l, names[li], sizes[si], &traced);
        cr_assert(passed > 0 && passed < traced, "%s: %d of %d pass; both kinds must be covered",
                  names[li], passed, traced);
        lens_free(&l);
    }
}

/* Each instruction set this processor has (the best is the default). */
Test(trace, batch_and_single_ray_agree_bit_for_bit)
{
    const char *best = trace_batch_isa(), *isas[] = {"avx512", "avx2", "sse2", "scalar"};
    for (int i = 0; i < 4; i++) {
        if (trace_batch_use_isa(isas[i]) != 0) {
            cr_log_info("this processor has no %s: its lanes are not checked here", isas[i]);
            continue;
        }
        cr_assert_str_eq(trace_batch_isa(), isas[i]);
        check_batch_against_kernel();
    }
    cr_assert_eq(trace_batch_use_isa("scalar"), 0, "the one-ray kernel is always there");
    cr_assert_eq(trace_batch_use_isa("avx1024"), -1, "an unknown name is refused");
    cr_assert_eq(trace_batch_use_isa(best), 0);
}
