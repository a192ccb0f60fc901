/* Errors carried up to main: an exit status and one line of text. */
#ifndef LENS2POV_ERROR_H
#define LENS2POV_ERROR_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Exit statuses of the contract: 2 bad usage or bad input, 1 anything else. */
enum { L2P_OK = 0, L2P_FAILED = 1, L2P_BAD_INPUT = 2 };

typedef struct l2p_error {
    int status;
    char text[1024];
} l2p_error;

/* Sets the error as "FILE:LINE: message" (FILE and LINE left out when NULL or 0) and returns
   status, so that callers can write `return l2p_fail(err, ...)`. */
int l2p_fail(l2p_error *err, int status, const char *file, int line, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));

#ifdef __cplusplus
}
#endif

#endif
