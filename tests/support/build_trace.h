/* tests/support/build_trace.h - build a BVH over a depth map and trace rays
   with it, in one call: the entry point of each copy of the implementation
   in tests/paths_tu.c, and of tests/test_paths.c's own copy. Include it
   after linear_rt.h's implementation. */
#ifndef LRT_TEST_BUILD_TRACE_H
#define LRT_TEST_BUILD_TRACE_H

#include <string.h>

#if defined(__GNUC__) || defined(__clang__)
#define BUILD_TRACE_FN static __attribute__((unused))
#else
#define BUILD_TRACE_FN static
#endif

/* an lrt_result: the build's, or the trace's */
BUILD_TRACE_FN int build_and_trace(const lrt_depth *depth, const lrt_build_options *opt, const lrt_ray *rays, lrt_hit *hits,
                           size_t n, uint32_t flags)
{
    lrt_bvh bvh;
    lrt_result r;
    memset(&bvh, 0, sizeof bvh); /* zeroed before its first build (C and C++ alike) */
    if ((r = lrt_bvh_build(&bvh, depth, opt, NULL)) != LRT_SUCCESS) return (int)r;
    r = lrt_trace(&bvh, depth, rays, hits, n, flags);
    lrt_bvh_destroy(&bvh);
    return (int)r;
}

#endif
