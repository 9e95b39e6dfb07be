"""Register-level models of the STM32F103 peripherals the FOC image uses.

Every behaviour is a rule written from the reference manual (RM0008, rev.
21: STM32F101/102/103/105/107) or the Cortex-M3 programming manual
(PM0056), cited beside it as [RM §x.y] / [PM §x.y]; docs/pil.md lists them.
Where the manual reads two ways the choice is an option of Machine (the
`readings` dict) and both are documented.

Time is counted in ticks of 1/72 MHz (the SYSCLK the board runs at; the
CPU cycle model converts its cycles to ticks with the clock in use).
"""

import heapq

TICK_HZ = 72000000.0

# ----------------------------------------------------------- addresses --
APB1, APB2, AHB = 0x40000000, 0x40010000, 0x40020000
TIM3_BASE = APB1 + 0x0400
IWDG_BASE = APB1 + 0x3000
AFIO_BASE = APB2 + 0x0000
GPIO_BASE = {"A": APB2 + 0x0800, "B": APB2 + 0x0C00, "C": APB2 + 0x1000,
             "D": APB2 + 0x1400, "E": APB2 + 0x1800}
ADC1_BASE, ADC2_BASE = APB2 + 0x2400, APB2 + 0x2800
TIM1_BASE = APB2 + 0x2C00
USART1_BASE = APB2 + 0x3800
RCC_BASE, FLASH_BASE_R = AHB + 0x1000, AHB + 0x2000

# interrupt numbers [RM §10.1.2 table 63, medium density]
IRQ_ADC1_2, IRQ_TIM1_BRK, IRQ_TIM1_UP = 18, 24, 25
EXC_SYSTICK = 15


class Scheduler:
    """Timed events: (tick, seq, fn, wake).  `wake` events stop the CPU
    (they can raise an interrupt); the others are processed lazily before
    any register access and before any wake event."""

    def __init__(self):
        self.heap = []
        self.seq = 0

    def at(self, t, fn, wake=True):
        self.seq += 1
        heapq.heappush(self.heap, (t, self.seq, fn, wake))

    def next_wake(self):
        # heap order is not sorted order: the smallest wake time
        return min((e[0] for e in self.heap if e[3]), default=None)

    def run_until(self, t):
        h = self.heap
        while h and h[0][0] <= t:
            tt, _, fn, _ = heapq.heappop(h)
            fn(tt)


# ---------------------------------------------------------------- TIM1 --
class Tim1:
    """Advanced-control timer TIM1 [RM §14], as far as the image uses it:
    centre-aligned counting, repetition counter, preloaded compare values,
    PWM modes 1/2 and forced modes, CH4 as the ADC trigger, break input,
    MOE, dead time, update/break interrupts."""

    def __init__(self, m):
        self.m = m
        self.cr1 = self.cr2 = self.dier = self.sr = 0
        self.ccmr1 = self.ccmr2 = self.ccer = self.bdtr = 0
        self.psc = 0
        self.arr = 0xFFFF
        self.arr_sh = 0xFFFF
        self.rcr = 0
        self.rep = 0
        self.ccr = [0, 0, 0, 0]     # preload registers
        self.ccr_sh = [0, 0, 0, 0]  # shadow (active) registers
        self.cnt_stopped = 0
        self.t0 = None              # tick at which phase 0 was (counter running)
        self.gen = 0                # invalidates scheduled counter events
        self.oc4 = 0                # OC4 level seen by the ADC trigger
        self.updates = []           # ticks of the update events (recent)
        self.last_uev = None
        self.uev_count = 0
        self.break_count = 0

    # --- counter [RM §14.3.2 "Center-aligned mode (up/down counting)"]:
    # 0, 1, .. ARR-1 (overflow at ARR), ARR, .. 1 (underflow at 0): one
    # period = 2 ARR timer clocks; DIR is read-only and follows the count.
    def phase(self, t):
        p2 = 2 * self.arr_sh
        return int(t - self.t0) % p2 if p2 else 0

    def cnt(self, t):
        if self.t0 is None:
            return self.cnt_stopped
        ph = self.phase(t)
        return ph if ph <= self.arr_sh else 2 * self.arr_sh - ph

    def dir_down(self, t):
        if self.t0 is None:
            return 0
        return 1 if self.phase(t) >= self.arr_sh else 0

    def centre(self):
        return (self.cr1 >> 5) & 3

    def start(self, t, cnt):
        """Counter (re)started at `cnt` counting up at tick t."""
        self.gen += 1
        self.t0 = t - cnt
        self.schedule_edges(t)

    def schedule_edges(self, t):
        """Next overflow and underflow, and the CH4 compare edges within
        them, from tick t on."""
        if self.t0 is None or self.centre() == 0:
            return
        g = self.gen
        ph = self.phase(t)
        base = t - ph
        a = self.arr_sh
        wake = self.rep == 0 or bool(self.m.diag)  # an update comes with this over/underflow
        if ph < a:
            self.m.sched.at(base + a, lambda tt: g == self.gen and self.over_under(tt, True), wake)
        else:
            self.m.sched.at(base + 2 * a, lambda tt: g == self.gen and self.over_under(tt, False), wake)
        # CH4 compare instants [RM §14.3.10 PWM mode 2]: OC4REF active for
        # CNT >= CCR4 counting up and CNT > CCR4 counting down, i.e. on
        # the period timeline [CCR4, 2 ARR - CCR4).
        c = self.ccr_sh[3]
        if ph < a:
            e1 = c
            if ph < e1 <= a:
                self.m.sched.at(base + e1, lambda tt: g == self.gen and self.cc4_match(tt, False), False)
        else:
            e2 = 2 * a - c
            if ph < e2 < 2 * a:
                self.m.sched.at(base + e2, lambda tt: g == self.gen and self.cc4_match(tt, True), False)
        self.m.sched_dirty = True

    def oc4ref(self, t):
        """[RM §14.3.10] PWM mode 2 (OC4M = 111) / 1 (110) of channel 4."""
        mode = (self.ccmr2 >> 12) & 7
        if self.t0 is None:
            return 0
        c = self.ccr_sh[3]
        ph = self.phase(t)
        up_active = c <= ph < 2 * self.arr_sh - c
        if mode == 7:
            return 1 if up_active else 0
        if mode == 6:
            return 0 if up_active else 1
        if mode == 5:
            return 1
        return 0

    def refresh_oc4(self, t, match_down=None):
        """OC4 = OC4REF xor CC4P [RM §14.3.9, §14.4.9 CC4P]; the ADC sees
        its rising edge (reading 'oc4'), or the CC4 compare event (reading
        'cc4event', [RM §14.4.1 CMS: in centre-aligned mode 1 the compare
        flags of output channels are set only when counting down])."""
        lvl = self.oc4ref(t) ^ ((self.ccer >> 13) & 1)
        rising = lvl and not self.oc4
        self.oc4 = lvl
        rd = self.m.readings["cc4_trigger"]
        if rd == "oc4":
            if rising:
                self.m.adc_trigger(t, "CC4")
        elif match_down is not None:
            cms = self.centre()
            if (cms == 1 and match_down) or (cms == 2 and not match_down) or cms == 3:
                self.m.adc_trigger(t, "CC4")

    def cc4_match(self, t, down):
        # [RM §14.4.5 CC4IF set on a compare match; direction per CMS]
        cms = self.centre()
        if (cms == 1 and down) or (cms == 2 and not down) or cms == 3:
            self.sr |= 1 << 4
        self.refresh_oc4(t, match_down=down)

    def over_under(self, t, overflow):
        """[RM §14.3.3 Repetition counter]: in centre-aligned mode the
        repetition down-counter counts overflows and underflows; the update
        event (UEV) comes when it is 0, and then it reloads from RCR."""
        diag = self.m.diag
        do = self.rep == 0
        if self.rep == 0:
            self.rep = self.rcr
        else:
            self.rep -= 1
        if "uev-every" in diag:
            do = True  # NOT RM0008 (--diag): RCR ignored
        elif "uev-swap" in diag and self.rcr == 1:
            do = not do  # NOT RM0008 (--diag): the other end of the count
        if do:
            self.uev(t, at_bottom=not overflow)
        self.refresh_oc4(t)
        self.schedule_edges(t + 1)

    def uev(self, t, at_bottom, software=False):
        """Update event [RM §14.3.1, §14.4.6 UG]: preload registers to the
        shadow ones (ARR with ARPE, CCRx with OCxPE), UIF set, TRGO pulse
        when MMS = 010 [RM §14.4.2], the repetition counter reloaded."""
        m = self.m
        m.plant_to(t)
        self.arr_sh = self.arr
        pe = [(self.ccmr1 >> 3) & 1, (self.ccmr1 >> 11) & 1,
              (self.ccmr2 >> 3) & 1, (self.ccmr2 >> 11) & 1]
        for i in range(4):
            if pe[i]:
                self.ccr_sh[i] = self.ccr[i]
        self.sr |= 1
        self.uev_count += 1
        self.last_uev = t
        m.on_uev(t, at_bottom)
        if ((self.cr2 >> 4) & 7) == 2:
            m.adc_trigger(t, "TRGO")
        m.update_bridge(t)
        m.irq_lines(t)

    # --- outputs to the plant
    def bridge(self):
        """(mode, duties): 0 off, 1 PWM, 2 low sides.  [RM §14.4.18 BDTR
        MOE / OSSI, table 83 "Output control bits for complementary OCx
        and OCxN channels with break feature"]: MOE = 0 with OSSI = 1
        drives both outputs to their idle levels (OISx = 0: gates off).
        OCxM = 100 forces OCxREF low [RM §14.4.7]: high side off, low side
        on.  PWM mode 1 (110) in centre-aligned mode: OCxREF high while
        CNT < CCRx, so the high side is on for CCRx / ARR of the period."""
        if not (self.bdtr >> 15) & 1:
            return 0, (0.0, 0.0, 0.0)
        modes = [(self.ccmr1 >> 4) & 7, (self.ccmr1 >> 12) & 7, (self.ccmr2 >> 4) & 7]
        if all(md == 4 for md in modes):
            return 2, (0.0, 0.0, 0.0)
        a = float(self.arr_sh) or 1.0
        d = []
        for i, md in enumerate(modes):
            if md == 6:
                d.append(min(self.ccr_sh[i], self.arr_sh) / a)
            elif md == 7:
                d.append(1.0 - min(self.ccr_sh[i], self.arr_sh) / a)
            elif md == 5:
                d.append(1.0)
            else:
                d.append(0.0)
        return 1, tuple(d)

    def deadtime_ticks(self):
        """[RM §14.4.18 DTG]: four ranges, tDTS = tCK_INT (CKD = 00)."""
        dtg = self.bdtr & 0xFF
        if dtg & 0x80 == 0:
            n = dtg
        elif dtg & 0xC0 == 0x80:
            n = 2 * (64 + (dtg & 0x3F))
        elif dtg & 0xE0 == 0xC0:
            n = 8 * (32 + (dtg & 0x1F))
        else:
            n = 16 * (32 + (dtg & 0x1F))
        return n << ((self.cr1 >> 8) & 3)

    def break_input(self, t, level):
        """[RM §14.3.11 Using the break function]: with BKE set, the active
        level of BKIN (BKP = 0: low) clears MOE asynchronously, sets BIF
        (interrupt if BIE); MOE cannot be set while the input is active."""
        if (self.bdtr >> 12) & 1 and level == ((self.bdtr >> 13) & 1):
            self.m.plant_to(t)
            self.bdtr &= ~(1 << 15)
            self.sr |= 1 << 7
            self.break_count += 1
            self.m.update_bridge(t)
            self.m.irq_lines(t)

    # --- registers [RM §14.4]
    def read(self, off, t):
        if off == 0x00:
            return self.cr1 | (self.dir_down(t) << 4)
        if off == 0x24:
            return self.cnt(t)
        return {0x04: self.cr2, 0x0C: self.dier, 0x10: self.sr, 0x18: self.ccmr1,
                0x1C: self.ccmr2, 0x20: self.ccer, 0x28: self.psc, 0x2C: self.arr,
                0x30: self.rcr, 0x34: self.ccr[0], 0x38: self.ccr[1], 0x3C: self.ccr[2],
                0x40: self.ccr[3], 0x44: self.bdtr}.get(off, 0)

    def write(self, off, v, t):
        m = self.m
        v &= 0xFFFF
        if off == 0x00:
            was = self.cr1 & 1
            self.cr1 = v & ~(1 << 4)
            if (v & 1) and not was:
                self.start_counter(t)
            elif not (v & 1) and was:
                self.cnt_stopped = self.cnt(t)
                self.t0 = None
                self.gen += 1
        elif off == 0x04:
            self.cr2 = v
        elif off == 0x0C:
            self.dier = v
            m.irq_lines(t)
        elif off == 0x10:
            self.sr &= v  # rc_w0 [RM §14.4.5]
            m.irq_lines(t)
        elif off == 0x14:
            if v & 1:  # UG [RM §14.4.6]: counter cleared (centre-aligned)
                self.rep = self.rcr
                if m.readings["rcr_start"] == "overflow" and self.rcr & 1:
                    self.rep = self.rcr - 1
                self.uev(t, at_bottom=True, software=True)
                if self.t0 is not None:
                    self.start(t, 0)
                else:
                    self.cnt_stopped = 0
        elif off == 0x18:
            self.ccmr1 = v
            m.update_bridge(t)
        elif off == 0x1C:
            self.ccmr2 = v
            m.update_bridge(t)
            self.refresh_oc4(t)
        elif off == 0x20:
            self.ccer = v
            self.refresh_oc4(t)  # CC4P acts at once (not preloaded)
        elif off == 0x24:
            if self.t0 is not None:
                self.start(t, v)
            else:
                self.cnt_stopped = v
        elif off == 0x28:
            self.psc = v
        elif off == 0x2C:
            self.arr = v
            if not (self.cr1 >> 7) & 1:
                self.arr_sh = v
        elif off == 0x30:
            self.rcr = v & 0xFF  # preloaded: used at the next UEV
        elif 0x34 <= off <= 0x40:
            i = (off - 0x34) // 4
            self.ccr[i] = v
            pe = [(self.ccmr1 >> 3) & 1, (self.ccmr1 >> 11) & 1,
                  (self.ccmr2 >> 3) & 1, (self.ccmr2 >> 11) & 1][i]
            if "ccr-nopreload" in m.diag or ("duty-nopreload" in m.diag and i < 3):
                pe = 0  # NOT RM0008 (--diag): the preload ignored
            if not pe:
                self.ccr_sh[i] = v
                m.update_bridge(t)
                if i == 3 and self.t0 is not None:
                    # the compare instants move with the new value
                    self.gen += 1
                    self.schedule_edges(t)
                    self.refresh_oc4(t)
        elif off == 0x44:
            # LOCK level 1 freezes DTG, BKE, BKP, AOE, OISx [RM §14.4.18]
            if (self.bdtr >> 8) & 3:
                keep = 0x30FF
                v = (v & ~keep) | (self.bdtr & keep)
                v = (v & ~0x300) | (self.bdtr & 0x300)
            moe_req = (v >> 15) & 1
            self.bdtr = v
            if moe_req and m.bkin_active():
                self.bdtr &= ~(1 << 15)  # [RM §14.3.11] MOE held low
            m.update_bridge(t)
        m.irq_lines(t)

    def start_counter(self, t):
        """CEN set [RM §14.4.1]: counting starts from CNT.  Reading
        'overflow' of the odd-RCR note [RM §14.3.3, figure "Update rate
        examples depending on mode and TIMx_RCR register settings"]: the
        first UEV of a counter started with an odd RCR written before comes
        at an overflow; reading 'count' follows the down-counter alone."""
        if self.m.readings["rcr_start"] == "overflow" and self.rcr & 1:
            self.rep = self.rcr - 1
        self.start(t, self.cnt_stopped)


# ----------------------------------------------------------------- ADC --
ADC_CONV_CYCLES = 12.5  # [RM §11.6 "Channel-by-channel programmable sample time": Tconv = Tsmp + 12.5]
SMP_CYCLES = [1.5, 7.5, 13.5, 28.5, 41.5, 55.5, 71.5, 239.5]  # [RM §11.12.4 SMPx]


class Adc:
    """ADC1/ADC2 [RM §11]: injected group, external trigger, dual
    injected-simultaneous mode, data alignment, calibration."""

    def __init__(self, m, n):
        self.m, self.n = m, n
        self.sr = self.cr1 = self.cr2 = self.smpr1 = self.smpr2 = self.jsqr = 0
        self.jdr = [0, 0, 0, 0]
        self.dr = 0
        self.busy_until = -1
        self.cal_until = 0
        self.regular_starts = 0  # conversions started by rewriting ADON
        self.sequences = 0
        self.ignored_triggers = 0
        self.first_current_k = -1  # index of the first phase-current conversion
        self.current_lead = 0.0

    def smp(self, ch):
        if ch < 10:
            code = (self.smpr2 >> (3 * ch)) & 7
        else:
            code = (self.smpr1 >> (3 * (ch - 10))) & 7
        return SMP_CYCLES[code]

    def sequence(self):
        """[RM §11.12.12 ADC_JSQR]: JL + 1 conversions, of JSQ(4-JL) ..
        JSQ4 in that order; returns [(slot 1..4, channel)]."""
        jl = (self.jsqr >> 20) & 3
        out = []
        for slot in range(4 - jl, 5):
            out.append((slot, (self.jsqr >> (5 * (slot - 1))) & 0x1F))
        return out

    def start_injected(self, t):
        """An injected sequence from tick t.  Timing [RM §11.6, §11.9
        "Injected channel management" and the datasheet's trigger latency
        (machine option adc_latency, ADC clocks)]: conversion k samples for
        SMP cycles and converts for 12.5 more; its input is held at the
        end of its sampling time.  JDRk is written at the end of its
        conversion, JEOC set after the last [RM §11.3.4? JEOC]."""
        m = self.m
        if not (self.cr2 & 1):
            return
        if t < self.busy_until:
            self.ignored_triggers += 1
            return
        if "jdr-prev" in m.diag:  # NOT RM0008 (--diag): last sequence's results now
            for target, val in getattr(self, "deferred", {}).items():
                self.jdr[target - 1] = val
            self.deferred = {}
        clk = m.adc_clock_ticks()
        ts = t + m.adc_latency * clk
        seq = self.sequence()
        self.sequences += 1
        self.first_current_k = next((k for k, (_, ch) in enumerate(seq) if ch in (11, 12, 13)), -1)
        self.current_lead = 0.0  # ticks from the trigger's latency end to the current conversion
        for k, (slot, ch) in enumerate(seq):
            if k == self.first_current_k:
                self.current_lead = ts - (t + m.adc_latency * clk)
            s_end = ts + self.smp(ch) * clk
            c_end = s_end + ADC_CONV_CYCLES * clk
            target = (k + 1) if m.readings["jdr_order"] == "sequence" else slot
            at = t if "sample-at-trigger" in m.diag else s_end  # NOT RM0008 (--diag)
            m.sched.at(at, self._sampler(ch, target, k), False)
            ts = c_end
        self.busy_until = ts
        if "jeoc-at-trigger" in m.diag:  # NOT RM0008 (--diag): JEOC at the start
            t_start = t + m.adc_latency * clk
            m.sched.at(t_start, self._jeoc, True)
        m.sched.at(ts, self._eos, True)
        self.sr |= 1 << 3  # JSTRT

    def _sampler(self, ch, target, k):
        def f(tt):
            v = self.m.adc_input(tt, ch, self.n, k)
            code = max(0, min(4095, int(v / self.m.vref * 4096.0)))
            # [RM §11.5 Data alignment]: injected data, left aligned:
            # SEXT in bit 15, the 12-bit result in bits 14..3.
            self.pending = getattr(self, "pending", {})
            self.pending[target] = (code << 3) if (self.cr2 >> 11) & 1 else code
        return f

    def _eos(self, tt):
        if "jdr-prev" in self.m.diag:
            self.deferred = dict(getattr(self, "pending", {}))
        else:
            for target, val in getattr(self, "pending", {}).items():
                self.jdr[target - 1] = val
        self.pending = {}
        if "jeoc-at-trigger" not in self.m.diag:
            self._jeoc(tt)

    def _jeoc(self, tt):
        self.sr |= 1 << 2  # JEOC [RM §11.12.1]
        self.m.on_jeoc(tt, self.n)
        self.m.irq_lines(tt)

    def read(self, off, t):
        if off == 0x08:
            v = self.cr2
            if t < self.cal_until:
                return v
            return v & ~((1 << 2) | (1 << 3))  # CAL, RSTCAL cleared by hardware
        if 0x3C <= off <= 0x48:
            return self.jdr[(off - 0x3C) // 4]
        return {0x00: self.sr, 0x04: self.cr1, 0x0C: self.smpr1, 0x10: self.smpr2,
                0x38: self.jsqr, 0x4C: self.dr}.get(off, 0)

    def write(self, off, v, t):
        m = self.m
        if off == 0x00:
            self.sr &= v  # rc_w0
            m.irq_lines(t)
        elif off == 0x04:
            self.cr1 = v
            m.irq_lines(t)
        elif off == 0x08:
            old = self.cr2
            # [RM §11.12.3 ADON]: writing 1 while it is 1 starts a regular
            # conversion, unless another bit changes in the same write.
            if (old & 1) and (v & 1) and (v & ~0x0C) == (old & ~0x0C):
                self.regular_starts += 1
            if v & 0xC:  # CAL / RSTCAL: about 83 ADC clocks [RM §11.4]
                self.cal_until = t + 83 * m.adc_clock_ticks()
            self.cr2 = v
            # JSWSTART [RM §11.12.3] (ADC2 in dual mode follows ADC1 instead)
            if v & (1 << 21) and ((v >> 12) & 7) == 7 and (v >> 15) & 1:
                self.cr2 &= ~(1 << 21)
                self.start_injected(t)
        elif off == 0x0C:
            self.smpr1 = v
        elif off == 0x10:
            self.smpr2 = v
        elif off == 0x38:
            self.jsqr = v


# ------------------------------------------------------------- SysTick --
class SysTick:
    """[PM §4.5]: a 24-bit down-counter; reload from LOAD on the clock
    after it reaches 0, COUNTFLAG set and the exception pended (TICKINT)
    when it goes from 1 to 0; writing VAL clears it and COUNTFLAG.
    CLKSOURCE = 1: processor clock, 0: HCLK / 8 [RM §7.1 clock tree]."""

    def __init__(self, m):
        self.m = m
        self.ctrl = self.load = 0
        self.origin = None
        self.gen = 0

    def period(self):
        return (self.load + 1) * self.m.cpu_ticks() * (1 if self.ctrl & 4 else 8)

    def arm(self, t):
        self.gen += 1
        if not self.ctrl & 1 or self.load == 0:
            self.origin = None
            return
        self.origin = t
        self._next(t + self.period())

    def _next(self, when):
        g = self.gen
        self.m.sched.at(when, lambda tt: g == self.gen and self._wrap(tt), True)

    def _wrap(self, t):
        self.ctrl |= 1 << 16
        if self.ctrl & 2:
            self.m.pend_exc(EXC_SYSTICK)
        self.origin = t
        self._next(t + self.period())

    def read(self, off, t):
        if off == 0x0:
            v = self.ctrl
            self.ctrl &= ~(1 << 16)
            return v
        if off == 0x4:
            return self.load
        if off == 0x8:
            if self.origin is None:
                return 0
            per = self.period()
            left = per - (t - self.origin) % per
            return int(left / per * (self.load + 1)) & 0xFFFFFF
        return 0

    def write(self, off, v, t):
        if off == 0x0:
            self.ctrl = (self.ctrl & (1 << 16)) | (v & 7)
            self.arm(t)
        elif off == 0x4:
            self.load = v & 0xFFFFFF
        elif off == 0x8:
            self.ctrl &= ~(1 << 16)
            self.arm(t)


# -------------------------------------------------------------- USART1 --
class Usart:
    """USART1 [RM §27]: 1 start + 8 data + 1 stop bits (M = 0, STOP = 00),
    baud = fPCLK2 / (BRR / 16) [RM §27.3.4].  TX: TXE set when TDR moves to
    the shift register, which happens at once when it is empty, else at
    the end of the byte being sent [RM §27.3.2]; TC at the end of a frame.
    RX: RXNE set when a byte arrives; a byte arriving while RXNE is set
    sets ORE and is lost; reading SR then DR clears them [RM §27.6.1]."""

    def __init__(self, m):
        self.m = m
        self.sr = 0xC0  # TXE, TC [RM §27.6.1 reset value 0x00C0]
        self.brr = self.cr1 = 0
        self.rdr = 0
        self.tdr_full = False
        self.shift_until = -1
        self.tx = bytearray()
        self.rx_last = 0
        self.overruns = 0

    def char_ticks(self):
        brr = self.brr or 625
        return 10 * brr * self.m.pclk2_ticks()

    def read(self, off, t):
        if off == 0x00:
            if not self.sr & 0x28:
                self.m.idle_probe()
            return self.sr
        if off == 0x04:
            v = self.rdr
            self.sr &= ~((1 << 5) | (1 << 3))
            return v
        return {0x08: self.brr, 0x0C: self.cr1}.get(off, 0)

    def write(self, off, v, t):
        if off == 0x04:
            if not (self.cr1 & (1 << 13) and self.cr1 & (1 << 3)):
                return
            self.tx.append(v & 0xFF)
            if t >= self.shift_until:
                self.shift_until = t + self.char_ticks()
                self.sr |= 1 << 7
            else:
                self.sr &= ~(1 << 7)
                start = self.shift_until
                self.shift_until = start + self.char_ticks()
                self.m.sched.at(start, lambda tt: self._txe(), False)
            self.sr &= ~(1 << 6)
            self.m.sched.at(self.shift_until, lambda tt: self._tc(tt), False)
            self.m.on_tx(v & 0xFF, t)
        elif off == 0x08:
            self.brr = v
        elif off == 0x0C:
            self.cr1 = v
        elif off == 0x00:
            self.sr &= v | ~0x60

    def _txe(self):
        self.sr |= 1 << 7

    def _tc(self, t):
        if t >= self.shift_until:
            self.sr |= 1 << 6

    def send(self, t, data, baud=115200.0):
        """Bytes from the operator's terminal (8N1 at `baud`), back to back
        from tick t."""
        t = max(t, self.rx_last)
        for b in data:
            t += 10.0 * TICK_HZ / baud
            self.m.sched.at(t, self._rx(b), False)
        self.rx_last = t

    def _rx(self, b):
        def f(tt):
            if self.sr & (1 << 5):
                self.sr |= 1 << 3
                self.overruns += 1
                return
            self.rdr = b
            self.sr |= 1 << 5
        return f


# ---------------------------------------------------------------- IWDG --
class Iwdg:
    """[RM §19]: key 0xCCCC starts the watchdog, 0x5555 unlocks PR/RLR,
    0xAAAA reloads the counter; the 12-bit counter runs from the LSI (40
    kHz nominal, option lsi_hz) / 4 x 2^PR; reaching 0 resets the chip.
    PVU/RVU stay set for about 5 LSI periods after a write (the update
    crosses to the LSI domain)."""

    def __init__(self, m):
        self.m = m
        self.pr = 0
        self.rlr = 0xFFF
        self.running = False
        self.unlocked = False
        self.busy_until = 0
        self.gen = 0
        self.refreshes = []
        self.expired = None
        self.armed = False
        self.deadline = None

    def tick_ticks(self):
        return TICK_HZ / self.m.lsi_hz * (4 << self.pr)

    def reload(self, t):
        self.refreshes.append(t)
        self.deadline = t + (self.rlr + 1) * self.tick_ticks()
        if not self.armed:
            self.armed = True
            self.m.sched.at(self.deadline, self._expire, True)

    def _expire(self, t):
        if t < self.deadline:  # refreshed meanwhile: look again then
            self.m.sched.at(self.deadline, self._expire, True)
            return
        self.armed = False
        self.expired = t
        self.m.watchdog_reset(t)

    def read(self, off, t):
        if off == 0x0C:
            return 3 if t < self.busy_until else 0
        return {0x04: self.pr, 0x08: self.rlr}.get(off, 0)

    def write(self, off, v, t):
        v &= 0xFFFF
        if off == 0x00:
            if v == 0xCCCC:
                self.running = True
                self.reload(t)
            elif v == 0x5555:
                self.unlocked = True
            elif v == 0xAAAA:
                self.unlocked = False
                if self.running:
                    self.reload(t)
        elif off == 0x04 and self.unlocked:
            self.pr = v & 7
            self.busy_until = t + 5 * TICK_HZ / self.m.lsi_hz
        elif off == 0x08 and self.unlocked:
            self.rlr = v & 0xFFF
            self.busy_until = t + 5 * TICK_HZ / self.m.lsi_hz


# ---------------------------------------------------- RCC, FLASH, GPIO --
class Rcc:
    """[RM §7.3]: HSEON -> HSERDY, PLLON -> PLLRDY (set at once: the
    crystal and the PLL lock instantly here), SW -> SWS, CSS; the PLL
    multiplies HSE (PLLSRC = 1) by PLLMUL + 2; the system clock follows
    SWS; AHB / APB prescalers from CFGR."""

    def __init__(self, m):
        self.m = m
        self.cr = 0x83  # HSION, HSIRDY, HSITRIM 16
        self.cfgr = self.apb1enr = self.apb2enr = self.cir = 0
        self.ahbenr = 0x14

    def sysclk(self):
        sws = (self.cfgr >> 2) & 3
        if sws == 1:
            return 8e6
        if sws == 2:
            src = 8e6 if (self.cfgr >> 16) & 1 else 4e6
            mul = ((self.cfgr >> 18) & 0xF) + 2
            return src * min(mul, 16)
        return 8e6

    def read(self, off, t):
        return {0x00: self.cr, 0x04: self.cfgr, 0x08: self.cir, 0x14: self.ahbenr,
                0x18: self.apb2enr, 0x1C: self.apb1enr}.get(off, 0)

    def write(self, off, v, t):
        if off == 0x00:
            self.cr = v
            if v & (1 << 16):
                self.cr |= 1 << 17
            else:
                self.cr &= ~(1 << 17)
            if v & (1 << 24):
                self.cr |= 1 << 25
            else:
                self.cr &= ~(1 << 25)
        elif off == 0x04:
            sw = v & 3
            self.cfgr = (v & ~0xC) | (sw << 2)
            self.m.clock_changed(t)
        elif off == 0x08:
            self.cir = v & 0xFF
        elif off == 0x14:
            self.ahbenr = v
        elif off == 0x18:
            self.apb2enr = v
        elif off == 0x1C:
            self.apb1enr = v


class Gpio:
    """[RM §9.2]: CRL/CRH configuration, IDR = the pin levels (inputs from
    the board: buttons, break input), ODR, BSRR (set / reset, set wins),
    BRR."""

    def __init__(self, m, name):
        self.m, self.name = m, name
        self.crl = self.crh = 0x44444444
        self.odr = 0
        self.inputs = 0xFFFF  # pull-ups on the board: buttons released

    def read(self, off, t):
        if off == 0x08:
            return (self.inputs & 0xFFFF)
        return {0x00: self.crl, 0x04: self.crh, 0x0C: self.odr}.get(off, 0)

    def write(self, off, v, t):
        old = self.odr
        if off == 0x00:
            self.crl = v
        elif off == 0x04:
            self.crh = v
        elif off == 0x0C:
            self.odr = v & 0xFFFF
        elif off == 0x10:
            self.odr = (self.odr & ~(v >> 16)) | (v & 0xFFFF)
        elif off == 0x14:
            self.odr &= ~v & 0xFFFF
        if self.odr != old:
            self.m.on_gpio_out(self.name, old, self.odr, t)


class Plain:
    """Registers that only hold what is written (AFIO MAPR [RM §9.4], TIM3
    as the debug 'DAC' [RM §15], FLASH_ACR [RM §3.3.3]: LATENCY and PRFTBE
    read back, PRFTBS follows PRFTBE)."""

    def __init__(self, reset=None):
        self.r = dict(reset or {})

    def read(self, off, t):
        v = self.r.get(off, 0)
        return v

    def write(self, off, v, t):
        self.r[off] = v
