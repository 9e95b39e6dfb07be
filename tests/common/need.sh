#!/bin/sh
# need.sh <test name> <tool>... -- <command> [<argument>...]
#
# Runs the command of a test that needs optional tools (CMake's
# foc_add_test_needing registers it so).  When a tool is missing the test
# is skipped -- exit 77, ctest's SKIP_RETURN_CODE -- naming the Debian
# packages to install, and a line "<test><TAB><packages>" is appended to
# $FOC_SKIP_LOG (make test's closing summary, skip_summary.sh); under
# CI=true a missing tool fails the test instead: CI installs everything.
# Tools:
#   python3  python3 on PATH
#   m3sim    Debian's Unicorn, Capstone and pyelftools for /usr/bin/python3
#            (the Cortex-M3 instruction-set simulator, tools/bench, tools/pil)
#   arm      arm-none-eabi-gcc with newlib (nano.specs)
#   avr      avr-gcc with avr-libc (a compiler whose int is 16 bits)
#   clang    clang
#   llvm     llvm-cov, llvm-profdata, opt
#   chromium Debian's chromium (the monitor's web view in a headless browser)
name=$1
shift
missing=""
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
    case $1 in
        python3)
            command -v python3 >/dev/null 2>&1 || missing="$missing python3" ;;
        m3sim)
            /usr/bin/python3 -c 'import unicorn, capstone, elftools' >/dev/null 2>&1 ||
                missing="$missing python3-unicorn python3-capstone python3-pyelftools" ;;
        arm)
            # -print-file-name echoes the bare name when newlib is absent
            case $(arm-none-eabi-gcc -print-file-name=nano.specs 2>/dev/null) in
                /*) ;;
                *) missing="$missing gcc-arm-none-eabi libnewlib-arm-none-eabi" ;;
            esac ;;
        avr)
            echo '#include <stdint.h>' |
                avr-gcc -mmcu=atmega2560 -E -o /dev/null - >/dev/null 2>&1 ||
                missing="$missing gcc-avr avr-libc" ;;
        clang)
            command -v clang >/dev/null 2>&1 || missing="$missing clang" ;;
        chromium)
            { command -v chromium || command -v chromium-browser; } >/dev/null 2>&1 ||
                missing="$missing chromium" ;;
        llvm)
            { command -v llvm-cov && command -v llvm-profdata && command -v opt; } \
                >/dev/null 2>&1 || missing="$missing llvm" ;;
        *)
            echo "need.sh: $name: unknown tool '$1'" >&2
            exit 2 ;;
    esac
    shift
done
[ "${1-}" = "--" ] || { echo "need.sh: $name: no -- before the command" >&2; exit 2; }
shift

if [ -n "$missing" ]; then
    missing=${missing# }
    if [ "${CI-}" = true ]; then
        echo "$name: FAIL: needs $missing (CI=true: a missing tool fails, never skips)"
        echo "  Install (Debian/Ubuntu): apt-get install $missing"
        exit 1
    fi
    echo "$name: SKIP: needs $missing"
    echo "  Install (Debian/Ubuntu): apt-get install $missing"
    [ -z "${FOC_SKIP_LOG-}" ] || printf '%s\t%s\n' "$name" "$missing" >> "$FOC_SKIP_LOG"
    exit 77
fi
# 77 means skipped to ctest: from the test's own command it is a failure
"$@"
status=$?
[ "$status" != 77 ] || { echo "$name: FAIL: the command exited 77"; exit 1; }
exit "$status"
