#!/usr/bin/python3
"""Figures of a pil.py CSV over time windows (docs/pil.md, high modulation).

    csvstats.py FILE.csv T0:T1 [T0:T1 ...]

Per window: periods, unclean periods (the port's own count, column
fw_unclean, -1 if absent), overruns (the model's), plant speed mean /
min / max, current ripple -- standard deviation of the plant's true id
and iq, and RMS of id minus its reference --, and the RMS of the angle
error (estimate minus true, electrical)."""

import csv
import math
import sys


def stats(rows, t0, t1):
    w = [r for r in rows if t0 <= float(r["t_s"]) < t1 and r["state"] == "RUN"]
    if not w:
        return None
    f = lambda k: [float(r[k]) for r in w]
    def sd(v):
        m = sum(v) / len(v)
        return math.sqrt(sum((x - m) ** 2 for x in v) / len(v))
    sp, idt, iqt, idr = f("speed_rpm"), f("id_a"), f("iq_a"), f("id_ref_a")
    err = [((float(r["theta_est_deg"]) - float(r["theta_e_deg"]) + 180.0) % 360.0) - 180.0 for r in w]
    unc = [int(r.get("fw_unclean", -1)) for r in w]
    return dict(periods=len(w), unclean=(unc[-1] - unc[0]) if unc[0] >= 0 else -1,
                overruns=sum(int(r.get("overrun", 0)) for r in w),
                speed_mean=sum(sp) / len(sp), speed_min=min(sp), speed_max=max(sp),
                id_sd=sd(idt), iq_sd=sd(iqt),
                id_err_rms=math.sqrt(sum((a - b) ** 2 for a, b in zip(idt, idr)) / len(w)),
                angle_err_rms=math.sqrt(sum(e * e for e in err) / len(err)))


def main():
    if len(sys.argv) < 3:
        raise SystemExit(__doc__)
    rows = list(csv.DictReader(open(sys.argv[1])))
    for w in sys.argv[2:]:
        t0, t1 = (float(x) for x in w.split(":"))
        s = stats(rows, t0, t1)
        if s is None:
            print("%s: no RUN rows" % w)
            continue
        print("%s: " % w + " ".join("%s=%s" % (k, ("%.3f" % v) if isinstance(v, float) else v)
                                    for k, v in s.items()))


if __name__ == "__main__":
    main()
