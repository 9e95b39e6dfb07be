#!/usr/bin/env python3
"""Scope round trip on the host: capture in focsim -> dump -> plot.

    scope_roundtrip.py FOCSIM SCOPE_PLOT SRC_DIR WORK_DIR

focsim runs scope_step.scn with the monitor script scope_step.mon and
writes the monitor's output and a CSV of every PWM period.  The script
makes two captures: the start-up (state, estimated speed, d current
reference; immediate trigger) and a speed step (four channels, triggered on
the estimated speed).  Checks:
  - both dumps are complete and scope_plot.py turns each into a well-formed
    SVG naming every channel (the state channel as labelled state bands); a
    corrupted dump is refused, and so is a malformed monitor script;
  - the trigger frame is where the rule puts it, found independently on the
    CSV: frames are taken every `decim` periods from the arm period on, and
    the first frame with `pre` frames before it whose trigger variable
    crosses the level (previous < level <= this one) is the trigger;
  - every dumped sample equals focsim's CSV value at the same period within
    one LSB of the channel's scale (plus half the CSV's printed resolution,
    which for vq_v is coarser than one LSB); the state equals the CSV's
    state name.  Channels written by the fast step are compared with the
    CSV row of the same period; those the slow step writes (id_ref, iq_ref,
    state), with the previous row: the slow step runs after the fast step
    (and the capture) in the same period, so the capture sees the value of
    the previous period's end, which is what that row shows.
Exit status 0 when all checks pass.
"""
import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

ARM_TIMES_S = [0.0, 0.45]  # scope_step.mon, one per capture
CSV_COLUMN = {  # channel -> (CSV column, row offset: 0 same period, -1 previous)
    "speed_est": ("speed_est_rpm", 0),
    "theta_est": ("theta_est_deg", 0),
    "vq": ("vq_v", 0),
    "iq_ref": ("iq_ref_a", -1),
    "id_ref": ("id_ref_a", -1),
    "state": ("state", -1),
}
# foc_state_name() order (foc_state_t)
STATE_NAMES = ["IDLE", "CALIB", "ALIGN", "OPENLOOP", "RUN", "STOP", "BRAKE", "FAULT", "CATCH",
               "COMMISSION"]

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


def read_dumps(path):
    """Every dump: (header dict, channels [(name, unit, fs, unsigned)],
    rows [(k, [counts])], end-line dict)."""
    dumps, header, chans, rows = [], None, [], []
    with open(path, newline="") as f:
        text = f.read()
    check("\r\n" in text and "\n" not in text.replace("\r\n", ""),
          "monitor output uses CR LF line ends")
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
            dumps.append((header, chans, rows, dict(x.split("=", 1) for x in w[2:])))
            header = None
    return dumps


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
    for name in os.listdir(work):
        os.remove(os.path.join(work, name))

    r = run([focsim, "--scenario", os.path.join(src, "scope_step.scn"),
             "--monitor", os.path.join(src, "scope_step.mon"),
             "--monitor-out", out, "--csv", csv])
    if not check(r.returncode == 0, "focsim exit status %d" % r.returncode):
        return 1

    dumps = read_dumps(out)
    if not check(len(dumps) == 2, "two dumps (%d)" % len(dumps)):
        return 1
    cols = read_csv(csv)
    t = [float(x) for x in cols["t_s"]]
    for index, (arm_time, dump) in enumerate(zip(ARM_TIMES_S, dumps)):
        check_plot(scope_plot, out, index, dump, os.path.join(work, "scope_%d.svg" % index))
        check_samples(dump, arm_time, cols, t)
    check_corrupt_refused(scope_plot, out, work)
    check_bad_script_refused(focsim, src, work)
    print("%d check(s) failed" % len(failures) if failures else "all checks passed")
    return 1 if failures else 0


def check_plot(scope_plot, out, index, dump, svg):
    """scope_plot.py draws dump number `index`: every channel named, one line
    per channel (the state as bands instead)."""
    header, chans, rows, end = dump
    r = run([sys.executable, scope_plot, out, "--index", str(index), "-o", svg])
    check(r.returncode == 0, "scope_plot.py exit status %d" % r.returncode)
    if not check(os.path.exists(svg), "SVG %s written" % svg):
        return
    root = ET.parse(svg).getroot()
    texts = [(e.text or "") for e in root.iter() if e.tag.endswith("text")]
    lines = [c for c in chans if c[0] != "state"]
    for name, unit, _, _ in lines:
        check(any(name in x for x in texts), "SVG %d names channel %s" % (index, name))
        check(unit in texts, "SVG %d shows unit %s" % (index, unit))
    paths = [e for e in root.iter() if e.tag.endswith("path")]
    check(len(paths) == len(lines), "SVG %d: one line per channel (%d)" % (index, len(paths)))
    if any(c[0] == "state" for c in chans):
        for state in ("CALIB", "ALIGN", "OPENLOOP", "RUN"):
            check(state in texts, "SVG %d: state band %s" % (index, state))


def check_samples(dump, arm_time, cols, t):
    """Structure, trigger position and every sample against the CSV."""
    header, chans, rows, end = dump
    frames, pre, decim = int(header["frames"]), int(header["pre"]), int(header["decim"])
    check(header["state"] == "DONE", "capture done")
    check(len(rows) == frames and int(end["frames"]) == frames, "frame count")
    check([k for k, _ in rows] == list(range(-pre, frames - pre)), "frame indices")
    check(sum(v & 0xFFFF for _, vals in rows for v in vals) % 65536 == int(end["sum"]),
          "checksum")

    # the trigger, found on the CSV
    ts = float(header["dt_s"]) / decim
    check(all(abs(t[i] - i * ts) < 2e-6 for i in range(len(t))), "CSV has every period")
    k_arm = next(i for i, ti in enumerate(t) if ti >= arm_time - 1e-9)
    if header["trigger"] == "immediate":
        trigger_period = k_arm + pre * decim
    else:
        c = [ch[0] for ch in chans].index(header["trigger"])
        col, _ = CSV_COLUMN[header["trigger"]]
        fs = chans[c][2]
        level = int(header["level"])
        counts = lambda i: round(float(cols[col][i]) * 32768.0 / fs)
        j = max(pre, 1)
        while not (counts(k_arm + (j - 1) * decim) < level <= counts(k_arm + j * decim)):
            j += 1
        trigger_period = k_arm + j * decim
        check(rows[pre][1][c] >= level and rows[pre - 1][1][c] < level,
              "trigger frame crosses")
    print("capture %s: arm period %d, trigger period %d (t = %.4f s)"
          % ("/".join(ch[0] for ch in chans), k_arm, trigger_period, trigger_period * ts))

    # every sample against the CSV
    worst = {}
    for k, vals in rows:
        period = trigger_period + k * decim
        for c, (name, unit, fs, _) in enumerate(chans):
            col, offset = CSV_COLUMN[name]
            row = period + offset
            if name == "state":
                want = cols[col][row] if row >= 0 else "IDLE"  # foc_init's state
                if not check(STATE_NAMES[vals[c]] == want, "state at period %d: dump %s, CSV %s"
                             % (period, STATE_NAMES[vals[c]], want)):
                    return
                continue
            if row < 0:
                continue
            csv_text = cols[col][row]
            lsb = fs / 32768.0
            tol = lsb + 0.5 * 10.0 ** -decimals(csv_text) + 1e-12
            diff = vals[c] * lsb - float(csv_text)
            if unit == "deg":
                diff = math.remainder(diff, 360.0)
            worst[name] = max(worst.get(name, 0.0), abs(diff) / lsb)
            if not check(abs(diff) <= tol, "%s at period %d: dump %g, CSV %s"
                         % (name, period, vals[c] * lsb, csv_text)):
                return
    for name, w in worst.items():
        print("  %-10s largest |dump - CSV| = %.3f LSB" % (name, w))
    print("  %d frames x %d channels compared" % (len(rows), len(chans)))


def check_corrupt_refused(scope_plot, out, work):
    """One value of the last dump changed: the checksum catches it."""
    bad = os.path.join(work, "scope_step_corrupt.out")
    with open(out, newline="") as f:
        text = f.read()
    k0 = text.rindex("\r\n0 ") + 2  # the last dump's trigger frame
    line_end = text.index("\r\n", k0)
    fields = text[k0:line_end].split(" ")
    fields[1] = str(int(fields[1]) + 1)
    with open(bad, "w", newline="") as f:
        f.write(text[:k0] + " ".join(fields) + text[line_end:])
    r = run([sys.executable, scope_plot, bad, "-o", os.path.join(work, "corrupt.svg")],
            quiet=True)
    check(r.returncode == 1 and "checksum" in r.stderr, "corrupted dump refused")


def check_bad_script_refused(focsim, src, work):
    bad = os.path.join(work, "bad.mon")
    with open(bad, "w") as f:
        f.write("0.1 status\n# fine so far\n0.05 status\n")
    r = run([focsim, "--scenario", os.path.join(src, "scope_step.scn"), "--monitor", bad],
            quiet=True)
    check(r.returncode == 1 and "bad.mon:3:" in r.stderr, "bad script refused: %s" % r.stderr)


if __name__ == "__main__":
    sys.exit(main())
