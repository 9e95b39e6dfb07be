# The Cortex-M3 bench image: the portable core (-O2, as `make core-arm`
# compiles it, plus -ffunction-sections/-fdata-sections and the stack
# usage outputs), the frame-replay port and loop, the recorded frames.
#
#   make -f tools/bench/image.mk OUT=<dir> FRAMES=<frames.bin> USERPARMS=<userparms.h>
#        [EXTRA_DEFS=-DFOC_ALL_ESTIMATORS]
#
# Without EXTRA_DEFS the core is built as firmware builds it (only the
# estimator userparms.h selects, plus the sensor); with
# -DFOC_ALL_ESTIMATORS it contains every estimator, like the host build, so
# that every recorded scenario can be replayed.
# Run from the repository root.  Outputs in OUT: bench.elf, bench.map,
# libfoc_core.a, and per core object its .su (-fstack-usage) and .ci
# (-fcallgraph-info=su) for the worst-case stack of the ISR path.
OUT       ?= build/bench
FRAMES    ?= $(OUT)/frames.bin
USERPARMS ?= $(abspath userparms.h.in)

ARM_PREFIX ?= arm-none-eabi-
CC  := $(ARM_PREFIX)gcc
AR  := $(ARM_PREFIX)ar

CPU      := -mcpu=cortex-m3 -mthumb
OPT      ?= -O2
WARN     := -Wall -Wextra -Wconversion -Werror
DEFS     := -Iinclude -DFOC_USERPARMS_FILE='"$(USERPARMS)"' $(EXTRA_DEFS)
CORE_CFLAGS  := $(CPU) $(OPT) -g -std=c99 $(WARN) $(DEFS) -ffunction-sections \
                -fdata-sections -fstack-usage -fcallgraph-info=su
# The harness avoids library calls (no loop-to-memcpy rewriting) so that
# any library code in the image is there for the core.
BENCH_CFLAGS := $(CORE_CFLAGS) -Itools/bench -fno-tree-loop-distribute-patterns
LDFLAGS  := $(CPU) -nostartfiles --specs=nano.specs --specs=nosys.specs \
            -T tools/bench/arm/bench.ld -Wl,--gc-sections -Wl,-Map=$(OUT)/bench.map

CORE_SRC  := $(wildcard src/*.c)
CORE_OBJ  := $(patsubst src/%.c,$(OUT)/core/%.o,$(CORE_SRC))
BENCH_SRC := tools/bench/bench_io.c tools/bench/bench_port.c tools/bench/replay.c \
             tools/bench/arm/main.c \
             tools/bench/arm/startup.c
BENCH_OBJ := $(patsubst tools/bench/%.c,$(OUT)/harness/%.o,$(BENCH_SRC))
HEADERS   := $(wildcard include/foc/*.h) $(wildcard tools/bench/*.h) $(USERPARMS) \
             tools/bench/image.mk $(OUT)/defs.stamp

.PHONY: all
all: $(OUT)/bench.elf

# Rebuild everything when the defines change.
$(OUT)/defs.stamp: FORCE
	@mkdir -p $(@D)
	@echo '$(DEFS) $(OPT)' | cmp -s - $@ || echo '$(DEFS) $(OPT)' > $@
.PHONY: FORCE

$(OUT)/core/%.o: src/%.c $(HEADERS)
	@mkdir -p $(@D)
	$(CC) $(CORE_CFLAGS) -c $< -o $@

$(OUT)/harness/%.o: tools/bench/%.c $(HEADERS)
	@mkdir -p $(@D)
	$(CC) $(BENCH_CFLAGS) -c $< -o $@

$(OUT)/harness/frames.o: tools/bench/arm/frames.S $(FRAMES)
	@mkdir -p $(@D)
	$(CC) $(CPU) -DBENCH_FRAMES_FILE='"$(abspath $(FRAMES))"' -c $< -o $@

$(OUT)/libfoc_core.a: $(CORE_OBJ)
	@rm -f $@
	$(AR) rcs $@ $(CORE_OBJ)

$(OUT)/bench.elf: $(BENCH_OBJ) $(OUT)/harness/frames.o $(OUT)/libfoc_core.a tools/bench/arm/bench.ld
	$(CC) $(LDFLAGS) $(BENCH_OBJ) $(OUT)/harness/frames.o $(OUT)/libfoc_core.a -o $@
