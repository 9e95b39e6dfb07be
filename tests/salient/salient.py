#!/usr/bin/env python3
"""Interior-magnet (salient) motor checks on a torture_<motor> executable
(tests/salient/CMakeLists.txt), judged from the plant's true values in its
--trace CSV (true angle, true rotor-frame currents, true torque, true
speed), never from what the firmware says about itself:

  salient.py angle    EXE pll|luenberger|flux SCN   angle error RMS <= 0.6 deg
                                                    (0.8 deg under load)
  salient.py mtpa     EXE SCN                       torque per ampere gain
  salient.py fw_range EXE SCN                       highest steady speed

Each prints its figures; exit status 0 when the check holds."""
import math
import os
import subprocess
import sys
import tempfile

COLS = ("t_s state fault speed_ref_rpm speed_rpm speed_est_rpm theta_e_deg "
        "theta_est_deg id_a iq_a id_ref_a iq_ref_a vd_v vq_v vdc_v torque_nm "
        "ia_a ib_a ic_a").split()
# Issue 12 asked 3 deg RMS (salient motor, 20-100 % of rated speed); at
# no load the three estimators measure 0.06-0.17 deg: 0.6 deg (3.5 x).
ANGLE_RMS_MAX_DEG = 0.6
# Under load (true torque above half the rated), every estimator's model
# must be right for the salient rotor: on the mean of Ld and Lq the
# Luenberger observer was 1.70 deg RMS off at the rated torque, on Lq (the
# extended EMF) 0.18-0.25 deg, like the PLL and the flux estimator (0.18-
# 0.23 deg measured): 0.8 deg (3.5 x; was 1.0).
ANGLE_RMS_LOADED_MAX_DEG = 0.8
SPEED_TOL = 0.01              # a window counts at its speed within 1 %


def params(exe):
    out = subprocess.run([exe, "--params"], capture_output=True, text=True, check=True).stdout
    d = {}
    for tok in out.split():
        k, v = tok.split("=", 1)
        try:
            d[k] = float(v)
        except ValueError:
            d[k] = v
    return d


def windows(scn):
    """`#@ window <from> <to> <rpm>` lines of the scenario."""
    out = []
    for line in open(scn):
        f = line.split()
        if len(f) == 5 and f[0] == "#@" and f[1] == "window":
            out.append((float(f[2]), float(f[3]), float(f[4])))
    return out


def run(exe, scn, est=None, extra=""):
    """Runs the scenario (with `extra` directives prepended); returns the
    trace rows (dicts of floats but state/fault) and the result line."""
    with tempfile.NamedTemporaryFile("w", suffix=".scn", delete=False) as f:
        f.write(extra + open(scn).read())
        path = f.name
    try:
        cmd = [exe, "--scenario", path, "--trace-every", "4"]
        if est:
            cmd += ["--estimator", est]
        p = subprocess.run(cmd, capture_output=True, text=True)
    finally:
        os.unlink(path)
    rows, result = [], ""
    for line in p.stdout.splitlines():
        if line[:1].isdigit():
            r = dict(zip(COLS, line.split(",")))
            for k in COLS:
                if k not in ("state", "fault"):
                    r[k] = float(r[k])
            rows.append(r)
        elif line.startswith(("PASS", "FAIL")):
            result = line
    return rows, result, p.returncode


def in_window(rows, w):
    sel = [r for r in rows if w[0] <= r["t_s"] < w[1]]
    if not sel or any(r["state"] != "RUN" for r in sel):
        raise SystemExit("window %.2f-%.2f s: not in RUN throughout" % w[:2])
    return sel


def mean(xs):
    return sum(xs) / len(xs)


def angle_error_deg(r):
    return (r["theta_est_deg"] - r["theta_e_deg"] + 180.0) % 360.0 - 180.0


def check_speed(sel, rpm, what):
    v = mean([r["speed_rpm"] for r in sel])
    if abs(v - rpm) > SPEED_TOL * abs(rpm):
        raise SystemExit("%s: true speed %.1f rpm, not %.0f" % (what, v, rpm))
    return v


def cmd_angle(exe, est, scn):
    p = params(exe)
    rows, result, rc = run(exe, scn, est)
    print(result)
    bad = rc != 0
    for w in windows(scn):
        sel = in_window(rows, w)
        check_speed(sel, w[2], "%s %.0f rpm" % (est, w[2]))
        errs = [angle_error_deg(r) for r in sel]
        rms = math.sqrt(mean([e * e for e in errs]))
        torque = mean([r["torque_nm"] for r in sel])
        limit = ANGLE_RMS_LOADED_MAX_DEG if torque > 0.5 * p["rated_torque_nm"] \
            else ANGLE_RMS_MAX_DEG
        ok = rms <= limit
        bad |= not ok
        print("%s %5.0f rpm, true torque %.3f Nm: angle error RMS %.2f deg, peak %.2f deg%s" % (
            est, w[2], torque, rms, max(abs(e) for e in errs),
            "" if ok else "  > %.1f deg" % limit))
    return 1 if bad else 0


def cmd_mtpa(exe, scn):
    p = params(exe)
    (w,) = windows(scn)
    fig = {}
    for label, extra in (("mtpa", ""), ("id=0", "#! mtpa off\n")):
        rows, result, rc = run(exe, scn, "pll", extra)
        print(result)
        if rc != 0:
            return 1
        sel = in_window(rows, w)
        check_speed(sel, w[2], label)
        fig[label] = {
            "torque": mean([r["torque_nm"] for r in sel]),
            "i": mean([math.hypot(r["id_a"], r["iq_a"]) for r in sel]),
            "id": mean([r["id_a"] for r in sel]),
            "iq": mean([r["iq_a"] for r in sel]),
        }
        f = fig[label]
        print("%-5s true torque %.4f Nm, true |i| %.4f A (id %.4f, iq %.4f): %.5f Nm/A" % (
            label, f["torque"], f["i"], f["id"], f["iq"], f["torque"] / f["i"]))
    # the closed form on the plant's parameters at the measured current
    psi, ld, lq, pp = p["flux_wb"], p["ld_h"], p["lq_h"], p["pole_pairs"]
    a = psi / (2.0 * (lq - ld))
    i = fig["id=0"]["i"]
    id_opt = (psi - math.sqrt(psi * psi + 8.0 * (lq - ld) ** 2 * i * i)) / (4.0 * (lq - ld))
    iq_opt = math.sqrt(i * i - id_opt * id_opt)
    t_opt = 1.5 * pp * (psi + (ld - lq) * id_opt) * iq_opt
    t_id0 = 1.5 * pp * psi * i
    gain_theory = t_opt / t_id0 - 1.0
    m, z = fig["mtpa"], fig["id=0"]
    gain = (m["torque"] / m["i"]) / (z["torque"] / z["i"]) - 1.0
    id_at_iq = a - math.sqrt(a * a + m["iq"] ** 2)
    print("MTPA gain in torque per ampere: %.3f %% measured, %.3f %% closed form at %.3f A "
          "(id %.3f A)" % (100.0 * gain, 100.0 * gain_theory, i, id_opt))
    print("MTPA d current: %.4f A true, %.4f A closed form at the true iq" % (m["id"], id_at_iq))
    ok = (0.75 * gain_theory <= gain <= 1.5 * gain_theory and
          abs(m["id"] - id_at_iq) <= 0.1 * abs(id_at_iq) and
          abs(m["torque"] - z["torque"]) <= 0.002 * z["torque"])
    return 0 if ok else 1


def cmd_fw_range(exe, scn):
    p = params(exe)
    (w,) = windows(scn)
    rows, result, rc = run(exe, scn, "pll")
    print(result)
    sel = in_window(rows, w)
    speed = mean([r["speed_rpm"] for r in sel])
    idm = mean([r["id_a"] for r in sel])
    vdc = mean([r["vdc_v"] for r in sel])
    peak = max(math.sqrt((r["ia_a"] ** 2 + r["ib_a"] ** 2 + r["ic_a"] ** 2) * 2.0 / 3.0)
               for r in rows)
    psi, pp = p["flux_wb"], p["pole_pairs"]
    # no field weakening: the back-EMF alone reaches the voltage limit
    # (0.95 of Vdc / sqrt(3)) at the base speed
    base = 0.95 * vdc / math.sqrt(3.0) / psi / pp * 60.0 / (2.0 * math.pi)
    print("field weakening: %.0f rpm held (true, %.0f V bus), id %.3f A (limit -%.2f A), "
          "peak |i| %.3f A (limit %.2f A); base speed without it %.0f rpm: x%.2f" % (
              speed, vdc, idm, p["fw_id_max_a"], peak, p["current_limit_a"], base, speed / base))
    ok = rc == 0 and speed >= 1.5 * base and peak <= 1.05 * p["current_limit_a"]
    return 0 if ok else 1


def main(argv):
    if len(argv) == 5 and argv[1] == "angle":
        return cmd_angle(argv[2], argv[3], argv[4])
    if len(argv) == 4 and argv[1] == "mtpa":
        return cmd_mtpa(argv[2], argv[3])
    if len(argv) == 4 and argv[1] == "fw_range":
        return cmd_fw_range(argv[2], argv[3])
    sys.stderr.write(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
