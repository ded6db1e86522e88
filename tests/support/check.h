/* tests/support/check.h - the tests' one assertion: CHECK(cond, printf-args) counts
   a pass or prints the failure and counts it; check_summary() prints the
   closing "N passed, M failed" line and gives the exit code.
   One test of a program: `build/test_core test_update` runs only the test
   function of that name (check_select(argc, argv) first, then RUN_TEST(fn)
   for each test); a name no test has is an error (exit 2). */
#ifndef LINEAR_RT_TESTS_CHECK_H
#define LINEAR_RT_TESTS_CHECK_H

#include <stdio.h>
#include <string.h>

static int g_pass, g_fail;
static const char *g_only_test; /* NULL: every test */
static int g_tests_run;

#define CHECK(cond, ...)                                                  \
    do {                                                                  \
        if (cond) ++g_pass;                                               \
        else {                                                            \
            ++g_fail;                                                     \
            printf("FAIL %s:%d: ", __FILE__, __LINE__);                   \
            printf(__VA_ARGS__);                                          \
            printf("\n");                                                 \
        }                                                                 \
    } while (0)

/* The test the command line names, if any: argv[1] (later arguments are
   the program's own). */
static void check_select(int argc, char **argv)
{
    g_only_test = argc > 1 && argv[1][0] != '-' ? argv[1] : NULL;
}

/* Is test `name` to run? Counts it if so. */
static int check_wanted(const char *name)
{
    if (g_only_test && strcmp(g_only_test, name) != 0) return 0;
    ++g_tests_run;
    return 1;
}

/* a test function without arguments; others: if (check_wanted("name")) ... */
#define RUN_TEST(fn)                     \
    do {                                 \
        if (check_wanted(#fn)) fn();     \
    } while (0)

static int check_summary(void)
{
    (void)check_select; /* a program that runs every test never calls them */
    (void)check_wanted;
    if (g_only_test && g_tests_run == 0) {
        printf("no test named %s in this program\n", g_only_test);
        return 2;
    }
    printf("%d passed, %d failed\n", g_pass, g_fail);
    return g_fail ? 1 : 0;
}

#endif
