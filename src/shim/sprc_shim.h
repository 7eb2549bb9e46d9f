/* What sprc's C shims share: the status codes and the message writer. */
#ifndef SPRC_SHIM_H
#define SPRC_SHIM_H

#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>

/* Mirror sprc_core_error: never renumber. */
enum {
    SPRC_OK = 0,
    SPRC_INVALID = 1,
    SPRC_SINGULAR = 2,
    SPRC_NOT_POSDEF = 3,
    SPRC_NOT_CONVERGED = 4,
    SPRC_NO_MEMORY = 6,
    SPRC_INTERNAL = 8
};

/* Write the printf-style message into msg (len bytes, NUL-terminated) and
 * return status. */
static inline int report(int status, char *msg, int64_t len, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

static inline int report(int status, char *msg, int64_t len, const char *fmt, ...)
{
    if (msg != NULL && len > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, (size_t)len, fmt, ap);
        va_end(ap);
    }
    return status;
}

#endif
