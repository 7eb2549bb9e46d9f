/* sprc — C interface.
 *
 * Version 0.1.0 has no C entry points yet: the bind(C) API (error handles,
 * running a scene, recovery on a caller's mesh) arrives with the interfaces
 * work. Only the version macros are defined here, so nothing pretends.
 */
#ifndef SPRC_H
#define SPRC_H

#define SPRC_VERSION_MAJOR 0
#define SPRC_VERSION_MINOR 1
#define SPRC_VERSION_PATCH 0
/* 10000*major + 100*minor + patch, as sprc_get_version() will return */
#define SPRC_VERSION (10000 * SPRC_VERSION_MAJOR + 100 * SPRC_VERSION_MINOR + SPRC_VERSION_PATCH)

#endif /* SPRC_H */
