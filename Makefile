# Top-level entry points.  The host build lives in build/host (CMake).
#
#   make test        configure, build, run the ctest suite (the CI command)
#   make sim         build focsim and run the default scenario
#                    -> build/sim/default.csv, build/sim/default.svg
#   make core-arm    compile the portable core for Cortex-M3 (warnings = errors)
#
# FOC_USERPARMS=<path> selects the userparms.h of the host build.

BUILD      := build/host
JOBS       ?= 2
CMAKE_ARGS := -DFOC_USERPARMS="$(FOC_USERPARMS)"

.PHONY: all test sim configure build core-arm clean

all: build

configure:
	cmake -S . -B $(BUILD) $(CMAKE_ARGS)

build: configure
	cmake --build $(BUILD) -j $(JOBS)

test: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

sim: build
	@mkdir -p build/sim
	$(BUILD)/focsim --scenario tools/scenarios/default.scn \
	    --csv build/sim/default.csv --plot build/sim/default.svg

# The core alone, cross-compiled as the STM32 image will compile it.
ARM_CC     := arm-none-eabi-gcc
ARM_FLAGS  := -mcpu=cortex-m3 -mthumb -O2 -std=c99 -Wall -Wextra -Wconversion \
              -Werror -Iinclude
ARM_PARMS  := $(if $(FOC_USERPARMS),$(abspath $(FOC_USERPARMS)),$(abspath userparms.h.in))
CORE_SRC   := $(wildcard src/*.c)
CORE_OBJ   := $(patsubst src/%.c,build/core-arm/%.o,$(CORE_SRC))

core-arm: $(CORE_OBJ)
	arm-none-eabi-size -t $(CORE_OBJ)

build/core-arm/%.o: src/%.c $(wildcard include/foc/*.h) $(ARM_PARMS)
	@mkdir -p $(@D)
	$(ARM_CC) $(ARM_FLAGS) -DFOC_USERPARMS_FILE='"$(ARM_PARMS)"' -c $< -o $@

clean:
	rm -rf build
