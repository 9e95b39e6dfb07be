#!/bin/sh
# skip_summary.sh <skip log>: make test's closing line, the tests need.sh
# skipped counted per set of missing packages, e.g.
#   skipped: 5 tests (need gcc-avr avr-libc: 1; python3-unicorn ...: 4)
log=$1
if [ ! -s "$log" ]; then
    echo "skipped: 0 tests"
    exit 0
fi
tab=$(printf '\t')
sort -t "$tab" -k 2,2 -k 1,1 "$log" | awk -F '\t' '
    !($2 in count) { order[++sets] = $2 }
    { count[$2]++; total++ }
    END {
        line = "skipped: " total (total == 1 ? " test" : " tests") " (need "
        for (i = 1; i <= sets; i++)
            line = line (i > 1 ? "; " : "") order[i] ": " count[order[i]]
        print line ")"
    }'
