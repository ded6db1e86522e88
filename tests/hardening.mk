# tests/hardening.mk - included by the Makefile (filled in by the hardening work)
