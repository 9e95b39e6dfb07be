"""The STM32F103 around the FOC image: Unicorn's Cortex-M3 core, the cycle
model of tools/bench/bench.py (imported, not copied) plus a flash
wait-state model, a software NVIC, the peripheral models of periph.py, and
the project's motor model (tools/plant, through build/pil/libpilplant.so)
fed from the PWM the image generates."""

import ctypes
import math
import os
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "bench"))
import bench  # noqa: E402  (the Cortex-M3 cycle model of make bench)
from bench import UA, Uc, UC_ARCH_ARM, UC_MODE_THUMB, UC_MODE_MCLASS, UC_HOOK_BLOCK, \
    UC_HOOK_CODE, UC_PROT_ALL  # noqa: E402
import periph  # noqa: E402
from periph import TICK_HZ  # noqa: E402

FLASH_ADDR, FLASH_SIZE = 0x08000000, 0x20000
RAM_ADDR, RAM_SIZE = 0x20000000, 0x5000
EXC_RETURN_PAGE = 0xFFFFF000

STATE_NAMES = bench.STATE_NAMES

# Deliberate modelling errors, NOT RM0008 (`pil.py run --diag NAME,...`):
# readings of the hardware the manual does not support, the mistakes a
# model writer could make.  They exist only to look for the model behind
# issue 16's swing (docs/pil.md, "The oscillation of issue 16: cause");
# off by default, never used by the tests or by `make pil`.
DIAG_ERRORS = {
    "ccr-nopreload": "CCR1..4 take effect when written, OCxPE ignored (RM0008 §14.4.7: at the update event)",
    "duty-nopreload": "CCR1..3 take effect when written, OCxPE ignored; CCR4 preloaded",
    "uev-every": "update event at every overflow and underflow, RCR ignored (RM0008 §14.3.3)",
    "uev-swap": "with RCR = 1, the update event at the other end of the count than the repetition counter's",
    "jeoc-at-trigger": "JEOC (and the interrupt) when the sequence starts; JDRx at each conversion's end (RM0008 §11.3.9: JEOC after the last)",
    "jdr-prev": "JDRx written with the previous sequence's results (at the next trigger); JEOC on time",
    "sample-at-trigger": "every conversion of a sequence sees the plant at the trigger instant (RM0008 §11.6: at the end of its sampling time)",
    "no-deadtime": "no dead time: the plant's bridge and the shunt window without DTG (RM0008 §14.3.13)",
    "no-deadtime-bridge": "no dead time in the plant's bridge only (the outputs follow OCxREF); shunt window with it",
    "no-deadtime-shunt": "no dead time in the shunt window only; the plant's bridge with it",
    "deadtime-wrong-edge": "the shunt's conduction window shortened at the low switch's turn-off instead of delayed at its turn-on",
    "adc-reentry": "the ADC interrupt taken again while active when JEOC rises (PM0056 §4.3.9: an active interrupt is not re-entered)",
    "jexttrig-ignored": "the injected trigger starts conversions whatever JEXTTRIG (RM0008 §11.12.3)",
    "pllmul-plus1": "PLLMUL decoded as field + 1 (x8, SYSCLK 64 MHz) where RM0008 §7.3.2 says field + 2 "
                    "(x9, 72 MHz): CPU, TIM1, ADC, USART 8/9 as fast against the plant's time",
}
FAULT_NAMES = None  # filled from include/foc/faults.h by pil.py


class PilImage(bench.Image):
    """bench.Image (symbols, functions, $t/$d mapping) for an image linked
    at the STM32's flash address instead of 0."""

    def __init__(self, path):
        try:
            super().__init__(path)
        except SystemExit:
            pass  # bench.Image wants its vector table at 0
        self.func_addr = {n: a for a, _, n in self.funcs}
        self.vectors = None
        for addr, blob in self.segments:
            if addr == FLASH_ADDR:
                self.vectors = struct.unpack_from("<2I", blob, 0)
        if self.vectors is None:
            raise SystemExit("pil: %s: no vector table at 0x%08x" % (path, FLASH_ADDR))
        self.objects_all = {}
        from elftools.elf.elffile import ELFFile
        with open(path, "rb") as f:
            for s in ELFFile(f).get_section_by_name(".symtab").iter_symbols():
                if s["st_info"]["type"] == "STT_OBJECT":
                    self.objects_all.setdefault(s.name, []).append((s["st_value"], s["st_size"]))


class Machine:
    def __init__(self, elf, plant_lib, layout, readings=None, flash_ws="rm0008",
                 cpu_scale=1.0, adc_latency=3.0, lsi_hz=40000.0, seed=1, shunt="lowside",
                 diag=frozenset()):
        self.img = PilImage(elf)
        self.diag = frozenset(diag)
        self.readings = dict(rcr_start="count", cc4_trigger="oc4", jdr_order="sequence")
        self.readings.update(readings or {})
        self.flash_ws_model = flash_ws
        self.shunt_model = shunt
        self.cpu_scale = cpu_scale
        self.adc_latency = adc_latency
        self.lsi_hz = lsi_hz
        self.sched = periph.Scheduler()
        self.sched_dirty = True
        self.t = 0.0
        self.cycles = 0.0          # CPU cycles (DWT base)
        self.dwt_on = False
        self.dwt_base = 0.0
        self.halted = None
        self.check_stops = bool(os.environ.get("PIL_CHECK_STOPS"))
        self.idle_ok = not os.environ.get("PIL_NO_IDLE_SKIP")
        # peripherals
        self.rcc = periph.Rcc(self)
        self.flash_acr = periph.Plain({0x00: 0x30})
        self.afio = periph.Plain()
        self.tim3 = periph.Plain()
        self.gpio = {k: periph.Gpio(self, k) for k in periph.GPIO_BASE}
        self.tim1 = periph.Tim1(self)
        self.adc1 = periph.Adc(self, 1)
        self.adc2 = periph.Adc(self, 2)
        self.usart = periph.Usart(self)
        self.iwdg = periph.Iwdg(self)
        self.systick = periph.SysTick(self)
        self.map = {}
        for base, dev in ((periph.RCC_BASE, self.rcc), (periph.FLASH_BASE_R, self.flash_acr),
                          (periph.AFIO_BASE, self.afio), (periph.TIM3_BASE, self.tim3),
                          (periph.TIM1_BASE, self.tim1), (periph.ADC1_BASE, self.adc1),
                          (periph.ADC2_BASE, self.adc2), (periph.USART1_BASE, self.usart),
                          (periph.IWDG_BASE, self.iwdg)):
            self.map[base] = dev
        for k, base in periph.GPIO_BASE.items():
            self.map[base] = self.gpio[k]
        self.unknown_access = {}
        # NVIC / SCB [PM §4.2, §4.3, §4.4]
        self.nvic_en = 0
        self.nvic_pend = 0
        self.ipr = bytearray(68)
        self.shpr = bytearray(12)
        self.aircr_prigroup = 0
        self.vtor = 0
        self.ccr = 0x0  # STKALIGN 0 (r1p1 reset value, option)
        self.demcr = 0
        self.dwt_ctrl = 0x40000000
        self.active = []           # exception numbers, nesting order
        self.pending_exc = set()   # system exceptions pending (SysTick)
        self.irq_check = True
        self.masked_pending = False
        self.exc_return_hit = False
        # statistics
        self.handler_time = {}     # exc -> list of (start_tick, cycles)
        self.exc_entry = []        # stack of [exc, start_tick, nested_cycles]
        self.isr_log = []          # ADC ISR: (t_start, cycles, t_end)
        self.tail_chains = 0
        # plant
        self.lib = ctypes.CDLL(plant_lib)
        self.lib.pil_new_board.restype = ctypes.c_void_p
        self.lib.pil_new_board.argtypes = [ctypes.c_uint, ctypes.POINTER(ctypes.c_double)]
        for fn, args in (("pil_set_active", [ctypes.c_void_p, ctypes.c_int] + [ctypes.c_double] * 3),
                         ("pil_advance", [ctypes.c_void_p, ctypes.c_double]),
                         ("pil_state", [ctypes.c_void_p, ctypes.POINTER(ctypes.c_double)]),
                         ("pil_cmd", [ctypes.c_void_p, ctypes.c_int, ctypes.c_double])):
            getattr(self.lib, fn).argtypes = args
            getattr(self.lib, fn).restype = None
        board = (ctypes.c_double * 16)()
        self.plant = self.lib.pil_new_board(seed, board)
        (self.pwm_hz, self.vdc_fs, self.i_fs, self.vref, self.temp_v0, self.temp_slope,
         _bits, self.deadtime_s, self.vdc_nom, self.pole_pairs, self.speed_base) = list(board)[:11]
        self.plant_t = 0.0
        self.stbuf = (ctypes.c_double * 12)()
        self.bridge_state = (0, (0.0, 0.0, 0.0))
        self.lib.pil_set_active(self.plant, 0, 0.0, 0.0, 0.0)
        self.plant_deadtime_from_image = True
        self.temp_degc = 25.0
        self.pot_fraction = 0.0
        self.bkin_low = False
        self.layout = layout
        self.ctrl_addr = None
        for addr, size in self.img.objects_all.get("ctrl", []):
            if size == layout["size"]:
                self.ctrl_addr = addr
        # per-conversion records
        self.conv_snap = None      # plant state at the sequence's first current sample
        self.trig_t = None
        self.jeoc_t = None
        self.rows_cb = None
        self.tx_cb = None
        self.uev_cb = None
        self._clocks()
        self.idle_last = None
        self.idle_dirty = True
        self.idle_skipped = 0.0
        self._build_cpu()

    # ------------------------------------------------------------ clocks --
    def cpu_hz(self):
        return self.rcc.sysclk()

    def cpu_ticks(self):
        return self.tpc

    def _clocks(self):
        self.tpc = TICK_HZ / self.cpu_hz()
        self.ws = self._wait_states()
        self.tpc_scaled = self.tpc * self.cpu_scale

    def pclk2_ticks(self):
        return self.cpu_ticks()  # PPRE2 = 1 in this image (APB2 = HCLK)

    def adc_clock_ticks(self):
        div = [2, 4, 6, 8][(self.rcc.cfgr >> 14) & 3]  # [RM §7.3.2 ADCPRE]
        return div * self.pclk2_ticks()

    def clock_changed(self, t):
        self._clocks()

    def wait_states(self):
        return self.ws

    def _wait_states(self):
        """FLASH_ACR LATENCY as programmed [RM §3.3.3]: 0 below 24 MHz, 1
        up to 48, 2 up to 72; the model option 'zero' ignores it."""
        if self.flash_ws_model == "zero":
            return 0
        return self.flash_acr.r.get(0, 0x30) & 7

    # --------------------------------------------------------------- CPU --
    def _build_cpu(self):
        img = self.img
        uc = self.uc = Uc(UC_ARCH_ARM, UC_MODE_THUMB | UC_MODE_MCLASS)
        try:
            uc.ctl_set_cpu_model(UA.UC_CPU_ARM_CORTEX_M3)
        except Exception:
            pass
        uc.mem_map(0, FLASH_SIZE, UC_PROT_ALL)             # boot alias [RM §3.4]
        uc.mem_map(FLASH_ADDR, FLASH_SIZE, UC_PROT_ALL)
        uc.mem_map(RAM_ADDR, 0x10000, UC_PROT_ALL)
        uc.mem_map(EXC_RETURN_PAGE, 0x1000, UC_PROT_ALL)
        uc.mem_write(EXC_RETURN_PAGE, b"\xfe\xe7" * 0x800)  # b . (never run)
        for addr, blob in img.segments:
            uc.mem_write(addr, blob)
            if addr == FLASH_ADDR:
                uc.mem_write(0, blob)
        uc.mmio_map(0x40000000, 0x30000, self._pread, None, self._pwrite, None)
        uc.mmio_map(0xE0000000, 0x100000, self._sread, None, self._swrite, None)
        self.table = bench.decode_all(img)
        self.blocks = {}
        self.ws_cache = {}
        self.prev = None
        self.errors = []
        self._fast_block_hook(FLASH_ADDR, FLASH_ADDR + FLASH_SIZE - 1)
        uc.hook_add(UC_HOOK_BLOCK, self._excret, None, EXC_RETURN_PAGE, 0xFFFFFFFF)
        for a, ins in self.table.items():
            if ins.cond is not None and ins.base > 1:
                uc.hook_add(UC_HOOK_CODE, self._cond, ins.base - 1, a, a)
            if ins.kind == bench.K_DIV:
                uc.hook_add(UC_HOOK_CODE, self._div, (ins.div_regs[0], ins.div_regs[1], ins.signed), a, a)
        uc.reg_write(UA.UC_ARM_REG_SP, img.vectors[0])
        self.pc = img.vectors[1] & ~1

    def _fast_block_hook(self, begin, end):
        """The block hook registered through Unicorn's C interface with a
        plain ctypes callback: the Python binding's two wrapper layers cost
        as much as the hook itself, and it runs once per executed block."""
        import unicorn.unicorn as uu
        blk = self._block
        uc = self.uc
        m = self
        P = bench.P_REFILL

        def cb(handle, addr, size, user):
            # the common case of _block, inlined: no stop, block cost known
            if m.t >= m.stop_t or m.irq_check or m.masked_pending:
                return blk(uc, addr, size, None)
            r = m.ws_cache.get((addr, size))
            if r is None:
                return blk(uc, addr, size, None)
            prev = m.prev
            c = r[0] + (P + m.ws if (prev is not None and prev.branch and addr != prev.fall) else 0)
            m.cycles += c * m.cpu_scale
            m.t += c * m.tpc_scaled
            m.prev = r[1]
        self._cb_keep = uu.UC_HOOK_CODE_CB(cb)
        h = uu.uc_hook_h()
        st = uu._uc.uc_hook_add(uc._uch, ctypes.byref(h), UC_HOOK_BLOCK,
                                ctypes.cast(self._cb_keep, uu.UC_HOOK_CODE_CB),
                                ctypes.c_void_p(0), ctypes.c_uint64(begin), ctypes.c_uint64(end))
        if st != 0:
            raise SystemExit("pil: uc_hook_add failed (%d)" % st)

    def _block_cost(self, addr, size):
        """Cycles of a translation block: bench.make_block's Cortex-M3
        cost, plus the flash wait-state model (docs/pil.md):
          - each PC-relative load (literal pool, in flash) waits LATENCY;
          - instruction fetch: with the prefetch buffer on, the fetch unit
            reads 64 bits per (1 + LATENCY) cycles [RM §3.3.3 "Read
            interface"]; a block whose code needs more fetch cycles than it
            executes is stretched to its fetch time.
        The taken-branch refill waits LATENCY more (added by the caller)."""
        ws = self.ws
        key = (addr, size)
        blk = self.blocks.get((addr, size))
        if blk is None:
            blk = self.blocks[(addr, size)] = bench.make_block(self.table, addr, size)
        cost = blk.cost
        if ws:
            lits = 0
            a = addr
            while a < addr + size:
                ins = self.table[a]
                if ins.kind == bench.K_LDR and ins.addr_regs & (1 << 15):
                    lits += 1
                a = ins.fall
            prefetch = (self.flash_acr.r.get(0, 0x30) >> 4) & 1
            per_word = (1 + ws) if prefetch else (1 + ws) * 2
            fetch = math.ceil(size / 8.0) * per_word
            cost = max(cost + lits * ws, fetch + lits * ws)
        r = (cost, blk.last)
        self.ws_cache[key] = r
        return r

    def _block(self, uc, addr, size, _):
        try:
            if self.t >= self.stop_t or self.irq_check or (
                    self.masked_pending and uc.reg_read(UA.UC_ARM_REG_PRIMASK) == 0):
                # Unicorn does not run a block whose hook stopped it, but
                # the PC it reports then may be stale: resume here
                uc.emu_stop()
                self.stopped_at = addr
                if self.check_stops:
                    self.stop_regs = [uc.reg_read(r) for r in bench.UC_REG[:15]]
                return
            prev = self.prev
            cyc = bench.P_REFILL + self.ws if (prev is not None and prev.branch and addr != prev.fall) else 0
            r = self.ws_cache.get((addr, size))
            if r is None:
                r = self._block_cost(addr, size)
            self.cycles += (cyc + r[0]) * self.cpu_scale
            self.t += (cyc + r[0]) * self.tpc_scaled
            self.prev = r[1]
        except Exception as e:
            self.errors.append(e)
            uc.emu_stop()

    def _cond(self, uc, addr, size, extra):
        c = extra * self.cpu_scale
        self.cycles += c
        self.t += c * self.cpu_ticks()

    def _div(self, uc, addr, size, regs):
        n = uc.reg_read(bench.UC_REG[regs[0]])
        d = uc.reg_read(bench.UC_REG[regs[1]])
        c = (bench.div_cycles(n, d, regs[2]) - 2) * self.cpu_scale
        self.cycles += c
        self.t += c * self.cpu_ticks()

    def _excret(self, uc, addr, size, _):
        self.exc_return_hit = True
        uc.emu_stop()

    def add_cycles(self, n):
        c = n * self.cpu_scale
        self.cycles += c
        self.t += c * self.cpu_ticks()

    # -------------------------------------------------------- bus access --
    def _dev(self, addr):
        base = addr & ~0x3FF
        return self.map.get(base), addr - base

    def _pread(self, uc, off, size, _):
        addr = 0x40000000 + off
        self.catch_up()
        dev, o = self._dev(addr)
        if dev is None:
            self.unknown_access[addr] = self.unknown_access.get(addr, 0) + 1
            return 0
        v = dev.read(o & ~3, self.t)
        return (v >> (8 * (o & 3))) & ((1 << (8 * size)) - 1)

    def _pwrite(self, uc, off, size, value, _):
        addr = 0x40000000 + off
        self.catch_up()
        dev, o = self._dev(addr)
        if dev is None:
            self.unknown_access[addr] = self.unknown_access.get(addr, 0) + 1
            return
        if size < 4 and (o & 3):
            cur = dev.read(o & ~3, self.t)
            sh = 8 * (o & 3)
            mask = ((1 << (8 * size)) - 1) << sh
            value = (cur & ~mask) | ((value << sh) & mask)
        dev.write(o & ~3, value & 0xFFFFFFFF, self.t)
        self.idle_dirty = True
        if dev is self.flash_acr:
            self._clocks()
            self.ws_cache = {}

    def dwt_cyccnt(self):
        return int(self.cycles - self.dwt_base) & 0xFFFFFFFF if self.dwt_on else \
            int(self.dwt_frozen) & 0xFFFFFFFF

    def _sread(self, uc, off, size, _):
        addr = 0xE0000000 + off
        self.catch_up()
        w = addr & ~3
        sh = 8 * (addr & 3)
        mask = (1 << (8 * size)) - 1
        if 0xE000E400 <= addr < 0xE000E400 + len(self.ipr):
            return int.from_bytes(self.ipr[addr - 0xE000E400:addr - 0xE000E400 + size], "little")
        if 0xE000ED18 <= addr < 0xE000ED24:
            return int.from_bytes(self.shpr[addr - 0xE000ED18:addr - 0xE000ED18 + size], "little")
        if 0xE000E010 <= w <= 0xE000E01C:
            v = self.systick.read(w - 0xE000E010, self.t)
        elif w == 0xE0001004:
            v = self.dwt_cyccnt()
        elif w == 0xE0001000:
            v = self.dwt_ctrl
        elif w == 0xE000EDFC:
            v = self.demcr
        elif w == 0xE000ED08:
            v = self.vtor
        elif w == 0xE000ED0C:
            v = 0xFA050000 | (self.aircr_prigroup << 8)
        elif w == 0xE000ED14:
            v = self.ccr
        elif w in (0xE000E100, 0xE000E104, 0xE000E180, 0xE000E184):
            v = (self.nvic_en >> (32 * ((w >> 2) & 1))) & 0xFFFFFFFF
        elif w in (0xE000E200, 0xE000E204, 0xE000E280, 0xE000E284):
            v = (self.nvic_pend >> (32 * ((w >> 2) & 1))) & 0xFFFFFFFF
        elif w == 0xE000ED00:
            v = 0x411FC231  # CPUID: Cortex-M3 r1p1 [PM §4.4.1]
        else:
            self.unknown_access[addr] = self.unknown_access.get(addr, 0) + 1
            v = 0
        return (v >> sh) & mask

    def _swrite(self, uc, off, size, value, _):
        addr = 0xE0000000 + off
        self.catch_up()
        self.irq_check = True
        self.idle_dirty = True
        if 0xE000E400 <= addr < 0xE000E400 + len(self.ipr):
            o = addr - 0xE000E400
            # [PM §4.2.7] only the top 4 bits are implemented on STM32
            for k in range(size):
                self.ipr[o + k] = ((value >> (8 * k)) & 0xF0)
            return
        if 0xE000ED18 <= addr < 0xE000ED24:
            o = addr - 0xE000ED18
            for k in range(size):
                self.shpr[o + k] = ((value >> (8 * k)) & 0xF0)
            return
        w = addr & ~3
        if 0xE000E010 <= w <= 0xE000E01C:
            self.systick.write(w - 0xE000E010, value, self.t)
        elif w == 0xE0001004:
            self.dwt_base = self.cycles - value
            self.dwt_frozen = value
        elif w == 0xE0001000:
            # [ARMv7-M ARM C1.8.7 DWT_CTRL.CYCCNTENA], counting needs
            # DEMCR.TRCENA [C1.6.5]
            on = bool(value & 1) and bool(self.demcr & (1 << 24))
            if on and not self.dwt_on:
                self.dwt_base = self.cycles - getattr(self, "dwt_frozen", 0)
            self.dwt_on = on
            self.dwt_ctrl = value
        elif w == 0xE000EDFC:
            self.demcr = value
        elif w == 0xE000ED08:
            self.vtor = value & 0x3FFFFF80  # [PM §4.4.4]
        elif w == 0xE000ED0C:
            if (value >> 16) == 0x05FA:    # [PM §4.4.5] VECTKEY
                self.aircr_prigroup = (value >> 8) & 7
        elif w == 0xE000ED14:
            self.ccr = value
        elif w in (0xE000E100, 0xE000E104):
            self.nvic_en |= (value & 0xFFFFFFFF) << (32 * ((w >> 2) & 1))
            self.irq_lines(self.t)
        elif w in (0xE000E180, 0xE000E184):
            self.nvic_en &= ~((value & 0xFFFFFFFF) << (32 * ((w >> 2) & 1)))
        elif w in (0xE000E200, 0xE000E204):
            self.nvic_pend |= (value & 0xFFFFFFFF) << (32 * ((w >> 2) & 1))
        elif w in (0xE000E280, 0xE000E284):
            self.nvic_pend &= ~((value & 0xFFFFFFFF) << (32 * ((w >> 2) & 1)))
        else:
            self.unknown_access[addr] = self.unknown_access.get(addr, 0) + 1

    # -------------------------------------------------------------- NVIC --
    def irq_level(self, irq):
        if irq == periph.IRQ_ADC1_2:
            a1, a2 = self.adc1, self.adc2
            return bool((a1.sr & 4 and a1.cr1 & (1 << 7)) or (a2.sr & 4 and a2.cr1 & (1 << 7)) or
                        (a1.sr & 2 and a1.cr1 & (1 << 5)) or (a2.sr & 2 and a2.cr1 & (1 << 5)))
        if irq == periph.IRQ_TIM1_UP:
            return bool(self.tim1.sr & 1 and self.tim1.dier & 1)
        if irq == periph.IRQ_TIM1_BRK:
            return bool(self.tim1.sr & 0x80 and self.tim1.dier & 0x80)
        return False

    def irq_lines(self, t):
        """[PM §4.3.9 "Level-sensitive and pulse interrupts"]: an asserted
        line pends its interrupt unless it is active; the pending bit is
        cleared on entry; a line still asserted when the handler returns
        pends it again."""
        for irq in (periph.IRQ_ADC1_2, periph.IRQ_TIM1_UP, periph.IRQ_TIM1_BRK):
            if self.irq_level(irq) and (16 + irq) not in self.active:
                if not self.nvic_pend >> irq & 1:
                    self.nvic_pend |= 1 << irq
                    self.irq_check = True

    def pend_exc(self, exc):
        self.pending_exc.add(exc)
        self.irq_check = True

    def prio(self, exc):
        if exc >= 16:
            return self.ipr[exc - 16]
        if exc >= 4:
            return self.shpr[exc - 4]
        return {1: -3, 2: -2, 3: -1}[exc]

    def group(self, p):
        """[PM §4.4.5 AIRCR PRIGROUP, table 45]: the group (preemption)
        priority is the priority field above bit PRIGROUP."""
        if p < 0:
            return p
        return p >> (self.aircr_prigroup + 1)

    def exec_prio(self):
        if not self.active:
            return 256
        return min(self.group(self.prio(e)) for e in self.active)

    def best_pending(self):
        cands = [16 + i for i in range(68) if (self.nvic_pend >> i & 1) and (self.nvic_en >> i & 1)]
        cands += list(self.pending_exc)
        if not cands:
            return None
        return min(cands, key=lambda e: (self.group(self.prio(e)), self.prio(e), e))

    def take_exceptions(self):
        """Exception entry [PM §2.3.7]: preemption when the pending
        exception's group priority is higher (lower number) than the
        execution priority and PRIMASK is 0; 8 words stacked (R0-R3, R12,
        LR, return address, xPSR), 4-byte or 8-byte aligned by
        CCR.STKALIGN [PM §4.4.7]; LR = EXC_RETURN; 12 cycles (Cortex-M3
        TRM, "Interrupt latency")."""
        uc = self.uc
        self.masked_pending = False
        while True:
            e = self.best_pending()
            if e is None:
                return
            if self.group(self.prio(e)) >= self.exec_prio() and not (
                    self.adc_reenter and e == 16 + periph.IRQ_ADC1_2):
                return
            if uc.reg_read(UA.UC_ARM_REG_PRIMASK) & 1:
                self.masked_pending = True
                return
            sp = uc.reg_read(UA.UC_ARM_REG_SP)
            xpsr = uc.reg_read(UA.UC_ARM_REG_XPSR)
            frame_align = 0
            if (self.ccr >> 9) & 1 and (sp & 4):
                frame_align = 1
                sp -= 4
            sp -= 32
            regs = [uc.reg_read(r) for r in (UA.UC_ARM_REG_R0, UA.UC_ARM_REG_R1, UA.UC_ARM_REG_R2,
                                              UA.UC_ARM_REG_R3, UA.UC_ARM_REG_R12, UA.UC_ARM_REG_LR)]
            regs += [self.pc, (xpsr & ~(1 << 9) & ~0x1FF) | (frame_align << 9) | 0x01000000 |
                     (self.active[-1] if self.active else 0)]
            uc.mem_write(sp, struct.pack("<8I", *[r & 0xFFFFFFFF for r in regs]))
            uc.reg_write(UA.UC_ARM_REG_SP, sp)
            uc.reg_write(UA.UC_ARM_REG_LR, 0xFFFFFFF1 if self.active else 0xFFFFFFF9)
            self._activate(e, 12)

    def _activate(self, e, entry_cycles):
        if e >= 16:
            self.nvic_pend &= ~(1 << (e - 16))
            if e == 16 + periph.IRQ_ADC1_2:
                self.adc_reenter = False
        else:
            self.pending_exc.discard(e)
        vt = self.vtor
        vec = struct.unpack("<I", self.uc.mem_read(vt + 4 * e, 4))[0]
        if self.exc_entry:
            outer = self.exc_entry[-1]
            outer[2] += self.t - outer[1]  # preempted: its clock stops
        self.add_cycles(entry_cycles)
        self.active.append(e)
        self.idle_dirty = True
        self.exc_entry.append([e, self.t, 0.0])
        self.pc = vec & ~1
        self.prev = None
        if self.on_entry:
            self.on_entry(e, self.t)

    def exception_return(self):
        """[PM §2.3.7 "Exception return"]: EXC_RETURN in PC; a pending
        exception that may preempt the level being returned to is
        tail-chained (6 cycles, no unstacking); otherwise the frame is
        popped (12 cycles)."""
        uc = self.uc
        e = self.active.pop()
        rec = self.exc_entry.pop()
        run = rec[2] + (self.t - rec[1])
        if self.exc_entry:
            self.exc_entry[-1][1] = self.t
        self.handler_done(e, run / self.cpu_ticks(), self.t)
        if e >= 16 and self.irq_level(e - 16):
            self.nvic_pend |= 1 << (e - 16)
        nxt = self.best_pending()
        if nxt is not None and self.group(self.prio(nxt)) < self.exec_prio() and \
                not uc.reg_read(UA.UC_ARM_REG_PRIMASK) & 1:
            self.tail_chains += 1
            uc.reg_write(UA.UC_ARM_REG_LR, 0xFFFFFFF1 if self.active else 0xFFFFFFF9)
            self._activate(nxt, 6)
            return
        sp = uc.reg_read(UA.UC_ARM_REG_SP)
        r = struct.unpack("<8I", uc.mem_read(sp, 32))
        for reg, v in zip((UA.UC_ARM_REG_R0, UA.UC_ARM_REG_R1, UA.UC_ARM_REG_R2, UA.UC_ARM_REG_R3,
                           UA.UC_ARM_REG_R12, UA.UC_ARM_REG_LR), r[:6]):
            uc.reg_write(reg, v)
        sp += 32 + (4 if (r[7] >> 9) & 1 else 0)
        uc.reg_write(UA.UC_ARM_REG_SP, sp)
        uc.reg_write(UA.UC_ARM_REG_XPSR, r[7] & 0xF8000000 | 0x01000000)
        self.pc = r[6] & ~1
        self.prev = None
        self.add_cycles(12)
        if self.exc_entry:
            self.exc_entry[-1][1] = self.t

    # --------------------------------------------------------- main loop --
    def catch_up(self):
        h = self.sched.heap
        if h and h[0][0] <= self.t:
            self.idle_dirty = True
            self.sched.run_until(self.t)

    def idle_probe(self):
        """Called when thread code polls USART1 SR and finds nothing.  If
        nothing happened since the previous poll (no register write, no
        event, no exception), the main loop is idling: every further turn
        is the same until the next scheduled event, so time jumps over
        whole turns (the interrupt then comes at most one turn, ~90
        cycles, off the instant a cycle-by-cycle run would have it)."""
        if self.active:
            self.idle_last = None
            return
        t = self.t
        if self.idle_last is not None and not self.idle_dirty and self.idle_ok:
            turn = t - self.idle_last
            h = self.sched.heap
            if h and turn > 0:
                nxt = min(e[0] for e in h)
                k = int((nxt - t) / turn) - 1
                if k > 0:
                    self.t += k * turn
                    self.cycles += k * turn / self.tpc
                    self.idle_skipped += k * turn
        self.idle_last = self.t
        self.idle_dirty = False

    def run(self, t_end):
        uc = self.uc
        while self.t < t_end and self.halted is None:
            self.catch_up()
            self.take_exceptions()
            nw = self.sched.next_wake()
            self.stop_t = min(nw if nw is not None else t_end, t_end)
            self.irq_check = False
            self.exc_return_hit = False
            self.stopped_at = None
            try:
                uc.emu_start(self.pc | 1, 0xFFFFFFFF)
            except Exception as ex:
                pc = uc.reg_read(UA.UC_ARM_REG_PC)
                if pc >= 0xFFFFFF00 and self.active:
                    # QEMU's M-profile core stops on an EXC_RETURN branch
                    # outside its own handler mode: the return is ours
                    self.exception_return()
                    continue
                self.halted = "cpu fault: %s at pc=0x%08x" % (ex, pc)
                break
            if self.errors:
                raise self.errors[0]
            if self.exc_return_hit:
                self.exception_return()
            elif self.stopped_at is not None:
                if self.check_stops:
                    now = [uc.reg_read(r) for r in bench.UC_REG[:15]]
                    if now != self.stop_regs:
                        raise SystemExit("pil: the stopped block ran (0x%x)" % self.stopped_at)
                self.pc = self.stopped_at
            else:
                self.pc = uc.reg_read(UA.UC_ARM_REG_PC) & ~1

    # -------------------------------------------------------------- plant --
    def plant_to(self, t):
        if t > self.plant_t:
            # --diag pllmul-plus1 (NOT RM0008): every clock of the chip 8/9
            # as fast, i.e. the plant sees 9/8 of the time of the ticks
            k = 9.0 / 8.0 if "pllmul-plus1" in self.diag else 1.0
            self.lib.pil_advance(self.plant, (t - self.plant_t) / TICK_HZ * k)
            self.plant_t = t

    def plant_state(self, t):
        self.plant_to(t)
        self.lib.pil_state(self.plant, self.stbuf)
        return list(self.stbuf)

    def update_bridge(self, t):
        mode, d = self.tim1.bridge()
        if (mode, d) != self.bridge_state:
            self.plant_to(t)
            self.bridge_state = (mode, d)
            self.lib.pil_set_active(self.plant, mode, d[0], d[1], d[2])
            if self.plant_deadtime_from_image:
                dt = 0 if ({"no-deadtime", "no-deadtime-bridge"} & self.diag) else self.tim1.deadtime_ticks()
                self.lib.pil_cmd(self.plant, 16, dt / TICK_HZ)

    def bkin_active(self):
        return self.bkin_low and (self.tim1.bdtr >> 12) & 1

    def set_bkin(self, t, low):
        self.bkin_low = low
        g = self.gpio["E"]
        g.inputs = (g.inputs & ~(1 << 15)) | (0 if low else 1 << 15)
        if low:
            self.tim1.break_input(t, 0)
        self.irq_check = True

    def adc_input(self, t, ch, adc_n, k):
        """Voltage at an ADC pin (board: docs/boards/stm3210b_mckit.md):
        shunt amplifiers centred on Vref/2 falling for current into the
        motor, bus divider, NTC, potentiometer."""
        st = self.plant_state(t)
        # the CSV's plant state: at ADC2's first phase-current sample (the
        # instant the currents are read, whatever the sequence puts first)
        if adc_n == 2 and k == self.adc2.first_current_k:
            self.conv_snap = (t, st)
        half = self.vref / 2.0
        if ch in (11, 12, 13):
            i = self.shunt_current(t, ch - 11, st[ch - 11])
            return half - i / self.i_fs * half
        if ch == 3:
            return st[3] / self.vdc_fs * self.vref
        if ch == 10:
            return self.temp_v0 + self.temp_slope * self.temp_degc
        if ch == 14:
            return self.pot_fraction * self.vref
        return 0.0

    def shunt_current(self, t, ph, i):
        """What phase ph's low-side shunt carries at tick t (MB459: one
        shunt in each low-side leg).  The leg's low switch conducts from
        its compare value plus the dead time (the complementary output's
        delayed rising edge, RM0008 §14.3.13 "Complementary outputs and
        dead-time insertion") until the compare value on the way down; in
        the dead times the current flows through a diode: the low one
        (through the shunt) for current into the motor, the high one
        (not) for current out of it.  Bridge off: diodes only; low sides
        forced on: the shunt carries the phase current.  `--shunt ideal`
        reads the phase current at any instant (an average-value probe).
        The amplifier's settling after an edge is not modelled."""
        if self.shunt_model == "ideal":
            return i
        mode = self.bridge_state[0]
        if mode == 2:
            return i
        if mode == 0:
            return i if i > 0 else 0.0
        tim = self.tim1
        a = tim.arr_sh
        md = ((tim.ccmr1 >> 4) & 7, (tim.ccmr1 >> 12) & 7, (tim.ccmr2 >> 4) & 7)[ph]
        c = min(tim.ccr_sh[ph], a)
        pos = tim.phase(t)  # timeline 0 .. 2 ARR
        dt = 0 if ({"no-deadtime", "no-deadtime-shunt"} & self.diag) else tim.deadtime_ticks()
        if md == 4:
            return i
        if md != 6:
            return i if i > 0 else 0.0
        if "deadtime-wrong-edge" in self.diag:  # NOT RM0008 (--diag)
            if c <= pos < 2 * a - c - dt:
                return i
            if 2 * a - c - dt <= pos < 2 * a - c or c - dt <= pos < c:
                return i if i > 0 else 0.0
            return 0.0
        # PWM mode 1: high side on for pos < c or pos > 2a - c
        if c + dt <= pos < 2 * a - c:
            return i              # low switch on
        if c <= pos < c + dt or 2 * a - c <= pos < 2 * a - c + dt:
            return i if i > 0 else 0.0  # dead time: a diode
        return 0.0                # high switch on

    def adc_trigger(self, t, source):
        """[RM §11.12.3 JEXTSEL / JEXTTRIG, table 72 "External trigger for
        injected channels for ADC1 and ADC2"]: 000 TIM1 TRGO, 001 TIM1 CC4,
        111 JSWSTART; a rising edge starts the injected group; in dual
        injected simultaneous mode (ADC1 DUALMOD = 0101 [RM §11.9.2]) ADC2
        converts its own injected sequence at the same time."""
        a1 = self.adc1
        if not (a1.cr2 >> 15) & 1 and "jexttrig-ignored" not in self.diag:
            return
        sel = (a1.cr2 >> 12) & 7
        if (sel == 0 and source == "TRGO") or (sel == 1 and source == "CC4"):
            a1.start_injected(t)
            lead = a1.current_lead
            if ((a1.cr1 >> 16) & 0xF) == 5:
                self.adc2.start_injected(t)
                lead = self.adc2.current_lead
            # the trigger as the currents see it: the trigger itself when
            # they are converted first, later by the conversions before
            # them (the port's four-conversion sequences: two)
            self.trig_t = t + lead

    adc_reenter = False

    def on_jeoc(self, t, n):
        if n == 1:
            self.jeoc_t = t
            if "adc-reentry" in self.diag and (16 + periph.IRQ_ADC1_2) in self.active:
                # NOT PM0056 (--diag adc-reentry): a JEOC rising while the
                # handler runs enters it again, nested
                self.nvic_pend |= 1 << periph.IRQ_ADC1_2
                self.adc_reenter = True
                self.irq_check = True

    def on_uev(self, t, at_bottom):
        if self.uev_cb:
            self.uev_cb(t, at_bottom)

    def on_tx(self, b, t):
        if self.tx_cb:
            self.tx_cb(b, t)

    def on_gpio_out(self, port, old, new, t):
        if port == "D" and (old ^ new) & (1 << 13):  # brake resistor switch
            self.plant_to(t)
            self.lib.pil_cmd(self.plant, 6, 1.0 if new >> 13 & 1 else 0.0)

    def watchdog_reset(self, t):
        self.halted = "watchdog reset at t=%.6f s" % (t / TICK_HZ)

    on_entry = None

    def handler_done(self, e, cycles, t):
        pass

    # ------------------------------------------------------------ memory --
    def read_fw_unclean(self):
        """The port's own count of periods without two valid currents
        (stm32_isr_stats_t.unclean, the fifth word of the port's `stats`),
        -1 if the image has no such object: a diagnostic CSV column (where
        the unclean periods fall), not an oracle."""
        if not hasattr(self, "_unclean_addr"):
            objs = self.img.objects_all.get("stats", [])
            self._unclean_addr = objs[0][0] + 16 if len(objs) == 1 and objs[0][1] == 28 else None
        if self._unclean_addr is None:
            return -1
        return struct.unpack("<I", bytes(self.uc.mem_read(self._unclean_addr, 4)))[0]

    def read_ctrl(self):
        """The controller's fields (CSV columns only)."""
        out = {}
        if self.ctrl_addr is None:
            return out
        raw = bytes(self.uc.mem_read(self.ctrl_addr, self.layout["size"]))
        for name, (off, size) in self.layout["fields"].items():
            fmt = {1: "<B", 2: "<h", 4: "<i"}[size]
            if name in ("est_theta",):
                fmt = "<H"
            if name in ("state", "first") and size == 2:
                fmt = "<H"
            out[name] = struct.unpack_from(fmt, raw, off)[0]
        return out
