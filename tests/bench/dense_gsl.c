/* dyadfmu benchmark: a dyad solved as a generic dense 6x6 system with GSL.
 *
 * The assembly, from d'Alembert equilibrium of the two links (the physics of
 * scripts/dyadfmu/reference.py; none of the core's closed forms):
 *
 * Each link g in {m, n} carries, at its centre of mass S_g, the known resultant
 * F_g of active load, weight and inertia force, and the known couple M_g of
 * active and inertia moment (both from dyad_link_resultant()). With
 * r_g = S_g - D_g = x_S i_g + y_S j_g, its moment about D_g is r_g x F_g + M_g.
 *
 * Each pair contributes two unknowns, in the order of reference.py:
 *   u[0..1] pair D_m,  u[2..3] pair D_n,  u[4..5] pair E.
 * A revolute pair's unknowns are the force components (R.x, R.y); a
 * translational pair's are its normal force N and reactive moment M, the force
 * being R = N j with j = k0 x i the normal of its guide (D_m: i_k, D_n: i_p,
 * E: i_m). R_mk acts on m at D_m, R_np on n at D_n, R_mn (and M_mn) on m at E,
 * and their opposites on n.
 *
 * Rows 0..2: link m, force x, force y, moment about D_m; rows 3..5: link n, the
 * same about D_n. With the arms of E, a_m = E - D_m = l_m i_m and
 * a_n = E - D_n = l_n i_n:
 *
 *   link m:  R_mk + R_mn + F_m = 0
 *            M_mk + a_m x R_mn + M_mn + r_m x F_m + M_m = 0
 *   link n:  R_np - R_mn + F_n = 0
 *            M_np - a_n x R_mn - M_mn + r_n x F_n + M_n = 0
 *
 * So A u = b with b = -(F_m.x, F_m.y, r_m x F_m + M_m, F_n.x, F_n.y, r_n x F_n + M_n),
 * and each unknown's column collects, for every link the pair acts on (sign s:
 * +1, or -1 for n at E; arm a from that link's D to the pair point):
 *   - a force unknown with unit force e:  s e.x, s e.y, s (a x e) in the link's
 *     three rows; for R, e = (1, 0) gives moment entry -s a.y, e = (0, 1) s a.x;
 *     for T, e = j;
 *   - a moment unknown:                   s in the link's moment row only.
 *
 * A is block-sparse (about half of its entries are zero, as the closed forms
 * exploit); here it is factorised as a general dense matrix on purpose: this is
 * the yardstick. A mixes force rows (N) and moment rows (N m), so its 2-norm
 * condition number depends on the length unit and is not the core's
 * scale-free conditioning; both vanish/blow up at the same singular positions.
 */
#include "dense_gsl.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_permutation.h>
#include <gsl/gsl_vector.h>

#include "dyadfmu/vec2.h"

struct dense_gsl {
    gsl_matrix* a;         /* A, overwritten by LU or by U of the SVD */
    gsl_vector* b;         /* right-hand side */
    gsl_vector* x;         /* the unknowns u */
    gsl_permutation* perm; /* LU row permutation */
    gsl_matrix* v;         /* SVD: V */
    gsl_vector* s;         /* SVD: singular values, descending */
    gsl_vector* work;      /* SVD work space */
};

dense_gsl* dense_gsl_alloc(void)
{
    dense_gsl* ws = calloc(1, sizeof *ws);
    if (ws == NULL) {
        return NULL;
    }
    gsl_set_error_handler_off();
    ws->a = gsl_matrix_alloc(DENSE_DIM, DENSE_DIM);
    ws->b = gsl_vector_alloc(DENSE_DIM);
    ws->x = gsl_vector_alloc(DENSE_DIM);
    ws->perm = gsl_permutation_alloc(DENSE_DIM);
    ws->v = gsl_matrix_alloc(DENSE_DIM, DENSE_DIM);
    ws->s = gsl_vector_alloc(DENSE_DIM);
    ws->work = gsl_vector_alloc(DENSE_DIM);
    if (ws->a == NULL || ws->b == NULL || ws->x == NULL || ws->perm == NULL || ws->v == NULL ||
        ws->s == NULL || ws->work == NULL) {
        dense_gsl_free(ws);
        return NULL;
    }
    return ws;
}

void dense_gsl_free(dense_gsl* ws)
{
    if (ws == NULL) {
        return;
    }
    if (ws->a != NULL)
        gsl_matrix_free(ws->a);
    if (ws->b != NULL)
        gsl_vector_free(ws->b);
    if (ws->x != NULL)
        gsl_vector_free(ws->x);
    if (ws->perm != NULL)
        gsl_permutation_free(ws->perm);
    if (ws->v != NULL)
        gsl_matrix_free(ws->v);
    if (ws->s != NULL)
        gsl_vector_free(ws->s);
    if (ws->work != NULL)
        gsl_vector_free(ws->work);
    free(ws);
}

/* Adds the columns of the pair whose unknowns start at column col, acting with
 * sign s on the link whose equations start at row row0, at arm a from its D.
 * j is the normal of the pair's guide (read for a translational pair only). */
static void add_pair(double* a, size_t tda, dyad_pair_kind kind, size_t col, size_t row0, double s,
                     dyad_vec2 arm, dyad_vec2 j)
{
    double* fx = a + row0 * tda;
    double* fy = fx + tda;
    double* mo = fy + tda;
    if (kind == DYAD_PAIR_REVOLUTE) {
        fx[col] += s; /* unit force (1, 0) */
        mo[col] += -s * arm.y;
        fy[col + 1] += s; /* unit force (0, 1) */
        mo[col + 1] += s * arm.x;
    } else {
        fx[col] += s * j.x; /* unit normal force j */
        fy[col] += s * j.y;
        mo[col] += s * dyad_cross(arm, j);
        mo[col + 1] += s; /* unit reactive moment */
    }
}

/* Known loads of one link: resultant force and its moment about D_g. */
static void known_loads(const dyad_link* link, dyad_vec2 gravity, dyad_vec2* force,
                        double* moment_about_d)
{
    const dyad_vec2 j = dyad_perp(link->dir);
    const dyad_vec2 r = dyad_combine(link->com.x, link->dir, link->com.y, j);
    double couple;
    dyad_link_resultant(link, gravity, force, &couple);
    *moment_about_d = couple + dyad_cross(r, *force);
}

void dense_assemble(dyad_type type, const dyad_input* in, double* a, size_t tda, double* b)
{
    const dyad_vec2 zero = dyad_vec2_make(0, 0);
    const dyad_vec2 arm_m = dyad_scale(in->m.length, in->m.dir); /* E - D_m */
    const dyad_vec2 arm_n = dyad_scale(in->n.length, in->n.dir); /* E - D_n */
    const dyad_pair_kind kind_e = dyad_pair_kind_of(type, DYAD_PAIR_E);
    const dyad_vec2 j_m = dyad_perp(in->m.dir);
    dyad_vec2 f_m, f_n;
    double mo_m, mo_n;
    size_t r, c;

    for (r = 0; r < DENSE_DIM; ++r) {
        for (c = 0; c < DENSE_DIM; ++c) {
            a[r * tda + c] = 0;
        }
    }
    add_pair(a, tda, dyad_pair_kind_of(type, DYAD_PAIR_DM), 0, 0, 1, zero, dyad_perp(in->guide_k));
    add_pair(a, tda, dyad_pair_kind_of(type, DYAD_PAIR_DN), 2, 3, 1, zero, dyad_perp(in->guide_p));
    add_pair(a, tda, kind_e, 4, 0, 1, arm_m, j_m);
    add_pair(a, tda, kind_e, 4, 3, -1, arm_n, j_m);

    known_loads(&in->m, in->gravity, &f_m, &mo_m);
    known_loads(&in->n, in->gravity, &f_n, &mo_n);
    b[0] = -f_m.x;
    b[1] = -f_m.y;
    b[2] = -mo_m;
    b[3] = -f_n.x;
    b[4] = -f_n.y;
    b[5] = -mo_n;
}

/* One pair's outputs from its two unknowns. */
static void unpack_pair(dyad_pair_kind kind, const double* u, dyad_vec2 guide, dyad_vec2* force,
                        double* normal, double* moment)
{
    if (kind == DYAD_PAIR_REVOLUTE) {
        *force = dyad_vec2_make(u[0], u[1]);
        *normal = 0;
        *moment = 0;
    } else {
        *force = dyad_scale(u[0], dyad_perp(guide));
        *normal = u[0];
        *moment = u[1];
    }
}

/* Fills *result from the unknowns, or with NaN reactions when u is NULL. */
static dyad_status finish(dyad_type type, const dyad_input* in, const double* u,
                          dyad_result* result)
{
    result->field = DYAD_FIELD_NONE;
    result->denominator = NAN;
    result->conditioning = NAN;
    result->amplification = NAN;
    if (u == NULL) {
        result->status = DYAD_STATUS_SINGULAR;
        result->r_mk = result->r_np = result->r_mn = dyad_vec2_make(NAN, NAN);
        result->n_mk = result->n_np = result->n_mn = NAN;
        result->m_mk = result->m_np = result->m_mn = NAN;
        return result->status;
    }
    result->status = DYAD_STATUS_OK;
    unpack_pair(dyad_pair_kind_of(type, DYAD_PAIR_DM), u, in->guide_k, &result->r_mk, &result->n_mk,
                &result->m_mk);
    unpack_pair(dyad_pair_kind_of(type, DYAD_PAIR_DN), u + 2, in->guide_p, &result->r_np,
                &result->n_np, &result->m_np);
    unpack_pair(dyad_pair_kind_of(type, DYAD_PAIR_E), u + 4, in->m.dir, &result->r_mn,
                &result->n_mn, &result->m_mn);
    return result->status;
}

dyad_status dense_gsl_solve_lu(dense_gsl* ws, dyad_type type, const dyad_input* input,
                               dyad_result* result)
{
    int signum;
    dense_assemble(type, input, ws->a->data, ws->a->tda, ws->b->data);
    /* With the error handler off, LU_solve returns GSL_EDOM for a zero pivot. */
    if (gsl_linalg_LU_decomp(ws->a, ws->perm, &signum) != GSL_SUCCESS ||
        gsl_linalg_LU_solve(ws->a, ws->perm, ws->b, ws->x) != GSL_SUCCESS) {
        return finish(type, input, NULL, result);
    }
    return finish(type, input, ws->x->data, result);
}

dyad_status dense_gsl_solve_svd(dense_gsl* ws, dyad_type type, const dyad_input* input,
                                dyad_result* result, double* cond2)
{
    double s_max, s_min;
    dense_assemble(type, input, ws->a->data, ws->a->tda, ws->b->data);
    if (gsl_linalg_SV_decomp(ws->a, ws->v, ws->s, ws->work) != GSL_SUCCESS) {
        *cond2 = NAN;
        return finish(type, input, NULL, result);
    }
    s_max = gsl_vector_get(ws->s, 0);
    s_min = gsl_vector_get(ws->s, DENSE_DIM - 1);
    *cond2 = s_max / s_min; /* +inf for an exactly singular A */
    /* SV_solve would silently drop zero singular values (a least-squares
     * answer); a rank-deficient A is reported singular instead, with the usual
     * numerical-rank tolerance. */
    if (!(s_min > DENSE_DIM * DBL_EPSILON * s_max) ||
        gsl_linalg_SV_solve(ws->a, ws->v, ws->s, ws->b, ws->x) != GSL_SUCCESS) {
        return finish(type, input, NULL, result);
    }
    return finish(type, input, ws->x->data, result);
}
