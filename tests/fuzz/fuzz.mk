# tests/fuzz/fuzz.mk - included by the Makefile: the libFuzzer harnesses.
#   make fuzz        each harness for FUZZ_SECONDS (default 60), one after the
#                    other, from the seed corpus; prints the executions reached
#   make test-fuzz   each for FUZZ_QUICK_SECONDS (3): they build, and the seeds
#                    (the inputs of the bugs found among them) still pass
# Needs clang with its libFuzzer runtime (Debian: clang, libclang-rt-14-dev);
# without it test-fuzz skips, and fails under CI=true.
# Working corpora, logs and failing inputs go to build/fuzz/; the seeds in
# tests/fuzz/corpus/ are only read (tests/fuzz/make_seeds.py writes them).
FUZZ_CC ?= clang
FUZZ_SECONDS ?= 60
FUZZ_QUICK_SECONDS ?= 3
FUZZ_FLAGS := $(STD) -Wall -Wextra -Wpedantic -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all
FB := $(B)/fuzz

# the harnesses this machine can build: the Vulkan one needs the Vulkan
# headers (no loader, no device), the files one stb_image (libstb-dev)
FUZZERS := fuzz_core
ifeq ($(HAVE_VULKAN),1)
FUZZERS += fuzz_vk_args
endif
ifneq ($(wildcard /usr/include/stb/stb_image.h),)
FUZZERS += fuzz_files
endif

# can FUZZ_CC link a libFuzzer program? (clang without libclang-rt-*-dev cannot)
FUZZ_PROBE = printf 'int LLVMFuzzerTestOneInput(const unsigned char *d, unsigned long n);\nint LLVMFuzzerTestOneInput(const unsigned char *d, unsigned long n) { (void)d; (void)n; return 0; }\n' \
	| $(FUZZ_CC) -fsanitize=fuzzer,address,undefined -x c - -o $(FB)/probe >/dev/null 2>&1

.PHONY: fuzz fuzz-build test-fuzz

$(FB):
	@mkdir -p $(FB)

$(FB)/fuzz_core: tests/fuzz/fuzz_core.c tests/fuzz/fuzz_common.h $(LIB) $(REF) | $(FB)
	$(FUZZ_CC) $(FUZZ_FLAGS) $< -o $@ $(LDLIBS)

$(FB)/fuzz_vk_args: tests/fuzz/fuzz_vk_args.c tests/fuzz/fuzz_common.h $(LIB) $(SPV_H) | $(FB)
	$(FUZZ_CC) $(FUZZ_FLAGS) $< -o $@ $(LDLIBS)

# stb_image is third-party: UBSan leaves it alone (ASan does not), see the list
$(FB)/fuzz_files: tests/fuzz/fuzz_files.c tests/fuzz/fuzz_common.h examples/depth_file.h tests/fuzz/ubsan-ignore.txt | $(FB)
	$(FUZZ_CC) $(FUZZ_FLAGS) -fsanitize-ignorelist=tests/fuzz/ubsan-ignore.txt $< -o $@ $(LDLIBS)

fuzz-build: $(addprefix $(FB)/,$(FUZZERS))

# the toolchain first: a clear message rather than a link error
fuzz: | $(FB)
	@$(FUZZ_PROBE) || { echo "fuzz: $(FUZZ_CC) cannot link -fsanitize=fuzzer: install clang and libclang-rt-14-dev"; exit 1; }
	@$(MAKE) --no-print-directory fuzz-build
	@sh tests/fuzz/run-fuzzers.sh $(FUZZ_SECONDS) $(FUZZERS)

test-fuzz: | $(FB)
	@if ! $(FUZZ_PROBE); then \
	  if [ "$$CI" = "true" ]; then echo "test-fuzz: FAIL: $(FUZZ_CC) cannot link -fsanitize=fuzzer (CI=true): install clang and libclang-rt-14-dev"; exit 1; fi; \
	  echo "test-fuzz: skipped: $(FUZZ_CC) cannot link -fsanitize=fuzzer (clang and libclang-rt-14-dev)"; exit 0; fi; \
	$(MAKE) --no-print-directory fuzz-build && \
	sh tests/fuzz/run-fuzzers.sh $(FUZZ_QUICK_SECONDS) --quick $(FUZZERS) && \
	echo "test-fuzz: ok, $(words $(FUZZERS)) harnesses ran $(FUZZ_QUICK_SECONDS) s each: $(FUZZERS)"

TESTS += test-fuzz
