#!/usr/bin/env python3
"""The torture campaign of issue 10 (docs/safety.md): runs the per-motor
torture executables (tests/torture/torture.c) and prints the oracle's table.

  torture.py --bin build/host/torture --seed S --runs M [--jobs J]
      runs seeds S .. S+M-1; seed N runs on motor MOTORS[N % len(MOTORS)]
      (the seed decides everything else), so one seed reproduces one run:
      make torture TORTURE_SEED=N TORTURE_RUNS=1
      --plant averaged: the averaged bridge model instead of the realistic
      plant (the same runs otherwise), for comparison.
      Exit status 1 if any run violated an invariant.
  torture.py --bin build/host/torture --regress tests/torture/regress
      the named findings: each .scn names its motor (#! motor X) and its
      expectations; exit status 1 if any fails.
"""
import argparse
import collections
import os
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

# Order matters: seed N runs on MOTORS[N % 6].
MOTORS = ["hurst075", "shinano_la052", "drone_12pp_24v", "servo_8pp_48v",
          "ipm_320v", "fan_highj"]
KINDS = ["current", "transit", "nofollow", "thermal", "overspeed", "bus_ov",
         "false_trip"]


def parse_line(line):
    """'seed=3 motor=x ... violations=a,b peak_ratio=1.2 ...' -> dict."""
    out = {}
    for tok in line.split():
        if "=" in tok:
            k, v = tok.split("=", 1)
            out[k] = v
    return out


def run_seed(bindir, seed, plant):
    motor = MOTORS[seed % len(MOTORS)]
    exe = os.path.join(bindir, "torture_" + motor)
    t0 = time.time()
    p = subprocess.run([exe, "--seed", str(seed), "--plant", plant], capture_output=True,
                       text=True)
    lines = p.stdout.splitlines()
    res = parse_line(lines[0]) if lines and p.returncode == 0 else {}
    res["details"] = lines[1:]
    res["rc"] = p.returncode
    res["stderr"] = p.stderr.strip()
    res["seed"] = seed
    res["motor"] = motor
    res["cpu_s"] = time.time() - t0
    return res


def campaign(args):
    seeds = list(range(args.seed, args.seed + args.runs))
    t0 = time.time()
    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as ex:
        results = list(ex.map(lambda s: run_seed(args.bin, s, args.plant), seeds))
    wall = time.time() - t0
    by_kind = collections.OrderedDict((k, []) for k in KINDS)
    crashed = [r for r in results if r["rc"] != 0 or "violations" not in r]
    per_motor = collections.Counter()
    bad_motor = collections.Counter()
    worst_peak = (0.0, None)
    worst_det = (0.0, None)
    detections = 0
    for r in results:
        per_motor[r["motor"]] += 1
        if "violations" not in r:
            continue
        v = r["violations"]
        kinds = [] if v == "none" else v.split(",")
        if kinds:
            bad_motor[r["motor"]] += 1
        for k in kinds:
            by_kind.setdefault(k, []).append(r)
        pk = float(r.get("peak_ratio", 0))
        if pk > worst_peak[0]:
            worst_peak = (pk, r)
        dt = float(r.get("det_worst_s", 0))
        detections += int(r.get("detections", 0))
        if dt > worst_det[0]:
            worst_det = (dt, r)
    failing = [r for r in results if r.get("violations", "none") != "none"]

    print("torture: seeds %d..%d, %d runs, %s plant, %.1f s wall (%d jobs)" %
          (seeds[0], seeds[-1], len(results), args.plant, wall, args.jobs))
    print()
    print("| motor | runs | runs with a violation |")
    print("|---|---:|---:|")
    for m in MOTORS:
        if per_motor[m]:
            print("| %s | %d | %d |" % (m, per_motor[m], bad_motor[m]))
    print()
    print("| invariant | runs violating | seeds (first 3) |")
    print("|---|---:|---|")
    for k, rs in by_kind.items():
        print("| %s | %d | %s |" % (k, len(rs), " ".join(str(r["seed"]) for r in rs[:3])))
    print()
    print("runs: %d, clean: %d, with a violation: %d, crashed: %d" %
          (len(results), len(results) - len(failing) - len(crashed), len(failing),
           len(crashed)))
    if worst_peak[1]:
        r = worst_peak[1]
        print("worst peak phase current: %.3f x CURRENT_LIMIT_A (seed %d, %s, %s)" %
              (worst_peak[0], r["seed"], r["motor"], r.get("est")))
    print("not-following rotors detected by a fault: %d; worst detection time %.3f s%s" %
          (detections, worst_det[0],
           " (seed %d, %s)" % (worst_det[1]["seed"], worst_det[1]["motor"])
           if worst_det[1] else ""))
    print("false trips: %d runs" % len(by_kind["false_trip"]))
    if failing and not args.quiet:
        print()
        print("failing runs (reproduce each with the command shown):")
        for r in failing:
            print("  seed %d (%s, %s, stop %s): %s; end %s %s" %
                  (r["seed"], r["motor"], r.get("est"), r.get("stop"), r["violations"],
                   r.get("end_state"), r.get("fault")))
            for d in r["details"]:
                print("    " + d.strip())
            extra = "" if args.plant == "realistic" else " --plant " + args.plant
            print("    make torture TORTURE_SEED=%d TORTURE_RUNS=1%s   # or: %s --seed %d%s "
                  "--dump seed%d.scn" % (r["seed"],
                                         extra.replace(" --plant ", " TORTURE_PLANT="),
                                         os.path.join(args.bin, "torture_" + r["motor"]),
                                         r["seed"], extra, r["seed"]))
    for r in crashed:
        print("CRASH seed %d (%s): rc %d %s" % (r["seed"], r["motor"], r["rc"],
                                                 r["stderr"][:300]))
    if args.machinery_only:
        ok = not crashed and len(results) == args.runs
        print("torture: machinery %s" % ("ok" if ok else "FAILED"))
        return 0 if ok else 1
    return 1 if failing or crashed else 0


def regress(args):
    files = sorted(f for f in os.listdir(args.regress) if f.endswith(".scn"))
    fails = 0
    for f in files:
        path = os.path.join(args.regress, f)
        motor = None
        with open(path) as fh:
            for line in fh:
                if line.startswith("#! motor"):
                    motor = line.split()[2]
        if motor is None:
            print("FAIL %s: no '#! motor' line" % path)
            fails += 1
            continue
        exe = os.path.join(args.bin, "torture_" + motor)
        p = subprocess.run([exe, "--scenario", path], capture_output=True, text=True)
        sys.stdout.write(p.stdout)
        if p.returncode != 0:
            fails += 1
            if p.stderr:
                sys.stdout.write(p.stderr)
    print("torture-regress: %d of %d findings pass" % (len(files) - fails, len(files)))
    return 1 if fails else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", required=True, help="folder of the torture_<motor> executables")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--runs", type=int, default=200)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--plant", choices=["realistic", "averaged"], default="realistic",
                    help="the generated runs' plant (default: realistic, issue 13)")
    ap.add_argument("--regress", help="folder of the regression scenarios")
    ap.add_argument("--quiet", action="store_true", help="no per-run details")
    ap.add_argument("--machinery-only", action="store_true",
                    help="exit 0 when every run completed, violations or not (ctest)")
    args = ap.parse_args()
    if args.regress:
        return regress(args)
    return campaign(args)


if __name__ == "__main__":
    sys.exit(main())
