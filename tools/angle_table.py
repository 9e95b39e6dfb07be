#!/usr/bin/env python3
"""The estimators' angle error on every torture motor (docs/estimators.md,
"Gains from the motor").

  angle_table.py --bin build/host/torture [--motors a,b] [--jobs J]

For every motor of the torture campaign, every sensorless estimator, the
speeds 20, 50 and 100 % of the motor's nominal speed (and 8000 rpm on the
drone motor, issue 12's case), without load and with half the rated
torque: start with the command, 2 codes of ADC noise (the board's dead
time is the plant's by default), and 0.3 s after the start-up time-out
plus the speed ramp, the load; the figure is the torture binary's
angle_err_rms_deg (estimated minus the plant's true electrical angle, RMS
over the periods in RUN) over the last 0.3 s.  `fault` where the run did
not stay in RUN.  Prints one Markdown table row per case.
"""

import argparse
import concurrent.futures
import os
import subprocess
import sys

NOMINAL_RPM = {"drone_12pp_24v": 6000, "fan_highj": 1200, "hurst075": 2000,
               "ipm_320v": 3000, "servo_8pp_48v": 3000, "shinano_la052": 3000}
EXTRA_RPM = {"drone_12pp_24v": [8000]}
ESTIMATORS = ("pll", "luenberger", "flux")


def key_values(text):
    return dict(t.split("=", 1) for t in text.split() if "=" in t)


def run(exe, params, rpm, load_fraction, est):
    t_load = float(params["startup_timeout_s"]) + rpm / float(params["ramp_rpm_per_s"]) + 0.3
    lines = ["#! measure_from %g" % (t_load + 0.3), "0 plant noise 2",
             "0 speed %g" % rpm, "0 start"]
    if load_fraction:
        lines.append("%g load %g" % (t_load, load_fraction * float(params["rated_torque_nm"])))
    lines.append("%g end" % (t_load + 0.6))
    path = "%s.%d.%g.%g.%s.scn" % (exe, os.getpid(), rpm, load_fraction, est)
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    try:
        out = subprocess.run([exe, "--scenario", path, "--estimator", est],
                             capture_output=True, text=True).stdout
    finally:
        os.unlink(path)
    res = key_values(out.splitlines()[0] if out else "")
    if res.get("end_state") != "RUN":
        return "fault"
    return "%.2f" % float(res["angle_err_rms_deg"])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", required=True, help="directory of the torture_<motor> binaries")
    ap.add_argument("--motors", default=",".join(NOMINAL_RPM))
    ap.add_argument("--jobs", type=int, default=1)
    args = ap.parse_args()
    cases = []
    for motor in args.motors.split(","):
        exe = os.path.join(args.bin, "torture_" + motor)
        params = key_values(subprocess.run([exe, "--params"], capture_output=True,
                                           text=True).stdout)
        speeds = [f * NOMINAL_RPM[motor] for f in (0.2, 0.5, 1.0)] + EXTRA_RPM.get(motor, [])
        for rpm in speeds:
            for load in (0.0, 0.5):
                cases.append((motor, exe, params, rpm, load))
    print("| motor | rpm | load | PLL | Luenberger | flux |")
    print("|---|---|---|---|---|---|")
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        rows = [[pool.submit(run, exe, params, rpm, load, est) for est in ESTIMATORS]
                for motor, exe, params, rpm, load in cases]
        for (motor, _, _, rpm, load), futures in zip(cases, rows):
            print("| %s | %.0f | %s | %s |" % (motor, rpm, "1/2 rated" if load else "-",
                                               " | ".join(f.result() for f in futures)))
            sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
