#!/usr/bin/env python3
"""Scope round trip on the host: capture in focsim -> dump -> plot.

    scope_roundtrip.py FOCSIM SCOPE_PLOT SRC_DIR WORK_DIR

focsim runs scope_step.scn with the monitor script scope_step.mon (a
capture armed before a speed step, triggered on the estimated speed) and
writes the monitor's output and a CSV of every PWM period.  Checks:
  - the dump is complete and scope_plot.py turns it into a well-formed SVG
    naming every channel; a corrupted dump is refused;
  - the trigger frame is where the rule puts it, found independently on the
    CSV: frames are taken every `decim` periods from the arm period on, and
    the first frame with `pre` frames before it whose trigger variable
    crosses the level (previous < level <= this one) is the trigger;
  - every dumped sample equals focsim's CSV value at the same period within
    one LSB of the channel's scale (plus half the CSV's printed resolution,
    which for vq_v is coarser than one LSB).  Channels written by the fast
    step are compared with the CSV row of the same period; iq_ref, written by
    the slow step that runs after the fast step (and after the capture) in
    the same period, with the previous row, the last value the capture saw.
Exit status 0 when all checks pass.
"""
import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

ARM_TIME_S = 0.45  # scope_step.mon
CSV_COLUMN = {  # channel -> (CSV column, row offset: 0 same period, -1 previous)
    "speed_est": ("speed_est_rpm", 0),
    "theta_est": ("theta_est_deg", 0),
    "vq": ("vq_v", 0),
    "iq_ref": ("iq_ref_a", -1),
}

failures = []


def check(cond, msg):
    if not cond:
        failures.append(msg)
        print("FAIL: " + msg, file=sys.stderr)
    return cond


def run(cmd, quiet=False):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0 and not quiet:
        sys.stderr.write(r.stdout + r.stderr)
    return r


def read_dump(path):
    """Header dict, channels [(name, unit, fs, unsigned)], rows [(k, [counts])]."""
    header, chans, rows = None, [], []
    with open(path, newline="") as f:
        text = f.read()
    check("\r\n" in text, "monitor output uses CR LF line ends")
    for line in text.splitlines():
        w = line.split()
        if not w:
            continue
        if w[0] == "scope" and len(w) > 1 and w[1].startswith("state="):
            header = dict(x.split("=", 1) for x in w[1:])
            chans, rows = [], []
        elif header is not None and w[0] == "chan":
            chans.append((w[2], w[3], float(w[4]), w[5] == "u"))
        elif header is not None and (w[0].lstrip("-").isdigit()):
            rows.append((int(w[0]), [int(x) for x in w[1:]]))
        elif header is not None and w[:2] == ["ok", "dump"]:
            return header, chans, rows, dict(x.split("=", 1) for x in w[2:])
    raise SystemExit("no complete dump in " + path)


def read_csv(path):
    with open(path) as f:
        names = f.readline().strip().split(",")
        cols = {n: [] for n in names}
        for line in f:
            for n, v in zip(names, line.strip().split(",")):
                cols[n].append(v)
    return cols


def decimals(s):
    return len(s.split(".", 1)[1]) if "." in s else 0


def main():
    focsim, scope_plot, src, work = sys.argv[1:5]
    os.makedirs(work, exist_ok=True)
    out = os.path.join(work, "scope_step.out")
    csv = os.path.join(work, "scope_step.csv")
    svg = os.path.join(work, "scope_step.svg")
    for p in (out, csv, svg):
        if os.path.exists(p):
            os.remove(p)

    r = run([focsim, "--scenario", os.path.join(src, "scope_step.scn"),
             "--monitor", os.path.join(src, "scope_step.mon"),
             "--monitor-out", out, "--csv", csv])
    if not check(r.returncode == 0, "focsim exit status %d" % r.returncode):
        return 1

    # ---- dump -> plot
    r = run([sys.executable, scope_plot, out, "-o", svg])
    check(r.returncode == 0, "scope_plot.py exit status %d" % r.returncode)
    check(os.path.exists(svg), "SVG written")
    header, chans, rows, end = read_dump(out)
    if os.path.exists(svg):
        root = ET.parse(svg).getroot()
        texts = " ".join((e.text or "") for e in root.iter() if e.tag.endswith("text"))
        for name, unit, _, _ in chans:
            check(name in texts, "SVG names channel %s" % name)
            check(unit in texts, "SVG shows unit %s" % unit)
        paths = [e for e in root.iter() if e.tag.endswith("path")]
        check(len(paths) == len(chans), "one line per channel (%d)" % len(paths))

    bad = os.path.join(work, "scope_step_corrupt.out")
    with open(out, newline="") as f:
        text = f.read()
    k0 = text.index("\n0 ") + 1  # the trigger frame's line: change one value
    line_end = text.index("\r\n", k0)
    fields = text[k0:line_end].split(" ")
    fields[1] = str(int(fields[1]) + 1)
    with open(bad, "w", newline="") as f:
        f.write(text[:k0] + " ".join(fields) + text[line_end:])
    r = run([sys.executable, scope_plot, bad, "-o", os.path.join(work, "corrupt.svg")], quiet=True)
    check(r.returncode == 1 and "checksum" in r.stderr, "corrupted dump refused")

    # ---- the dump's structure
    frames, pre, decim = int(header["frames"]), int(header["pre"]), int(header["decim"])
    check(header["state"] == "DONE", "capture done")
    check([c[0] for c in chans] == ["speed_est", "theta_est", "iq_ref", "vq"], "channels")
    check(len(rows) == frames and int(end["frames"]) == frames, "frame count")
    check([k for k, _ in rows] == list(range(-pre, frames - pre)), "frame indices")
    check(sum(v & 0xFFFF for _, vals in rows for v in vals) % 65536 == int(end["sum"]),
          "checksum")

    # ---- the trigger, found on the CSV
    cols = read_csv(csv)
    t = [float(x) for x in cols["t_s"]]
    ts = float(header["dt_s"]) / decim
    check(all(abs(t[i] - i * ts) < 2e-6 for i in range(len(t))), "CSV has every period")
    k_arm = next(i for i, ti in enumerate(t) if ti >= ARM_TIME_S - 1e-9)
    fs_speed = chans[0][2]
    level = int(header["level"])
    counts = lambda i: round(float(cols["speed_est_rpm"][i]) * 32768.0 / fs_speed)
    j = max(pre, 1)
    while not (counts(k_arm + (j - 1) * decim) < level <= counts(k_arm + j * decim)):
        j += 1
    trigger_period = k_arm + j * decim
    check(rows[pre][1][0] >= level and rows[pre - 1][1][0] < level, "trigger frame crosses")
    print("arm period %d, trigger period %d (t = %.4f s), level %d counts"
          % (k_arm, trigger_period, trigger_period * ts, level))

    # ---- every sample against the CSV
    worst = {}
    for k, vals in rows:
        period = trigger_period + k * decim
        for c, (name, unit, fs, _) in enumerate(chans):
            col, offset = CSV_COLUMN[name]
            csv_text = cols[col][period + offset]
            lsb = fs / 32768.0
            tol = lsb + 0.5 * 10.0 ** -decimals(csv_text) + 1e-12
            diff = vals[c] * lsb - float(csv_text)
            if unit == "deg":
                diff = math.remainder(diff, 360.0)
            worst[name] = max(worst.get(name, 0.0), abs(diff) / lsb)
            if not check(abs(diff) <= tol, "%s at period %d: dump %g, CSV %s"
                         % (name, period, vals[c] * lsb, csv_text)):
                return 1
    for name, w in worst.items():
        print("%-10s largest |dump - CSV| = %.3f LSB" % (name, w))
    print("%d frames x %d channels compared" % (len(rows), len(chans)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
