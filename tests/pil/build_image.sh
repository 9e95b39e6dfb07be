#!/bin/sh
# pil.image <source dir> <build dir> <userparms.h>: the STM32 image (make
# stm32, in the source tree as the firmware is built) and the controller
# layout object tools/pil reads.  Fails, never skips.
set -u
src=$1 out=$2 parms=$3
missing=""
command -v arm-none-eabi-gcc >/dev/null 2>&1 ||
    missing="$missing gcc-arm-none-eabi libnewlib-arm-none-eabi"
if [ ! -x /usr/bin/python3 ] ||
   ! /usr/bin/python3 -c 'import unicorn, capstone, elftools' 2>/dev/null; then
    missing="$missing python3 python3-unicorn python3-capstone python3-pyelftools"
fi
if [ -n "$missing" ]; then
    echo "pil.image: FAIL: the Cortex-M3 toolchain or simulator is missing."
    echo "  Install (Debian/Ubuntu): apt-get install$missing"
    exit 1
fi
make --no-print-directory -C "$src" stm32 > "$out/image.log" 2>&1 ||
    { cat "$out/image.log"; echo "pil.image: FAIL: make stm32"; exit 1; }
arm-none-eabi-gcc -mcpu=cortex-m3 -mthumb -O2 -std=c99 -Wall -Wextra -Werror \
    -I"$src/include" -DFOC_USERPARMS_FILE="\"$parms\"" \
    -c "$src/tools/pil/ctrl_layout.c" -o "$out/ctrl_layout.o" ||
    { echo "pil.image: FAIL: ctrl_layout.c"; exit 1; }
echo "pil.image: ok"
