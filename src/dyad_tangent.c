/* dyadfmu: directional derivatives of the reactions, exact, for every type.
 *
 * The reactions u of a dyad solve its six equilibrium equations E(x, u) = 0:
 * for each link g, the forces on it and their moments about D_g. For fixed
 * geometry these are linear in u and in the links' loads, and the solvers are
 * exactly the map from loads (F_g at D_g, moment M_g about D_g) to u. Along an
 * input direction dx,
 *
 *      dE/dx dx + dE/du du = 0,
 *
 * so du is the solution of the same dyad (same directions, lengths and guides)
 * under the loads dE/dx dx: the change of the equilibrium sums when the inputs
 * move and the reactions are held. Those loads are, per link,
 *   - the derivative of the link's own resultant (active load, weight,
 *     inertia; moment about D_g), from eqs. 1 and 2 differentiated by hand;
 *   - the change of the reactions' directions where a translational pair's
 *     guide turns (its force is N j: dj = -i dtheta);
 *   - the change of the lever arm of R_mn about D_g (d(l_g i_g)).
 * One more solve of the closed forms then gives du exactly (to round-off): no
 * step size, no truncation. The outputs follow: a revolute pair's force is its
 * unknown, a translational pair's force N j also turns with its guide.
 *
 * A direction's seed is the derivative of its unit vector; only its component
 * normal to the direction counts (the angle rate dtheta = dir x ddir), as a
 * unit vector can only turn.
 */
#include "dyad_internal.h"

/* Angle rate of a unit direction d under the seed dd. */
static dyad_real turn_rate(dyad_vec2 d, dyad_vec2 dd)
{
    return dyad_cross(d, dd);
}

/* Derivative of a link's resultant force F and moment about D, M_D, along the
 * seed dk, for the link frame i (already unit) turning at dtheta; and the sizes
 * of both sums with their rates, for the amplification. */
static void resultant_rate(const dyad_link* k, const dyad_link* dk, dyad_vec2 i, dyad_real dtheta,
                           dyad_vec2 gravity, dyad_vec2 dgravity, dyad_vec2* dforce,
                           dyad_real* dmoment_d, dyad_link_sizes* sizes)
{
    const dyad_vec2 j = dyad_perp(i);
    const dyad_vec2 r = dyad_combine(k->com.x, i, k->com.y, j);
    /* r turns with the link and moves with com. */
    const dyad_vec2 dr = dyad_add(dyad_combine(dk->com.x, i, dk->com.y, j),
                                  dyad_scale(dtheta, dyad_perp(r)));
    const dyad_vec2 w = dyad_add(k->force, dyad_scale(k->mass, dyad_sub(gravity,
                          dyad_add(k->accel_d, dyad_scale(k->epsilon, dyad_perp(r))))));
    const dyad_vec2 dtangential = dyad_add(
        dyad_add(dk->accel_d, dyad_scale(dk->epsilon, dyad_perp(r))),
        dyad_scale(k->epsilon, dyad_perp(dr)));
    const dyad_vec2 dw = dyad_add(
        dyad_add(dk->force,
                 dyad_scale(dk->mass, dyad_sub(gravity, dyad_add(k->accel_d,
                                               dyad_scale(k->epsilon, dyad_perp(r)))))),
        dyad_scale(k->mass, dyad_sub(dgravity, dtangential)));
    const dyad_real w2 = k->omega * k->omega;
    const dyad_vec2 dcentripetal =
        dyad_add(dyad_scale(dk->mass * w2 + 2 * k->mass * k->omega * dk->omega, r),
                 dyad_scale(k->mass * w2, dr));
    const dyad_real dmoment = dk->moment - dk->inertia * k->epsilon - k->inertia * dk->epsilon;
    *dforce = dyad_add(dw, dcentripetal);
    *dmoment_d = dmoment + dyad_cross(dr, w) + dyad_cross(r, dw);
    *sizes = dyad_link_sizes_of(k, dk, r, dr, gravity, dgravity);
}

/* The rate of the amplification (dyad_amplification.h): the same formulas as
 * the solvers', on dual numbers. inv: the inverse of the type's divisor with
 * its rate. */
static dyad_real amplification_rate(dyad_type type, const dyad_input* input, const dyad_input* seed,
                                    const dyad_link_sizes* m, const dyad_link_sizes* n,
                                    dyad_dual inv, const dyad_result* value,
                                    const dyad_result* derivative)
{
    dyad_size_terms t;
    dyad_output_sizes sizes;
    t.f_m = m->f;
    t.m_m = m->m_d;
    t.f_n = n->f;
    t.m_n = n->m_d;
    t.l_m = dyad_dual_make(input->m.length, seed->m.length);
    t.l_n = dyad_dual_make(input->n.length, seed->n.length);
    t.inv = inv;
    switch (type) {
    case DYAD_RRR: sizes = dyad_sizes_rrr(&t); break;
    case DYAD_RRT: sizes = dyad_sizes_rrt(&t); break;
    case DYAD_RTR: sizes = dyad_sizes_rtr(&t); break;
    case DYAD_TRT: sizes = dyad_sizes_trt(&t); break;
    default: sizes = dyad_sizes_rtt(&t); break;
    }
    return dyad_amplification_of(
               sizes, dyad_largest_force(value, derivative),
               dyad_largest_moment(value, derivative, dyad_guide_used(type, DYAD_PAIR_DM),
                                   dyad_guide_used(type, DYAD_PAIR_E),
                                   dyad_guide_used(type, DYAD_PAIR_DN)),
               dyad_dual_make(value->conditioning, derivative->conditioning))
        .d;
}

dyad_status dyad_solve_tangent_with(dyad_solver solve, dyad_type type, const dyad_input* input,
                                    const dyad_input* seed, dyad_result* value,
                                    dyad_result* derivative)
{
    dyad_input loads;
    dyad_status status;
    dyad_vec2 i_m, i_n, i_k, i_p, df_m, df_n, dr_mn_turn;
    dyad_real dth_m, dth_n, dth_k, dth_p, dmd_m, dmd_n, dc = 0;
    dyad_link_sizes sizes_m, sizes_n;
    /* the type's divisor |d| (RTR: |D_m D_n| |d|) and its rate */
    dyad_dual divisor = dyad_dual_const(1);

    if (value == NULL || derivative == NULL || solve == NULL ||
        (unsigned)type >= DYAD_TYPE_COUNT) {
        return DYAD_STATUS_INVALID_INPUT;
    }
    status = solve(input, value);
    if (status != DYAD_STATUS_OK) {
        *derivative = *value;
        return status;
    }
    if (seed == NULL) {
        *derivative = *value;
        return dyad_reject(derivative, DYAD_STATUS_INVALID_INPUT, DYAD_FIELD_INPUT);
    }

    i_m = dyad_unit_of(input->m.dir);
    i_n = dyad_unit_of(input->n.dir);
    i_k = dyad_unit_of(input->guide_k);
    i_p = dyad_unit_of(input->guide_p);
    dth_m = turn_rate(i_m, seed->m.dir);
    dth_n = turn_rate(i_n, seed->n.dir);
    dth_k = dyad_guide_used(type, DYAD_PAIR_DM) ? turn_rate(i_k, seed->guide_k) : 0;
    dth_p = dyad_guide_used(type, DYAD_PAIR_DN) ? turn_rate(i_p, seed->guide_p) : 0;

    resultant_rate(&input->m, &seed->m, i_m, dth_m, input->gravity, seed->gravity, &df_m, &dmd_m,
                   &sizes_m);
    resultant_rate(&input->n, &seed->n, i_n, dth_n, input->gravity, seed->gravity, &df_n, &dmd_n,
                   &sizes_n);

    /* Reactions held, geometry moving: a turning guide turns its normal force
     * (d(N j) = -N i dtheta), and R_mn's lever l_g i_g about D_g changes. */
    if (dyad_guide_used(type, DYAD_PAIR_DM)) {
        df_m = dyad_add(df_m, dyad_scale(-value->n_mk * dth_k, i_k));
    }
    if (dyad_guide_used(type, DYAD_PAIR_DN)) {
        df_n = dyad_add(df_n, dyad_scale(-value->n_np * dth_p, i_p));
    }
    dr_mn_turn = dyad_pair_kind_of(type, DYAD_PAIR_E) == DYAD_PAIR_TRANSLATIONAL
                     ? dyad_scale(-value->n_mn * dth_m, i_m)
                     : dyad_vec2_make(0, 0);
    df_m = dyad_add(df_m, dr_mn_turn);
    df_n = dyad_sub(df_n, dr_mn_turn);
    {
        const dyad_vec2 lever_m = dyad_scale(input->m.length, i_m);
        const dyad_vec2 lever_n = dyad_scale(input->n.length, i_n);
        const dyad_vec2 dlever_m = dyad_combine(seed->m.length, i_m, input->m.length * dth_m,
                                                dyad_perp(i_m));
        const dyad_vec2 dlever_n = dyad_combine(seed->n.length, i_n, input->n.length * dth_n,
                                                dyad_perp(i_n));
        dmd_m += dyad_cross(dlever_m, value->r_mn) + dyad_cross(lever_m, dr_mn_turn);
        dmd_n -= dyad_cross(dlever_n, value->r_mn) + dyad_cross(lever_n, dr_mn_turn);
    }

    /* The same dyad under those loads, applied at D_g (com at the origin). */
    loads = *input;
    loads.m.com = loads.n.com = dyad_vec2_make(0, 0);
    loads.m.mass = loads.n.mass = loads.m.inertia = loads.n.inertia = 0;
    loads.m.omega = loads.n.omega = loads.m.epsilon = loads.n.epsilon = 0;
    loads.m.accel_d = loads.n.accel_d = loads.gravity = dyad_vec2_make(0, 0);
    loads.m.force = df_m;
    loads.n.force = df_n;
    loads.m.moment = dmd_m;
    loads.n.moment = dmd_n;
    status = solve(&loads, derivative);
    if (status != DYAD_STATUS_OK) {
        return status;
    }
    /* A translational pair's force N j turns with its guide. */
    if (dyad_guide_used(type, DYAD_PAIR_DM)) {
        derivative->r_mk = dyad_add(derivative->r_mk, dyad_scale(-value->n_mk * dth_k, i_k));
    }
    if (dyad_guide_used(type, DYAD_PAIR_DN)) {
        derivative->r_np = dyad_add(derivative->r_np, dyad_scale(-value->n_np * dth_p, i_p));
    }
    derivative->r_mn = dyad_add(derivative->r_mn, dr_mn_turn);

    /* The conditioning's own rate, from its definition per type. */
    switch (type) {
    case DYAD_RRR: /* d = i_m . j_n */
        dc = dth_m * dyad_dot(dyad_perp(i_m), dyad_perp(i_n)) - dth_n * dyad_dot(i_m, i_n);
        break;
    case DYAD_RRT: /* d = i_n . i_k */
        dc = dth_n * dyad_dot(dyad_perp(i_n), i_k) + dth_k * dyad_dot(i_n, dyad_perp(i_k));
        break;
    case DYAD_TRT: /* d = j_k . i_p */
        dc = -dth_k * dyad_dot(i_k, i_p) + dth_p * dyad_dot(dyad_perp(i_k), dyad_perp(i_p));
        break;
    case DYAD_RTT: /* d = j_k . i_m */
        dc = -dth_k * dyad_dot(i_k, i_m) + dth_m * dyad_dot(dyad_perp(i_k), dyad_perp(i_m));
        break;
    case DYAD_RTR: { /* the smaller of |i_beta . i_m| and |D_m D_n| / (l_m + l_n) */
        const dyad_vec2 v = dyad_combine(input->m.length, i_m, -input->n.length, i_n);
        const dyad_vec2 dv = dyad_add(
            dyad_combine(seed->m.length, i_m, input->m.length * dth_m, dyad_perp(i_m)),
            dyad_combine(-seed->n.length, i_n, -input->n.length * dth_n, dyad_perp(i_n)));
        const dyad_real dist = dyad_length(v);
        const dyad_real ddist = dyad_dot(v, dv) / dist;
        const dyad_real spread = dist / (input->m.length + input->n.length);
        const dyad_real slant = dyad_dot(v, i_m) / dist;
        const dyad_real dslant =
            (dyad_dot(dv, i_m) + dth_m * dyad_dot(v, dyad_perp(i_m))) / dist - slant * ddist / dist;
        divisor = dyad_dual_mul(dyad_dual_make(dist, ddist), dyad_dual_abs(slant, dslant));
        derivative->denominator = dslant;
        derivative->conditioning =
            dyad_abs(slant) > spread
                ? (ddist - spread * (seed->m.length + seed->n.length)) /
                      (input->m.length + input->n.length)
                : (slant < 0 ? -dslant : dslant);
        break;
    }
    case DYAD_TYPE_COUNT: break;
    }
    if (type != DYAD_RTR) {
        divisor = dyad_dual_abs(value->denominator, dc);
        derivative->denominator = dc;
        derivative->conditioning = value->denominator < 0 ? -dc : dc;
    }
    derivative->amplification =
        amplification_rate(type, input, seed, &sizes_m, &sizes_n,
                           dyad_dual_div(dyad_dual_const(1), divisor), value, derivative);
    return DYAD_STATUS_OK;
}
