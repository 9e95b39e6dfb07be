#!/usr/bin/env python3
"""focsim --report against the same figures computed here from focsim's CSV.

usage: report_check.py FOCSIM SCENARIO WORKDIR

Runs the scenario once with --report and --csv (every period), then
recomputes every report key from the CSV's true columns: the steps from the
scenario's `speed` lines, each step's target from the CSV (the ramped
reference at the step's end: where the ramp completes, the accepted
command), the 2 % band (of the target, or of 5 % of the maximum speed near
zero), the last row outside it, the overshoot in the step's direction, the
steady error over the step's last 20 %, the angle error in RUN, the peak
phase current and the time above the limit.  Exit 0 when every key agrees
within one PWM period (times) or 0.01 (rpm, deg, A).
"""
import csv
import math
import os
import subprocess
import sys


def main():
    focsim, scenario, work = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    path = os.path.join(work, "report.csv")
    out = subprocess.run([focsim, "--scenario", scenario, "--report", "--csv", path],
                         capture_output=True, text=True, check=True).stdout
    got = dict(line.split("=", 1) for line in out.splitlines() if "=" in line)
    # the build's references, which the report states (userparms.h)
    max_rpm = float(got["report_max_speed_rpm"])
    i_lim = float(got["report_current_limit_a"])

    events, stops, end = [], [], None
    for line in open(scenario):
        f = line.split("#")[0].split()
        if len(f) >= 2 and f[1] == "speed":
            events.append(float(f[0]))
        elif len(f) >= 2 and f[1] == "stop":
            stops.append(float(f[0]))
        elif len(f) >= 2 and f[1] == "end":
            end = float(f[0])
    rows = list(csv.DictReader(open(path)))
    t = [float(r["t_s"]) for r in rows]
    dt = t[1] - t[0]

    want = {"report_steps": len(events)}
    for k, t0 in enumerate(events):
        # a step ends at the next speed command, a stop, or the end
        t1 = min([t for t in events + stops if t > t0] + [end])
        last = t1 == end  # a step that ends with the run keeps its last row
        span = [r for r, tr in zip(rows, t) if t0 <= tr and (tr < t1 or (last and tr <= t1))]
        target = float(span[-1]["speed_ref_rpm"])
        start = float(span[0]["speed_rpm"])
        band = 0.02 * max(abs(target), 0.05 * max_rpm)
        d = 1.0 if target >= start else -1.0
        outside = [float(r["t_s"]) + dt for r in span if abs(float(r["speed_rpm"]) - target) > band]
        settle = 0.0 if not outside else (math.nan if outside[-1] >= t1 else outside[-1] - t0)
        over = max(0.0, max(d * (float(r["speed_rpm"]) - target) for r in span))
        steady = [float(r["speed_rpm"]) - target for r in span
                  if float(r["t_s"]) >= t1 - 0.2 * (t1 - t0)]
        n = k + 1
        want["step%d_target_rpm" % n] = target
        want["step%d_start_rpm" % n] = start
        want["step%d_settle_s" % n] = settle
        want["step%d_overshoot_rpm" % n] = over
        want["step%d_steady_err_rpm" % n] = sum(steady) / len(steady)
    errs = [(float(r["theta_est_deg"]) - float(r["theta_e_deg"]) + 180.0) % 360.0 - 180.0
            for r in rows if r["state"] == "RUN"]
    want["run_angle_err_rms_deg"] = math.sqrt(sum(e * e for e in errs) / len(errs))
    want["run_angle_err_peak_deg"] = max(abs(e) for e in errs)
    peaks = [max(abs(float(r[c])) for c in ("ia_a", "ib_a", "ic_a")) for r in rows]
    want["peak_phase_current_a"] = max(peaks)
    want["time_above_current_limit_s"] = dt * sum(1 for p in peaks if p > i_lim)

    bad = 0
    for key, value in want.items():
        g = float(got.get(key, "nan"))
        tol = dt * 1.01 if key.endswith("_s") else 0.011
        ok = (math.isnan(value) and math.isnan(g)) or abs(g - value) <= tol
        # the CSV rounds to 0.01 rpm and 4-5 decimals: the tolerances cover it
        print("%-32s report %12.5f  from the CSV %12.5f  %s" % (key, g, value, "ok" if ok else "DIFF"))
        bad += not ok
    print("report_check: %s" % ("PASS" if bad == 0 else "FAIL (%d keys)" % bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
