/* SPDX-License-Identifier: GPL-2.0-or-later */
/* A minimal test harness. Each test file defines cases with TEST_CASE(name)
 * and lists them in TEST_MAIN(...). CMake reads the TEST_CASE lines and
 * registers every case as its own ctest entry (`test_x case_name`); with no
 * argument the executable runs all of its cases. */
#ifndef HBAO_TEST_HARNESS_H
#define HBAO_TEST_HARNESS_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hbao.h"

static int test_failures;

/* Whether the library runs `implementation` itself on this CPU. Where it
 * does not, it runs the slower one that hbao_implementation_that_runs names,
 * in every stage; a test's loop over implementations meets that one in its
 * own turn, so it skips this one rather than run that one twice. */
static inline int implementation_runs_itself(int32_t implementation) {
    return hbao_implementation_that_runs(implementation) == implementation;
}

#define TEST_CASE(name) static void name(void)

#define CHECK(condition)                                                                           \
    do {                                                                                           \
        if (!(condition)) {                                                                        \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #condition);          \
            test_failures++;                                                                       \
        }                                                                                          \
    } while (0)

/* |actual - expected| <= tolerance, with both values printed on failure. */
#define CHECK_NEAR(actual, expected, tolerance)                                                    \
    do {                                                                                           \
        double check_a_ = (double)(actual), check_e_ = (double)(expected);                         \
        if (!(fabs(check_a_ - check_e_) <= (double)(tolerance))) {                                 \
            fprintf(stderr,                                                                        \
                    "%s:%d: CHECK_NEAR failed: %s = %.6g, expected %.6g "                          \
                    "+- %.3g\n",                                                                   \
                    __FILE__, __LINE__, #actual, check_a_, check_e_, (double)(tolerance));         \
            test_failures++;                                                                       \
        }                                                                                          \
    } while (0)

#define CHECK_RESULT(call, expected)                                                               \
    do {                                                                                           \
        int check_r_ = (int)(call);                                                                \
        if (check_r_ != (int)(expected)) {                                                         \
            fprintf(stderr, "%s:%d: %s returned %d (%s), expected %s\n", __FILE__, __LINE__,       \
                    #call, check_r_, hbao_result_message(check_r_), #expected);                    \
            test_failures++;                                                                       \
        }                                                                                          \
    } while (0)

typedef struct test_entry {
    const char *name;
    void (*run)(void);
} test_entry;

#define TEST_ENTRY(name)                                                                           \
    { #name, name }

#define TEST_MAIN(...)                                                                             \
    int main(int argc, char **argv) {                                                              \
        static const test_entry tests[] = {__VA_ARGS__};                                           \
        const size_t count = sizeof(tests) / sizeof(tests[0]);                                     \
        int ran = 0;                                                                               \
        for (size_t i = 0; i < count; i++) {                                                       \
            if (argc > 1 && strcmp(argv[1], tests[i].name) != 0) continue;                         \
            int before = test_failures;                                                            \
            tests[i].run();                                                                        \
            printf("%s %s\n", test_failures == before ? "PASS" : "FAIL", tests[i].name);           \
            ran++;                                                                                 \
        }                                                                                          \
        if (ran == 0) {                                                                            \
            fprintf(stderr, "no test case named %s\n", argc > 1 ? argv[1] : "");                   \
            return 2;                                                                              \
        }                                                                                          \
        return test_failures == 0 ? 0 : 1;                                                         \
    }

#endif /* HBAO_TEST_HARNESS_H */
