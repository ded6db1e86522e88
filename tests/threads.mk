# tests/threads.mk - included by the Makefile after tests/hardening.mk: the
# concurrency claims of linear_rt.h (threads trace disjoint slices of a batch
# at once; several threads record with one lrt_vk_context at once), each a
# target of its own in `make test`'s list:
#   test-threads                tests/test_threads.c as built by CC: 4 threads
#                               on slices of one batch, the tree updated
#                               between frames, two trees and both flags at once
#   test-threads-tsan           the same under ThreadSanitizer (clang): any
#                               report fails; then its --break-rule self-check
#                               (an update during a trace) must be reported
#   test-vulkan-threads         tests/test_vulkan_threads.c: 4 threads record
#                               build, update and trace with one context into
#                               their own command buffers, validation on
#   test-vulkan-threads-tsan    the same under ThreadSanitizer, first without
#                               the validation layer (its mutexes would order
#                               the threads and hide a race from TSan), then
#                               with it; the loader and lavapipe run
#                               uninstrumented in the process (no report of
#                               theirs with Mesa 25: no suppression file)
#   make test-threads-all       all of them
# and, not in `make test`:
#   make soak                   tests/soak.c (-O2) for SOAK_SECONDS (default 60):
#                               a frame loop of random maps, dirty rects, refits
#                               and threaded traces; SOAK_SEED=n replays a run
#   make soak-tsan              the same under ThreadSanitizer
# of which `make test` runs a short one (test-soak: TEST_SOAK_SECONDS of each).
# The TSan targets skip (exit 0, with a line that says what is missing) where
# clang's TSan runtime is not installed, and fail there under CI=true; the
# Vulkan ones skip without Vulkan, as test-vulkan does.

CLANG ?= clang
SOAK_SECONDS ?= 60
TEST_SOAK_SECONDS ?= 10

TSAN := -fsanitize=thread -fno-omit-frame-pointer -O1 -g
# halt_on_error: the first report ends the run with exit code 66, so any
# report fails its target; suppressions only where the file exists
TSAN_SUPP := tools/tsan.supp
TSAN_ENV = TSAN_OPTIONS=halt_on_error=1:exitcode=66:second_deadlock_stack=1$(if $(wildcard $(TSAN_SUPP)),:suppressions=$(CURDIR)/$(TSAN_SUPP))
THREADS_DEPS := tests/test_threads.c examples/trace_threads.h $(LIB) $(REF) $(SCENE) $(RAYS)
VK_THREADS_DEPS := tests/test_vulkan_threads.c $(LIB) $(SPV_H) $(REF) $(SCENE) $(RAYS) $(VK_UTIL)

THREADS_TESTS := test-threads test-threads-tsan test-vulkan-threads test-vulkan-threads-tsan test-soak
TESTS += $(THREADS_TESTS)

.PHONY: test-threads-all soak soak-tsan
test-threads-all: $(THREADS_TESTS)

# the probe runs the program too: a TSan runtime that cannot map its shadow
# memory on this kernel fails here, not in the test
HAVE_TSAN = $(call need,$@,printf 'int main(void) { return 0; }\n' | $(CLANG) -x c $(TSAN) - -o $(B)/probe_tsan_$@ && $(B)/probe_tsan_$@,clang with its ThreadSanitizer runtime (libclang-rt-14-dev) is not installed or cannot run here: tools/install-deps.sh installs it)
NEED_VULKAN = if [ "$(HAVE_VULKAN)" != 1 ]; then \
  if [ "$$CI" = "true" ]; then echo "$@: FAIL under CI=true: <vulkan/vulkan.h> not found"; exit 1; fi; \
  echo "$@: skipped: <vulkan/vulkan.h> not found (tools/install-deps.sh installs libvulkan-dev)"; exit 0; fi

# ---- CPU: threads tracing slices of a batch ------------------------------------------
$(B)/test_threads: $(THREADS_DEPS) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) $(ONE_WALK) $< -o $@ $(LDLIBS)

$(B)/test_threads_tsan: $(THREADS_DEPS) | deps $(B)
	$(CLANG) $(STD) $(WARN) $(TSAN) $(ONE_WALK) $< -o $@ $(LDLIBS)

test-threads: $(B)/test_threads
	$(B)/test_threads

# The self-check breaks the documented rule on purpose (a refit while two
# threads trace the tree): TSan must report it, or the run above proves
# nothing. Its report goes to a log, not to the screen.
test-threads-tsan: | $(B)
	@$(HAVE_TSAN); \
	$(MAKE) --no-print-directory $(B)/test_threads_tsan && \
	echo "$(TSAN_ENV) $(B)/test_threads_tsan" && $(TSAN_ENV) $(B)/test_threads_tsan && \
	log=$(B)/test_threads_tsan_break_rule.log; \
	$(TSAN_ENV) $(B)/test_threads_tsan --break-rule > $$log 2>&1; rc=$$?; \
	if [ $$rc -eq 66 ] && grep -q 'ThreadSanitizer: data race' $$log; then \
	  echo "$@: ok, and the self-check's update during a trace was reported ($$log)"; \
	else cat $$log; echo "$@: FAIL: the self-check's race went unreported (exit $$rc)"; exit 1; fi

# ---- Vulkan: threads recording with one context --------------------------------------
$(B)/test_vulkan_threads: $(VK_THREADS_DEPS) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) $(ONE_WALK) $(VK_PROGRAM_FLAGS) $< -o $@ $(LDLIBS) $(VK_LIBS)

$(B)/test_vulkan_threads_tsan: $(VK_THREADS_DEPS) | deps $(B)
	$(CLANG) $(STD) $(WARN) $(TSAN) $(ONE_WALK) $(VK_PROGRAM_FLAGS) $< -o $@ $(LDLIBS) $(VK_LIBS)

test-vulkan-threads: | $(B)
	@$(NEED_VULKAN); \
	$(MAKE) --no-print-directory $(B)/test_vulkan_threads && $(B)/test_vulkan_threads

test-vulkan-threads-tsan: | $(B)
	@$(NEED_VULKAN); \
	$(HAVE_TSAN); \
	$(MAKE) --no-print-directory $(B)/test_vulkan_threads_tsan && \
	echo "$(TSAN_ENV) $(B)/test_vulkan_threads_tsan --no-validation" && \
	$(TSAN_ENV) $(B)/test_vulkan_threads_tsan --no-validation && \
	echo "$(TSAN_ENV) $(B)/test_vulkan_threads_tsan" && $(TSAN_ENV) $(B)/test_vulkan_threads_tsan

# ---- the soak ----------------------------------------------------------------------------
$(B)/soak: tests/soak.c $(LIB) $(REF) $(SCENE) $(RAYS) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) -O2 $< -o $@ $(LDLIBS)

$(B)/soak_tsan: tests/soak.c $(LIB) $(REF) $(SCENE) $(RAYS) | deps $(B)
	$(CLANG) $(STD) $(WARN) $(TSAN) $< -o $@ $(LDLIBS)

soak: $(B)/soak
	$(B)/soak $(SOAK_SECONDS)

soak-tsan: | $(B)
	@$(HAVE_TSAN); \
	$(MAKE) --no-print-directory $(B)/soak_tsan && \
	echo "$(TSAN_ENV) $(B)/soak_tsan $(SOAK_SECONDS)" && $(TSAN_ENV) $(B)/soak_tsan $(SOAK_SECONDS)

# make test's short soak: both builds, TEST_SOAK_SECONDS each (a new seed each
# run: the seed is printed, SOAK_SEED=n replays it)
test-soak: $(B)/soak
	$(B)/soak $(TEST_SOAK_SECONDS)
	@$(MAKE) --no-print-directory soak-tsan SOAK_SECONDS=$(TEST_SOAK_SECONDS)
