/* dyadfmu benchmark: time per dyad configuration of
 *   core     the closed-form solvers of the C core (dyad_solve),
 *   gsl_lu   the same dyad as a dense 6x6 system, LU with GSL (dense_gsl.c),
 *   gsl_svd  the same with an SVD,
 *   fmu      an FMU binary stepped from C (FMI 2 or 3), one row per doStep,
 *   batch    dyad_solve_batch over the rows laid out as dyadfmu.solve passes NumPy
 *            arrays (a scalar's rows contiguous, a vector's x and y interleaved).
 *
 * Built twice from this file: dyad_bench against the double core (all methods),
 * dyad_bench_float against the float core (method core only; inputs are rounded
 * to float for the solve, outputs widened back to double).
 *
 * Files are raw little-endian float64, row-major; see usage() for the layout.
 * Each timed loop is its own non-inlined function bench_loop_<method>, so that
 *   valgrind --tool=callgrind --toggle-collect='bench_loop_*' dyad_bench ... --repeat 1
 * counts the instructions of the solves and of nothing else. The loops write
 * every result to an array that is written out afterwards, so none of the work
 * can be dropped.
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "dyadfmu/batch.h"
#include "dyadfmu/dyad.h"

#ifndef DYAD_REAL_FLOAT
#include "dense_gsl.h"
#define BENCH_REAL_NAME "double"
#define BENCH_PROGRAM   "dyad_bench"
#else
#define BENCH_REAL_NAME "float"
#define BENCH_PROGRAM   "dyad_bench_float"
#endif

/* The fmu method needs the FMI headers (CMake defines DYADFMU_BENCH_FMI when it
 * has them) and exists in the double binary only. */
#if defined(DYADFMU_BENCH_FMI) && !defined(DYAD_REAL_FLOAT)
#define BENCH_HAVE_FMU 1
#include <dlfcn.h>
#include <stdarg.h>

#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"
#endif

#define EXIT_USAGE 2

enum {
    IN_LINK_COLS = 14, /* columns per link in the inputs file */
    IN_COLS = 35,      /* 2 links, guide_k, guide_p, gravity, singular_threshold */
    OUT_COLS = 16
};

typedef enum bench_method {
    METHOD_CORE,
    METHOD_GSL_LU,
    METHOD_GSL_SVD,
    METHOD_FMU,
    METHOD_BATCH
} bench_method;

static const char* const method_names[] = {"core", "gsl_lu", "gsl_svd", "fmu", "batch"};

typedef struct options {
    int have_type;
    dyad_type type;
    int have_method;
    bench_method method;
    const char* inputs;
    const char* outputs;
    long count; /* 0: every row */
    long repeat;
    const char* fmu_path;
    int fmi_version;
    const char* token;
    const char* fmu_inputs;
    const char* in_vrs;
    const char* out_vrs;
} options;

static void usage(FILE* out)
{
    fprintf(out,
            "usage: %s --type RRR|RRT|RTR|TRT|RTT --method core|gsl_lu|gsl_svd|batch\n"
            "           --inputs FILE [--outputs FILE] [--count N] [--repeat R]\n"
            "       %s --method fmu --fmu BINARY.so --fmi 2|3 --token TOKEN\n"
            "           --fmu-inputs FILE --in-vrs VR,VR,... --out-vrs VR,VR,...\n"
            "           [--outputs FILE] [--count N] [--repeat R]\n"
            "\n"
            "Times the solve of every configuration (row) of the inputs file, R times\n"
            "(default 5), and prints one JSON line: method, real, type, count, repeat,\n"
            "seconds_per_config (the median over the R runs) and seconds_all (the time\n"
            "per configuration of each run).\n"
            "\n"
            "methods:\n"
            "  core     dyad_solve of the C core (%s)\n"
            "  gsl_lu   the dyad's 6x6 Newton-Euler system, GSL LU (double binary only)\n"
            "  gsl_svd  the same, GSL SVD (double binary only)\n"
            "  batch    dyad_solve_batch, one call over all rows laid out as dyadfmu.solve\n"
            "           passes NumPy arrays (scalars stride 1, vectors' x and y stride 2)\n"
            "           (double binary only)\n"
            "  fmu      the FMU binary stepped from C, one doStep (h = 1e-3 s) per row\n"
            "           (double binary only)\n"
            "\n"
            "files (raw little-endian float64, row-major):\n"
            "  --inputs      N x 35: per link m then n: dir.x, dir.y, length, omega, epsilon,\n"
            "                accel_d.x, accel_d.y, com.x, com.y, mass, inertia, force.x,\n"
            "                force.y, moment; then guide_k.x/y, guide_p.x/y, gravity.x/y,\n"
            "                singular_threshold\n"
            "  --outputs     N x 16: r_mk.x, r_mk.y, r_np.x, r_np.y, r_mn.x, r_mn.y, n_mk,\n"
            "                n_np, n_mn, m_mk, m_np, m_mn, status (0 ok, 1 singular, 2 invalid,\n"
            "                3 out of range), conditioning (core; else NaN), cond2 (gsl_svd:\n"
            "                s_max/s_min of the 6x6 matrix; else NaN), amplification (core;\n"
            "                else NaN).\n"
            "                For fmu: N x (number of out-vrs), the values read back.\n"
            "  --fmu-inputs  N x (number of in-vrs), in the FMU's units\n"
            "\n"
            "options:\n"
            "  --count N     use the first N rows (default: all)\n"
            "  --repeat R    run the timed loop R times (default 5)\n"
            "  --fmi 2|3     FMI version of the binary; --token is its guid (FMI 2) or\n"
            "                instantiationToken (FMI 3); --in-vrs/--out-vrs are value\n"
            "                references of Real (FMI 2) / Float64 (FMI 3) variables\n"
            "  --help        this text\n"
            "\n"
            "exit status: 0 done, 1 an FMU call did not return OK, 2 bad arguments or files\n",
            BENCH_PROGRAM, BENCH_PROGRAM, BENCH_REAL_NAME);
}

static void fail_usage(const char* what, const char* detail)
{
    fprintf(stderr, "%s: %s%s%s\n", BENCH_PROGRAM, what, detail ? ": " : "", detail ? detail : "");
    fprintf(stderr, "Try '%s --help'.\n", BENCH_PROGRAM);
    exit(EXIT_USAGE);
}

/* ---- arguments ------------------------------------------------------------------------------ */

static int same_ignoring_case(const char* a, const char* b)
{
    for (; *a != '\0' && *b != '\0'; ++a, ++b) {
        char x = *a, y = *b;
        if (x >= 'a' && x <= 'z')
            x = (char)(x - 'a' + 'A');
        if (y >= 'a' && y <= 'z')
            y = (char)(y - 'a' + 'A');
        if (x != y)
            return 0;
    }
    return *a == *b;
}

static long parse_positive(const char* option, const char* text)
{
    char* end;
    long value;
    errno = 0;
    value = strtol(text, &end, 10);
    if (errno != 0 || end == text || *end != '\0' || value <= 0) {
        fprintf(stderr, "%s: %s needs a positive integer, not '%s'\n", BENCH_PROGRAM, option, text);
        exit(EXIT_USAGE);
    }
    return value;
}

static void require(int present, const char* option, bench_method method)
{
    if (!present) {
        fprintf(stderr, "%s: %s is required with --method %s\n", BENCH_PROGRAM, option,
                method_names[method]);
        fprintf(stderr, "Try '%s --help'.\n", BENCH_PROGRAM);
        exit(EXIT_USAGE);
    }
}

static void parse_args(int argc, char** argv, options* opt)
{
    int k;
    memset(opt, 0, sizeof *opt);
    opt->repeat = 5;
    for (k = 1; k < argc; ++k) {
        const char* arg = argv[k];
        const char* value;
        if (strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0) {
            usage(stdout);
            exit(0);
        }
        if (strncmp(arg, "--", 2) != 0) {
            fail_usage("unexpected argument", arg);
        }
        if (k + 1 >= argc) {
            fail_usage("missing value for", arg);
        }
        value = argv[++k];
        if (strcmp(arg, "--type") == 0) {
            int t;
            opt->have_type = 0;
            for (t = 0; t < DYAD_TYPE_COUNT; ++t) {
                if (same_ignoring_case(value, dyad_type_name((dyad_type)t))) {
                    opt->type = (dyad_type)t;
                    opt->have_type = 1;
                }
            }
            if (!opt->have_type) {
                fail_usage("unknown --type (expected RRR, RRT, RTR, TRT or RTT)", value);
            }
        } else if (strcmp(arg, "--method") == 0) {
            int m;
            opt->have_method = 0;
            for (m = 0; m < (int)(sizeof method_names / sizeof method_names[0]); ++m) {
                if (strcmp(value, method_names[m]) == 0) {
                    opt->method = (bench_method)m;
                    opt->have_method = 1;
                }
            }
            if (!opt->have_method) {
                fail_usage("unknown --method (expected core, gsl_lu, gsl_svd, batch or fmu)",
                           value);
            }
        } else if (strcmp(arg, "--inputs") == 0) {
            opt->inputs = value;
        } else if (strcmp(arg, "--outputs") == 0) {
            opt->outputs = value;
        } else if (strcmp(arg, "--count") == 0) {
            opt->count = parse_positive(arg, value);
        } else if (strcmp(arg, "--repeat") == 0) {
            opt->repeat = parse_positive(arg, value);
        } else if (strcmp(arg, "--fmu") == 0) {
            opt->fmu_path = value;
        } else if (strcmp(arg, "--fmi") == 0) {
            if (strcmp(value, "2") == 0) {
                opt->fmi_version = 2;
            } else if (strcmp(value, "3") == 0) {
                opt->fmi_version = 3;
            } else {
                fail_usage("--fmi must be 2 or 3, not", value);
            }
        } else if (strcmp(arg, "--token") == 0) {
            opt->token = value;
        } else if (strcmp(arg, "--fmu-inputs") == 0) {
            opt->fmu_inputs = value;
        } else if (strcmp(arg, "--in-vrs") == 0) {
            opt->in_vrs = value;
        } else if (strcmp(arg, "--out-vrs") == 0) {
            opt->out_vrs = value;
        } else {
            fail_usage("unknown option", arg);
        }
    }
    if (!opt->have_method) {
        fail_usage("--method is required", NULL);
    }
    if (opt->method != METHOD_FMU) {
        require(opt->have_type, "--type", opt->method);
        require(opt->inputs != NULL, "--inputs", opt->method);
    } else {
        require(opt->fmu_path != NULL, "--fmu", opt->method);
        require(opt->fmi_version != 0, "--fmi", opt->method);
        require(opt->token != NULL, "--token", opt->method);
        require(opt->fmu_inputs != NULL, "--fmu-inputs", opt->method);
        require(opt->in_vrs != NULL, "--in-vrs", opt->method);
        require(opt->out_vrs != NULL, "--out-vrs", opt->method);
    }
}

/* ---- files ---------------------------------------------------------------------------------- */

static int host_is_little_endian(void)
{
    const unsigned int one = 1;
    unsigned char first;
    memcpy(&first, &one, 1);
    return first == 1;
}

/* Reads a raw float64 file of rows of `cols` values; exits 2 on any problem. */
static double* read_rows(const char* path, size_t cols, size_t* rows)
{
    const size_t row_bytes = cols * sizeof(double);
    struct stat info;
    FILE* file = fopen(path, "rb");
    double* data;
    size_t size;
    if (file == NULL) {
        fprintf(stderr, "%s: cannot open %s: %s\n", BENCH_PROGRAM, path, strerror(errno));
        exit(EXIT_USAGE);
    }
    if (fstat(fileno(file), &info) != 0 || !S_ISREG(info.st_mode)) {
        fprintf(stderr, "%s: %s is not a regular file\n", BENCH_PROGRAM, path);
        exit(EXIT_USAGE);
    }
    size = (size_t)info.st_size;
    if (size == 0 || size % row_bytes != 0) {
        fprintf(stderr,
                "%s: %s has %lu bytes, not a positive multiple of its row size %lu "
                "(%lu float64 values)\n",
                BENCH_PROGRAM, path, (unsigned long)size, (unsigned long)row_bytes,
                (unsigned long)cols);
        exit(EXIT_USAGE);
    }
    *rows = size / row_bytes;
    data = malloc(size);
    if (data == NULL) {
        fprintf(stderr, "%s: out of memory reading %s\n", BENCH_PROGRAM, path);
        exit(EXIT_USAGE);
    }
    if (fread(data, row_bytes, *rows, file) != *rows) {
        fprintf(stderr, "%s: cannot read %s\n", BENCH_PROGRAM, path);
        exit(EXIT_USAGE);
    }
    fclose(file);
    return data;
}

static void write_rows(const char* path, const double* data, size_t rows, size_t cols)
{
    FILE* file = fopen(path, "wb");
    if (file == NULL) {
        fprintf(stderr, "%s: cannot create %s: %s\n", BENCH_PROGRAM, path, strerror(errno));
        exit(EXIT_USAGE);
    }
    if (fwrite(data, cols * sizeof(double), rows, file) != rows || fclose(file) != 0) {
        fprintf(stderr, "%s: cannot write %s\n", BENCH_PROGRAM, path);
        exit(EXIT_USAGE);
    }
}

/* Picks the rows to use: all, or the first --count. */
static size_t rows_to_use(const options* opt, size_t rows, const char* path)
{
    if (opt->count == 0) {
        return rows;
    }
    if ((unsigned long)opt->count > rows) {
        fprintf(stderr, "%s: --count %ld, but %s holds only %lu rows\n", BENCH_PROGRAM, opt->count,
                path, (unsigned long)rows);
        exit(EXIT_USAGE);
    }
    return (size_t)opt->count;
}

static void* xmalloc(size_t count, size_t size)
{
    void* p = count > 0 ? calloc(count, size) : NULL;
    if (count > 0 && p == NULL) {
        fprintf(stderr, "%s: out of memory\n", BENCH_PROGRAM);
        exit(EXIT_USAGE);
    }
    return p;
}

/* ---- rows to inputs, results to rows -------------------------------------------------------- */

static dyad_vec2 vec_at(const double* c)
{
    dyad_vec2 v;
    v.x = (dyad_real)c[0];
    v.y = (dyad_real)c[1];
    return v;
}

/* Columns 0..13 of a link block (explicit, independent of the struct layout). */
static void link_from_row(const double* c, dyad_link* link)
{
    link->dir = vec_at(c + 0);
    link->length = (dyad_real)c[2];
    link->omega = (dyad_real)c[3];
    link->epsilon = (dyad_real)c[4];
    link->accel_d = vec_at(c + 5);
    link->com = vec_at(c + 7);
    link->mass = (dyad_real)c[9];
    link->inertia = (dyad_real)c[10];
    link->force = vec_at(c + 11);
    link->moment = (dyad_real)c[13];
}

static void input_from_row(const double* row, dyad_input* in)
{
    *in = dyad_input_default();
    link_from_row(row, &in->m);
    link_from_row(row + IN_LINK_COLS, &in->n);
    in->guide_k = vec_at(row + 28);
    in->guide_p = vec_at(row + 30);
    in->gravity = vec_at(row + 32);
    in->singular_threshold = (dyad_real)row[34];
}

static void row_from_result(const dyad_result* r, double cond2, double* row)
{
    row[0] = (double)r->r_mk.x;
    row[1] = (double)r->r_mk.y;
    row[2] = (double)r->r_np.x;
    row[3] = (double)r->r_np.y;
    row[4] = (double)r->r_mn.x;
    row[5] = (double)r->r_mn.y;
    row[6] = (double)r->n_mk;
    row[7] = (double)r->n_np;
    row[8] = (double)r->n_mn;
    row[9] = (double)r->m_mk;
    row[10] = (double)r->m_np;
    row[11] = (double)r->m_mn;
    row[12] = (double)r->status;
    row[13] = (double)r->conditioning;
    row[14] = cond2;
    row[15] = (double)r->amplification;
}

/* ---- timing --------------------------------------------------------------------------------- */

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int compare_doubles(const void* a, const void* b)
{
    const double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

static double median(const double* values, size_t count)
{
    double* sorted = xmalloc(count, sizeof *sorted);
    double mid;
    memcpy(sorted, values, count * sizeof *sorted);
    qsort(sorted, count, sizeof *sorted, compare_doubles);
    mid = count % 2 ? sorted[count / 2] : 0.5 * (sorted[count / 2 - 1] + sorted[count / 2]);
    free(sorted);
    return mid;
}

static void print_json(const options* opt, size_t count, const double* per_config)
{
    long k;
    printf("{\"method\": \"%s\", \"real\": \"%s\", ", method_names[opt->method], BENCH_REAL_NAME);
    if (opt->have_type) {
        printf("\"type\": \"%s\", ", dyad_type_name(opt->type));
    } else {
        printf("\"type\": null, ");
    }
    printf("\"count\": %lu, \"repeat\": %ld, \"seconds_per_config\": %.6e, \"seconds_all\": [",
           (unsigned long)count, opt->repeat, median(per_config, (size_t)opt->repeat));
    for (k = 0; k < opt->repeat; ++k) {
        printf("%s%.6e", k ? ", " : "", per_config[k]);
    }
    printf("]}\n");
}

/* ---- the timed loops ------------------------------------------------------------------------ */

/* External linkage and noinline: each loop keeps its own symbol for callgrind's
 * --toggle-collect, and the solves cannot be folded into main. */
__attribute__((noinline)) void bench_loop_core(dyad_type type, const dyad_input* in,
                                               dyad_result* out, size_t count);

void bench_loop_core(dyad_type type, const dyad_input* in, dyad_result* out, size_t count)
{
    size_t i;
    for (i = 0; i < count; ++i) {
        dyad_solve(type, &in[i], &out[i]);
    }
}

#ifndef DYAD_REAL_FLOAT
__attribute__((noinline)) void bench_loop_batch(dyad_type type, const dyad_batch_input* in,
                                                const dyad_batch_output* out, size_t count);

void bench_loop_batch(dyad_type type, const dyad_batch_input* in, const dyad_batch_output* out,
                      size_t count)
{
    dyad_solve_batch(type, count, in, out);
}

/* Whether a column is the x of a vector field: dyadfmu.solve passes each vector as an
 * (N, 2) array, x and y interleaved, and each scalar as an array of its own. */
static int starts_vector(int column, int output)
{
    static const int input_x[] = {DYAD_IN_M_DIR_X,   DYAD_IN_M_ACCEL_D_X, DYAD_IN_M_COM_X,
                                  DYAD_IN_M_FORCE_X, DYAD_IN_N_DIR_X,     DYAD_IN_N_ACCEL_D_X,
                                  DYAD_IN_N_COM_X,   DYAD_IN_N_FORCE_X,   DYAD_IN_GUIDE_K_X,
                                  DYAD_IN_GUIDE_P_X, DYAD_IN_GRAVITY_X};
    static const int output_x[] = {DYAD_OUT_R_MK_X, DYAD_OUT_R_NP_X, DYAD_OUT_R_MN_X};
    const int* x = output ? output_x : input_x;
    const size_t n = output ? sizeof output_x / sizeof *x : sizeof input_x / sizeof *x;
    size_t k;
    for (k = 0; k < n; ++k) {
        if (x[k] == column) {
            return 1;
        }
    }
    return 0;
}

/* Runs batch on the inputs file, its rows laid out first as dyadfmu.solve passes NumPy
 * arrays: a scalar field's rows contiguous (stride 1), a vector's x and y interleaved
 * (stride 2); the outputs likewise. */
static void run_batch(const options* opt)
{
    size_t rows, count, c, r;
    long rep;
    double* raw = read_rows(opt->inputs, IN_COLS, &rows);
    double* per_config = xmalloc((size_t)opt->repeat, sizeof *per_config);
    double *columns, *results;
    unsigned char* status;
    dyad_batch_input in;
    dyad_batch_output out;
    count = rows_to_use(opt, rows, opt->inputs);
    columns = xmalloc(count * DYAD_INPUT_COLUMN_COUNT, sizeof *columns);
    results = xmalloc(count * DYAD_OUTPUT_COLUMN_COUNT, sizeof *results);
    status = xmalloc(2 * count, 1);
    for (c = 0; c < DYAD_INPUT_COLUMN_COUNT; ++c) {
        const int vector = starts_vector((int)c, 0);
        in.column[c].data = columns + c * count;
        in.column[c].stride = vector ? 2 : 1;
        for (r = 0; r < count; ++r) {
            columns[c * count + (vector ? 2 * r : r)] = raw[r * IN_COLS + c];
            if (vector) {
                columns[c * count + 2 * r + 1] = raw[r * IN_COLS + c + 1];
            }
        }
        if (vector) {
            ++c;
            in.column[c].data = columns + (c - 1) * count + 1;
            in.column[c].stride = 2;
        }
    }
    for (c = 0; c < DYAD_OUTPUT_COLUMN_COUNT; ++c) {
        const int vector = starts_vector((int)c, 1);
        out.column[c].data = results + c * count;
        out.column[c].stride = vector ? 2 : 1;
        if (vector) {
            ++c;
            out.column[c].data = results + (c - 1) * count + 1;
            out.column[c].stride = 2;
        }
    }
    out.status = status;
    out.field = status + count;
    for (rep = 0; rep < opt->repeat; ++rep) {
        const double start = now_seconds();
        bench_loop_batch(opt->type, &in, &out, count);
        per_config[rep] = (now_seconds() - start) / (double)count;
    }
    print_json(opt, count, per_config);
    free(raw);
    free(columns);
    free(results);
    free(status);
    free(per_config);
}

__attribute__((noinline)) void bench_loop_gsl_lu(dense_gsl* ws, dyad_type type,
                                                 const dyad_input* in, dyad_result* out,
                                                 size_t count);
__attribute__((noinline)) void bench_loop_gsl_svd(dense_gsl* ws, dyad_type type,
                                                  const dyad_input* in, dyad_result* out,
                                                  double* cond2, size_t count);

void bench_loop_gsl_lu(dense_gsl* ws, dyad_type type, const dyad_input* in, dyad_result* out,
                       size_t count)
{
    size_t i;
    for (i = 0; i < count; ++i) {
        dense_gsl_solve_lu(ws, type, &in[i], &out[i]);
    }
}

void bench_loop_gsl_svd(dense_gsl* ws, dyad_type type, const dyad_input* in, dyad_result* out,
                        double* cond2, size_t count)
{
    size_t i;
    for (i = 0; i < count; ++i) {
        dense_gsl_solve_svd(ws, type, &in[i], &out[i], &cond2[i]);
    }
}
#endif

/* Runs core, gsl_lu or gsl_svd on the inputs file. */
static void run_solver(const options* opt)
{
    size_t rows, count, i;
    long rep;
    double* raw = read_rows(opt->inputs, IN_COLS, &rows);
    dyad_input* in;
    dyad_result* out;
    double* cond2;
    double* per_config = xmalloc((size_t)opt->repeat, sizeof *per_config);
#ifndef DYAD_REAL_FLOAT
    dense_gsl* ws = NULL;
#endif

    count = rows_to_use(opt, rows, opt->inputs);
    in = xmalloc(count, sizeof *in);
    out = xmalloc(count, sizeof *out);
    cond2 = xmalloc(count, sizeof *cond2);
    for (i = 0; i < count; ++i) {
        input_from_row(raw + i * IN_COLS, &in[i]);
        cond2[i] = NAN;
    }
    free(raw);
#ifndef DYAD_REAL_FLOAT
    if (opt->method != METHOD_CORE) {
        ws = dense_gsl_alloc();
        if (ws == NULL) {
            fprintf(stderr, "%s: cannot allocate the GSL workspace\n", BENCH_PROGRAM);
            exit(EXIT_USAGE);
        }
    }
#endif

    for (rep = 0; rep < opt->repeat; ++rep) {
        const double start = now_seconds();
        switch (opt->method) {
        case METHOD_CORE: bench_loop_core(opt->type, in, out, count); break;
#ifndef DYAD_REAL_FLOAT
        case METHOD_GSL_LU: bench_loop_gsl_lu(ws, opt->type, in, out, count); break;
        case METHOD_GSL_SVD: bench_loop_gsl_svd(ws, opt->type, in, out, cond2, count); break;
#endif
        default: break; /* refused in main */
        }
        per_config[rep] = (now_seconds() - start) / (double)count;
    }

    if (opt->outputs != NULL) {
        double* table = xmalloc(count * OUT_COLS, sizeof *table);
        for (i = 0; i < count; ++i) {
            row_from_result(&out[i], cond2[i], table + i * OUT_COLS);
        }
        write_rows(opt->outputs, table, count, OUT_COLS);
        free(table);
    }
    print_json(opt, count, per_config);

#ifndef DYAD_REAL_FLOAT
    dense_gsl_free(ws);
#endif
    free(in);
    free(out);
    free(cond2);
    free(per_config);
}

/* ---- fmu ------------------------------------------------------------------------------------ */

#ifdef BENCH_HAVE_FMU

#define FMU_STEP_SIZE 1e-3

/* One instance of either FMI version, with the calls the benchmark makes. */
typedef struct fmu_session {
    int version;
    void* library;
    void* instance;
    fmi2FreeInstanceTYPE* free2;
    fmi2TerminateTYPE* terminate2;
    fmi2SetRealTYPE* set2;
    fmi2DoStepTYPE* step2;
    fmi2GetRealTYPE* get2;
    fmi3FreeInstanceTYPE* free3;
    fmi3TerminateTYPE* terminate3;
    fmi3SetFloat64TYPE* set3;
    fmi3DoStepTYPE* step3;
    fmi3GetFloat64TYPE* get3;
    const unsigned* in_vrs;
    size_t in_count;
    const unsigned* out_vrs;
    size_t out_count;
} fmu_session;

/* Where the timed loop stopped when a call did not return OK. */
typedef struct fmu_failure {
    int status;
    const char* call;
} fmu_failure;

static void fmi2_log(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                     fmi2String category, fmi2String message, ...)
{
    va_list args;
    (void)env;
    if (status < fmi2Warning) {
        return;
    }
    fprintf(stderr, "%s: FMU %s [%s, status %d]: ", BENCH_PROGRAM, name ? name : "",
            category ? category : "", (int)status);
    va_start(args, message);
    vfprintf(stderr, message, args);
    va_end(args);
    fputc('\n', stderr);
}

static void fmi3_log(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category,
                     fmi3String message)
{
    (void)env;
    if (status < fmi3Warning) {
        return;
    }
    fprintf(stderr, "%s: FMU [%s, status %d]: %s\n", BENCH_PROGRAM, category ? category : "",
            (int)status, message);
}

static void* symbol(void* library, const char* path, const char* name)
{
    void* p = dlsym(library, name);
    if (p == NULL) {
        fprintf(stderr, "%s: %s does not export %s\n", BENCH_PROGRAM, path, name);
        exit(EXIT_USAGE);
    }
    return p;
}

/* dlsym returns an object pointer; ISO C has no conversion to a function
 * pointer, so the address is copied bytewise (as POSIX permits). */
#define RESOLVE(target, name)                                     \
    do {                                                          \
        void* address_ = symbol(s->library, opt->fmu_path, name); \
        memcpy(&(target), &address_, sizeof address_);            \
    } while (0)

static void fmu_check(int status, int ok, const char* call)
{
    if (status != ok) {
        fprintf(stderr, "%s: %s returned status %d, not OK\n", BENCH_PROGRAM, call, status);
        exit(EXIT_FAILURE);
    }
}

static fmi2CallbackFunctions fmi2_callbacks; /* must outlive the FMI 2 instance */

static void fmu_open(const options* opt, fmu_session* s)
{
    s->version = opt->fmi_version;
    s->library = dlopen(opt->fmu_path, RTLD_NOW | RTLD_LOCAL);
    if (s->library == NULL) {
        fprintf(stderr, "%s: cannot load %s: %s\n", BENCH_PROGRAM, opt->fmu_path, dlerror());
        exit(EXIT_USAGE);
    }
    if (s->version == 2) {
        fmi2InstantiateTYPE* instantiate;
        fmi2SetupExperimentTYPE* setup;
        fmi2EnterInitializationModeTYPE* enter;
        fmi2ExitInitializationModeTYPE* leave;
        RESOLVE(instantiate, "fmi2Instantiate");
        RESOLVE(setup, "fmi2SetupExperiment");
        RESOLVE(enter, "fmi2EnterInitializationMode");
        RESOLVE(leave, "fmi2ExitInitializationMode");
        RESOLVE(s->free2, "fmi2FreeInstance");
        RESOLVE(s->terminate2, "fmi2Terminate");
        RESOLVE(s->set2, "fmi2SetReal");
        RESOLVE(s->step2, "fmi2DoStep");
        RESOLVE(s->get2, "fmi2GetReal");
        fmi2_callbacks.logger = fmi2_log;
        fmi2_callbacks.allocateMemory = calloc;
        fmi2_callbacks.freeMemory = free;
        fmi2_callbacks.stepFinished = NULL;
        fmi2_callbacks.componentEnvironment = NULL;
        s->instance = instantiate("bench", fmi2CoSimulation, opt->token, NULL, &fmi2_callbacks,
                                  fmi2False, fmi2False);
        if (s->instance == NULL) {
            fprintf(stderr, "%s: fmi2Instantiate failed\n", BENCH_PROGRAM);
            exit(EXIT_FAILURE);
        }
        fmu_check(setup(s->instance, fmi2False, 0, 0, fmi2False, 0), fmi2OK, "fmi2SetupExperiment");
        fmu_check(enter(s->instance), fmi2OK, "fmi2EnterInitializationMode");
        fmu_check(leave(s->instance), fmi2OK, "fmi2ExitInitializationMode");
    } else {
        fmi3InstantiateCoSimulationTYPE* instantiate;
        fmi3EnterInitializationModeTYPE* enter;
        fmi3ExitInitializationModeTYPE* leave;
        RESOLVE(instantiate, "fmi3InstantiateCoSimulation");
        RESOLVE(enter, "fmi3EnterInitializationMode");
        RESOLVE(leave, "fmi3ExitInitializationMode");
        RESOLVE(s->free3, "fmi3FreeInstance");
        RESOLVE(s->terminate3, "fmi3Terminate");
        RESOLVE(s->set3, "fmi3SetFloat64");
        RESOLVE(s->step3, "fmi3DoStep");
        RESOLVE(s->get3, "fmi3GetFloat64");
        s->instance = instantiate("bench", opt->token, NULL, fmi3False, fmi3False, fmi3False,
                                  fmi3False, NULL, 0, NULL, fmi3_log, NULL);
        if (s->instance == NULL) {
            fprintf(stderr, "%s: fmi3InstantiateCoSimulation failed\n", BENCH_PROGRAM);
            exit(EXIT_FAILURE);
        }
        fmu_check(enter(s->instance, fmi3False, 0, 0, fmi3False, 0), fmi3OK,
                  "fmi3EnterInitializationMode");
        fmu_check(leave(s->instance), fmi3OK, "fmi3ExitInitializationMode");
    }
}

static void fmu_close(fmu_session* s)
{
    if (s->version == 2) {
        s->terminate2(s->instance);
        s->free2(s->instance);
    } else {
        s->terminate3(s->instance);
        s->free3(s->instance);
    }
    dlclose(s->library);
}

__attribute__((noinline)) size_t bench_loop_fmu(const fmu_session* s, const double* in, double* out,
                                                size_t count, unsigned long* steps,
                                                fmu_failure* failure);

/* Set, doStep, get for every row; the communication time runs on across
 * repeats. Returns the number of rows done: count, or the failing row. */
size_t bench_loop_fmu(const fmu_session* s, const double* in, double* out, size_t count,
                      unsigned long* steps, fmu_failure* failure)
{
    size_t i;
    if (s->version == 2) {
        for (i = 0; i < count; ++i) {
            const double t = (double)(*steps)++ * FMU_STEP_SIZE;
            fmi2Status st = s->set2(s->instance, s->in_vrs, s->in_count, in + i * s->in_count);
            if (st != fmi2OK) {
                failure->call = "fmi2SetReal";
                failure->status = st;
                return i;
            }
            st = s->step2(s->instance, t, FMU_STEP_SIZE, fmi2True);
            if (st != fmi2OK) {
                failure->call = "fmi2DoStep";
                failure->status = st;
                return i;
            }
            st = s->get2(s->instance, s->out_vrs, s->out_count, out + i * s->out_count);
            if (st != fmi2OK) {
                failure->call = "fmi2GetReal";
                failure->status = st;
                return i;
            }
        }
    } else {
        for (i = 0; i < count; ++i) {
            const double t = (double)(*steps)++ * FMU_STEP_SIZE;
            fmi3Boolean event, terminate, early;
            fmi3Float64 last;
            fmi3Status st =
                s->set3(s->instance, s->in_vrs, s->in_count, in + i * s->in_count, s->in_count);
            if (st != fmi3OK) {
                failure->call = "fmi3SetFloat64";
                failure->status = st;
                return i;
            }
            st = s->step3(s->instance, t, FMU_STEP_SIZE, fmi3True, &event, &terminate, &early,
                          &last);
            if (st != fmi3OK) {
                failure->call = "fmi3DoStep";
                failure->status = st;
                return i;
            }
            st = s->get3(s->instance, s->out_vrs, s->out_count, out + i * s->out_count,
                         s->out_count);
            if (st != fmi3OK) {
                failure->call = "fmi3GetFloat64";
                failure->status = st;
                return i;
            }
        }
    }
    return count;
}

/* "1,2,3" -> value references; exits 2 on anything else. */
static unsigned* parse_vrs(const char* option, const char* text, size_t* count)
{
    const char* p = text;
    size_t n = 1, k = 0;
    unsigned* vrs;
    for (; *p != '\0'; ++p) {
        n += *p == ',';
    }
    vrs = xmalloc(n, sizeof *vrs);
    for (p = text; k < n; ++k) {
        char* end;
        unsigned long value;
        errno = 0;
        value = strtoul(p, &end, 10);
        if (errno != 0 || end == p || *p == '-' || *p == '+' || value > 0xFFFFFFFFul ||
            (*end != ',' && *end != '\0')) {
            fprintf(stderr, "%s: %s must be a comma-separated list of value references, not '%s'\n",
                    BENCH_PROGRAM, option, text);
            exit(EXIT_USAGE);
        }
        vrs[k] = (unsigned)value;
        p = end + 1;
    }
    *count = n;
    return vrs;
}

static void run_fmu(const options* opt)
{
    fmu_session s;
    fmu_failure failure = {0, NULL};
    size_t rows, count, done = 0;
    unsigned long steps = 0;
    unsigned* in_vrs;
    unsigned* out_vrs;
    double* in;
    double* out;
    double* per_config = xmalloc((size_t)opt->repeat, sizeof *per_config);
    long rep;

    memset(&s, 0, sizeof s);
    in_vrs = parse_vrs("--in-vrs", opt->in_vrs, &s.in_count);
    out_vrs = parse_vrs("--out-vrs", opt->out_vrs, &s.out_count);
    s.in_vrs = in_vrs;
    s.out_vrs = out_vrs;
    in = read_rows(opt->fmu_inputs, s.in_count, &rows);
    count = rows_to_use(opt, rows, opt->fmu_inputs);
    out = xmalloc(count * s.out_count, sizeof *out);

    fmu_open(opt, &s);
    for (rep = 0; rep < opt->repeat; ++rep) {
        const double start = now_seconds();
        done = bench_loop_fmu(&s, in, out, count, &steps, &failure);
        per_config[rep] = (now_seconds() - start) / (double)count;
        if (done != count) {
            fprintf(stderr, "%s: row %lu (from 0) of %s: %s returned status %d, not OK\n",
                    BENCH_PROGRAM, (unsigned long)done, opt->fmu_inputs, failure.call,
                    failure.status);
            exit(EXIT_FAILURE);
        }
    }
    fmu_close(&s);

    if (opt->outputs != NULL) {
        write_rows(opt->outputs, out, count, s.out_count);
    }
    print_json(opt, count, per_config);
    free(in_vrs);
    free(out_vrs);
    free(in);
    free(out);
    free(per_config);
}

#endif /* BENCH_HAVE_FMU */

int main(int argc, char** argv)
{
    options opt;
    parse_args(argc, argv, &opt);
    if (!host_is_little_endian()) {
        fprintf(stderr, "%s: the files are little-endian float64; this host is big-endian\n",
                BENCH_PROGRAM);
        return EXIT_USAGE;
    }
#ifdef DYAD_REAL_FLOAT
    if (opt.method != METHOD_CORE) {
        fprintf(stderr,
                "%s: method %s is not available in the float build (only core); "
                "use dyad_bench\n",
                BENCH_PROGRAM, method_names[opt.method]);
        return EXIT_USAGE;
    }
#endif
    if (opt.method == METHOD_FMU) {
#ifdef BENCH_HAVE_FMU
        run_fmu(&opt);
#else
        fprintf(stderr,
                "%s: method fmu is not available: built without the FMI headers "
                "(configure with DYADFMU_BUILD_FMUS=ON)\n",
                BENCH_PROGRAM);
        return EXIT_USAGE;
#endif
    } else if (opt.method == METHOD_BATCH) {
#ifndef DYAD_REAL_FLOAT
        if (opt.outputs != NULL) {
            fprintf(stderr, "%s: method batch writes no --outputs (core does, the same)\n",
                    BENCH_PROGRAM);
            return EXIT_USAGE;
        }
        run_batch(&opt);
#endif
    } else {
        run_solver(&opt);
    }
    return 0;
}
