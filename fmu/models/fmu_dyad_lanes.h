/* dyadfmu FMU layer: a generic dyad FMU's many samples at once (fmu_lanes), for the
 * columns entry. Its generated <id>_model.c defines DYAD_LANES_<TYPE> for its one type,
 * includes this header and writes FMU_DYAD_LANES(<type>): it links no other type.
 *
 * The lanes' grid holds the input block's reals (dyad_input, every member a real, in the
 * order of dyad_input_column), then the output block's (dyad_result: its status and field
 * share the first real, its reals follow in the order of dyad_output_column), then the
 * count of failed checks: a column each, FMU_DYAD_LANE_COUNT samples deep. One loop over
 * the samples solves each by the type's lane (src/dyad_lanes.h: dyad_solve_<type> without
 * a branch, its checks counted), which the compiler vectorises. A sample that passes every
 * check has dyad_solve_valid_<type>'s outputs bit for bit, which fmu_dyad_evaluate gives it
 * alone; the layer evaluates any other alone, for its status and reason. As a scene's
 * lanes, compiled for the baseline, AVX2 and AVX-512, and each call takes the widest the
 * CPU runs up to its cap. */
#ifndef DYADFMU_FMU_DYAD_LANES_H
#define DYADFMU_FMU_DYAD_LANES_H

#define DYAD_LANES_NO_KINEMATICS
#include "dyad_lanes.h"
#include "fmu_dyad.h"

#include <stddef.h>

/* Samples a call of the lanes takes at most. */
#define FMU_DYAD_LANE_COUNT  64
#define FMU_DYAD_ONE(member) +1
#define FMU_DYAD_LANE_INPUTS (0 DYAD_LANE_INPUT_MEMBERS(FMU_DYAD_ONE))
/* the status and field's real, then the reals */
#define FMU_DYAD_LANE_OUTPUTS (1 DYAD_LANE_OUTPUT_MEMBERS(FMU_DYAD_ONE))
/* the count of failed checks after the outputs */
#define FMU_DYAD_LANE_FAILED (FMU_DYAD_LANE_INPUTS + FMU_DYAD_LANE_OUTPUTS)

/* The grid's columns are the blocks' reals at their offsets (the layer places them so):
 * every member of dyad_input listed, and dyad_result's after its status and field. */
#define FMU_DYAD_INPUT_FITS (sizeof(dyad_input) == FMU_DYAD_LANE_INPUTS * sizeof(double))
#define FMU_DYAD_RESULT_FITS                                          \
    (sizeof(dyad_result) == FMU_DYAD_LANE_OUTPUTS * sizeof(double) && \
     offsetof(dyad_result, r_mk) == sizeof(double))
typedef char fmu_dyad_input_is_its_columns[FMU_DYAD_INPUT_FITS ? 1 : -1];
typedef char fmu_dyad_result_is_its_columns[FMU_DYAD_RESULT_FITS ? 1 : -1];

#define FMU_DYAD_READ(member)  row.member = lanes[column++ * FMU_DYAD_LANE_COUNT + i];
#define FMU_DYAD_WRITE(member) lanes[column++ * FMU_DYAD_LANE_COUNT + i] = result.member;

/* The loop of the type's lane over the first `count` samples of the grid. */
#define FMU_DYAD_LANE_LOOP(name, suffix, attributes)                                  \
    attributes static void fmu_dyad_lanes_##name##suffix(size_t count, double* lanes) \
    {                                                                                 \
        size_t i;                                                                     \
        for (i = 0; i < count; ++i) {                                                 \
            dyad_input row;                                                           \
            dyad_result result;                                                       \
            size_t column = 0;                                                        \
            double failed;                                                            \
            DYAD_LANE_INPUT_MEMBERS(FMU_DYAD_READ)                                    \
            failed = dyad_solve_lane_##name(&row, &result);                           \
            column = FMU_DYAD_LANE_INPUTS + 1;                                        \
            DYAD_LANE_OUTPUT_MEMBERS(FMU_DYAD_WRITE)                                  \
            lanes[FMU_DYAD_LANE_FAILED * FMU_DYAD_LANE_COUNT + i] = failed;           \
        }                                                                             \
    }

/* The lanes of each instruction set and fmu_lanes.whole, which takes the widest up to
 * `cap`; every output is computed (`wanted` aside: they cost little beside the solve). */
#if DYAD_LANES_HAVE_AVX512
#define FMU_DYAD_LANE_LOOPS(name)                           \
    FMU_DYAD_LANE_LOOP(name, , )                            \
    FMU_DYAD_LANE_LOOP(name, _avx2, DYAD_LANES_AVX2_TARGET) \
    FMU_DYAD_LANE_LOOP(name, _avx512, DYAD_LANES_AVX512_TARGET)
#define FMU_DYAD_LANE_WHOLE(name)                                               \
    static void fmu_dyad_whole(dyad_lanes_isa cap, size_t count, double* lanes, \
                               const unsigned char* wanted)                     \
    {                                                                           \
        const dyad_lanes_isa widest = dyad_lanes_widest(cap);                   \
        (void)wanted;                                                           \
        if (widest == DYAD_LANES_AVX512) {                                      \
            fmu_dyad_lanes_##name##_avx512(count, lanes);                       \
        } else if (widest == DYAD_LANES_AVX2) {                                 \
            fmu_dyad_lanes_##name##_avx2(count, lanes);                         \
        } else {                                                                \
            fmu_dyad_lanes_##name(count, lanes);                                \
        }                                                                       \
    }
#else
#define FMU_DYAD_LANE_LOOPS(name) FMU_DYAD_LANE_LOOP(name, , )
#define FMU_DYAD_LANE_WHOLE(name)                                               \
    static void fmu_dyad_whole(dyad_lanes_isa cap, size_t count, double* lanes, \
                               const unsigned char* wanted)                     \
    {                                                                           \
        (void)cap;                                                              \
        (void)wanted;                                                           \
        fmu_dyad_lanes_##name(count, lanes);                                    \
    }
#endif

/* The lanes of type `name` (rrr, ...) and the behaviour on them, fmu_dyad_lane_behaviour. */
#define FMU_DYAD_LANES(name)                                          \
    FMU_DYAD_LANE_LOOPS(name)                                         \
    FMU_DYAD_LANE_WHOLE(name)                                         \
    static const fmu_lanes fmu_dyad_many = {FMU_DYAD_LANE_COUNT,      \
                                            FMU_DYAD_LANE_INPUTS,     \
                                            FMU_DYAD_LANE_OUTPUTS,    \
                                            FMU_DYAD_LANE_FAILED + 1, \
                                            fmu_dyad_whole,           \
                                            NULL,                     \
                                            NULL,                     \
                                            NULL};                    \
    static const fmu_behaviour fmu_dyad_lane_behaviour = FMU_DYAD_BEHAVIOUR(&fmu_dyad_many);

#endif /* DYADFMU_FMU_DYAD_LANES_H */
