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
#include "dyad_tangent.h"

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
    const dyad_vec2 dr =
        dyad_add(dyad_combine(dk->com.x, i, dk->com.y, j), dyad_scale(dtheta, dyad_perp(r)));
    const dyad_vec2 w = dyad_add(
        k->force,
        dyad_scale(k->mass,
                   dyad_sub(gravity, dyad_add(k->accel_d, dyad_scale(k->epsilon, dyad_perp(r))))));
    const dyad_vec2 dtangential =
        dyad_add(dyad_add(dk->accel_d, dyad_scale(dk->epsilon, dyad_perp(r))),
                 dyad_scale(k->epsilon, dyad_perp(dr)));
    const dyad_vec2 dw = dyad_add(
        dyad_add(dk->force,
                 dyad_scale(dk->mass,
                            dyad_sub(gravity,
                                     dyad_add(k->accel_d, dyad_scale(k->epsilon, dyad_perp(r)))))),
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
static dyad_real amplification_rate(const dyad_tangent_type* kind, const dyad_input* input,
                                    const dyad_input* seed, const dyad_link_sizes* m,
                                    const dyad_link_sizes* n, dyad_dual inv,
                                    const dyad_result* value, const dyad_result* derivative)
{
    const dyad_type type = kind->type;
    dyad_size_terms t;
    t.f_m = m->f;
    t.m_m = m->m_d;
    t.f_n = n->f;
    t.m_n = n->m_d;
    t.l_m = dyad_dual_make(input->m.length, seed->m.length);
    t.l_n = dyad_dual_make(input->n.length, seed->n.length);
    t.inv = inv;
    return dyad_amplification_of(kind->sizes(&t), dyad_largest_force(value, derivative),
                                 dyad_largest_moment(value, derivative,
                                                     dyad_guide_used(type, DYAD_PAIR_DM),
                                                     dyad_guide_used(type, DYAD_PAIR_E),
                                                     dyad_guide_used(type, DYAD_PAIR_DN)),
                                 dyad_dual_make(value->conditioning, derivative->conditioning))
        .d;
}

/* How the dyad's frames turn along the seed; a guide the type has not stays. */
static dyad_turning turning_of(dyad_type type, const dyad_input* input, const dyad_input* seed)
{
    dyad_turning t;
    t.i_m = dyad_unit_of(input->m.dir);
    t.i_n = dyad_unit_of(input->n.dir);
    t.i_k = dyad_unit_of(input->guide_k);
    t.i_p = dyad_unit_of(input->guide_p);
    t.dth_m = turn_rate(t.i_m, seed->m.dir);
    t.dth_n = turn_rate(t.i_n, seed->n.dir);
    t.dth_k = dyad_guide_used(type, DYAD_PAIR_DM) ? turn_rate(t.i_k, seed->guide_k) : 0;
    t.dth_p = dyad_guide_used(type, DYAD_PAIR_DN) ? turn_rate(t.i_p, seed->guide_p) : 0;
    return t;
}

/* What the reactions held at `value` add to the links' equilibrium sums when
 * the geometry moves along the seed: a turning guide turns its normal force
 * (d(N j) = -N i dtheta), R_mn turns with a translational pair E
 * (dr_mn_turn), and R_mn's lever l_g i_g about D_g changes (dl_g: the
 * lengths' rates). Added to df_g and dmd_g. */
static void add_held_reactions(dyad_type type, const dyad_turning* t, const dyad_result* value,
                               dyad_vec2 dr_mn_turn, dyad_dual l_m, dyad_dual l_n, dyad_vec2* df_m,
                               dyad_vec2* df_n, dyad_real* dmd_m, dyad_real* dmd_n)
{
    const dyad_vec2 lever_m = dyad_scale(l_m.v, t->i_m);
    const dyad_vec2 lever_n = dyad_scale(l_n.v, t->i_n);
    const dyad_vec2 dlever_m = dyad_combine(l_m.d, t->i_m, l_m.v * t->dth_m, dyad_perp(t->i_m));
    const dyad_vec2 dlever_n = dyad_combine(l_n.d, t->i_n, l_n.v * t->dth_n, dyad_perp(t->i_n));
    if (dyad_guide_used(type, DYAD_PAIR_DM)) {
        *df_m = dyad_add(*df_m, dyad_scale(-value->n_mk * t->dth_k, t->i_k));
    }
    if (dyad_guide_used(type, DYAD_PAIR_DN)) {
        *df_n = dyad_add(*df_n, dyad_scale(-value->n_np * t->dth_p, t->i_p));
    }
    *df_m = dyad_add(*df_m, dr_mn_turn);
    *df_n = dyad_sub(*df_n, dr_mn_turn);
    *dmd_m += dyad_cross(dlever_m, value->r_mn) + dyad_cross(lever_m, dr_mn_turn);
    *dmd_n -= dyad_cross(dlever_n, value->r_mn) + dyad_cross(lever_n, dr_mn_turn);
}

/* A dyad under the loads (force at D_g, moment about D_g) alone: the shape of
 * the derivative's solve. */
static void load_at_d(dyad_loaded_link* link, dyad_vec2 force, dyad_real moment)
{
    link->f = force;
    link->m = link->m_d = moment;
    link->f_size = dyad_norm1(force);
    link->m_d_size = DYAD_FABS(moment);
}

/* The loads of the derivative's solve: the change of each link's equilibrium
 * sums when the inputs move along the seed and the reactions are held, applied
 * at D_g (com at the origin, no mass). dr_mn_turn: how R_mn turns with a
 * translational pair E. Also the sizes of the links' sums with their rates. */
static dyad_input held_reaction_loads(dyad_type type, const dyad_input* input,
                                      const dyad_input* seed, const dyad_turning* t,
                                      const dyad_result* value, dyad_vec2 dr_mn_turn,
                                      dyad_link_sizes* sizes_m, dyad_link_sizes* sizes_n)
{
    dyad_input loads = *input;
    dyad_vec2 df_m, df_n;
    dyad_real dmd_m, dmd_n;
    resultant_rate(&input->m, &seed->m, t->i_m, t->dth_m, input->gravity, seed->gravity, &df_m,
                   &dmd_m, sizes_m);
    resultant_rate(&input->n, &seed->n, t->i_n, t->dth_n, input->gravity, seed->gravity, &df_n,
                   &dmd_n, sizes_n);
    add_held_reactions(type, t, value, dr_mn_turn, dyad_dual_make(input->m.length, seed->m.length),
                       dyad_dual_make(input->n.length, seed->n.length), &df_m, &df_n, &dmd_m,
                       &dmd_n);

    loads.m.com = loads.n.com = dyad_vec2_make(0, 0);
    loads.m.mass = loads.n.mass = loads.m.inertia = loads.n.inertia = 0;
    loads.m.omega = loads.n.omega = loads.m.epsilon = loads.n.epsilon = 0;
    loads.m.accel_d = loads.n.accel_d = loads.gravity = dyad_vec2_make(0, 0);
    loads.m.force = df_m;
    loads.n.force = df_n;
    loads.m.moment = dmd_m;
    loads.n.moment = dmd_n;
    return loads;
}

/* The derivative's last step, shared by both entries: a translational pair's
 * force N j turns with its guide, R_mn with a sliding E; then the
 * conditioning's rate from its definition in the type's file and the
 * amplification's from the sizes' rates. */
static void finish_tangent(const dyad_tangent_type* kind, const dyad_input* input,
                           const dyad_input* seed, const dyad_turning* t, dyad_vec2 dr_mn_turn,
                           const dyad_link_sizes* sizes_m, const dyad_link_sizes* sizes_n,
                           const dyad_result* value, dyad_result* derivative)
{
    dyad_dual divisor; /* the type's divisor |d| (RTR: |D_m D_n| |d|) and its rate */
    if (dyad_guide_used(kind->type, DYAD_PAIR_DM)) {
        derivative->r_mk = dyad_add(derivative->r_mk, dyad_scale(-value->n_mk * t->dth_k, t->i_k));
    }
    if (dyad_guide_used(kind->type, DYAD_PAIR_DN)) {
        derivative->r_np = dyad_add(derivative->r_np, dyad_scale(-value->n_np * t->dth_p, t->i_p));
    }
    derivative->r_mn = dyad_add(derivative->r_mn, dr_mn_turn);
    divisor = kind->conditioning_rate(input, seed, t, value, derivative);
    derivative->amplification =
        amplification_rate(kind, input, seed, sizes_m, sizes_n,
                           dyad_dual_div(dyad_dual_const(1), divisor), value, derivative);
}

/* How R_mn turns along the seed: with link m where E slides along it. */
static dyad_vec2 mn_turn(dyad_type type, const dyad_turning* t, const dyad_result* value)
{
    return dyad_pair_kind_of(type, DYAD_PAIR_E) == DYAD_PAIR_TRANSLATIONAL
               ? dyad_scale(-value->n_mn * t->dth_m, t->i_m)
               : dyad_vec2_make(0, 0);
}

dyad_status dyad_solve_tangent_of(const dyad_tangent_type* kind, const dyad_input* input,
                                  const dyad_input* seed, dyad_result* value,
                                  dyad_result* derivative)
{
    dyad_status status;
    dyad_turning t;
    dyad_input loads;
    dyad_vec2 dr_mn_turn;
    dyad_link_sizes sizes_m, sizes_n;

    if (kind == NULL || value == NULL || derivative == NULL) {
        return DYAD_STATUS_INVALID_INPUT;
    }
    status = kind->solve(input, value);
    if (status != DYAD_STATUS_OK) {
        *derivative = *value;
        return status;
    }
    if (seed == NULL) {
        *derivative = *value;
        return dyad_reject(derivative, DYAD_STATUS_INVALID_INPUT, DYAD_FIELD_INPUT);
    }

    t = turning_of(kind->type, input, seed);
    dr_mn_turn = mn_turn(kind->type, &t, value);
    loads = held_reaction_loads(kind->type, input, seed, &t, value, dr_mn_turn, &sizes_m, &sizes_n);
    status = kind->solve(&loads, derivative);
    if (status != DYAD_STATUS_OK) {
        return status;
    }
    finish_tangent(kind, input, seed, &t, dr_mn_turn, &sizes_m, &sizes_n, value, derivative);
    return DYAD_STATUS_OK;
}

/* The geometry of a loaded dyad as a dyad_input (directions, lengths, guides):
 * what the conditioning's and the amplification's rates read. */
static dyad_input geometry_of(const dyad_loaded* dyad)
{
    dyad_input g = dyad_input_default();
    g.m.dir = dyad->m.i;
    g.n.dir = dyad->n.i;
    g.m.length = dyad->m.l;
    g.n.length = dyad->n.l;
    g.guide_k = dyad->i_k;
    g.guide_p = dyad->i_p;
    return g;
}

dyad_status dyad_react_tangent_of(const dyad_tangent_type* kind, const dyad_loaded* dyad,
                                  const dyad_loaded* seed, dyad_result* value,
                                  dyad_result* derivative)
{
    dyad_status status;
    dyad_input geometry, rate;
    dyad_turning t;
    dyad_loaded loads;
    dyad_vec2 dr_mn_turn, df_m, df_n;
    dyad_real dmd_m, dmd_n;
    dyad_link_sizes sizes_m, sizes_n;

    if (kind == NULL || dyad == NULL || value == NULL || derivative == NULL) {
        return DYAD_STATUS_INVALID_INPUT;
    }
    status = kind->react(dyad, value);
    if (status != DYAD_STATUS_OK || seed == NULL) {
        *derivative = *value;
        return seed == NULL ? dyad_reject(derivative, DYAD_STATUS_INVALID_INPUT, DYAD_FIELD_INPUT)
                            : status;
    }
    geometry = geometry_of(dyad);
    rate = geometry_of(seed);
    t = turning_of(kind->type, &geometry, &rate);
    dr_mn_turn = mn_turn(kind->type, &t, value);
    df_m = seed->m.f;
    df_n = seed->n.f;
    dmd_m = seed->m.m_d;
    dmd_n = seed->n.m_d;
    add_held_reactions(kind->type, &t, value, dr_mn_turn, dyad_dual_make(dyad->m.l, seed->m.l),
                       dyad_dual_make(dyad->n.l, seed->n.l), &df_m, &df_n, &dmd_m, &dmd_n);
    loads = *dyad;
    load_at_d(&loads.m, df_m, dmd_m);
    load_at_d(&loads.n, df_n, dmd_n);
    status = kind->react(&loads, derivative);
    if (status != DYAD_STATUS_OK) {
        return status;
    }
    sizes_m.f = dyad_dual_make(dyad->m.f_size, seed->m.f_size);
    sizes_m.m_d = dyad_dual_make(dyad->m.m_d_size, seed->m.m_d_size);
    sizes_n.f = dyad_dual_make(dyad->n.f_size, seed->n.f_size);
    sizes_n.m_d = dyad_dual_make(dyad->n.m_d_size, seed->n.m_d_size);
    finish_tangent(kind, &geometry, &rate, &t, dr_mn_turn, &sizes_m, &sizes_n, value, derivative);
    return DYAD_STATUS_OK;
}

/* The rate of dyad_force_size and dyad_moment_size: amplification x the
 * largest of three magnitudes, compared as they are (ties to the later). */
static dyad_real error_scale_rate(const dyad_result* value, const dyad_result* derivative,
                                  dyad_dual mk, dyad_dual np, dyad_dual mn)
{
    const dyad_dual largest = mk.v > np.v ? (mk.v > mn.v ? mk : mn) : (np.v > mn.v ? np : mn);
    return dyad_dual_mul(dyad_dual_make(value->amplification, derivative->amplification), largest)
        .d;
}

dyad_real dyad_force_size_rate(const dyad_result* value, const dyad_result* derivative)
{
    return error_scale_rate(value, derivative, dyad_dual_norm1(value->r_mk, derivative->r_mk),
                            dyad_dual_norm1(value->r_np, derivative->r_np),
                            dyad_dual_norm1(value->r_mn, derivative->r_mn));
}

dyad_real dyad_moment_size_rate(const dyad_result* value, const dyad_result* derivative)
{
    return error_scale_rate(value, derivative, dyad_dual_abs(value->m_mk, derivative->m_mk),
                            dyad_dual_abs(value->m_np, derivative->m_np),
                            dyad_dual_abs(value->m_mn, derivative->m_mn));
}
