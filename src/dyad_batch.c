/* dyadfmu: the solvers over columns of rows (see dyadfmu/batch.h).
 *
 * Rows go through the scalar solver in blocks: a block of dyad_inputs is filled
 * column by column (a column given once for every row is written into the block
 * once, before the first row), solved row by row, and its results are written out
 * column by column. The gather and scatter loops run over one column's rows, so
 * each is a short strided copy. */
#include "dyadfmu/batch.h"

#include "dyadfmu/dyad.h"

#include <stddef.h>

#define LINK_OFFSETS(g)                                                                           \
    offsetof(dyad_input, g.dir.x), offsetof(dyad_input, g.dir.y), offsetof(dyad_input, g.length), \
        offsetof(dyad_input, g.omega), offsetof(dyad_input, g.epsilon),                           \
        offsetof(dyad_input, g.accel_d.x), offsetof(dyad_input, g.accel_d.y),                     \
        offsetof(dyad_input, g.com.x), offsetof(dyad_input, g.com.y),                             \
        offsetof(dyad_input, g.mass), offsetof(dyad_input, g.inertia),                            \
        offsetof(dyad_input, g.force.x), offsetof(dyad_input, g.force.y),                         \
        offsetof(dyad_input, g.moment)

/* Where each column lives in a dyad_input. */
static const size_t input_offset[DYAD_INPUT_COLUMN_COUNT] = {
    LINK_OFFSETS(m),
    LINK_OFFSETS(n),
    offsetof(dyad_input, guide_k.x),
    offsetof(dyad_input, guide_k.y),
    offsetof(dyad_input, guide_p.x),
    offsetof(dyad_input, guide_p.y),
    offsetof(dyad_input, gravity.x),
    offsetof(dyad_input, gravity.y),
    offsetof(dyad_input, singular_threshold)};

/* Where each column lives in a dyad_result. */
static const size_t output_offset[DYAD_OUTPUT_COLUMN_COUNT] = {
    offsetof(dyad_result, r_mk.x),       offsetof(dyad_result, r_mk.y),
    offsetof(dyad_result, r_np.x),       offsetof(dyad_result, r_np.y),
    offsetof(dyad_result, r_mn.x),       offsetof(dyad_result, r_mn.y),
    offsetof(dyad_result, n_mk),         offsetof(dyad_result, n_np),
    offsetof(dyad_result, n_mn),         offsetof(dyad_result, m_mk),
    offsetof(dyad_result, m_np),         offsetof(dyad_result, m_mn),
    offsetof(dyad_result, denominator),  offsetof(dyad_result, conditioning),
    offsetof(dyad_result, amplification)};

static dyad_solver solver_of(dyad_type type)
{
    switch (type) {
    case DYAD_RRR: return dyad_solve_rrr;
    case DYAD_RRT: return dyad_solve_rrt;
    case DYAD_RTR: return dyad_solve_rtr;
    case DYAD_TRT: return dyad_solve_trt;
    case DYAD_RTT: return dyad_solve_rtt;
    case DYAD_TYPE_COUNT: break;
    }
    return NULL;
}

static dyad_real* input_member(dyad_input* row, int column)
{
    return (dyad_real*)(void*)((char*)row + input_offset[column]);
}

/* Every row of the block: the defaults, then the columns given once for all rows. */
static void preset(const dyad_batch_input* input, dyad_input block[])
{
    int c;
    size_t r;
    block[0] = dyad_input_default();
    for (c = 0; c < DYAD_INPUT_COLUMN_COUNT; ++c) {
        const dyad_input_array* column = &input->column[c];
        if (column->data != NULL && column->stride == 0) {
            *input_member(&block[0], c) = column->data[0];
        }
    }
    for (r = 1; r < DYAD_BATCH_BLOCK; ++r) {
        block[r] = block[0];
    }
}

/* One column's rows into the block; inlined with rows a constant for a whole
 * block, so that the copy unrolls. */
static inline void gather_column(const dyad_input_array* column, size_t offset, size_t first,
                                 size_t rows, dyad_input block[])
{
    const ptrdiff_t stride = column->stride;
    const dyad_real* source = column->data + (ptrdiff_t)first * stride;
    size_t r;
    for (r = 0; r < rows; ++r) {
        *(dyad_real*)(void*)((char*)&block[r] + offset) = source[(ptrdiff_t)r * stride];
    }
}

/* The copies of the common layouts, each its own function: inlined, their unrolled
 * moves would crowd the general copies out of unrolling. */
#if defined(__GNUC__)
#define BATCH_OUT_OF_LINE __attribute__((noinline))
#else
#define BATCH_OUT_OF_LINE
#endif

/* A whole block of a column of its own (stride 1: a NumPy array of one field), as
 * plain moves. */
BATCH_OUT_OF_LINE static void gather_contiguous(const dyad_real* source, size_t offset,
                                                dyad_input block[])
{
    size_t r;
    for (r = 0; r < DYAD_BATCH_BLOCK; ++r) {
        *(dyad_real*)(void*)((char*)&block[r] + offset) = source[r];
    }
}

/* A whole block of x and y of an (N, 2) array (stride 2), as plain moves. */
BATCH_OUT_OF_LINE static void gather_pairs(const dyad_real* source, size_t offset,
                                           dyad_input block[])
{
    size_t r;
    for (r = 0; r < DYAD_BATCH_BLOCK; ++r) {
        *(dyad_real*)(void*)((char*)&block[r] + offset) = source[2 * r];
    }
}

/* Rows first .. first + rows - 1 of the columns that vary by row. */
static void gather(const dyad_batch_input* input, size_t first, size_t rows, dyad_input block[])
{
    int c;
    for (c = 0; c < DYAD_INPUT_COLUMN_COUNT; ++c) {
        const dyad_input_array* column = &input->column[c];
        if (column->data != NULL && column->stride != 0) {
            if (rows == DYAD_BATCH_BLOCK && column->stride == 1) {
                gather_contiguous(column->data + first, input_offset[c], block);
            } else if (rows == DYAD_BATCH_BLOCK && column->stride == 2) {
                gather_pairs(column->data + 2 * first, input_offset[c], block);
            } else if (rows == DYAD_BATCH_BLOCK) {
                gather_column(column, input_offset[c], first, DYAD_BATCH_BLOCK, block);
            } else {
                gather_column(column, input_offset[c], first, rows, block);
            }
        }
    }
}

static inline void scatter_column(const dyad_output_array* column, size_t offset, size_t first,
                                  size_t rows, const dyad_result results[])
{
    const ptrdiff_t stride = column->stride;
    dyad_real* target = column->data + (ptrdiff_t)first * stride;
    size_t r;
    for (r = 0; r < rows; ++r) {
        target[(ptrdiff_t)r * stride] =
            *(const dyad_real*)(const void*)((const char*)&results[r] + offset);
    }
}

/* A whole block into a column of its own (stride 1), as plain moves. */
BATCH_OUT_OF_LINE static void scatter_contiguous(dyad_real* target, size_t offset,
                                                 const dyad_result results[])
{
    size_t r;
    for (r = 0; r < DYAD_BATCH_BLOCK; ++r) {
        target[r] = *(const dyad_real*)(const void*)((const char*)&results[r] + offset);
    }
}

/* A whole block into x or y of an (N, 2) array (stride 2), as plain moves. */
BATCH_OUT_OF_LINE static void scatter_pairs(dyad_real* target, size_t offset,
                                            const dyad_result results[])
{
    size_t r;
    for (r = 0; r < DYAD_BATCH_BLOCK; ++r) {
        target[2 * r] = *(const dyad_real*)(const void*)((const char*)&results[r] + offset);
    }
}

static void scatter(const dyad_batch_output* output, size_t first, size_t rows,
                    const dyad_result results[])
{
    int c;
    size_t r;
    for (c = 0; c < DYAD_OUTPUT_COLUMN_COUNT; ++c) {
        const dyad_output_array* column = &output->column[c];
        if (column->data != NULL) {
            if (rows == DYAD_BATCH_BLOCK && column->stride == 1) {
                scatter_contiguous(column->data + first, output_offset[c], results);
            } else if (rows == DYAD_BATCH_BLOCK && column->stride == 2) {
                scatter_pairs(column->data + 2 * first, output_offset[c], results);
            } else if (rows == DYAD_BATCH_BLOCK) {
                scatter_column(column, output_offset[c], first, DYAD_BATCH_BLOCK, results);
            } else {
                scatter_column(column, output_offset[c], first, rows, results);
            }
        }
    }
    for (r = 0; output->status != NULL && r < rows; ++r) {
        output->status[first + r] = (unsigned char)results[r].status;
    }
    for (r = 0; output->field != NULL && r < rows; ++r) {
        output->field[first + r] = (unsigned char)results[r].field;
    }
}

/* Every row as dyad_solve reports a call it cannot make (unknown type, no input). */
static void refuse_all(dyad_type type, size_t count, const dyad_batch_output* output)
{
    dyad_result refused[DYAD_BATCH_BLOCK];
    size_t first, r;
    (void)dyad_solve(type, NULL, &refused[0]);
    for (r = 1; r < DYAD_BATCH_BLOCK; ++r) {
        refused[r] = refused[0];
    }
    for (first = 0; first < count; first += DYAD_BATCH_BLOCK) {
        const size_t rows = count - first < DYAD_BATCH_BLOCK ? count - first : DYAD_BATCH_BLOCK;
        scatter(output, first, rows, refused);
    }
}

size_t dyad_solve_batch(dyad_type type, size_t count, const dyad_batch_input* input,
                        const dyad_batch_output* output)
{
    const dyad_solver solve = solver_of(type);
    dyad_input block[DYAD_BATCH_BLOCK];
    dyad_result results[DYAD_BATCH_BLOCK];
    size_t first, r, solved = 0;
    if (output == NULL) {
        return 0;
    }
    if (solve == NULL || input == NULL) {
        refuse_all(type, count, output);
        return 0;
    }
    preset(input, block);
    for (first = 0; first < count; first += DYAD_BATCH_BLOCK) {
        const size_t rows = count - first < DYAD_BATCH_BLOCK ? count - first : DYAD_BATCH_BLOCK;
        gather(input, first, rows, block);
        for (r = 0; r < rows; ++r) {
            solved += solve(&block[r], &results[r]) == DYAD_STATUS_OK;
        }
        scatter(output, first, rows, results);
    }
    return solved;
}
