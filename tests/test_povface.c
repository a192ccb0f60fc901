/* The triangles that carry rays to mesh_camera: a ray alone, and two rays on a shared edge.
   POV-Ray's rule, checked here in double: origin = centroid, direction =
   normalize((P3 - P1) x (P2 - P1)). */
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include "raytable/povface.h"

/* The ray POV-Ray makes of the face (p, q, r). */
static void face_ray(vec3 p, vec3 q, vec3 r, vec3 *o, vec3 *d)
{
    *o = v3_scale(v3_add(v3_add(p, q), r), 1.0 / 3.0);
    *d = v3_normalize(v3_cross(v3_sub(r, p), v3_sub(q, p)));
}

/* A small deterministic generator (xorshift64*), uniform in [0, 1). */
static double uniform(uint64_t *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ull) >> 11) * 0x1p-53;
}

/* A ray leaving a lens of radius 10 near z = 0, within 60 degrees of the axis. */
static void lens_ray(uint64_t *s, vec3 *o, vec3 *d)
{
    const double r = 10 * sqrt(uniform(s)), a = 2 * M_PI * uniform(s);
    *o = v3(r * cos(a), r * sin(a), 2 * uniform(s) - 1);
    const double t = acos(1 - (1 - 0.5) * uniform(s)), b = 2 * M_PI * uniform(s);
    *d = v3(sin(t) * cos(b), sin(t) * sin(b), cos(t));
}

Test(povface, a_lone_triangle_carries_its_ray)
{
    uint64_t s = 1;
    for (int i = 0; i < 10000; i++) {
        vec3 o, d, v[3], fo, fd;
        lens_ray(&s, &o, &d);
        povface_single(o, d, 5.0, v);
        face_ray(v[0], v[1], v[2], &fo, &fd);
        cr_assert_lt(v3_length(v3_sub(fo, o)), 1e-13, "ray %d: centroid off", i);
        cr_assert_lt(v3_length(v3_sub(fd, d)), 1e-14, "ray %d: normal off", i);
    }
}

/* Pairs of neighbouring rays: when paired, each face's centroid and normal are its ray (to a
   few roundings of the reach; measured worst normal 1.0e-13, five orders below what float32
   vertices can hold), and the vertices keep within the limits the emitter relies on; most
   such pairs are taken. */
Test(povface, a_pair_carries_both_rays_exactly)
{
    uint64_t s = 7;
    int taken = 0;
    double worst = 0;
    const int pairs = 20000;
    for (int i = 0; i < pairs; i++) {
        vec3 o1, d1, o2, d2, v[4];
        lens_ray(&s, &o1, &d1);
        lens_ray(&s, &o2, &d2);
        /* Neighbours: the second ray within about 0.05 rad of the first. */
        d2 = v3_normalize(v3_madd(d1, v3_sub(d2, d1), 0.05));
        bool swap[2];
        if (!povface_pair(o1, d1, o2, d2, 5.0, v, swap))
            continue;
        taken++;
        double reach = 0;
        for (int k = 0; k < 4; k++)
            reach = fmax(reach, v3_length(v[k]));
        cr_assert_leq(reach, 128 * 5.0, "pair %d: a vertex %g from the origin", i, reach);
        for (int k = 0; k < 2; k++) {
            const vec3 p = swap[k] ? v[1] : v[0], q = swap[k] ? v[0] : v[1];
            vec3 fo, fd;
            face_ray(p, q, v[2 + k], &fo, &fd);
            const vec3 o = k ? o2 : o1, d = k ? d2 : d1;
            cr_assert_lt(v3_length(v3_sub(fo, o)), 1e-13 * reach, "pair %d face %d: centroid", i, k);
            worst = fmax(worst, v3_length(v3_sub(fd, d)));
            cr_assert_lt(v3_length(v3_sub(fd, d)), 1e-12, "pair %d face %d: normal %g off", i, k,
                         v3_length(v3_sub(fd, d)));
        }
    }
    cr_expect_gt(taken, pairs / 2, "only %d of %d neighbouring pairs share an edge", taken, pairs);
    cr_log_info("%d of %d pairs taken, worst normal %.3g", taken, pairs, worst);
}

Test(povface, pairs_that_float32_would_spoil_are_refused)
{
    vec3 v[4] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    bool swap[2];
    const vec3 z = v3(0, 0, 1);
    /* Parallel rays: their planes never meet, or are one plane. */
    cr_expect(!povface_pair(v3(1, 0, 0), z, v3(-1, 0, 0), z, 5.0, v, swap));
    cr_expect(!povface_pair(v3(1, 0, 0), z, v3(-1, 0, 3), z, 5.0, v, swap));
    /* Nearly parallel: the shared edge would lie some 1e6 away. */
    const vec3 tilted = v3_normalize(v3(1e-6, 0, 1));
    cr_expect(!povface_pair(v3(0, 0, 0), z, v3(0, 1, 1), tilted, 5.0, v, swap));
    /* The second origin on the first ray's plane and on the planes' line: the first face would
       have no height over the edge. */
    const vec3 d2 = v3_normalize(v3(1, 0, 1));
    cr_expect(!povface_pair(v3(0, 0, 0), z, v3(0, 0, 0), d2, 5.0, v, swap));
    /* Not a number anywhere: refused, nothing written. */
    cr_expect(!povface_pair(v3(NAN, 0, 0), z, v3(1, 0, 0), d2, 5.0, v, swap));
    cr_expect(!povface_pair(v3(0, 0, 0), v3(0, NAN, 1), v3(1, 0, 0), d2, 5.0, v, swap));
    for (int k = 0; k < 4; k++)
        cr_expect(v[k].x == 0 && v[k].y == 0 && v[k].z == 0, "a refused pair wrote vertex %d", k);
    /* Well apart: taken. */
    cr_expect(povface_pair(v3(1, 0, 0), z, v3(-1, 0, 0.5), d2, 5.0, v, swap));
}
