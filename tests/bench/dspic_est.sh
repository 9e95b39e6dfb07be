#!/bin/sh
# The dsPIC33 estimator (tools/bench/dspic/dspic_est.py) on a hand-worked
# function (tests/bench/dspic/hand.c) whose cycle count is derived by hand
# from DS70157: builds it with clang's coverage, runs the estimate, fails
# unless it gives the hand figure.
#   dspic_est.sh <source dir> <work dir>
set -e
src=$1
work=$2
mkdir -p "$work"
d=$src/tests/bench/dspic
clang -O1 -fprofile-instr-generate -fcoverage-mapping -I"$d" -c "$d/hand.c" -o "$work/hand.o"
clang -O1 -I"$d" -c "$d/hand_main.c" -o "$work/hand_main.o"
clang -fprofile-instr-generate "$work/hand.o" "$work/hand_main.o" -o "$work/hand"
cd "$work"
python3 "$src/tools/bench/dspic/dspic_est.py" estimate --binary "$work/hand" \
    --run "$work/hand" --sources "$d/hand.c" --cflags="-I$d" --keep "$d/hand.c" \
    --label hand.c --expect 25.10 --tolerance 0.005
