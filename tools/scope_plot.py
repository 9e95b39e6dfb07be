#!/usr/bin/env python3
"""Plot a scope dump of the FOC monitor as an SVG like focsim's plots.

    python3 tools/scope_plot.py DUMP [-o OUT.svg] [--index N] [--csv OUT.csv]

DUMP is the monitor's output (a UART log or focsim --monitor-out): the
`scope dump` reply is found in it (the last one, or number N from 0 with
--index), checked (frame count and sum) and converted to physical units
with each channel's full scale.  The SVG has focsim's look (svgplot.c):
stacked panels sharing the time axis, one panel per unit, round ticks, a
legend; the time axis is relative to the trigger frame (t = 0, dashed line).
A `state` channel is drawn as the shaded state bands of focsim's plots.
--csv also writes the converted samples (t_s, then one column per channel).

Standard library only.  Exit status 0, or 1 with a message on stderr.
"""
import argparse
import math
import sys

# foc_state_name() order (include/foc/controller.h, foc_state_t).
STATE_NAMES = ["IDLE", "CALIB", "ALIGN", "OPENLOOP", "RUN", "STOP", "BRAKE", "FAULT", "CATCH",
               "COMMISSION"]


class DumpError(Exception):
    pass


# ------------------------------------------------------------- parsing --

def _keyvals(words):
    out = {}
    for w in words:
        if "=" in w:
            k, v = w.split("=", 1)
            out[k] = v
    return out


def parse_dumps(text):
    """All complete dumps in a monitor log, in order.  Each is a dict with
    the header fields, 'chans' [(name, unit, full_scale, is_unsigned)] and
    'rows' [(k, [counts...])]."""
    dumps = []
    cur = None
    for lineno, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        words = line.split()
        if not words:
            continue
        if words[0] == "scope" and len(words) > 1 and words[1].startswith("state="):
            cur = {"header": _keyvals(words[1:]), "chans": [], "rows": [], "line": lineno}
            continue
        if cur is None:
            continue
        if words[0] == "chan" and len(words) == 6:
            unit = "" if words[3] == "-" else words[3]
            cur["chans"].append((words[2], unit, float(words[4]), words[5] == "u"))
        elif words[0] == "ok" and len(words) > 1 and words[1] == "dump":
            cur["end"] = _keyvals(words[2:])
            dumps.append(cur)
            cur = None
        elif words[0] in ("ok", "err"):
            cur = None  # aborted or interrupted: not a complete dump
        else:
            try:
                nums = [int(w) for w in words]
            except ValueError:
                raise DumpError("line %d: not a data line: %r" % (lineno, line))
            cur["rows"].append((nums[0], nums[1:]))
    return dumps


def check_dump(d):
    """Consistency checks; returns (t, columns) in seconds and units."""
    h = d["header"]
    try:
        frames = int(h["frames"])
        nch = int(h["channels"])
        dt = float(h["dt_s"])
        pre = int(h["pre"])
    except (KeyError, ValueError):
        raise DumpError("dump at line %d: incomplete header" % d["line"])
    if len(d["chans"]) != nch:
        raise DumpError("dump: %d channel lines, header says %d" % (len(d["chans"]), nch))
    rows = d["rows"]
    if len(rows) != frames or int(d["end"].get("frames", -1)) != frames:
        raise DumpError("dump: %d data lines, header says %d" % (len(rows), frames))
    total = 0
    for i, (k, vals) in enumerate(rows):
        if k != i - pre or len(vals) != nch:
            raise DumpError("dump: data line %d malformed (k=%d, %d values)" % (i, k, len(vals)))
        total += sum(v & 0xFFFF for v in vals)
    if "sum" in d["end"] and int(d["end"]["sum"]) != total % 65536:
        raise DumpError("dump: checksum mismatch (%d, data gives %d)"
                        % (int(d["end"]["sum"]), total % 65536))
    t = [k * dt for k, _ in rows]
    cols = []
    for c, (name, unit, fs, _uns) in enumerate(d["chans"]):
        cols.append([vals[c] * fs / 32768.0 for _, vals in rows])
    return t, cols


# ------------------------------------------------- SVG (as svgplot.c) --

WIDTH = 1200
PLOT_X0 = 84
UNIT_X = 24
LEGEND_WIDTH = 190
TITLE_HEIGHT = 40
BAND_LEGEND_HEIGHT = 22
BAND_LANE_HEIGHT = 18
BAND_LANE_GAP = 6
PANEL_TITLE_HEIGHT = 24
PANEL_MIN_HEIGHT = 170
PANEL_GAP = 14
LEGEND_ROW = 18
TIME_AXIS_HEIGHT = 48
Y_TICKS = 8
T_TICKS = 12
PLOT_X1 = WIDTH - LEGEND_WIDTH
PLOT_WIDTH = PLOT_X1 - PLOT_X0
Y_MARGIN = 0.06
CHAR_WIDTH = 7.0
SERIES_PALETTE = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e",
                  "#9467bd", "#8c564b", "#e377c2", "#17becf"]
BAND_PALETTE = ["#dce9fb", "#dcf1d8", "#feedc9", "#eadcf5",
                "#e6e6e6", "#d3efee", "#f3e3d0"]
FAULT_BAND_COLOR = "#f7c4c4"


class Axis:
    def __init__(self, v0, v1, px0, px1):
        self.v0, self.v1, self.px0, self.px1 = v0, v1, px0, px1

    def px(self, v):
        return self.px0 + (v - self.v0) * (self.px1 - self.px0) / (self.v1 - self.v0)


def esc(s):
    out = []
    for ch in s or "":
        o = ord(ch)
        out.append({"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;",
                    "'": "&apos;"}.get(ch, "?" if o < 0x20 and ch != "\t" else ch))
    return "".join(out)


def text_el(x, y, attrs, s):
    return '<text x="%.1f" y="%.1f" %s>%s</text>\n' % (x, y, attrs, esc(s))


def tick_range(a, step):
    return math.ceil(a.v0 / step - 1e-9), math.floor(a.v1 / step + 1e-9)


def nice_step(a, max_ticks):
    decade = 10.0 ** math.floor(math.log10((a.v1 - a.v0) / max_ticks))
    while True:
        for m in (1.0, 2.0, 5.0):
            k0, k1 = tick_range(a, m * decade)
            if k1 - k0 + 1 <= max_ticks:
                return m * decade
        decade *= 10.0


def format_tick(v, step):
    if abs(v) < step * 1e-6:
        v = 0.0
    digits = math.ceil(-math.log10(step) - 1e-9)
    if digits > 6 or abs(v) >= 1e7:
        return "%g" % v
    return "%.*f" % (max(int(digits), 0), v)


def is_fault(label):
    return "fault" in (label or "").lower()


def series_path(t, y, tx, ya, color):
    """Min/max of each pixel column, NaN breaks the line (svgplot.c)."""
    parts = []
    pen = [0]

    def lift():
        if pen[0] == 1:
            parts.append(" h0")
        pen[0] = 0

    def point(x, yy):
        parts.append("%s%.1f,%.1f" % (" M" if pen[0] == 0 else " L", x, yy))
        pen[0] += 1

    def flush(col):
        if col["gap_before"] or not col["finite"]:
            lift()
        if col["finite"]:
            a, b = sorted((col["imin"], col["imax"]))
            point(tx.px(t[a]), ya.px(y[a]))
            if b != a:
                point(tx.px(t[b]), ya.px(y[b]))
        if col["gap_after"]:
            lift()

    def new_col():
        return {"imin": 0, "imax": 0, "finite": False, "gap_before": False, "gap_after": False}

    col = new_col()
    col_index = -1
    for i in range(len(t)):
        ok = math.isfinite(t[i]) and math.isfinite(y[i])
        here = col_index
        if math.isfinite(t[i]):
            here = int(math.floor(tx.px(t[i]) - PLOT_X0))
            here = 0 if here < 0 else PLOT_WIDTH - 1 if here >= PLOT_WIDTH else here
        if here != col_index and i > 0:
            flush(col)
            col = new_col()
        col_index = here
        if not ok:
            col["gap_before"] |= not col["finite"]
            col["gap_after"] = col["finite"]
        elif not col["finite"]:
            col["imin"] = col["imax"] = i
            col["finite"] = True
        else:
            if y[i] < y[col["imin"]]:
                col["imin"] = i
            if y[i] > y[col["imax"]]:
                col["imax"] = i
            col["gap_after"] = False
    if t:
        flush(col)
    lift()
    return ('<path class="series" fill="none" stroke-width="1.4" '
            'stroke-linejoin="round" stroke-linecap="round" stroke="%s" d="%s"/>\n'
            % (esc(color), "".join(parts)))


def panel_y_axis(panel, top, bottom):
    vals = [v for _, _, y in panel["series"] for v in y if math.isfinite(v)]
    if not vals:
        lo, hi = -1.0, 1.0
    else:
        lo, hi = min(vals), max(vals)
        if hi - lo <= 1e-9 * max(abs(lo), abs(hi)):
            pad = 0.1 * abs(lo) if lo != 0.0 else 1.0
            lo, hi = lo - pad, hi + pad
    margin = Y_MARGIN * (hi - lo)
    a = Axis(lo - margin, hi + margin, bottom, top)
    return a, nice_step(a, Y_TICKS)


def band_colors(bands):
    colors, first, seen = [], [], {}
    for _, _, label in bands:
        first.append(label not in seen)
        if label not in seen:
            seen[label] = FAULT_BAND_COLOR if is_fault(label) else \
                BAND_PALETTE[sum(1 for l in seen if not is_fault(l)) % len(BAND_PALETTE)]
        colors.append(seen[label])
    return colors, first


def put_bands(out, tx, bands, colors, top, height, lane):
    min_width = 3.0 if lane else 2.0
    for narrow_pass in (False, True):
        for (t0, t1, label), color in zip(bands, colors):
            x0 = tx.px(max(t0, tx.v0))
            x1 = tx.px(min(t1, tx.v1))
            if not (x1 >= x0) or ((x1 - x0 < min_width) != narrow_pass):
                continue
            if narrow_pass:
                x0 = (x0 + x1 - min_width) / 2
                x1 = x0 + min_width
            out.append('<rect class="band" x="%.1f" y="%.1f" width="%.1f" height="%.1f" '
                       'fill="%s" fill-opacity="%s"/>\n'
                       % (x0, top, x1 - x0, height, color,
                          "1" if lane or narrow_pass else "0.6"))
            if lane and x1 - x0 >= CHAR_WIDTH * len(label) + 6:
                out.append(text_el((x0 + x1) / 2, top + height / 2 + 4,
                                   'class="band-label" font-size="11" fill="#333" '
                                   'text-anchor="middle"', label))


def panel_height(panel):
    return max(PANEL_MIN_HEIGHT, 12.0 + LEGEND_ROW * len(panel["series"]))


def put_panel(out, panel, t, tx, t_step, top, height, bands, colors):
    bottom = top + height
    ya, y_step = panel_y_axis(panel, top, bottom)
    put_bands(out, tx, bands, colors, top, height, False)
    out.append('<g stroke="#e2e2e2" stroke-width="1">\n')
    tk0, tk1 = tick_range(tx, t_step)
    yk0, yk1 = tick_range(ya, y_step)
    for k in range(tk0, tk1 + 1):
        x = tx.px(k * t_step)
        out.append('<line x1="%.1f" y1="%.1f" x2="%.1f" y2="%.1f"/>\n' % (x, top, x, bottom))
    for k in range(yk0, yk1 + 1):
        y = ya.px(k * y_step)
        out.append('<line x1="%d" y1="%.1f" x2="%d" y2="%.1f"/>\n' % (PLOT_X0, y, PLOT_X1, y))
    out.append("</g>\n")
    if ya.v0 < 0.0 < ya.v1:
        y0 = ya.px(0.0)
        out.append('<line x1="%d" y1="%.1f" x2="%d" y2="%.1f" stroke="#9a9a9a" '
                   'stroke-width="1"/>\n' % (PLOT_X0, y0, PLOT_X1, y0))
    if tx.v0 <= 0.0 <= tx.v1:  # the trigger instant
        x = tx.px(0.0)
        out.append('<line class="trigger" x1="%.1f" y1="%.1f" x2="%.1f" y2="%.1f" '
                   'stroke="#555" stroke-width="1" stroke-dasharray="4,3"/>\n'
                   % (x, top, x, bottom))
    for s, (label, color, y) in enumerate(panel["series"]):
        out.append(series_path(t, y, tx, ya, color))
    out.append('<rect x="%d" y="%.1f" width="%d" height="%.1f" fill="none" '
               'stroke="#808080"/>\n' % (PLOT_X0, top, PLOT_WIDTH, height))
    for k in range(yk0, yk1 + 1):
        v = k * y_step
        out.append(text_el(PLOT_X0 - 6, ya.px(v) + 4,
                           'class="ytick" font-size="11" fill="#444" text-anchor="end"',
                           format_tick(v, y_step)))
    if panel["unit"]:
        mid = top + height / 2
        out.append('<text class="unit" x="%d" y="%.1f" font-size="12" fill="#333" '
                   'text-anchor="middle" transform="rotate(-90 %d %.1f)">%s</text>\n'
                   % (UNIT_X, mid, UNIT_X, mid, esc(panel["unit"])))
    out.append(text_el(PLOT_X0, top - 7, 'class="panel-title" font-size="13" '
                       'font-weight="bold" fill="#222"', panel["title"]))
    for s, (label, color, _) in enumerate(panel["series"]):
        y = top + 14 + LEGEND_ROW * s
        out.append('<line x1="%d" y1="%.1f" x2="%d" y2="%.1f" stroke-width="3" '
                   'stroke="%s"/>\n' % (PLOT_X1 + 12, y - 4, PLOT_X1 + 34, y - 4, esc(color)))
        out.append(text_el(PLOT_X1 + 40, y, 'class="legend" font-size="12" fill="#222"', label))


def svg_document(title, t, panels, bands):
    colors, first = band_colors(bands)
    tx = Axis(0.0, 1.0, PLOT_X0, PLOT_X1)
    if t and math.isfinite(t[0]):
        tx.v0 = t[0]
        tx.v1 = t[-1] if len(t) > 1 and math.isfinite(t[-1]) and t[-1] > t[0] else t[0] + 1.0
    t_step = nice_step(tx, T_TICKS)
    t_round = math.ceil(tx.v1 / t_step) * t_step
    if t_round - tx.v1 < 0.01 * (tx.v1 - tx.v0):
        tx.v1 = t_round
    bands_height = BAND_LEGEND_HEIGHT + BAND_LANE_HEIGHT + BAND_LANE_GAP if bands else 0
    height = TITLE_HEIGHT + bands_height
    for p in panels:
        height += PANEL_TITLE_HEIGHT + panel_height(p) + PANEL_GAP
    height += TIME_AXIS_HEIGHT - PANEL_GAP

    out = ['<?xml version="1.0" encoding="UTF-8"?>\n'
           '<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%.0f" '
           'viewBox="0 0 %d %.0f" font-family="DejaVu Sans, Arial, Helvetica, sans-serif">\n'
           % (WIDTH, height, WIDTH, height),
           "<title>%s</title>\n" % esc(title),
           '<rect width="%d" height="%.0f" fill="white"/>\n' % (WIDTH, height),
           text_el(PLOT_X0, 26, 'class="title" font-size="17" font-weight="bold" fill="#111"',
                   title)]
    y = TITLE_HEIGHT
    if bands:
        x = PLOT_X0
        for (t0, t1, label), color, is_first in zip(bands, colors, first):
            if not is_first:
                continue
            out.append('<rect x="%.1f" y="%.1f" width="16" height="11" fill="%s" '
                       'stroke="#999" stroke-width="0.5"/>\n' % (x, y + 6 - 10, color))
            out.append(text_el(x + 21, y + 6, 'class="band-legend" font-size="12" fill="#333"',
                               label))
            x += 21 + CHAR_WIDTH * len(label) + 16
        lane_top = y + BAND_LEGEND_HEIGHT
        put_bands(out, tx, bands, colors, lane_top, BAND_LANE_HEIGHT, True)
        out.append('<rect x="%d" y="%.1f" width="%d" height="%d" fill="none" '
                   'stroke="#808080"/>\n' % (PLOT_X0, lane_top, PLOT_WIDTH, BAND_LANE_HEIGHT))
        y += bands_height
    for p in panels:
        h = panel_height(p)
        y += PANEL_TITLE_HEIGHT
        put_panel(out, p, t, tx, t_step, y, h, bands, colors)
        y += h + PANEL_GAP
    y -= PANEL_GAP
    k0, k1 = tick_range(tx, t_step)
    for k in range(k0, k1 + 1):
        v = k * t_step
        out.append(text_el(tx.px(v), y + 15, 'class="ttick" font-size="11" fill="#444" '
                           'text-anchor="middle"', format_tick(v, t_step)))
    out.append(text_el((PLOT_X0 + PLOT_X1) / 2.0, y + 36, 'class="axis-label" font-size="12" '
                       'fill="#333" text-anchor="middle"', "time from trigger (s)"))
    out.append("</svg>\n")
    return "".join(out)


# ------------------------------------------------------------ the plot --

def state_bands(t, counts):
    bands = []
    for ti, c in zip(t, counts):
        label = STATE_NAMES[c] if 0 <= c < len(STATE_NAMES) else "state %d" % c
        if not bands or bands[-1][2] != label:
            bands.append([ti, ti, label])
        bands[-1][1] = ti
    return [tuple(b) for b in bands]


def build_plot(d, t, cols):
    """Panels (one per unit, in order of first appearance) and bands."""
    panels, by_unit, bands = [], {}, []
    chans = d["chans"]
    for c, (name, unit, fs, _) in enumerate(chans):
        if name == "state":
            bands = state_bands(t, [int(round(v)) for v in cols[c]])
            if len(chans) > 1:
                continue
        if unit not in by_unit:
            by_unit[unit] = {"title": "", "unit": unit, "series": []}
            panels.append(by_unit[unit])
        p = by_unit[unit]
        p["series"].append((name, SERIES_PALETTE[len(p["series"]) % len(SERIES_PALETTE)],
                            cols[c]))
    for p in panels:
        names = ", ".join(s[0] for s in p["series"])
        p["title"] = names + (" (%s)" % p["unit"] if p["unit"] else "")
    h = d["header"]
    if h.get("trigger", "immediate") == "immediate":
        trig = "immediate trigger"
    else:
        fs, unit = next(((c[2], c[1]) for c in chans if c[0] == h["trigger"]), (None, ""))
        level = h.get("level", "?")
        if fs is not None:
            level = "%g%s" % (int(level) * fs / 32768.0, " " + unit if unit else "")
        trig = "trigger %s %s %s" % (h["trigger"], h.get("edge", ""), level)
    title = "scope: %s, %s frames every %s s" % (trig, h["frames"], h["dt_s"])
    return title, panels, bands


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dump", help="monitor output holding a 'scope dump' reply")
    ap.add_argument("-o", "--output", help="SVG file (default: DUMP with .svg)")
    ap.add_argument("--index", type=int, default=-1, help="which dump (0 = first; default last)")
    ap.add_argument("--csv", help="also write the samples in physical units")
    args = ap.parse_args(argv)
    try:
        with open(args.dump, encoding="ascii", errors="replace") as f:
            dumps = parse_dumps(f.read())
        if not dumps:
            raise DumpError("%s: no complete scope dump" % args.dump)
        try:
            d = dumps[args.index]
        except IndexError:
            raise DumpError("%s: no dump number %d (%d found)" % (args.dump, args.index, len(dumps)))
        t, cols = check_dump(d)
        title, panels, bands = build_plot(d, t, cols)
        out = args.output or (args.dump.rsplit(".", 1)[0] + ".svg")
        with open(out, "w", encoding="utf-8") as f:
            f.write(svg_document(title, t, panels, bands))
        if args.csv:
            with open(args.csv, "w", encoding="ascii") as f:
                f.write(",".join(["t_s"] + ["%s_%s" % (c[0], c[1] or "1") for c in d["chans"]]) + "\n")
                for i, ti in enumerate(t):
                    f.write(",".join(["%.9g" % ti] + ["%.9g" % col[i] for col in cols]) + "\n")
    except (OSError, DumpError) as e:
        print("scope_plot: %s" % e, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
