/* bench/clock.c - the benchmark's clock, in a file of its own: main.c and the
   method files (m_*.c, march_cpu.c) all read it, and none calls into
   another's. */
#define _POSIX_C_SOURCE 200809L
#include <time.h>

double bench_now_ms(void); /* bench/bench.h */
double bench_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}
