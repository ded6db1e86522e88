/* tests/fuzz/fuzz_common.h - what the harnesses of tests/fuzz/ share:
   libFuzzer's initializer, which has each harness print its counts when a
   run ends. A harness defines fuzz_print_counts (declared here) and
   LLVMFuzzerTestOneInput. */
#ifndef FUZZ_COMMON_H
#define FUZZ_COMMON_H

#include <stdlib.h>

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
