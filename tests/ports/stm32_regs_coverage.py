#!/usr/bin/env python3
"""The register-map test (tests/ports/test_stm32_regs.c) covers the whole
register map (hal/stm32f10x/stm32f10x_regs.h): every peripheral pointer has
a BASE row, every constant and interrupt number a VAL row, and every named
register of every structure a REG row (directly or through the test's
ADC_ROWS/GPIO_ROWS) for some peripheral of that structure.  The port
compiles against this header, so whatever it uses is covered.  Also lists
which of the header's names the port's sources use.

Usage: stm32_regs_coverage.py <repository root>
"""
import pathlib
import re
import sys


def header_names(text):
    """(constants, {instance: type}, {type: [registers]}) of the map."""
    start = text.index("#include <stdint.h>")
    end = text.index("#endif /* FOC_STM32_VENDOR_CMSIS */")
    text = re.sub(r"/\*.*?\*/", "", text[start:end], flags=re.S)
    instances, constants = {}, []
    for name, value in re.findall(r"^#define\s+(\w+)\s+(.*)$", text, re.M):
        m = re.match(r"\(\((\w+) \*\)", value.strip())
        if m:
            instances[name] = m.group(1)
        elif name != "__IO":
            constants.append(name)
    for body in re.findall(r"typedef enum \{(.*?)\}", text, re.S):
        constants += re.findall(r"(\w+)\s*=", body)
    structs = {}
    for body, name in re.findall(r"typedef struct \{(.*?)\}\s*(\w+);", text, re.S):
        regs = re.findall(r"__IO\s+\w+\s+(\w+)\s*(?:\[\w+\])?\s*;", body)
        structs[name] = [r for r in regs if not re.match(r"R[E]?SERVED", r)]
    return constants, instances, structs


def table_rows(text):
    """(VAL names, BASE names, {(instance, register)}) of the test."""
    vals = set(re.findall(r"\bVAL\((\w+),", text))
    bases = set(re.findall(r"\bBASE\((\w+),", text))
    regs = set(re.findall(r"\bREG\((\w+), (\w+)", text))
    macros = {}
    for name, body in re.findall(r"#define (\w+_ROWS)\(\w\)(.*?)\n\n", text, re.S):
        macros[name] = re.findall(r"REGN\(#\w, \w, (\w+)", body)
    for name, inst in re.findall(r"^\s+(\w+_ROWS)\((\w+)\),?$", text, re.M):
        regs |= {(inst, r) for r in macros[name]}
    return vals, bases, regs


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    header = (root / "hal/stm32f10x/stm32f10x_regs.h").read_text()
    test = (root / "tests/ports/test_stm32_regs.c").read_text()
    constants, instances, structs = header_names(header)
    vals, bases, regs = table_rows(test)

    missing = [f"constant {c}" for c in constants if c not in vals]
    missing += [f"base address {i}" for i in instances if i not in bases]
    covered = {(instances.get(i), r) for i, r in regs}
    for struct, names in structs.items():
        missing += [f"register {struct}.{r}" for r in names if (struct, r) not in covered]
    for m in missing:
        print(f"stm32_regs_coverage: not in test_stm32_regs.c: {m}")

    # The port's own uses (implied by the above; listed for the record).
    port = ""
    for d in ("hal/stm32f10x", "boards/stm3210b_mckit"):
        for f in sorted((root / d).glob("*.[ch]")):
            if f.name != "stm32f10x_regs.h":
                port += re.sub(r"/\*.*?\*/", "", f.read_text(), flags=re.S)
    used = [n for n in constants + list(instances) if re.search(rf"\b{n}\b", port)]
    direct = set(re.findall(r"\b(\w+)->([A-Z][A-Z0-9_]*)", port))
    direct = {(i, r) for i, r in direct if i in instances}
    for i, r in sorted(direct):
        if (instances[i], r) not in covered:
            print(f"stm32_regs_coverage: the port's {i}->{r} is not in test_stm32_regs.c")
            missing.append(r)
    print(f"stm32_regs_coverage: header: {len(constants)} constants, {len(instances)} "
          f"peripherals, {sum(map(len, structs.values()))} registers in {len(structs)} "
          f"structures, {'not all' if missing else 'all'} in the test; the port "
          f"names {len(used)} of the "
          f"constants and peripherals and writes {len(direct)} registers as "
          f"PERIPHERAL->REGISTER (others through pointers)")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
