#!/usr/bin/python3
"""Writes the fuzz harness's seed corpus (tests/fuzz/corpus): a few
hand-made command sequences that reach the interesting states, for libFuzzer
to mutate.  Format: see fuzz_controller.c (8-byte header, 16-byte records).

    tests/fuzz/make_seeds.py tests/fuzz/corpus tests/fuzz/findings \
        tests/fuzz/corpus_monitor
"""
import os
import struct
import sys

PLL, SENSORED, LUENBERGER, FLUX = 1, 0, 2, 3
VDC_NOM = 14895   # 24 V on 52.8 V full scale (Hurst075 board), about
TEMP_25C = 7447   # 0.75 V of 3.3 V


def header(est=PLL, fw=2, stop=0, flags=0):
    return bytes([est, fw, stop, flags, 0, 0, 0, 0])


def rec(ia=0, ib=0, ic=0, vdc=VDC_NOM, temp=TEMP_25C, theta=0, phases=0, oc=0,
        start=0, stop=0, ack=0, speed=None, spin=0, repeat=0):
    ctl = (phases & 3) | (oc << 2) | (start << 3) | (stop << 4) | (ack << 5) \
        | ((speed is not None) << 6) | (spin << 7)
    return struct.pack("<hhhhhHBBh", ia, ib, ic, vdc, temp, theta & 0xFFFF, ctl,
                       repeat, speed or 0)


def idle(n):
    out = b""
    while n > 0:
        k = min(n, 256)
        out += rec(repeat=k - 1)
        n -= k
    return out


def spinning(n, speed, amp=2000, phases=0):
    """n periods of a sensor angle turning at `speed`, with sinusoid-ish
    currents (coarse: one record per 16 periods)."""
    out = b""
    theta = 0
    import math
    for k in range(0, n, 16):
        a = theta / 65536.0 * 2 * math.pi
        ia = int(amp * math.sin(a))
        ib = int(amp * math.sin(a - 2.094))
        ic = -ia - ib
        out += rec(ia, ib, ic, theta=theta, phases=phases, spin=1, speed=speed, repeat=15)
        theta = (theta + 16 * (speed // 64)) & 0xFFFF
    return out


SEEDS = {
    "sensored_run_stop": header(SENSORED) + rec(start=1, speed=4000) + idle(1300)
    + spinning(2000, 4000) + rec(stop=1) + idle(600),
    "pll_start": header(PLL) + rec(start=1, speed=6000) + idle(3000) + spinning(2000, 3000),
    "flux_start_3shunt": header(FLUX) + rec(start=1, speed=-5000, phases=3) + idle(4000),
    "luenberger_start": header(LUENBERGER) + rec(start=1, speed=5000) + idle(4000),
    "overcurrent_ack": header(SENSORED) + rec(start=1, speed=3000) + idle(1300)
    + rec(oc=1) + idle(2100) + rec(ack=1) + idle(20) + rec(start=1) + idle(1500),
    "overvoltage_brake": header(PLL, flags=1) + rec(start=1, speed=3000) + idle(600)
    + rec(vdc=24000, repeat=200) + rec(vdc=20000, repeat=200) + rec(vdc=14000, repeat=255)
    + idle(2100) + rec(ack=1) + idle(100),
    "undervoltage_overtemp": header(PLL) + rec(vdc=3000, repeat=50) + rec(ack=1)
    + rec(temp=20000, repeat=255) + idle(2100) + rec(ack=1) + idle(30),
    "short_brake": header(SENSORED, stop=2) + rec(start=1, speed=8000) + idle(1300)
    + spinning(3000, 8000) + rec(stop=1) + spinning(2000, 2000),
    "table_fw_reverse": header(SENSORED, fw=1) + rec(start=1, speed=20000) + idle(1300)
    + spinning(2000, 20000) + rec(speed=-20000) + spinning(2000, -20000),
    # Regressions (fuzz findings, fixed): an over-current trip in IDLE, the
    # bus below the under-voltage level while in FAULT, then an acknowledge:
    # FAULT must stay (the cause is present) ...
    "regression_ack_with_cause_present": header(PLL) + rec(oc=1) + idle(2100)
    + rec(vdc=3000, repeat=20) + rec(vdc=3000, ack=1) + rec(vdc=3000, repeat=30),
    # ... and RUN with the speed reference ramping up, then a command of
    # -32768 (-SPEED_BASE_RPM): the ramp's difference overflowed int32_t.
    "regression_speed_ramp_overflow": header(SENSORED) + rec(start=1, speed=3000)
    + idle(1500) + rec(speed=-32768) + idle(30),
}


# The monitor harness (fuzz_monitor.c): byte 0 odd = requests the harness
# frames itself, each a length byte (bit 7: corrupt one byte) and payload.
def req(*payload):
    return bytes([len(payload)]) + bytes(payload)


MONITOR_SEEDS = {
    "identify_status": b"\x01" + req(0x01) + req(0x06) + req(0x07, 16) + req(0x07, 64)
    + req(0x08, 17) + req(0x08, 65),
    "run": b"\x01" + req(0x05, 0x00, 0x20) + req(0x02) + req(0x06) * 30
    + req(0x09, 64, 1, 0) + req(0x09, 66, 1, 0) + req(0x03) + req(0x04),
    "scope": b"\x01" + req(0x10, 4, 5, 6, 21, 16, 2, 0, 6, 1, 0x00, 0x10, 0, 0, 20)
    + req(0x11) + req(0x02) + req(0x06) * 20 + req(0x13) + req(0x14, 0, 0, 16)
    + req(0x14, 16, 0, 16) + req(0x12),
    "scope_immediate": b"\x01" + req(0x10, 1, 13, 1, 0, 0, 0, 0, 0, 0, 0, 0) + req(0x11)
    + req(0x06) * 10 + req(0x14, 0, 0, 16) + req(0x14, 0xF8, 0, 8),
    "errors": b"\x01" + req(0x7E) + req(0x05) + req(0x09, 64, 9, 0) + req(0x09, 3, 0, 0)
    + req(0x14, 0, 0, 0) + bytes([0x83, 0x06, 0x01, 0x02, 0x05]) + req(0x20) + req(0x21),
    # the gains (entries 72 .. 82): PI gains at their extremes while
    # running, an observer's refused, then written stopped and restarted
    "gains": b"\x01" + req(0x05, 0x00, 0x20) + req(0x02) + req(0x06) * 20
    + req(0x09, 72, 0xFF, 0x7F) + req(0x09, 73, 0, 0) + req(0x09, 74, 0xFF, 0x7F)
    + req(0x09, 75, 0, 0x80) + req(0x08, 74) + req(0x07, 82) + req(0x09, 78, 1, 0)
    + req(0x06) * 10 + req(0x03) + req(0x06) * 20 + req(0x09, 80, 0xFF, 0x3F)
    + req(0x09, 81, 0, 0) + req(0x09, 79, 0xFF, 0x7F) + req(0x02) + req(0x06) * 20,
    "noise": b"\x00\x03\x06\x11\x22\x00\x00\xff" + bytes(range(1, 60)) + b"\x00\x02\x06\x00",
}

# Reproducers of open findings: kept out of the corpus so that `make test`
# stays green until they are fixed (`make check` runs them and fails), then
# moved into SEEDS as regression inputs.  None open.
FINDINGS = {}

def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "tests/fuzz/corpus"
    findings = sys.argv[2] if len(sys.argv) > 2 else "tests/fuzz/findings"
    monitor = sys.argv[3] if len(sys.argv) > 3 else "tests/fuzz/corpus_monitor"
    for d, items in ((out, SEEDS), (findings, FINDINGS), (monitor, MONITOR_SEEDS)):
        if not items:
            continue
        os.makedirs(d, exist_ok=True)
        for name, data in items.items():
            with open(os.path.join(d, name), "wb") as f:
                f.write(data)
        print("%d inputs -> %s" % (len(items), d))


if __name__ == "__main__":
    main()
