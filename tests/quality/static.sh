#!/bin/sh
# Static analysis of the core and the ports (make static, make check):
#   cppcheck 2.x with its MISRA C 2012 addon (rule numbers only: the rule
#   texts are not distributed) and clang-tidy (tests/quality/clang-tidy.yaml)
# over src/, include/, hal/ and boards/ as they are when it runs.
#
# Units (each with its include paths, defines and userparms.h):
#   core     src/*.c, every estimator built (FOC_ALL_ESTIMATORS)
#   config   include/foc/config.h on its own (see below)
#   stm32    hal/stm32f10x, boards/stm3210b_mckit (the kit's userparms.h)
#   dspic    hal/dspic33fj (without its host stub), boards/dspicdem_mclv,
#            against the stub <xc.h> register declarations
#   host     hal/host (the host port over the motor model)
#   any other directory under hal/ or boards/: its .c files with -I<dir>,
#            the hal/ directories and userparms.h.in (a note is printed)
#
# cppcheck reads the core's derived constants from a copy of config.h in
# which they are replaced by their values (flatten_config.py explains why);
# config.h itself is checked as the unit `config`.
#
# Deviations: tests/quality/cppcheck-suppressions.txt (advisory MISRA rules,
# and rules for a set of files), per-line cppcheck-suppress comments (the
# required rules; tests/quality/misra_deviations.py checks that each is in
# the list of docs/static-analysis.md), with the reasons in that document,
# and the check list of clang-tidy.yaml.
# Every other finding is printed and makes the script fail; the last lines
# count the findings by rule.  Output also in build/static/.
set -u
cd "$(dirname "$0")/../.."
OUT=${STATIC_OUT:-build/static}
Q=tests/quality
mkdir -p "$OUT"
rm -f "$OUT"/*.txt

for tool in cppcheck clang-tidy gcc; do
    if ! command -v $tool >/dev/null 2>&1; then
        echo "static: $tool not found (Debian: apt-get install cppcheck clang-tidy gcc)"
        exit 1
    fi
done
MISRA=$(cppcheck --version | awk '{print $2}')
TEMPLATE='{file}:{line}:{column}: {severity}: [{id}] {message}'
PARMS_DEFAULT=$PWD/userparms.h.in

# unit <name> <userparms.h> <"flags"> <files...>
unit() {
    name=$1 parms=$2 flags=$3
    shift 3
    [ $# -gt 0 ] || return 0
    echo "static: unit $name: $# files"
    shim=$OUT/shim-$name
    defs="-DFOC_USERPARMS_FILE=\"$parms\""
    # shellcheck disable=SC2086
    /usr/bin/python3 $Q/flatten_config.py "$shim" -Iinclude $flags "$defs" \
        >"$OUT/flatten-$name.log" 2>&1 || { cat "$OUT/flatten-$name.log"; exit 1; }
    # shellcheck disable=SC2086
    cppcheck --addon=misra --std=c99 --platform=unix32 --enable=warning,style,performance,portability \
        --inline-suppr --suppressions-list=$Q/cppcheck-suppressions.txt -q -j 2 \
        --template="$TEMPLATE" -I"$shim" -Iinclude $flags "$defs" "$@" \
        2>>"$OUT/cppcheck-raw.txt"
    for f in "$@"; do
        # shellcheck disable=SC2086
        clang-tidy --quiet --config-file=$Q/clang-tidy.yaml "$f" -- -std=c99 -Iinclude \
            $flags "$defs" -Wall -Wextra 2>/dev/null | grep -E '^[^ ].*: (warning|error): ' \
            >>"$OUT/clang-tidy.txt"
    done
}

# shellcheck disable=SC2046
unit core "$PARMS_DEFAULT" "-DFOC_ALL_ESTIMATORS" $(ls src/*.c)
unit config "$PARMS_DEFAULT" "-DFOC_ALL_ESTIMATORS" $Q/config_alone.c

known=""
if [ -d hal/stm32f10x ]; then
    known="$known hal/stm32f10x boards/stm3210b_mckit"
    # shellcheck disable=SC2046
    unit stm32 "$PWD/boards/stm3210b_mckit/userparms.h" \
        "-Ihal/stm32f10x -Iboards/stm3210b_mckit -DSTM32F10X_MD" \
        $(ls hal/stm32f10x/*.c boards/stm3210b_mckit/*.c 2>/dev/null)
fi
if [ -d hal/dspic33fj ]; then
    known="$known hal/dspic33fj boards/dspicdem_mclv"
    # shellcheck disable=SC2046
    unit dspic "$PARMS_DEFAULT" "-Ihal/dspic33fj -Ihal/dspic33fj/stub -Iboards/dspicdem_mclv" \
        $(ls hal/dspic33fj/*.c boards/dspicdem_mclv/*.c 2>/dev/null)
fi
if [ -d hal/host ]; then
    known="$known hal/host"
    # shellcheck disable=SC2046
    unit host "$PARMS_DEFAULT" "-Ihal/host -Itools/plant" $(ls hal/host/*.c)
fi
halinc=$(for d in hal/*/; do printf ' -I%s' "${d%/}"; done)
for d in hal/*/ boards/*/; do
    d=${d%/}
    case " $known " in *" $d "*) continue ;; esac
    ls "$d"/*.c >/dev/null 2>&1 || continue
    echo "static: note: $d has no configuration in $0: generic flags"
    parms=$PARMS_DEFAULT
    [ -f "$d/userparms.h" ] && parms=$PWD/$d/userparms.h
    # shellcheck disable=SC2046
    unit "$(echo "$d" | tr / -)" "$parms" "-I$d $halinc" $(ls "$d"/*.c)
done

# cppcheck: findings in the flattened copies of config.h are config.h's
# (checked as the unit `config`, whose own unused-macro reports are noise).
grep -E '^[^ ]+:[0-9]+:[0-9]+: [a-z]+: \[' "$OUT/cppcheck-raw.txt" |
    grep -v "^$OUT/shim-" |
    grep -v "^$Q/config_alone.c" |
    sort -u >"$OUT/cppcheck.txt"
grep -vE '^[^ ]+:[0-9]+:[0-9]+: [a-z]+: \[' "$OUT/cppcheck-raw.txt" | grep -v '^$' |
    grep -v 'misra violation' >"$OUT/cppcheck-notes.txt" || true
sort -u "$OUT/clang-tidy.txt" -o "$OUT/clang-tidy.txt"

nc=$(wc -l <"$OUT/cppcheck.txt")
nt=$(wc -l <"$OUT/clang-tidy.txt")
if [ "$nc" -gt 0 ]; then
    sed 's/ misra violation (use --rule-texts=<file> to get proper output)//' "$OUT/cppcheck.txt"
fi
if [ "$nt" -gt 0 ]; then
    cat "$OUT/clang-tidy.txt"
fi
if [ -s "$OUT/cppcheck-notes.txt" ]; then
    echo "static: cppcheck said (not findings):"
    sed 's/^/  /' "$OUT/cppcheck-notes.txt"
fi
echo "static: cppcheck $MISRA + MISRA C 2012 addon: $nc findings not covered by a documented deviation"
if [ "$nc" -gt 0 ]; then
    grep -o '\[[A-Za-z0-9._-]*\]' "$OUT/cppcheck.txt" | sort | uniq -c | sort -rn | sed 's/^/static:   /'
fi
echo "static: clang-tidy: $nt findings"
if [ "$nt" -gt 0 ]; then
    grep -o '\[[A-Za-z0-9.,_-]*\]$' "$OUT/clang-tidy.txt" | sort | uniq -c | sort -rn | sed 's/^/static:   /'
fi
# every per-line MISRA deviation has a class and is listed in the document
nd=0
dev=$(/usr/bin/python3 $Q/misra_deviations.py --check) || nd=1
echo "$dev" | sed 's/^/static: /'
[ "$nc" -eq 0 ] && [ "$nt" -eq 0 ] && [ "$nd" -eq 0 ]
