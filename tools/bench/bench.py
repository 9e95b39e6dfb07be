#!/usr/bin/python3
"""Cortex-M3 benchmark of the FOC core on an instruction-set simulator.

Runs the bench image (tools/bench/image.mk: the core at -O2, the frame
replay port and loop, the recorded frames) on Unicorn (QEMU's Thumb-2 CPU)
and reports, per control-step call, instruction counts and cycles estimated
with the Cortex-M3 timing model below; the core's flash and RAM from the
linker map; the worst-case stack of the ISR path from -fcallgraph-info=su
(-fstack-usage figures plus the call graph).

    bench.py check  --elf bench.elf --frames frames.bin [--hash 0x...]
        bit-exactness only: runs every frame (no timing hooks, fast) and
        fails unless every period's outputs equal the recorded ones (and,
        with --hash, the output hash equals the host replay's).
    bench.py report --elf bench.elf --frames frames.bin --build-dir DIR
        the full benchmark; ends with key=value lines.

Needs Debian's python3-unicorn, python3-capstone and python3-pyelftools,
which serve /usr/bin/python3 (run it with that interpreter).

Cycle model (Cortex-M3 TRM, ARM DDI 0337, "Cortex-M3 instructions" and
"Load/store timings"; zero wait states, no bus contention):
  data processing, MUL, saturate, extend, bit-field, CLZ   1
  MLA, MLS 2; SMULL/UMULL 5 and SMLAL/UMLAL 7 (the upper ends of 3-5, 4-7)
  SDIV/UDIV  2 + ceil(q/3), at most 12, where q = number of quotient bits
             (an estimate of the documented early termination, 2..12)
  LDR/LDRH/LDRB/LDRSH/LDRSB  2, or 1 right after a single LDR whose result
             is not used in this one's address (pipelined)
  STR with immediate offset 1; STR with register offset 2, 1 after an LDR
  LDRD/STRD 3; LDM/POP/STM/PUSH 1 + N (N registers)
  a load/store whose address register was written by the preceding data-
             processing instruction: +1 (no forwarding path)
  B, CBZ/CBNZ 1, plus P when taken; BL, BLX, BX 1 + P; TBB/TBH 2 + P;
  POP/LDM/LDR into PC, and ALU writes to PC, add P
  IT 1 (not folded); an instruction whose IT condition fails 1
  P (pipeline refill) = 2, the middle of the TRM's 1..3 (the count of
             refills is reported, so P = 1 and P = 3 bounds follow)
Exception entry and return (12 + 12 cycles, tail-chaining 6) are not part
of the measured function; the report adds them as a note.
"""

import argparse
import glob
import os
import re
import struct
import subprocess
import sys

try:
    from unicorn import (Uc, UcError, UC_ARCH_ARM, UC_MODE_THUMB, UC_MODE_MCLASS,
                         UC_HOOK_CODE, UC_HOOK_BLOCK, UC_PROT_ALL)
    from unicorn import arm_const as UA
    import capstone
    from capstone import arm_const as CA
    from elftools.elf.elffile import ELFFile
except ImportError as e:  # pragma: no cover
    sys.stderr.write(
        "bench.py: %s\n"
        "  needs Debian's python3-unicorn python3-capstone python3-pyelftools\n"
        "  (apt-get install python3-unicorn python3-capstone python3-pyelftools),\n"
        "  run with /usr/bin/python3\n" % e)
    sys.exit(2)

P_REFILL = 2
STATE_NAMES = ["IDLE", "CALIB", "ALIGN", "OPENLOOP", "RUN", "STOP", "BRAKE", "FAULT", "CATCH",
               "COMMISSION"]
LOOP_STATES = {2, 3, 4, 5, 6, 8, 9}  # ALIGN OPENLOOP RUN STOP BRAKE CATCH COMMISSION: current loop runs
EST_NAMES = ["sensored", "pll", "luenberger", "flux"]
FW_NAMES = ["off", "table", "voltage"]

HEADER_BYTES, SCENARIO_BYTES, FRAME_BYTES, IN_BYTES, OUT_BYTES = 64, 48, 52, 20, 32
F_RESET, F_SLOW = 0x01, 0x40

# ----------------------------------------------------------------- frames --


class Frames:
    """The recorded frame file (tools/bench/bench_io.h)."""

    def __init__(self, path):
        with open(path, "rb") as f:
            self.data = f.read()
        d = self.data
        if d[:8] != b"FOCBNCH1":
            raise SystemExit("bench.py: %s is not a frame file" % path)
        self.count, nsc, fbytes, self.slow_divider, self.pwm_hz = struct.unpack_from("<5I", d, 8)
        if fbytes != FRAME_BYTES:
            raise SystemExit("bench.py: %s: frame size %d, expected %d" % (path, fbytes, FRAME_BYTES))
        self.scenarios = []
        for i in range(nsc):
            p = HEADER_BYTES + i * SCENARIO_BYTES
            name = d[p:p + 32].split(b"\0")[0].decode()
            first, n = struct.unpack_from("<II", d, p + 32)
            est, fw, stop, brake, sens, olo, tun, shunts = d[p + 40:p + 48]
            self.scenarios.append(dict(name=name, first=first, count=n, estimator=est,
                                       fw_mode=fw, shunts=shunts, sensored_start=sens))
        self.base = HEADER_BYTES + nsc * SCENARIO_BYTES
        # per frame: scenario, state before the fast step, flags
        self.scenario_of = [0] * self.count
        self.state_before = [0] * self.count
        self.flags = [0] * self.count
        prev_state = 0
        for i in range(self.count):
            p = self.base + i * FRAME_BYTES
            flags = d[p + 15]
            sc = struct.unpack_from("<H", d, p + 18)[0]
            if flags & F_RESET:
                prev_state = 0  # foc_init: IDLE
            self.scenario_of[i] = sc
            self.state_before[i] = prev_state
            self.flags[i] = flags
            prev_state = d[p + IN_BYTES + 8]

    def expected(self, i):
        p = self.base + i * FRAME_BYTES + IN_BYTES
        return self.data[p:p + OUT_BYTES]


# ------------------------------------------------------------------ image --


class Image:
    def __init__(self, path):
        self.path = path
        with open(path, "rb") as f:
            elf = ELFFile(f)
            self.segments = []
            for seg in elf.iter_segments():
                if seg["p_type"] == "PT_LOAD" and seg["p_filesz"] > 0:
                    self.segments.append((seg["p_paddr"], seg.data()))
            self.funcs = []   # (addr, size, name)
            self.objects = {}  # name -> (addr, size)
            self.mapping = []  # ($t / $d mapping symbols) (addr, is_code)
            self.symbols = {}  # every named symbol -> value
            symtab = elf.get_section_by_name(".symtab")
            for s in symtab.iter_symbols():
                t = s["st_info"]["type"]
                if s.name:
                    self.symbols[s.name] = s["st_value"]
                if t == "STT_FUNC" and s["st_size"] > 0:
                    self.funcs.append((s["st_value"] & ~1, s["st_size"], s.name))
                elif t == "STT_OBJECT":
                    self.objects[s.name] = (s["st_value"], s["st_size"])
                elif s.name in ("$t", "$d") or s.name.startswith(("$t.", "$d.")):
                    self.mapping.append((s["st_value"], s.name.startswith("$t")))
            self.funcs.sort()
            self.mapping.sort()
            self.vectors = None
            for addr, blob in self.segments:
                if addr == 0:
                    self.vectors = struct.unpack_from("<2I", blob, 0)
            if self.vectors is None:
                raise SystemExit("bench.py: %s: no vector table at 0" % path)
        self.func_addr = {n: a for a, _, n in self.funcs}

    def code_bytes(self, addr, size):
        for base, blob in self.segments:
            if base <= addr and addr + size <= base + len(blob):
                return blob[addr - base:addr - base + size]
        raise KeyError(hex(addr))

    def code_ranges(self, addr, size):
        """[start, end) pieces of a function that are code (not literal
        pools), from the $t/$d mapping symbols."""
        end = addr + size
        marks = [(a, c) for a, c in self.mapping if addr < a < end]
        ranges, cur, is_code = [], addr, True
        for a, c in self.mapping:
            if a <= addr:
                is_code = c
        for a, c in marks:
            if is_code and a > cur:
                ranges.append((cur, a))
            cur, is_code = a, c
        if is_code and end > cur:
            ranges.append((cur, end))
        return ranges


def new_cpu(img, frames_data, mask=0xFFFFFFFF):
    """A Cortex-M3 with the image loaded: FLASH at 0, RAM at 0x20000000,
    the image's own copy of the frames at 0x60000000 (checked to be the
    frame file the report describes)."""
    mu = Uc(UC_ARCH_ARM, UC_MODE_THUMB | UC_MODE_MCLASS)
    try:
        mu.ctl_set_cpu_model(UA.UC_CPU_ARM_CORTEX_M3)
    except Exception:  # older unicorn: the default M-class CPU
        pass
    mu.mem_map(0x00000000, 0x80000, UC_PROT_ALL)
    mu.mem_map(0x20000000, 0x10000, UC_PROT_ALL)
    embedded = b""
    for addr, blob in img.segments:
        if addr >= 0x60000000:
            mu.mem_map(addr, (len(blob) + 0xFFFF) & ~0xFFFF, UC_PROT_ALL)
            embedded = blob
        mu.mem_write(addr, blob)
    if embedded[:len(frames_data)] != frames_data:
        raise SystemExit("bench.py: %s does not embed this frame file (rebuild the image)"
                         % img.path)
    # .data is copied from flash at reset: patch the initial value there
    maddr = img.symbols["bench_scenario_mask"]
    load = img.symbols["_data_load"] + (maddr - img.symbols["_data_start"])
    mu.mem_write(load, struct.pack("<I", mask))
    mu.reg_write(UA.UC_ARM_REG_SP, img.vectors[0])
    return mu


def read_result(mu, img):
    addr, size = img.objects["bench_result"]
    raw = bytes(mu.mem_read(addr, size))
    status, frames, mism, first, h, skipped = struct.unpack_from("<6I", raw, 0)
    return dict(status=status, frames=frames, mismatches=mism, first_mismatch=first,
                hash=h, skipped=skipped, first_actual=raw[24:24 + OUT_BYTES])


def run_plain(img, frames, mask=0xFFFFFFFF):
    mu = new_cpu(img, frames.data, mask)
    done = img.func_addr["bench_done"]
    try:
        mu.emu_start(img.vectors[1] | 1, done)
    except UcError as e:
        raise SystemExit("bench.py: the image faulted: %s at pc=0x%x"
                         % (e, mu.reg_read(UA.UC_ARM_REG_PC)))
    return read_result(mu, img)


# ------------------------------------------------------------ timing model --

K_ALU, K_LDR, K_STR_IMM, K_STR_REG, K_LDST_MULTI, K_BRANCH, K_IT, K_DIV = range(8)

REG_NUM = {}
for _n in range(13):
    REG_NUM[getattr(CA, "ARM_REG_R%d" % _n)] = _n
REG_NUM[CA.ARM_REG_SP] = 13
REG_NUM[CA.ARM_REG_LR] = 14
REG_NUM[CA.ARM_REG_PC] = 15
UC_REG = [getattr(UA, "UC_ARM_REG_R%d" % n) for n in range(13)] + [
    UA.UC_ARM_REG_SP, UA.UC_ARM_REG_LR, UA.UC_ARM_REG_PC]

LOADS = {"ldr", "ldrh", "ldrb", "ldrsh", "ldrsb", "ldrt", "ldrht", "ldrbt", "ldrsht",
         "ldrsbt", "ldrex", "ldrexb", "ldrexh"}
STORES = {"str", "strh", "strb", "strt", "strht", "strbt", "strex", "strexb", "strexh"}


class Insn:
    __slots__ = ("addr", "size", "fall", "kind", "base", "addr_regs", "dest", "cond",
                 "branch", "call", "writes_sp", "fn", "div_regs", "signed", "sp_step")


def bits(regs):
    m = 0
    for r in regs:
        if r in REG_NUM:
            m |= 1 << REG_NUM[r]
    return m


def decode_all(img):
    """Per-address instruction facts for every function in the image."""
    md = capstone.Cs(capstone.CS_ARCH_ARM, capstone.CS_MODE_THUMB | capstone.CS_MODE_MCLASS)
    md.detail = True
    table = {}
    for fn_index, (addr, size, name) in enumerate(img.funcs):
        for lo, hi in img.code_ranges(addr, size):
            for ins in md.disasm(img.code_bytes(lo, hi - lo), lo):
                table[ins.address] = classify(ins, fn_index)
    return table


def classify(ins, fn_index):
    i = Insn()
    i.addr, i.size = ins.address, ins.size
    i.fall = ins.address + ins.size
    i.fn = fn_index
    m = ins.mnemonic.split(".")[0]
    cc = ins.cc
    regs_read, regs_write = ins.regs_access()
    wr = bits(regs_write)
    i.dest = wr & 0x7FFF
    i.writes_sp = bool(wr & (1 << 13))
    i.addr_regs = 0
    i.call = False
    i.branch = False
    i.cond = None
    i.div_regs = None
    i.signed = False
    i.sp_step = 0  # SP change, where static (push/pop, add/sub sp, #imm)
    for op in ins.operands:
        if op.type == CA.ARM_OP_MEM:
            i.addr_regs = bits([op.mem.base, op.mem.index])
    base_mn = m
    # a condition suffix inside an IT block (capstone reports it as cc)
    if cc not in (CA.ARM_CC_AL, CA.ARM_CC_INVALID) and base_mn not in ("b", "cbz", "cbnz"):
        i.cond = cc
    if base_mn == "it" or re.fullmatch(r"it[te]{0,3}", base_mn):
        i.kind, i.base = K_IT, 1
    elif base_mn in ("b", "cbz", "cbnz"):
        i.kind, i.base, i.branch = K_BRANCH, 1, True
    elif base_mn in ("bl", "blx"):
        i.kind, i.base, i.branch, i.call = K_BRANCH, 1, True, True
    elif base_mn == "bx":
        i.kind, i.base, i.branch = K_BRANCH, 1, True
    elif base_mn in ("tbb", "tbh"):
        i.kind, i.base, i.branch = K_BRANCH, 2, True
    elif base_mn in ("pop", "ldm", "ldmia", "ldmdb", "ldmfd", "push", "stm", "stmia",
                     "stmdb", "stmfd"):
        n = sum(1 for op in ins.operands if op.type == CA.ARM_OP_REG)
        if base_mn.startswith("ld") or base_mn.startswith("st"):
            n -= 1  # the base register operand
        i.kind, i.base = K_LDST_MULTI, 1 + n
        if base_mn == "push":
            i.sp_step = -4 * n
        elif base_mn == "pop":
            i.sp_step = 4 * n
        if base_mn in ("pop", "ldm", "ldmia", "ldmdb", "ldmfd") and (wr & (1 << 15)):
            i.branch = True
        if base_mn.startswith("ld") or base_mn.startswith("st"):
            i.addr_regs = bits([ins.operands[0].reg])
        else:
            i.addr_regs = 1 << 13
    elif base_mn in ("ldrd", "strd"):
        i.kind, i.base = K_LDST_MULTI, 3
    elif base_mn in LOADS:
        i.kind, i.base = K_LDR, 2
        if wr & (1 << 15):
            i.branch = True
    elif base_mn in STORES:
        mem = [op for op in ins.operands if op.type == CA.ARM_OP_MEM]
        reg_offset = bool(mem) and mem[0].mem.index not in (0, CA.ARM_REG_INVALID)
        i.kind, i.base = (K_STR_REG, 2) if reg_offset else (K_STR_IMM, 1)
    elif base_mn in ("sdiv", "udiv"):
        i.kind, i.base = K_DIV, 2
        i.div_regs = (REG_NUM[ins.operands[1].reg], REG_NUM[ins.operands[2].reg])
        i.signed = base_mn == "sdiv"
    elif base_mn in ("mla", "mls"):
        i.kind, i.base = K_ALU, 2
    elif base_mn in ("smull", "umull"):
        i.kind, i.base = K_ALU, 5
    elif base_mn in ("smlal", "umlal"):
        i.kind, i.base = K_ALU, 7
    else:
        i.kind, i.base = K_ALU, 1
        if wr & (1 << 15):
            i.branch = True  # ALU write to PC
        ops = ins.operands
        if base_mn in ("sub", "add", "subw", "addw") and ops and ops[0].type == CA.ARM_OP_REG \
                and ops[0].reg == CA.ARM_REG_SP and ops[-1].type == CA.ARM_OP_IMM \
                and all(o.reg == CA.ARM_REG_SP for o in ops[:-1]):
            i.sp_step = (-1 if base_mn.startswith("sub") else 1) * ops[-1].imm
    return i


def div_cycles(n, d, signed):
    if signed:
        n = abs(n - (1 << 32) if n & 0x80000000 else n)
        d = abs(d - (1 << 32) if d & 0x80000000 else d)
    if d == 0 or n < d:
        return 2
    q = n.bit_length() - d.bit_length() + 1
    return min(12, 2 + (q + 2) // 3)


class Block:
    """Static facts of one translation block (a run of instructions that
    ends at a branch): its cost with every IT-conditional instruction
    skipped (1 cycle) and no divide early termination (2 cycles), the
    instruction count, the last instruction, and how far below its entry
    SP it pushes."""
    __slots__ = ("cost", "n", "last", "sp_low", "fn", "costs")


def make_block(table, addr, size):
    b = Block()
    cost, n, prev, depth, low = 0, 0, None, 0, 0
    a, end = addr, addr + size
    last = None
    costs = []
    while a < end:
        ins = table.get(a)
        if ins is None:
            raise RuntimeError("executed 0x%x, which is not code of any function" % a)
        n += 1
        if ins.cond is not None:
            cost += 1
            costs.append((a, 1))
            prev = None
        else:
            c = ins.base
            k = ins.kind
            if prev is not None and k in (K_LDR, K_STR_IMM, K_STR_REG, K_LDST_MULTI):
                if prev.kind == K_LDR and k != K_LDST_MULTI and not (prev.dest & ins.addr_regs):
                    if k != K_STR_IMM:
                        c -= 1
                elif prev.kind in (K_ALU, K_DIV) and (prev.dest & ins.addr_regs):
                    c += 1
            cost += c
            costs.append((a, c))
            prev = ins
            depth += ins.sp_step
            low = min(low, depth)
        last = ins
        a = ins.fall
    b.cost, b.n, b.last, b.sp_low = cost, n, last, low
    b.costs = costs
    b.fn = table[addr].fn
    return b


class Call:
    __slots__ = ("fn", "ret", "cyc0", "child")

    def __init__(self, fn, ret, cyc0):
        self.fn, self.ret, self.cyc0, self.child = fn, ret, cyc0, 0


def run_profiled(img, frames, target_frames, mask=0xFFFFFFFF):
    """Runs the image with the cycle model over the measured calls
    (foc_fast_step, foc_slow_step).  A block hook adds each translation
    block's static cost; the taken-branch refill is added when the next
    block does not start at the fall-through; instructions whose cost
    depends on data get their own hooks: IT-conditional ones that cost more
    than 1 when executed (Unicorn calls no hook for a skipped one), and
    divides.  Returns the replay result, per-call figures of the fast and
    slow steps and, for fast-step calls whose index is in target_calls,
    per-function inclusive/self cycles.  Per-call figures are returned per
    frame index (None for frames of skipped scenarios)."""
    table = decode_all(img)
    entries = {a: idx for idx, (a, _, _) in enumerate(img.funcs)}
    fast = img.func_addr["foc_fast_step"]
    slow = img.func_addr["foc_slow_step"]
    nf = len(img.funcs)
    incl, selfc, ncalls = [0] * nf, [0] * nf, [0] * nf
    fast_calls, slow_calls = [], []   # (cycles, insns, refills, stack, divides)
    blocks = {}
    bcount = {}   # target fast-step executions per block (line profile)
    # which frame each fast-step call belongs to: a first, untimed run
    # tells which scenarios the image can run (its estimators), the timed
    # run is limited to those
    mask &= ~run_plain(img, frames, mask)["skipped"] & 0xFFFFFFFF
    order = [i for i in range(frames.count) if mask >> frames.scenario_of[i] & 1]
    target_calls = set(k for k, i in enumerate(order) if i in target_frames)
    mu = new_cpu(img, frames.data, mask)
    sp_reg, lr_reg = UA.UC_ARM_REG_SP, UA.UC_ARM_REG_LR
    # mutable state in a list for speed: see the names below
    ACTIVE, CYC, INS, REF, DIVS, PREV, SP0, SPMIN, NFAST, TARGET = range(10)
    st = [None, 0, 0, 0, 0, None, 0, 0, 0, False]
    stack = []
    errors = []

    def block_hook(uc, addr, size, _):
        try:
            if st[ACTIVE] is None:
                if addr != fast and addr != slow:
                    return
                st[ACTIVE] = addr
                if addr == fast:
                    st[TARGET] = st[NFAST] in target_calls
                    st[NFAST] += 1
                else:
                    st[TARGET] = False
                st[CYC] = st[INS] = st[REF] = st[DIVS] = 0
                st[SP0] = st[SPMIN] = uc.reg_read(sp_reg)
                del stack[:]
                stack.append(Call(table[addr].fn, uc.reg_read(lr_reg) & ~1, 0))
                st[PREV] = None
            cyc = st[CYC]
            prev = st[PREV]
            if prev is not None and prev.branch and addr != prev.fall:
                cyc += P_REFILL
                st[REF] += 1
                if prev.call:
                    stack.append(Call(entries.get(addr, -1), prev.fall, cyc))
                elif addr in entries and entries[addr] != stack[-1].fn:
                    # tail call: it returns where its caller would have
                    stack.append(Call(entries[addr], stack[-1].ret, cyc))
            if addr == stack[-1].ret:
                while stack and addr == stack[-1].ret:
                    c = stack.pop()
                    total = cyc - c.cyc0
                    if st[TARGET] and c.fn >= 0:
                        incl[c.fn] += total
                        selfc[c.fn] += total - c.child
                        ncalls[c.fn] += 1
                    if stack:
                        stack[-1].child += total
                if not stack:
                    rec = (cyc, st[INS], st[REF], st[SP0] - st[SPMIN], st[DIVS])
                    (fast_calls if st[ACTIVE] == fast else slow_calls).append(rec)
                    st[ACTIVE] = None
                    return
            b = blocks.get((addr, size))
            if b is None:
                b = blocks[(addr, size)] = make_block(table, addr, size)
            if b.sp_low:
                sp = uc.reg_read(sp_reg) + b.sp_low
                if sp < st[SPMIN]:
                    st[SPMIN] = sp
            st[CYC] = cyc + b.cost
            if st[TARGET]:
                bcount[b] = bcount.get(b, 0) + 1
            st[INS] += b.n
            st[PREV] = b.last
        except Exception as e:  # a hook cannot raise through Unicorn
            errors.append(e)
            uc.emu_stop()

    def cond_hook(uc, addr, size, extra):
        # an IT-conditional instruction that executed: it costs `extra` more
        # than the 1 cycle its block counted
        if st[ACTIVE] is not None:
            st[CYC] += extra

    def div_hook(uc, addr, size, regs):
        if st[ACTIVE] is not None:
            n = uc.reg_read(UC_REG[regs[0]])
            d = uc.reg_read(UC_REG[regs[1]])
            st[CYC] += div_cycles(n, d, regs[2]) - 2
            st[DIVS] += 1

    lo, hi = img.symbols["_timed_start"], img.symbols["_timed_end"]
    mu.hook_add(UC_HOOK_BLOCK, block_hook, None, lo, hi - 1)
    for a, ins in table.items():
        if ins.cond is not None and ins.base > 1:
            mu.hook_add(UC_HOOK_CODE, cond_hook, ins.base - 1, a, a)
        if ins.kind == K_DIV:
            mu.hook_add(UC_HOOK_CODE, div_hook, (ins.div_regs[0], ins.div_regs[1], ins.signed), a, a)
    done = img.func_addr["bench_done"]
    try:
        mu.emu_start(img.vectors[1] | 1, done)
    except UcError as e:
        raise SystemExit("bench.py: the image faulted: %s at pc=0x%x"
                         % (e, mu.reg_read(UA.UC_ARM_REG_PC)))
    if errors:
        raise SystemExit("bench.py: %s" % errors[0])
    insn_cycles = {}
    for b, n in bcount.items():
        for addr, c in b.costs:
            insn_cycles[addr] = insn_cycles.get(addr, 0) + c * n
    prof = dict(incl=incl, self=selfc, calls=ncalls, insn_cycles=insn_cycles,
                target_calls=len(target_calls))
    res = read_result(mu, img)
    ran = [i for i in range(frames.count) if not res["skipped"] >> frames.scenario_of[i] & 1]
    if ran != order or len(ran) != len(fast_calls):
        raise SystemExit("bench.py: %d fast-step calls for %d frames" % (len(fast_calls), len(order)))
    fast_of = [None] * frames.count
    slow_of = [None] * frames.count
    k = 0
    for n, i in enumerate(ran):
        fast_of[i] = fast_calls[n]
        if frames.flags[i] & F_SLOW:
            slow_of[i] = slow_calls[k]
            k += 1
    if k != len(slow_calls):
        raise SystemExit("bench.py: %d slow-step calls, %d expected" % (len(slow_calls), k))
    return res, fast_of, slow_of, prof


# ----------------------------------------------------------- sizes, stack --

def map_sizes(map_path, img):
    """Flash and RAM of the core as linked: input sections from
    libfoc_core.a members, plus the C library / libgcc members the image
    pulls in (the harness calls none), plus the controller instance.
    Flash = code + read-only data + initial values of .data."""
    out_sec = None
    acc = {}
    with open(map_path) as f:
        lines = f.read().split("\n")
    start = next(i for i, l in enumerate(lines) if l.startswith("Linker script and memory map"))
    # an input section: " .name  0xADDR  0xSIZE file", or the name alone on
    # its line and "  0xADDR  0xSIZE file" on the next
    rx = re.compile(r"^ (?:\.\S+|COMMON)?\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S.*)$")
    for l in lines[start:]:
        m = re.match(r"^(\.\S+)", l)
        if m:
            out_sec = m.group(1)
            continue
        m = rx.match(l)
        if m and out_sec is not None:
            size = int(m.group(2), 16)
            fname = m.group(3).strip()
            if size == 0:
                continue
            if "libfoc_core.a(" in fname:
                who = "core"
            elif re.search(r"lib(gcc|c_nano|c|nosys|m)\.a\(", fname):
                who = "runtime"
            else:
                who = "harness"
            if out_sec in (".bss",):
                kind = "bss"
            elif out_sec == ".data":
                kind = "data"
            elif out_sec in (".text", ".rodata", ".harness", ".vectors", ".ARM.exidx"):
                kind = "text"
            else:
                continue  # .frames, debug sections
            acc[(who, kind)] = acc.get((who, kind), 0) + size

    res = {}
    for who in ("core", "runtime", "harness"):
        res[who] = dict((k, acc.get((who, k), 0)) for k in ("text", "data", "bss"))
    ctrl = img.objects.get("bench_ctrl", (0, 0))[1]
    res["ctrl"] = ctrl
    res["flash"] = sum(res[w]["text"] + res[w]["data"] for w in ("core", "runtime"))
    res["ram"] = sum(res[w]["data"] + res[w]["bss"] for w in ("core", "runtime")) + ctrl
    return res


def object_sizes(objs):
    """text, data, bss of the core's objects (arm-none-eabi-size -t)."""
    out = subprocess.run(["arm-none-eabi-size", "-t"] + objs, check=True,
                         capture_output=True, text=True).stdout.strip().split("\n")
    text, data, bss = (int(x) for x in out[-1].split()[:3])
    return text, data, bss


def worst_stack(ci_files, root):
    """Worst-case stack from `root` over the static call graph of the .ci
    files (-fcallgraph-info=su).  Returns (bytes, path, notes)."""
    usage, edges, qual = {}, {}, {}
    node_rx = re.compile(r'node: \{ title: "([^"]+)" label: "([^"]*)"')
    edge_rx = re.compile(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"')
    for path in ci_files:
        with open(path) as f:
            text = f.read()
        for m in node_rx.finditer(text):
            title, label = m.group(1), m.group(2)
            sm = re.search(r"\\n(\d+) bytes \((static|dynamic[^)]*)\)", label)
            if sm:
                usage[title] = int(sm.group(1))
                qual[title] = sm.group(2)
        for m in edge_rx.finditer(text):
            edges.setdefault(m.group(1), []).append(m.group(2))
    notes = set()
    memo = {}

    def resolve(name, ctx):
        if name in usage:
            return name
        # a static function of the same file
        fname = ctx.rsplit(":", 1)[0] if ":" in ctx else None
        if fname and "%s:%s" % (fname, name) in usage:
            return "%s:%s" % (fname, name)
        return None

    def walk(node, seen):
        if node in seen:
            raise SystemExit("bench.py: recursion through %s" % node)
        if node in memo:
            return memo[node]
        if qual.get(node, "static") != "static":
            notes.add("%s: %s stack" % (node, qual[node]))
        best, best_path = 0, []
        for t in edges.get(node, []):
            r = resolve(t, node)
            if r is None:
                notes.add("%s: not compiled with -fcallgraph-info (counted as 0)" % t)
                continue
            b, p = walk(r, seen | {node})
            if b > best:
                best, best_path = b, p
        memo[node] = (usage.get(node, 0) + best, [node] + best_path)
        return memo[node]

    total, path = walk(root, frozenset())
    return total, path, sorted(notes)


# ----------------------------------------------------------------- report --

def stats(xs):
    if not xs:
        return (0, 0.0, 0)
    return (min(xs), sum(xs) / len(xs), max(xs))


def cmd_check(a):
    img = Image(a.elf)
    frames = Frames(a.frames)
    r = run_plain(img, frames)
    print("frames=%d\nmismatches=%d\nhash=0x%08x\nskipped=0x%x"
          % (r["frames"], r["mismatches"], r["hash"], r["skipped"]))
    ok = r["status"] == 0 and r["frames"] == frames.count and r["mismatches"] == 0
    if r["status"] != 0:
        print("bench.py: the image rejected the frame file (built for another "
              "userparms.h or CONTROL_SLOW_DIVIDER?)")
    if r["skipped"]:
        print("bench.py: scenarios not run (estimator not built into the image): %s"
              % ", ".join(s["name"] for n, s in enumerate(frames.scenarios) if r["skipped"] >> n & 1))
    if r["mismatches"]:
        i = r["first_mismatch"]
        print("first_mismatch=%d (scenario %s)" % (i, frames.scenarios[frames.scenario_of[i]]["name"]))
        print("expected=%s\nactual=  %s" % (frames.expected(i).hex(), r["first_actual"].hex()))
    if a.hash is not None and int(a.hash, 0) != r["hash"]:
        print("bench.py: output hash differs from the host replay's (%s)" % a.hash)
        ok = False
    print("bitexact=%s" % ("PASS" if ok else "FAIL"))
    return 0 if ok else 1


def scenario_rows(w, frames, fast_of, scenarios):
    for si in scenarios:
        sc = frames.scenarios[si]
        rng = range(sc["first"], sc["first"] + sc["count"])
        for s in range(len(STATE_NAMES)):
            idx = [i for i in rng if frames.state_before[i] == s and fast_of[i] is not None]
            if not idx:
                continue
            c = stats([fast_of[i][0] for i in idx])
            n = stats([fast_of[i][1] for i in idx])
            w("%-27s %-9s %7d %6d/%7.1f/%6d %6d/%7.1f/%6d" % (sc["name"], STATE_NAMES[s], len(idx),
                                                            c[0], c[1], c[2], n[0], n[1], n[2]))


def write_line_profile(elf, prof, path):
    """Cycles per source line of the target's fast step, most first: each
    instruction at its own line (inlined code at the header's line), then
    at the line of the function it was inlined into (a statement's cost
    with what it inlines).  Taken-branch refills are not included."""
    addrs = sorted(prof["insn_cycles"])
    out = subprocess.run(["arm-none-eabi-addr2line", "-a", "-i", "-e", elf]
                         + ["0x%x" % x for x in addrs],
                         capture_output=True, text=True, check=True).stdout.split("\n")
    own, outer = {}, {}
    k = 0
    for x in addrs:
        while not out[k].startswith("0x"):
            k += 1
        k += 1
        frames = []
        while k < len(out) and out[k] and not out[k].startswith("0x"):
            frames.append(out[k].split(" (")[0])
            k += 1
        c = prof["insn_cycles"][x]
        own[frames[0]] = own.get(frames[0], 0) + c
        outer[frames[-1]] = outer.get(frames[-1], 0) + c
    n = max(prof["target_calls"], 1)
    with open(path, "w") as f:
        for title, table in (("own line", own), ("line of the calling function", outer)):
            f.write("# cycles per fast step by %s\n" % title)
            for loc, c in sorted(table.items(), key=lambda kv: -kv[1]):
                f.write("%8.1f  %s\n" % (c / n, loc))


def cmd_report(a):
    img = Image(a.elf)
    frames = Frames(a.frames)
    bdir = a.build_dir
    target_sc = 0
    tinfo = frames.scenarios[target_sc]
    # the target: periods of the first scenario with the current loop running
    target = set(i for i in range(tinfo["first"], tinfo["first"] + tinfo["count"])
                 if frames.state_before[i] in LOOP_STATES)
    result, fast_of, slow_of, prof = run_profiled(img, frames, target)
    if a.line_profile:
        write_line_profile(a.elf, prof, a.line_profile)
    ran_fw = [n for n in range(len(frames.scenarios)) if not result["skipped"] >> n & 1]
    if result["frames"] != sum(frames.scenarios[n]["count"] for n in ran_fw):
        raise SystemExit("bench.py: the image ran %d frames" % result["frames"])
    if target_sc not in ran_fw:
        raise SystemExit("bench.py: the image does not contain the target's estimator (%s):"
                         " set FOC_ESTIMATOR to FOC_EST_PLL" % EST_NAMES[tinfo["estimator"]])
    rows_all = []
    res_all = None
    if a.elf_all and result["skipped"]:
        img_all = Image(a.elf_all)
        res_all, fast_all, _, _ = run_profiled(img_all, frames, set(), result["skipped"])
        rows_all = [n for n in range(len(frames.scenarios)) if result["skipped"] >> n & 1
                    and not res_all["skipped"] >> n & 1]

    out = []
    w = out.append
    w("Cortex-M3 benchmark of the FOC core (instruction-set simulator: Unicorn %s,"
      " cycle model: tools/bench/bench.py)" % __import__("unicorn").__version__)
    w("firmware image %s (the core as firmware builds it; estimators built in: %s)"
      % (a.elf, ", ".join(sorted(set(EST_NAMES[frames.scenarios[n]["estimator"]] for n in ran_fw)))))
    w("frames %s: %d PWM periods at %d Hz, slow step every %d periods"
      % (a.frames, frames.count, frames.pwm_hz, frames.slow_divider))
    w("")
    w("Replay in the firmware image: frames=%d mismatches=%d (scenarios of other estimators"
      " not built in: %d)" % (result["frames"], result["mismatches"], len(frames.scenarios) - len(ran_fw)))
    if res_all is not None:
        w("Replay of those in the all-estimator image %s: frames=%d mismatches=%d"
          % (a.elf_all, res_all["frames"], res_all["mismatches"]))
    w("")
    w("foc_fast_step per scenario and state before the step, min/avg/max")
    w("%-27s %-9s %7s %22s %22s" % ("scenario", "state", "periods", "cycles", "instructions"))
    scenario_rows(w, frames, fast_of, ran_fw)
    if rows_all:
        w("(all-estimator image:)")
        scenario_rows(w, frames, fast_all, rows_all)
    w("")
    for sc in frames.scenarios:
        w("  %-27s estimator=%s field weakening=%s shunts=%d" % (
            sc["name"], EST_NAMES[sc["estimator"]] if sc["estimator"] < 4 else "?",
            FW_NAMES[sc["fw_mode"]] if sc["fw_mode"] < 3 else "?", sc["shunts"]))
    w("")

    tidx = sorted(target)
    fc = [fast_of[i][0] for i in tidx]
    fi = [fast_of[i][1] for i in tidx]
    fr = [fast_of[i][2] for i in tidx]
    fd = [fast_of[i][4] for i in tidx]
    fstack = max(x[3] for x in fast_of if x is not None)
    per = [fast_of[i][0] + (slow_of[i][0] if slow_of[i] else 0) for i in tidx]
    slows = [slow_of[i][0] for i in tidx if slow_of[i]]
    slow_ins = [slow_of[i][1] for i in tidx if slow_of[i]]
    all_slow = [x[0] for x in slow_of if x is not None]
    sstack = max(x[3] for x in slow_of if x is not None)
    fmin, favg, fmax = stats(fc)
    imin, iavg, imax = stats(fi)
    smin, savg, smax = stats(slows)
    amort = sum(per) / len(per)
    refill_avg = sum(fr) / len(fr)
    w("Target: %s (PLL estimator, field weakening %s, %d shunts), the %d periods with the"
      " current loop running (ALIGN, OPENLOOP, RUN, STOP)"
      % (tinfo["name"], FW_NAMES[tinfo["fw_mode"]], tinfo["shunts"], len(tidx)))
    w("  fast step      cycles min/avg/max %d / %.1f / %d   instructions %d / %.1f / %d"
      % (fmin, favg, fmax, imin, iavg, imax))
    w("  pipeline refills per fast step %.1f avg: avg cycles %.1f with P=1, %.1f with P=3;"
      " divides per step %.2f avg" % (refill_avg, favg - refill_avg, favg + refill_avg,
                                      sum(fd) / len(fd)))
    w("  slow step      cycles min/avg/max %d / %.1f / %d   instructions %.1f avg"
      "   (every %d periods)" % (smin, savg, smax, sum(slow_ins) / max(1, len(slow_ins)),
                                 frames.slow_divider))
    w("  fast + slow amortised per period: %.1f cycles avg; worst period (fast, then slow): %d"
      % (amort, max(per)))
    w("  at 72 MHz: fast step %.2f us avg, %.2f us max (+ 24 cycles exception entry/exit:"
      " %.2f us avg); fast + slow %.1f %% of a %d Hz period"
      % (favg / 72.0, fmax / 72.0, (favg + 24) / 72.0, 100.0 * amort * frames.pwm_hz / 72e6,
         frames.pwm_hz))
    w("")
    n = len(tidx)
    w("Where the cycles go (target, per fast step, average over %d steps; inclusive ="
      " the function and what it calls):" % n)
    w("  %-30s %8s %10s %10s" % ("function", "calls", "inclusive", "self"))
    rows = [(prof["incl"][f], prof["self"][f], prof["calls"][f], img.funcs[f][2])
            for f in range(len(img.funcs)) if prof["calls"][f]]
    rows.sort(reverse=True)
    for inc, sf, calls, name in rows:
        w("  %-30s %8.2f %10.1f %10.1f" % (name, calls / n, inc / n, sf / n))
    w("")

    sizes = map_sizes(os.path.join(bdir, "bench.map"), img)
    core_objs = sorted(glob.glob(os.path.join(bdir, "core", "*.o")))
    t, d, b = object_sizes(core_objs)
    w("Core flash as linked (--gc-sections): core %d + library code it calls %d = %d bytes"
      % (sizes["core"]["text"] + sizes["core"]["data"],
         sizes["runtime"]["text"] + sizes["runtime"]["data"], sizes["flash"]))
    w("Core objects, every function (arm-none-eabi-size -t): text %d data %d bss %d"
      % (t, d, b))
    w("Core RAM: static data+bss %d + controller instance (foc_ctrl_t) %d = %d bytes"
      % (sizes["core"]["data"] + sizes["core"]["bss"] + sizes["runtime"]["data"]
         + sizes["runtime"]["bss"], sizes["ctrl"], sizes["ram"]))
    ci = sorted(glob.glob(os.path.join(bdir, "core", "*.ci")) +
                glob.glob(os.path.join(bdir, "harness", "*.ci")))
    stack_static, path, notes = worst_stack(ci, "foc_fast_step")
    stack_bytes = stack_static + 32
    w("ISR stack: foc_fast_step's call tree %d bytes (-fstack-usage over the call graph)"
      " + 32 bytes exception frame = %d; the simulator's deepest %d (+32)"
      % (stack_static, stack_bytes, fstack))
    w("  deepest path: %s" % " -> ".join(p.split(":")[-1] for p in path))
    for nt in notes:
        w("  note: %s" % nt)
    slow_stack, _, _ = worst_stack(ci, "foc_slow_step")
    w("Slow step stack (its own, lower-priority interrupt): %d bytes + 32; simulator %d"
      % (slow_stack, sstack))
    w("")

    # the other estimators' fast step, averaged like the target's (loop states)
    est_avg = {}
    for sc_idx in rows_all:
        sc = frames.scenarios[sc_idx]
        rng = range(sc["first"], sc["first"] + sc["count"])
        xs = [fast_all[i][0] for i in rng if frames.state_before[i] in LOOP_STATES]
        if xs and sc["estimator"] in (2, 3):
            est_avg.setdefault(EST_NAMES[sc["estimator"]], []).extend(xs)
    est_avg = {k: sum(v) / len(v) for k, v in est_avg.items()}
    targets = [("isr_cycles_avg", favg, 650), ("isr_cycles_max", fmax, 800),
               ("fast_slow_cycles_avg", amort, 750)]
    targets += [("isr_cycles_avg_" + k, v, 800) for k, v in sorted(est_avg.items())]
    targets += [("flash_bytes", sizes["flash"], 8192), ("ram_bytes", sizes["ram"], 512),
                ("stack_bytes", stack_bytes, 200)]
    w("Targets (Cortex-M3, -O2, PLL + field weakening, 3 shunts; the other estimators"
      " in the all-estimator image):")
    for name, val, lim in targets:
        w("  %-26s %8.1f <= %5d  %s" % (name, val, lim,
                                        "met" if val <= lim else "MISSED by %.1f (%.0f %%)"
                                        % (val - lim, 100.0 * (val - lim) / lim)))
    w("")
    kv = [
        ("target_scenario", tinfo["name"]),
        ("isr_cycles_min", fmin), ("isr_cycles_avg", "%.1f" % favg), ("isr_cycles_max", fmax),
        ("isr_insns_min", imin), ("isr_insns_avg", "%.1f" % iavg), ("isr_insns_max", imax),
        ("slow_cycles_min", smin), ("slow_cycles_avg", "%.1f" % savg), ("slow_cycles_max", smax),
        ("slow_cycles_max_all", max(all_slow)),
        ("fast_slow_cycles_avg", "%.1f" % amort), ("period_cycles_max", max(per)),
        ("flash_bytes", sizes["flash"]), ("flash_bytes_all_functions", t + d),
        ("ram_bytes", sizes["ram"]), ("ctrl_bytes", sizes["ctrl"]),
        ("stack_bytes", stack_bytes), ("stack_bytes_measured", fstack + 32),
        ("replay_mismatches", result["mismatches"] + (res_all["mismatches"] if res_all else 0)),
    ] + [("isr_cycles_avg_" + k, "%.1f" % v) for k, v in sorted(est_avg.items())] + [
        ("bench_elf", os.path.abspath(a.elf)),
        ("isr_symbol", "foc_fast_step"),
    ]
    for key, val in kv:
        w("%s=%s" % (key, val))
    text = "\n".join(out) + "\n"
    sys.stdout.write(text)
    if a.output:
        with open(a.output, "w") as f:
            f.write(text)
    bad = result["mismatches"] or result["status"] or (res_all and res_all["mismatches"])
    return 1 if bad else 0


def cmd_gate(a):
    """Fails when a figure of the report exceeds its ceiling in the gates
    file by more than the allowed margin (5 %)."""
    got = {}
    for path in a.report:
        with open(path) as f:
            got.update(line.strip().split("=", 1) for line in f
                       if re.match(r"^[a-z_0-9]+=", line))
    bad = 0
    with open(a.gates) as f:
        for line in f:
            line = line.split("#")[0].split()
            if not line:
                continue
            key, ceiling = line[0], float(line[1])
            if key not in got:
                print("gate %-28s missing from %s" % (key, " ".join(a.report)))
                bad += 1
                continue
            val = float(got[key])
            ok = val <= ceiling * (1.0 + a.margin)
            print("gate %-28s %9.1f  ceiling %9.1f (+%d %%)  %s"
                  % (key, val, ceiling, round(a.margin * 100), "ok" if ok else "FAILED"))
            bad += 0 if ok else 1
    return 1 if bad else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("check")
    c.add_argument("--elf", required=True)
    c.add_argument("--frames", required=True)
    c.add_argument("--hash")
    r = sub.add_parser("report")
    r.add_argument("--elf", required=True)
    r.add_argument("--frames", required=True)
    r.add_argument("--build-dir", required=True)
    r.add_argument("--elf-all", help="an all-estimator image for the other scenarios")
    r.add_argument("--output")
    r.add_argument("--line-profile", help="write the fast step's cycles per source line here")
    g = sub.add_parser("gate")
    g.add_argument("--report", required=True, action="append")
    g.add_argument("--gates", required=True)
    g.add_argument("--margin", type=float, default=0.05)
    a = ap.parse_args()
    return {"check": cmd_check, "report": cmd_report, "gate": cmd_gate}[a.cmd](a)


if __name__ == "__main__":
    sys.exit(main())
