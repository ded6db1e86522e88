#!/usr/bin/env bash
# tools/install-deps.sh [demo|test|bench] - make sure what a make target needs
# is here, and install what is missing. The Makefile calls it first thing in
# `make demo`, `make test` and `make bench`; it does nothing, in well under a
# second and with no network, when everything is there.
#   demo   make, a C compiler and its library headers, stb (libstb-dev: the
#          examples' PNG in and out), the Vulkan headers and loader and Mesa's
#          lavapipe (a Vulkan device on the CPU) new enough to have ray query:
#          Mesa 25 from bookworm-backports on Debian 12.
#   test   (the default) the demo's, and g++ and clang, the Khronos validation
#          layer, glslang and spirv-tools, valgrind, cppcheck, clang-tidy,
#          clang's sanitizer and libFuzzer runtime (libclang-rt-14-dev on
#          Debian 12) and, on amd64, gcc-multilib (32-bit builds), and
#          qemu-user where the kernel cannot run 32-bit programs.
#   bench  the tests', and gnuplot (gnuplot-nox) and Embree 3 (libembree-dev).
# Installs with apt-get (Debian/Ubuntu) as root, or through sudo. Without
# either it prints one line naming the packages and the command that
# installs them, and exits 2.
#
# bookworm-backports: when no apt source has that suite yet, the script adds
# it in /etc/apt/sources.list.d/linear-rt-backports.sources, reusing the URI
# (and key) of the Debian source already configured, so the machine's own
# mirror is used; running again finds it and changes nothing.
set -euo pipefail

BACKPORTS_FILE=/etc/apt/sources.list.d/linear-rt-backports.sources
MESA_MIN=25 # lavapipe with VK_KHR_ray_query

profile=${1:-test}
case $profile in
demo | test | bench) ;;
--bench) profile=bench ;; # the older spelling
*)
    echo "usage: tools/install-deps.sh [demo|test|bench]" >&2
    exit 2
    ;;
esac
wants() { # does this profile need what <profile> needs?
    case $1 in
    demo) return 0 ;;
    test) [ "$profile" != demo ] ;;
    bench) [ "$profile" = bench ] ;;
    esac
}

main_pkgs=() # from the release's own suites
bpo_pkgs=()  # from <codename>-backports

installed() { # a Debian package, installed (not just known)
    [ "$(dpkg-query -W -f='${Status}' "$1" 2>/dev/null)" = "install ok installed" ]
}

# Can this kernel run a 32-bit x86 program? Some VMs' cannot ("Exec format
# error" although gcc -m32 builds it): tests/hardening.mk then runs its
# 32-bit tests under qemu-i386 (qemu-user). Unknown (no gcc -m32 yet): yes.
runs_m32() {
    local dir ok=0
    dir=$(mktemp -d 2>/dev/null) || return 0
    if ! printf 'int main(void) { return 0; }\n' | gcc -m32 -x c - -o "$dir/probe" >/dev/null 2>&1 ||
        "$dir/probe" >/dev/null 2>&1; then
        ok=1
    fi
    rm -rf "$dir"
    [ "$ok" = 1 ]
}
needs_qemu_i386() { ! command -v qemu-i386 >/dev/null 2>&1 && ! runs_m32; }

tools=(make gcc)
wants test && tools+=(g++ clang)
for tool in "${tools[@]}"; do
    command -v "$tool" >/dev/null 2>&1 || main_pkgs+=("$tool")
done
# libc6-dev: a compiler without the C library headers cannot build anything
if command -v gcc >/dev/null 2>&1 &&
    ! printf '#include <stdio.h>\n#include <math.h>\n#include <pthread.h>\nint main(void){return 0;}\n' |
        gcc -x c - -o /dev/null -lm -lpthread >/dev/null 2>&1; then
    main_pkgs+=("libc6-dev")
fi

codename=""
if [ -r /etc/os-release ]; then
    # shellcheck source=/dev/null
    codename=$(. /etc/os-release && echo "${VERSION_CODENAME:-}")
fi

if command -v dpkg-query >/dev/null 2>&1; then
    installed libstb-dev || main_pkgs+=("libstb-dev") # the examples' PNG in and out
    installed libvulkan-dev || main_pkgs+=("libvulkan-dev")
    if wants test; then
        installed vulkan-validationlayers || main_pkgs+=("vulkan-validationlayers")
        command -v glslangValidator >/dev/null 2>&1 || main_pkgs+=("glslang-tools")
        command -v spirv-val >/dev/null 2>&1 || main_pkgs+=("spirv-tools")
        # tests/hardening.mk and tests/fuzz: valgrind, the static checkers,
        # clang's sanitizer and libFuzzer runtimes (of the clang installed, or
        # of the distribution's clang), and 32-bit builds on amd64
        command -v valgrind >/dev/null 2>&1 || main_pkgs+=("valgrind")
        command -v cppcheck >/dev/null 2>&1 || main_pkgs+=("cppcheck")
        command -v clang-tidy >/dev/null 2>&1 || main_pkgs+=("clang-tidy")
        if ! command -v clang >/dev/null 2>&1; then
            main_pkgs+=("libclang-rt-dev")
        elif ! printf 'int LLVMFuzzerTestOneInput(const unsigned char *d, unsigned long n) { (void)d; (void)n; return 0; }\n' |
            clang -x c -fsanitize=fuzzer,address,undefined - -o /dev/null >/dev/null 2>&1; then
            main_pkgs+=("libclang-rt-$(clang -dumpversion | cut -d. -f1)-dev") # Debian 12: libclang-rt-14-dev
        fi
        if [ "$(dpkg --print-architecture 2>/dev/null)" = amd64 ]; then
            installed gcc-multilib || main_pkgs+=("gcc-multilib") # gcc -m32: test-m32
            needs_qemu_i386 && main_pkgs+=("qemu-user")
        fi
    fi
    if wants bench; then
        command -v gnuplot >/dev/null 2>&1 || main_pkgs+=("gnuplot-nox")
        installed libembree-dev || main_pkgs+=("libembree-dev")
    fi
    mesa=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
    if ! installed mesa-vulkan-drivers || ! dpkg --compare-versions "$mesa" ge "$MESA_MIN"; then
        if [ "$codename" = bookworm ]; then
            bpo_pkgs+=("mesa-vulkan-drivers") # Debian 12's own Mesa 22 has no ray query
        else
            main_pkgs+=("mesa-vulkan-drivers")
        fi
    fi
else
    echo "install-deps: not a Debian system: install by hand what tools/install-deps.sh lists for '$profile'" >&2
    exit 0
fi

if [ ${#main_pkgs[@]} -eq 0 ] && [ ${#bpo_pkgs[@]} -eq 0 ]; then
    exit 0
fi

missing="${main_pkgs[*]}${bpo_pkgs[*]:+ ${bpo_pkgs[*]} (from $codename-backports)}"
missing=${missing# }
if [ "$(id -u)" -eq 0 ]; then
    as_root=()
elif command -v sudo >/dev/null 2>&1 && { sudo -n true 2>/dev/null || [ -t 0 ]; }; then
    as_root=(sudo)
else
    echo "install-deps: missing $missing; not root and no sudo: as root run  $0 $profile  (or apt-get install them yourself)" >&2
    exit 2
fi
if ! command -v apt-get >/dev/null 2>&1; then
    echo "install-deps: missing $missing and no apt-get here: install them by hand" >&2
    exit 2
fi
echo "install-deps: missing $missing; installing with apt-get" >&2
run_root() { ${as_root[@]+"${as_root[@]}"} "$@"; }

# Is <suite> already an apt source? (one-line .list and deb822 .sources)
has_suite() {
    local suite=$1 f
    for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
        [ -r "$f" ] || continue
        # deb [options] URI SUITE COMPONENTS...
        if sed -e 's/\[[^]]*\]//' "$f" | awk -v s="$suite" '$1 == "deb" && $3 == s { found = 1 } END { exit !found }'; then
            return 0
        fi
    done
    for f in /etc/apt/sources.list.d/*.sources; do
        [ -r "$f" ] || continue
        if awk -v s="$suite" 'tolower($1) == "suites:" { for (i = 2; i <= NF; ++i) if ($i == s) found = 1 }
                END { exit !found }' "$f"; then
            return 0
        fi
    done
    return 1
}

# The URI and Signed-By of the configured Debian source that carries
# <codename> itself; prints "URI<TAB>SIGNED_BY" (SIGNED_BY may be empty).
debian_source() {
    local suite=$1 f
    for f in /etc/apt/sources.list.d/*.sources; do
        [ -r "$f" ] || continue
        # deb822: paragraphs separated by blank lines
        awk -v s="$suite" '
            function flush() {
                if (types ~ /(^| )deb( |$)/ && has && uri != "" && !done) { print uri "\t" key; done = 1 }
                types = ""; has = 0; uri = ""; key = ""
            }
            /^[ \t]*$/ { flush(); next }
            /^[ \t]*#/ { next }
            tolower($1) == "types:" { types = " " $0 " " }
            tolower($1) == "uris:" { uri = $2 }
            tolower($1) == "suites:" { for (i = 2; i <= NF; ++i) if ($i == s) has = 1 }
            tolower($1) == "signed-by:" && NF == 2 { key = $2 }
            END { flush() }' "$f" | head -n 1 | grep . && return 0
    done
    for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
        [ -r "$f" ] || continue
        awk -v s="$suite" '
            $1 != "deb" { next }
            {
                key = ""; opts = ""
                if ($2 ~ /^\[/) { # [opt=value ...]
                    line = $0; sub(/^deb[ \t]+\[/, "", line); opts = substr(line, 1, index(line, "]") - 1)
                    sub(/^[^]]*\][ \t]*/, "", line); split(line, rest, /[ \t]+/); uri = rest[1]; suite = rest[2]
                    n = split(opts, o, /[ \t]+/)
                    for (i = 1; i <= n; ++i) if (o[i] ~ /^signed-by=/) { key = o[i]; sub(/^signed-by=/, "", key) }
                } else { uri = $2; suite = $3 }
                if (suite == s) { print uri "\t" key; exit }
            }' "$f" | head -n 1 | grep . && return 0
    done
    return 1
}

export DEBIAN_FRONTEND=noninteractive
if [ ${#bpo_pkgs[@]} -gt 0 ] && ! has_suite "$codename-backports"; then
    src=$(debian_source "$codename" || true)
    if [ -z "$src" ]; then
        echo "install-deps: no apt source for $codename found: cannot add $codename-backports" >&2
        exit 1
    fi
    uri=${src%%$'\t'*}
    key=${src#*$'\t'}
    if [ -z "$key" ] && [ -r /usr/share/keyrings/debian-archive-keyring.gpg ]; then
        key=/usr/share/keyrings/debian-archive-keyring.gpg
    fi
    echo "install-deps: adding $codename-backports from $uri in $BACKPORTS_FILE" >&2
    {
        echo "# added by linear_rt's tools/install-deps.sh: Mesa $MESA_MIN (lavapipe with ray query)"
        echo "Types: deb"
        echo "URIs: $uri"
        echo "Suites: $codename-backports"
        echo "Components: main"
        if [ -n "$key" ]; then echo "Signed-By: $key"; fi
    } | run_root tee "$BACKPORTS_FILE" >/dev/null
fi
run_root apt-get -q update
if [ ${#bpo_pkgs[@]} -gt 0 ]; then
    run_root apt-get -q install -y --no-install-recommends -t "$codename-backports" "${bpo_pkgs[@]}"
fi
if [ ${#main_pkgs[@]} -gt 0 ]; then
    run_root apt-get -q install -y --no-install-recommends "${main_pkgs[@]}"
fi
# gcc-multilib just installed: only now can the kernel's 32-bit programs be tried
if wants test && [ "$(dpkg --print-architecture 2>/dev/null)" = amd64 ] && needs_qemu_i386; then
    echo "install-deps: this kernel cannot run 32-bit programs: installing qemu-user (qemu-i386 runs test-m32's)" >&2
    run_root apt-get -q install -y --no-install-recommends qemu-user
fi
