/* The values of command-line options: numbers, vectors and crops, read whole (strtod and
   strtol, not sscanf: trailing text and out-of-range digits are refused, not undefined). */
#ifndef LENS2POV_VALUES_H
#define LENS2POV_VALUES_H

#include <stdbool.h>
#include "base/error.h"
#include "base/vec3.h"

/* A finite number and nothing else. */
bool value_double(const char *s, double *v);
/* A whole number that fits an int. */
bool value_int(const char *s, int *v);
/* "x,y,z" or "<x,y,z>", as in POV-Ray. */
bool value_vec3(const char *s, vec3 *v);
/* "X0,Y0,X1,Y1", four whole numbers with X1 > X0 >= 0 and Y1 > Y0 >= 0. */
bool value_crop(const char *s, int crop[4]);

/* L2P_BAD_INPUT: "OPT: expected WANT, got 'GOT'". */
int value_bad(l2p_error *err, const char *opt, const char *want, const char *got);

/* The same checks with that message: a positive whole number; a positive number; a whole
   number in [1, most]; a number in [least, most]. */
int value_positive_int(const char *opt, const char *v, int *out, l2p_error *err);
int value_positive_double(const char *opt, const char *v, double *out, l2p_error *err);
int value_int_up_to(const char *opt, const char *v, int most, int *out, l2p_error *err);
int value_double_in(const char *opt, const char *v, double least, double most, double *out,
                    l2p_error *err);

#endif
