/*
 * Minimal test kit for the host tests.
 *
 * A test program holds several named cases; ctest runs each case as its own
 * test (`prog case_name`), registered by foc_add_test_cases() in CMake.
 * With no argument the program runs every case.
 *
 *   static void case_sin_error(void) { ... TK_CHECK(err <= 2, "err=%d", err); }
 *   TK_CASES(TK_CASE(case_sin_error), TK_CASE(case_cos_error))
 *
 * TK_CHECK records a failure with file:line and a printf-style message and
 * carries on; the case fails if any check failed.
 */
#ifndef TESTKIT_H
#define TESTKIT_H

#include <stdio.h>
#include <string.h>

extern int tk_failures;

#define TK_CHECK(cond, ...)                                                    \
    do {                                                                       \
        if (!(cond)) {                                                         \
            tk_failures++;                                                     \
            fprintf(stderr, "%s:%d: check failed: %s: ", __FILE__, __LINE__,   \
                    #cond);                                                    \
            fprintf(stderr, __VA_ARGS__);                                      \
            fputc('\n', stderr);                                               \
        }                                                                      \
    } while (0)

typedef struct {
    const char *name;
    void (*fn)(void);
} tk_case_t;

#define TK_CASE(f) { #f, f }

int tk_main(int argc, char **argv, const tk_case_t *cases, size_t n);

#define TK_CASES(...)                                                          \
    static const tk_case_t tk_cases_[] = { __VA_ARGS__ };                      \
    int main(int argc, char **argv)                                            \
    {                                                                          \
        return tk_main(argc, argv, tk_cases_,                                  \
                       sizeof tk_cases_ / sizeof tk_cases_[0]);                \
    }

#endif /* TESTKIT_H */
