/* dyadfmu: FMUs driven over given inputs, every output written bit for bit. The
 * same program is built for Linux and, with MinGW-w64, for Windows: run natively
 * it drives each FMU's Linux binary, run under Wine its Windows binary, over the
 * same inputs (scripts/tests/test_windows.py compares the two).
 *
 * Usage: fmu_replay JOBS
 *
 * JOBS has one run per line: "FMU_DIR INPUT_FILE OUTPUT_FILE" (paths without
 * spaces; FMU_DIR is the extracted FMU, build/fmus/stage/<id>_fmi<version>).
 * INPUT_FILE: "steps K step H inputs N" and the N value references, then K rows
 * of N input values. Each value is the 16 hex digits of a double's bit pattern,
 * which every C library reads and writes exactly.
 * OUTPUT_FILE: "reals R" and their value references, "integers I" and theirs
 * (every output of the FMU), then K lines, one per step: the status of doStep at
 * t = k H after setting row k, the R real outputs (bit patterns) and the I
 * integer outputs. Then "columns S", S the status dyadfmu_evaluate_columns
 * returns for the K rows in one call (the FMU's batch evaluation, its lanes where
 * it has them), and where S is 0 (an algebraic model) K lines: each row's status
 * and its R real outputs.
 *
 * Exits 0 when every run went through (whatever the FMU's statuses), 1 when a
 * file or an FMU could not be read or loaded, with the reason on stderr. */
#define _POSIX_C_SOURCE 200809L

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmu_probe.h"

enum { REPLAY_PATH = 4096 };

typedef struct replay_run {
    probe_model model;
    probe_fmi2 f2;
    probe_fmi3 f3;
    void* instance;
    probe_log_book book;
    unsigned* inputs;
    size_t n_inputs;
    unsigned *reals, *integers;
    size_t n_reals, n_integers;
} replay_run;

static int read_bits(FILE* file, double* value)
{
    char text[17];
    uint64_t bits;
    if (fscanf(file, " %16s", text) != 1) {
        return 0;
    }
    bits = (uint64_t)strtoull(text, NULL, 16);
    memcpy(value, &bits, sizeof bits);
    return 1;
}

/* The value references of the model's scalar outputs of one type. */
static unsigned* outputs_of(const probe_model* model, probe_type type, size_t* count)
{
    unsigned* vrs = (unsigned*)malloc((model->variable_count + 1) * sizeof *vrs);
    size_t k;
    *count = 0;
    for (k = 0; vrs != NULL && k < model->variable_count; ++k) {
        const probe_variable* v = &model->variables[k];
        if (v->causality == PROBE_OUTPUT && v->type == type && !v->is_array) {
            vrs[(*count)++] = v->vr;
        }
    }
    return vrs;
}

static int instantiate(replay_run* run)
{
    char error[600];
    if (run->model.fmi_version == 2) {
        fmi2CallbackFunctions callbacks;
        if (!probe_load_fmi2(&run->model, &run->f2, error, sizeof error)) {
            fprintf(stderr, "fmu_replay: %s\n", error);
            return 0;
        }
        callbacks = probe_fmi2_callbacks(&run->book);
        run->instance = run->f2.Instantiate("replay", fmi2CoSimulation, run->model.token, "",
                                            &callbacks, fmi2False, fmi2False);
        return run->instance != NULL &&
               run->f2.SetupExperiment(run->instance, fmi2False, 0, 0, fmi2False, 0) <=
                   fmi2Warning &&
               run->f2.EnterInitializationMode(run->instance) <= fmi2Warning &&
               run->f2.ExitInitializationMode(run->instance) <= fmi2Warning;
    }
    if (!probe_load_fmi3(&run->model, &run->f3, error, sizeof error)) {
        fprintf(stderr, "fmu_replay: %s\n", error);
        return 0;
    }
    run->instance = run->f3.InstantiateCoSimulation("replay", run->model.token, NULL, fmi3False,
                                                    fmi3False, fmi3False, fmi3False, NULL, 0,
                                                    &run->book, probe_fmi3_logger, NULL);
    return run->instance != NULL &&
           run->f3.EnterInitializationMode(run->instance, fmi3False, 0, 0, fmi3False, 0) <=
               fmi3Warning &&
           run->f3.ExitInitializationMode(run->instance) <= fmi3Warning;
}

static void write_reals(FILE* out, int status, const double* reals, size_t count)
{
    size_t j;
    fprintf(out, "%d", status);
    for (j = 0; j < count; ++j) {
        uint64_t bits;
        memcpy(&bits, &reals[j], sizeof bits);
        fprintf(out, " %016" PRIx64, bits);
    }
}

/* Sets the row's inputs, steps from t over h, and writes the status and outputs. */
static void step_and_write(replay_run* run, const double* row, double t, double h, double* reals,
                           int* integers, FILE* out)
{
    int status;
    size_t j;
    if (run->model.fmi_version == 2) {
        run->f2.SetReal(run->instance, run->inputs, run->n_inputs, row);
        status = (int)run->f2.DoStep(run->instance, t, h, fmi2True);
        run->f2.GetReal(run->instance, run->reals, run->n_reals, reals);
        run->f2.GetInteger(run->instance, run->integers, run->n_integers, integers);
    } else {
        fmi3Boolean event, terminate, early;
        fmi3Float64 last;
        run->f3.SetFloat64(run->instance, run->inputs, run->n_inputs, row, run->n_inputs);
        status =
            (int)run->f3.DoStep(run->instance, t, h, fmi3True, &event, &terminate, &early, &last);
        run->f3.GetFloat64(run->instance, run->reals, run->n_reals, reals, run->n_reals);
        run->f3.GetInt32(run->instance, run->integers, run->n_integers, integers, run->n_integers);
    }
    write_reals(out, status, reals, run->n_reals);
    for (j = 0; j < run->n_integers; ++j) {
        fprintf(out, " %d", integers[j]);
    }
    fputc('\n', out);
}

static void write_header(const replay_run* run, FILE* out)
{
    size_t j;
    fprintf(out, "reals %u", (unsigned)run->n_reals);
    for (j = 0; j < run->n_reals; ++j) {
        fprintf(out, " %u", run->reals[j]);
    }
    fprintf(out, "\nintegers %u", (unsigned)run->n_integers);
    for (j = 0; j < run->n_integers; ++j) {
        fprintf(out, " %u", run->integers[j]);
    }
    fputc('\n', out);
}

/* Reads the input file's header: steps, step size and input value references. */
static int read_header(replay_run* run, FILE* in, long* steps, double* h)
{
    unsigned n, j;
    if (fscanf(in, " steps %ld step", steps) != 1 || !read_bits(in, h) ||
        fscanf(in, " inputs %u", &n) != 1 || *steps < 1) {
        return 0;
    }
    run->inputs = (unsigned*)malloc((n + 1) * sizeof *run->inputs);
    run->n_inputs = n;
    for (j = 0; run->inputs != NULL && j < n; ++j) {
        if (fscanf(in, " %u", &run->inputs[j]) != 1) {
            return 0;
        }
    }
    return run->inputs != NULL;
}

/* Every row through dyadfmu_evaluate_columns in one call, written after the steps. */
typedef int (*replay_columns_fn)(const char* token, const unsigned int vr_x[], size_t n_x,
                                 const double* const x[], const ptrdiff_t x_step[],
                                 const unsigned int vr_y[], size_t n_y, double* const y[],
                                 const ptrdiff_t y_step[], int status[], size_t count);

static int replay_columns(const replay_run* run, const double* rows, long steps, FILE* out)
{
    void* library = run->model.fmi_version == 2 ? run->f2.library : run->f3.library;
    const size_t count = (size_t)steps;
    replay_columns_fn columns;
    char error[200];
    const double** x = (const double**)malloc((run->n_inputs + 1) * sizeof *x);
    double** y = (double**)malloc((run->n_reals + 1) * sizeof *y);
    ptrdiff_t* x_step = (ptrdiff_t*)malloc((run->n_inputs + 1) * sizeof *x_step);
    ptrdiff_t* y_step = (ptrdiff_t*)malloc((run->n_reals + 1) * sizeof *y_step);
    double* values = (double*)malloc((count * run->n_reals + 1) * sizeof *values);
    int* status = (int*)malloc(count * sizeof *status);
    int ok = x != NULL && y != NULL && x_step != NULL && y_step != NULL && values != NULL &&
             status != NULL &&
             probe_resolve(library, "dyadfmu_evaluate_columns", &columns, error, sizeof error);
    size_t j, k;
    for (j = 0; ok && j < run->n_inputs; ++j) {
        x[j] = rows + j;
        x_step[j] = (ptrdiff_t)run->n_inputs;
    }
    for (j = 0; ok && j < run->n_reals; ++j) {
        y[j] = values + j;
        y_step[j] = (ptrdiff_t)run->n_reals;
    }
    if (ok) {
        const int called = columns(run->model.token, run->inputs, run->n_inputs, x, x_step,
                                   run->reals, run->n_reals, y, y_step, status, count);
        fprintf(out, "columns %d\n", called);
        for (k = 0; called == 0 && k < count; ++k) {
            write_reals(out, status[k], values + k * run->n_reals, run->n_reals);
            fputc('\n', out);
        }
    }
    free((void*)x);
    free(y);
    free(x_step);
    free(y_step);
    free(values);
    free(status);
    return ok;
}

/* The steps of one run, then the columns entry over the same rows: returns 1, or 0 where
 * a row could not be read or the columns entry is missing. */
static int replay_steps(replay_run* run, FILE* in, FILE* out, long steps, double h)
{
    double* rows = (double*)malloc(((size_t)steps * run->n_inputs + 1) * sizeof *rows);
    double* reals = (double*)malloc((run->n_reals + 1) * sizeof *reals);
    int* integers = (int*)malloc((run->n_integers + 1) * sizeof *integers);
    int ok = rows != NULL && reals != NULL && integers != NULL;
    long k;
    size_t j;
    write_header(run, out);
    for (k = 0; ok && k < steps; ++k) {
        double* row = rows + (size_t)k * run->n_inputs;
        for (j = 0; ok && j < run->n_inputs; ++j) {
            ok = read_bits(in, &row[j]);
        }
        if (ok) {
            step_and_write(run, row, (double)k * h, h, reals, integers, out);
        }
    }
    ok = ok && replay_columns(run, rows, steps, out);
    free(rows);
    free(reals);
    free(integers);
    return ok;
}

static void release(replay_run* run)
{
    if (run->instance != NULL) {
        if (run->model.fmi_version == 2) {
            run->f2.FreeInstance(run->instance);
        } else {
            run->f3.FreeInstance(run->instance);
        }
    }
    probe_unload(run->model.fmi_version == 2 ? run->f2.library : run->f3.library);
    probe_free_model(&run->model);
    free(run->inputs);
    free(run->reals);
    free(run->integers);
}

static int replay(const char* directory, const char* input, const char* output)
{
    replay_run run;
    char error[600];
    FILE *in = NULL, *out = NULL;
    long steps = 0;
    double h = 0;
    int ok;
    memset(&run, 0, sizeof run);
    probe_log_book_clear(&run.book);
    if (!probe_read_model(directory, &run.model, error, sizeof error)) {
        fprintf(stderr, "fmu_replay: %s: %s\n", directory, error);
        return 0;
    }
    run.reals = outputs_of(&run.model, PROBE_REAL, &run.n_reals);
    run.integers = outputs_of(&run.model, PROBE_INTEGER, &run.n_integers);
    in = fopen(input, "r");
    out = fopen(output, "wb"); /* "\n" line ends on Windows too */
    ok = in != NULL && out != NULL && run.reals != NULL && run.integers != NULL &&
         read_header(&run, in, &steps, &h);
    if (!ok) {
        fprintf(stderr, "fmu_replay: cannot read %s or write %s\n", input, output);
    } else if (!instantiate(&run)) {
        fprintf(stderr, "fmu_replay: %s: cannot instantiate and initialise (%s)\n", directory,
                run.book.last);
        ok = 0;
    } else if (!replay_steps(&run, in, out, steps, h)) {
        fprintf(stderr, "fmu_replay: %s: a row of %s is short, or no dyadfmu_evaluate_columns\n",
                directory, input);
        ok = 0;
    }
    if (in != NULL) {
        fclose(in);
    }
    if (out != NULL) {
        ok = fclose(out) == 0 && ok;
    }
    release(&run);
    return ok;
}

int main(int argc, char** argv)
{
    char directory[REPLAY_PATH], input[REPLAY_PATH], output[REPLAY_PATH];
    FILE* jobs;
    int ok = 1, runs = 0;
    if (argc != 2 || strcmp(argv[1], "--help") == 0) {
        fprintf(stderr, "usage: fmu_replay JOBS (one line per run: FMU_DIR INPUT OUTPUT)\n"
                        "Drives each unpacked FMU over the inputs of its INPUT file and writes "
                        "every output's bit pattern and each doStep's status to OUTPUT (the "
                        "Windows comparison runs it under Wine and natively).\n");
        return argc == 2 ? 0 : 2;
    }
    jobs = fopen(argv[1], "r");
    if (jobs == NULL) {
        fprintf(stderr, "fmu_replay: cannot open %s\n", argv[1]);
        return 1;
    }
    while (fscanf(jobs, " %4095s %4095s %4095s", directory, input, output) == 3) {
        ok = replay(directory, input, output) && ok;
        ++runs;
    }
    fclose(jobs);
    printf("fmu_replay: %d runs\n", runs);
    return ok ? 0 : 1;
}
