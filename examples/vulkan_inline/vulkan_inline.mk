# examples/vulkan_inline/vulkan_inline.mk - the vulkan_inline example: a
# compute shader of the user's own (contact_shadows.comp) that includes
# shaders/linear_rt.glsl, and its host code (main.c, and
# linear_rt_vk_util.h, which the demo shares).
# Included by the Makefile, which defines B, LIB, SCENE, STD, WARN, CFLAGS,
# HAVE_VULKAN, VK_PROGRAM_FLAGS, VK_LIBS, GLSLANG, GLSLANG_HLSL, SPIRV_VAL, SPV_ENV, HLSL_ENV, TESTS
# and the rules for $(B), deps and $(B)/spv2h. It leaves the default goal alone.
#   make build/vulkan_inline      the example (needs <vulkan/vulkan.h> and glslang)
#   make test-vulkan-inline       runs it with validation at 64x64; skips (exit 0)
#                                 without Vulkan headers, glslang or a device,
#                                 unless CI=true

VI_DEFAULT_GOAL := $(.DEFAULT_GOAL)
VI_DIR := examples/vulkan_inline
VI_SPV_H := $(B)/vulkan_inline_spv.h
VI_HAVE_GLSLANG := $(shell command -v $(GLSLANG) >/dev/null 2>&1 && echo 1)
# the library, the examples' scene and our Vulkan helper are included by main.c
VI_DEPS := $(VI_DIR)/main.c $(LIB) shaders_spv.h $(SCENE) linear_rt_vk_util.h $(VI_SPV_H)

TESTS += test-vulkan-inline test-hlsl-inline
.PHONY: test-vulkan-inline test-hlsl-inline

# examples/hlsl_inline: the same host (main.c with HLSL_INLINE), the shader in
# HLSL over shaders/linear_rt.hlsl, compiled by glslang's HLSL front end
# (GLSLANG_HLSL, the Makefile's)
HI_SPV_H := $(B)/hlsl_inline_spv.h
$(HI_SPV_H): examples/hlsl_inline/contact_shadows.hlsl shaders/linear_rt.hlsl shaders/linear_rt.glsl linear_rt.h \
  $(B)/spv2h | $(B)
	@mkdir -p $(B)/hlsl_inline_spv
	$(GLSLANG_HLSL) -I. -Ishaders -o $(B)/hlsl_inline_spv/contact_shadows.spv \
	  examples/hlsl_inline/contact_shadows.hlsl > $(B)/hlsl_inline_spv/contact_shadows.log 2>&1 || \
	  { cat $(B)/hlsl_inline_spv/contact_shadows.log; exit 1; }
	@if command -v $(SPIRV_VAL) >/dev/null 2>&1; then $(SPIRV_VAL) $(HLSL_ENV) $(B)/hlsl_inline_spv/contact_shadows.spv; fi
	$(B)/spv2h $@ contact_shadows_spv=$(B)/hlsl_inline_spv/contact_shadows.spv

# The SPIR-V is compiled here, never committed: glslang finds linear_rt.h
# (its contract block) through -I. and linear_rt.glsl through -Ishaders, and
# spv2h embeds it as contact_shadows_spv[].
$(VI_SPV_H): $(VI_DIR)/contact_shadows.comp shaders/linear_rt.glsl linear_rt.h $(B)/spv2h | $(B)
	@mkdir -p $(B)/vulkan_inline_spv
	$(GLSLANG) -V $(SPV_ENV) -I. -Ishaders -o $(B)/vulkan_inline_spv/contact_shadows.spv $(VI_DIR)/contact_shadows.comp \
	  > $(B)/vulkan_inline_spv/contact_shadows.log 2>&1 || { cat $(B)/vulkan_inline_spv/contact_shadows.log; exit 1; }
	@if command -v $(SPIRV_VAL) >/dev/null 2>&1; then $(SPIRV_VAL) $(SPV_ENV) $(B)/vulkan_inline_spv/contact_shadows.spv; fi
	$(B)/spv2h $@ contact_shadows_spv=$(B)/vulkan_inline_spv/contact_shadows.spv

ifeq ($(HAVE_VULKAN)$(VI_HAVE_GLSLANG),11)
$(B)/vulkan_inline: $(VI_DEPS) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) -O3 $(VK_PROGRAM_FLAGS) -I$(B) $< -o $@ -lm $(VK_LIBS)

$(B)/hlsl_inline: $(filter-out $(VI_SPV_H),$(VI_DEPS)) $(HI_SPV_H) | deps $(B)
	$(CC) $(STD) $(WARN) $(CFLAGS) -O3 $(VK_PROGRAM_FLAGS) -DHLSL_INLINE -I$(B) $< -o $@ -lm $(VK_LIBS)

test-hlsl-inline: $(B)/hlsl_inline
	@$(B)/hlsl_inline --validation --size 64 --out $(B)/hlsl_inline_out; rc=$$?; \
	if [ $$rc -eq 77 ]; then echo "test-hlsl-inline: skipped: no Vulkan device"; exit 0; fi; \
	if [ $$rc -eq 0 ]; then echo "test-hlsl-inline: ok"; fi; exit $$rc

# exit 77 is the program's "no Vulkan loader or device" (1 under CI=true)
test-vulkan-inline: $(B)/vulkan_inline
	@$(B)/vulkan_inline --validation --size 64 --out $(B)/vulkan_inline_out; rc=$$?; \
	if [ $$rc -eq 77 ]; then echo "test-vulkan-inline: skipped: no Vulkan device"; exit 0; fi; \
	if [ $$rc -eq 0 ]; then echo "test-vulkan-inline: ok"; fi; exit $$rc
else
VI_MISSING := $(if $(filter 1,$(HAVE_VULKAN)),$(GLSLANG) is not installed (Debian: glslang-tools),<vulkan/vulkan.h> not found (tools/install-deps.sh installs libvulkan-dev))
# make examples still builds the others
.PHONY: $(B)/vulkan_inline $(B)/hlsl_inline
$(B)/vulkan_inline $(B)/hlsl_inline:
	@echo "$(notdir $@): not built: $(VI_MISSING)"
test-vulkan-inline test-hlsl-inline:
	@echo "$@: skipped: $(VI_MISSING)"; \
	[ "$$CI" != "true" ]
endif

# the Makefile's first target stays the default goal wherever this is included
.DEFAULT_GOAL := $(VI_DEFAULT_GOAL)
