/* dyadfmu benchmark: a dyad solved as a generic dense 6x6 linear system with GSL,
 * the yardstick for the closed-form solvers of the core.
 *
 * Only for the double core: the system is assembled from the core's public API
 * (dyad_link_resultant, dyad_pair_kind_of) in double and solved in double.
 */
#ifndef DYADFMU_BENCH_DENSE_GSL_H
#define DYADFMU_BENCH_DENSE_GSL_H

#ifdef DYAD_REAL_FLOAT
#error "dense_gsl is built against the double core only"
#endif

#include <stddef.h>

#include "dyadfmu/dyad.h"

/** Number of equations and of unknowns of a dyad. */
#define DENSE_DIM 6

/** Workspace of the GSL solves: matrix, vectors, permutation and SVD work
 *  space, allocated once and reused by every solve. */
typedef struct dense_gsl dense_gsl;

/** Allocates a workspace (NULL when out of memory). Also switches GSL's error
 *  handler off for the whole process: the solves report failures through their
 *  status instead of aborting. */
dense_gsl* dense_gsl_alloc(void);

void dense_gsl_free(dense_gsl* ws);

/** Assembles A u = b of the dyad (see dense_gsl.c): A row-major with row stride
 *  tda (>= DENSE_DIM), b of DENSE_DIM entries. The input is not validated;
 *  directions are used as given (unit). */
void dense_assemble(dyad_type type, const dyad_input* input, double* a, size_t tda, double* b);

/** Solves by LU with partial pivoting (gsl_linalg_LU_decomp, _LU_solve) and maps
 *  the unknowns to *result as the core does: status DYAD_STATUS_OK, or
 *  DYAD_STATUS_SINGULAR (reactions NaN) when the factorisation meets a zero
 *  pivot. denominator, conditioning and amplification are NaN. */
dyad_status dense_gsl_solve_lu(dense_gsl* ws, dyad_type type, const dyad_input* input,
                               dyad_result* result);

/** Solves by SVD (gsl_linalg_SV_decomp, _SV_solve); *result as for the LU solve,
 *  DYAD_STATUS_SINGULAR when s_min <= 6 eps s_max (numerical rank below 6).
 *  *cond2 receives the 2-norm condition number s_max / s_min of A. */
dyad_status dense_gsl_solve_svd(dense_gsl* ws, dyad_type type, const dyad_input* input,
                                dyad_result* result, double* cond2);

#endif /* DYADFMU_BENCH_DENSE_GSL_H */
