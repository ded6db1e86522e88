# Makefile of linear_rt (GNU make).
#   make demo    build build/demo (-O3) and run the headline workload
#   make test    every test; ends with one line "N passed, M failed"
#   make clean
CC ?= cc
CFLAGS ?= -O2 -g

STD      := -std=c99
WARN     := -Wall -Wextra -Wpedantic
LDLIBS   := -lpthread -lm
SAN      := -fsanitize=address,undefined -fno-sanitize-recover=all -O1 -g
STRICT   := -Wall -Wextra -Wpedantic -Werror
# the demo is always built with -O3 on top of CFLAGS; it prints these flags
DEMO_FLAGS = $(STD) $(WARN) $(CFLAGS) -O3

B := build
LIB := linear_rt.h
REF := tests/reference.h
SCENE := examples/scene.h

# what `make test` runs, one count each in its summary line
TESTS := test-reference test-core test-sanitize-reference test-sanitize-core test-header test-demo

.PHONY: all demo test deps clean $(TESTS) test-sanitize

all: $(B)/demo $(B)/test_reference $(B)/test_core

# Cheap: runs tools/install-deps.sh only when a tool is missing.
deps:
	@for t in $(firstword $(CC)) gcc g++; do \
	  command -v $$t >/dev/null 2>&1 || { echo "deps: $$t is missing"; tools/install-deps.sh; break; }; \
	done

$(B):
	@mkdir -p $(B)

# ---- demo ---------------------------------------------------------------------
$(B)/demo: examples/demo.c $(LIB) $(SCENE) $(REF) | deps $(B)
	$(CC) $(DEMO_FLAGS) -DDEMO_CFLAGS="\"$(DEMO_FLAGS)\"" examples/demo.c -o $@ $(LDLIBS)

demo: $(B)/demo
	$(B)/demo

# ---- tests --------------------------------------------------------------------
$(B)/test_reference: tests/test_reference.c $(REF) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

$(B)/test_core: tests/test_core.c $(LIB) $(REF) $(SCENE) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

$(B)/test_reference_san: tests/test_reference.c $(REF) | deps $(B)
	$(CC) $(STD) $(WARN) $(SAN) $< -o $@ $(LDLIBS)

$(B)/test_core_san: tests/test_core.c $(LIB) $(REF) $(SCENE) | deps $(B)
	$(CC) $(STD) $(WARN) $(SAN) $< -o $@ $(LDLIBS)

test-reference: $(B)/test_reference
	$(B)/test_reference

test-core: $(B)/test_core
	$(B)/test_core

test-sanitize-reference: $(B)/test_reference_san
	$(B)/test_reference_san

test-sanitize-core: $(B)/test_core_san
	$(B)/test_core_san

test-sanitize: test-sanitize-reference test-sanitize-core

# The header alone, as C99 and C++11, gcc and clang, warnings as errors; the
# STATIC and NO_SIMD variants with gcc; and the README's code sample.
test-header: | deps $(B)
	@printf '#define LINEAR_RT_IMPLEMENTATION\n#include "../linear_rt.h"\n' > $(B)/header_tu.c
	@awk '/^```c$$/ { f = 1; next } /^```$$/ { if (f) exit } f' README.md > $(B)/readme_sample.c
	@n=0; bad=0; \
	run() { echo "  $$*"; if "$$@"; then n=$$((n + 1)); else bad=$$((bad + 1)); fi; }; \
	run gcc $(STD) $(STRICT) -c $(B)/header_tu.c -o $(B)/header_gcc.o; \
	run g++ -x c++ -std=c++11 $(STRICT) -c $(B)/header_tu.c -o $(B)/header_gxx.o; \
	if command -v clang >/dev/null 2>&1; then \
	  run clang $(STD) $(STRICT) -c $(B)/header_tu.c -o $(B)/header_clang.o; \
	else echo "  note: clang is not installed: C99 clang check skipped"; fi; \
	if command -v clang++ >/dev/null 2>&1; then \
	  run clang++ -x c++ -std=c++11 $(STRICT) -c $(B)/header_tu.c -o $(B)/header_clangxx.o; \
	else echo "  note: clang++ is not installed: C++11 clang check skipped"; fi; \
	run gcc $(STD) $(STRICT) -DLINEAR_RT_STATIC -c $(B)/header_tu.c -o $(B)/header_static.o; \
	run gcc $(STD) $(STRICT) -DLINEAR_RT_NO_SIMD -c $(B)/header_tu.c -o $(B)/header_nosimd.o; \
	run gcc $(STD) $(STRICT) -I. $(B)/readme_sample.c -o $(B)/readme_sample -lm; \
	run $(B)/readme_sample; \
	run g++ -x c++ -std=c++11 $(STRICT) -I. -c $(B)/readme_sample.c -o $(B)/readme_sample_gxx.o; \
	echo "test-header: $$n passed, $$bad failed"; \
	[ $$bad -eq 0 ]

test-demo: $(B)/demo
	$(B)/demo --size 128
	@echo "test-demo: ok, every checked ray agrees with the reference"

# Every test, each run even when an earlier one failed; then one summary line.
test: deps
	@pass=0; fail=0; failed=; start=$$(date +%s); \
	for t in $(TESTS); do \
	  echo "== $$t"; \
	  if $(MAKE) --no-print-directory $$t; then pass=$$((pass + 1)); \
	  else fail=$$((fail + 1)); failed="$$failed $$t"; fi; \
	done; \
	echo "== done in $$(( $$(date +%s) - start )) s"; \
	if [ $$fail -ne 0 ]; then echo "failed:$$failed"; fi; \
	echo "$$pass passed, $$fail failed"; \
	[ $$fail -eq 0 ]

clean:
	rm -rf $(B)
