#!/usr/bin/python3
"""dsPIC33F cycle estimate of C code from its typed AST and measured counts.

No XC16 here, so the estimate is built from three things:

 1. Operation classes per source expression: each core source is parsed by
    clang for a 16-bit-int target (--target=msp430: int 16 bits, long 32,
    pointers 16, like XC16) and its typed AST (-ast-dump=json, implicit
    casts included) is walked; every operator is classed by its C type under
    those rules (an int16_t * int16_t widened to int32_t is one 16x16
    multiply, MUL.SS; a 32-bit add is ADD + ADDC; ...).
 2. Execution counts per source region: a host run of an instrumented
    program (clang source-based coverage; for the bench: dspic_replay, only
    the fast steps in the current-loop states counted), exported with
    llvm-cov.  Each operation takes the count of the innermost code region
    that contains it.
 3. Cost per class in dsPIC33F instruction cycles (COSTS below, from the
    16-bit MCU and DSC Programmer's Reference Manual DS70157), times count,
    summed, divided by the number of steps the program reports (steps= or
    fast_steps= on its output).

    dspic_est.py estimate --binary B --run "cmd args" --sources a.c b.c
                          [--cflags "..."] [--expect N --tolerance T]

prints the per-class breakdown and dspic_cycles_est=.  Model and limits:
docs/benchmarks.md ("dsPIC33 estimate").
"""

import argparse
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile

# Cycles per operation class (dsPIC33F: one instruction cycle = 2 clocks,
# 40 MIPS at 80 MHz).  DS70157 = "16-bit MCU and DSC Programmer's Reference
# Manual": its instruction set overview (most instructions 1 cycle,
# double-word moves 2, PC-changing instructions 2-3) and the "Cycles" entry
# of each instruction's description; the dsPIC33FJ data sheets' "Instruction
# Set Summary" chapter gives the same figures.
COSTS = {
    # class         cycles  what XC16 emits / source
    "mul16x16":     1,    # MUL.SS/MUL.UU/MUL.SU Wb,Ws,Wnd: 16x16->32, 1 cycle
    "mul16":        1,    # MUL.SS keeping the low word (or MUL.UU)
    "mul32x32":     6,    # 3 x MUL.UU/MUL.SU (low x low, 2 cross terms) + 3 ADD/ADDC (assumed inline)
    "div16":        19,   # REPEAT #17 + DIV.S/DIV.U: 18 + 1 cycles (DS70157 DIV.S)
    "div32":        100,  # 32/32: library call (__divsi3), an assumption: no figure in DS70157
    "add32":        2,    # ADD + ADDC / SUB + SUBB, 1 cycle each
    "cmp32":        2,    # CP + CPB
    "logic32":      2,    # AND/IOR/XOR on both words
    "shift32c":     4,    # 32-bit shift by a constant k (2..15): 2 barrel shifts (SL/ASR/LSR #lit4) + the bits crossing words (shift + IOR)
    "shift32s":     2,    # 32-bit shift by 1 (SL + RLC / ASR + RRC) or by >= 16 (a word move + SL/ASR or sign fill)
    "shift32v":     8,    # 32-bit shift by a variable: as above plus computing 16 - n and a branch for n >= 16 (assumed)
    "const32":      1,    # a 32-bit constant operand outside the #lit5 forms: one MOV #lit16 (the
                          # other word is usually 0 or -1: #lit5 forms of CPB/ADDC/SUBB, or SETM)
    "alu16":        1,    # ADD/SUB/AND/IOR/XOR/CP/NEG/COM/SE/ZE/barrel shift on one word
    "alu32":        2,    # NEG/COM/INC/DEC on a long: one per word (+ carry)
    "ext":          1,    # widening 16 -> 32 (ASR Wn,#15 into the high word, or CLR) or 8 -> 16 (SE/ZE)
    "load":         1,    # per 16-bit word: MOV [Ws+lit],Wd 1 cycle (MOV.D: 2 for a long)
    "store":        1,    # per 16-bit word: MOV Ws,[Wd+lit] 1 cycle
    "index":        1,    # array index scaled to bytes: SL (then [Ws+Wb] addressing)
    "branch":       1.5,  # BRA cond: 1 not taken, 2 taken (DS70157 BRA); 50/50 assumed
    "switch":       5,    # bounds CP + BRA cond + BRA Wn computed jump (2) + BRA to case (2), assumed
    "call":         5,    # RCALL/CALL 2 + RETURN 3 (DS70157 CALL, RCALL, RETURN)
}

CLASS_ORDER = ["mul16x16", "mul16", "mul32x32", "div16", "div32", "add32", "cmp32",
               "logic32", "shift32s", "shift32c", "shift32v", "const32", "alu16", "alu32", "ext", "load",
               "store", "index", "branch", "switch", "call"]


TYPE_WORDS = {"i1": 1, "i8": 1, "i16": 1, "i32": 2, "i64": 4}


def ir_of(src, cflags, tmp):
    """The source as LLVM IR for a 16-bit-int target (msp430: int 16 bits,
    long 32, pointers 16, like XC16), with debug locations, locals promoted
    to registers (sroa) and nothing else optimised."""
    ll = os.path.join(tmp, os.path.basename(src) + ".ll")
    cmd = ["clang", "--target=msp430", "-ffreestanding", "-O0", "-Xclang",
           "-disable-O0-optnone", "-g", "-gcolumn-info", "-w", "-S", "-emit-llvm"] + \
        shlex.split(cflags) + [src, "-o", ll]
    if subprocess.run(cmd).returncode != 0:
        raise SystemExit("dspic_est: %s does not compile for a 16-bit-int target"
                         " (clang --target=msp430): %s" % (src, " ".join(cmd)))
    out = subprocess.run(["opt", "-S", "-passes=sroa", ll], check=True,
                         stdout=subprocess.PIPE, universal_newlines=True).stdout
    return out


RE_META = re.compile(r"^!(\d+) = (?:distinct )?!(\w+)\((.*)\)\s*$")
RE_FIELD = re.compile(r"(\w+): (\"(?:[^\"\\]|\\.)*\"|![0-9]+|[^,]+)")
RE_DEFINE = re.compile(r"^define .*@([\w.$]+)\(.*!dbg !(\d+)")
RE_DBG = re.compile(r"!dbg !(\d+)")
RE_INST = re.compile(r"^\s+(?:%[\w.]+ = )?(\w+)(.*)$")


def parse_meta(text):
    meta = {}
    for line in text.splitlines():
        m = RE_META.match(line)
        if m:
            meta[int(m.group(1))] = (m.group(2), dict(
                (k, v.strip('"')) for k, v in RE_FIELD.findall(m.group(3))))
    return meta


def meta_file(meta, n, seen=0):
    """Path of the file a scope / location / subprogram belongs to."""
    kind, f = meta.get(n, (None, {}))
    if kind == "DIFile":
        name = f.get("filename", "")
        return os.path.realpath(os.path.join(f.get("directory", ""), name))
    if "file" in f:
        return meta_file(meta, int(f["file"][1:]))
    if "scope" in f and seen < 50:
        return meta_file(meta, int(f["scope"][1:]), seen + 1)
    return None


def is_pow2_const(tok):
    try:
        v = int(tok)
    except ValueError:
        return False
    return v > 0 and v & (v - 1) == 0


def fits16(tok):
    try:
        v = int(tok)
    except ValueError:
        return False
    return -32768 <= v <= 65535


def classify_inst(op, rest, defs, header_funcs):
    """[(class, quantity)] for one IR instruction."""
    toks = rest.replace(",", " ").split()
    ty = None
    for t in toks:
        if re.match(r"^i\d+$", t):
            ty = t
            break
    w = TYPE_WORDS.get(ty, 1)
    wide = w > 1
    if op == "mul":
        a, b = re.findall(r"(%[\w.]+|-?\d+)", rest.split(ty, 1)[1])[:2] if ty else ("", "")
        if not wide:
            return [("mul16", 1)]
        if is_pow2_const(b) or is_pow2_const(a):
            k = max(int(x) for x in (a, b) if is_pow2_const(x)).bit_length() - 1
            return [("shift32s" if k == 1 or k >= 16 else "shift32c", 1)]
        narrow = lambda x: fits16(x) or defs.get(x) in ("sext16", "zext16")
        return [("mul16x16", 1)] if narrow(a) and narrow(b) else [("mul32x32", 1)]
    if op in ("sdiv", "udiv", "srem", "urem"):
        b = re.findall(r"(%[\w.]+|-?\d+)", rest.split(ty, 1)[1])[1] if ty else ""
        if is_pow2_const(b):
            return [("shift32c" if wide else "alu16", 1), ("add32" if wide else "alu16", 1)]
        return [("div32" if wide else "div16", 1)]
    if op in ("shl", "ashr", "lshr"):
        if not wide:
            return [("alu16", 1)]
        b = re.findall(r"(%[\w.]+|-?\d+)", rest.split(ty, 1)[1])[1]
        if b.startswith("%"):
            return [("shift32v", 1)]
        return [("shift32s" if int(b) == 1 or int(b) >= 16 else "shift32c", 1)]
    if op in ("add", "sub", "and", "or", "xor", "icmp"):
        cls = {"add": "add32", "sub": "add32", "icmp": "cmp32"}.get(op, "logic32")
        if not wide:
            return [("alu16", 1)]
        consts = [c for c in re.findall(r"(?<![%\w.!#])(-?\d+)\b", rest.split(ty, 1)[1].split("!dbg")[0])
                  if not 0 <= int(c) <= 31]
        return [(cls, 1)] + [("const32", 1)] * min(1, len(consts))
    if op in ("sext", "zext"):
        m = re.match(r"\s*(i\d+) \S+ to (i\d+)", rest)
        if m and m.group(1) == "i1":
            return [("alu16", 1)]
        return [("ext", 1)] if m and TYPE_WORDS.get(m.group(2), 1) > TYPE_WORDS.get(m.group(1), 1) or \
            (m and m.group(1) == "i8") else []
    if op == "load":
        return [("load", w)]
    if op == "store":
        return [("store", w)]
    if op == "getelementptr":
        idx = re.findall(r"i(?:16|32) (%[\w.]+)", rest)
        return [("index", 1)] if idx else []
    if op == "br":
        return [("branch", 1)] if rest.strip().startswith("i1") else []
    if op == "select":
        return [("branch", 1)]
    if op == "switch":
        return [("switch", 1)]
    if op == "call" or op == "tail":
        m = re.search(r"@([\w.$]+)\(", rest)
        if not m:
            return [("call", 1)]
        name = m.group(1)
        if name.startswith("llvm.dbg") or name.startswith("llvm.lifetime"):
            return []
        if name.startswith("llvm.memcpy") or name.startswith("llvm.memmove"):
            n = re.findall(r"i16 (\d+), i1", rest)
            words_ = (int(n[0]) + 1) // 2 if n else 2
            return [("load", words_), ("store", words_)]
        if name.startswith("llvm.memset"):
            n = re.findall(r"i16 (\d+), i1", rest)
            return [("store", (int(n[0]) + 1) // 2 if n else 2)]
        if name in header_funcs:
            return []  # inlined by XC16 -O1: static inline in a header, or called once
        return [("call", 1)]
    return []


def collect_ir(text, ops, seen_funcs, keep):
    """Operations of every function defined in the IR: (file, line, col,
    class, quantity).  A function already collected from another
    translation unit (a header's static inline one) is skipped: the
    coverage lookup sums its executions over every copy."""
    meta = parse_meta(text)
    header_funcs = set()
    funcs = []
    cur = None
    for line in text.splitlines():
        m = RE_DEFINE.match(line)
        if m:
            sp = int(m.group(2))
            f = meta_file(meta, sp)
            cur = (m.group(1), f, [])
            funcs.append(cur)
            if f and os.sep + "include" + os.sep in f:
                header_funcs.add(m.group(1))
            continue
        if cur is None:
            continue
        if line.startswith("}"):
            cur = None
            continue
        cur[2].append(line)
    # XC16 -O1 (GCC's -finline-functions-called-once): a static function
    # called from one place is inlined there
    for line in text.splitlines():
        m = re.match(r"^define internal .*@([\w.$]+)\(", line)
        if m and len(re.findall(r"call [^@]*@%s\(" % re.escape(m.group(1)), text)) == 1:
            header_funcs.add(m.group(1))
    for name, f, body in funcs:
        if f is None or not keep(f) or (f, name) in seen_funcs:
            continue
        seen_funcs.add((f, name))
        defs = {}
        # a widening whose every use is a multiply: MUL.SS/MUL.UU take the
        # 16-bit operands as they are, so it costs nothing
        # and one that only widens a shift count (a 32-bit shift takes
        # its count in one register)
        uses = {}
        for line in body:
            mi = RE_INST.match(line)
            if mi:
                for pos, v in enumerate(re.findall(r"(%[\w.]+)", mi.group(2))):
                    uses.setdefault(v, []).append((mi.group(1), pos))
        free_ext = set(v for v, u in uses.items() if u and all(
            o == "mul" or (o in ("shl", "ashr", "lshr") and pos == 1) for o, pos in u))
        for line in body:
            mi = RE_INST.match(line)
            if not mi:
                continue
            op, rest = mi.group(1), mi.group(2)
            md = re.match(r"\s*(%[\w.]+) = (sext|zext) i(8|16) ", line)
            if md:
                defs[md.group(1)] = "sext16" if md.group(2) == "sext" else "zext16"
            cls = classify_inst(op, rest, defs, header_funcs)
            if md and md.group(1) in free_ext:
                cls = []
            if not cls:
                continue
            d = RE_DBG.search(rest)
            if not d:
                continue
            kind, loc = meta.get(int(d.group(1)), (None, {}))
            if kind != "DILocation" or int(loc.get("line", "0")) == 0:
                continue
            lf = meta_file(meta, int(loc["scope"][1:]))
            for c, q in cls:
                ops.append((lf, int(loc["line"]), int(loc.get("column", "1")), c, q))


def coverage(binary, run, tmp):
    raw = os.path.join(tmp, "run.profraw")
    env = dict(os.environ, LLVM_PROFILE_FILE=raw)
    p = subprocess.run(shlex.split(run), env=env, stdout=subprocess.PIPE, check=False,
                       universal_newlines=True)
    if p.returncode != 0:
        raise SystemExit("dspic_est: %s failed (%d):\n%s" % (run, p.returncode, p.stdout))
    m = re.search(r"^(?:fast_)?steps=(\d+)$", p.stdout, re.M)
    if not m:
        raise SystemExit("dspic_est: %s printed no steps= / fast_steps=" % run)
    prof = os.path.join(tmp, "run.profdata")
    subprocess.run(["llvm-profdata", "merge", "-sparse", raw, "-o", prof], check=True)
    exp = subprocess.run(["llvm-cov", "export", binary, "-instr-profile=" + prof],
                         check=True, stdout=subprocess.PIPE).stdout
    return json.loads(exp), int(m.group(1)), p.stdout


def region_index(cov):
    """file -> list of (functions' code regions) for innermost lookup."""
    idx = {}
    for fn in cov["data"][0]["functions"]:
        files = fn["filenames"]
        regs = []
        for r in fn["regions"]:
            if len(r) != 8 or r[7] != 0:  # code regions only (not branch/gap/skipped)
                continue
            regs.append((r[5], r[0], r[1], r[2], r[3], r[4]))
        for fid in set(r[0] for r in regs):
            f = os.path.realpath(files[fid])
            idx.setdefault(f, []).append([r[1:] for r in regs if r[0] == fid])
    return idx


def count_at(idx, f, line, col):
    total = 0
    for regs in idx.get(f, []):
        best = None
        for (l0, c0, l1, c1, n) in regs:
            if (line, col) >= (l0, c0) and (line, col) < (l1, c1):
                size = (l1 - l0, c1 - c0)
                if best is None or size < best[0]:
                    best = (size, n)
        if best is not None:
            total += best[1]
    return total


def tally(ops, cov, steps):
    idx = region_index(cov)
    per_class = {c: 0.0 for c in COSTS}
    per_file = {}
    per_line = {}
    for (f, line, col, cls, qty) in ops:
        n = count_at(idx, f, line, col)
        if n:
            per_class[cls] += n * qty
            per_file[f] = per_file.get(f, 0.0) + n * qty * COSTS[cls]
            key = (os.path.relpath(f), line)
            per_line.setdefault(key, {})
            per_line[key][cls] = per_line[key].get(cls, 0.0) + n * qty / steps
    total = sum(per_class[c] * COSTS[c] for c in COSTS)
    return per_class, per_file, per_line, total / steps


def estimate(a):
    keep_dirs = [os.path.realpath(d) for d in a.keep]

    def keep(p):
        rp = os.path.realpath(p)
        return any(rp.startswith(d + os.sep) or rp == d for d in keep_dirs)
    ops = []
    seen = set()
    with tempfile.TemporaryDirectory() as tmp:
        for src in a.sources:
            collect_ir(ir_of(src, a.cflags, tmp), ops, seen, keep)
        cov, steps, out = coverage(a.binary, a.run, tmp)
        slow = None
        if a.slow_run:
            scov, ssteps, sout = coverage(a.binary, a.slow_run, tmp)
            m = re.search(r"^loop_periods=(\d+)$", sout, re.M)
            periods = int(m.group(1)) if m else steps
            slow = (tally(ops, scov, ssteps), ssteps, periods)
    per_class, per_file, per_line, est = tally(ops, cov, steps)
    lines = []
    w = lines.append
    w("dsPIC33F estimate (tools/bench/dspic/dspic_est.py, costs from DS70157; model and"
      " limits in docs/benchmarks.md): %s, %d steps counted" % (a.label, steps))
    w("  %-10s %8s %12s %10s" % ("class", "cycles", "ops/step", "cycles/step"))
    for c in CLASS_ORDER:
        if per_class[c]:
            w("  %-10s %8g %12.1f %10.1f" % (c, COSTS[c], per_class[c] / steps,
                                            per_class[c] * COSTS[c] / steps))
    w("  %-10s %8s %12s %10.1f" % ("total", "", "", est))
    w("  per source file, cycles/step: " + ", ".join(
        "%s %.0f" % (os.path.basename(f), v / steps)
        for f, v in sorted(per_file.items(), key=lambda x: -x[1])))
    if a.lines:
        w("  costliest source lines, cycles/step (operations/step by class):")
        top = sorted(per_line.items(), key=lambda kv: -sum(COSTS[c] * q for c, q in kv[1].items()))
        for (f, line), cl in top[:a.lines]:
            w("    %-28s %6.1f  %s" % ("%s:%d" % (f, line), sum(COSTS[c] * q for c, q in cl.items()),
                                      " ".join("%s %.2f" % (c, q) for c, q in sorted(cl.items()))))
    kv = [("dspic_%s" % c, "%.1f" % (per_class[c] * COSTS[c] / steps)) for c in CLASS_ORDER]
    if slow is not None:
        (_, _, _, sest), ssteps, periods = slow
        amort = est + sest * ssteps / periods
        w("  slow step: %.1f cycles per call, %d calls in %d periods; fast + slow amortised"
          " %.1f cycles per period = %.1f %% of the %d-cycle period (%s)"
          % (sest, ssteps, periods, amort, 100.0 * amort / a.period_cycles, a.period_cycles,
             a.period_note))
        kv += [("dspic_slow_cycles_est", "%.1f" % sest),
               ("dspic_fast_slow_cycles_est", "%.1f" % amort),
               ("dspic_load_percent_est", "%.1f" % (100.0 * amort / a.period_cycles))]
    kv.append(("dspic_cycles_est", "%.1f" % est))
    for k, v in kv:
        w("%s=%s" % (k, v))
    text = "\n".join(lines) + "\n"
    sys.stdout.write(text)
    if a.output:
        with open(a.output, "w") as fo:
            fo.write(text)
    if a.expect is not None:
        if abs(est - a.expect) > a.tolerance:
            print("dspic_est: FAILED: %.2f cycles, expected %.2f +- %.2f" % (est, a.expect, a.tolerance))
            return 1
        print("dspic_est: ok: %.2f cycles, expected %.2f +- %.2f" % (est, a.expect, a.tolerance))
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    e = sub.add_parser("estimate")
    e.add_argument("--binary", required=True, help="the coverage-instrumented program")
    e.add_argument("--run", required=True, help="command line that runs it")
    e.add_argument("--sources", nargs="+", required=True)
    e.add_argument("--cflags", default="")
    e.add_argument("--keep", nargs="+", default=["src", "include"],
                   help="directories whose code is costed (default src include)")
    e.add_argument("--label", default="")
    e.add_argument("--output", help="write the report to this file too")
    e.add_argument("--slow-run", help="a second run counting the slow step (prints steps="
                   " and loop_periods=): adds its estimate, amortised per period")
    e.add_argument("--period-cycles", type=int, default=2000,
                   help="instruction cycles per control period (2000: 40 MIPS, 20 kHz)")
    e.add_argument("--period-note", default="dsPIC33FJ at 40 MIPS, 20 kHz PWM")
    e.add_argument("--lines", type=int, default=0, help="list the N costliest source lines")
    e.add_argument("--expect", type=float)
    e.add_argument("--tolerance", type=float, default=0.01)
    a = ap.parse_args()
    return estimate(a)


if __name__ == "__main__":
    sys.exit(main())
