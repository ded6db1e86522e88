/* tests/check.h - the tests' one assertion: CHECK(cond, printf-args) counts
   a pass or prints the failure and counts it; check_summary() prints the
   closing "N passed, M failed" line and gives the exit code. */
#ifndef LINEAR_RT_TESTS_CHECK_H
#define LINEAR_RT_TESTS_CHECK_H

#include <stdio.h>

static int g_pass, g_fail;

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

static int check_summary(void)
{
    printf("%d passed, %d failed\n", g_pass, g_fail);
    return g_fail ? 1 : 0;
}

#endif
