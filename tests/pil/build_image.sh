#!/bin/sh
# pil.image <source dir> <build dir> <userparms.h> <image dir>: the STM32
# image (make stm32, into the build tree's image folder) and the
# controller layout object tools/pil reads (through tests/common/need.sh).
set -u
src=$1 out=$2 parms=$3 image=$4
make --no-print-directory -C "$src" stm32 STM32_OUT="$image" > "$out/image.log" 2>&1 ||
    { cat "$out/image.log"; echo "pil.image: FAIL: make stm32"; exit 1; }
arm-none-eabi-gcc -mcpu=cortex-m3 -mthumb -O2 -std=c99 -Wall -Wextra -Werror \
    -I"$src/include" -DFOC_USERPARMS_FILE="\"$parms\"" \
    -c "$src/tools/pil/ctrl_layout.c" -o "$out/ctrl_layout.o" ||
    { echo "pil.image: FAIL: ctrl_layout.c"; exit 1; }
echo "pil.image: ok"
