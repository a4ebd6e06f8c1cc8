/* dyadfmu: instances of one FMU in several threads at once, each its own
 * instance fed the same sequence of calls, compared bit for bit with one
 * instance run alone. scripts/run-tests runs it on a ThreadSanitizer build of
 * the FMUs and of this test (build-tsan), where any data race between
 * instances (shared mutable state in the FMU) is reported and fails the test;
 * elsewhere it checks that instances in threads compute what one alone does.
 *
 * The sequence comes from a seed: parameters and inputs (mostly plausible, now
 * and then NaN, infinite, -0 or the smallest double), doStep with small step sizes, and every
 * variable read after each step; each thread instantiates, runs it, and frees
 * its instance, twice. Each step starts where the instance's last accepted step
 * ended, as an importer steps on (a model with states, the drive or a plant, refuses
 * a step that does not start at its time): a step refused with Error fails the test,
 * so that every step is one the model computes. A model with states that discards a
 * step stopped where its motion has no answer (a plant at a dead centre); the instance
 * is then reset and initialised again, and steps on from the start.
 *
 * Usage: fmu_threads [--threads N] [--steps N] [--seed S] FMU_DIR
 */
#define _POSIX_C_SOURCE 200809L

#include <float.h>
#include <inttypes.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmu_probe.h"

enum { OP_SET, OP_STEP, OP_ENTER, OP_EXIT };

typedef struct thread_op {
    int kind;
    unsigned vr;
    double value; /* OP_SET */
    double h;     /* OP_STEP: the step size; it starts where the last accepted step ended */
} thread_op;

typedef struct thread_program {
    probe_model model;
    probe_fmi2 f2;
    probe_fmi3 f3;
    thread_op* ops;
    size_t count;
    unsigned* real_vrs;
    size_t n_reals;
    unsigned* integer_vrs;
    size_t n_integers;
} thread_program;

/* What the steps of one run returned. */
typedef struct step_counts {
    long ok, discarded, refused;
} step_counts;

typedef struct thread_run {
    const thread_program* program;
    pthread_barrier_t* start;
    int index;
    int ok;
    uint64_t* trace; /* one hash per operation */
} thread_run;

static const int runs_per_thread = 2;

/* A value for a variable: now and then an awkward one, otherwise its start value moved
 * by up to 10 % (a start of 0 by up to 0.1 upwards: a drive's load.inertia below
 * -inertia is an input its steps refuse). The awkward values are those every setter
 * refuses (NaN, inf) and, for an input, -0 and the smallest double; nothing huge: a
 * model with states that took one (a drive's load.torque of DBL_MAX) would reach a
 * speed that no later step can integrate, and a parameter holds for the whole run.
 * Huge values are fmu_fuzz's and fmu_api_tests'. */
static double some_value(probe_rng* rng, const probe_variable* v)
{
    static const double awkward[] = {NAN, INFINITY, -INFINITY, -0.0, 4.9406564584124654e-324};
    const uint64_t refused_by_setters = 3;
    const double start = v->has_start ? v->start : 0.0;
    if (probe_rng_below(rng, 10) == 0) {
        return awkward[probe_rng_below(rng, v->causality == PROBE_PARAMETER
                                                ? refused_by_setters
                                                : sizeof awkward / sizeof awkward[0])];
    }
    if (start == 0) {
        return 0.1 * probe_rng_uniform(rng);
    }
    return start * (1 + 0.1 * (2 * probe_rng_uniform(rng) - 1));
}

/* The calls every instance makes, from the seed. */
static int make_program(thread_program* p, long steps, uint64_t seed)
{
    probe_rng rng;
    size_t k, capacity = (size_t)steps * 4 + p->model.variable_count + 8, settable = 0;
    long s;
    const probe_variable** inputs;
    probe_rng_seed(&rng, seed);
    p->ops = (thread_op*)calloc(capacity, sizeof *p->ops);
    p->real_vrs = (unsigned*)calloc(p->model.variable_count + 1, sizeof *p->real_vrs);
    p->integer_vrs = (unsigned*)calloc(p->model.variable_count + 1, sizeof *p->integer_vrs);
    inputs = (const probe_variable**)calloc(p->model.variable_count + 1, sizeof *inputs);
    if (p->ops == NULL || p->real_vrs == NULL || p->integer_vrs == NULL || inputs == NULL) {
        free((void*)inputs);
        return 0;
    }
    for (k = 0; k < p->model.variable_count; ++k) {
        const probe_variable* v = &p->model.variables[k];
        if (v->causality == PROBE_INDEPENDENT) {
            continue;
        }
        if (v->type == PROBE_REAL) {
            p->real_vrs[p->n_reals++] = v->vr;
        } else if (v->type == PROBE_INTEGER) {
            p->integer_vrs[p->n_integers++] = v->vr;
        }
        if (v->type == PROBE_REAL && v->causality == PROBE_PARAMETER &&
            probe_rng_below(&rng, 2) == 0) {
            thread_op* op = &p->ops[p->count++];
            op->kind = OP_SET;
            op->vr = v->vr;
            op->value = some_value(&rng, v);
        }
        if (v->type == PROBE_REAL && v->causality == PROBE_INPUT) {
            inputs[settable++] = v;
        }
    }
    p->ops[p->count++].kind = OP_ENTER;
    p->ops[p->count++].kind = OP_EXIT;
    for (s = 0; s < steps; ++s) {
        const size_t sets = settable > 0 ? (size_t)probe_rng_below(&rng, 3) : 0;
        thread_op* op;
        for (k = 0; k < sets; ++k) {
            const probe_variable* v = inputs[probe_rng_below(&rng, settable)];
            op = &p->ops[p->count++];
            op->kind = OP_SET;
            op->vr = v->vr;
            op->value = some_value(&rng, v);
        }
        op = &p->ops[p->count++];
        op->kind = OP_STEP;
        op->h = pow(10.0, -4.0 + 2.0 * probe_rng_uniform(&rng));
    }
    free((void*)inputs);
    return 1;
}

/* One doStep from `t`; the hash of what it returned (FMI 3: with its last
 * successful time and whether it terminated) goes into *h, and the last successful
 * time into *last. */
static int step_once(const thread_program* p, void* c, double t, double size, uint64_t* h,
                     double* last)
{
    fmi3Boolean event, terminate, early;
    int status;
    if (p->model.fmi_version == 2) {
        status = (int)p->f2.DoStep(c, t, size, fmi2True);
        if (status == fmi2Discard && p->f2.GetRealStatus(c, fmi2LastSuccessfulTime, last) != 0) {
            *last = NAN;
        }
        *h = probe_hash_double(*h, *last);
        return status;
    }
    status = (int)p->f3.DoStep(c, t, size, fmi3True, &event, &terminate, &early, last);
    *h = probe_hash_double(probe_hash_u64(*h, (uint64_t)terminate), *last);
    return status;
}

/* Resets the instance and initialises it again from t = 0: the sum of the statuses. */
static int restart(const thread_program* p, void* c)
{
    if (p->model.fmi_version == 2) {
        return (int)p->f2.Reset(c) + (int)p->f2.SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) +
               (int)p->f2.EnterInitializationMode(c) + (int)p->f2.ExitInitializationMode(c);
    }
    return (int)p->f3.Reset(c) +
           (int)p->f3.EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0) +
           (int)p->f3.ExitInitializationMode(c);
}

/* Runs the program on a fresh instance; trace[k] is the hash of what call k
 * returned and every variable read after it. Each step starts where the last step
 * that returned OK or Warning ended; `counts` (NULL: none) gets what the steps
 * returned. */
static int run_program(const thread_program* p, int index, uint64_t* trace, step_counts* counts)
{
    double now = 0, last = 0;
    const int fmi2 = p->model.fmi_version == 2;
    const int has_states = probe_has_states(&p->model);
    probe_log_book book;
    char name[32];
    double* reals = (double*)calloc(p->n_reals + 1, sizeof *reals);
    int* integers = (int*)calloc(p->n_integers + 1, sizeof *integers);
    void* c;
    size_t k, j;
    if (reals == NULL || integers == NULL) {
        free(reals);
        free(integers);
        return 0;
    }
    probe_log_book_clear(&book);
    sprintf(name, "thread %d", index);
    if (fmi2) {
        fmi2CallbackFunctions callbacks = probe_fmi2_callbacks(&book);
        c = p->f2.Instantiate(name, fmi2CoSimulation, p->model.token, "", &callbacks, fmi2False,
                              fmi2True);
    } else {
        c = p->f3.InstantiateCoSimulation(name, p->model.token, NULL, fmi3False, fmi3True,
                                          fmi3False, fmi3False, NULL, 0, &book, probe_fmi3_logger,
                                          NULL);
    }
    if (c == NULL) {
        free(reals);
        free(integers);
        return 0;
    }
    for (k = 0; k < p->count; ++k) {
        const thread_op* op = &p->ops[k];
        uint64_t h = PROBE_HASH_START;
        int status = 0;
        switch (op->kind) {
        case OP_SET:
            status = fmi2 ? (int)p->f2.SetReal(c, &op->vr, 1, &op->value)
                          : (int)p->f3.SetFloat64(c, &op->vr, 1, &op->value, 1);
            break;
        case OP_ENTER:
            status = fmi2 ? (int)p->f2.SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) +
                                (int)p->f2.EnterInitializationMode(c)
                          : (int)p->f3.EnterInitializationMode(c, fmi3False, 0, 0, fmi3False, 0);
            break;
        case OP_EXIT:
            status =
                fmi2 ? (int)p->f2.ExitInitializationMode(c) : (int)p->f3.ExitInitializationMode(c);
            break;
        case OP_STEP:
            last = now;
            status = step_once(p, c, now, op->h, &h, &last);
            if (status <= 1) {
                now += op->h;
            }
            if (has_states && status == 2) {
                status = 16 * restart(p, c) + 2;
                now = 0;
            }
            if (counts != NULL) {
                counts->ok += status <= 1;
                counts->discarded += status == 2;
                counts->refused += status > 2;
            }
            h = probe_hash_u64(h, fmi2 ? (uint64_t)p->f2.GetReal(c, p->real_vrs, p->n_reals, reals)
                                       : (uint64_t)p->f3.GetFloat64(c, p->real_vrs, p->n_reals,
                                                                    reals, p->n_reals));
            h = probe_hash_u64(
                h, fmi2 ? (uint64_t)p->f2.GetInteger(c, p->integer_vrs, p->n_integers, integers)
                        : (uint64_t)p->f3.GetInt32(c, p->integer_vrs, p->n_integers, integers,
                                                   p->n_integers));
            for (j = 0; j < p->n_reals; ++j) {
                h = probe_hash_double(h, reals[j]);
            }
            for (j = 0; j < p->n_integers; ++j) {
                h = probe_hash_u64(h, (uint64_t)(unsigned)integers[j]);
            }
            break;
        }
        trace[k] = probe_hash_u64(h, (uint64_t)status);
    }
    /* what the instance logged, with its name taken out */
    trace[p->count] = (uint64_t)book.count;
    if (fmi2) {
        p->f2.FreeInstance(c);
    } else {
        p->f3.FreeInstance(c);
    }
    free(reals);
    free(integers);
    return 1;
}

static void* thread_main(void* argument)
{
    thread_run* run = (thread_run*)argument;
    int r;
    pthread_barrier_wait(run->start);
    run->ok = 1;
    for (r = 0; r < runs_per_thread && run->ok; ++r) {
        run->ok = run_program(run->program, run->index,
                              run->trace + (size_t)r * (run->program->count + 1), NULL);
    }
    return NULL;
}

int main(int argc, char** argv)
{
    thread_program p;
    char error[512];
    const char* directory = NULL;
    long steps = 2000, threads = 8, t;
    uint64_t seed = 1;
    uint64_t* solo;
    thread_run* runs;
    pthread_t* ids;
    pthread_barrier_t start;
    step_counts alone = {0, 0, 0};
    int a, failed = 0, r;
    size_t k, length;
    if (argc == 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
        printf("usage: fmu_threads [--threads N] [--steps N] [--seed S] FMU_DIR\n"
               "N instances of the unpacked FMU stepped in threads at once, each against the "
               "same program run alone: their outputs must be equal bit for bit (run under "
               "ThreadSanitizer by scripts/run-tests); exits non-zero if they differ.\n");
        return 0;
    }
    for (a = 1; a < argc; ++a) {
        if (strcmp(argv[a], "--threads") == 0 && a + 1 < argc) {
            threads = strtol(argv[++a], NULL, 10);
        } else if (strcmp(argv[a], "--steps") == 0 && a + 1 < argc) {
            steps = strtol(argv[++a], NULL, 10);
        } else if (strcmp(argv[a], "--seed") == 0 && a + 1 < argc) {
            seed = strtoull(argv[++a], NULL, 0);
        } else if (argv[a][0] != '-' && directory == NULL) {
            directory = argv[a];
        } else {
            directory = NULL;
            break;
        }
    }
    if (directory == NULL || threads < 1 || steps < 1) {
        printf("usage: fmu_threads [--threads N] [--steps N] [--seed S] FMU_DIR\n");
        return 2;
    }
    memset(&p, 0, sizeof p);
    if (!probe_read_model(directory, &p.model, error, sizeof error) ||
        !(p.model.fmi_version == 2 ? probe_load_fmi2(&p.model, &p.f2, error, sizeof error)
                                   : probe_load_fmi3(&p.model, &p.f3, error, sizeof error)) ||
        !make_program(&p, steps, seed)) {
        printf("%s\n", error);
        return 1;
    }
    length = p.count + 1;
    solo = (uint64_t*)calloc(length, sizeof *solo);
    runs = (thread_run*)calloc((size_t)threads, sizeof *runs);
    ids = (pthread_t*)calloc((size_t)threads, sizeof *ids);
    if (solo == NULL || runs == NULL || ids == NULL || !run_program(&p, 0, solo, &alone)) {
        printf("cannot run %s alone\n", directory);
        return 1;
    }
    printf("threads %s fmi%d: alone, %ld steps OK, %ld discarded, %ld refused\n",
           p.model.identifier, p.model.fmi_version, alone.ok, alone.discarded, alone.refused);
    /* a step refused, or most steps failed, and the threads would compare runs in which
     * the model computed little */
    if (alone.refused > 0 || alone.ok < (steps + 1) / 2) {
        printf("FAIL %s fmi%d: %ld of %ld steps refused, %ld discarded (seed %" PRIu64 ")\n",
               p.model.identifier, p.model.fmi_version, alone.refused, steps, alone.discarded,
               seed);
        failed = 1;
    }
    pthread_barrier_init(&start, NULL, (unsigned)threads);
    for (t = 0; t < threads; ++t) {
        runs[t].program = &p;
        runs[t].start = &start;
        runs[t].index = (int)t;
        runs[t].trace = (uint64_t*)calloc(length * (size_t)runs_per_thread, sizeof(uint64_t));
        if (runs[t].trace == NULL || pthread_create(&ids[t], NULL, thread_main, &runs[t]) != 0) {
            printf("cannot start thread %ld\n", t);
            return 1;
        }
    }
    for (t = 0; t < threads; ++t) {
        pthread_join(ids[t], NULL);
    }
    pthread_barrier_destroy(&start);
    for (t = 0; t < threads; ++t) {
        if (!runs[t].ok) {
            printf("FAIL %s fmi%d: thread %ld could not run\n", p.model.identifier,
                   p.model.fmi_version, t);
            failed = 1;
            continue;
        }
        for (r = 0; r < runs_per_thread; ++r) {
            for (k = 0; k < length; ++k) {
                if (runs[t].trace[(size_t)r * length + k] != solo[k]) {
                    printf("FAIL %s fmi%d: thread %ld, run %d differs from one instance alone at "
                           "call %zu of %zu (seed %" PRIu64 ")\n",
                           p.model.identifier, p.model.fmi_version, t, r, k, length, seed);
                    failed = 1;
                    break;
                }
            }
        }
    }
    printf("threads %s fmi%d: %ld threads x %d instances x %zu calls (%ld steps) %s one instance "
           "alone\n",
           p.model.identifier, p.model.fmi_version, threads, runs_per_thread, p.count, steps,
           failed ? "NOT identical to" : "identical, bit for bit, to");
    for (t = 0; t < threads; ++t) {
        free(runs[t].trace);
    }
    free(runs);
    free(ids);
    free(solo);
    free(p.ops);
    free(p.real_vrs);
    free(p.integer_vrs);
    probe_unload(p.model.fmi_version == 2 ? p.f2.library : p.f3.library);
    probe_free_model(&p.model);
    return failed;
}
