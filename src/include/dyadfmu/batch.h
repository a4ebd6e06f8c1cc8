/* dyadfmu: many dyads of one type in one call, structure of arrays in and out.
 *
 * Row r of a batch is the dyad_input whose every scalar is taken from its column
 * at row r; each row's status and outputs are bit for bit those of dyad_solve on
 * that row (the rows are solved together, in loops the compiler vectorises, from
 * the same formulas; a row that fails a check is solved again alone). Nothing is
 * allocated: rows are gathered and scattered in blocks of DYAD_BATCH_BLOCK on
 * the stack (DYAD_BATCH_BLOCK * 416 bytes for double). Reentrant.
 */
#ifndef DYADFMU_BATCH_H
#define DYADFMU_BATCH_H

#include <stddef.h>

#include "dyadfmu/types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Rows gathered, solved and scattered together. */
#define DYAD_BATCH_BLOCK 32

/** The scalars of a dyad_input, in the order of its fields: link m, link n
 *  (dir.x, dir.y, length, omega, epsilon, accel_d.x, accel_d.y, com.x, com.y,
 *  mass, inertia, force.x, force.y, moment), then guide_k, guide_p, gravity
 *  (x, y) and singular_threshold. Units as in dyad_input. */
typedef enum dyad_input_column {
    DYAD_IN_M_DIR_X = 0,
    DYAD_IN_M_DIR_Y,
    DYAD_IN_M_LENGTH,
    DYAD_IN_M_OMEGA,
    DYAD_IN_M_EPSILON,
    DYAD_IN_M_ACCEL_D_X,
    DYAD_IN_M_ACCEL_D_Y,
    DYAD_IN_M_COM_X,
    DYAD_IN_M_COM_Y,
    DYAD_IN_M_MASS,
    DYAD_IN_M_INERTIA,
    DYAD_IN_M_FORCE_X,
    DYAD_IN_M_FORCE_Y,
    DYAD_IN_M_MOMENT,
    DYAD_IN_N_DIR_X,
    DYAD_IN_N_DIR_Y,
    DYAD_IN_N_LENGTH,
    DYAD_IN_N_OMEGA,
    DYAD_IN_N_EPSILON,
    DYAD_IN_N_ACCEL_D_X,
    DYAD_IN_N_ACCEL_D_Y,
    DYAD_IN_N_COM_X,
    DYAD_IN_N_COM_Y,
    DYAD_IN_N_MASS,
    DYAD_IN_N_INERTIA,
    DYAD_IN_N_FORCE_X,
    DYAD_IN_N_FORCE_Y,
    DYAD_IN_N_MOMENT,
    DYAD_IN_GUIDE_K_X,
    DYAD_IN_GUIDE_K_Y,
    DYAD_IN_GUIDE_P_X,
    DYAD_IN_GUIDE_P_Y,
    DYAD_IN_GRAVITY_X,
    DYAD_IN_GRAVITY_Y,
    DYAD_IN_SINGULAR_THRESHOLD,
    DYAD_INPUT_COLUMN_COUNT
} dyad_input_column;

/** The scalar outputs of a dyad_result after status and field, in its order:
 *  r_mk, r_np, r_mn (x, y; N), n_mk, n_np, n_mn (N), m_mk, m_np, m_mn (N m),
 *  denominator, conditioning, amplification (-). */
typedef enum dyad_output_column {
    DYAD_OUT_R_MK_X = 0,
    DYAD_OUT_R_MK_Y,
    DYAD_OUT_R_NP_X,
    DYAD_OUT_R_NP_Y,
    DYAD_OUT_R_MN_X,
    DYAD_OUT_R_MN_Y,
    DYAD_OUT_N_MK,
    DYAD_OUT_N_NP,
    DYAD_OUT_N_MN,
    DYAD_OUT_M_MK,
    DYAD_OUT_M_NP,
    DYAD_OUT_M_MN,
    DYAD_OUT_DENOMINATOR,
    DYAD_OUT_CONDITIONING,
    DYAD_OUT_AMPLIFICATION,
    DYAD_OUTPUT_COLUMN_COUNT
} dyad_output_column;

/** One input column: row r reads data[r * stride] (stride in elements; 0 gives
 *  every row data[0]). data NULL: every row has dyad_input_default()'s value. */
typedef struct dyad_input_array {
    const dyad_real* data;
    ptrdiff_t stride;
} dyad_input_array;

/** One output column: row r writes data[r * stride]. data NULL: not written. */
typedef struct dyad_output_array {
    dyad_real* data;
    ptrdiff_t stride;
} dyad_output_array;

typedef struct dyad_batch_input {
    dyad_input_array column[DYAD_INPUT_COLUMN_COUNT];
} dyad_batch_input;

typedef struct dyad_batch_output {
    dyad_output_array column[DYAD_OUTPUT_COLUMN_COUNT];
    /** Per row, its dyad_status (NULL: not written). */
    unsigned char* status;
    /** Per row, the dyad_field an invalid input names, else 0 (NULL: not written). */
    unsigned char* field;
} dyad_batch_output;

/** Solves `count` dyads of one type. Every row gets its own status; a failed row
 *  (singular, invalid, out of range) has NaN reactions like dyad_solve's and
 *  does not stop the others. Returns the number of rows solved with status ok;
 *  0 with every row invalid (field DYAD_FIELD_TYPE or DYAD_FIELD_INPUT) for an
 *  unknown type or a NULL input or output. */
size_t dyad_solve_batch(dyad_type type, size_t count, const dyad_batch_input* input,
                        const dyad_batch_output* output);

/** dyad_solve_batch in the widest lanes this CPU runs up to `cap` (dyadfmu/types.h;
 *  dyad_solve_batch takes the widest): to measure or test each. The same results. */
size_t dyad_solve_batch_at_most(dyad_lanes_isa cap, dyad_type type, size_t count,
                                const dyad_batch_input* input, const dyad_batch_output* output);

#ifdef __cplusplus
}
#endif

#endif /* DYADFMU_BATCH_H */
