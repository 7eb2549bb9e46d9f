/* MPI collectives of a partitioned level (src/sprc/study/partition.f90 is the
 * only caller): this process's rank and the ranks' count, Allgatherv of
 * doubles and of ints over MPI_COMM_WORLD in rank order, and what a failed
 * run needs to end on every rank (sprc_mpi_fail_together, sprc_mpi_abort).
 *
 * Open MPI is not linked: it enters the process with PETSc (sprc_petsc.c's
 * dlopen, RTLD_GLOBAL, started by `sprc_petsc_ranks` under mpirun), and the
 * functions here are found in the libmpi already loaded (RTLD_NOLOAD), so a
 * serial run loads nothing. The declarations are Open MPI 4's (handles are
 * pointers to its predefined objects, found by dlsym like the functions).
 */
#include <dlfcn.h>
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <time.h>

#include "sprc_shim.h"

#define SPRC_MPI_LIBRARY "libmpi.so.40"

typedef void *handle_t;

static int (*p_allgatherv)(const void *, int, handle_t, void *, const int *, const int *, handle_t, handle_t);
static int (*p_comm_rank)(handle_t, int *);
static int (*p_comm_size)(handle_t, int *);
static int (*p_comm_dup)(handle_t, handle_t *);
static int (*p_ibarrier)(handle_t, handle_t *);
static int (*p_test)(handle_t *, int *, void *);
static int (*p_abort)(handle_t, int);
static handle_t p_world, p_double, p_int;
static void *lib = NULL;
/* A copy of MPI_COMM_WORLD for the failure barrier alone: ranks that wait in
 * a collective of the world's must not meet it there. */
static handle_t fail_comm = NULL;

/* The functions and handles of the Open MPI already in the process. */
static int load_mpi(char *msg, int64_t len)
{
    void *h;
    if (lib != NULL) return SPRC_OK;
    h = dlopen(SPRC_MPI_LIBRARY, RTLD_NOW | RTLD_NOLOAD);
    if (h == NULL) return report(SPRC_INTERNAL, msg, len, "MPI: %s is not loaded (the ranks were not started)",
                                 SPRC_MPI_LIBRARY);
    *(void **)&p_allgatherv = dlsym(h, "MPI_Allgatherv");
    *(void **)&p_comm_rank = dlsym(h, "MPI_Comm_rank");
    *(void **)&p_comm_size = dlsym(h, "MPI_Comm_size");
    *(void **)&p_comm_dup = dlsym(h, "MPI_Comm_dup");
    *(void **)&p_ibarrier = dlsym(h, "MPI_Ibarrier");
    *(void **)&p_test = dlsym(h, "MPI_Test");
    *(void **)&p_abort = dlsym(h, "MPI_Abort");
    p_world = dlsym(h, "ompi_mpi_comm_world");
    p_double = dlsym(h, "ompi_mpi_double");
    p_int = dlsym(h, "ompi_mpi_int");
    if (p_allgatherv == NULL || p_comm_rank == NULL || p_comm_size == NULL || p_comm_dup == NULL ||
        p_ibarrier == NULL || p_test == NULL || p_abort == NULL || p_world == NULL || p_double == NULL || p_int == NULL)
        return report(SPRC_INTERNAL, msg, len, "MPI: %s lacks a function or handle sprc needs", SPRC_MPI_LIBRARY);
    lib = h;
    return SPRC_OK;
}

int sprc_mpi_ranks(int *rank, int *size, char *msg, int64_t len)
{
    int status = load_mpi(msg, len);
    *rank = 0;
    *size = 1;
    if (status != SPRC_OK) return status;
    if (p_comm_rank(p_world, rank) != 0 || p_comm_size(p_world, size) != 0)
        return report(SPRC_INTERNAL, msg, len, "MPI: MPI_Comm_rank or MPI_Comm_size failed");
    if (*size > 1 && fail_comm == NULL && p_comm_dup(p_world, &fail_comm) != 0) {
        fail_comm = NULL;
        return report(SPRC_INTERNAL, msg, len, "MPI: MPI_Comm_dup failed");
    }
    return SPRC_OK;
}

/* 1 when every rank calls this within `seconds` (a failure they all know of:
 * sprc agrees on failures before each collective step), 0 when not (this
 * rank failed alone, while the others wait in a collective it will never
 * enter, or run on). 1 when there are no ranks. For the driver, which then
 * ends the run with sprc_mpi_abort. */
int sprc_mpi_fail_together(double seconds)
{
    handle_t request = NULL;
    int done = 0;
    struct timespec start, now, pause = {0, 10000000};
    if (lib == NULL || fail_comm == NULL) return 1;
    if (p_ibarrier(fail_comm, &request) != 0) return 0;
    clock_gettime(CLOCK_MONOTONIC, &start);
    for (;;) {
        if (p_test(&request, &done, NULL) != 0) return 0;
        if (done) return 1;
        clock_gettime(CLOCK_MONOTONIC, &now);
        if ((double)(now.tv_sec - start.tv_sec) + 1e-9 * (double)(now.tv_nsec - start.tv_nsec) > seconds) return 0;
        nanosleep(&pause, NULL);
    }
}

/* MPI_Abort of every rank with exit status `code`: for the driver only (a
 * library never ends the process), when a rank failed alone. */
void sprc_mpi_abort(int code)
{
    if (lib != NULL) p_abort(p_world, code);
}

/* recv = the ranks' send arrays concatenated in rank order; counts[r] values
 * from rank r (every rank passes the same counts). kind 0: doubles, 1: ints. */
static int gather(int kind, const void *send, int64_t count, void *recv, const int64_t *counts, int size, char *msg,
                  int64_t len)
{
    int *c, *d;
    int64_t off = 0;
    int status = load_mpi(msg, len);
    if (status != SPRC_OK) return status;
    c = malloc(2 * (size_t)size * sizeof(int));
    if (c == NULL) return report(SPRC_NO_MEMORY, msg, len, "MPI: cannot allocate the counts of %d ranks", size);
    d = c + size;
    for (int r = 0; r < size && status == SPRC_OK; ++r) {
        if (counts[r] < 0 || counts[r] > INT_MAX || off > INT_MAX)
            status = report(SPRC_INVALID, msg, len, "MPI: %lld values from rank %d (offset %lld) exceed MPI's int "
                            "counts", (long long)counts[r], r, (long long)off);
        c[r] = (int)counts[r];
        d[r] = (int)off;
        off += counts[r];
    }
    if (status == SPRC_OK && p_allgatherv(send, (int)count, kind == 0 ? p_double : p_int, recv, c, d,
                                          kind == 0 ? p_double : p_int, p_world) != 0)
        status = report(SPRC_INTERNAL, msg, len, "MPI: MPI_Allgatherv of %lld values failed", (long long)off);
    free(c);
    return status;
}

int sprc_mpi_gather_double(const double *send, int64_t count, double *recv, const int64_t *counts, int size,
                           char *msg, int64_t len)
{
    return gather(0, send, count, recv, counts, size, msg, len);
}

int sprc_mpi_gather_int(const int32_t *send, int64_t count, int32_t *recv, const int64_t *counts, int size, char *msg,
                        int64_t len)
{
    return gather(1, send, count, recv, counts, size, msg, len);
}
