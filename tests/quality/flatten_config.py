#!/usr/bin/python3
"""Writes a copy of include/foc/config.h in which the derived constants
(object-like FOC_* macros with a long expansion) are replaced by their
values, as the C compiler computes them, for cppcheck.

Why: config.h derives its fixed-point constants with nested conditional
macros (FOC_GAIN_SHIFT, FOC_NORM_RSHIFT, Q15), whose expansions reach
hundreds of thousands of tokens; cppcheck 2.10 spends minutes on one use
(src/flux_est.c did not finish in 5 minutes).  Compilers fold them at once.
The .c files are analysed unchanged; config.h itself is checked on its own
(tests/quality/static.sh).

    flatten_config.py <out dir> <compiler flags...>

writes <out dir>/foc/config.h; put -I<out dir> before -Iinclude.
"""
import os
import re
import subprocess
import sys
import tempfile

MIN_EXPANSION = 200  # characters: shorter expansions are kept as they are

TYPES = [  # _Generic association -> printf format of a typed literal
    ("double", '"(%#.17g)"', "double"),  # '#': always a decimal point
    ("float", '"(%#.9g)"', "double"),
    ("signed char", '"((int8_t)%d)"', "int"),
    ("short", '"((int16_t)%d)"', "int"),
    ("int", '"(%d)"', "int"),
    ("long", '"(%ldL)"', "long"),
    ("long long", '"(%lldLL)"', "long long"),
    ("unsigned char", '"((uint8_t)%uu)"', "unsigned"),
    ("unsigned short", '"((uint16_t)%uu)"', "unsigned"),
    ("unsigned", '"(%uu)"', "unsigned"),
    ("unsigned long", '"(%luUL)"', "unsigned long"),
    ("unsigned long long", '"(%lluULL)"', "unsigned long long"),
]


def run(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, **kw)


def main():
    out, flags = sys.argv[1], sys.argv[2:]
    src = None
    for f in flags:
        if f.startswith("-I") and os.path.exists(os.path.join(f[2:], "foc", "config.h")):
            src = os.path.join(f[2:], "foc", "config.h")
            break
    if src is None:
        sys.exit("flatten_config.py: no -I directory holds foc/config.h")
    tmp = tempfile.mkdtemp(prefix="flatten-")
    tu = os.path.join(tmp, "tu.c")
    with open(tu, "w") as f:
        f.write('#include "foc/config.h"\n')
    r = run(["gcc", "-std=c11", "-dM", "-E"] + flags + [tu])
    if r.returncode:
        sys.exit("flatten_config.py: %s" % r.stderr)
    names = sorted(set(m.group(1) for m in re.finditer(r"^#define (FOC_\w+) ", r.stdout, re.M)))
    with open(tu, "w") as f:
        f.write('#include "foc/config.h"\n')
        for k, n in enumerate(names):
            f.write("@@%d@@ %s\n" % (k, n))
    r = run(["gcc", "-std=c11", "-E", "-P"] + flags + [tu])
    expansion = {}
    for line in r.stdout.split("\n"):
        m = re.match(r"^@@(\d+)@@ (.*)$", line)
        if m:
            expansion[names[int(m.group(1))]] = m.group(2)
    cand = [n for n in names if len(expansion.get(n, "")) > MIN_EXPANSION
            and "{" not in expansion[n] and '"' not in expansion[n]]
    values = {}
    while cand:
        prog = os.path.join(tmp, "prog.c")
        with open(prog, "w") as f:
            f.write("#include <stdio.h>\n#include <stdint.h>\n#include \"foc/config.h\"\n")
            f.write("#define P(n, v) (printf(\"%s \", n), printf(_Generic((v), " + ", ".join(
                "%s: %s" % (t, fmt) for t, fmt, _ in TYPES) + "), _Generic((v), " + ", ".join(
                "%s: (%s)(v)" % (t, c) for t, _, c in TYPES) + ")), printf(\"\\n\"))\n")
            f.write("int main(void)\n{\n")
            first = 6
            for n in cand:
                f.write("    P(\"%s\", %s);\n" % (n, n))
            f.write("    return 0;\n}\n")
        exe = os.path.join(tmp, "prog")
        r = run(["gcc", "-std=c11", "-w"] + flags + [prog, "-o", exe])
        if r.returncode:
            bad = set()
            for m in re.finditer(r"prog\.c:(\d+):\d+: error", r.stderr):
                k = int(m.group(1)) - first - 1
                if 0 <= k < len(cand):
                    bad.add(cand[k])
            if not bad:
                sys.exit("flatten_config.py: cannot compile the constants:\n" + r.stderr[:2000])
            cand = [n for n in cand if n not in bad]
            continue
        for line in run([exe]).stdout.split("\n"):
            if line:
                n, v = line.split(" ", 1)
                values[n] = v
        break

    with open(src) as f:
        text = f.read()
    lines = text.split("\n")
    outl = []
    i = 0
    done = set()
    while i < len(lines):
        line = lines[i]
        m = re.match(r"^#define (FOC_\w+)(\s|$)", line)
        if m and m.group(1) in values and m.group(1) not in done:
            while lines[i].endswith("\\"):
                i += 1
            outl.append("#define %s %s /* flattened (tests/quality/flatten_config.py) */"
                        % (m.group(1), values[m.group(1)]))
            done.add(m.group(1))
        else:
            outl.append(line)
        i += 1
    os.makedirs(os.path.join(out, "foc"), exist_ok=True)
    with open(os.path.join(out, "foc", "config.h"), "w") as f:
        f.write("\n".join(outl))
    print("flatten_config.py: %d of %d FOC_ constants flattened -> %s/foc/config.h"
          % (len(done), len(names), out))


if __name__ == "__main__":
    main()
