#!/usr/bin/python3
"""Issue 16's swing looked for among deliberate modelling errors (pil.py
run --diag, NOT RM0008; docs/pil.md, "The oscillation of issue 16: cause").

    diag16.py [--old-elf E] [--old-layout L] [NAME ...]

For each --diag NAME (default: "none" and every one of machine.DIAG_ERRORS)
runs tests/pil/run1500.scn on the image of ef7908a (full CPU cost and
--cpu-scale 0.3, --jdr-order sequence) and on the present image, and
prints one markdown row each: state at the end, plant speed in RUN from
0.8 s to 1.2 s (min .. max, mean), overruns."""

import argparse
import csv
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import machine  # noqa: E402


def run(elf, layout, diag, extra, csvp):
    cmd = [sys.executable, os.path.join(HERE, "pil.py"), "run", "--elf", elf, "--layout", layout,
           "--scenario", "tests/pil/run1500.scn", "--csv", csvp] + extra
    if diag != "none":
        cmd += ["--diag", diag]
    out = subprocess.run(cmd, capture_output=True, text=True)
    kv = dict(l.split("=", 1) for l in out.stdout.splitlines() if "=" in l)
    rows = []
    with open(csvp) as fh:
        for r in csv.DictReader(fh):
            if 0.8 <= float(r["t_s"]) < 1.2 and r["state"] == "RUN":
                rows.append(float(r["speed_rpm"]))
    if rows:
        sp = "%.0f .. %.0f (%.1f)" % (min(rows), max(rows), sum(rows) / len(rows))
    else:
        sp = "-"
    state = kv.get("pil_final_state", "?")
    fault = kv.get("pil_first_fault", "?")
    st = state if fault == "NONE" else "%s/%s" % (state, fault)
    if kv.get("pil_halted", "no") != "no":
        st += " (%s)" % kv["pil_halted"]
    return "%s %s, ovr %s" % (st, sp, kv.get("image_overruns", "?"))


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--old-elf", default="/work/wt/old/build/stm32/foc_stm32f10x.elf")
    p.add_argument("--old-layout", default="build/pil/ctrl_layout_old.o")
    p.add_argument("--no-present", action="store_true")
    p.add_argument("names", nargs="*")
    a = p.parse_args()
    names = a.names or ["none"] + sorted(machine.DIAG_ERRORS)
    os.makedirs("build/pil/diag16", exist_ok=True)
    print("| --diag | ef7908a, full CPU cost | ef7908a, --cpu-scale 0.3 | present image |")
    print("|---|---|---|---|")
    for n in names:
        c = [run(a.old_elf, a.old_layout, n, ["--jdr-order", "sequence"],
                 "build/pil/diag16/%s_old.csv" % n),
             run(a.old_elf, a.old_layout, n, ["--jdr-order", "sequence", "--cpu-scale", "0.3"],
                 "build/pil/diag16/%s_old03.csv" % n)]
        c.append("" if a.no_present else
                 run("build/stm32/foc_stm32f10x.elf", "build/pil/ctrl_layout.o", n, [],
                     "build/pil/diag16/%s_new.csv" % n))
        print("| %s | %s |" % (n, " | ".join(c)), flush=True)


if __name__ == "__main__":
    main()
