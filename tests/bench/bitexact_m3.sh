#!/bin/sh
# bench.bitexact_m3 <source dir> <image dir> <frames.bin> <userparms.h> <bench_replay_host>
#
# The recorded frames run through the core compiled for Cortex-M3 (-O2,
# every estimator built in) on the instruction-set simulator must give, in
# every period, the outputs of the recording (duties, bridge, state,
# faults, angle, speed, references), and the same output hash as the host
# replay.  Fails, never skips: without the cross compiler or the simulator's
# Python modules it says what to install.
set -u
src=$1 out=$2 frames=$3 parms=$4 replay=$5

missing=""
command -v arm-none-eabi-gcc >/dev/null 2>&1 ||
    missing="$missing gcc-arm-none-eabi libnewlib-arm-none-eabi"
if [ ! -x /usr/bin/python3 ] ||
   ! /usr/bin/python3 -c 'import unicorn, capstone, elftools' 2>/dev/null; then
    missing="$missing python3 python3-unicorn python3-capstone python3-pyelftools"
fi
if [ -n "$missing" ]; then
    echo "bench.bitexact_m3: FAIL: the Cortex-M3 toolchain or simulator is missing."
    echo "  Install (Debian/Ubuntu): apt-get install$missing"
    echo "  (the simulator runs on /usr/bin/python3 with Debian's modules)"
    exit 1
fi

hash=$("$replay" "$frames" | sed -n 's/^hash=//p')
if [ -z "$hash" ]; then
    echo "bench.bitexact_m3: FAIL: the host replay gave no hash"
    exit 1
fi
echo "host replay hash=$hash"
make -s -j2 -C "$src" -f tools/bench/image.mk OUT="$out" FRAMES="$frames" \
    USERPARMS="$parms" EXTRA_DEFS=-DFOC_ALL_ESTIMATORS || exit 1
exec /usr/bin/python3 "$src/tools/bench/bench.py" check --elf "$out/bench.elf" \
    --frames "$frames" --hash "$hash"
