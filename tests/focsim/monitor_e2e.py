#!/usr/bin/env python3
"""End to end: tools/foc-monitor <-> focsim --pty (the same monitor source
the boards run), checked against focsim's CSV.

    monitor_e2e.py FOCSIM FOC_MONITOR SRC_DIR WORK_DIR

focsim runs monitor_e2e.scn (5 s, no commands) paced to wall time, its
monitor on a pseudo-terminal, writing a CSV of every PWM period.  Through
foc-monitor's command line (the JSON output): identify; status at rest;
start and speed 1000 rpm; wait for RUN; a gain written while running
(speed_gain_shift 1, read back) and a write refused while running
(stop_mode); the speed PI's gains read in their units, set to 0 while
running for 0.4 s and restored; then a scope capture of speed_est,
theta_est, iq_ref and vq,
every period, triggered on speed_est rising through 1500 rpm with 25 %
before it, armed before the tool commands 2000 rpm; CSV and SVG written.

Checks, after focsim has finished, against its CSV (the oracle is the
plant-side simulation's record, not the monitor's replies):
  - the trigger period is found on the CSV alone: the first period after
    the controller reached RUN whose estimated speed crosses the level
    (previous < level <= this one, in counts);
  - every captured sample equals the CSV's value at its period within one
    LSB of the channel's scale plus half the CSV's printed resolution;
    channels the slow step writes (iq_ref) against the previous row: the
    slow step runs after the fast step (and the capture) in the same
    period, so the capture sees the value of the previous period's end,
    which is what that row shows;
  - status at rest: IDLE, bus voltage equal to the CSV's within one step
    of the board's bus ADC (the status carries the ADC sample, the CSV the
    plant's bus);
    status in RUN at the commanded 1000 rpm within 3 %;
  - the gain reads back; the refused write exits non-zero saying why;
  - speed_kp reads as userparms.h.in's SPEED_KP_A_PER_RPM; with the speed
    PI's gains at 0 its output (iq_ref) holds still: the CSV shows iq_ref
    constant over at least 0.3 s of RUN (with the gains it changes every
    few tens of periods), and the gains read back 0, then restored;
  - the SVG names every channel and its unit.
"""
import json
import math
import os
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from focsim_csv import decimals, read_csv

failures = []
ADC_BITS = 10  # userparms.h.in BOARD_ADC_BITS
SPEED_KP_A_PER_RPM = 3.312e-3  # userparms.h.in


def check(cond, msg):
    print(("ok   " if cond else "FAIL ") + msg)
    if not cond:
        failures.append(msg)
    return cond


CSV_COLUMN = {"speed_est": ("speed_est_rpm", 0), "theta_est": ("theta_est_deg", 0),
              "vq": ("vq_v", 0), "iq_ref": ("iq_ref_a", -1), "id": ("id_a", 0),
              "iq": ("iq_a", 0), "vdc": ("vdc_v", 0), "speed": ("speed_rpm", 0)}



def start_focsim(focsim, scn, csv, work):
    err = open(os.path.join(work, "focsim.err"), "w+")
    proc = subprocess.Popen([focsim, "--pty", "--scenario", scn, "--csv", csv],
                            stdout=open(os.path.join(work, "focsim.out"), "w"), stderr=err)
    end = time.monotonic() + 5
    while time.monotonic() < end:
        err.seek(0)
        for line in err.read().splitlines():
            if line.startswith("pty: "):
                return proc, line[5:].strip()
        time.sleep(0.02)
    proc.kill()
    raise SystemExit("focsim printed no pty line")


def tool(fm, pty, *cmds):
    args = [sys.executable, fm, "--port", pty, "--json"]
    for c in cmds:
        args += ["-e", c]
    r = subprocess.run(args, capture_output=True, text=True, timeout=60)
    res = [json.loads(l) for l in r.stdout.splitlines() if l.startswith("{")]
    return r, res


def main():
    focsim, fm, src, work = sys.argv[1:5]
    os.makedirs(work, exist_ok=True)
    csv = os.path.join(work, "focsim.csv")
    cap_csv = os.path.join(work, "scope.csv")
    cap_svg = os.path.join(work, "scope.svg")
    for f in (csv, cap_csv, cap_svg):
        if os.path.exists(f):
            os.remove(f)
    proc, pty = start_focsim(focsim, os.path.join(src, "monitor_e2e.scn"), csv, work)
    try:
        r, res = tool(fm, pty, "identify", "status", "start", "speed 1000", "wait RUN 3",
                      "sleep 0.8", "status", "set speed_gain_shift 1", "get speed_gain_shift")
        check(r.returncode == 0, "tool run 1 exit status %d %s" % (r.returncode, r.stderr))
        refused = subprocess.run([sys.executable, fm, "--port", pty, "set", "stop_mode", "1"],
                                 capture_output=True, text=True, timeout=30)
        check(refused.returncode == 1 and "refused while the motor is driven" in refused.stderr,
              "stop_mode write refused while running: %r" % refused.stderr.strip())
        rg, gains = tool(fm, pty, "get speed_kp", "get speed_ki")
        kp, ki = (gains[0]["result"], gains[1]["result"]) if len(gains) == 2 else (None, None)
        check(rg.returncode == 0 and kp is not None and abs(kp - SPEED_KP_A_PER_RPM) <=
              1e-3 * SPEED_KP_A_PER_RPM, "speed_kp %s A/rpm, speed_ki %s A/(rpm s)" % (kp, ki))
        rz, zeroed = tool(fm, pty, "set speed_kp 0", "set speed_ki 0", "sleep 0.4",
                          "get speed_kp", "get speed_ki", "set speed_kp %r" % kp,
                          "set speed_ki %r" % ki, "get speed_kp", "get speed_ki")
        check(rz.returncode == 0 and len(zeroed) == 9 and zeroed[3]["result"] == 0 and
              zeroed[4]["result"] == 0 and zeroed[7]["result"] == kp and
              zeroed[8]["result"] == ki, "speed PI gains 0 while running, read back, restored")
        r2, res2 = tool(fm, pty, "scope ch=speed_est,theta_est,iq_ref,vq decim=1 trig=speed_est "
                        "edge=rising level=1500 pre=25 timeout=3 then=speed,2000 csv=%s svg=%s"
                        % (cap_csv, cap_svg))
        check(r2.returncode == 0, "tool run 2 (scope) exit status %d %s"
              % (r2.returncode, r2.stderr))
    finally:
        proc.wait(timeout=30)
    check(proc.returncode == 0, "focsim exit status %s" % proc.returncode)
    if len(res) < 9 or len(res2) < 1:
        check(False, "all results received (%d, %d)" % (len(res), len(res2)))
        return 1

    ident = res[0]["result"]
    check(ident["pwm_hz"] > 0 and ident["protocol"] == 1, "identify: %s" % ident)
    cols = read_csv(csv)
    st0, st1 = res[1]["result"], res[6]["result"]
    adc_step = ident["vdc_base_v"] / 2 ** ADC_BITS
    check(st0["state"] == "IDLE" and abs(st0["vdc_v"] - float(cols["vdc_v"][0])) <= adc_step,
          "status at rest: IDLE, vdc %.3f V (CSV %s)" % (st0["vdc_v"], cols["vdc_v"][0]))
    check(st1["state"] == "RUN" and abs(st1["speed_est_rpm"] - 1000) < 30 and
          st1["fault_names"] == [], "status in RUN: %.1f rpm" % st1["speed_est_rpm"])
    check(res[7]["result"] == 1 and res[8]["result"] == 1.0, "speed_gain_shift written, reads 1")

    # the speed PI without gains: its output held
    run_rows = [i for i, s in enumerate(cols["state"]) if s == "RUN"]
    longest = cur = 1
    for a, b in zip(run_rows, run_rows[1:]):
        cur = cur + 1 if b == a + 1 and cols["iq_ref_a"][a] == cols["iq_ref_a"][b] else 1
        longest = max(longest, cur)
    check(longest >= 0.3 * ident["pwm_hz"], "iq_ref constant over %d periods (%.3f s) of RUN"
          % (longest, longest / ident["pwm_hz"]))

    # the capture
    with open(cap_csv) as f:
        head = f.readline().strip().split(",")
        rows = [l.strip().split(",") for l in f]
    chans = [h[:-7] for h in head if h.endswith("_counts")]
    check(chans == ["speed_est", "theta_est", "iq_ref", "vq"], "capture channels %s" % chans)
    fs = {"speed_est": ident["speed_base_rpm"], "theta_est": 180.0,
          "iq_ref": ident["i_base_a"], "vq": ident["v_base_v"]}
    ks = [int(r[0]) for r in rows]
    pre = -ks[0]
    check(ks == list(range(-pre, len(rows) - pre)) and pre == len(rows) // 4,
          "frames %d, %d before the trigger" % (len(rows), pre))

    run0 = cols["state"].index("RUN")
    level = round(1500 * 32768 / fs["speed_est"])
    counts = [round(float(v) * 32768 / fs["speed_est"]) for v in cols["speed_est_rpm"]]
    p = next(i for i in range(run0 + 1, len(counts)) if counts[i - 1] < level <= counts[i])
    print("trigger period from the CSV: %d (t = %s s)" % (p, cols["t_s"][p]))
    worst, bad = {}, 0
    for r in rows:
        period = p + int(r[0])
        for c, name in enumerate(chans):
            col, off = CSV_COLUMN[name]
            text = cols[col][period + off]
            lsb = fs[name] / 32768
            v = int(r[2 + 2 * c])
            if name == "theta_est" and v < 0:
                v += 65536
            diff = v * lsb - float(text)
            if name == "theta_est":
                diff = math.remainder(diff, 360.0)
            tol = lsb + 0.5 * 10.0 ** -decimals(text) + 1e-12
            worst[name] = max(worst.get(name, 0.0), abs(diff) / lsb)
            if abs(diff) > tol:
                bad += 1
                if bad <= 5:
                    print("  %s at period %d: capture %g, CSV %s" % (name, period, v * lsb, text))
    for name in chans:
        print("  %-10s largest |capture - CSV| = %.3f LSB" % (name, worst.get(name, -1)))
    check(bad == 0, "%d frames x %d channels equal to the CSV within 1 LSB (+ CSV rounding): "
          "%d mismatches" % (len(rows), len(chans), bad))

    root = ET.parse(cap_svg).getroot()
    texts = [(e.text or "") for e in root.iter() if e.tag.endswith("text")]
    for name, unit in (("speed_est", "rpm"), ("theta_est", "deg"), ("iq_ref", "A"), ("vq", "V")):
        check(name in texts and unit in texts, "SVG shows %s and %s" % (name, unit))
    print("%d check(s) failed" % len(failures) if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
