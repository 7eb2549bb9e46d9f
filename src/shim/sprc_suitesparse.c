/* Thin shim over CHOLMOD (supernodal Cholesky) and UMFPACK (LU) for sprc.
 *
 * The Fortran side (src/sprc/fem/cholmod.f90, umfpack.f90) passes a CSR
 * matrix exactly as sprc stores it: 1-based, int64 row pointers, int columns
 * strictly increasing within rows. Every function returns a status that
 * mirrors sprc's stat_* codes and writes a NUL-terminated message into the
 * caller's buffer; nothing here prints (CHOLMOD print level 0, no error
 * handler). Handles are opaque; sprc_*_free accepts and leaves a NULL handle.
 * 64-bit SuiteSparse interfaces (cholmod_l_*, umfpack_dl_*) throughout, so
 * factors beyond 2^31 nonzeros work.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sprc_shim.h"

#include <suitesparse/cholmod.h>
#include <suitesparse/umfpack.h>


_Static_assert(sizeof(SuiteSparse_long) == sizeof(int64_t), "SuiteSparse_long must be 64-bit");

/* ------------------------------------------------------- BLAS thread count
 *
 * OpenBLAS splits its level-2/3 work across threads in ways that change the
 * rounding: the same factorization run with 1 or 2 BLAS threads differs in
 * the last bits. sprc promises the same bits for any thread count, so every
 * factorization and solve runs its BLAS in one thread; sprc's own
 * parallelism is OpenMP over elements and patches. The OpenBLAS controls
 * are weak references: with another BLAS they are absent and nothing is done.
 */
extern int openblas_get_num_threads(void) __attribute__((weak));
extern void openblas_set_num_threads(int) __attribute__((weak));

int sprc_blas_get_threads(void)
{
    return openblas_get_num_threads ? openblas_get_num_threads() : 0;
}

void sprc_blas_set_threads(int n)
{
    if (openblas_set_num_threads && n > 0) openblas_set_num_threads(n);
}

static int blas_serial_begin(void)
{
    int n = sprc_blas_get_threads();
    if (n > 1) sprc_blas_set_threads(1);
    return n;
}

static void blas_serial_end(int n)
{
    if (n > 1) sprc_blas_set_threads(n);
}

/* ------------------------------------------------------------------ CHOLMOD */

typedef struct {
    cholmod_common c;
    cholmod_factor *L;
} sprc_cholmod;

int sprc_cholmod_new(void **handle, char *msg, int64_t len)
{
    sprc_cholmod *s = calloc(1, sizeof(*s));
    *handle = NULL;
    if (s == NULL) return report(SPRC_NO_MEMORY, msg, len, "CHOLMOD: cannot allocate a handle");
    cholmod_l_start(&s->c);
    s->c.print = 0;
    s->c.error_handler = NULL;
    s->c.supernodal = CHOLMOD_SUPERNODAL;
    *handle = s;
    return SPRC_OK;
}

void sprc_cholmod_free(void **handle)
{
    sprc_cholmod *s = *handle;
    if (s == NULL) return;
    if (s->L != NULL) cholmod_l_free_factor(&s->L, &s->c);
    cholmod_l_finish(&s->c);
    free(s);
    *handle = NULL;
}

static int cholmod_failure(const cholmod_common *c, char *msg, int64_t len, const char *what)
{
    if (c->status == CHOLMOD_OUT_OF_MEMORY)
        return report(SPRC_NO_MEMORY, msg, len, "CHOLMOD %s: out of memory", what);
    return report(SPRC_INTERNAL, msg, len, "CHOLMOD %s failed with status %d", what, c->status);
}

/* The fill-reducing ordering: AMD, and METIS as well when AMD's factorization
 * would cost at least METIS_MIN_FLOPS_PER_NZ flops per nonzero of tril(A),
 * keeping the ordering of fewer flops. METIS's analysis costs time in
 * proportion to nnz(A) (0.1-0.4 us per nonzero here), what it saves in
 * proportion to the factorization's flops: in 3D it cuts them 2.5-6 times
 * from 1.5e4 unknowns on (AMD: 2.2e4 flops per nonzero and more), in 2D by a
 * quarter of a factorization that is cheap anyway (Kirsch, 5.2e5 unknowns:
 * 5.6e3 flops per nonzero, METIS's analysis 1.8 s more for 0.3 s less
 * factorization). CHOLMOD's default tries METIS when AMD gives 500 flops
 * per nonzero of L, which sent such 2D systems to METIS at a loss. */
#define METIS_MIN_FLOPS_PER_NZ 1.5e4

static cholmod_factor *cholmod_analyze_amd_or_metis(cholmod_sparse *A, cholmod_common *c)
{
    cholmod_factor *amd, *metis;
    double amd_fl, amd_lnz;

    c->nmethods = 1;
    c->method[0].ordering = CHOLMOD_AMD;
    amd = cholmod_l_analyze(A, c);
    if (amd == NULL || c->fl < METIS_MIN_FLOPS_PER_NZ * c->anz) return amd;
    amd_fl = c->fl;
    amd_lnz = c->lnz;
    c->method[0].ordering = CHOLMOD_METIS;
    metis = cholmod_l_analyze(A, c);
    if (metis != NULL && c->fl < amd_fl) {
        cholmod_l_free_factor(&amd, c);
        return metis;
    }
    /* METIS gave more flops, or failed (out of memory): AMD's analysis stands */
    if (metis != NULL) cholmod_l_free_factor(&metis, c);
    c->status = CHOLMOD_OK;
    c->fl = amd_fl;
    c->lnz = amd_lnz;
    return amd;
}

/* The ordering of the current factor: 1 AMD, 2 METIS, 0 none (no factor). */
int sprc_cholmod_ordering(void *handle)
{
    sprc_cholmod *s = handle;
    if (s == NULL || s->L == NULL) return 0;
    return s->L->ordering == CHOLMOD_METIS ? 2 : 1;
}

/* Factor the SPD matrix whose lower triangle (columns j <= i of row i) the
 * CSR holds; the strict upper triangle is ignored. Read as compressed
 * columns, that lower triangle of rows is the upper triangle of columns
 * (stype = +1), CHOLMOD's preferred input, with no transpose. */
static int sprc_cholmod_factorize_serial(void *handle, int64_t n, const int64_t *rowptr, const int *col,
                           const double *val, int64_t *factor_nnz, int64_t *peak_bytes,
                           double *pivot_ratio, char *msg, int64_t len)
{
    sprc_cholmod *s = handle;
    cholmod_common *c = &s->c;
    cholmod_sparse *A;
    SuiteSparse_long *Ap, *Ai, *perm;
    double *Ax;
    int64_t i, p, nz = 0;

    if (s->L != NULL) cholmod_l_free_factor(&s->L, c);
    for (i = 0; i < n; i++)
        for (p = rowptr[i] - 1; p < rowptr[i + 1] - 1; p++)
            if (col[p] - 1 <= i) nz++;

    A = cholmod_l_allocate_sparse((size_t)n, (size_t)n, (size_t)nz, 1, 1, 1, CHOLMOD_REAL, c);
    if (A == NULL) return cholmod_failure(c, msg, len, "allocate");
    Ap = A->p;
    Ai = A->i;
    Ax = A->x;
    nz = 0;
    for (i = 0; i < n; i++) {
        Ap[i] = nz;
        for (p = rowptr[i] - 1; p < rowptr[i + 1] - 1; p++) {
            if (col[p] - 1 > i) break; /* columns are sorted */
            Ai[nz] = col[p] - 1;
            Ax[nz] = val[p];
            nz++;
        }
    }
    Ap[n] = nz;

    c->memory_usage = c->memory_inuse; /* peak of this factorization only */
    s->L = cholmod_analyze_amd_or_metis(A, c);
    if (s->L == NULL) {
        cholmod_l_free_sparse(&A, c);
        return cholmod_failure(c, msg, len, "analyze");
    }
    cholmod_l_factorize(A, s->L, c);
    cholmod_l_free_sparse(&A, c);
    *factor_nnz = (int64_t)c->lnz;
    *peak_bytes = (int64_t)c->memory_usage;

    if (c->status == CHOLMOD_NOT_POSDEF) {
        int64_t k = (int64_t)s->L->minor;
        perm = s->L->Perm;
        return report(SPRC_NOT_POSDEF, msg, len,
                      "CHOLMOD factorize: the matrix is not positive definite: pivot %lld of %lld "
                      "(matrix column %lld) is not positive: the matrix is indefinite, or singular up to rounding",
                      (long long)(k + 1), (long long)n, (long long)(perm[k] + 1));
    }
    if (c->status < CHOLMOD_OK) return cholmod_failure(c, msg, len, "factorize");
    /* (min diag L / max diag L)^2: the pivot ratio of A = L D L^T */
    *pivot_ratio = cholmod_l_rcond(s->L, c);
    return SPRC_OK;
}

static int sprc_cholmod_solve_serial(void *handle, int64_t n, int64_t nrhs, const double *b, double *x,
                       char *msg, int64_t len)
{
    sprc_cholmod *s = handle;
    cholmod_dense B, *X;

    if (s == NULL || s->L == NULL) return report(SPRC_INVALID, msg, len, "CHOLMOD solve: no factor");
    memset(&B, 0, sizeof(B));
    B.nrow = (size_t)n;
    B.ncol = (size_t)nrhs;
    B.nzmax = (size_t)(n * nrhs);
    B.d = (size_t)n;
    B.x = (void *)b; /* read only: cholmod_l_solve does not write B */
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    X = cholmod_l_solve(CHOLMOD_A, s->L, &B, &s->c);
    if (X == NULL) return cholmod_failure(&s->c, msg, len, "solve");
    memcpy(x, X->x, sizeof(double) * (size_t)(n * nrhs));
    cholmod_l_free_dense(&X, &s->c);
    return SPRC_OK;
}

/* ------------------------------------------------------------------ UMFPACK */

typedef struct {
    SuiteSparse_long n;
    SuiteSparse_long *Ap, *Ai; /* the CSR of A read as CSC: the matrix A^T */
    double *Ax;
    void *numeric;
    double control[UMFPACK_CONTROL];
    double info[UMFPACK_INFO];
} sprc_umfpack;

int sprc_umfpack_new(void **handle, char *msg, int64_t len)
{
    sprc_umfpack *s = calloc(1, sizeof(*s));
    *handle = NULL;
    if (s == NULL) return report(SPRC_NO_MEMORY, msg, len, "UMFPACK: cannot allocate a handle");
    umfpack_dl_defaults(s->control);
    s->control[UMFPACK_PRL] = 0;
    *handle = s;
    return SPRC_OK;
}

static void umfpack_release(sprc_umfpack *s)
{
    if (s->numeric != NULL) umfpack_dl_free_numeric(&s->numeric);
    free(s->Ap);
    free(s->Ai);
    free(s->Ax);
    s->Ap = s->Ai = NULL;
    s->Ax = NULL;
    s->n = 0;
}

void sprc_umfpack_free(void **handle)
{
    sprc_umfpack *s = *handle;
    if (s == NULL) return;
    umfpack_release(s);
    free(s);
    *handle = NULL;
}

static int umfpack_failure(SuiteSparse_long status, char *msg, int64_t len, const char *what)
{
    switch (status) {
    case UMFPACK_WARNING_singular_matrix:
        return report(SPRC_SINGULAR, msg, len, "UMFPACK %s: the matrix is singular (a zero pivot)", what);
    case UMFPACK_ERROR_out_of_memory:
        return report(SPRC_NO_MEMORY, msg, len, "UMFPACK %s: out of memory", what);
    default:
        return report(SPRC_INTERNAL, msg, len, "UMFPACK %s failed with status %ld", what, (long)status);
    }
}

/* The CSR is kept (0-based, 64-bit) because solves refine iteratively
 * against A. UMFPACK factors the column form, A^T; solve picks the system. */
static int sprc_umfpack_factorize_serial(void *handle, int64_t n, const int64_t *rowptr, const int *col,
                           const double *val, int64_t *factor_nnz, int64_t *peak_bytes,
                           double *pivot_ratio, char *msg, int64_t len)
{
    sprc_umfpack *s = handle;
    void *symbolic = NULL;
    int64_t i, p, nnz = rowptr[n] - 1;
    SuiteSparse_long status;

    umfpack_release(s);
    s->Ap = malloc(sizeof(SuiteSparse_long) * (size_t)(n + 1));
    s->Ai = malloc(sizeof(SuiteSparse_long) * (size_t)(nnz > 0 ? nnz : 1));
    s->Ax = malloc(sizeof(double) * (size_t)(nnz > 0 ? nnz : 1));
    if (s->Ap == NULL || s->Ai == NULL || s->Ax == NULL) {
        umfpack_release(s);
        return report(SPRC_NO_MEMORY, msg, len, "UMFPACK factorize: cannot copy the matrix");
    }
    for (i = 0; i <= n; i++) s->Ap[i] = rowptr[i] - 1;
    for (p = 0; p < nnz; p++) {
        s->Ai[p] = col[p] - 1;
        s->Ax[p] = val[p];
    }
    s->n = n;

    status = umfpack_dl_symbolic(n, n, s->Ap, s->Ai, s->Ax, &symbolic, s->control, s->info);
    if (status != UMFPACK_OK) {
        umfpack_release(s);
        return umfpack_failure(status, msg, len, "symbolic analysis");
    }
    status = umfpack_dl_numeric(s->Ap, s->Ai, s->Ax, symbolic, &s->numeric, s->control, s->info);
    umfpack_dl_free_symbolic(&symbolic);
    *factor_nnz = (int64_t)(s->info[UMFPACK_LNZ] + s->info[UMFPACK_UNZ]);
    *peak_bytes = (int64_t)(s->info[UMFPACK_PEAK_MEMORY] * s->info[UMFPACK_SIZE_OF_UNIT]) +
                  (int64_t)((sizeof(SuiteSparse_long) + sizeof(double)) * (size_t)nnz);
    *pivot_ratio = s->info[UMFPACK_RCOND];
    if (status != UMFPACK_OK) {
        umfpack_release(s);
        return umfpack_failure(status, msg, len, "factorize");
    }
    return SPRC_OK;
}

static int sprc_umfpack_solve_serial(void *handle, int64_t n, int64_t nrhs, int transposed, const double *b,
                       double *x, char *msg, int64_t len)
{
    sprc_umfpack *s = handle;
    /* The stored matrix is A^T, so A x = b is its transposed system. */
    int sys = transposed ? UMFPACK_A : UMFPACK_Aat;
    int64_t k;
    SuiteSparse_long status;

    if (s == NULL || s->numeric == NULL) return report(SPRC_INVALID, msg, len, "UMFPACK solve: no factor");
    for (k = 0; k < nrhs; k++) {
        status = umfpack_dl_solve(sys, s->Ap, s->Ai, s->Ax, x + k * n, b + k * n, s->numeric, s->control,
                                  s->info);
        if (status != UMFPACK_OK) return umfpack_failure(status, msg, len, "solve");
    }
    return SPRC_OK;
}

/* ------------------------------------------- entry points: BLAS in one thread */

int sprc_cholmod_factorize(void *handle, int64_t n, const int64_t *rowptr, const int *col,
                           const double *val, int64_t *factor_nnz, int64_t *peak_bytes,
                           double *pivot_ratio, char *msg, int64_t len)
{
    int saved = blas_serial_begin();
    int status = sprc_cholmod_factorize_serial(handle, n, rowptr, col, val, factor_nnz, peak_bytes,
                                               pivot_ratio, msg, len);
    blas_serial_end(saved);
    return status;
}

int sprc_cholmod_solve(void *handle, int64_t n, int64_t nrhs, const double *b, double *x,
                       char *msg, int64_t len)
{
    int saved = blas_serial_begin();
    int status = sprc_cholmod_solve_serial(handle, n, nrhs, b, x, msg, len);
    blas_serial_end(saved);
    return status;
}

int sprc_umfpack_factorize(void *handle, int64_t n, const int64_t *rowptr, const int *col,
                           const double *val, int64_t *factor_nnz, int64_t *peak_bytes,
                           double *pivot_ratio, char *msg, int64_t len)
{
    int saved = blas_serial_begin();
    int status = sprc_umfpack_factorize_serial(handle, n, rowptr, col, val, factor_nnz, peak_bytes,
                                               pivot_ratio, msg, len);
    blas_serial_end(saved);
    return status;
}

int sprc_umfpack_solve(void *handle, int64_t n, int64_t nrhs, int transposed, const double *b,
                       double *x, char *msg, int64_t len)
{
    int saved = blas_serial_begin();
    int status = sprc_umfpack_solve_serial(handle, n, nrhs, transposed, b, x, msg, len);
    blas_serial_end(saved);
    return status;
}
