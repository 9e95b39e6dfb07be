#!/bin/sh
# Summary of a `make fuzz` run in <dir> (build/fuzz/<harness>): executions,
# coverage, corpus size, and each distinct failure with how many crash files
# show it (replayed one by one).  Exit status 1 if there was any failure.
dir=$1
log=$dir/fuzz.log
last=$(grep -E '^#[0-9]+: cov: ' "$log" | tail -1)
echo "fuzz: last status: $last"
grep -E 'INFO: fuzzed for|INFO: exiting' "$log" | tail -2 | sed 's/^/fuzz: /'
echo "fuzz: corpus: $(ls "$dir/corpus" | wc -l) inputs"
n=$(ls "$dir/crashes" 2>/dev/null | wc -l)
echo "fuzz: crash files: $n"
if [ "$n" -gt 0 ]; then
    for f in "$dir"/crashes/*; do
        "$dir/fuzzer" "$f" 2>&1 |
            grep -E 'oracle violated|runtime error|ERROR: AddressSanitizer|ERROR: libFuzzer' |
            grep -v 'deadly signal' | head -1 |
            sed -E 's/at period [0-9]+: //; s/(runtime error: [a-z -]+).*/\1/; s/^.*(src|hal|boards)\//\1\//'
    done | sort | uniq -c | sed 's/^/fuzz: failures: /'
    exit 1
fi
exit 0
