/* tests/fuzz/fuzz_common.h - what the harnesses of tests/fuzz/ share:
   libFuzzer's initializer, which has each harness print its counts when a
   run ends, and the rule of the trace flags both trace calls check. A
   harness defines fuzz_print_counts (declared here) and
   LLVMFuzzerTestOneInput, and includes linear_rt.h first where it traces. */
#ifndef FUZZ_COMMON_H
#define FUZZ_COMMON_H

#include <stdint.h>
#include <stdlib.h>

/* trace flags lrt_trace and lrt_vk_cmd_trace refuse (LRT_ERROR_INVALID_OPTION):
   a bit past the budget's and the finish's, a finish past 2^7 samples, or a
   finish without a budget (docs: LRT_TRACE_FINISH); for the harnesses that
   include linear_rt.h */
#ifdef LINEAR_RT_CONTRACT
static int fuzz_trace_flags_bad(uint32_t flags)
{
    const uint32_t finish = (flags & LRT_K_TRACE_FINISH_MASK) >> LRT_K_TRACE_FINISH_SHIFT;
    return (flags & ~(uint32_t)(LRT_K_TRACE_BUDGET_MASK | LRT_K_TRACE_FINISH_MASK)) || finish > LRT_K_FINISH_MAX ||
           (finish && !(flags & LRT_K_TRACE_BUDGET_MASK));
}
#endif

static void fuzz_print_counts(void);

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    atexit(fuzz_print_counts);
    return 0;
}

#endif
