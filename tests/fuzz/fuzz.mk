# tests/fuzz/fuzz.mk - included by the Makefile (filled in by the fuzzing work)
