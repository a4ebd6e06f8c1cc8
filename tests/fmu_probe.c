/* dyadfmu: the probes' view of an FMU (see fmu_probe.h). */
#define _POSIX_C_SOURCE 200809L

#include "fmu_probe.h"

#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The binary of this platform, and how to load it: the probes run on the Linux
 * binaries natively and, cross-compiled, on the Windows ones under Wine and on the
 * 64-bit ARM ones under QEMU's user mode (tests/fmu_replay.c). FMI 2 names no folder
 * for 64-bit ARM: there only the FMI 3 FMUs carry a binary. */
#if defined(_WIN32)
#include <windows.h>
#define PROBE_PLATFORM_FMI2 "win64"
#define PROBE_PLATFORM_FMI3 "x86_64-windows"
#define PROBE_BINARY_SUFFIX ".dll"
#elif defined(__aarch64__)
#include <dlfcn.h>
#define PROBE_PLATFORM_FMI2 "aarch64-linux"
#define PROBE_PLATFORM_FMI3 "aarch64-linux"
#define PROBE_BINARY_SUFFIX ".so"
#else
#include <dlfcn.h>
#define PROBE_PLATFORM_FMI2 "linux64"
#define PROBE_PLATFORM_FMI3 "x86_64-linux"
#define PROBE_BINARY_SUFFIX ".so"
#endif

/* ---- a minimal XML reader ------------------------------------------------------------------- */

/* One start tag and its attributes, values with the five entities and
 * character references resolved. Attribute storage is owned by the tag. */
enum { PROBE_MAX_ATTRIBUTES = 32 };

typedef struct xml_tag {
    char name[64];
    int closing;      /* </name> */
    int self_closing; /* <name .../> */
    size_t count;
    char* keys[PROBE_MAX_ATTRIBUTES];
    char* values[PROBE_MAX_ATTRIBUTES];
} xml_tag;

static void tag_clear(xml_tag* tag)
{
    size_t k;
    for (k = 0; k < tag->count; ++k) {
        free(tag->keys[k]);
        free(tag->values[k]);
    }
    tag->count = 0;
}

static const char* tag_attribute(const xml_tag* tag, const char* key)
{
    size_t k;
    for (k = 0; k < tag->count; ++k) {
        if (strcmp(tag->keys[k], key) == 0) {
            return tag->values[k];
        }
    }
    return NULL;
}

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

/* Appends the UTF-8 encoding of code point c; returns the bytes written. */
static size_t put_utf8(char* out, unsigned long c)
{
    if (c < 0x80) {
        out[0] = (char)c;
        return 1;
    }
    if (c < 0x800) {
        out[0] = (char)(0xC0 | (c >> 6));
        out[1] = (char)(0x80 | (c & 0x3F));
        return 2;
    }
    if (c < 0x10000) {
        out[0] = (char)(0xE0 | (c >> 12));
        out[1] = (char)(0x80 | ((c >> 6) & 0x3F));
        out[2] = (char)(0x80 | (c & 0x3F));
        return 3;
    }
    out[0] = (char)(0xF0 | (c >> 18));
    out[1] = (char)(0x80 | ((c >> 12) & 0x3F));
    out[2] = (char)(0x80 | ((c >> 6) & 0x3F));
    out[3] = (char)(0x80 | (c & 0x3F));
    return 4;
}

/* The text of [begin, end) with entities resolved, or NULL on a malformed one. */
static char* unescape(const char* begin, const char* end)
{
    char* out = (char*)malloc((size_t)(end - begin) + 1);
    size_t n = 0;
    if (out == NULL) {
        return NULL;
    }
    while (begin < end) {
        if (*begin != '&') {
            out[n++] = *begin++;
            continue;
        }
        {
            const char* semicolon = memchr(begin, ';', (size_t)(end - begin));
            const size_t length = semicolon != NULL ? (size_t)(semicolon - begin) + 1 : 0;
            if (length == 0 || length > 12) {
                free(out);
                return NULL;
            }
            if (strncmp(begin, "&lt;", length) == 0 && length == 4) {
                out[n++] = '<';
            } else if (strncmp(begin, "&gt;", length) == 0 && length == 4) {
                out[n++] = '>';
            } else if (strncmp(begin, "&amp;", length) == 0 && length == 5) {
                out[n++] = '&';
            } else if (strncmp(begin, "&quot;", length) == 0 && length == 6) {
                out[n++] = '"';
            } else if (strncmp(begin, "&apos;", length) == 0 && length == 6) {
                out[n++] = '\'';
            } else if (length > 3 && begin[1] == '#') {
                char* stop;
                const int hex = begin[2] == 'x';
                const unsigned long c = strtoul(begin + 2 + hex, &stop, hex ? 16 : 10);
                if (stop != semicolon || c == 0 || c > 0x10FFFF) {
                    free(out);
                    return NULL;
                }
                n += put_utf8(out + n, c); /* a reference is never shorter than its code */
            } else {
                free(out);
                return NULL;
            }
            begin += length;
        }
    }
    out[n] = '\0';
    return out;
}

/* Reads the next start or end tag at or after *cursor, skipping text,
 * comments, processing instructions and declarations. Returns 1 with the tag,
 * 0 at the end of the text, -1 on malformed markup. */
static int next_tag(const char** cursor, xml_tag* tag)
{
    const char* p = *cursor;
    size_t n;
    tag_clear(tag);
    for (;;) {
        p = strchr(p, '<');
        if (p == NULL) {
            return 0;
        }
        if (strncmp(p, "<!--", 4) == 0) {
            p = strstr(p + 4, "-->");
            if (p == NULL) {
                return -1;
            }
            p += 3;
        } else if (strncmp(p, "<?", 2) == 0) {
            p = strstr(p + 2, "?>");
            if (p == NULL) {
                return -1;
            }
            p += 2;
        } else if (strncmp(p, "<![CDATA[", 9) == 0) {
            p = strstr(p + 9, "]]>");
            if (p == NULL) {
                return -1;
            }
            p += 3;
        } else if (p[1] == '!') {
            p = strchr(p, '>');
            if (p == NULL) {
                return -1;
            }
            ++p;
        } else {
            break;
        }
    }
    ++p;
    tag->closing = *p == '/';
    tag->self_closing = 0;
    p += tag->closing;
    for (n = 0; *p != '\0' && !is_space(*p) && *p != '/' && *p != '>'; ++p) {
        if (n + 1 >= sizeof tag->name) {
            return -1;
        }
        tag->name[n++] = *p;
    }
    tag->name[n] = '\0';
    for (;;) {
        const char *key, *key_end, *value;
        char quote;
        while (is_space(*p)) {
            ++p;
        }
        if (*p == '>') {
            *cursor = p + 1;
            return 1;
        }
        if (p[0] == '/' && p[1] == '>') {
            tag->self_closing = 1;
            *cursor = p + 2;
            return 1;
        }
        if (*p == '\0' || tag->count == PROBE_MAX_ATTRIBUTES) {
            return -1;
        }
        key = p;
        while (*p != '\0' && *p != '=' && !is_space(*p) && *p != '>' && *p != '/') {
            ++p;
        }
        key_end = p;
        while (is_space(*p)) {
            ++p;
        }
        if (*p != '=' || key_end == key) {
            return -1;
        }
        ++p;
        while (is_space(*p)) {
            ++p;
        }
        quote = *p;
        if (quote != '"' && quote != '\'') {
            return -1;
        }
        value = ++p;
        p = strchr(p, quote);
        if (p == NULL) {
            return -1;
        }
        tag->keys[tag->count] = unescape(key, key_end);
        tag->values[tag->count] = unescape(value, p);
        ++tag->count;
        if (tag->keys[tag->count - 1] == NULL || tag->values[tag->count - 1] == NULL) {
            return -1;
        }
        ++p;
    }
}

/* ---- the model description ------------------------------------------------------------------ */

static char* copy_string(const char* s)
{
    char* copy = (char*)malloc(strlen(s) + 1);
    if (copy != NULL) {
        strcpy(copy, s);
    }
    return copy;
}

static int parse_number(const char* text, double* value)
{
    char* stop;
    if (text == NULL) {
        return 0;
    }
    *value = strtod(text, &stop);
    return stop != text && *stop == '\0';
}

/* An enumerated attribute: the index of `text` in `names`, or `fallback` when
 * the attribute is absent (its default in both standards); 0 when unknown. */
static int parse_enum(const char* text, const char* const names[], size_t count, int fallback,
                      int* index)
{
    size_t k;
    if (text == NULL) {
        *index = fallback;
        return 1;
    }
    for (k = 0; k < count; ++k) {
        if (strcmp(text, names[k]) == 0) {
            *index = (int)k;
            return 1;
        }
    }
    return 0;
}

static int parse_causality(const char* text, probe_causality* causality)
{
    static const char* const names[] = {
        "parameter", "calculatedParameter", "structuralParameter", "input", "output",
        "local",     "independent"};
    int k;
    if (!parse_enum(text, names, sizeof names / sizeof names[0], PROBE_LOCAL, &k)) {
        return 0;
    }
    *causality = (probe_causality)k;
    return 1;
}

static int parse_variability(const char* text, probe_variability* variability)
{
    static const char* const names[] = {"constant", "fixed", "tunable", "discrete", "continuous"};
    int k;
    if (!parse_enum(text, names, sizeof names / sizeof names[0], PROBE_CONTINUOUS, &k)) {
        return 0;
    }
    *variability = (probe_variability)k;
    return 1;
}

/* Element names of variable types: FMI 2 (child of <ScalarVariable>), FMI 3. */
static int type_of_element(int fmi_version, const char* name, probe_type* type)
{
    static const char* const fmi2_others[] = {"Boolean", "String"};
    static const char* const fmi3_others[] = {"Float32", "Int8",   "UInt8",  "Int16",
                                              "UInt16",  "UInt32", "Int64",  "UInt64",
                                              "Boolean", "String", "Binary", "Clock"};
    const char* const* others = fmi_version == 2 ? fmi2_others : fmi3_others;
    const size_t count = fmi_version == 2 ? sizeof fmi2_others / sizeof fmi2_others[0]
                                          : sizeof fmi3_others / sizeof fmi3_others[0];
    size_t k;
    if (strcmp(name, fmi_version == 2 ? "Real" : "Float64") == 0) {
        *type = PROBE_REAL;
        return 1;
    }
    if (strcmp(name, fmi_version == 2 ? "Integer" : "Int32") == 0) {
        *type = PROBE_INTEGER;
        return 1;
    }
    if (strcmp(name, "Enumeration") == 0) {
        *type = PROBE_ENUMERATION;
        return 1;
    }
    for (k = 0; k < count; ++k) {
        if (strcmp(name, others[k]) == 0) {
            *type = PROBE_OTHER;
            return 1;
        }
    }
    return 0;
}

static int fail(char* error, size_t error_size, const char* format, ...) PROBE_PRINTF_FORMAT(3, 4);
static int fail(char* error, size_t error_size, const char* format, ...)
{
    va_list args;
    va_start(args, format);
    vsnprintf(error, error_size, format, args);
    va_end(args);
    return 0;
}

static char* read_file(const char* path, char* error, size_t error_size)
{
    FILE* file = fopen(path, "rb");
    char* text;
    long size;
    if (file == NULL) {
        fail(error, error_size, "cannot open %s", path);
        return NULL;
    }
    if (fseek(file, 0, SEEK_END) != 0 || (size = ftell(file)) < 0 || size > (64L << 20) ||
        fseek(file, 0, SEEK_SET) != 0) {
        fclose(file);
        fail(error, error_size, "cannot read %s", path);
        return NULL;
    }
    text = (char*)malloc((size_t)size + 1);
    if (text == NULL || fread(text, 1, (size_t)size, file) != (size_t)size) {
        free(text);
        fclose(file);
        fail(error, error_size, "cannot read %s", path);
        return NULL;
    }
    text[size] = '\0';
    fclose(file);
    return text;
}

/* Starts a variable from the attributes FMI 2's <ScalarVariable> and FMI 3's
 * type elements share. */
static int begin_variable(const xml_tag* tag, probe_variable* v, char* error, size_t error_size)
{
    const char* name = tag_attribute(tag, "name");
    const char* vr = tag_attribute(tag, "valueReference");
    char* stop;
    unsigned long number;
    memset(v, 0, sizeof *v);
    if (name == NULL || vr == NULL) {
        return fail(error, error_size, "a variable without name or valueReference");
    }
    number = strtoul(vr, &stop, 10);
    if (stop == vr || *stop != '\0' || number > UINT_MAX) {
        return fail(error, error_size, "%s: valueReference '%s'", name, vr);
    }
    v->vr = (unsigned)number;
    if (!parse_causality(tag_attribute(tag, "causality"), &v->causality) ||
        !parse_variability(tag_attribute(tag, "variability"), &v->variability)) {
        return fail(error, error_size, "%s: unknown causality or variability", name);
    }
    v->name = copy_string(name);
    return v->name != NULL;
}

/* Start, min and max of a type element (FMI 2's child, FMI 3's variable). */
static void read_bounds(const xml_tag* tag, probe_variable* v)
{
    v->has_start = parse_number(tag_attribute(tag, "start"), &v->start);
    v->has_min = parse_number(tag_attribute(tag, "min"), &v->min);
    v->has_max = parse_number(tag_attribute(tag, "max"), &v->max);
}

static int add_variable(probe_model* model, const probe_variable* v, size_t* capacity)
{
    if (model->variable_count == *capacity) {
        const size_t grown = *capacity == 0 ? 64 : 2 * *capacity;
        probe_variable* more =
            (probe_variable*)realloc(model->variables, grown * sizeof *model->variables);
        if (more == NULL) {
            return 0;
        }
        model->variables = more;
        *capacity = grown;
    }
    model->variables[model->variable_count++] = *v;
    return 1;
}

static int read_variables(const char* text, probe_model* model, char* error, size_t error_size)
{
    const char* cursor = text;
    xml_tag tag;
    size_t capacity = 0;
    int in_variables = 0, in_scalar = 0, status = 0, ok = 1;
    probe_variable current;
    memset(&tag, 0, sizeof tag);
    memset(&current, 0, sizeof current);
    while (ok && (status = next_tag(&cursor, &tag)) == 1) {
        if (strcmp(tag.name, "fmiModelDescription") == 0 && !tag.closing) {
            const char* version = tag_attribute(&tag, "fmiVersion");
            const char* token = tag_attribute(&tag, "guid");
            if (token == NULL) {
                token = tag_attribute(&tag, "instantiationToken");
            }
            if (version == NULL || token == NULL || (version[0] != '2' && version[0] != '3')) {
                ok = fail(error, error_size,
                          "fmiModelDescription: no fmiVersion 2 or 3, or no token");
                break;
            }
            model->fmi_version = version[0] - '0';
            model->token = copy_string(token);
        } else if (strcmp(tag.name, "CoSimulation") == 0 && !tag.closing) {
            const char* id = tag_attribute(&tag, "modelIdentifier");
            const char* derivatives =
                tag_attribute(&tag, model->fmi_version == 2 ? "providesDirectionalDerivative"
                                                            : "providesDirectionalDerivatives");
            if (id == NULL) {
                ok = fail(error, error_size, "CoSimulation without modelIdentifier");
                break;
            }
            model->identifier = copy_string(id);
            model->provides_directional_derivatives =
                derivatives != NULL && strcmp(derivatives, "true") == 0;
            model->interpolates = tag_attribute(&tag, "maxOutputDerivativeOrder") != NULL &&
                                  atoi(tag_attribute(&tag, "maxOutputDerivativeOrder")) >= 1;
        } else if (strcmp(tag.name, "ModelVariables") == 0) {
            in_variables = !tag.closing && !tag.self_closing;
        } else if (in_variables && model->fmi_version == 2 &&
                   strcmp(tag.name, "ScalarVariable") == 0) {
            if (tag.closing) {
                in_scalar = 0;
                ok = add_variable(model, &current, &capacity);
                memset(&current, 0, sizeof current);
            } else {
                ok = begin_variable(&tag, &current, error, error_size);
                current.type = PROBE_OTHER;
                in_scalar = 1;
            }
        } else if (in_variables && model->fmi_version == 2 && in_scalar && !tag.closing) {
            probe_type type;
            if (type_of_element(2, tag.name, &type)) {
                current.type = type;
                read_bounds(&tag, &current);
            }
        } else if (in_variables && model->fmi_version == 3 && !tag.closing) {
            probe_type type;
            if (strcmp(tag.name, "Dimension") == 0 && model->variable_count > 0) {
                model->variables[model->variable_count - 1].is_array = 1;
            } else if (type_of_element(3, tag.name, &type)) {
                ok = begin_variable(&tag, &current, error, error_size);
                if (ok) {
                    current.type = type;
                    read_bounds(&tag, &current);
                    ok = add_variable(model, &current, &capacity);
                    memset(&current, 0, sizeof current);
                }
            }
        }
    }
    tag_clear(&tag);
    free(current.name);
    if (ok && status < 0) {
        ok = fail(error, error_size, "malformed XML near byte %ld", (long)(cursor - text));
    }
    if (ok && (model->identifier == NULL || model->token == NULL)) {
        ok = fail(error, error_size, "no <CoSimulation> modelIdentifier or no token");
    }
    return ok;
}

int probe_read_model(const char* directory, probe_model* model, char* error, size_t error_size)
{
    char* path;
    char* text;
    int ok;
    memset(model, 0, sizeof *model);
    path = (char*)malloc(strlen(directory) + 64);
    if (path == NULL) {
        return fail(error, error_size, "out of memory");
    }
    sprintf(path, "%s/modelDescription.xml", directory);
    text = read_file(path, error, error_size);
    free(path);
    if (text == NULL) {
        return 0;
    }
    ok = read_variables(text, model, error, error_size);
    free(text);
    if (!ok) {
        probe_free_model(model);
        return 0;
    }
    model->directory = copy_string(directory);
    model->binary_path = (char*)malloc(strlen(directory) + strlen(model->identifier) + 64);
    if (model->directory == NULL || model->binary_path == NULL) {
        probe_free_model(model);
        return fail(error, error_size, "out of memory");
    }
    sprintf(model->binary_path, "%s/binaries/%s/%s" PROBE_BINARY_SUFFIX, directory,
            model->fmi_version == 2 ? PROBE_PLATFORM_FMI2 : PROBE_PLATFORM_FMI3, model->identifier);
    return 1;
}

void probe_free_model(probe_model* model)
{
    size_t k;
    for (k = 0; k < model->variable_count; ++k) {
        free(model->variables[k].name);
    }
    free(model->variables);
    free(model->identifier);
    free(model->token);
    free(model->directory);
    free(model->binary_path);
    memset(model, 0, sizeof *model);
}

const probe_variable* probe_variable_named(const probe_model* model, const char* name)
{
    size_t k;
    for (k = 0; k < model->variable_count; ++k) {
        if (strcmp(model->variables[k].name, name) == 0) {
            return &model->variables[k];
        }
    }
    return NULL;
}

const probe_variable* probe_state_start(const probe_model* model, const probe_variable* v)
{
    static const char* const drive[][2] = {{"crank.angle", "start.angle"},
                                           {"crank.omega", "start.speed"}};
    char name[256];
    const probe_variable* start;
    size_t k;
    if (v->causality != PROBE_OUTPUT || strlen(v->name) + sizeof "_start" > sizeof name) {
        return NULL;
    }
    snprintf(name, sizeof name, "%s_start", v->name);
    start = probe_variable_named(model, name);
    for (k = 0; start == NULL && k < sizeof drive / sizeof drive[0]; ++k) {
        if (strcmp(v->name, drive[k][0]) == 0) {
            start = probe_variable_named(model, drive[k][1]);
        }
    }
    return start != NULL && start->causality == PROBE_PARAMETER ? start : NULL;
}

int probe_has_states(const probe_model* model)
{
    size_t k;
    for (k = 0; k < model->variable_count; ++k) {
        if (probe_state_start(model, &model->variables[k]) != NULL) {
            return 1;
        }
    }
    return 0;
}

const probe_variable* probe_variable_of_vr(const probe_model* model, unsigned vr)
{
    size_t k;
    for (k = 0; k < model->variable_count; ++k) {
        if (model->variables[k].vr == vr) {
            return &model->variables[k];
        }
    }
    return NULL;
}

int probe_settable_before_initialization(const probe_variable* v)
{
    return v->causality == PROBE_INPUT ||
           (v->causality == PROBE_PARAMETER && v->variability != PROBE_CONSTANT);
}

int probe_settable_in_step_mode(const probe_variable* v)
{
    return v->causality == PROBE_INPUT ||
           (v->causality == PROBE_PARAMETER && v->variability == PROBE_TUNABLE);
}

unsigned probe_unused_vr(const probe_model* model)
{
    unsigned highest = 0;
    size_t k;
    for (k = 0; k < model->variable_count; ++k) {
        if (model->variables[k].vr > highest) {
            highest = model->variables[k].vr;
        }
    }
    return highest + 1;
}

/* ---- loading -------------------------------------------------------------------------------- */

#if defined(_WIN32)
int probe_resolve(void* library, const char* name, void* function_pointer, char* error,
                  size_t error_size)
{
    FARPROC symbol = GetProcAddress((HMODULE)library, name);
    if (symbol == NULL) {
        return fail(error, error_size, "missing symbol %s", name);
    }
    memcpy(function_pointer, &symbol, sizeof symbol);
    return 1;
}

static void* open_library(const probe_model* model, char* error, size_t error_size)
{
    HMODULE library = LoadLibraryA(model->binary_path);
    if (library == NULL) {
        fail(error, error_size, "cannot load %s: error %lu", model->binary_path,
             (unsigned long)GetLastError());
    }
    return (void*)library;
}
#else
int probe_resolve(void* library, const char* name, void* function_pointer, char* error,
                  size_t error_size)
{
    void* symbol = dlsym(library, name);
    if (symbol == NULL) {
        return fail(error, error_size, "missing symbol %s", name);
    }
    /* ISO C has no conversion from void* to a function pointer; POSIX guarantees
     * the representation is the same. */
    memcpy(function_pointer, &symbol, sizeof symbol);
    return 1;
}

static void* open_library(const probe_model* model, char* error, size_t error_size)
{
    void* library = dlopen(model->binary_path, RTLD_NOW | RTLD_LOCAL);
    if (library == NULL) {
        fail(error, error_size, "cannot load %s: %s", model->binary_path, dlerror());
    }
    return library;
}
#endif

#define PROBE_RESOLVE2(name) \
    ok = ok && probe_resolve(api->library, "fmi2" #name, &api->name, error, error_size);
#define PROBE_RESOLVE3(name) \
    ok = ok && probe_resolve(api->library, "fmi3" #name, &api->name, error, error_size);

int probe_load_fmi2(const probe_model* model, probe_fmi2* api, char* error, size_t error_size)
{
    int ok = 1;
    memset(api, 0, sizeof *api);
    api->library = open_library(model, error, error_size);
    if (api->library == NULL) {
        return 0;
    }
    PROBE_FMI2_FUNCTIONS(PROBE_RESOLVE2)
    if (!ok) {
        probe_unload(api->library);
    }
    return ok;
}

int probe_load_fmi3(const probe_model* model, probe_fmi3* api, char* error, size_t error_size)
{
    int ok = 1;
    memset(api, 0, sizeof *api);
    api->library = open_library(model, error, error_size);
    if (api->library == NULL) {
        return 0;
    }
    PROBE_FMI3_FUNCTIONS(PROBE_RESOLVE3)
    if (!ok) {
        probe_unload(api->library);
    }
    return ok;
}

void probe_unload(void* library)
{
    if (library != NULL) {
#if defined(_WIN32)
        FreeLibrary((HMODULE)library);
#else
        dlclose(library);
#endif
    }
}

/* ---- the logger ----------------------------------------------------------------------------- */

void probe_log_book_clear(probe_log_book* book)
{
    book->count = 0;
    book->last_status = 0;
    book->last[0] = '\0';
    book->hash = PROBE_HASH_START;
}

static void record(probe_log_book* book, int status, const char* message)
{
    ++book->count;
    book->last_status = status;
    book->hash = probe_hash_string(probe_hash_u64(book->hash, (uint64_t)status), message);
}

void probe_fmi2_logger(fmi2ComponentEnvironment environment, fmi2String instance_name,
                       fmi2Status status, fmi2String category, fmi2String message, ...)
{
    probe_log_book* book = (probe_log_book*)environment;
    va_list args;
    (void)instance_name;
    (void)category;
    if (book == NULL) {
        return;
    }
    va_start(args, message);
    vsnprintf(book->last, sizeof book->last, message, args);
    va_end(args);
    record(book, (int)status, book->last);
}

void probe_fmi3_logger(fmi3InstanceEnvironment environment, fmi3Status status, fmi3String category,
                       fmi3String message)
{
    probe_log_book* book = (probe_log_book*)environment;
    (void)category;
    if (book == NULL) {
        return;
    }
    snprintf(book->last, sizeof book->last, "%s", message != NULL ? message : "(NULL)");
    record(book, (int)status, book->last);
}

fmi2CallbackFunctions probe_fmi2_callbacks(probe_log_book* book)
{
    fmi2CallbackFunctions callbacks;
    memset(&callbacks, 0, sizeof callbacks);
    callbacks.logger = probe_fmi2_logger;
    callbacks.allocateMemory = calloc;
    callbacks.freeMemory = free;
    callbacks.componentEnvironment = book;
    return callbacks;
}

/* ---- random numbers and hashing ------------------------------------------------------------- */

uint64_t probe_splitmix64(uint64_t* state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

void probe_rng_seed(probe_rng* rng, uint64_t seed)
{
    int k;
    for (k = 0; k < 4; ++k) {
        rng->s[k] = probe_splitmix64(&seed);
    }
}

static uint64_t rotl(uint64_t x, int k)
{
    return (x << k) | (x >> (64 - k));
}

uint64_t probe_rng_next(probe_rng* rng)
{
    uint64_t* s = rng->s;
    const uint64_t result = rotl(s[1] * 5, 7) * 9;
    const uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

double probe_rng_uniform(probe_rng* rng)
{
    return (double)(probe_rng_next(rng) >> 11) * 0x1.0p-53;
}

uint64_t probe_rng_below(probe_rng* rng, uint64_t n)
{
    /* n is small in every use: the modulo bias is below 2^-40 */
    return probe_rng_next(rng) % n;
}

uint64_t probe_hash_u64(uint64_t h, uint64_t v)
{
    int k;
    for (k = 0; k < 8; ++k) {
        h ^= (v >> (8 * k)) & 0xFFu;
        h *= 0x100000001B3ULL;
    }
    return h;
}

uint64_t probe_bits(double x)
{
    uint64_t bits;
    memcpy(&bits, &x, sizeof bits);
    return bits;
}

uint64_t probe_hash_double(uint64_t h, double x)
{
    return probe_hash_u64(h, probe_bits(x));
}

uint64_t probe_hash_string(uint64_t h, const char* s)
{
    for (; *s != '\0'; ++s) {
        h ^= (unsigned char)*s;
        h *= 0x100000001B3ULL;
    }
    return probe_hash_u64(h, 0);
}
