/* dyadfmu: the solvers over columns of rows (see dyadfmu/batch.h).
 *
 * Rows go through the scalar solver in blocks: a block of dyad_inputs is filled
 * column by column (a column given once for every row is written into the block
 * once, before the first row), solved row by row, and its results are written out
 * column by column. The gather and scatter loops run over one column's rows, so
 * each is a short strided copy. How each column of a whole block is copied is
 * decided once per call, with loops of their own for the layouts NumPy gives
 * dyadfmu.solve: a field's rows contiguous, or x and y of an (N, 2) array, which
 * fill adjacent members and so move together. */
#include "dyadfmu/batch.h"

#include "dyadfmu/dyad.h"

#include <stddef.h>
#include <string.h>

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

/* A whole block of x and y of an (N, 2) array at once: both members of a vector of
 * dyad_input, adjacent there too. */
BATCH_OUT_OF_LINE static void gather_vectors(const dyad_real* source, size_t offset,
                                             dyad_input block[])
{
    size_t r;
    for (r = 0; r < DYAD_BATCH_BLOCK; ++r) {
        memcpy((char*)&block[r] + offset, source + 2 * r, 2 * sizeof *source);
    }
}

/* Whether columns c and c + 1 are x and y of one (N, 2) array that fill adjacent
 * members: then one copy moves both. */
static int adjacent_pair(const dyad_real* x, ptrdiff_t x_stride, const dyad_real* y,
                         ptrdiff_t y_stride, size_t x_offset, size_t y_offset)
{
    return x != NULL && x_stride == 2 && y == x + 1 && y_stride == 2 &&
           y_offset == x_offset + sizeof *x;
}

/* How a whole block copies each input column, decided once per call. */
typedef enum copy_kind {
    COPY_NONE = 0,   /* the block holds its value already (preset), or column c - 1 copies it */
    COPY_VECTOR,     /* this column and the next, x and y of an (N, 2) array */
    COPY_CONTIGUOUS, /* stride 1 */
    COPY_PAIRS,      /* stride 2 alone */
    COPY_GENERAL     /* any other stride */
} copy_kind;

static void plan_gather(const dyad_batch_input* input, unsigned char kinds[])
{
    int c;
    for (c = 0; c < DYAD_INPUT_COLUMN_COUNT; ++c) {
        const dyad_input_array* column = &input->column[c];
        kinds[c] = COPY_NONE;
        if (column->data == NULL || column->stride == 0) {
            continue;
        }
        if (c + 1 < DYAD_INPUT_COLUMN_COUNT &&
            adjacent_pair(column->data, column->stride, input->column[c + 1].data,
                          input->column[c + 1].stride, input_offset[c], input_offset[c + 1])) {
            kinds[c] = COPY_VECTOR;
            kinds[++c] = COPY_NONE;
        } else {
            kinds[c] = column->stride == 1   ? COPY_CONTIGUOUS
                       : column->stride == 2 ? COPY_PAIRS
                                             : COPY_GENERAL;
        }
    }
}

/* Rows first .. first + rows - 1 of the columns that vary by row. */
static void gather(const dyad_batch_input* input, const unsigned char kinds[], size_t first,
                   size_t rows, dyad_input block[])
{
    int c;
    for (c = 0; c < DYAD_INPUT_COLUMN_COUNT; ++c) {
        const dyad_input_array* column = &input->column[c];
        if (rows < DYAD_BATCH_BLOCK) {
            if (column->data != NULL && column->stride != 0) {
                gather_column(column, input_offset[c], first, rows, block);
            }
            continue;
        }
        switch ((copy_kind)kinds[c]) {
        case COPY_NONE: break;
        case COPY_VECTOR: gather_vectors(column->data + 2 * first, input_offset[c], block); break;
        case COPY_CONTIGUOUS:
            gather_contiguous(column->data + first, input_offset[c], block);
            break;
        case COPY_PAIRS: gather_pairs(column->data + 2 * first, input_offset[c], block); break;
        case COPY_GENERAL:
            gather_column(column, input_offset[c], first, DYAD_BATCH_BLOCK, block);
            break;
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

/* A whole block into x and y of an (N, 2) array at once, from adjacent members. */
BATCH_OUT_OF_LINE static void scatter_vectors(dyad_real* target, size_t offset,
                                              const dyad_result results[])
{
    size_t r;
    for (r = 0; r < DYAD_BATCH_BLOCK; ++r) {
        memcpy(target + 2 * r, (const char*)&results[r] + offset, 2 * sizeof *target);
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
            if (rows == DYAD_BATCH_BLOCK && c + 1 < DYAD_OUTPUT_COLUMN_COUNT &&
                adjacent_pair(column->data, column->stride, output->column[c + 1].data,
                              output->column[c + 1].stride, output_offset[c],
                              output_offset[c + 1])) {
                scatter_vectors(column->data + 2 * first, output_offset[c], results);
                ++c;
            } else if (rows == DYAD_BATCH_BLOCK && column->stride == 1) {
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
    unsigned char kinds[DYAD_INPUT_COLUMN_COUNT];
    size_t first, r, solved = 0;
    if (output == NULL) {
        return 0;
    }
    if (solve == NULL || input == NULL) {
        refuse_all(type, count, output);
        return 0;
    }
    preset(input, block);
    plan_gather(input, kinds);
    for (first = 0; first < count; first += DYAD_BATCH_BLOCK) {
        const size_t rows = count - first < DYAD_BATCH_BLOCK ? count - first : DYAD_BATCH_BLOCK;
        gather(input, kinds, first, rows, block);
        for (r = 0; r < rows; ++r) {
            solved += solve(&block[r], &results[r]) == DYAD_STATUS_OK;
        }
        scatter(output, first, rows, results);
    }
    return solved;
}
