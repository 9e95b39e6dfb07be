# The instrumented host replay for the dsPIC33 cycle estimate
# (tools/bench/dspic/dspic_est.py, dspic_replay.c):
#
#   make -f tools/bench/dspic/dspic.mk OUT=<dir> USERPARMS=<userparms.h>
#
# -> OUT/dspic_replay: the core as firmware builds it (the estimator
# userparms.h selects), compiled twice by clang: with source-based coverage
# (OUT/cov, the fast steps counted) and plain with every global symbol
# renamed u_<name> (OUT/plain, everything else).  Run from the repository
# root.
OUT       ?= build/bench/dspic
USERPARMS ?= $(abspath userparms.h.in)
CLANG     ?= clang
OBJCOPY   ?= objcopy
NM        ?= nm

CFLAGS    := -O1 -std=c99 -Iinclude -Itools/bench -DFOC_USERPARMS_FILE='"$(USERPARMS)"'
COV       := -fprofile-instr-generate -fcoverage-mapping
CORE_SRC  := $(wildcard src/*.c)
HARNESS   := tools/bench/bench_io.c tools/bench/bench_port.c tools/bench/replay.c \
             tools/bench/frames_file.c
COV_OBJ   := $(patsubst src/%.c,$(OUT)/cov/%.o,$(CORE_SRC))
PLAIN_OBJ := $(patsubst src/%.c,$(OUT)/plain/%.o,$(CORE_SRC)) \
             $(patsubst tools/bench/%.c,$(OUT)/plain/%.o,$(HARNESS))
REN_OBJ   := $(patsubst $(OUT)/plain/%,$(OUT)/renamed/%,$(PLAIN_OBJ))
DEPS      := $(wildcard include/foc/*.h tools/bench/*.h) $(USERPARMS) \
             tools/bench/dspic/dspic.mk $(OUT)/defs.stamp

.PHONY: all FORCE
.SECONDARY:
all: $(OUT)/dspic_replay

$(OUT)/defs.stamp: FORCE
	@mkdir -p $(@D)
	@echo '$(CFLAGS)' | cmp -s - $@ || echo '$(CFLAGS)' > $@

$(OUT)/cov/%.o: src/%.c $(DEPS)
	@mkdir -p $(@D)
	$(CLANG) $(CFLAGS) $(COV) -c $< -o $@

$(OUT)/plain/%.o: src/%.c $(DEPS)
	@mkdir -p $(@D)
	$(CLANG) $(CFLAGS) -c $< -o $@

$(OUT)/plain/replay.o: tools/bench/replay.c $(DEPS)
	@mkdir -p $(@D)
	$(CLANG) $(CFLAGS) -Dfoc_fast_step=dspic_fast_step -Dfoc_slow_step=dspic_slow_step -c $< -o $@

$(OUT)/plain/%.o: tools/bench/%.c $(DEPS)
	@mkdir -p $(@D)
	$(CLANG) $(CFLAGS) -c $< -o $@

# every global symbol the plain core defines -> u_<symbol>
$(OUT)/rename.txt: $(patsubst src/%.c,$(OUT)/plain/%.o,$(CORE_SRC))
	$(NM) -g --defined-only $^ | awk 'NF == 3 { print $$3 " u_" $$3 }' | sort -u > $@

$(OUT)/renamed/%.o: $(OUT)/plain/%.o $(OUT)/rename.txt
	@mkdir -p $(@D)
	$(OBJCOPY) --redefine-syms=$(OUT)/rename.txt $< $@

$(OUT)/dspic_replay.o: tools/bench/dspic/dspic_replay.c $(DEPS)
	$(CLANG) $(CFLAGS) -c $< -o $@

$(OUT)/dspic_replay: $(COV_OBJ) $(REN_OBJ) $(OUT)/dspic_replay.o
	$(CLANG) -fprofile-instr-generate $^ -o $@
