/* Thin shim over PETSc (KSP CG or GMRES; PCMG on a geometric hierarchy given
 * by the caller, or PCGAMG) for sprc's iterative back end
 * (src/sprc/fem/petsc.f90 is its only caller).
 *
 * The Fortran side passes a square matrix in 0-based CSR with PetscInt (int32)
 * indices, already padded to whole blocks of `dim` unknowns, and the
 * coordinates of each block's node, from which the rigid-body near-null space
 * is built. Every function returns a status mirroring sprc's stat_* codes and
 * writes a NUL-terminated message into the caller's buffer; nothing here
 * prints: PETSc's error handler is the one that only returns codes, and its
 * signal handler is off.
 *
 * Loading. PETSc (with Open MPI, hypre, MUMPS, ... and the Open MPI build of
 * HDF5) is loaded with dlopen when the iterative solver is first used, not
 * linked: a direct solve never pays its start-up (about 20 MB of resident
 * memory, and exit-time work), and the MPI build of HDF5 enters the process
 * only then, after the serial HDF5 that sprc uses has bound every H5 symbol.
 * The functions are called through pointers found by dlsym.
 *
 * Declarations. Debian's pkg-config file for PETSc carries no MPI flags and
 * fpm 0.12 has no per-file C flags, so this file does not include PETSc's or
 * MPI's headers in the build: the few declarations it needs are below, for
 * PETSc 3.18 as Debian builds it (32-bit PetscInt, double PetscScalar, Open
 * MPI). `make test` compiles this file once more with -DSPRC_PETSC_HEADERS
 * and PETSc's and MPI's own headers: every prototype below is then checked
 * for compatibility by the compiler and every constant by a static assert, so
 * a PETSc that differs fails the suite instead of the run.
 *
 * Not thread-safe: one solve at a time per process (PETSc's own rule).
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sprc_shim.h"
#include <math.h>
#include <dlfcn.h>

/* The constants used, with their PETSc 3.18 values. */
#define SPRC_PETSC_CONSTANTS(X)         \
    X(PETSC_DEFAULT, -2)                \
    X(KSP_NORM_PRECONDITIONED, 1)       \
    X(KSP_NORM_NATURAL, 3)              \
    X(KSP_CONVERGED_ITERATING, 0)       \
    X(KSP_CONVERGED_ATOL, 3)            \
    X(KSP_DIVERGED_ITS, -3)             \
    X(KSP_DIVERGED_NANORINF, -9)        \
    X(KSP_DIVERGED_INDEFINITE_PC, -8)   \
    X(KSP_DIVERGED_INDEFINITE_MAT, -10) \
    X(INSERT_VALUES, 1)                 \
    X(SCATTER_FORWARD, 0)               \
    X(PC_MG_GALERKIN_BOTH, 0)           \
    X(SOR_LOCAL_FORWARD_SWEEP, 4)       \
    X(SOR_LOCAL_BACKWARD_SWEEP, 8)      \
    X(PETSC_ERR_MEM, 55)

#ifdef SPRC_PETSC_HEADERS
#include <petscksp.h>
#undef MPI_Allreduce /* PETSc's logging wraps it in a macro; the prototype below is MPI's */
#define SPRC_CHECK_CONSTANT(name, value) _Static_assert((name) == (value), #name " differs in this PETSc");
SPRC_PETSC_CONSTANTS(SPRC_CHECK_CONSTANT)
_Static_assert(sizeof(PetscInt) == 4 && sizeof(PetscScalar) == 8 && sizeof(PetscReal) == 8,
               "this PETSc's scalar types differ from Debian's libpetsc-real-dev");
_Static_assert(NORM_2 == 1, "NORM_2 differs in this PETSc");
#else
typedef int PetscErrorCode;
typedef int PetscInt;
typedef double PetscScalar;
typedef double PetscReal;
typedef enum { PETSC_FALSE, PETSC_TRUE } PetscBool;
typedef enum { PETSC_ERROR_INITIAL, PETSC_ERROR_REPEAT, PETSC_ERROR_IN_CXX } PetscErrorType;
typedef enum { NORM_1 = 0, NORM_2 = 1 } NormType;
typedef int KSPNormType;
typedef int KSPConvergedReason;
typedef int PCMGGalerkinType;
typedef int MatSORType;
typedef struct ompi_communicator_t *MPI_Comm;
typedef struct ompi_datatype_t *MPI_Datatype;
typedef struct ompi_op_t *MPI_Op;
typedef struct _p_Mat *Mat;
typedef struct _p_Vec *Vec;
typedef struct _p_KSP *KSP;
typedef struct _p_PC *PC;
typedef struct _p_MatNullSpace *MatNullSpace;
typedef struct _p_PetscOptions *PetscOptions;
typedef struct _p_PetscSF *VecScatter;
typedef int InsertMode;
typedef int ScatterMode;
typedef const char *MatType;
typedef const char *KSPType;
typedef const char *PCType;
typedef const char *MatSolverType;
#define SPRC_DEFINE_CONSTANT(name, value) enum { name = (value) };
SPRC_PETSC_CONSTANTS(SPRC_DEFINE_CONSTANT)
#endif

/* Open MPI's MPI_COMM_SELF and MPI_COMM_WORLD (PETSc's PETSC_COMM_SELF and,
 * by default, PETSC_COMM_WORLD) are these objects. */
extern struct ompi_predefined_communicator_t ompi_mpi_comm_self;
extern struct ompi_predefined_communicator_t ompi_mpi_comm_world;
extern int MPI_Comm_rank(MPI_Comm, int *);
extern int MPI_Comm_size(MPI_Comm, int *);
extern int MPI_Allreduce(const void *, void *, int, MPI_Datatype, MPI_Op, MPI_Comm);
extern PetscErrorCode PetscFinalize(void);
extern PetscErrorCode PetscInitializeNoArguments(void);
extern PetscErrorCode PetscInitialized(PetscBool *);
extern PetscErrorCode PetscOptionsSetValue(PetscOptions, const char[], const char[]);
extern PetscErrorCode PetscReturnErrorHandler(MPI_Comm, int, const char *, const char *, PetscErrorCode,
                                              PetscErrorType, const char *, void *);
extern PetscErrorCode PetscPushErrorHandler(PetscErrorCode (*)(MPI_Comm, int, const char *, const char *,
                                                               PetscErrorCode, PetscErrorType, const char *, void *),
                                            void *);
extern PetscErrorCode PetscErrorMessage(int, const char *[], char **);
extern PetscErrorCode MatCreate(MPI_Comm, Mat *);
extern PetscErrorCode MatSetSizes(Mat, PetscInt, PetscInt, PetscInt, PetscInt);
extern PetscErrorCode MatSetType(Mat, MatType);
extern PetscErrorCode MatSetBlockSize(Mat, PetscInt);
extern PetscErrorCode MatCreateSeqAIJWithArrays(MPI_Comm, PetscInt, PetscInt, PetscInt[], PetscInt[], PetscScalar[],
                                                Mat *);
extern PetscErrorCode MatMPIAIJSetPreallocationCSR(Mat, const PetscInt[], const PetscInt[], const PetscScalar[]);
extern PetscErrorCode MatSetNearNullSpace(Mat, MatNullSpace);
extern PetscErrorCode MatDestroy(Mat *);
extern PetscErrorCode MatNullSpaceCreateRigidBody(Vec, MatNullSpace *);
extern PetscErrorCode MatNullSpaceDestroy(MatNullSpace *);
extern PetscErrorCode VecCreateSeq(MPI_Comm, PetscInt, Vec *);
extern PetscErrorCode VecCreateMPI(MPI_Comm, PetscInt, PetscInt, Vec *);
extern PetscErrorCode VecScatterCreateToAll(Vec, VecScatter *, Vec *);
extern PetscErrorCode VecScatterBegin(VecScatter, Vec, Vec, InsertMode, ScatterMode);
extern PetscErrorCode VecScatterEnd(VecScatter, Vec, Vec, InsertMode, ScatterMode);
extern PetscErrorCode VecScatterDestroy(VecScatter *);
extern PetscErrorCode VecSetBlockSize(Vec, PetscInt);
extern PetscErrorCode VecGetArray(Vec, PetscScalar **);
extern PetscErrorCode VecRestoreArray(Vec, PetscScalar **);
extern PetscErrorCode VecDot(Vec, Vec, PetscScalar *);
extern PetscErrorCode VecNorm(Vec, NormType, PetscReal *);
extern PetscErrorCode VecDuplicate(Vec, Vec *);
extern PetscErrorCode VecDestroy(Vec *);
extern PetscErrorCode KSPCreate(MPI_Comm, KSP *);
extern PetscErrorCode KSPSetOperators(KSP, Mat, Mat);
extern PetscErrorCode KSPSetType(KSP, KSPType);
extern PetscErrorCode KSPGetPC(KSP, PC *);
extern PetscErrorCode KSPSetNormType(KSP, KSPNormType);
extern PetscErrorCode KSPSetComputeSingularValues(KSP, PetscBool);
extern PetscErrorCode KSPSetFromOptions(KSP);
extern PetscErrorCode KSPSetUp(KSP);
extern PetscErrorCode KSPSetInitialGuessNonzero(KSP, PetscBool);
extern PetscErrorCode KSPSetTolerances(KSP, PetscReal, PetscReal, PetscReal, PetscInt);
extern PetscErrorCode KSPSetConvergenceTest(KSP, PetscErrorCode (*)(KSP, PetscInt, PetscReal, KSPConvergedReason *,
                                                                    void *),
                                            void *, PetscErrorCode (*)(void *));
extern PetscErrorCode KSPSolve(KSP, Vec, Vec);
extern PetscErrorCode KSPGetConvergedReason(KSP, KSPConvergedReason *);
extern PetscErrorCode KSPGetIterationNumber(KSP, PetscInt *);
extern PetscErrorCode KSPComputeExtremeSingularValues(KSP, PetscReal *, PetscReal *);
extern PetscErrorCode KSPDestroy(KSP *);
extern PetscErrorCode PCSetType(PC, PCType);
extern PetscErrorCode PCApply(PC, Vec, Vec);
extern PetscErrorCode KSPGetConvergedReasonString(KSP, const char **);
extern PetscErrorCode MatSeqAIJGetArray(Mat, PetscScalar *[]);
extern PetscErrorCode MatSeqAIJRestoreArray(Mat, PetscScalar *[]);
extern PetscErrorCode MatSeqAIJSetPreallocationCSR(Mat, const PetscInt[], const PetscInt[], const PetscScalar[]);
extern PetscErrorCode PCMGSetLevels(PC, PetscInt, MPI_Comm *);
extern PetscErrorCode PCMGSetGalerkin(PC, PCMGGalerkinType);
extern PetscErrorCode PCMGSetInterpolation(PC, PetscInt, Mat);
extern PetscErrorCode PCMGGetSmoother(PC, PetscInt, KSP *);
extern PetscErrorCode PCMGSetDistinctSmoothUp(PC);
extern PetscErrorCode PCMGGetSmootherUp(PC, PetscInt, KSP *);
extern PetscErrorCode PCMGGetSmootherDown(PC, PetscInt, KSP *);
extern PetscErrorCode PCSORSetSymmetric(PC, MatSORType);
extern PetscErrorCode KSPChebyshevEstEigSet(KSP, PetscReal, PetscReal, PetscReal, PetscReal);
extern PetscErrorCode PCRedundantGetKSP(PC, KSP *);
extern PetscErrorCode PCMGGetCoarseSolve(PC, KSP *);
extern PetscErrorCode PCFactorSetMatSolverType(PC, MatSolverType);

/* The soname of Debian's PETSc 3.18 (real scalars, 32-bit indices). */
#define SPRC_PETSC_LIBRARY "libpetsc_real.so.3.18"

#define SPRC_PETSC_FUNCTIONS(X)                                                                              \
    X(PetscInitializeNoArguments) X(PetscInitialized) X(PetscOptionsSetValue) X(PetscReturnErrorHandler)    \
    X(PetscPushErrorHandler) X(PetscErrorMessage) X(MatCreate) X(MatSetSizes) X(MatSetType)                 \
    X(MatSetBlockSize) X(MatCreateSeqAIJWithArrays) X(MatSetNearNullSpace) X(MatDestroy)                  \
    X(MatNullSpaceCreateRigidBody) X(MatNullSpaceDestroy) X(VecCreateSeq) X(VecSetBlockSize) X(VecGetArray)  \
    X(VecRestoreArray) X(VecDot) X(VecNorm) X(VecDuplicate) X(VecDestroy) X(KSPCreate) X(KSPSetOperators)    \
    X(KSPSetType) X(KSPGetPC) X(KSPSetNormType) X(KSPSetComputeSingularValues) X(KSPSetFromOptions)          \
    X(KSPSetUp) X(KSPSetInitialGuessNonzero) X(KSPSetTolerances) X(KSPSetConvergenceTest) X(KSPSolve) X(KSPGetConvergedReason)           \
    X(KSPGetIterationNumber) X(KSPComputeExtremeSingularValues) X(KSPDestroy) X(PCSetType) X(PCApply)       \
    X(KSPGetConvergedReasonString) X(MatMPIAIJSetPreallocationCSR) X(VecCreateMPI) X(VecScatterCreateToAll)   \
    X(VecScatterBegin) X(VecScatterEnd) X(VecScatterDestroy) X(MPI_Comm_rank) X(MPI_Comm_size) X(PetscFinalize)   \
    X(MPI_Allreduce) X(MatSeqAIJSetPreallocationCSR) X(PCMGSetLevels) X(PCMGSetGalerkin) X(PCMGSetInterpolation)   \
    X(PCMGGetSmoother) X(PCMGGetCoarseSolve) X(PCFactorSetMatSolverType)       \
    X(KSPChebyshevEstEigSet) X(PCRedundantGetKSP) X(PCMGSetDistinctSmoothUp) X(PCMGGetSmootherUp)               \
    X(PCMGGetSmootherDown) X(PCSORSetSymmetric) X(MatSeqAIJGetArray) X(MatSeqAIJRestoreArray)

/* One pointer per function, set by load_petsc; from here on every call of
 * such a function goes through its pointer. */
#define SPRC_DECLARE_POINTER(f) static __typeof__(f) *p_##f;
SPRC_PETSC_FUNCTIONS(SPRC_DECLARE_POINTER)
static struct ompi_predefined_communicator_t *p_comm_self, *p_comm_world;
static void *p_mpi_int, *p_op_min; /* Open MPI's MPI_INT and MPI_MIN */
#define PetscInitializeNoArguments (*p_PetscInitializeNoArguments)
#define PetscInitialized (*p_PetscInitialized)
#define PetscOptionsSetValue (*p_PetscOptionsSetValue)
#define PetscReturnErrorHandler (*p_PetscReturnErrorHandler)
#define PetscPushErrorHandler (*p_PetscPushErrorHandler)
#define PetscErrorMessage (*p_PetscErrorMessage)
#define MatCreate (*p_MatCreate)
#define MatSetSizes (*p_MatSetSizes)
#define MatSetType (*p_MatSetType)
#define MatSetBlockSize (*p_MatSetBlockSize)
#define MatCreateSeqAIJWithArrays (*p_MatCreateSeqAIJWithArrays)
#define MatSetNearNullSpace (*p_MatSetNearNullSpace)
#define MatDestroy (*p_MatDestroy)
#define MatNullSpaceCreateRigidBody (*p_MatNullSpaceCreateRigidBody)
#define MatNullSpaceDestroy (*p_MatNullSpaceDestroy)
#define VecCreateSeq (*p_VecCreateSeq)
#define VecSetBlockSize (*p_VecSetBlockSize)
#define VecGetArray (*p_VecGetArray)
#define VecRestoreArray (*p_VecRestoreArray)
#define VecDot (*p_VecDot)
#define VecNorm (*p_VecNorm)
#define VecDuplicate (*p_VecDuplicate)
#define VecDestroy (*p_VecDestroy)
#define KSPCreate (*p_KSPCreate)
#define KSPSetOperators (*p_KSPSetOperators)
#define KSPSetType (*p_KSPSetType)
#define KSPGetPC (*p_KSPGetPC)
#define KSPSetNormType (*p_KSPSetNormType)
#define KSPSetComputeSingularValues (*p_KSPSetComputeSingularValues)
#define KSPSetFromOptions (*p_KSPSetFromOptions)
#define KSPSetUp (*p_KSPSetUp)
#define KSPSetInitialGuessNonzero (*p_KSPSetInitialGuessNonzero)
#define KSPSetTolerances (*p_KSPSetTolerances)
#define KSPSetConvergenceTest (*p_KSPSetConvergenceTest)
#define KSPSolve (*p_KSPSolve)
#define KSPGetConvergedReason (*p_KSPGetConvergedReason)
#define KSPGetIterationNumber (*p_KSPGetIterationNumber)
#define KSPComputeExtremeSingularValues (*p_KSPComputeExtremeSingularValues)
#define KSPDestroy (*p_KSPDestroy)
#define PCSetType (*p_PCSetType)
#define PCApply (*p_PCApply)
#define KSPGetConvergedReasonString (*p_KSPGetConvergedReasonString)
#define MatMPIAIJSetPreallocationCSR (*p_MatMPIAIJSetPreallocationCSR)
#define VecCreateMPI (*p_VecCreateMPI)
#define VecScatterCreateToAll (*p_VecScatterCreateToAll)
#define VecScatterBegin (*p_VecScatterBegin)
#define VecScatterEnd (*p_VecScatterEnd)
#define VecScatterDestroy (*p_VecScatterDestroy)
#define MPI_Comm_rank (*p_MPI_Comm_rank)
#define MPI_Comm_size (*p_MPI_Comm_size)
#define PetscFinalize (*p_PetscFinalize)
#define MPI_Allreduce (*p_MPI_Allreduce)
#define MatSeqAIJSetPreallocationCSR (*p_MatSeqAIJSetPreallocationCSR)
#define PCMGSetLevels (*p_PCMGSetLevels)
#define PCMGSetGalerkin (*p_PCMGSetGalerkin)
#define PCMGSetInterpolation (*p_PCMGSetInterpolation)
#define PCMGGetSmoother (*p_PCMGGetSmoother)
#define PCMGSetDistinctSmoothUp (*p_PCMGSetDistinctSmoothUp)
#define PCMGGetSmootherUp (*p_PCMGGetSmootherUp)
#define PCMGGetSmootherDown (*p_PCMGGetSmootherDown)
#define PCSORSetSymmetric (*p_PCSORSetSymmetric)
#define MatSeqAIJGetArray (*p_MatSeqAIJGetArray)
#define MatSeqAIJRestoreArray (*p_MatSeqAIJRestoreArray)
#define KSPChebyshevEstEigSet (*p_KSPChebyshevEstEigSet)
#define PCRedundantGetKSP (*p_PCRedundantGetKSP)
#define PCMGGetCoarseSolve (*p_PCMGGetCoarseSolve)
#define PCFactorSetMatSolverType (*p_PCFactorSetMatSolverType)
#undef PETSC_COMM_SELF
#define PETSC_COMM_SELF ((MPI_Comm)(void *)p_comm_self)
#define SPRC_COMM_WORLD ((MPI_Comm)(void *)p_comm_world)


/* A PETSc error code as a status and a message naming the call that failed. */
static int petsc_failure(PetscErrorCode ierr, const char *call, char *msg, int64_t len)
{
    const char *text = NULL;
    if (PetscErrorMessage(ierr, &text, NULL) != 0 || text == NULL) text = "unknown error";
    return report(ierr == PETSC_ERR_MEM ? SPRC_NO_MEMORY : SPRC_INTERNAL, msg, len,
                  "PETSc %s failed: %s (error %d)", call, text, (int)ierr);
}

#define TRY(call)                                                  \
    do {                                                           \
        PetscErrorCode ierr_ = (call);                             \
        if (ierr_ != 0) return petsc_failure(ierr_, #call, msg, len); \
    } while (0)

/* dlopen PETSc and find every function (once per process). */
static int load_petsc(char *msg, int64_t len)
{
    static void *lib = NULL;
    void *h;
    if (lib != NULL) return SPRC_OK;
    h = dlopen(SPRC_PETSC_LIBRARY, RTLD_NOW | RTLD_GLOBAL);
    if (h == NULL)
        return report(SPRC_INTERNAL, msg, len, "PETSc: cannot load %s (%s); install libpetsc-real-dev "
                      "(tools/ensure-deps) or use solver = 'direct'", SPRC_PETSC_LIBRARY, dlerror());
#define SPRC_FIND(f)                                                                                          \
    if ((*(void **)&p_##f = dlsym(h, #f)) == NULL)                                                             \
        return report(SPRC_INTERNAL, msg, len, "PETSc: %s has no %s", SPRC_PETSC_LIBRARY, #f);
    SPRC_PETSC_FUNCTIONS(SPRC_FIND)
#undef SPRC_FIND
    p_comm_self = dlsym(h, "ompi_mpi_comm_self");
    p_comm_world = dlsym(h, "ompi_mpi_comm_world");
    p_mpi_int = dlsym(h, "ompi_mpi_int");
    p_op_min = dlsym(h, "ompi_mpi_op_min");
    if (p_comm_self == NULL || p_comm_world == NULL || p_mpi_int == NULL || p_op_min == NULL)
        return report(SPRC_INTERNAL, msg, len, "PETSc: %s is not built on Open MPI", SPRC_PETSC_LIBRARY);
    lib = h;
    return SPRC_OK;
}

/* The ranks of MPI_COMM_WORLD: 1 without mpirun (a singleton MPI).
 * `distributed`: solves are spread over the world's ranks; set by
 * sprc_petsc_ranks only, so a program that did not ask (a library caller
 * under mpirun) keeps one solve per process on PETSC_COMM_SELF. */
static int world_rank = 0, world_size = 1, distributed = 0;

static void finalize_at_exit(void) { PetscFinalize(); }

/* PetscFinalize (and so MPI_Finalize) at exit, once: Open MPI's mpirun
 * reports a rank that ends without MPI_Finalize as failed, also with one rank. */
static void finalize_when_done(void)
{
    static int registered = 0;
    if (!registered) atexit(finalize_at_exit);
    registered = 1;
}

/* PETSc (and MPI, as a singleton when not under mpirun) once per process. */
static int ensure_petsc(char *msg, int64_t len)
{
    PetscBool up = PETSC_FALSE;
    int status = load_petsc(msg, len);
    if (status != SPRC_OK) return status;
    TRY(PetscInitialized(&up));
    if (up) return SPRC_OK;
    /* before PetscInitialize: a library does not take over the signals */
    TRY(PetscOptionsSetValue(NULL, "-no_signal_handler", NULL));
    TRY(PetscInitializeNoArguments());
    TRY(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
    if (getenv("OMPI_COMM_WORLD_SIZE") != NULL) finalize_when_done();
    if (MPI_Comm_rank(SPRC_COMM_WORLD, &world_rank) != 0 || MPI_Comm_size(SPRC_COMM_WORLD, &world_size) != 0)
        return report(SPRC_INTERNAL, msg, len, "PETSc: MPI_Comm_rank or MPI_Comm_size failed");
    return SPRC_OK;
}

/* Load and start PETSc now (once per process), so that its start-up is not
 * timed as part of the first iterative solve (sprc_fem_petsc's start_petsc). */
int sprc_petsc_start(char *msg, int64_t len) { return ensure_petsc(msg, len); }

/* Start PETSc and MPI, give this process's rank and the number of ranks,
 * and distribute every later solve over them (sprc runs under `mpirun -n R`:
 * every rank runs the study and takes part in each solve). With several
 * ranks MPI is finalized at exit: Open MPI's mpirun reports a rank that ends
 * without MPI_Finalize as failed. */
int sprc_petsc_ranks(int *rank, int *size, char *msg, int64_t len)
{
    int status = ensure_petsc(msg, len);
    *rank = world_rank;
    *size = world_size;
    if (status == SPRC_OK && world_size > 1 && !distributed) {
        distributed = 1;
        finalize_when_done();
    }
    return status;
}

/* Every rank learns whether any failed, before a collective step (distributed
 * solves; a serial one returns `status`): a rank that did not fail gets
 * SPRC_INTERNAL naming the lowest failed rank and `what` it was doing, so no
 * rank enters a collective that a failed one will not. */
static int agree_status(int status, const char *what, char *msg, int64_t len)
{
    int mine, first = 0;
    if (!distributed) return status;
    mine = status != SPRC_OK ? world_rank : world_size;
    if (MPI_Allreduce(&mine, &first, 1, (MPI_Datatype)p_mpi_int, (MPI_Op)p_op_min, SPRC_COMM_WORLD) != 0)
        return status != SPRC_OK ? status : report(SPRC_INTERNAL, msg, len, "PETSc %s: MPI_Allreduce failed", what);
    if (status == SPRC_OK && first < world_size)
        return report(SPRC_INTERNAL, msg, len, "PETSc %s failed on rank %d (its message is on its standard error)",
                      what, first);
    return status;
}

/* A test hook, not reachable from a scene: SPRC_TEST_FAIL_SETUP_RANK=r in the
 * environment makes the setup fail on rank r alone, as a rank-local failure
 * (an allocation, a PETSc error on one rank) would, before the collective
 * steps: tools/test-driver checks that every rank then returns the error. */
static int injected_failure(char *msg, int64_t len)
{
    const char *r = getenv("SPRC_TEST_FAIL_SETUP_RANK");
    if (r == NULL || *r == '\0' || atoi(r) != world_rank) return SPRC_OK;
    return report(SPRC_INTERNAL, msg, len, "PETSc setup: failure injected on rank %d (SPRC_TEST_FAIL_SETUP_RANK)",
                  world_rank);
}

typedef struct {
    Mat a;
    KSP ksp;
    Vec b, x, w;
    Vec all;           /* the whole solution on every rank (distributed solves) */
    VecScatter gather; /* x -> all */
    MPI_Comm comm;     /* PETSC_COMM_SELF, or the world with several ranks */
    PetscInt lo, n_local; /* this rank's rows: lo .. lo + n_local - 1 */
    int symmetric;
    const char *pc_name; /* "GAMG" or "geometric multigrid" (messages) */
    int geometric;       /* 1: PCMG on the caller's hierarchy; 0: GAMG */
    double tau, bnorm; /* the solve's tolerance and size of b (energy_test) */
    double kappa;      /* condition estimate of B A (CG), 1 for GMRES */
    double bound;      /* the stopping quantity at the last iteration */
} sprc_petsc;

void sprc_petsc_free(void **handle)
{
    sprc_petsc *s = *handle;
    if (s == NULL) return;
    KSPDestroy(&s->ksp);
    MatDestroy(&s->a);
    VecDestroy(&s->b);
    VecDestroy(&s->x);
    VecDestroy(&s->w);
    VecDestroy(&s->all);
    VecScatterDestroy(&s->gather);
    free(s);
    *handle = NULL;
}

/* A vector of this rank's rows (block size dim). */
static int create_vector(sprc_petsc *s, PetscInt n, PetscInt dim, Vec *v, char *msg, int64_t len)
{
    if (distributed)
        TRY(VecCreateMPI(s->comm, s->n_local, n, v));
    else
        TRY(VecCreateSeq(PETSC_COMM_SELF, n, v));
    TRY(VecSetBlockSize(*v, dim));
    return SPRC_OK;
}

/* This rank's rows (the CSR arrays of sprc_petsc_setup: n_local rows,
 * global columns) as MATMPIAIJ, preallocated from their pattern (PETSc
 * copies them). */
static int set_rows(sprc_petsc *s, const PetscInt *rowptr, const PetscInt *col, const double *val, char *msg,
                    int64_t len)
{
    TRY(MatSetType(s->a, "mpiaij"));
    TRY(MatMPIAIJSetPreallocationCSR(s->a, rowptr, col, val));
    return SPRC_OK;
}

/* Matrix with block size `dim` and its rigid-body near-null space from the
 * node coordinates coords(dim, n/dim) of all n rows. On one rank the matrix
 * is the caller's CSR arrays themselves (columns ascending in each row). */
static int build_matrix(sprc_petsc *s, PetscInt n, PetscInt dim, const PetscInt *rowptr, const PetscInt *col,
                        const double *val, const double *coords, char *msg, int64_t len)
{
    Vec xyz = NULL;
    MatNullSpace nearnull = NULL;
    PetscScalar *p;
    int status;

    if (distributed) {
        TRY(MatCreate(s->comm, &s->a));
        TRY(MatSetSizes(s->a, s->n_local, s->n_local, n, n));
        TRY(MatSetBlockSize(s->a, dim));
        status = set_rows(s, rowptr, col, val, msg, len);
        if (status != SPRC_OK) return status;
    } else {
        /* the caller's arrays, not a copy (they live until sprc_petsc_free) */
        TRY(MatCreateSeqAIJWithArrays(PETSC_COMM_SELF, n, n, (PetscInt *)rowptr, (PetscInt *)col, (double *)val,
                                      &s->a));
        TRY(MatSetBlockSize(s->a, dim));
    }
    status = create_vector(s, n, dim, &xyz, msg, len);
    if (status != SPRC_OK) return status;
    TRY(VecGetArray(xyz, &p));
    memcpy(p, coords + s->lo, (size_t)s->n_local * sizeof(double));
    TRY(VecRestoreArray(xyz, &p));
    TRY(MatNullSpaceCreateRigidBody(xyz, &nearnull));
    TRY(MatSetNearNullSpace(s->a, nearnull));
    TRY(MatNullSpaceDestroy(&nearnull));
    TRY(VecDestroy(&xyz));
    return SPRC_OK;
}

/* The geometric multigrid hierarchy (sprc_fem_multigrid) of a one-rank
 * solve: `n_levels` prolongations, finest first; prolongation k maps the
 * n_coarse[k] unknowns of the next coarser level to the unknowns of its
 * finer level (n for k = 0, n_coarse[k - 1] after). Their 0-based CSR arrays
 * follow one another in rowptr (rows + 1 entries each, every level's from
 * 0), col and val. n_levels = 0: no hierarchy, GAMG builds its own. */
typedef struct {
    int32_t n_levels;
    const int32_t *n_coarse, *rowptr, *col;
    const double *val;
} sprc_petsc_levels;

/* One smoothing step on a PCMG level: Richardson on PETSc's SOR (omega =
 * 1, Gauss-Seidel) sweeping `sweep` (SOR_LOCAL_FORWARD_SWEEP or
 * SOR_LOCAL_BACKWARD_SWEEP); PETSc applies it as one MatSOR call, with no
 * separate residual. */
static int set_sweep(KSP smoother, MatSORType sweep, char *msg, int64_t len)
{
    PC pc;
    TRY(KSPSetType(smoother, "richardson"));
    TRY(KSPSetTolerances(smoother, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT, 1));
    TRY(KSPGetPC(smoother, &pc));
    TRY(PCSetType(pc, "sor"));
    TRY(PCSORSetSymmetric(pc, sweep));
    return SPRC_OK;
}

/* Smoothing on PCMG's levels 1 .. levels - 1. One rank: one forward
 * Gauss-Seidel sweep before the coarse correction and one backward sweep
 * after it. The backward sweep is the adjoint of the forward one (with A =
 * L + D + L^T their iteration matrices are I - (D + L)^-1 A and
 * I - (D + L^T)^-1 A), so the V-cycle is symmetric and, Gauss-Seidel
 * converging for SPD A, positive definite: CG's preconditioner. Each sweep
 * reads the matrix once; the two Chebyshev steps of symmetric sweeps used
 * before read it about six times per side and bought fewer iterations than
 * that costs (doc/benchmarks.md). On several ranks PETSc's SOR sweeps each
 * rank's rows alone (a block Jacobi of Gauss-Seidel sweeps), which need
 * not converge undamped: there two Chebyshev steps of symmetric sweeps on
 * the interval from PETSc's estimate of the largest eigenvalue (0.1 and 1.1
 * times it). PETSC_OPTIONS (-mg_levels_...) still applies. */
static int set_smoothers(PC pc, PetscInt levels, char *msg, int64_t len)
{
    PetscInt l;
    if (!distributed) TRY(PCMGSetDistinctSmoothUp(pc));
    for (l = 1; l < levels; ++l) {
        KSP smoother;
        PC sweep;
        int status;
        if (!distributed) {
            TRY(PCMGGetSmootherDown(pc, l, &smoother));
            status = set_sweep(smoother, SOR_LOCAL_FORWARD_SWEEP, msg, len);
            if (status != SPRC_OK) return status;
            TRY(PCMGGetSmootherUp(pc, l, &smoother));
            status = set_sweep(smoother, SOR_LOCAL_BACKWARD_SWEEP, msg, len);
            if (status != SPRC_OK) return status;
            continue;
        }
        TRY(PCMGGetSmoother(pc, l, &smoother));
        TRY(KSPSetType(smoother, "chebyshev"));
        TRY(KSPChebyshevEstEigSet(smoother, 0.0, 0.1, 0.0, 1.1));
        TRY(KSPGetPC(smoother, &sweep));
        TRY(PCSetType(sweep, "sor"));
    }
    return SPRC_OK;
}

void sprc_petsc_own_blocks(int64_t blocks, int64_t *first, int64_t *last);

/* A prolongation of a distributed solve (every rank is given all its rows:
 * 0-based CSR, `rows` + 1 row starts from 0, columns global): this rank's
 * rows are those of its fine blocks, its columns those of its coarse blocks
 * (sprc_petsc_own_blocks on each level's blocks, as the finest level's rows
 * of the matrix), as MATMPIAIJ (PETSc copies them). */
static int distributed_prolongation(PetscInt rows, PetscInt cols, PetscInt dim, const PetscInt *rowptr,
                                    const PetscInt *col, const double *val, Mat *p, char *msg, int64_t len)
{
    int64_t first, last, cfirst, clast;
    PetscInt *local, lo, n, i;
    PetscErrorCode ierr;

    sprc_petsc_own_blocks(rows / dim, &first, &last);
    sprc_petsc_own_blocks(cols / dim, &cfirst, &clast);
    lo = (PetscInt)(first * dim);
    n = (PetscInt)((last - first) * dim);
    local = malloc(((size_t)n + 1) * sizeof(*local));
    if (local == NULL) return report(SPRC_NO_MEMORY, msg, len, "PETSc setup: cannot allocate a prolongation's rows");
    for (i = 0; i <= n; ++i) local[i] = rowptr[lo + i] - rowptr[lo];
    ierr = MatCreate(SPRC_COMM_WORLD, p);
    if (!ierr) ierr = MatSetSizes(*p, n, (PetscInt)((clast - cfirst) * dim), rows, cols);
    if (!ierr) ierr = MatSetBlockSize(*p, dim);
    if (!ierr) ierr = MatSetType(*p, "mpiaij");
    if (!ierr) ierr = MatMPIAIJSetPreallocationCSR(*p, local, col + rowptr[lo], val + rowptr[lo]);
    free(local);
    if (ierr) return petsc_failure(ierr, "MatMPIAIJSetPreallocationCSR (prolongation)", msg, len);
    return SPRC_OK;
}

/* PCMG on the hierarchy `mg` with Galerkin coarse matrices P^T A P (PETSc
 * copies the prolongations). PCMG numbers its levels from the coarsest (0)
 * to the finest (levels - 1). On several ranks the prolongations are
 * distributed (`distributed_prolongation`), the Galerkin products and
 * MUMPS's coarse factor too. */
static int build_multigrid(PC pc, PetscInt n, PetscInt dim, const sprc_petsc_levels *mg, char *msg, int64_t len)
{
    PetscInt levels = mg->n_levels + 1, rows = n, k;
    const PetscInt *rowptr = mg->rowptr, *col = mg->col;
    const double *val = mg->val;
    TRY(PCSetType(pc, "mg"));
    TRY(PCMGSetLevels(pc, levels, NULL));
    TRY(PCMGSetGalerkin(pc, PC_MG_GALERKIN_BOTH));
    for (k = 0; k < mg->n_levels; ++k) {
        PetscInt cols = mg->n_coarse[k], nnz = rowptr[rows];
        Mat p;
        if (cols < 1 || cols > rows || cols % dim != 0 || nnz < rows)
            return report(SPRC_INVALID, msg, len, "PETSc setup: multigrid level %d maps %d unknowns to %d (%d entries)",
                          (int)k, (int)cols, (int)rows, (int)nnz);
        if (distributed) {
            int status = distributed_prolongation(rows, cols, dim, rowptr, col, val, &p, msg, len);
            if (status != SPRC_OK) return status;
        } else {
            TRY(MatCreate(PETSC_COMM_SELF, &p));
            TRY(MatSetSizes(p, rows, cols, rows, cols));
            TRY(MatSetBlockSize(p, dim));
            TRY(MatSetType(p, "seqaij"));
            TRY(MatSeqAIJSetPreallocationCSR(p, rowptr, col, val));
        }
        TRY(PCMGSetInterpolation(pc, levels - 1 - k, p));
        TRY(MatDestroy(&p));
        rowptr += rows + 1;
        col += nnz;
        val += nnz;
        rows = cols;
    }
    {
        /* The coarsest level by MUMPS's LU (PETSc's own by default): with the
         * contact nodes kept on every level (sprc_fem_multigrid) it holds the
         * whole contact surface, a 2D-like graph whose factor MUMPS builds
         * faster than PETSc's own LU. On several ranks every rank factors
         * the whole coarse matrix by MUMPS on its own (PCREDUNDANT): MUMPS
         * across ranks schedules its work by the ranks' load as it goes, so
         * its factor, and the solution, changed bits from run to run. */
        KSP coarse;
        PC lu;
        TRY(PCMGGetCoarseSolve(pc, &coarse));
        TRY(KSPGetPC(coarse, &lu));
        if (distributed) {
            TRY(PCSetType(lu, "redundant"));
            TRY(PCRedundantGetKSP(lu, &coarse));
            TRY(KSPGetPC(coarse, &lu));
        }
        TRY(PCSetType(lu, "lu"));
        TRY(PCFactorSetMatSolverType(lu, "mumps"));
    }
    return set_smoothers(pc, levels, msg, len);
}

/* CG (symmetric) or GMRES with geometric multigrid on the hierarchy `mg`,
 * or GAMG (no hierarchy); the hierarchy's
 * coarse matrices are built here (KSPSetUp). PETSc options given in
 * PETSC_OPTIONS are applied (-ksp_view and the like, for experiments). */
static int build_solver(sprc_petsc *s, PetscInt n, PetscInt dim, const sprc_petsc_levels *mg, char *msg, int64_t len)
{
    PC pc;
    TRY(KSPCreate(s->comm, &s->ksp));
    TRY(KSPSetOperators(s->ksp, s->a, s->a));
    TRY(KSPSetType(s->ksp, s->symmetric ? "cg" : "gmres"));
    TRY(KSPGetPC(s->ksp, &pc));
    if (mg != NULL && mg->n_levels > 0) {
        int status = build_multigrid(pc, n, dim, mg, msg, len);
        if (status != SPRC_OK) return status;
        s->pc_name = "geometric multigrid";
        s->geometric = 1;
    } else {
        TRY(PCSetType(pc, "gamg"));
        s->pc_name = "GAMG";
    }
    TRY(KSPSetNormType(s->ksp, s->symmetric ? KSP_NORM_NATURAL : KSP_NORM_PRECONDITIONED));
    TRY(KSPSetComputeSingularValues(s->ksp, s->symmetric ? PETSC_TRUE : PETSC_FALSE));
    TRY(KSPSetFromOptions(s->ksp));
    TRY(KSPSetUp(s->ksp));
    return SPRC_OK;
}

/* 1 when the solve uses the hierarchy passed to sprc_petsc_setup, 0 when GAMG. */
int sprc_petsc_multigrid(const void *handle)
{
    const sprc_petsc *s = handle;
    return s != NULL && s->geometric;
}

static int create_vectors(sprc_petsc *s, PetscInt n, PetscInt dim, char *msg, int64_t len)
{
    int status = create_vector(s, n, dim, &s->b, msg, len);
    if (status != SPRC_OK) return status;
    TRY(VecDuplicate(s->b, &s->x));
    TRY(VecDuplicate(s->b, &s->w));
    if (distributed) TRY(VecScatterCreateToAll(s->x, &s->gather, &s->all));
    return SPRC_OK;
}

/* This rank's blocks [first, last) of `blocks` (0-based): all of them unless
 * the solves are distributed; then contiguous ranges of nearly equal length
 * in rank order, blocks * r / R to blocks * (r + 1) / R, the split of the
 * masters by sprc_study_partition's `owned_rows` (a block is a master node). */
void sprc_petsc_own_blocks(int64_t blocks, int64_t *first, int64_t *last)
{
    int64_t rank = distributed ? world_rank : 0, size = distributed ? world_size : 1;
    *first = blocks * rank / size;
    *last = blocks * (rank + 1) / size;
}

/* This rank's rows: whole blocks (sprc_petsc_own_blocks). */
static void own_rows(sprc_petsc *s, PetscInt n, PetscInt dim)
{
    int64_t first, last;
    sprc_petsc_own_blocks(n / dim, &first, &last);
    s->comm = distributed ? SPRC_COMM_WORLD : PETSC_COMM_SELF;
    s->lo = (PetscInt)(first * dim);
    s->n_local = (PetscInt)((last - first) * dim);
}

/* Set up the solver of the order-n matrix given in 0-based CSR (rowptr,
 * col, val), blocks of `dim` unknowns at the node coordinates `coords` (all
 * n), preconditioned by multigrid on the hierarchy `mg` (may be NULL:
 * GAMG). Distributed solves: only this rank's rows (sprc_petsc_own_blocks),
 * rowptr of n_local + 1 values from 0 and the columns global; no rank holds
 * the whole matrix. `borrowed` is set to 1 when PETSc uses the arrays in
 * place (one rank): they must then stay as they are until sprc_petsc_free;
 * 0 when it copied them (several ranks). With several ranks every rank
 * returns an error when any failed (agree_status). */
int sprc_petsc_setup(void **handle, int64_t n, int dim, const int32_t *rowptr, const int32_t *col,
                     const double *val, const double *coords, const sprc_petsc_levels *mg, int symmetric,
                     int *borrowed, char *msg, int64_t len)
{
    sprc_petsc *s;
    int status;

    *handle = NULL;
    *borrowed = !distributed;
    status = ensure_petsc(msg, len);
    if (status == SPRC_OK && (n < 1 || n > INT32_MAX || (dim != 2 && dim != 3) || n % dim != 0))
        status = report(SPRC_INVALID, msg, len, "PETSc setup: order %lld with block size %d does not fit",
                        (long long)n, dim);
    s = status == SPRC_OK ? calloc(1, sizeof(*s)) : NULL;
    if (status == SPRC_OK && s == NULL) status = report(SPRC_NO_MEMORY, msg, len, "PETSc setup: cannot allocate a handle");
    if (status == SPRC_OK) {
        own_rows(s, (PetscInt)n, dim);
        if (rowptr[0] != 0 || rowptr[s->n_local] < 0)
            status = report(SPRC_INVALID, msg, len, "PETSc setup: the row starts of rows %d..%d do not begin at 0 "
                            "or overflow", (int)s->lo, (int)(s->lo + s->n_local - 1));
    }
    if (status == SPRC_OK) status = injected_failure(msg, len);
    status = agree_status(status, "setup", msg, len);
    if (status != SPRC_OK) {
        free(s);
        return status;
    }
    s->symmetric = symmetric;
    *handle = s;
    status = build_matrix(s, (PetscInt)n, dim, rowptr, col, val, coords, msg, len);
    if (status == SPRC_OK) status = build_solver(s, (PetscInt)n, dim, mg, msg, len);
    if (status == SPRC_OK) status = create_vectors(s, (PetscInt)n, dim, msg, len);
    status = agree_status(status, "setup", msg, len);
    if (status != SPRC_OK) sprc_petsc_free(handle);
    return status;
}

/* The values of a one-rank solver's matrix were changed in place (the
 * caller's arrays, sprc_petsc_setup's `borrowed`), its pattern kept: the
 * restore of PETSc's array marks the matrix changed (and drops SOR's cached
 * diagonal), and the set-up is redone for the same nonzero pattern, so
 * PCMG's Galerkin products and the coarse LU (MUMPS) redo only their
 * numeric phase. */
int sprc_petsc_update(void *handle, char *msg, int64_t len)
{
    sprc_petsc *s = handle;
    PetscScalar *values;
    if (s == NULL || distributed)
        return report(SPRC_INVALID, msg, len, "PETSc update: no one-rank solver was set up");
    TRY(MatSeqAIJGetArray(s->a, &values));
    TRY(MatSeqAIJRestoreArray(s->a, &values));
    TRY(KSPSetOperators(s->ksp, s->a, s->a));
    TRY(KSPSetUp(s->ksp));
    return SPRC_OK;
}

/* This rank's rows of the whole vector a into v. */
static int copy_in(sprc_petsc *s, Vec v, const double *a, char *msg, int64_t len)
{
    PetscScalar *p;
    TRY(VecGetArray(v, &p));
    memcpy(p, a + s->lo, (size_t)s->n_local * sizeof(double));
    TRY(VecRestoreArray(v, &p));
    return SPRC_OK;
}

/* The whole solution into a (n values), on every rank. */
static int copy_out(sprc_petsc *s, double *a, PetscInt n, char *msg, int64_t len)
{
    PetscScalar *p;
    Vec v = s->x;
    if (distributed) {
        TRY(VecScatterBegin(s->gather, s->x, s->all, INSERT_VALUES, SCATTER_FORWARD));
        TRY(VecScatterEnd(s->gather, s->x, s->all, INSERT_VALUES, SCATTER_FORWARD));
        v = s->all;
    }
    TRY(VecGetArray(v, &p));
    memcpy(a, p, (size_t)n * sizeof(double));
    TRY(VecRestoreArray(v, &p));
    return SPRC_OK;
}

/* The size of b the stopping test measures against: the natural norm
 * sqrt(b^T B b) for CG (B the multigrid preconditioner), ||B b||_2 for GMRES;
 * 0 when b = 0. A b != 0 of no positive size means the preconditioner is
 * not positive definite (CG; the caller may take GMRES) or gave NaN or Inf:
 * an error, never a zero solution. CG from x = 0 computes sqrt(b^T B b) as
 * its own first residual norm (r = b): then *bnorm is -1 and energy_test
 * takes that norm, which saves one multigrid cycle (a tenth of a solve). */
static int rhs_norm(sprc_petsc *s, int guess, double *bnorm, char *msg, int64_t len)
{
    PC pc;
    PetscScalar bb;
    PetscReal nrm, b2;
    *bnorm = 0.0;
    TRY(VecNorm(s->b, NORM_2, &b2));
    if (b2 == 0.0) return SPRC_OK;
    if (isinf(b2) || isnan(b2))
        return report(SPRC_INTERNAL, msg, len, "PETSc solve: the right-hand side is NaN or Inf");
    if (s->symmetric && !guess) {
        *bnorm = -1.0;
        return SPRC_OK;
    }
    TRY(KSPGetPC(s->ksp, &pc));
    TRY(PCApply(pc, s->b, s->w));
    if (s->symmetric) {
        TRY(VecDot(s->b, s->w, &bb));
        nrm = bb > 0.0 ? sqrt(bb) : bb;
    } else {
        TRY(VecNorm(s->w, NORM_2, &nrm));
    }
    if (isnan(nrm) || isinf(nrm) || isinf(b2))
        return report(SPRC_INTERNAL, msg, len, "PETSc solve: the preconditioned right-hand side is NaN or Inf "
                      "(||b||_2 = %.3e)", b2);
    if (!(nrm > 0.0))
        return report(s->symmetric ? SPRC_NOT_POSDEF : SPRC_INTERNAL, msg, len,
                      "PETSc solve: the preconditioner B is not positive definite (%s = %.3e for ||b||_2 = %.3e)",
                      s->symmetric ? "b^T B b" : "||B b||_2", nrm, b2);
    *bnorm = nrm;
    return SPRC_OK;
}

/* The stopping test (KSPSetConvergenceTest), run at every iteration. With e
 * the iteration error, r = A e and B the preconditioner,
 *   ||e||_A^2 = r^T A^-1 r <= r^T B r / lambda_min(BA),
 *   ||x_h||_A^2 = b^T A^-1 b >= b^T B b / lambda_max(BA),
 * so ||e||_A / ||x_h||_A <= sqrt(kappa(BA)) ||r||_B / ||b||_B =: bound. CG
 * works in the natural norm ||r||_B, and its Lanczos process estimates
 * kappa(BA) from its iterations (from inside: the extreme Ritz values
 * converge to the extreme eigenvalues first, long before ||r||_B reaches the
 * tolerance). The solve stops when bound <= tau. GMRES (unsymmetric A) has no
 * such bound: it stops at ||B r||_2 <= tau ||B b||_2. */
static PetscErrorCode energy_test(KSP ksp, PetscInt it, PetscReal rnorm, KSPConvergedReason *reason, void *ctx)
{
    sprc_petsc *s = ctx;
    PetscReal emax, emin;

    *reason = KSP_CONVERGED_ITERATING;
    if (isnan(rnorm) || isinf(rnorm)) {
        *reason = KSP_DIVERGED_NANORINF;
        return 0;
    }
    if (s->bnorm < 0.0) {
        /* from x = 0: CG's first norm is sqrt(b^T B b) (rhs_norm); b != 0 */
        if (!(rnorm > 0.0)) {
            *reason = KSP_DIVERGED_INDEFINITE_PC;
            return 0;
        }
        s->bnorm = rnorm;
    }
    if (s->symmetric && it > 0 && KSPComputeExtremeSingularValues(ksp, &emax, &emin) == 0 && emin > 0.0 &&
        emax >= emin)
        s->kappa = emax / emin;
    s->bound = rnorm / s->bnorm * sqrt(s->kappa);
    if (s->bound <= s->tau && (it > 0 || rnorm == 0.0)) *reason = KSP_CONVERGED_ATOL;
    return 0;
}

static int run_ksp(sprc_petsc *s, int max_it, int guess, char *msg, int64_t len)
{
    TRY(KSPSetInitialGuessNonzero(s->ksp, guess ? PETSC_TRUE : PETSC_FALSE));
    TRY(KSPSetTolerances(s->ksp, 0.0, 0.0, PETSC_DEFAULT, max_it));
    TRY(KSPSetConvergenceTest(s->ksp, energy_test, s, NULL));
    TRY(KSPSolve(s->ksp, s->b, s->x));
    return SPRC_OK;
}

static int ksp_outcome(sprc_petsc *s, int *iterations, char *msg, int64_t len)
{
    KSPConvergedReason reason;
    PetscInt n_it;
    const char *why = "unknown reason";
    TRY(KSPGetConvergedReason(s->ksp, &reason));
    TRY(KSPGetIterationNumber(s->ksp, &n_it));
    *iterations = (int)n_it;
    if (reason > 0) return SPRC_OK;
    TRY(KSPGetConvergedReasonString(s->ksp, &why));
    return report(reason == KSP_DIVERGED_INDEFINITE_PC || reason == KSP_DIVERGED_INDEFINITE_MAT ? SPRC_NOT_POSDEF
                                                                                                : SPRC_NOT_CONVERGED,
                  msg, len, "%s + %s stopped (%s) after %d iterations: relative residual bound %.3e, target %.3e",
                  s->symmetric ? "CG" : "GMRES", s->pc_name, why, *iterations, s->bound, s->tau);
}

/* Solve A x = b (b, x of order n) to the tolerance `tau` of energy_test in
 * at most `max_it` iterations, from x = 0, or from the x given when `guess`
 * is nonzero (the test's bound holds for any start: it measures the
 * residual reached against b). `iterations` gets the Krylov iterations and
 * `bound` the stopping quantity reached; a solve that ends otherwise is
 * SPRC_NOT_CONVERGED (SPRC_NOT_POSDEF when CG meets an indefinite system)
 * with the count and the bound in the message. */
int sprc_petsc_solve(void *handle, int64_t n, const double *b, double *x, int guess, double tau, int max_it,
                     int *iterations, double *bound, char *msg, int64_t len)
{
    sprc_petsc *s = handle;
    double bnorm = 0.0;
    int status;

    *iterations = 0;
    *bound = 0.0;
    if (s == NULL) return report(SPRC_INVALID, msg, len, "PETSc solve: no solver was set up");
    status = copy_in(s, s->b, b, msg, len);
    if (status == SPRC_OK) status = rhs_norm(s, guess, &bnorm, msg, len);
    if (status == SPRC_OK && guess) status = copy_in(s, s->x, x, msg, len);
    if (status != SPRC_OK) return status;
    if (bnorm == 0.0) {
        memset(x, 0, (size_t)n * sizeof(double));
        return SPRC_OK;
    }
    s->tau = tau;
    s->bnorm = bnorm;
    s->kappa = 1.0;
    s->bound = 1.0;
    status = run_ksp(s, max_it, guess, msg, len);
    if (status == SPRC_OK) status = ksp_outcome(s, iterations, msg, len);
    *bound = s->bound;
    /* the outcome is the same on every rank (PETSc's reductions); a failure of
     * this rank's own steps is made known before the gather of x */
    status = agree_status(status, "solve", msg, len);
    if (status != SPRC_OK) return status;
    return copy_out(s, x, (PetscInt)n, msg, len);
}
