/* dyadfmu: the solvers over columns of rows (see dyadfmu/batch.h).
 *
 * Rows go through a block of DYAD_BATCH_BLOCK at a time, held as columns: each input
 * column's rows are copied into the block's column (a column given once for every row,
 * or left out, is written once, before the first block), then one loop over the rows
 * solves each by its type's lane (dyad_lanes.h: dyad_solve_<type> without a branch, its
 * checks counted), which the compiler vectorises across rows. A row whose lane counts a
 * failed check is solved again alone by dyad_solve_<type>, whose status, field and NaN
 * outputs it then gets; every other row is ok, with the lane's outputs, which are that
 * solver's bit for bit. The outputs go out column by column.
 *
 * On x86-64 with GCC or Clang the loop is compiled three times, for the baseline, AVX2 and
 * AVX-512 (no fused multiply-add: the same results), and each call takes the widest the CPU
 * runs. */
#include "dyadfmu/batch.h"

#include "dyadfmu/dyad.h"

#define DYAD_LANES_NO_KINEMATICS
#define DYAD_LANES_RRR
#define DYAD_LANES_RRT
#define DYAD_LANES_RTR
#define DYAD_LANES_TRT
#define DYAD_LANES_RTT
#include "dyad_lanes.h"

#include <stddef.h>
#include <string.h>

#define BATCH_ONE(member) +1
typedef char batch_input_members_are_its_columns
    [(0 DYAD_LANE_INPUT_MEMBERS(BATCH_ONE)) == DYAD_INPUT_COLUMN_COUNT ? 1 : -1];
typedef char batch_output_members_are_its_columns
    [(0 DYAD_LANE_OUTPUT_MEMBERS(BATCH_ONE)) == DYAD_OUTPUT_COLUMN_COUNT ? 1 : -1];
#undef BATCH_ONE

/* A block of rows, column by column. */
typedef struct batch_block {
    dyad_real in[DYAD_INPUT_COLUMN_COUNT][DYAD_BATCH_BLOCK];
    dyad_real out[DYAD_OUTPUT_COLUMN_COUNT][DYAD_BATCH_BLOCK];
    /* per row, its lane's count of failed checks */
    dyad_real failed[DYAD_BATCH_BLOCK];
} batch_block;

/* Row r of the block as a dyad_input, and a result into row r: member by member, so that
 * in the loop over rows each stays a register. */
#define BATCH_READ(member)  row.member = block->in[column++][r];
#define BATCH_WRITE(member) block->out[column++][r] = result->member;

static inline dyad_input batch_row(const batch_block* block, size_t r)
{
    dyad_input row;
    int column = 0;
    DYAD_LANE_INPUT_MEMBERS(BATCH_READ)
    return row;
}

static inline void batch_store(batch_block* block, size_t r, const dyad_result* result)
{
    int column = 0;
    DYAD_LANE_OUTPUT_MEMBERS(BATCH_WRITE)
}

/* The loop of one type's lanes over the first `rows` rows of a block. */
#define BATCH_LOOP(name, suffix, attributes)                                           \
    attributes static void solve_lanes_##name##suffix(size_t rows, batch_block* block) \
    {                                                                                  \
        size_t r;                                                                      \
        for (r = 0; r < rows; ++r) {                                                   \
            const dyad_input row = batch_row(block, r);                                \
            dyad_result result;                                                        \
            block->failed[r] = dyad_solve_lane_##name(&row, &result);                  \
            batch_store(block, r, &result);                                            \
        }                                                                              \
    }
#if DYAD_LANES_HAVE_AVX512
#define BATCH_LOOPS(name)                           \
    BATCH_LOOP(name, , )                            \
    BATCH_LOOP(name, _avx2, DYAD_LANES_AVX2_TARGET) \
    BATCH_LOOP(name, _avx512, DYAD_LANES_AVX512_TARGET)
#else
#define BATCH_LOOPS(name) BATCH_LOOP(name, , )
#endif
BATCH_LOOPS(rrr)
BATCH_LOOPS(rrt)
BATCH_LOOPS(rtr)
BATCH_LOOPS(trt)
BATCH_LOOPS(rtt)

typedef void (*batch_lanes)(size_t rows, batch_block* block);

/* The lanes of a type, for this CPU up to `cap`; NULL for an unknown type. */
static batch_lanes lanes_of(dyad_type type, dyad_lanes_isa cap)
{
    static const batch_lanes baseline[DYAD_TYPE_COUNT] = {
        solve_lanes_rrr, solve_lanes_rrt, solve_lanes_rtr, solve_lanes_trt, solve_lanes_rtt};
    dyad_lanes_isa widest;
    if ((unsigned)type >= DYAD_TYPE_COUNT) {
        return NULL;
    }
    widest = dyad_lanes_widest(cap);
#if DYAD_LANES_HAVE_AVX512
    if (widest == DYAD_LANES_AVX512) {
        static const batch_lanes avx512[DYAD_TYPE_COUNT] = {
            solve_lanes_rrr_avx512, solve_lanes_rrt_avx512, solve_lanes_rtr_avx512,
            solve_lanes_trt_avx512, solve_lanes_rtt_avx512};
        return avx512[type];
    }
#endif
#if DYAD_LANES_HAVE_AVX2
    if (widest == DYAD_LANES_AVX2) {
        static const batch_lanes avx2[DYAD_TYPE_COUNT] = {
            solve_lanes_rrr_avx2, solve_lanes_rrt_avx2, solve_lanes_rtr_avx2, solve_lanes_trt_avx2,
            solve_lanes_rtt_avx2};
        return avx2[type];
    }
#endif
    (void)widest;
    return baseline[type];
}

/* Every row of the block holds, in each column given once for all rows or left out, that
 * value: the column's, or dyad_input_default()'s. */
static void preset(const dyad_batch_input* input, batch_block* block)
{
    const dyad_input defaults = dyad_input_default();
    size_t r;
    int c;
    for (r = 0; r < DYAD_BATCH_BLOCK; ++r) {
        int column = 0;
#define BATCH_DEFAULT(member) block->in[column++][r] = defaults.member;
        DYAD_LANE_INPUT_MEMBERS(BATCH_DEFAULT)
#undef BATCH_DEFAULT
    }
    for (c = 0; c < DYAD_INPUT_COLUMN_COUNT; ++c) {
        const dyad_input_array* column = &input->column[c];
        for (r = 0; column->data != NULL && column->stride == 0 && r < DYAD_BATCH_BLOCK; ++r) {
            block->in[c][r] = column->data[0];
        }
    }
}

/* Rows first .. first + rows - 1 of the columns that vary by row. */
static void gather(const dyad_batch_input* input, size_t first, size_t rows, batch_block* block)
{
    int c;
    for (c = 0; c < DYAD_INPUT_COLUMN_COUNT; ++c) {
        const dyad_input_array* column = &input->column[c];
        const ptrdiff_t stride = column->stride;
        if (column->data == NULL || stride == 0) {
            continue;
        }
        if (stride == 1) {
            memcpy(block->in[c], column->data + first, rows * sizeof column->data[0]);
        } else if (stride == 2) {
            /* x or y of an (N, 2) array, as dyadfmu.solve passes every vector: with the
             * stride a constant the copy vectorises (3 ns a row of the 35 to 40) */
            const dyad_real* source = column->data + 2 * first;
            size_t r;
            for (r = 0; r < rows; ++r) {
                block->in[c][r] = source[2 * r];
            }
        } else {
            const dyad_real* source = column->data + (ptrdiff_t)first * stride;
            size_t r;
            for (r = 0; r < rows; ++r) {
                block->in[c][r] = source[(ptrdiff_t)r * stride];
            }
        }
    }
}

/* The block's first `rows` rows into rows first .. of the output columns. */
static void scatter(const dyad_batch_output* output, size_t first, size_t rows,
                    const batch_block* block)
{
    int c;
    for (c = 0; c < DYAD_OUTPUT_COLUMN_COUNT; ++c) {
        const dyad_output_array* column = &output->column[c];
        const ptrdiff_t stride = column->stride;
        if (column->data == NULL) {
            continue;
        }
        if (stride == 1) {
            memcpy(column->data + first, block->out[c], rows * sizeof column->data[0]);
        } else if (stride == 2) {
            dyad_real* target = column->data + 2 * first;
            size_t r;
            for (r = 0; r < rows; ++r) {
                target[2 * r] = block->out[c][r];
            }
        } else {
            dyad_real* target = column->data + (ptrdiff_t)first * stride;
            size_t r;
            for (r = 0; r < rows; ++r) {
                target[(ptrdiff_t)r * stride] = block->out[c][r];
            }
        }
    }
}

/* Rows whose lane failed a check, solved again alone: their status and field, and the
 * solver's outputs in place of the lane's; the others ok. Returns the rows ok. */
static size_t settle(dyad_type type, size_t rows, batch_block* block, dyad_status status[],
                     dyad_field field[])
{
    size_t r, ok = 0;
    for (r = 0; r < rows; ++r) {
        if (block->failed[r] == 0) {
            status[r] = DYAD_STATUS_OK;
            field[r] = DYAD_FIELD_NONE;
            ++ok;
        } else {
            const dyad_input row = batch_row(block, r);
            dyad_result result;
            status[r] = dyad_solve(type, &row, &result);
            field[r] = result.field;
            ok += status[r] == DYAD_STATUS_OK;
            batch_store(block, r, &result);
        }
    }
    return ok;
}

static void write_statuses(const dyad_batch_output* output, size_t first, size_t rows,
                           const dyad_status status[], const dyad_field field[])
{
    size_t r;
    for (r = 0; output->status != NULL && r < rows; ++r) {
        output->status[first + r] = (unsigned char)status[r];
    }
    for (r = 0; output->field != NULL && r < rows; ++r) {
        output->field[first + r] = (unsigned char)field[r];
    }
}

/* Every row as dyad_solve reports a call it cannot make (unknown type, no input). */
static void refuse_all(dyad_type type, size_t count, const dyad_batch_output* output)
{
    batch_block block;
    dyad_status status[DYAD_BATCH_BLOCK];
    dyad_field field[DYAD_BATCH_BLOCK];
    dyad_result refused;
    size_t first, r;
    (void)dyad_solve(type, NULL, &refused);
    for (r = 0; r < DYAD_BATCH_BLOCK; ++r) {
        batch_store(&block, r, &refused);
        status[r] = refused.status;
        field[r] = refused.field;
    }
    for (first = 0; first < count; first += DYAD_BATCH_BLOCK) {
        const size_t rows = count - first < DYAD_BATCH_BLOCK ? count - first : DYAD_BATCH_BLOCK;
        scatter(output, first, rows, &block);
        write_statuses(output, first, rows, status, field);
    }
}

size_t dyad_solve_batch(dyad_type type, size_t count, const dyad_batch_input* input,
                        const dyad_batch_output* output)
{
    return dyad_solve_batch_at_most(DYAD_LANES_AVX512, type, count, input, output);
}

size_t dyad_solve_batch_at_most(dyad_lanes_isa cap, dyad_type type, size_t count,
                                const dyad_batch_input* input, const dyad_batch_output* output)
{
    const batch_lanes lanes = lanes_of(type, cap);
    batch_block block;
    dyad_status status[DYAD_BATCH_BLOCK];
    dyad_field field[DYAD_BATCH_BLOCK];
    size_t first, solved = 0;
    if (output == NULL) {
        return 0;
    }
    if (lanes == NULL || input == NULL) {
        refuse_all(type, count, output);
        return 0;
    }
    preset(input, &block);
    for (first = 0; first < count; first += DYAD_BATCH_BLOCK) {
        const size_t rows = count - first < DYAD_BATCH_BLOCK ? count - first : DYAD_BATCH_BLOCK;
        gather(input, first, rows, &block);
        lanes(rows, &block);
        solved += settle(type, rows, &block, status, field);
        scatter(output, first, rows, &block);
        write_statuses(output, first, rows, status, field);
    }
    return solved;
}
