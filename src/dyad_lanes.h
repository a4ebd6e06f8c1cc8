/* dyadfmu: one sample of a batch, for a loop over samples that the compiler vectorises.
 * Not part of the public API; a generated scene's batch evaluation, dyad_solve_batch and a
 * generic dyad FMU's lanes (fmu/models/fmu_dyad_lanes.h) include it.
 *
 * A vector loop cannot branch per sample, and cannot call: each function here is the
 * computation of its public twin (dyad_kinematics_<type>, dyad_react_<type>,
 * dyad_solve_<type>, dyad_cylinder, dyad_point_on_link, dyad_force_size, ...) with every check made
 * and counted instead of acted on, inlined from the same source (the kinematics' formulas of
 * dyad_kin_<type>.c, the reactions' closed forms of dyad_<type>.c). Where a function
 * returns 0, its twin says DYAD_STATUS_OK and its outputs are its twin's, bit for bit;
 * elsewhere its outputs mean nothing, and the caller asks the twin what went wrong. A
 * result's status, field, failure and gap are not written.
 *
 * Vectorising needs the compiler to speculate the arithmetic of both sides of a
 * selection (GCC: -O3 -fno-trapping-math -fno-math-errno, which change no result).
 */
#ifndef DYADFMU_LANES_H
#define DYADFMU_LANES_H

/* No a * b + c fused into one operation in the functions that follow, in the compilers'
 * default modes: Clang fuses within an expression by default (even in ISO C), and in the
 * AVX-512 lanes, whose target has FMA, a fused one would change their bits; GCC's are told
 * so by DYAD_LANES_AVX512_TARGET (it fuses only in its GNU modes). A build for a target
 * with FMA (-mfma, -march=native) without -ffp-contract=off fuses in the scalar twins'
 * files, which have no such pragma, and the lanes then differ from them in the last bits. */
#if defined(__clang__)
#pragma clang fp contract(off)
#endif

#include "dyad_internal.h"

/* The lanes of the types its includer defines DYAD_LANES_<TYPE> for (a scene's, whose
 * files it ships); each type's formulas come from its files. Their kinematics too unless
 * it defines DYAD_LANES_NO_KINEMATICS (a generic dyad FMU, which solves one dyad whose
 * motion is given). */
#define DYAD_REACT_FORMULAS
#ifdef DYAD_LANES_RRR
#include "dyad_rrr.c"
#endif
#ifdef DYAD_LANES_RRT
#include "dyad_rrt.c"
#endif
#ifdef DYAD_LANES_RTR
#include "dyad_rtr.c"
#endif
#ifdef DYAD_LANES_TRT
#include "dyad_trt.c"
#endif
#ifdef DYAD_LANES_RTT
#include "dyad_rtt.c"
#endif
#undef DYAD_REACT_FORMULAS

#ifndef DYAD_LANES_NO_KINEMATICS
#include "dyad_kin_internal.h"
#include "dyad_kin_generic.h"
#define DYAD_KIN_FORMULAS
#ifdef DYAD_LANES_RRR
#include "dyad_kin_rrr.c"
#endif
#ifdef DYAD_LANES_RRT
#include "dyad_kin_rrt.c"
#endif
#ifdef DYAD_LANES_RTR
#include "dyad_kin_rtr.c"
#endif
#ifdef DYAD_LANES_TRT
#include "dyad_kin_trt.c"
#endif
#ifdef DYAD_LANES_RTT
#include "dyad_kin_rtt.c"
#endif
#ifdef DYAD_LANES_CYLINDER
#include "dyadfmu/cylinder.h"
#define DYAD_REACT_FORMULAS
#include "dyad_cylinder.c"
#undef DYAD_REACT_FORMULAS
#endif
#undef DYAD_KIN_FORMULAS
#endif /* DYAD_LANES_NO_KINEMATICS */

/* The scalars of a dyad_input in the order of dyad_input_column, and of a dyad_result
 * after its status and field in that of dyad_output_column (dyadfmu/batch.h): X(member)
 * for each, so that a loop over samples reads and writes them member by member, each
 * staying a register. */
/* clang-format off */
#define DYAD_LANE_LINK_MEMBERS(X, g)                                               \
    X(g.dir.x) X(g.dir.y) X(g.length) X(g.omega) X(g.epsilon)                      \
    X(g.accel_d.x) X(g.accel_d.y) X(g.com.x) X(g.com.y) X(g.mass) X(g.inertia)     \
    X(g.force.x) X(g.force.y) X(g.moment)
#define DYAD_LANE_INPUT_MEMBERS(X)                                                 \
    DYAD_LANE_LINK_MEMBERS(X, m)                                                   \
    DYAD_LANE_LINK_MEMBERS(X, n)                                                   \
    X(guide_k.x) X(guide_k.y) X(guide_p.x) X(guide_p.y) X(gravity.x) X(gravity.y)  \
    X(singular_threshold)
#define DYAD_LANE_OUTPUT_MEMBERS(X)                                                \
    X(r_mk.x) X(r_mk.y) X(r_np.x) X(r_np.y) X(r_mn.x) X(r_mn.y)                    \
    X(n_mk) X(n_np) X(n_mn) X(m_mk) X(m_np) X(m_mn)                                \
    X(denominator) X(conditioning) X(amplification)
/* clang-format on */

/* The lanes for a CPU with AVX2, and for one with AVX-512, beside those for the baseline,
 * chosen as the program runs: where the compiler can target an instruction set in one
 * function and ask the CPU (GCC or Clang on x86-64). No fused multiply-add in either (see
 * the top of this file): the same operations, the same results. AVX-512 in 512-bit
 * vectors (eight samples), which GCC would otherwise avoid; AVX-512F alone, which every
 * CPU with AVX-512 has. On Windows the stack is aligned to 16 bytes only, and GCC for
 * MinGW-w64 moves a wider vector to and from it as if it were aligned to the vector (GCC
 * bug 54412) unless patched as Debian's is, which builds the project's Windows binaries
 * (scripts/tests/test_windows.py holds their DLLs to unaligned moves).
 * dyad_lanes_widest: the widest this CPU runs, at most `cap` (dyadfmu/types.h). */
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__)
#define DYAD_LANES_HAVE_AVX2   1
#define DYAD_LANES_HAVE_AVX512 1
#define DYAD_LANES_AVX2_TARGET __attribute__((target("avx2")))
#if defined(__clang__)
#define DYAD_LANES_AVX512_TARGET __attribute__((target("avx512f"), min_vector_width(512)))
#else
#define DYAD_LANES_AVX512_TARGET \
    __attribute__((target("avx512f,prefer-vector-width=512"), optimize("fp-contract=off")))
#endif
static inline dyad_lanes_isa dyad_lanes_widest(dyad_lanes_isa cap)
{
    if (cap >= DYAD_LANES_AVX512 && __builtin_cpu_supports("avx512f")) {
        return DYAD_LANES_AVX512;
    }
    if (cap >= DYAD_LANES_AVX2 && __builtin_cpu_supports("avx2")) {
        return DYAD_LANES_AVX2;
    }
    return DYAD_LANES_BASELINE;
}
#else
#define DYAD_LANES_HAVE_AVX2   0
#define DYAD_LANES_HAVE_AVX512 0
static inline dyad_lanes_isa dyad_lanes_widest(dyad_lanes_isa cap)
{
    (void)cap;
    return DYAD_LANES_BASELINE;
}
#endif

#ifndef DYAD_LANES_NO_KINEMATICS
/* dyad_kin_input_default. */
static inline dyad_kin_input dyad_lane_kin_input_default(void)
{
    const dyad_kin_input defaults = DYAD_KIN_INPUT_DEFAULTS;
    return defaults;
}

#ifdef DYAD_LANES_CYLINDER
/* dyad_cylinder_input_default. */
static inline dyad_cylinder_input dyad_lane_cylinder_input_default(void)
{
    const dyad_cylinder_input defaults = DYAD_CYL_INPUT_DEFAULTS;
    return defaults;
}
#endif

/* dyad_point_on_link. */
#define dyad_lane_point_on_link dyad_kin_point_on_link

/* The kinematics of one dyad of each type (dyad_kinematics_<type>). */
#define DYAD_KIN_LANE(type, name)                                                                  \
    DYAD_CLOSED_FORM dyad_real dyad_kin_lane_##name(const dyad_kin_input* input, dyad_real branch, \
                                                    dyad_kin_result* value)                        \
    {                                                                                              \
        return dyad_kin_lane(type, name##_position_plain, name##_motion_plain, input, branch,      \
                             value);                                                               \
    }
#ifdef DYAD_LANES_RRR
DYAD_KIN_LANE(DYAD_RRR, rrr)
#endif
#ifdef DYAD_LANES_RRT
DYAD_KIN_LANE(DYAD_RRT, rrt)
#endif
#ifdef DYAD_LANES_RTR
DYAD_KIN_LANE(DYAD_RTR, rtr)
#endif
#ifdef DYAD_LANES_TRT
DYAD_KIN_LANE(DYAD_TRT, trt)
#endif
#ifdef DYAD_LANES_RTT
DYAD_KIN_LANE(DYAD_RTT, rtt)
#endif
#undef DYAD_KIN_LANE
#endif /* DYAD_LANES_NO_KINEMATICS */

/* The reactions of one loaded dyad (dyad_react_<type>): the conditioning stored, the
 * closed forms and, with `bounded`, the amplification whatever the conditioning; 0 where
 * it is accepted and every reaction is finite. Without `bounded` the amplification is
 * NaN, and the caller reads neither it nor the links' sizes, which the compiler then
 * drops; a reaction beyond DYAD_REAL_MAX eps (4e292 N in double) is counted too, since
 * up to it the amplification's data factor is at most 1 / eps (dyad_amplification_of),
 * which is what keeps a scene's bounds finite (emit/scene_c.py, bare_lanes). */
DYAD_CLOSED_FORM dyad_real dyad_react_lane(dyad_type type, const dyad_loaded* p, dyad_conditioned c,
                                           dyad_closed_forms_fn closed_forms, int bounded,
                                           dyad_result* result)
{
    dyad_output_sizes sizes;
    dyad_real bad;
    dyad_fill_outputs(result, 0);
    dyad_store_conditioning(c, result);
    bad = DYAD_FAILED(c.conditioning >= p->singular_threshold);
    sizes = closed_forms(p, c, result);
    bad += DYAD_FAILED(dyad_outputs_residue(result) == 0);
    if (bounded) {
        result->amplification = dyad_result_amplification(type, sizes, result);
    } else {
        const dyad_real beyond = DYAD_REAL_MAX * DYAD_REAL_EPSILON;
        const dyad_real moment =
            dyad_largest_moment(result, result, dyad_guide_used(type, DYAD_PAIR_DM),
                                dyad_guide_used(type, DYAD_PAIR_E),
                                dyad_guide_used(type, DYAD_PAIR_DN))
                .v;
        bad += DYAD_FAILED(dyad_largest_force(result, result).v <= beyond && moment <= beyond);
        result->amplification = NAN;
    }
    return bad;
}

/* dyad_react_lane_<type>, and dyad_react_lane_bare_<type> without the amplification. */
#define DYAD_REACT_LANE(type, name)                                                              \
    DYAD_CLOSED_FORM dyad_real dyad_react_lane_##name(const dyad_loaded* p, dyad_result* result) \
    {                                                                                            \
        return dyad_react_lane(type, p, name##_conditioning(p), name##_closed_forms, 1, result); \
    }                                                                                            \
    DYAD_CLOSED_FORM dyad_real dyad_react_lane_bare_##name(const dyad_loaded* p,                 \
                                                           dyad_result* result)                  \
    {                                                                                            \
        return dyad_react_lane(type, p, name##_conditioning(p), name##_closed_forms, 0, result); \
    }
#ifdef DYAD_LANES_RRR
DYAD_REACT_LANE(DYAD_RRR, rrr)
#endif
#ifdef DYAD_LANES_RRT
DYAD_REACT_LANE(DYAD_RRT, rrt)
#endif
#ifdef DYAD_LANES_RTR
DYAD_REACT_LANE(DYAD_RTR, rtr)
#endif
#ifdef DYAD_LANES_TRT
DYAD_REACT_LANE(DYAD_TRT, trt)
#endif
#ifdef DYAD_LANES_RTT
DYAD_REACT_LANE(DYAD_RTT, rtt)
#endif
#undef DYAD_REACT_LANE

/* dyad_solve_<type> of one input: its fast check (dyad_validate's, counted), its frames
 * and resultants, its reactions. */
DYAD_CLOSED_FORM dyad_real dyad_solve_lane(dyad_type type, const dyad_input* input,
                                           dyad_conditioned (*conditioning)(const dyad_loaded*),
                                           dyad_closed_forms_fn closed_forms, dyad_result* result)
{
    dyad_prepared p;
    const dyad_real bad = DYAD_FAILED(dyad_in_domain(type, input));
    dyad_prepare_valid(type, input, &p, result);
    return bad + dyad_react_lane(type, &p, conditioning(&p), closed_forms, 1, result);
}

#define DYAD_SOLVE_LANE(type, name)                                                            \
    DYAD_CLOSED_FORM dyad_real dyad_solve_lane_##name(const dyad_input* input,                 \
                                                      dyad_result* result)                     \
    {                                                                                          \
        return dyad_solve_lane(type, input, name##_conditioning, name##_closed_forms, result); \
    }
#ifdef DYAD_LANES_RRR
DYAD_SOLVE_LANE(DYAD_RRR, rrr)
#endif
#ifdef DYAD_LANES_RRT
DYAD_SOLVE_LANE(DYAD_RRT, rrt)
#endif
#ifdef DYAD_LANES_RTR
DYAD_SOLVE_LANE(DYAD_RTR, rtr)
#endif
#ifdef DYAD_LANES_TRT
DYAD_SOLVE_LANE(DYAD_TRT, trt)
#endif
#ifdef DYAD_LANES_RTT
DYAD_SOLVE_LANE(DYAD_RTT, rtt)
#endif
#undef DYAD_SOLVE_LANE

/* The largest of three sizes times the amplification: dyad_force_size and
 * dyad_moment_size of a result that is ok. */
static inline dyad_real dyad_lane_force_size(const dyad_result* result)
{
    return result->amplification * dyad_largest_of3(dyad_norm1(result->r_mk),
                                                    dyad_norm1(result->r_np),
                                                    dyad_norm1(result->r_mn));
}

static inline dyad_real dyad_lane_moment_size(const dyad_result* result)
{
    return result->amplification *
           dyad_largest_of3(dyad_abs(result->m_mk), dyad_abs(result->m_np), dyad_abs(result->m_mn));
}

#endif /* DYADFMU_LANES_H */
