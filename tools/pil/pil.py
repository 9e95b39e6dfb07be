#!/usr/bin/python3
"""Processor-in-the-loop run of the STM32 image (issue 16; docs/pil.md).

    pil.py run --elf build/stm32/foc_stm32f10x.elf --scenario FILE
               [--csv FILE] [--focsim build/shinano/focsim] [--cpu-scale K]
               [--flash-ws rm0008|zero] [--rcr-start count|overflow]
               [--cc4-trigger oc4|cc4event] [--jdr-order sequence|slot]
               [--adc-latency CLK] [--decimate N] [--monitor-log FILE]

Runs the unmodified image from its reset vector (machine.py) against the
project's motor model, drives it from a focsim scenario through its serial
monitor and its break input as an operator and the bench would, writes
focsim's CSV columns plus the interrupt timing, and prints key=value
figures, with focsim's on the same scenario when --focsim is given.

Needs Debian's python3-unicorn, python3-capstone, python3-pyelftools
(run with /usr/bin/python3) and `make pil` (the plant library and the
controller layout in build/pil).
"""

import argparse
import math
import os
import re
import struct
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import machine  # noqa: E402
from periph import TICK_HZ, IRQ_ADC1_2  # noqa: E402


def load_foc_monitor():
    """tools/foc-monitor as a module: its framing (COBS + CRC-16) and its
    command codes, so that the PIL speaks the monitor protocol exactly as
    the PC tool does."""
    import importlib.machinery
    import importlib.util
    path = os.path.join(HERE, "..", "foc-monitor")
    loader = importlib.machinery.SourceFileLoader("foc_monitor", path)
    spec = importlib.util.spec_from_loader("foc_monitor", loader)
    mod = importlib.util.module_from_spec(spec)
    loader.exec_module(mod)
    return mod


fm = load_foc_monitor()


def board_userparm(name):
    """A number from the board's userparms.h (the image's)."""
    path = os.path.join(HERE, "..", "..", "boards", "stm3210b_mckit", "userparms.h")
    with open(path) as fh:
        for line in fh:
            w = line.split()
            if len(w) >= 3 and w[0] == "#define" and w[1] == name:
                return float(w[2])
    raise SystemExit("userparms.h: no %s" % name)

EXC_ADC = 16 + IRQ_ADC1_2
STATES = ["IDLE", "CALIB", "ALIGN", "OPENLOOP", "RUN", "STOP", "BRAKE", "FAULT", "CATCH",
               "COMMISSION"]
CSV_HEADER = ("t_s,state,fault,speed_ref_rpm,speed_rpm,speed_est_rpm,theta_e_deg,"
              "theta_est_deg,id_a,iq_a,id_ref_a,iq_ref_a,vd_v,vq_v,vdc_v,torque_nm,"
              "ia_a,ib_a,ic_a")
PIL_COLUMNS = "isr_cycles,isr_latency_cycles,deadline_cycles,overrun,bridge,fw_unclean"


# ------------------------------------------------------------- scenario --
def parse_scenario(path):
    """focsim's scenario language (tools/focsim/scenario.h); returns
    (events [(t, cmd, args)], end)."""
    ev = []
    end = None
    with open(path) as f:
        for n, line in enumerate(f, 1):
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            fl = line.split()
            t = float(fl[0])
            cmd = fl[1]
            if cmd == "end":
                end = t
                continue
            ev.append((t, cmd, fl[2:], n))
    ev.sort(key=lambda e: (e[0], e[3]))
    if end is None:
        end = (ev[-1][0] if ev else 0.0) + 0.5
    return [(t, c, a) for t, c, a, _ in ev], end


def faults_from_header(root):
    names = {}
    path = os.path.join(root, "include", "foc", "faults.h")
    with open(path) as f:
        for m in re.finditer(r"FOC_FAULT_([A-Z_0-9]+)\s*=\s*\(?(0x[0-9a-fA-F]+|\d+)u?\s*(<<\s*(\d+))?",
                             f.read()):
            v = int(m.group(2), 0)
            if m.group(4):
                v <<= int(m.group(4))
            names[v] = m.group(1)
    return names


def load_layout(obj):
    """pil_ctrl_layout from build/pil/ctrl_layout.o (tools/pil/ctrl_layout.c)."""
    from elftools.elf.elffile import ELFFile
    with open(obj, "rb") as f:
        elf = ELFFile(f)
        sec = elf.get_section_by_name(".rodata.pil_ctrl_layout") or elf.get_section_by_name(".rodata")
        data = sec.data()
    w = struct.unpack_from("<12I", data, 0)
    if w[0] != 0x50494C31:
        raise SystemExit("pil: %s: no controller layout" % obj)
    names = ["state", "first", "forced_speed", "ramped", "est_speed", "est_theta",
             "id_ref", "iq_ref", "vd", "vq"]
    fields = {n: (v & 0xFFFF, v >> 16) for n, v in zip(names, w[1:11])}
    return dict(fields=fields, size=w[11])


# ------------------------------------------------------------------ run --
class Run:
    def __init__(self, a):
        root = os.path.abspath(os.path.join(HERE, "..", ".."))
        self.a = a
        self.faults = faults_from_header(root)
        layout = load_layout(a.layout)
        readings = dict(rcr_start=a.rcr_start, cc4_trigger=a.cc4_trigger, jdr_order=a.jdr_order)
        m = self.m = machine.Machine(a.elf, a.plant_lib, layout, readings, a.flash_ws,
                                     a.cpu_scale, a.adc_latency, shunt=a.shunt,
                                     diag=parse_diag(getattr(a, "diag", "")))
        m.handler_done = self.handler_done
        m.on_entry = self.on_entry
        m.tx_cb = self.on_tx
        m.uev_cb = self.on_uev
        self.rx_line = bytearray()
        self.tty_queue = []
        self.tty_busy = False
        self.sent = []
        self.lines = []            # (t, text) from the image (its banner)
        self.replies = []          # (t, reply payload) of the monitor
        self.in_frames = False     # text until the monitor's first zero
        self.speed_base_rpm = board_userparm("SPEED_BASE_RPM")
        self.rows = []
        self.isr = []              # (t_start, cycles, latency, deadline, overrun, state)
        self.isr_start = None
        self.uev_times = []
        self.period_ticks = TICK_HZ / m.pwm_hz
        self.csv = open(a.csv, "w") if a.csv else None
        if self.csv:
            self.csv.write(CSV_HEADER + "," + PIL_COLUMNS + "\n")
        self.row_n = 0
        self.start_t = None
        self.max_bridge_off_delay = None
        self.t_origin = 0.0

    # --- image output
    def on_tx(self, b, t):
        if b == 0:
            self.in_frames = True
        if self.in_frames:
            self.on_frame_byte(b, t)
        elif b in (10, 13):
            if self.rx_line:
                self.lines.append(((t - getattr(self, "t_origin", 0.0)) / TICK_HZ, self.rx_line.decode("ascii", "replace")))
                if self.tty_busy:
                    self.m.sched.at(t + 0.0005 * TICK_HZ, self._type)
                if self.a.verbose:
                    print("[%.4f] %s" % ((t - getattr(self, "t_origin", 0.0)) / TICK_HZ, self.rx_line.decode("ascii", "replace")))
            self.rx_line = bytearray()
        else:
            self.rx_line.append(b)

    def on_frame_byte(self, b, t):
        """The monitor's frames (docs/monitor.md): a reply per zero-ended
        frame that decodes; the next queued request after it."""
        if b != 0:
            self.rx_line.append(b)
            return
        enc, self.rx_line = bytes(self.rx_line), bytearray()
        payload = fm.unframe(enc) if enc else None
        if payload is None:
            return
        ts = (t - getattr(self, "t_origin", 0.0)) / TICK_HZ
        self.replies.append((ts, payload))
        if self.a.verbose:
            print("[%.4f] reply %s" % (ts, payload.hex(" ")))
        if self.tty_busy:
            self.m.sched.at(t + 0.0005 * TICK_HZ, self._type)

    def request_bytes(self, text):
        """The request payload of an operator's command: start, stop, ack,
        speed <rpm>, status, identify, or raw <hex bytes>."""
        w = text.split()
        if w[0] == "speed":
            q = int(round(float(w[1]) * 32768.0 / self.speed_base_rpm))
            return struct.pack("<Bh", fm.CMD["speed"], max(-32768, min(32767, q)))
        if w[0] == "raw":
            return bytes(int(x, 16) for x in w[1:])
        return bytes([fm.CMD[w[0]]])

    def on_uev(self, t, at_bottom):
        self.uev_times.append(t)
        if len(self.uev_times) > 8:
            del self.uev_times[0]

    def on_entry(self, e, t):
        if e == EXC_ADC:
            self.isr_start = t

    def handler_done(self, e, cycles, t_end):
        if e != EXC_ADC:
            return
        m = self.m
        # the duties of this step are due at the first update after the
        # conversion ended; the step overran if it ended after it
        jeoc = m.jeoc_t if m.jeoc_t is not None else t_end
        trig = m.trig_t if m.trig_t is not None else jeoc
        # next update after the conversion: bottom of the count
        p = self.period_ticks
        last = m.tim1.last_uev if m.tim1.last_uev is not None else 0.0
        nxt = last
        while nxt <= jeoc:
            nxt += p
        overrun = 1 if t_end > nxt else 0
        latency = (self.isr_start - jeoc) / m.cpu_ticks() if self.isr_start else 0.0
        deadline = (nxt - jeoc) / m.cpu_ticks()
        c = m.read_ctrl()
        state = STATES[c.get("state", 0)] if c.get("state", 0) < len(STATES) else "?"
        self.isr.append((t_end, cycles, latency, deadline, overrun, state, (nxt - trig) / m.cpu_ticks()))
        snap = m.conv_snap
        if snap is None:
            return
        if m.t >= self.t_origin and self.t_origin > 0:
            self.write_row(snap, c, state, cycles, latency, deadline, overrun)

    def write_row(self, snap, c, state, cycles, latency, deadline, overrun):
        t, st = snap
        m = self.m
        ib = 2.9 / 32768.0 if False else m.i_fs / 32768.0
        vb = m.vdc_nom / 32768.0
        sb = m.speed_base / 32768.0
        forced = state in ("ALIGN", "OPENLOOP")
        ref = c.get("forced_speed" if forced else "ramped", 0) * sb
        th = st[4]
        ia, ibb = st[0], st[1]
        alpha, beta = ia, (ia + 2.0 * ibb) / math.sqrt(3.0)
        idt = alpha * math.cos(th) + beta * math.sin(th)
        iqt = -alpha * math.sin(th) + beta * math.cos(th)
        row = ((t - self.t_origin) / TICK_HZ, state, self.faults.get(c.get("first", 0), "NONE") if c.get("first", 0) else "NONE",
               ref, st[5], c.get("est_speed", 0) * sb, math.degrees(th) % 360.0,
               c.get("est_theta", 0) * 360.0 / 65536.0, idt, iqt, c.get("id_ref", 0) * ib,
               c.get("iq_ref", 0) * ib, c.get("vd", 0) * vb, c.get("vq", 0) * vb, st[3], st[6],
               st[0], st[1], st[2])
        self.rows.append(row)
        self.row_n += 1
        if self.csv and (self.row_n - 1) % self.a.decimate == 0:
            self.csv.write("%.6f,%s,%s,%.2f,%.2f,%.2f,%.2f,%.2f,%.4f,%.4f,%.4f,%.4f,%.3f,%.3f,"
                           "%.3f,%.5f,%.4f,%.4f,%.4f" % row)
            self.csv.write(",%.0f,%.0f,%.0f,%d,%d,%d\n" % (cycles, latency, deadline, overrun,
                                                            m.bridge_state[0], m.read_fw_unclean()))

    # --- scenario
    def apply(self, t_s, cmd, args):
        m = self.m
        t = m.t
        m.plant_to(t)
        lib, pl = m.lib, m.plant
        if cmd in ("start", "stop", "ack"):
            self.say(t, cmd)
            if cmd == "start" and self.start_t is None:
                self.start_t = t_s
        elif cmd == "speed":
            self.say(t, "speed %d" % int(round(float(args[0]))))
        elif cmd == "load":
            lib.pil_cmd(pl, 0, float(args[0]))
        elif cmd == "lock":
            lib.pil_cmd(pl, 1, 0.0)
        elif cmd == "unlock":
            lib.pil_cmd(pl, 2, 0.0)
        elif cmd == "vdc":
            lib.pil_cmd(pl, 3, float(args[0]))
        elif cmd == "angle":
            lib.pil_cmd(pl, 4, math.radians(float(args[0])))
        elif cmd == "spin":
            lib.pil_cmd(pl, 5, float(args[0]))
        elif cmd == "temp":
            m.temp_degc = float(args[0])
        elif cmd == "overcurrent":
            # the MB459's over-current comparator pulls BKIN low for a moment
            self.oc_t = t
            m.set_bkin(t, True)
            m.sched.at(t + 0.000002 * TICK_HZ, lambda tt: m.set_bkin(tt, False), True)
        elif cmd == "plant":
            names = ["rs", "ld", "lq", "flux", "j", "b", "deadtime", "noise", "buscap", "brakeres"]
            if args[0] not in names:
                raise SystemExit("pil: plant %s: not in the PIL's plant (only %s; focsim has the "
                                 "others)" % (args[0], ", ".join(names)))
            k = names.index(args[0])
            if args[0] == "deadtime":
                m.plant_deadtime_from_image = False
            lib.pil_cmd(pl, 10 + k, float(args[1]))
        else:
            raise SystemExit("pil: unknown scenario command %s" % cmd)

    def say(self, t, text):
        """Sends a monitor request (request_bytes).  Like the PC tool, it
        waits for the reply to one request before sending the next: the
        USART holds one received byte, and the main loop takes them as
        they come (RM0008 section 27.6.1 ORE otherwise).  A request whose
        text starts with "garbled " is sent with one byte of its frame
        changed (a line error), which the monitor must drop."""
        self.tty_queue.append(text)
        if not self.tty_busy:
            self._type(t)

    def _type(self, t):
        if not self.tty_queue:
            self.tty_busy = False
            return
        self.tty_busy = True
        text = self.tty_queue.pop(0)
        self.sent.append((t, text))
        garbled = text.startswith("garbled ")
        data = bytearray(fm.frame(self.request_bytes(text[8:] if garbled else text)))
        if garbled:
            data[2] ^= 0x40  # the first byte after the code: the CRC fails
        self.m.usart.send(t, bytes(data))
        if garbled:  # no reply will come: the next request after a while
            self.m.sched.at(t + 0.005 * TICK_HZ, self._type)

    def run(self, events, end_s):
        """Boots the image until its banner (at most 0.1 s), then plays the
        scenario with its time 0 at the banner, as an operator who waits
        for the prompt would; CSV times count from there."""
        m = self.m
        wall = time.time()
        while not self.lines and m.t < 0.1 * TICK_HZ and m.halted is None:
            m.run(m.t + 0.0005 * TICK_HZ)
        self.t_origin = m.t
        o = m.t / TICK_HZ
        for t_s, cmd, args in events:
            m.sched.at((o + t_s) * TICK_HZ,
                       (lambda c, a, ts: lambda tt: self.apply(ts, c, a))(cmd, args, t_s))
        # the firmware's own status (its overrun count), asked at the end as
        # an operator would
        m.sched.at((o + end_s) * TICK_HZ, lambda tt: self.say(tt, "status"))
        m.run((o + end_s + 0.025) * TICK_HZ)
        self.wall = time.time() - wall
        if self.csv:
            self.csv.close()
        return self


# --------------------------------------------------------------- figures --
def segments(events, end):
    """Steady windows: for every speed command, the last 25 % (at most
    0.1 s) before the next command of any kind."""
    times = sorted(set([t for t, _, _ in events] + [end]))
    out = []
    for t, cmd, args in events:
        if cmd != "speed":
            continue
        nxt = min(x for x in times if x > t)
        w = min(0.1, 0.25 * (nxt - t))
        out.append((float(args[0]), nxt - w, nxt))
    return out


def figures(rows, events, end):
    """rows: (t, state, fault, ref, speed, est_speed, theta, theta_est, ...)."""
    f = {}
    start = next((t for t, c, _ in events if c == "start"), None)
    run_t = next((r[0] for r in rows if r[1] == "RUN"), None)
    f["startup_s"] = (run_t - start) if (run_t is not None and start is not None) else -1.0
    for ref, a, b in segments(events, end):
        sel = [r for r in rows if a <= r[0] < b]
        if not sel:
            continue
        sp = [r[4] for r in sel]
        key = "%d" % int(ref)
        f["speed_%s_mean" % key] = sum(sp) / len(sp)
        f["speed_%s_min" % key] = min(sp)
        f["speed_%s_max" % key] = max(sp)
        err = [((r[7] - r[6] + 180.0) % 360.0) - 180.0 for r in sel if r[1] == "RUN"]
        if err:
            f["angle_err_%s_rms_deg" % key] = math.sqrt(sum(e * e for e in err) / len(err))
            f["angle_err_%s_mean_deg" % key] = sum(err) / len(err)
    faults = [r[2] for r in rows if r[2] != "NONE"]
    f["first_fault"] = faults[0] if faults else "NONE"
    f["final_state"] = rows[-1][1] if rows else "?"
    return f


def read_csv(path):
    rows = []
    with open(path) as fh:
        hdr = fh.readline().strip().split(",")
        for line in fh:
            v = line.strip().split(",")
            r = [float(v[0]), v[1], v[2]] + [float(x) for x in v[3:19]]
            rows.append(tuple(r))
    return rows


def run_focsim(focsim, scenario, out_csv):
    subprocess.run([focsim, "--scenario", scenario, "--csv", out_csv], check=True,
                   stdout=subprocess.DEVNULL)
    return read_csv(out_csv)


def fmt(v):
    return ("%.3f" % v) if isinstance(v, float) else str(v)


def report(r, events, end, a):
    m = r.m
    out = []
    isr = [x for x in r.isr]
    run_isr = [x for x in isr if x[5] == "RUN"]
    use = run_isr or isr
    cyc = [x[1] for x in use]
    out.append(("pil_wall_s", r.wall))
    out.append(("pil_sim_s", m.t / TICK_HZ))
    out.append(("pil_halted", m.halted or "no"))
    banner = [l for _, l in r.lines if "ready" in l or "fault" in l]
    out.append(("pil_banner", banner[0].replace(" ", "_") if banner else "none"))
    out.append(("flash_wait_states", m.wait_states()))
    out.append(("cpu_scale", a.cpu_scale))
    if cyc:
        out.append(("image_isr_cycles_avg", int(round(sum(cyc) / len(cyc)))))
        out.append(("image_isr_cycles_max", int(round(max(cyc)))))
        # issue 11's deadline: from the ADC trigger to the duty load
        tl = sorted(x[6] for x in use)
        out.append(("image_deadline_cycles", int(round(tl[len(tl) // 2]))))
        # what the interrupt really has: from its request (end of the
        # conversions) to the duty load
        dl = sorted(x[3] for x in use)
        out.append(("image_isr_window_cycles", int(round(dl[len(dl) // 2]))))
    out.append(("pil_overruns", sum(x[4] for x in isr)))
    out.append(("pil_periods", len(isr)))
    st = [p for _, p in r.replies if p[0] == (fm.CMD["status"] | 0x80) and p[1] == 0]
    if st:
        f = struct.unpack_from("<BHHhhhhhhhhHHHB", st[-1], 2)
        out.append(("image_overruns", f[12]))
        out.append(("image_fw_cpu_load_pct", f[11] * 100.0 / 32768 if f[11] != 0xFFFF else -1.0))
        out.append(("image_dropped_frames", f[13]))
    else:
        out.append(("image_overruns", -1))
    # the port's count of unclean samples, read from its RAM as a debugger
    # would (the monitor's status has no field for it)
    out.append(("image_unclean", m.read_fw_unclean()))
    per = m.pwm_hz and TICK_HZ / m.pwm_hz / m.cpu_ticks()
    for st in STATES:
        c = [x[1] for x in isr if x[5] == st]
        if c:
            out.append(("cpu_load_%s" % st.lower(), sum(c) / len(c) / per))
    iw = m.iwdg.refreshes
    out.append(("watchdog_refreshes", len(iw)))
    gaps = [b - a_ for a_, b in zip(iw[1:], iw[2:])]
    out.append(("watchdog_max_gap_ms", (max(gaps) / TICK_HZ * 1000.0) if gaps else -1.0))
    out.append(("adc_regular_starts", m.adc1.regular_starts + m.adc2.regular_starts))
    out.append(("adc_ignored_triggers", m.adc1.ignored_triggers))
    out.append(("unknown_registers", len(m.unknown_access)))
    out.append(("diag_not_rm0008", ",".join(sorted(m.diag)) or "none"))
    fp = figures(r.rows, events, end)
    for k, v in fp.items():
        out.append(("pil_" + k, v))
    if a.focsim:
        fcsv = (a.csv or a.scenario) + ".focsim.csv"
        ff = figures(run_focsim(a.focsim, a.scenario, fcsv), events, end)
        for k, v in ff.items():
            out.append(("focsim_" + k, v))
        for k in fp:
            if k.startswith("speed_") and k.endswith("_mean") and k in ff and ff[k]:
                out.append(("diff_%s_pct" % k, 100.0 * (fp[k] - ff[k]) / ff[k]))
            if k.startswith("angle_err_") and k.endswith("_rms_deg") and k in ff:
                out.append(("diff_%s" % k, fp[k] - ff[k]))
        if fp.get("startup_s", -1) > 0 and ff.get("startup_s", -1) > 0:
            out.append(("diff_startup_pct", 100.0 * (fp["startup_s"] - ff["startup_s"]) / ff["startup_s"]))
    for k, v in out:
        print("%s=%s" % (k, fmt(v)))
    if a.monitor_log:
        with open(a.monitor_log, "w") as fh:
            for t, l in r.lines:
                fh.write("%.6f %s\n" % (t, l))
            for t, p in r.replies:
                fh.write("%.6f reply %s\n" % (t, p.hex(" ")))
    return dict(out)


def parse_diag(text):
    """--diag NAME[,NAME]: modelling errors on purpose (machine.DIAG_ERRORS),
    for the issue-16 study only (docs/pil.md)."""
    names = [n for n in (text or "").split(",") if n]
    for n in names:
        if n not in machine.DIAG_ERRORS:
            raise SystemExit("pil: --diag %s: not one of %s" % (n, ", ".join(sorted(machine.DIAG_ERRORS))))
    if names:
        sys.stderr.write("pil: --diag %s: NOT RM0008 -- a deliberate modelling error, "
                         "diagnostic only\n" % ",".join(names))
    return frozenset(names)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("cmd", choices=["run"])
    p.add_argument("--elf", default="build/stm32/foc_stm32f10x.elf")
    p.add_argument("--scenario", default="tools/scenarios/default.scn")
    p.add_argument("--csv")
    p.add_argument("--focsim")
    p.add_argument("--plant-lib", default="build/pil/libpilplant.so")
    p.add_argument("--layout", default="build/pil/ctrl_layout.o")
    p.add_argument("--cpu-scale", type=float, default=1.0)
    p.add_argument("--flash-ws", choices=["rm0008", "zero"], default="rm0008")
    p.add_argument("--rcr-start", choices=["count", "overflow"], default="count")
    p.add_argument("--cc4-trigger", choices=["oc4", "cc4event"], default="oc4")
    p.add_argument("--jdr-order", choices=["sequence", "slot"], default="sequence")
    p.add_argument("--adc-latency", type=float, default=3.0)
    p.add_argument("--shunt", choices=["lowside", "ideal"], default="lowside")
    p.add_argument("--diag", default="",
                   help="NOT RM0008: deliberate modelling errors, comma-separated (issue 16 study; "
                        "never used by tests or make pil): " + ", ".join(sorted(machine.DIAG_ERRORS)))
    p.add_argument("--decimate", type=int, default=1)
    p.add_argument("--monitor-log")
    p.add_argument("--until", type=float, help="stop at this time (s) instead of the scenario end")
    p.add_argument("-v", "--verbose", action="store_true")
    a = p.parse_args(argv)
    events, end = parse_scenario(a.scenario)
    if a.until is not None:
        end = a.until
        events = [e for e in events if e[0] < end]
    r = Run(a).run(events, end)
    return r, report(r, events, end, a)


if __name__ == "__main__":
    main()
