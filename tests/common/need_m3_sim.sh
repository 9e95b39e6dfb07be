# Sourced by the tests that need the Cortex-M3 toolchain and simulator:
# need_m3_sim <test name> fails the test (never skips) when
# arm-none-eabi-gcc or Debian's python3-unicorn/-capstone/-pyelftools for
# /usr/bin/python3 are missing, saying what to install.
need_m3_sim() {
    missing=""
    command -v arm-none-eabi-gcc >/dev/null 2>&1 ||
        missing="$missing gcc-arm-none-eabi libnewlib-arm-none-eabi"
    if [ ! -x /usr/bin/python3 ] ||
       ! /usr/bin/python3 -c 'import unicorn, capstone, elftools' 2>/dev/null; then
        missing="$missing python3 python3-unicorn python3-capstone python3-pyelftools"
    fi
    if [ -n "$missing" ]; then
        echo "$1: FAIL: the Cortex-M3 toolchain or simulator is missing."
        echo "  Install (Debian/Ubuntu): apt-get install$missing"
        echo "  (the simulator runs on /usr/bin/python3 with Debian's modules)"
        exit 1
    fi
}
