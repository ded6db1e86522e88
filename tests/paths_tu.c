/* tests/paths_tu.c - linear_rt.h's implementation in a translation unit of
   its own, compiled once per traversal path and per build of the Makefile's
   PATHS_BUILDS (compiler, language, flags), PATHS_FN naming its one entry
   point. LINEAR_RT_STATIC keeps each copy to itself, so tests/test_paths.c
   links them side by side and compares their answers. */
#define LINEAR_RT_STATIC
#define LINEAR_RT_IMPLEMENTATION
#include "../linear_rt.h"
#include "support/build_trace.h"

#ifdef __cplusplus
extern "C" {
#endif
/* builds a BVH over depth and traces rays with this unit's copy; an lrt_result */
int PATHS_FN(const lrt_depth *depth, const lrt_build_options *opt, const lrt_ray *rays, lrt_hit *hits, size_t n, uint32_t flags);
#ifdef __cplusplus
}
#endif
int PATHS_FN(const lrt_depth *depth, const lrt_build_options *opt, const lrt_ray *rays, lrt_hit *hits, size_t n, uint32_t flags)
{
    return build_and_trace(depth, opt, rays, hits, n, flags);
}
