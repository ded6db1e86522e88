#!/bin/sh
# tests/walk_twins.sh - every pair of linear_rt.h's TWINS table (section walk:
# a C helper of the walks ~ its GLSL twin) is defined on both sides: the C
# name as a function in linear_rt.h, the GLSL name in shaders/linear_rt.glsl;
# and the parameters both sides name come in the same order (C's w, the
# walk's constants, stands for GLSL's p; enter and exit for en and ex).
# Exit 1, naming the pair, when one side is missing or the order differs.
# Run by make check.
set -eu
cd "$(dirname "$0")/.."
pairs=$(awk '/^   -- twins --$/ { f = 1; next } /^   -- end twins --$/ { f = 0 } f' linear_rt.h |
    grep -oE 'lrt__[a-z0-9_]+ ~ lrt_[a-z0-9_]+' || true)
[ -n "$pairs" ] || { echo "walk_twins: FAIL: no TWINS table in linear_rt.h"; exit 1; }
# params FILE REGEX: the parameter names of the first definition matching
# REGEX, one line, each name as the other side calls it
params() {
    awk -v re="$2" '
        !on && $0 ~ re { on = 1; sig = "" }
        on { sig = sig " " $0; if (index($0, ")")) { on = 0; done = 1 } }
        done { exit }
        END {
            sub(/^[^(]*\(/, "", sig); sub(/\).*$/, "", sig)
            n = split(sig, ps, ",")
            out = ""
            for (i = 1; i <= n; ++i) {
                p = ps[i]; gsub(/\[[^]]*\]/, "", p); gsub(/[*]/, " ", p)
                m = split(p, ws, " "); name = ws[m]
                if (name == "w") name = "p"; else if (name == "enter") name = "en"; else if (name == "exit") name = "ex"
                out = out " " name
            }
            print out
        }' "$1"
}
# shared A B: the names of list A that list B holds too, in A's order
shared() { for x in $1; do case " $2 " in *" $x "*) printf ' %s' "$x" ;; esac; done; }
n=0 bad=0
echo "$pairs" | {
    while read -r c _ g; do
        n=$((n + 1))
        cdef="^(LRT__FORCE_INLINE|LRT__UNUSED static|static|LRT__INLINE)[^(]* \\*?$c\\("
        gdef="^[A-Za-z0-9_]+ $g\\("
        if ! grep -qE "$cdef" linear_rt.h; then
            echo "walk_twins: FAIL: $c (twin of $g) is not defined in linear_rt.h"; bad=$((bad + 1)); continue
        fi
        if ! grep -qE "$gdef" shaders/linear_rt.glsl; then
            echo "walk_twins: FAIL: $g (twin of $c) is not defined in shaders/linear_rt.glsl"; bad=$((bad + 1)); continue
        fi
        cp=$(params linear_rt.h "$cdef") gp=$(params shaders/linear_rt.glsl "$gdef")
        a=$(shared "$cp" "$gp") b=$(shared "$gp" "$cp")
        if [ "$a" != "$b" ]; then
            echo "walk_twins: FAIL: $c ($a) and $g ($b) take their shared parameters in different orders"
            bad=$((bad + 1))
        fi
    done
    if [ $bad -ne 0 ]; then exit 1; fi
    echo "walk_twins: ok, $n pairs, each defined in C and GLSL, shared parameters in one order"
}
