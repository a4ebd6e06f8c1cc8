/* dyadfmu FMU layer: a dyad as an FMU model (see fmu_dyad.h). */
#include "fmu_dyad.h"

#include <math.h>
#include <stdio.h>

/* The variables' offsets address doubles: the FMUs use the double core. */
typedef char fmu_dyad_real_is_double[sizeof(dyad_real) == sizeof(double) ? 1 : -1];

static int variable_of_field(const fmu_model* model, dyad_field field)
{
    const fmu_dyad_data* dyad = (const fmu_dyad_data*)model->data;
    size_t k;
    for (k = 0; k < dyad->feed_count; ++k) {
        if (dyad->feeds[k].field == field) {
            return dyad->feeds[k].variable;
        }
    }
    return -1;
}

/* Why a solve failed, for the log. */
FMU_COLD static void report_failure(const fmu_model* model, const dyad_input* input,
                                    const dyad_result* result, fmu_evaluation* evaluation)
{
    evaluation->bad_variable = -1;
    evaluation->reason[0] = '\0';
    switch (result->status) {
    case DYAD_STATUS_OK: evaluation->status = FMU_OK; break;
    case DYAD_STATUS_SINGULAR:
        evaluation->status = FMU_DISCARD;
        snprintf(evaluation->reason, sizeof evaluation->reason,
                 "singular configuration: conditioning %.3g is below singular_threshold %.3g; "
                 "the dyad cannot carry its load, reactions are NaN",
                 (double)result->conditioning, (double)input->singular_threshold);
        break;
    case DYAD_STATUS_OUT_OF_RANGE:
        evaluation->status = FMU_DISCARD;
        snprintf(evaluation->reason, sizeof evaluation->reason,
                 "the loads or reactions overflow double; reactions are NaN");
        break;
    case DYAD_STATUS_INVALID_INPUT:
        evaluation->status = FMU_ERROR;
        evaluation->bad_variable = variable_of_field(model, result->field);
        snprintf(evaluation->reason, sizeof evaluation->reason, "not valid for this dyad (%s)",
                 dyad_field_name(result->field));
        break;
    case DYAD_STATUS_CANNOT_ASSEMBLE: /* the kinematics' status: no solver returns it */
        evaluation->status = FMU_ERROR;
        snprintf(evaluation->reason, sizeof evaluation->reason, "unexpected status %s",
                 dyad_status_name(result->status));
        break;
    }
}

static void report(const fmu_model* model, const dyad_input* input, const dyad_result* result,
                   fmu_evaluation* evaluation)
{
    if (result->status == DYAD_STATUS_OK) {
        evaluation->status = FMU_OK;
        evaluation->bad_variable = -1;
        evaluation->reason[0] = '\0';
        return;
    }
    report_failure(model, input, result, evaluation);
}

void fmu_dyad_initialise(const fmu_model* model, void* input)
{
    (void)model;
    *(dyad_input*)input = dyad_input_default();
}

/* The layer checks every value against its variable's bounds where it is set (and
 * a deserialized FMU state's values likewise), and a dyad's bounds are its fields'
 * domains (an angle gives a unit direction, computed again after a state is
 * restored), so the common solve skips the core's check of its input. Where that
 * solve has no answer, the checking solve runs again to say whether an input is to
 * blame. */
void fmu_dyad_evaluate(const fmu_model* model, const void* input, void* output,
                       fmu_evaluation* evaluation)
{
    const fmu_dyad_data* dyad = (const fmu_dyad_data*)model->data;
    if (dyad->solve_valid((const dyad_input*)input, (dyad_result*)output) != DYAD_STATUS_OK) {
        dyad->solve((const dyad_input*)input, (dyad_result*)output);
    }
    report(model, (const dyad_input*)input, (const dyad_result*)output, evaluation);
}

/* The first Real output whose rate is not finite, or -1. */
static int nonfinite_rate(const fmu_model* model, const void* rate)
{
    size_t k;
    for (k = 0; k < model->variable_count; ++k) {
        const fmu_variable* v = &model->variables[k];
        if (v->causality == FMU_OUTPUT && v->target == FMU_TARGET_RESULT_REAL &&
            !isfinite(*(const double*)(const void*)((const char*)rate + v->offset))) {
            return (int)k;
        }
    }
    return -1;
}

/* A finite but huge seed (DBL_MAX, or two seeds of 1e308 for one known, which the
 * layer adds up to inf) overflows the tangent while the outputs themselves are fine:
 * the derivative has no value in double, so it is refused as the scene FMUs refuse it
 * rather than returned as NaN with OK. */
FMU_COLD static void refuse_rate(const fmu_model* model, int bad, fmu_evaluation* evaluation)
{
    evaluation->status = FMU_DISCARD;
    evaluation->bad_variable = -1; /* no input to blame */
    snprintf(evaluation->reason, sizeof evaluation->reason,
             "the directional derivative is not finite at these inputs (the rate of %s)",
             model->variables[bad].name);
}

void fmu_dyad_derivative(const fmu_model* model, const void* input, const void* seed, void* output,
                         void* rate, fmu_evaluation* evaluation)
{
    const fmu_dyad_data* dyad = (const fmu_dyad_data*)model->data;
    dyad_solve_tangent_of(dyad->tangent, (const dyad_input*)input, (const dyad_input*)seed,
                          (dyad_result*)output, (dyad_result*)rate);
    report(model, (const dyad_input*)input, (const dyad_result*)output, evaluation);
    if (evaluation->status == FMU_OK) {
        /* a solve of the tangent's loads that fails leaves its rates NaN */
        const int bad = nonfinite_rate(model, rate);
        if (bad >= 0) {
            refuse_rate(model, bad, evaluation);
        }
    }
}
