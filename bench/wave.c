/* bench/wave.c - what a wave pays: the steps of each ray of a set for the
   benchmark's Vulkan marches, counted in a copy of bench/march_cpu.c of this
   file's own (its MARCH_COUNT_STEP hook defined here), so the timed copy
   counts nothing. The CPU marches mirror the Vulkan peers' loops
   (bench/shaders/vkp_march64.comp, vkp_dda.comp, vkp_hiz.comp): the same
   samples, columns and iterations, in double where the kernels use float
   (and with the CPU's Hi-Z nudge of 1e-6 texel and no depth bias), so a
   ray whose sample lands on an edge may count a step more or less. The
   counters are this file's: one thread at a time. */
#include <stddef.h>
#include <stdint.h>

static uint32_t wave_count;
#define MARCH_COUNT_STEP() (++wave_count)
/* the copy's own adder, unused: the benchmark's methods are march_cpu.c's */
#define bench_add_march_cpu bench_wave_march_copy_unused
#include "march_cpu.c"

int bench_wave_march(const bench_scene *sc, const bench_rays *rs, int which, uint32_t *steps)
{
    march m;
    march_job jb;
    char why[128];
    double ms;
    size_t q;
    memset(&m, 0, sizeof m);
    m.kind = which == 0 ? MARCH_LINEAR : which == 1 ? MARCH_DDA : MARCH_HIZ;
    m.param = which == 0 ? 64 : which == 1 ? 1 : 64; /* the Vulkan peers: march64, dda stride 1, hiz64 */
    m.threads = 1;
    if (m.kind == MARCH_HIZ && hiz_build_chain(&m, sc, &ms, why, sizeof why)) return 1;
    march_job_init(&jb, &m, sc, rs->rays, NULL);
    for (q = 0; q < rs->count; ++q) {
        lrt_hit hit;
        wave_count = 0;
        switch (m.kind) {
        case MARCH_LINEAR: linear_one(&jb, &rs->rays[q], &hit); break;
        case MARCH_DDA: dda_one(&jb, &rs->rays[q], &hit); break;
        default: hiz_one(&jb, &rs->rays[q], &hit); break;
        }
        steps[q] = wave_count;
    }
    free(m.chain);
    return 0;
}

/* The mean of steps, and the mean over groups of `wave` consecutive rays
   (dispatch order; the last group may be short) of the group's most. */
void bench_wave_stats(const uint32_t *steps, size_t n, uint32_t wave, double *mean, double *wave_mean)
{
    size_t i, groups = 0;
    double sum = 0.0, wsum = 0.0;
    for (i = 0; i < n; i += wave) {
        size_t j, end = i + wave < n ? i + wave : n;
        uint32_t most = 0;
        for (j = i; j < end; ++j) {
            sum += steps[j];
            most = steps[j] > most ? steps[j] : most;
        }
        wsum += most;
        ++groups;
    }
    *mean = n ? sum / (double)n : 0.0;
    *wave_mean = groups ? wsum / (double)groups : 0.0;
}

/* The mean over groups of `wave` rays of the group's most trips, and of the
   number of distinct trips at which some lane of the group left the loop
   (exit_at[j]: the trip at which ray j left from inside, 0 for none): a
   wave runs a loop's exit blocks once for each of those. */
static void wave_trips(const uint32_t *trips, const uint32_t *exit_at, size_t n, uint32_t wave, double *trips_mean,
                       double *exits_mean)
{
    size_t i, groups = 0;
    double tsum = 0.0, esum = 0.0;
    for (i = 0; i < n; i += wave) {
        size_t j, k, end = i + wave < n ? i + wave : n;
        uint32_t most = 0;
        int distinct = 0;
        for (j = i; j < end; ++j) {
            int seen = 0;
            most = trips[j] > most ? trips[j] : most;
            if (!exit_at[j]) continue;
            for (k = i; k < j && !seen; ++k) seen = exit_at[k] == exit_at[j];
            distinct += !seen;
        }
        tsum += most;
        esum += distinct;
        ++groups;
    }
    *trips_mean = groups ? tsum / (double)groups : 0.0;
    *exits_mean = groups ? esum / (double)groups : 0.0;
}

/* The march counts each sample and each of its MARCH_BISECTIONS bisection
   steps. Its 65 samples lie on the clipped segment, so a miss takes 65; a
   hit at sample 0 takes 1; a hit at sample k >= 1 refines, k + 1 +
   MARCH_BISECTIONS. So a count of MARCH_BISECTIONS + 2 or more other than
   65 is a refinement (one at k = 56 also counts 65: taken as a miss): its
   trips are its samples, and it leaves by the refinement at the last. */
void bench_wave_march_blocks(const uint32_t *steps, size_t n, uint32_t wave, double *trips, double *refine_trips)
{
    uint32_t *samples = (uint32_t *)malloc(sizeof(uint32_t) * (n ? n : 1)), *exit_at = (uint32_t *)malloc(sizeof(uint32_t) * (n ? n : 1));
    size_t j;
    *trips = *refine_trips = 0.0;
    if (samples && exit_at) {
        for (j = 0; j < n; ++j) {
            const int refined = steps[j] >= MARCH_BISECTIONS + 2u && steps[j] != 65u;
            samples[j] = refined ? steps[j] - MARCH_BISECTIONS : steps[j];
            exit_at[j] = refined ? samples[j] : 0u;
        }
        wave_trips(samples, exit_at, n, wave, trips, refine_trips);
    }
    free(samples);
    free(exit_at);
}

void bench_wave_exits(const uint32_t *steps, size_t n, uint32_t wave, uint32_t cap, double *trips, double *exit_trips)
{
    uint32_t *exit_at = (uint32_t *)malloc(sizeof(uint32_t) * (n ? n : 1));
    size_t j;
    *trips = *exit_trips = 0.0;
    if (exit_at) {
        for (j = 0; j < n; ++j) exit_at[j] = steps[j] < cap ? steps[j] : 0u; /* at the cap: after the loop */
        wave_trips(steps, exit_at, n, wave, trips, exit_trips);
    }
    free(exit_at);
}
