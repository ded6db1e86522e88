#!/usr/bin/env bash
# tools/install-deps.sh - make sure the tools that `make test` uses are here:
# make, gcc, g++, clang (and the C library headers). Does nothing, and needs
# no network, when they all are; otherwise installs the missing ones with
# apt-get (Debian/Ubuntu), as root or through sudo.
set -euo pipefail

missing=()
for tool in make gcc g++ clang; do
    command -v "$tool" >/dev/null 2>&1 || missing+=("$tool")
done
# libc6-dev: a compiler without the C library headers cannot build anything
if command -v gcc >/dev/null 2>&1 &&
    ! printf '#include <stdio.h>\n#include <math.h>\n#include <pthread.h>\nint main(void){return 0;}\n' |
        gcc -x c - -o /dev/null -lm -lpthread >/dev/null 2>&1; then
    missing+=("libc6-dev")
fi

if [ ${#missing[@]} -eq 0 ]; then
    exit 0
fi

echo "install-deps: missing: ${missing[*]}; installing with apt-get" >&2
if ! command -v apt-get >/dev/null 2>&1; then
    echo "install-deps: no apt-get here; install make, gcc, g++ and clang by hand" >&2
    exit 1
fi
if [ "$(id -u)" -eq 0 ]; then
    as_root=()
elif command -v sudo >/dev/null 2>&1; then
    as_root=(sudo)
else
    echo "install-deps: not root and no sudo; install make, gcc, g++ and clang by hand" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
${as_root[@]+"${as_root[@]}"} apt-get update
${as_root[@]+"${as_root[@]}"} apt-get install -y --no-install-recommends make gcc g++ clang libc6-dev
