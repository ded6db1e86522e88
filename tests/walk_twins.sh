#!/bin/sh
# tests/walk_twins.sh - every pair of linear_rt.h's TWINS table (section walk:
# a C helper of the walks ~ its GLSL twin) is defined on both sides: the C
# name as a function in linear_rt.h, the GLSL name in shaders/linear_rt.glsl.
# Exit 1, naming the pair, when one side is missing. Run by make check.
set -eu
cd "$(dirname "$0")/.."
pairs=$(awk '/^   -- twins --$/ { f = 1; next } /^   -- end twins --$/ { f = 0 } f' linear_rt.h |
    grep -oE 'lrt__[a-z0-9_]+ ~ lrt_[a-z0-9_]+' || true)
[ -n "$pairs" ] || { echo "walk_twins: FAIL: no TWINS table in linear_rt.h"; exit 1; }
n=0 bad=0
echo "$pairs" | {
    while read -r c _ g; do
        n=$((n + 1))
        # a definition: the name, then '(', at the start of a declaration line
        if ! grep -qE "^(LRT__FORCE_INLINE|LRT__UNUSED static|static|LRT__INLINE)[^(]* \*?$c\(" linear_rt.h; then
            echo "walk_twins: FAIL: $c (twin of $g) is not defined in linear_rt.h"; bad=$((bad + 1))
        fi
        if ! grep -qE "^[A-Za-z0-9_]+ $g\(" shaders/linear_rt.glsl; then
            echo "walk_twins: FAIL: $g (twin of $c) is not defined in shaders/linear_rt.glsl"; bad=$((bad + 1))
        fi
    done
    if [ $bad -ne 0 ]; then exit 1; fi
    echo "walk_twins: ok, $n pairs, each defined in C and GLSL"
}
