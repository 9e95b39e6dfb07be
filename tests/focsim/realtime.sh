#!/bin/sh
# focsim's real-time factor (simulated seconds per processor second of the
# simulation loop, no CSV) on a 20 s scenario, the default estimator.
# Reported, not a benchmark gate: the test fails only below MIN (10x, far
# under the ~100x expected), so that a loaded machine cannot make it flaky.
#   realtime.sh <focsim> <scenario> [MIN]
focsim=$1
scn=$2
min=${3:-10}
out=$("$focsim" --scenario "$scn" --time) || { echo "$out"; exit 1; }
echo "$out" | grep -E '^(sim_time_s|cpu_time_s|realtime_factor)='
rtf=$(echo "$out" | sed -n 's/^realtime_factor=//p')
awk -v r="$rtf" -v m="$min" 'BEGIN { if (r + 0 < m + 0) { print "realtime_factor " r " below " m; exit 1 } }'
