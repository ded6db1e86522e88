# Makefile of linear_rt (GNU make).
#   make demo    install what the demo needs (tools/install-deps.sh demo), build
#                build/demo (-O3) and run it: the headline workload, pictures in out/
#   make test    install what the tests need (tools/install-deps.sh test), then
#                every test; ends with one line "N passed, M failed". A test
#                whose tool is missing fails (ALLOW_SKIP=1: it skips instead)
#   make bench   install gnuplot and Embree too, then the benchmark (bench/)
#   make bench-plain-vs-native  linear_rt's CPU rows, plain build / -march=native
#   make examples  build/minimal, ssr, ao, shadows, vulkan_inline, hlsl_inline, vulkan_trace
#   make spv     compile shaders/*.comp and regenerate shaders_spv.h (needs glslang)
#   make gpu-stats  the kernels' weight on AMD GPUs (RDNA3, RDNA2, GCN): Mesa's
#                RADV compiler on null hardware, tables in build/gpu-stats.md
#   make calibrate  the wave estimate against the H200's measured times
#   make clean
CC ?= cc
CFLAGS ?= -O2 -g

STD      := -std=c99
WARN     := -Wall -Wextra -Wpedantic
LDLIBS   := -lpthread -lm
SAN      := -fsanitize=address,undefined -fno-sanitize-recover=all -O1 -g
STRICT   := -Wall -Wextra -Wpedantic -Werror
# The SSE2 walk alone (no AVX2 pass): for the checks whose subject is not the
# walk's instruction set (limits, threads, the sanitized and threaded Vulkan
# tests), which then compile in a third of the time; test_core, test_paths,
# the sanitized core tests, the fuzzers and the examples build as users do.
ONE_WALK := -DLINEAR_RT_NO_RUNTIME_DISPATCH
# The demo and the benchmark build the library as engines do: -O3 for any
# x86-64, and linear_rt.h chooses its AVX2 walk at run time where the CPU has
# it. NATIVE=-march=native builds them for this CPU alone. Both print which
# walk ran.
NATIVE ?=
DEMO_FLAGS = $(STD) $(WARN) $(CFLAGS) -O3 $(NATIVE)

B := build
LIB := linear_rt.h
REF := tests/support/reference.h
SCENE := examples/scene.h
RAYS := tests/support/rays.h tests/support/check.h
SPV_H := shaders_spv.h
VK_UTIL := linear_rt_vk_util.h

# Vulkan: the headers decide whether the demo and tests get the Vulkan path.
# Nothing links against Vulkan: the loader is opened at run time (-ldl).
HAVE_VULKAN := $(shell printf '\043include <vulkan/vulkan.h>\n' | $(CC) -E -x c - >/dev/null 2>&1 && echo 1)
VK_FLAGS := -DLINEAR_RT_VULKAN
# tests and the demo prove it: no Vulkan prototypes, so no link-time Vulkan symbol
VK_PROGRAM_FLAGS := $(VK_FLAGS) -DVK_NO_PROTOTYPES
VK_LIBS := -ldl
ifeq ($(HAVE_VULKAN),1)
DEMO_VK := $(VK_PROGRAM_FLAGS)
DEMO_VK_DEPS := $(SPV_H) $(VK_UTIL)
DEMO_VK_LIBS := $(VK_LIBS)
endif

# SPIR-V: glslang and spirv-tools (Debian: glslang-tools, spirv-tools)
GLSLANG ?= glslangValidator
SPIRV_VAL ?= spirv-val
SPV_ENV := --target-env vulkan1.2
# HLSL through glslang's HLSL front end: SPIR-V 1.3, the newest for which it
# writes storage buffers (BufferBlock, dropped in 1.4)
HLSL_ENV := --target-env vulkan1.1
GLSLANG_HLSL = $(GLSLANG) -D -V $(HLSL_ENV) -e main -S comp
SPV_SOURCES := $(wildcard shaders/*.comp shaders/*.glsl) linear_rt.h # the kernels read its >>contract block
SPV_NAMES := refit_buffer refit_image trace_buffer trace_image

# what `make test` runs, one count each in its summary line
TESTS := test-programs-build test-walk-twins test-reference test-core test-misuse test-core-paths test-sanitize-reference test-sanitize-core test-header test-spv test-vulkan test-vulkan-hlsl test-vulkan-trace test-demo test-examples test-lift test-bench test-gpu-stats

# hardening (sanitizers with clang, valgrind, static checks, limits) and the
# fuzzers: their own makefiles, which add their tests to TESTS
include tests/hardening.mk
include tests/threads.mk
include tests/fuzz/fuzz.mk
include examples/vulkan_inline/vulkan_inline.mk

.PHONY: FORCE all demo examples pictures check test test-all test-programs deps clean spv spv-check bench bench-deps bench-publish bench-plain-vs-native gpu-stats calibrate $(TESTS) test-sanitize

all: $(B)/demo $(B)/test_reference $(B)/test_core

# Cheap: runs tools/install-deps.sh only when a tool is missing.
deps:
	@for t in $(firstword $(CC)) gcc g++; do \
	  command -v $$t >/dev/null 2>&1 || { echo "deps: $$t is missing"; tools/install-deps.sh; break; }; \
	done

$(B):
	@mkdir -p $(B)

# The optional parts this make found. The demo and the benchmark build them in
# or leave them out, so they are rebuilt when this line changes (a package
# installed since the last build).
CONFIG_LINE = vulkan=$(HAVE_VULKAN) embree=$(HAVE_EMBREE) glslang=$(HAVE_GLSLANG)
$(B)/config.stamp: FORCE | $(B)
	@echo '$(CONFIG_LINE)' | cmp -s - $@ || echo '$(CONFIG_LINE)' > $@
FORCE:

# ---- demo and examples ----------------------------------------------------------
# The examples' shared code, and what the demo adds: the classic march.
EXAMPLE_HDR := examples/example.h examples/depth_file.h examples/surface.h $(SCENE) $(LIB)
EXAMPLES := minimal ssr ao shadows

$(B)/demo: examples/demo.c examples/ssr.c examples/ao.c examples/shadows.c examples/march.h examples/trace_threads.h $(EXAMPLE_HDR) $(DEMO_VK_DEPS) $(B)/config.stamp | deps $(B)
	$(CC) $(DEMO_FLAGS) $(DEMO_VK) -DDEMO_CFLAGS="\"$(DEMO_FLAGS)\"" $< -o $@ $(LDLIBS) $(DEMO_VK_LIBS)

# install first, then a new make: HAVE_VULKAN and the like are read when make
# reads this file, so the build must come from a make started after the install
demo:
	@tools/install-deps.sh demo
	@$(MAKE) --no-print-directory $(B)/demo
	$(B)/demo

# each example is one file: make examples builds them all into build/
$(B)/minimal: examples/minimal.c $(LIB) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) -O3 $< -o $@ -lm

$(B)/ssr $(B)/ao $(B)/shadows: $(B)/%: examples/%.c $(EXAMPLE_HDR) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) -O3 $< -o $@ $(LDLIBS)

examples: $(addprefix $(B)/,$(EXAMPLES)) $(B)/vulkan_inline $(B)/hlsl_inline $(B)/vulkan_trace

# the README's pictures: the demo's, at 512x512
pictures: $(B)/demo $(B)/ssr
	$(B)/demo --size 512 --no-gpu --out examples/pictures
	$(B)/ssr --size 512 --out examples/pictures
	$(B)/ssr --size 512 --thickness 0.3 --out examples/pictures
	$(B)/ssr --size 512 --thickness 5% --out examples/pictures
	$(B)/ssr --size 512 --thickness back --out examples/pictures

# the examples as tests: their effects against the reference, their
# pictures, their answers to bad files (tests/test_examples.c)
$(B)/test_examples: tests/test_examples.c examples/ssr.c examples/ao.c examples/shadows.c $(EXAMPLE_HDR) $(REF) tests/support/check.h | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) -O2 $< -o $@ $(LDLIBS)

test-examples: $(B)/test_examples $(addprefix $(B)/,$(EXAMPLES))
	$(B)/test_examples

# THE LIFT of linear_rt.h on the embedded scene: rays leaving a surface along
# normals from depth, analytic and from an 8-bit G-buffer never hit their own
# texel and (almost) never a stair of their own surface; lifted rays reach
# the sky (tests/test_lift.c)
$(B)/test_lift: tests/test_lift.c $(EXAMPLE_HDR) tests/support/check.h | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) -O2 $< -o $@ $(LDLIBS)

test-lift: $(B)/test_lift
	$(B)/test_lift

# ---- tests --------------------------------------------------------------------
$(B)/test_reference: tests/test_reference.c $(REF) tests/support/check.h | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

$(B)/test_core: tests/test_core.c $(LIB) $(REF) $(SCENE) $(RAYS) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

$(B)/test_reference_san: tests/test_reference.c $(REF) tests/support/check.h | deps $(B)
	$(CC) $(STD) $(WARN) $(SAN) $< -o $@ $(LDLIBS)

$(B)/test_core_san: tests/test_core.c $(LIB) $(REF) $(SCENE) $(RAYS) | deps $(B)
	$(CC) $(STD) $(WARN) $(SAN) $< -o $@ $(LDLIBS)

$(B)/test_core_san_sse2: tests/test_core.c $(LIB) $(REF) $(SCENE) $(RAYS) | deps $(B)
	$(CC) $(STD) $(WARN) $(SAN) -DLINEAR_RT_NO_AVX $< -o $@ $(LDLIBS)

test-reference: $(B)/test_reference
	$(B)/test_reference

test-walk-twins:
	tests/walk_twins.sh

test-core: $(B)/test_core
	$(B)/test_core

# the mistakes a newcomer makes, plain and under ASan (reads past a struct
# or a map, and LeakSanitizer: a tree dropped by a second build)
$(B)/test_misuse: tests/test_misuse.c $(LIB) tests/support/check.h | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

$(B)/test_misuse_san: tests/test_misuse.c $(LIB) tests/support/check.h | deps $(B)
	$(CC) $(STD) $(WARN) $(SAN) $< -o $@ $(LDLIBS)

test-misuse: $(B)/test_misuse $(B)/test_misuse_san
	$(B)/test_misuse
	$(B)/test_misuse_san

# The same tests through the header's other traversal paths: scalar C
# (LINEAR_RT_NO_SIMD) and SSE2 alone (LINEAR_RT_NO_AVX). The default build
# above is plain x86-64: AVX2 chosen at run time where this CPU has it
# (test_core prints which walk ran). Every path must give the same answers.
$(B)/test_core_scalar: tests/test_core.c $(LIB) $(REF) $(SCENE) $(RAYS) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) -DLINEAR_RT_NO_SIMD $< -o $@ $(LDLIBS)

$(B)/test_core_sse2: tests/test_core.c $(LIB) $(REF) $(SCENE) $(RAYS) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) -DLINEAR_RT_NO_AVX $< -o $@ $(LDLIBS)

# and the paths against each other, bit for bit, in one program
$(B)/paths_scalar.o: tests/paths_tu.c tests/support/build_trace.h $(LIB) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) -DLINEAR_RT_NO_SIMD -DPATHS_FN=paths_trace_scalar -c $< -o $@

$(B)/paths_avx2.o: tests/paths_tu.c tests/support/build_trace.h $(LIB) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) -mavx2 -mfma -DPATHS_FN=paths_trace_avx2 -c $< -o $@

$(B)/paths_sse2.o: tests/paths_tu.c tests/support/build_trace.h $(LIB) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) -DLINEAR_RT_NO_AVX -DPATHS_FN=paths_trace_sse2 -c $< -o $@

# The builds an engine makes of the implementation, each a copy of it in
# tests/paths_tu.c held to this test's own -std=c99 copy bit for bit
# (tests/test_paths.c names them): GNU C modes (gcc fuses a * b + c wherever
# it may, -ffp-contract=fast), -ffast-math and -Ofast, -O0 to -O3, with and
# without -march=native, C and C++, gcc and clang. $(call paths_build,NAME,
# COMPILER AND FLAGS) adds one; test_paths.c's PATHS_BUILDS lists the same.
PATHS_OBJ := $(B)/paths_scalar.o $(B)/paths_sse2.o $(B)/paths_avx2.o
define paths_build
$(B)/paths_$(1).o: tests/paths_tu.c tests/support/build_trace.h $(LIB) | deps $(B)
	$(2) $(WARN) $(CFLAGS_PATHS) -DPATHS_FN=paths_trace_$(1) -c $$< -o $$@
PATHS_OBJ += $(B)/paths_$(1).o
endef
HAVE_CLANG := $(shell command -v clang >/dev/null 2>&1 && command -v clang++ >/dev/null 2>&1 && echo 1)
$(eval $(call paths_build,gnu99_contract,gcc -std=gnu99 -O2 -ffp-contract=fast))
$(eval $(call paths_build,gcc_gnu11_native,gcc -std=gnu11 -O2 -march=native))
$(eval $(call paths_build,gcc_fast_native,gcc -std=gnu11 -O3 -march=native -ffast-math))
$(eval $(call paths_build,gcc_ofast,gcc -std=gnu11 -Ofast))
$(eval $(call paths_build,gcc_o0,gcc -std=c99 -O0))
$(eval $(call paths_build,gcc_fast_nosimd,gcc -std=gnu11 -O2 -ffast-math -DLINEAR_RT_NO_SIMD))
$(eval $(call paths_build,gxx_fast_native,g++ -x c++ -std=gnu++14 -O3 -march=native -ffast-math))
$(eval $(call paths_build,gxx_o1,g++ -x c++ -std=c++11 -O1))
ifeq ($(HAVE_CLANG),1)
$(eval $(call paths_build,clang_fast,clang -std=gnu11 -O3 -ffast-math))
$(eval $(call paths_build,clang_ofast_native,clang -std=gnu11 -Ofast -march=native))
$(eval $(call paths_build,clang_o1_contract,clang -std=c99 -O1 -ffp-contract=fast))
$(eval $(call paths_build,clangxx_fast_native,clang++ -x c++ -std=c++17 -O2 -march=native -ffast-math))
endif
CFLAGS_PATHS := -g

$(B)/test_paths: tests/test_paths.c tests/support/build_trace.h bench/scenes.h $(PATHS_OBJ) $(LIB) $(REF) $(SCENE) $(RAYS) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) -DPATHS_HAVE_CLANG=$(if $(HAVE_CLANG),1,0) $< $(PATHS_OBJ) -o $@ $(LDLIBS)

test-core-paths: $(B)/test_core_scalar $(B)/test_core_sse2 $(B)/test_paths
	$(B)/test_paths
	$(B)/test_core_scalar
	$(B)/test_core_sse2

test-sanitize-reference: $(B)/test_reference_san
	$(B)/test_reference_san

test-sanitize-core: $(B)/test_core_san $(B)/test_core_san_sse2
	$(B)/test_core_san
	$(B)/test_core_san_sse2

test-sanitize: test-sanitize-reference test-sanitize-core

# The header alone, as C99 and C++11, gcc and clang, warnings as errors; the
# STATIC, NO_SIMD, NO_AVX, NO_RUNTIME_DISPATCH and AVX2 variants, the AVX2
# walk in a plain build, a renamed copy (LINEAR_RT_SELF); the README's code
# sample; the Vulkan build, and with it linear_rt_vk_util.h, the companion
# header (C99 and C++11, gcc and clang).
test-header: | deps $(B)
	@printf '#define LINEAR_RT_IMPLEMENTATION\n#include "../linear_rt.h"\n' > $(B)/header_tu.c
	@awk '/^```c$$/ { f = 1; next } /^```$$/ { if (f) exit } f' README.md > $(B)/readme_sample.c
	@awk 'NR > 60 { exit } /^-- 8< --$$/ { n++; next } n == 1' linear_rt.h > $(B)/header_sample.c
	@n=0; bad=0; \
	run() { echo "  $$*"; if "$$@"; then n=$$((n + 1)); else bad=$$((bad + 1)); fi; }; \
	j=$(B)/header_jobs; rm -rf $$j; mkdir -p $$j; k=0; q=; p=0; \
	job() { [ $$p -lt 2 ] || take; k=$$((k + 1)); p=$$((p + 1)); echo "  $$*" > $$j/$$k.cmd; \
	  "$$@" > $$j/$$k.out 2> $$j/$$k.err & q="$$q $$k:$$!"; }; \
	take() { set -- $$q; i=$${1%%:*}; pid=$${1#*:}; shift; q="$$*"; p=$$((p - 1)); \
	  if wait $$pid; then ok=1; else ok=0; fi; cat $$j/$$i.cmd $$j/$$i.out; cat $$j/$$i.err >&2; \
	  if [ $$ok = 1 ]; then n=$$((n + 1)); else bad=$$((bad + 1)); fi; }; \
	flush() { while [ $$p -gt 0 ]; do take; done; }; \
	job gcc $(STD) $(STRICT) -c $(B)/header_tu.c -o $(B)/header_gcc.o; \
	job g++ -x c++ -std=c++11 $(STRICT) -c $(B)/header_tu.c -o $(B)/header_gxx.o; \
	if command -v clang >/dev/null 2>&1; then \
	  job clang $(STD) $(STRICT) -c $(B)/header_tu.c -o $(B)/header_clang.o; \
	else echo "  note: clang is not installed: C99 clang check skipped"; fi; \
	if command -v clang++ >/dev/null 2>&1; then \
	  job clang++ -x c++ -std=c++11 $(STRICT) -c $(B)/header_tu.c -o $(B)/header_clangxx.o; \
	else echo "  note: clang++ is not installed: C++11 clang check skipped"; fi; \
	job gcc $(STD) $(STRICT) -DLINEAR_RT_STATIC -c $(B)/header_tu.c -o $(B)/header_static.o; \
	job gcc $(STD) $(STRICT) -DLINEAR_RT_NO_SIMD -c $(B)/header_tu.c -o $(B)/header_nosimd.o; \
	job gcc $(STD) $(STRICT) -mavx2 -c $(B)/header_tu.c -o $(B)/header_avx2.o; \
	job g++ -x c++ -std=c++11 $(STRICT) -mavx2 -c $(B)/header_tu.c -o $(B)/header_avx2_gxx.o; \
	if command -v clang >/dev/null 2>&1; then \
	  job clang $(STD) $(STRICT) -mavx2 -c $(B)/header_tu.c -o $(B)/header_avx2_clang.o; fi; \
	job gcc $(STD) $(STRICT) -mavx2 -mfma -c $(B)/header_tu.c -o $(B)/header_avx2fma.o; \
	job gcc $(STD) $(STRICT) -DLINEAR_RT_NO_AVX -c $(B)/header_tu.c -o $(B)/header_noavx.o; \
	job gcc $(STD) $(STRICT) -DLINEAR_RT_NO_RUNTIME_DISPATCH -c $(B)/header_tu.c -o $(B)/header_nodispatch.o; \
	job gcc $(STD) $(STRICT) -O2 -c $(B)/header_tu.c -o $(B)/header_gcc_o2.o; \
	if command -v clang >/dev/null 2>&1; then \
	  job clang $(STD) $(STRICT) -O2 -c $(B)/header_tu.c -o $(B)/header_clang_o2.o; fi; \
	flush; for o in gcc clang; do [ -f $(B)/header_$$o.o ] || continue; \
	  if nm $(B)/header_$$o.o | grep -q 'lrt__trace_walk_avx2'; then echo "  $$o: a plain build has the AVX2 walk (run-time choice)"; n=$$((n + 1)); \
	  else echo "  FAIL: $$o: a plain build has no AVX2 walk"; bad=$$((bad + 1)); fi; \
	  calls=$$(objdump -d --no-show-raw-insn $(B)/header_$${o}_o2.o | \
	    awk '/^[0-9a-f]+ <.*>:$$/ { fn = $$2 } /\tcall/ && fn ~ /_avx2/ && fn !~ /setup_rare_avx2/ && $$NF ~ /^<lrt__/ && $$NF !~ /_avx2[.>+]/ && $$NF != "<lrt__check_back>" { print "    " fn " calls " $$NF }' | sort -u); \
	  if [ -z "$$calls" ]; then echo "  $$o -O2: the AVX2 walk calls no helper compiled for plain x86-64 (an out-of-line one halved a 3x2 map's speed)"; n=$$((n + 1)); \
	  else echo "  FAIL: $$o -O2: the AVX2 walk calls helpers compiled for plain x86-64 (make them LRT__FORCE_INLINE):"; echo "$$calls"; bad=$$((bad + 1)); fi; done; \
	mkdir -p $(B)/renamed && cp linear_rt.h $(B)/renamed/lrt_copy.h && \
	printf '#define LINEAR_RT_SELF "lrt_copy.h"\n#define LINEAR_RT_IMPLEMENTATION\n#include "renamed/lrt_copy.h"\n' > $(B)/header_renamed_tu.c; \
	job gcc $(STD) $(STRICT) -c $(B)/header_renamed_tu.c -o $(B)/header_renamed.o; \
	job gcc $(STD) $(STRICT) -I. $(B)/readme_sample.c -o $(B)/readme_sample -lm; \
	job gcc $(STD) $(STRICT) -I. $(B)/header_sample.c -o $(B)/header_sample -lm; \
	flush; run $(B)/readme_sample; \
	if [ $$(awk 'NR <= 60 && /^-- 8< --$$/' linear_rt.h | wc -l) = 2 ]; then echo "  the header's example lies within its first 60 lines"; n=$$((n + 1)); \
	else echo "  FAIL: the header's example is not within its first 60 lines"; bad=$$((bad + 1)); fi; \
	run $(B)/header_sample; \
	job g++ -x c++ -std=c++11 $(STRICT) -I. -c $(B)/readme_sample.c -o $(B)/readme_sample_gxx.o; \
	job g++ -x c++ -std=c++11 $(STRICT) -I. -c $(B)/header_sample.c -o $(B)/header_sample_gxx.o; \
	flush; if gcc $(STD) -E $(B)/header_tu.c | grep -q 'vulkan'; then echo "  FAIL: the CPU-only build includes Vulkan headers"; bad=$$((bad + 1)); \
	else echo "  the CPU-only build includes no Vulkan header"; n=$$((n + 1)); fi; \
	if [ "$(HAVE_VULKAN)" = 1 ]; then \
	  printf '#define LINEAR_RT_IMPLEMENTATION\n#include "../linear_rt.h"\n' > $(B)/header_vk_tu.c; \
	  printf '#define LINEAR_RT_IMPLEMENTATION\n#include "../linear_rt.h"\n#include "../$(VK_UTIL)"\n' > $(B)/header_vku_tu.c; \
	  for tu in vk vku; do \
	    job gcc $(STD) $(STRICT) $(VK_FLAGS) -c $(B)/header_$${tu}_tu.c -o $(B)/header_$${tu}_gcc.o; \
	    job g++ -x c++ -std=c++11 $(STRICT) $(VK_FLAGS) -c $(B)/header_$${tu}_tu.c -o $(B)/header_$${tu}_gxx.o; \
	    if command -v clang >/dev/null 2>&1; then \
	      job clang $(STD) $(STRICT) $(VK_FLAGS) -c $(B)/header_$${tu}_tu.c -o $(B)/header_$${tu}_clang.o; fi; \
	    if command -v clang++ >/dev/null 2>&1; then \
	      job clang++ -x c++ -std=c++11 $(STRICT) $(VK_FLAGS) -c $(B)/header_$${tu}_tu.c -o $(B)/header_$${tu}_clangxx.o; fi; \
	  done; \
	  job gcc $(STD) $(STRICT) $(VK_FLAGS) -DVK_NO_PROTOTYPES -DLINEAR_RT_STATIC -c $(B)/header_vk_tu.c -o $(B)/header_vk_static.o; \
	  printf '#include "../linear_rt.h"\n#define LINEAR_RT_VULKAN\n#include "../linear_rt.h"\nint f(void);\nint f(void) { return (int)sizeof(lrt_vk_depth); }\n' > $(B)/header_vk_twice.c; \
	  job gcc $(STD) $(STRICT) -c $(B)/header_vk_twice.c -o $(B)/header_vk_twice.o; \
	  flush; if nm $(B)/header_vk_gcc.o $(B)/header_vku_gcc.o | grep -q ' U vk'; then echo "  FAIL: a link-time Vulkan symbol:"; \
	    nm $(B)/header_vk_gcc.o $(B)/header_vku_gcc.o | grep ' U vk'; bad=$$((bad + 1)); \
	  else echo "  no link-time Vulkan symbol in the Vulkan build and its companion header"; n=$$((n + 1)); fi; \
	else echo "  note: <vulkan/vulkan.h> not found: Vulkan variants skipped"; fi; \
	echo "test-header: $$n passed, $$bad failed"; \
	[ $$bad -eq 0 ]

# ---- SPIR-V --------------------------------------------------------------------
$(B)/spv2h: tools/spv2h.c | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) $< -o $@

# $(call spv_compile,FOLDER,HEADER): both kernels in both depth variants into
# FOLDER/lrt_<kernel>_<variant>.spv, each validated, then embedded in HEADER
define spv_compile
	@mkdir -p $(1)
	@set -e; for name in $(SPV_NAMES); do \
	  kernel=$${name%_*}; variant=$${name#*_}; image=0; [ $$variant = image ] && image=1; \
	  echo "  $(GLSLANG) -V $(SPV_ENV) -DLRT_DEPTH_IMAGE=$$image -o $(1)/lrt_$$name.spv shaders/lrt_$$kernel.comp"; \
	  $(GLSLANG) -V $(SPV_ENV) -DLRT_DEPTH_IMAGE=$$image -o $(1)/lrt_$$name.spv shaders/lrt_$$kernel.comp \
	    > $(1)/lrt_$$name.log 2>&1 || { cat $(1)/lrt_$$name.log; exit 1; }; \
	  echo "  $(SPIRV_VAL) $(SPV_ENV) $(1)/lrt_$$name.spv"; \
	  $(SPIRV_VAL) $(SPV_ENV) $(1)/lrt_$$name.spv; \
	done
	$(B)/spv2h $(2) $(foreach n,$(SPV_NAMES),lrt_spv_$(n)=$(1)/lrt_$(n).spv)
endef

# Regenerates the committed shaders_spv.h from shaders/ (glslang 12 of
# Debian 12: another glslang version writes other bytes, which test-spv sees).
spv: $(B)/spv2h $(SPV_SOURCES)
	@command -v $(GLSLANG) >/dev/null 2>&1 && command -v $(SPIRV_VAL) >/dev/null 2>&1 || \
	  { echo "spv: $(GLSLANG) and $(SPIRV_VAL) are needed: tools/install-deps.sh installs them"; exit 1; }
	$(call spv_compile,$(B)/spv,$(SPV_H))

# shaders_spv.h must be what make spv makes of shaders/ now.
test-spv: $(B)/spv2h
	@if ! command -v $(GLSLANG) >/dev/null 2>&1 || ! command -v $(SPIRV_VAL) >/dev/null 2>&1; then \
	  echo "test-spv: skipped: $(GLSLANG) or $(SPIRV_VAL) is not installed"; exit 0; fi; \
	$(MAKE) --no-print-directory spv-check && \
	if cmp -s $(B)/spv-check/$(SPV_H) $(SPV_H); then echo "test-spv: ok, $(SPV_H) is up to date"; \
	else echo "test-spv: FAIL: $(SPV_H) differs from what shaders/ compile to: run make spv"; exit 1; fi

spv-check: $(B)/spv2h
	$(call spv_compile,$(B)/spv-check,$(B)/spv-check/$(SPV_H))

# ---- Vulkan ------------------------------------------------------------------
# Skips (exit 0) where there is no Vulkan header, loader or device, except
# under CI=true, where that is a failure.
$(B)/test_vulkan: tests/test_vulkan.c $(LIB) $(SPV_H) $(REF) $(SCENE) $(RAYS) $(VK_UTIL) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) $(VK_PROGRAM_FLAGS) $< -o $@ $(LDLIBS) $(VK_LIBS)

# test_vulkan again with the trace kernels compiled from HLSL
# (tests/hlsl/lrt_trace.hlsl over shaders/linear_rt.hlsl, glslang's HLSL
# front end, buffer and image depth; HLSL_ENV). linear_rt adds float controls (RoundingModeRTE,
# ...) to its kernels, core in SPIR-V 1.4: before that a module names their
# extension, which the rule adds after the last OpCapability.
HLSL_TRACE = $(GLSLANG_HLSL) $(3) -DLRT_HLSL_DEPTH_IMAGE=$(2) \
	  -o $(B)/hlsl/$(1).spv tests/hlsl/lrt_trace.hlsl > $(B)/hlsl/$(1).log 2>&1 || { cat $(B)/hlsl/$(1).log; exit 1; }; \
	spirv-dis --raw-id $(B)/hlsl/$(1).spv > $(B)/hlsl/$(1).spvasm && \
	awk -v n=$$(grep -n OpCapability $(B)/hlsl/$(1).spvasm | tail -1 | cut -d: -f1) \
	  '{ print } NR == n { print "OpExtension \"SPV_KHR_float_controls\"" }' $(B)/hlsl/$(1).spvasm > $(B)/hlsl/$(1)_fc.spvasm && \
	spirv-as $(HLSL_ENV) --preserve-numeric-ids $(B)/hlsl/$(1)_fc.spvasm -o $(B)/hlsl/$(1)_fc.spv && \
	$(SPIRV_VAL) $(HLSL_ENV) $(B)/hlsl/$(1)_fc.spv
$(B)/test_vulkan_hlsl_spv.h: tests/hlsl/lrt_trace.hlsl shaders/linear_rt.hlsl shaders/linear_rt.glsl linear_rt.h \
  $(B)/spv2h | $(B)
	@mkdir -p $(B)/hlsl
	$(call HLSL_TRACE,lrt_trace_buffer,0)
	$(call HLSL_TRACE,lrt_trace_image,1,--auto-sampled-textures)
	$(B)/spv2h $@ lrt_hlsl_trace_buffer=$(B)/hlsl/lrt_trace_buffer_fc.spv lrt_hlsl_trace_image=$(B)/hlsl/lrt_trace_image_fc.spv

$(B)/test_vulkan_hlsl: tests/test_vulkan.c $(B)/test_vulkan_hlsl_spv.h $(LIB) $(SPV_H) $(REF) $(SCENE) $(RAYS) \
  $(VK_UTIL) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) $(VK_PROGRAM_FLAGS) -DTEST_HLSL -I$(B) $< -o $@ $(LDLIBS) $(VK_LIBS)

ifeq ($(HAVE_VULKAN),1)
ifeq ($(VI_HAVE_GLSLANG),1)
test-vulkan-hlsl: $(B)/test_vulkan_hlsl
	$(B)/test_vulkan_hlsl
	$(B)/test_vulkan_hlsl --flushing-device
	$(B)/test_vulkan_hlsl --compacted
else
test-vulkan-hlsl:
	@echo "$@: skipped: $(GLSLANG) is not installed (Debian: glslang-tools)"; [ "$$CI" != "true" ]
endif

test-vulkan: $(B)/test_vulkan
	$(B)/test_vulkan
	$(B)/test_vulkan --flushing-device
	$(B)/test_vulkan --compacted
else
test-vulkan test-vulkan-hlsl:
	@echo "$@: skipped: <vulkan/vulkan.h> not found (tools/install-deps.sh installs libvulkan-dev)"; \
	[ "$$CI" != "true" ]
endif

# examples/vulkan_trace.c: the plain GPU trace as a user writes it (the
# header's API only), held to lrt_trace bit for bit with the validation
# layer on. Its exit 77 is "no Vulkan loader or device" (1 under CI=true).
ifeq ($(HAVE_VULKAN),1)
$(B)/vulkan_trace: examples/vulkan_trace.c $(VK_UTIL) $(LIB) $(SPV_H) | deps $(B)
	$(CC) $(STD) $(STRICT) $(CFLAGS) $(VK_PROGRAM_FLAGS) $< -o $@ -lm $(VK_LIBS)

test-vulkan-trace: $(B)/vulkan_trace
	@$(B)/vulkan_trace; rc=$$?; \
	if [ $$rc -eq 77 ]; then echo "test-vulkan-trace: skipped: no Vulkan device"; exit 0; fi; \
	if [ $$rc -eq 0 ]; then echo "test-vulkan-trace: ok"; fi; exit $$rc
else
.PHONY: $(B)/vulkan_trace
$(B)/vulkan_trace:
	@echo "vulkan_trace: not built: <vulkan/vulkan.h> not found (tools/install-deps.sh installs libvulkan-dev)"
test-vulkan-trace:
	@echo "test-vulkan-trace: skipped: <vulkan/vulkan.h> not found (tools/install-deps.sh installs libvulkan-dev)"; \
	[ "$$CI" != "true" ]
endif

# make check: the quick loop while working, well under a minute on a 2-core
# machine: the reference's and the core CPU tests, the traversal paths bit
# for bit, the walks' C and GLSL twins (tests/walk_twins.sh: every pair of
# linear_rt.h's TWINS table defined on both sides), (where there is a
# Vulkan device) one Vulkan smoke test with validation on, and the shaders'
# one source for GLSL and HLSL. Any test program runs one test by name, e.g.
# build/test_core test_update.
CHECK_VK := $(if $(filter 1,$(HAVE_VULKAN)),$(B)/test_vulkan)
check: | deps $(B)
	@$(MAKE) --no-print-directory -j2 $(B)/test_reference $(B)/test_core $(B)/test_paths $(CHECK_VK)
	$(B)/test_reference
	$(B)/test_core
	$(B)/test_paths
	tests/walk_twins.sh
	$(if $(CHECK_VK),$(B)/test_vulkan test_smoke,@echo "check: no Vulkan headers here: the Vulkan smoke test is skipped")
	@# one source for GLSL and HLSL: linear_rt.hlsl defines no function but the
	@# built-in HLSL lacks, and linear_rt.glsl's body compiles as HLSL
	@fns=$$(grep -cE '^[a-zA-Z_][a-zA-Z0-9_ ]* [a-zA-Z_][a-zA-Z0-9_]*\(.*\)$$' shaders/linear_rt.hlsl); \
	  [ "$$fns" = 1 ] || { echo "check: shaders/linear_rt.hlsl defines $$fns functions: the tracer lives in linear_rt.glsl"; exit 1; }
	$(if $(and $(CHECK_VK),$(VI_HAVE_GLSLANG)),@$(MAKE) --no-print-directory $(B)/test_vulkan_hlsl_spv.h && \
	  echo "check: linear_rt.glsl compiles as HLSL",@echo "check: no glslang here: the HLSL compile is skipped")

# The demo at 128x128 (its own checks: 2 threads == 1, GPU == CPU bit for
# bit), then its CPU answers (--dump) judged by the exact reference:
# tests/test_demo.c, every primary ray and every segment at this size.
$(B)/test_demo: tests/test_demo.c $(LIB) $(REF) $(SCENE) tests/support/check.h | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

test-demo: $(B)/demo $(B)/test_demo
	$(B)/demo --size 128 --out $(B)/demo_out --dump $(B)/demo_answers.bin
	$(B)/test_demo $(B)/demo_answers.bin
	@echo "test-demo: ok, the demo's checks pass and every checked ray agrees with the reference"

# ---- benchmark ------------------------------------------------------------------
# make bench: every method on the same rays (bench/main.c), results in
# build/bench-results/; make bench-publish copies them over the committed
# run in bench/ (the README's table and chart), on purpose only.
# Optional parts are built when their package is there (tools/install-deps.sh
# --bench installs them): Embree 3, and for the Vulkan
# peers glslang (their kernels are compiled here into build/, never committed).
HAVE_EMBREE := $(shell test -f /usr/include/embree3/rtcore.h && echo 1)
HAVE_GLSLANG := $(shell command -v $(GLSLANG) >/dev/null 2>&1 && echo 1)
BENCH_SRC := bench/main.c bench/clock.c bench/m_linear_rt.c bench/visits.c bench/wave.c bench/m_embree.c bench/march_cpu.c bench/m_vk_peers.c
BENCH_HDR := bench/bench.h bench/scenes.h bench/march_common.h examples/march.h examples/depth_file.h examples/surface.h examples/trace_threads.h $(LIB) $(REF) $(SCENE)
BENCH_FLAGS := $(STD) $(WARN) $(CFLAGS) -O3 $(NATIVE)
BENCH_LIBS := $(LDLIBS)
BENCH_DEPS :=
ifeq ($(HAVE_EMBREE),1)
BENCH_FLAGS += -DBENCH_HAVE_EMBREE
BENCH_LIBS += -lembree3
endif
ifeq ($(HAVE_VULKAN),1)
BENCH_FLAGS += -DBENCH_HAVE_VULKAN -DVK_NO_PROTOTYPES
BENCH_LIBS += $(VK_LIBS)
BENCH_DEPS += $(SPV_H) $(VK_UTIL)
ifeq ($(HAVE_GLSLANG),1)
BENCH_FLAGS += -DBENCH_HAVE_VK_PEERS_SPV -I$(B)
BENCH_DEPS += $(B)/bench_vk_spv.h
endif
endif
VKP_KERNELS := rq_aabb rq_tri aabb_gen march64 dda hiz hiz_mip

$(B)/bench_vk_spv.h: $(wildcard bench/shaders/*.comp bench/shaders/*.glsl) $(B)/spv2h | $(B)
	@mkdir -p $(B)/bench_spv
	@set -e; for k in $(VKP_KERNELS); do \
	  $(GLSLANG) -V $(SPV_ENV) -o $(B)/bench_spv/vkp_$$k.spv bench/shaders/vkp_$$k.comp >$(B)/bench_spv/vkp_$$k.log 2>&1 || { cat $(B)/bench_spv/vkp_$$k.log; exit 1; }; \
	  if command -v $(SPIRV_VAL) >/dev/null 2>&1; then $(SPIRV_VAL) $(SPV_ENV) $(B)/bench_spv/vkp_$$k.spv; fi; \
	done
	$(B)/spv2h $@ $(foreach k,$(VKP_KERNELS),vkp_spv_$(k)=$(B)/bench_spv/vkp_$(k).spv)

$(B)/bench: $(BENCH_SRC) $(BENCH_HDR) $(BENCH_DEPS) $(B)/config.stamp | deps $(B)
	$(CC) $(BENCH_FLAGS) $(BENCH_SRC) -o $@ $(BENCH_LIBS)

bench-deps:
	@tools/install-deps.sh bench

# BENCH_ARGS: options of build/bench (build/bench --help), e.g. --quick
bench: bench-deps
	@$(MAKE) --no-print-directory $(B)/bench
	@mkdir -p $(B)/bench-results
	@$(MAKE) --no-print-directory gpu-stats GPU_STATS_OUT=$(B)/bench-results/gpu-stats.md GPU_WEIGHTS=$(B)/bench-results/gpu-weights.tsv
	w=$(B)/bench-results/gpu-weights.tsv; $(B)/bench $$([ -s $$w ] && echo --weights $$w) $(BENCH_ARGS)
	@if [ -f $(B)/bench-results/gpu-stats.md ] && [ -f $(B)/bench-results/results.md ]; then \
	  { echo; cat $(B)/bench-results/gpu-stats.md; } >> $(B)/bench-results/results.md; \
	  echo "bench: the kernels' weight on AMD GPUs appended to $(B)/bench-results/results.md"; fi

# make calibrate: is the benchmark's wave estimate a model of GPU time? The
# H200's measured peers (bench/h200.tsv) against the estimate of the same sets,
# and linear_rt's kernel as the H200 ran it (bench/h200_kernel.sh weighs that
# commit's SPIR-V): bench/calibrate.py's tables in build/h200/calibration.md
# (about 3 min; needs RADV and the git history)
calibrate: $(B)/gpu_stats $(B)/bench
	bench/h200_kernel.sh a46c342 $(B)/h200
	$(B)/bench --only-counts --size 1024 --weights $(B)/h200/gpu-weights.tsv --out $(B)/h200
	python3 bench/calibrate.py $(B)/h200/waves.tsv $(B)/h200/gpu-weights.tsv bench/h200.tsv | tee $(B)/h200/calibration.md

# The plain build's run-time walk against a -march=native build of the
# library, in one run: build/bench-twin holds both (bench/m_linear_rt.c a
# second time, with -march=native), bench/plain_vs_native.sh compares them.
# make bench-plain-vs-native [RUNS=N] (N runs, each row's best; default 1)
# TWIN_CFLAGS (default -march=native) and PLAIN_CFLAGS build the two copies
# otherwise, for any A/B of the CPU walk in one run: e.g. TWIN_CFLAGS=
# -DLINEAR_RT_NO_AVX (the SSE2 walk against the AVX2 one), or PLAIN_CFLAGS=
# -DLINEAR_RT_NO_AVX TWIN_CFLAGS=-DLINEAR_RT_NO_SIMD (plain C against SSE2);
# the twin's rows keep the name " native".
RUNS ?= 1
TWIN_CFLAGS ?= -march=native
PLAIN_CFLAGS ?=
$(B)/twin-flags.stamp: FORCE | $(B)
	@echo '$(PLAIN_CFLAGS) / $(TWIN_CFLAGS)' | cmp -s - $@ || echo '$(PLAIN_CFLAGS) / $(TWIN_CFLAGS)' > $@
$(B)/bench-twin: $(BENCH_SRC) $(BENCH_HDR) $(BENCH_DEPS) $(B)/config.stamp $(B)/twin-flags.stamp | deps $(B)
	$(CC) $(BENCH_FLAGS) $(TWIN_CFLAGS) -DBENCH_NATIVE_TWIN -c bench/m_linear_rt.c -o $(B)/m_linear_rt_native.o
	$(CC) $(BENCH_FLAGS) $(PLAIN_CFLAGS) -DBENCH_WITH_NATIVE_TWIN $(BENCH_SRC) $(B)/m_linear_rt_native.o -o $@ $(BENCH_LIBS)

bench-plain-vs-native: bench-deps
	@$(MAKE) --no-print-directory $(B)/bench-twin
	bench/plain_vs_native.sh $(RUNS)

BENCH_PUBLISHED := results.csv results.md speed_vs_accuracy.png
bench-publish:
	@for f in $(BENCH_PUBLISHED); do test -f $(B)/bench-results/$$f || { echo "bench-publish: no $(B)/bench-results/$$f: run make bench first"; exit 1; }; done
	cp $(addprefix $(B)/bench-results/,$(BENCH_PUBLISHED)) bench/
	@echo "bench-publish: bench/ now holds this run; say which commit it measured where you cite it"

# the benchmark at a small size, so that it keeps building and its exact
# methods keep agreeing with the reference (it exits non-zero otherwise)
test-bench: $(B)/bench
	$(B)/bench --quick --out $(B)
	python3 bench/compaction.py --self-test

# bench/walk_rays.c, the workload of bench/walk_ab.sh (which builds its own
# copies against two headers): built here so that it keeps compiling
$(B)/walk_rays: bench/walk_rays.c examples/trace_threads.h $(LIB) $(SCENE) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) -O3 $< -o $@ $(LDLIBS)

# ---- the kernels' weight on AMD GPUs ------------------------------------------
# bench/gpu_stats.c: every pipeline of lrt_vk_context_create, and the
# benchmark's Vulkan peers (their kernels as make bench compiles them), built
# by Mesa's RADV on null hardware for RDNA3, RDNA2 and GCN (RADV_FORCE_FAMILY:
# no AMD GPU needed, nothing dispatched); instructions, registers, spills,
# branches and waves per SIMD from VK_KHR_pipeline_executable_properties,
# and from each pipeline's disassembly its loops: the instructions and loads
# of a step (GPU_WEIGHTS, the benchmark's estimate reads them; no weight is
# typed anywhere). Every pipeline made must compile, or the run fails.
# RADV is Debian's mesa-vulkan-drivers, which make demo and make test install.
# Its exit 77 is "no RADV here" (1 under CI=true).
GPU_STATS_OUT ?= $(B)/gpu-stats.md
GPU_WEIGHTS ?= $(B)/gpu-weights.tsv
ifeq ($(HAVE_VULKAN),1)
GPU_STATS_FLAGS := -DLINEAR_RT_VULKAN -DVK_NO_PROTOTYPES $(ONE_WALK)
GPU_STATS_DEPS := $(LIB) $(SPV_H) $(VK_UTIL)
ifeq ($(HAVE_GLSLANG),1)
GPU_STATS_FLAGS += -DGPU_STATS_HAVE_PEERS -I$(B)
GPU_STATS_DEPS += $(B)/bench_vk_spv.h
endif
$(B)/gpu_stats: bench/gpu_stats.c $(GPU_STATS_DEPS) $(B)/config.stamp | deps $(B)
	$(CC) $(STD) $(STRICT) $(CFLAGS) $(GPU_STATS_FLAGS) $< -o $@ -lm $(VK_LIBS)

gpu-stats: $(B)/gpu_stats
	@$(B)/gpu_stats --out $(GPU_STATS_OUT) --weights $(GPU_WEIGHTS); rc=$$?; [ $$rc -eq 77 ] && exit 0; exit $$rc

# the library's trace pipeline alone compiled (--quick: all 32 are still
# made and identified), on each of the three GPUs; then the table of each
# must have its figures. Then every pipeline, the library's 32 and the
# benchmark's 7 peers, on RDNA3: each must compile and the walks' loops be
# found (a peer dropped or a loop lost fails here)
GPU_PIPELINES := 39
test-gpu-stats: $(B)/gpu_stats
	@$(B)/gpu_stats --quick --out $(B)/gpu-stats-quick.md; rc=$$?; \
	if [ $$rc -eq 77 ]; then echo "test-gpu-stats: skipped: no RADV"; exit 0; fi; [ $$rc -eq 0 ] || exit $$rc; \
	tables=$$(grep -c '^### ' $(B)/gpu-stats-quick.md); \
	good=$$(awk -F'|' '$$2 == " linear_rt trace buffer " && $$3 + 0 > 0 && $$4 + 0 > 0 && $$5 + 0 > 0 && $$9 + 0 > 0' $(B)/gpu-stats-quick.md | wc -l); \
	if [ "$$tables" = 3 ] && [ "$$good" = 3 ]; then echo "test-gpu-stats: ok, 3 GPUs, the trace pipeline's figures on each"; \
	else echo "test-gpu-stats: FAIL: $$tables tables, $$good with the trace pipeline's figures (of 3)"; exit 1; fi; \
	$(B)/gpu_stats --gpu navi31 --out $(B)/gpu-stats-all.md --weights $(B)/gpu-weights-test.tsv > /dev/null || exit 1; \
	rows=$$(grep -vc '^#' $(B)/gpu-weights-test.tsv); \
	loops=$$(awk -F'\t' '($$2 == "linear_rt trace buffer" || $$2 == "bench march64" || $$2 == "bench dda" || $$2 == "bench hiz64") && $$6 > 0' $(B)/gpu-weights-test.tsv | wc -l); \
	if [ "$(HAVE_GLSLANG)" != 1 ]; then echo "test-gpu-stats: FAIL: no glslang: the peers cannot be compiled"; exit 1; fi; \
	if [ "$$rows" = $(GPU_PIPELINES) ] && [ "$$loops" = 4 ]; then echo "test-gpu-stats: ok, RDNA3: all $$rows pipelines compiled, the walks' loops read"; \
	else echo "test-gpu-stats: FAIL: RDNA3: $$rows of $(GPU_PIPELINES) pipelines compiled, $$loops of 4 walks' loops read"; exit 1; fi
else
.PHONY: $(B)/gpu_stats
$(B)/gpu_stats:
	@echo "gpu_stats: not built: <vulkan/vulkan.h> not found (tools/install-deps.sh installs libvulkan-dev)"
gpu-stats test-gpu-stats:
	@echo "$@: skipped: <vulkan/vulkan.h> not found (tools/install-deps.sh installs libvulkan-dev)"; \
	[ "$$CI" != "true" ]
endif

# Every test, each run even when an earlier one failed; then one summary line.
# As for the demo: install, then a new make. CI=true turns every "skipped:
# TOOL is missing" of the tests into a failure; ALLOW_SKIP=1 keeps skips.
test:
	@tools/install-deps.sh test
	@$(if $(ALLOW_SKIP),,CI=true) $(MAKE) --no-print-directory test-all

# The programs the tests build, built first and two at a time (most are one
# translation unit of linear_rt.h and its AVX2 walk: 2 to 70 s of one core
# each), the slowest first; then each test finds its programs built. A build
# that fails here is tried again by its test, which fails (or skips) under
# its own name. A program missing from this list is only built later, by its
# test, one at a time.
TEST_PROGRAMS = $(addprefix $(FB)/,$(FUZZERS)) \
  $(if $(filter 1,$(HAVE_VULKAN)),$(B)/test_vulkan_csan) \
  $(addprefix $(B)/,test_core_csan test_core_san test_core_m32 test_limits_isan32 test_core_isan \
    test_limits_csan test_limits_m32 test_limits test_limits_isan test_core_san_sse2 test_core \
    test_core_scalar test_core_sse2 test_paths test_examples test_lift $(EXAMPLES) demo test_demo bench \
    test_threads test_threads_tsan test_reference test_reference_san test_reference_csan spv2h static_tu.c \
    test_misuse test_misuse_san soak soak_tsan bench-twin walk_rays) \
  $(if $(filter 1,$(HAVE_VULKAN)),$(addprefix $(B)/,$(VULKAN_PROGRAMS))) \
  $(if $(filter 11,$(HAVE_VULKAN)$(VI_HAVE_GLSLANG)),$(B)/vulkan_inline $(B)/hlsl_inline $(B)/test_vulkan_hlsl)
VULKAN_PROGRAMS := test_vulkan test_vulkan_threads test_vulkan_threads_tsan vulkan_trace gpu_stats

test-programs: $(TEST_PROGRAMS)

# Every program that a make target builds (the soaks, the benchmark and its
# twin, the tools, every example), also those no test runs: each is in
# TEST_PROGRAMS, so the build above compiles it, and here all of them must be
# built, so that a program that stops compiling fails make test. The list is
# read off the makefiles' rules (tests/programs.awk): a new program's rule
# that is missing from TEST_PROGRAMS fails here too. Without Vulkan headers
# (ALLOW_SKIP) the Vulkan programs are not asked for.
PROGRAM_MAKEFILES := Makefile tests/hardening.mk tests/threads.mk tests/fuzz/fuzz.mk examples/vulkan_inline/vulkan_inline.mk
PROGRAMS_NOT_HERE := $(if $(filter 1,$(HAVE_VULKAN)),,$(VULKAN_PROGRAMS) fuzz_vk_args vulkan_inline hlsl_inline) \
  $(if $(filter 11,$(HAVE_VULKAN)$(VI_HAVE_GLSLANG)),,vulkan_inline hlsl_inline test_vulkan_hlsl)
test-programs-build:
	@missing=; for p in $$(awk -f tests/programs.awk $(PROGRAM_MAKEFILES) | sort -u); do \
	  case " $(notdir $(TEST_PROGRAMS)) $(PROGRAMS_NOT_HERE) " in *" $$p "*) ;; *) missing="$$missing $$p";; esac; \
	done; \
	if [ -n "$$missing" ]; then echo "test-programs-build: FAIL: built by a make rule but not in TEST_PROGRAMS:$$missing"; exit 1; fi
	@$(MAKE) --no-print-directory -k test-programs && \
	echo "test-programs-build: ok, $(words $(TEST_PROGRAMS)) programs, every one a make target builds, compile"

# Then the tests, two at a time (tools/run_tests.sh: each one's output whole
# when it ends), the longest first so that both queues end together: in a
# fresh-clone run, one at a time, valgrind of test_core took 132 s, the
# Vulkan test under ASan 118 s and test-vulkan 92 s of 635 s of tests; the
# 32-bit tests take 70-90 s where they run under qemu-i386 (a kernel that
# cannot run 32-bit programs, tests/hardening.mk). Where the build failed,
# one at a time: two tests must not build one program.
TESTS_FIRST := test-valgrind-core test-sanitize-clang-vulkan test-vulkan test-m32 test-sanitize-integer
TEST_SLOTS ?= 2
test-all: | $(B)
	@start=$$(date +%s); slots=$(TEST_SLOTS); \
	echo "== build: the tests' programs, two at a time"; \
	$(MAKE) --no-print-directory -j2 -k -Otarget test-programs || \
	  { slots=1; echo "== build: not all of them built (above): each test builds its own again, and fails or skips there"; }; \
	echo "== the tests, $$slots at a time, each one's output when it ends"; \
	MAKE="$(MAKE)" TESTS_START=$$start tools/run_tests.sh $$slots $(B)/test_logs \
	  $(filter $(TESTS_FIRST),$(TESTS)) $(filter-out $(TESTS_FIRST),$(TESTS))

clean:
	rm -rf $(B)
