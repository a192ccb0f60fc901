#include "cli/values.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int value_bad(l2p_error *err, const char *opt, const char *want, const char *got)
{
    return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "%s: expected %s, got '%s'", opt, want, got);
}

bool value_double(const char *s, double *v)
{
    char *end;
    errno = 0;
    *v = strtod(s, &end);
    return end != s && *end == '\0' && errno == 0 && isfinite(*v);
}

bool value_int(const char *s, int *v)
{
    char *end;
    errno = 0;
    long x = strtol(s, &end, 10);
    if (end == s || *end != '\0' || errno || x < -2147483647L || x > 2147483647L)
        return false;
    *v = (int)x;
    return true;
}

bool value_vec3(const char *s, vec3 *v)
{
    char buf[256];
    size_t n = strlen(s);
    if (n >= sizeof buf || n == 0)
        return false;
    if (s[0] == '<' && s[n - 1] == '>') {
        memcpy(buf, s + 1, n - 2);
        buf[n - 2] = '\0';
    } else {
        memcpy(buf, s, n + 1);
    }
    double c[3];
    char *part = buf;
    for (int i = 0; i < 3; i++) {
        char *comma = strchr(part, ',');
        if ((i < 2) != (comma != NULL))
            return false;
        if (comma)
            *comma = '\0';
        while (*part == ' ')
            part++;
        if (!value_double(part, &c[i]))
            return false;
        part = comma ? comma + 1 : part;
    }
    *v = v3(c[0], c[1], c[2]);
    return true;
}

bool value_crop(const char *s, int crop[4])
{
    char buf[128];
    if (strlen(s) >= sizeof buf)
        return false;
    memcpy(buf, s, strlen(s) + 1);
    char *part = buf;
    for (int i = 0; i < 4; i++) {
        char *comma = strchr(part, ',');
        if ((i < 3) != (comma != NULL))
            return false;
        if (comma)
            *comma = '\0';
        if (!value_int(part, &crop[i]))
            return false;
        part = comma ? comma + 1 : part;
    }
    return crop[0] >= 0 && crop[1] >= 0 && crop[2] > crop[0] && crop[3] > crop[1];
}

int value_positive_int(const char *opt, const char *v, int *out, l2p_error *err)
{
    if (!value_int(v, out) || *out <= 0)
        return value_bad(err, opt, "a positive whole number, at most 2147483647", v);
    return L2P_OK;
}

int value_positive_double(const char *opt, const char *v, double *out, l2p_error *err)
{
    if (!value_double(v, out) || !(*out > 0.0))
        return value_bad(err, opt, "a positive number", v);
    return L2P_OK;
}

int value_int_up_to(const char *opt, const char *v, int most, int *out, l2p_error *err)
{
    if (!value_int(v, out) || *out <= 0 || *out > most) {
        char want[64];
        snprintf(want, sizeof want, "a whole number from 1 to %d", most);
        return value_bad(err, opt, want, v);
    }
    return L2P_OK;
}

int value_double_in(const char *opt, const char *v, double least, double most, double *out,
                     l2p_error *err)
{
    if (!value_double(v, out) || !(*out >= least && *out <= most)) {
        char want[96];
        snprintf(want, sizeof want, "a number from %g to %g", least, most);
        return value_bad(err, opt, want, v);
    }
    return L2P_OK;
}
