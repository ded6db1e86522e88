# tests/hardening.mk - included by the Makefile right after its TESTS list:
# sanitizers with clang, valgrind memcheck, the size limits (64- and 32-bit)
# and the static checks, each a target of its own in `make test`'s list:
#   test-sanitize-clang-reference, -core, -limits   clang ASan + UBSan
#   test-sanitize-clang-vulkan    the same, the Vulkan test on lavapipe with the
#                                 validation layer (tools/lsan.supp: its leaks)
#   test-sanitize-integer         clang -fsanitize=integer,implicit-conversion
#                                 on linear_rt.h (test_core, test_limits; -m32 too)
#   test-valgrind-reference, -core, -limits   memcheck: no error, nothing
#                                 "definitely lost"
#   test-limits, test-m32         tests/test_limits.c; test_limits and test_core
#                                 as 32-bit programs (gcc -m32: gcc-multilib;
#                                 under qemu-i386 where the kernel cannot run them)
#   test-cppcheck, test-clang-tidy  linear_rt.h's implementation, C99 and C++11,
#                                 with and without Vulkan (tools/cppcheck.supp,
#                                 .clang-tidy: what is off, and why)
#   make test-hardening           all of them
# Each skips (exit 0, with a line that says what is missing) where its tool
# is not installed, and fails there under CI=true; tools/install-deps.sh
# installs every tool.

CLANG ?= clang
GCC ?= gcc
VALGRIND ?= valgrind
CPPCHECK ?= cppcheck
CLANG_TIDY ?= clang-tidy

CLANG_SAN := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer -O1 -g
# unsigned wrap-around and lossy implicit conversions are not undefined, but
# in size arithmetic they are the bugs of the issue: linear_rt.h has none
INT_SAN := -fsanitize=integer,implicit-conversion -fno-sanitize-recover=all \
           -fsanitize-ignorelist=tools/ubsan-integer.ignore -O1 -g
# 32-bit x86 with SSE2 arithmetic (tests/support/reference.h refuses x87's excess precision)
M32 := -m32 -msse2 -mfpmath=sse
VALGRIND_FLAGS := -q --error-exitcode=1 --leak-check=full --show-leak-kinds=definite --errors-for-leak-kinds=definite
LSAN_ENV := LSAN_OPTIONS=suppressions=$(CURDIR)/tools/lsan.supp:print_suppressions=0
CPPCHECK_FLAGS := --enable=warning,style,performance,portability --inline-suppr --error-exitcode=1 --quiet \
                  --suppressions-list=tools/cppcheck.supp -I. -DLINEAR_RT_IMPLEMENTATION
LIMITS_DEPS := tests/test_limits.c $(LIB) $(REF) $(SCENE) $(RAYS)

HARDENING_TESTS := test-sanitize-clang-reference test-sanitize-clang-core test-sanitize-clang-limits \
                   test-sanitize-clang-vulkan test-sanitize-integer test-valgrind-reference test-valgrind-core \
                   test-valgrind-limits test-limits test-m32 test-cppcheck test-clang-tidy
TESTS += $(HARDENING_TESTS)

.PHONY: test-hardening
test-hardening: $(HARDENING_TESTS)

# $(call need,TARGET,COMMAND,WHAT): in a recipe; when COMMAND fails, TARGET
# is skipped (exit 0) with the line "TARGET: skipped: WHAT", or fails under CI=true
need = if ! ( $(2) ) >/dev/null 2>&1; then \
  if [ "$$CI" = "true" ]; then echo "$(1): FAIL under CI=true: $(3)"; exit 1; fi; \
  echo "$(1): skipped: $(3)"; exit 0; fi
HAVE_CLANG_SAN = $(call need,$@,printf 'int main(void) { return 0; }\n' | $(CLANG) -x c $(CLANG_SAN) - -o $(B)/probe_clang_san_$@,clang with its sanitizer runtime (libclang-rt-14-dev) is not installed: tools/install-deps.sh installs it)
HAVE_INT_SAN = $(call need,$@,printf 'int main(void) { return 0; }\n' | $(CLANG) -x c $(INT_SAN) - -o $(B)/probe_int_san_$@,clang with its sanitizer runtime (libclang-rt-14-dev) is not installed: tools/install-deps.sh installs it)
HAVE_M32 = $(call need,$@,printf '\043include <stdio.h>\nint main(void) { return 0; }\n' | $(GCC) -x c $(M32) - -o $(B)/probe_m32_$@,gcc cannot build 32-bit programs (gcc-multilib): tools/install-deps.sh installs it)
HAVE_TOOL = $(call need,$@,command -v $(1),$(1) is not installed: tools/install-deps.sh installs it)
# $(call run32,PROBE): in a recipe, after PROBE (a 32-bit program) was built;
# sets the shell variable run32 to what runs a 32-bit program here: nothing
# (the kernel runs it), or qemu-i386 (qemu-user) where the kernel cannot
# (some VMs: "Exec format error"); neither: skipped, or failed under CI=true
run32 = run32=; if ! $(1) >/dev/null 2>&1; then \
  if command -v qemu-i386 >/dev/null 2>&1 && qemu-i386 $(1) >/dev/null 2>&1; then run32=qemu-i386; \
    echo "$@: this kernel cannot run 32-bit programs: they run under qemu-i386"; \
  elif [ "$$CI" = "true" ]; then echo "$@: FAIL under CI=true: this kernel cannot run 32-bit programs, nor qemu-i386 (qemu-user)"; exit 1; \
  else echo "$@: skipped: this kernel cannot run 32-bit programs, nor qemu-i386 (qemu-user: tools/install-deps.sh installs it)"; exit 0; fi; fi

# ---- clang ASan + UBSan ----------------------------------------------------------
$(B)/test_reference_csan: tests/test_reference.c $(REF) tests/support/check.h | deps $(B)
	$(CLANG) $(STD) $(WARN) $(CLANG_SAN) $< -o $@ $(LDLIBS)

$(B)/test_core_csan: tests/test_core.c $(LIB) $(REF) $(SCENE) $(RAYS) | deps $(B)
	$(CLANG) $(STD) $(WARN) $(CLANG_SAN) $< -o $@ $(LDLIBS)

$(B)/test_limits_csan: $(LIMITS_DEPS) | deps $(B)
	$(CLANG) $(STD) $(WARN) $(CLANG_SAN) $(ONE_WALK) $< -o $@ $(LDLIBS)

$(B)/test_vulkan_csan: tests/test_vulkan.c $(LIB) $(SPV_H) $(REF) $(SCENE) $(RAYS) $(VK_UTIL) | deps $(B)
	$(CLANG) $(STD) $(WARN) $(CLANG_SAN) $(ONE_WALK) $(VK_PROGRAM_FLAGS) $< -o $@ $(LDLIBS) $(VK_LIBS)

test-sanitize-clang-reference test-sanitize-clang-core test-sanitize-clang-limits: test-sanitize-clang-%: | $(B)
	@$(HAVE_CLANG_SAN); \
	$(MAKE) --no-print-directory $(B)/test_$*_csan && $(B)/test_$*_csan

# lavapipe and the validation layer run uninstrumented inside the ASan
# process; the layer's own leaks are suppressed (tools/lsan.supp says why)
test-sanitize-clang-vulkan: | $(B)
	@if [ "$(HAVE_VULKAN)" != 1 ]; then \
	  if [ "$$CI" = "true" ]; then echo "$@: FAIL under CI=true: <vulkan/vulkan.h> not found"; exit 1; fi; \
	  echo "$@: skipped: <vulkan/vulkan.h> not found (tools/install-deps.sh installs libvulkan-dev)"; exit 0; fi; \
	$(HAVE_CLANG_SAN); \
	$(MAKE) --no-print-directory $(B)/test_vulkan_csan && $(LSAN_ENV) $(B)/test_vulkan_csan

# ---- clang integer checks (linear_rt.h only), 64- and 32-bit -----------------------
$(B)/test_core_isan: tests/test_core.c $(LIB) $(REF) $(SCENE) $(RAYS) tools/ubsan-integer.ignore | deps $(B)
	$(CLANG) $(STD) $(WARN) $(INT_SAN) $< -o $@ $(LDLIBS)

$(B)/test_limits_isan: $(LIMITS_DEPS) tools/ubsan-integer.ignore | deps $(B)
	$(CLANG) $(STD) $(WARN) $(INT_SAN) $(ONE_WALK) $< -o $@ $(LDLIBS)

$(B)/test_limits_isan32: $(LIMITS_DEPS) tools/ubsan-integer.ignore | deps $(B)
	$(CLANG) $(STD) $(WARN) $(M32) $(INT_SAN) $< -o $@ $(LDLIBS)

test-sanitize-integer: | $(B)
	@$(HAVE_INT_SAN); \
	$(MAKE) --no-print-directory $(B)/test_core_isan $(B)/test_limits_isan && \
	$(B)/test_core_isan && $(B)/test_limits_isan && \
	if printf 'int main(void) { return 0; }\n' | $(CLANG) -x c $(M32) $(INT_SAN) - -o $(B)/probe_int_san32 >/dev/null 2>&1; then \
	  $(call run32,$(B)/probe_int_san32); \
	  $(MAKE) --no-print-directory $(B)/test_limits_isan32 && $$run32 $(B)/test_limits_isan32; \
	elif [ "$$CI" = "true" ]; then echo "$@: FAIL under CI=true: no 32-bit clang build (gcc-multilib)"; exit 1; \
	else echo "$@: note: no 32-bit clang build here (gcc-multilib): the -m32 run is skipped"; fi

# ---- valgrind memcheck of the CPU tests ---------------------------------------------
# test_limits in its quick mode: the real 8192^2 and 16384^2 maps would add a
# minute under valgrind for the same code paths (ASan runs them)
$(B)/test_limits: $(LIMITS_DEPS) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) $(ONE_WALK) $< -o $@ $(LDLIBS)

test-valgrind-reference test-valgrind-core test-valgrind-limits: test-valgrind-%: | $(B)
	@$(call HAVE_TOOL,$(VALGRIND)); \
	$(MAKE) --no-print-directory $(B)/test_$* && LRT_TEST_LIMITS=quick $(VALGRIND) $(VALGRIND_FLAGS) $(B)/test_$*

# ---- the limits, 64- and 32-bit ------------------------------------------------------
test-limits: $(B)/test_limits
	$(B)/test_limits

$(B)/test_limits_m32: $(LIMITS_DEPS) | deps $(B)
	$(GCC) $(STD) $(WARN) $(CFLAGS) $(M32) $< -o $@ $(LDLIBS)

$(B)/test_core_m32: tests/test_core.c $(LIB) $(REF) $(SCENE) $(RAYS) | deps $(B)
	$(GCC) $(STD) $(WARN) $(CFLAGS) $(M32) $< -o $@ $(LDLIBS)

# 32-bit size_t: test_limits and test_core run; the Vulkan implementation
# and linear_rt_vk_util.h compile warning-free (no 32-bit Vulkan driver to run them on)
test-m32: | $(B)
	@$(HAVE_M32); \
	$(call run32,$(B)/probe_m32_$@); \
	$(MAKE) --no-print-directory $(B)/test_limits_m32 $(B)/test_core_m32 && \
	$$run32 $(B)/test_limits_m32 && $$run32 $(B)/test_core_m32 && \
	if [ "$(HAVE_VULKAN)" = 1 ]; then \
	  printf '#define LINEAR_RT_IMPLEMENTATION\n#include "../linear_rt.h"\n#include "../$(VK_UTIL)"\n' > $(B)/m32_vk_tu.c; \
	  echo "  $(GCC) $(M32) $(STD) $(STRICT) $(VK_FLAGS) -c $(B)/m32_vk_tu.c"; \
	  $(GCC) $(M32) $(STD) $(STRICT) $(VK_FLAGS) -c $(B)/m32_vk_tu.c -o $(B)/m32_vk_tu.o; \
	fi

# ---- static checks of linear_rt.h's implementation ------------------------------------
# with Vulkan, linear_rt_vk_util.h too (the device and the rest tools use)
$(B)/static_tu.c: tests/hardening.mk | $(B)
	@printf '#define LINEAR_RT_IMPLEMENTATION\n#include "../linear_rt.h"\n#ifdef LINEAR_RT_VULKAN\n#include "../$(VK_UTIL)"\n#endif\n' > $@

# C99 with SSE2, without SIMD, with AVX2, with Vulkan and linear_rt_vk_util.h; C++11.
# cppcheck is given no system include path: it checks the header's own code.
# The Vulkan run skips shaders_spv.h (its guard defined): cppcheck 2.10's
# value flow spent 86 of this test's 90 s on its 1.3 MB of generated words,
# which spirv-val checks (test-spv); the code that uses them is still read.
test-cppcheck: $(B)/static_tu.c
	@$(call HAVE_TOOL,$(CPPCHECK)); \
	n=0; bad=0; \
	run() { echo "  $(CPPCHECK) $$*"; if $(CPPCHECK) $(CPPCHECK_FLAGS) "$$@" $(B)/static_tu.c; then n=$$((n + 1)); else bad=$$((bad + 1)); fi; }; \
	run --language=c --std=c99 -D__SSE2__; \
	run --language=c --std=c99 -DLINEAR_RT_NO_SIMD; \
	run --language=c --std=c99 -D__SSE2__ -D__AVX2__ -D__FMA__; \
	run --language=c --std=c99 -D__SSE2__ $(VK_FLAGS) -DSHADERS_SPV_H; \
	run --language=c++ --std=c++11 -D__cplusplus -D__SSE2__; \
	echo "test-cppcheck: $$n passed, $$bad failed"; \
	[ $$bad -eq 0 ]

# .clang-tidy at the root: the checks, warnings as errors, the header only
test-clang-tidy: $(B)/static_tu.c
	@$(call HAVE_TOOL,$(CLANG_TIDY)); \
	n=0; bad=0; \
	run() { echo "  $(CLANG_TIDY) $(B)/static_tu.c -- $$*"; \
	  if $(CLANG_TIDY) --quiet $(B)/static_tu.c -- "$$@" 2>/dev/null; then n=$$((n + 1)); else bad=$$((bad + 1)); fi; }; \
	run -x c $(STD); \
	run -x c $(STD) -mavx2 -mfma; \
	run -x c++ -std=c++11; \
	if [ "$(HAVE_VULKAN)" = 1 ]; then \
	  run -x c $(STD) $(VK_FLAGS); \
	  run -x c++ -std=c++11 $(VK_FLAGS); \
	else echo "  note: <vulkan/vulkan.h> not found: the Vulkan variants are skipped"; fi; \
	echo "test-clang-tidy: $$n passed, $$bad failed"; \
	[ $$bad -eq 0 ]
