/* dyadfmu: the small runner shared by the C test executables: a table of named
 * tests, run all or by name, each printing its failures; the closing line
 * "N passed, N failed" is what CI reads. */
#ifndef DYADFMU_NAMED_TESTS_H
#define DYADFMU_NAMED_TESTS_H

#include <stdio.h>
#include <string.h>

/* A test file that counts its checks defines NAMED_TESTS_ON_CHECK() before
 * including this header. */
#ifndef NAMED_TESTS_ON_CHECK
#define NAMED_TESTS_ON_CHECK() ((void)0)
#endif

#define CHECK(cond, ...)                                    \
    do {                                                    \
        NAMED_TESTS_ON_CHECK();                             \
        if (!(cond)) {                                      \
            printf("    FAIL %s:%d: ", __FILE__, __LINE__); \
            printf(__VA_ARGS__);                            \
            printf("\n");                                   \
            ++fails;                                        \
        }                                                   \
    } while (0)

typedef struct named_test {
    const char* name;
    int (*run)(void); /* returns the number of failed checks */
} named_test;

/* Runs the tests named in names[0..count_names) (all if none), printing each
 * under `label`; returns the number that failed, or -1 if none ran. */
static int run_named_tests(const named_test tests[], size_t count, const char* label,
                           char* const names[], int count_names)
{
    int failed = 0, passed = 0, a;
    size_t k;
    if (count_names == 1 && (strcmp(names[0], "--help") == 0 || strcmp(names[0], "-h") == 0)) {
        printf("usage: TESTS [NAME ...]\nRuns the named tests (all without a name) and prints "
               "each one's result; exits non-zero if one fails. The tests:\n");
        for (k = 0; k < count; ++k) {
            printf("  %s\n", tests[k].name);
        }
        return 0;
    }
    for (k = 0; k < count; ++k) {
        int selected = count_names == 0;
        for (a = 0; a < count_names; ++a) {
            selected |= strcmp(names[a], tests[k].name) == 0;
        }
        if (!selected) {
            continue;
        }
        printf("[%s] %s\n", label, tests[k].name);
        if (tests[k].run() == 0) {
            ++passed;
        } else {
            ++failed;
            printf("    -> FAILED\n");
        }
    }
    printf("%d passed, %d failed\n", passed, failed);
    return passed == 0 ? -1 : failed;
}

#endif /* DYADFMU_NAMED_TESTS_H */
