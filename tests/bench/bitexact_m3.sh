#!/bin/sh
# bench.bitexact_m3 <source dir> <image dir> <frames.bin> <userparms.h> <bench_replay_host>
#
# The recorded frames run through the core compiled for Cortex-M3 (-O2,
# every estimator built in) on the instruction-set simulator must give, in
# every period, the outputs of the recording (duties, bridge, state,
# faults, angle, speed, references), and the same output hash as the host
# replay.  Registered through tests/common/need.sh (arm-none-eabi-gcc and
# the simulator's Python modules).
set -u
src=$1 out=$2 frames=$3 parms=$4 replay=$5

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
