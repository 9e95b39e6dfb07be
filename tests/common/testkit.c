#include "testkit.h"

int tk_failures = 0;

static int run_case(const tk_case_t *c)
{
    const int before = tk_failures;
    c->fn();
    const int failed = tk_failures != before;
    printf("%s: %s\n", failed ? "FAIL" : "ok", c->name);
    return failed;
}

int tk_main(int argc, char **argv, const tk_case_t *cases, size_t n)
{
    int failed = 0;
    if (argc < 2) {
        for (size_t i = 0; i < n; i++) {
            failed += run_case(&cases[i]);
        }
        return failed ? 1 : 0;
    }
    for (int a = 1; a < argc; a++) {
        size_t i = 0;
        while (i < n && strcmp(cases[i].name, argv[a]) != 0) {
            i++;
        }
        if (i == n) {
            fprintf(stderr, "no test case named '%s'\n", argv[a]);
            return 2;
        }
        failed += run_case(&cases[i]);
    }
    return failed ? 1 : 0;
}
