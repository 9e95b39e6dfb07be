#!/usr/bin/env python3
"""Every class of impossible userparms.h value stops the build with a
message that names the parameter (issue 14, item 2).

    bad_userparms.py CC SOURCE_DIR WORK_DIR

For each case: userparms.h.in with one #define changed (or two, for Ld =
Lq = 0), compiled alone with the core's headers (a file that includes
foc/controller.h, hence config.h and estimator.h); the compiler must fail
and its messages must name the parameter.  The unchanged template must
compile (the harness itself can fail)."""
import os
import re
import subprocess
import sys

CASES = [  # (parameter, bad value, name the messages must contain)
    ("MOTOR_RS_OHM", "-2.54", "MOTOR_RS_OHM"),
    ("MOTOR_RS_OHM", "1e999", "MOTOR_RS_OHM"),                 # infinity
    ("MOTOR_RS_OHM", "(__builtin_nan(\"\"))", "MOTOR_RS_OHM"),  # NaN
    ("MOTOR_RS_OHM", "(0.0 / 0.0)", "MOTOR_RS_OHM"),           # NaN as written
    ("PWM_FREQUENCY_HZ", "200000.0", "PWM_FREQUENCY_HZ"),
    ("MOTOR_POLE_PAIRS", "0", "MOTOR_POLE_PAIRS"),
    ("MOTOR_POLE_PAIRS", "2.5", "MOTOR_POLE_PAIRS"),
    ("BOARD_ADC_BITS", "0", "BOARD_ADC_BITS"),
    ("BOARD_ADC_BITS", "32", "BOARD_ADC_BITS"),
    ("CURRENT_KP_V_PER_A", "-12.06", "CURRENT_KP_V_PER_A"),
    ("SPEED_KI_A_PER_RPM_S", "-0.3266", "SPEED_KI_A_PER_RPM_S"),
    ("FOC_ESTIMATOR", "42", "FOC_ESTIMATOR"),
    ("STARTUP_TIMEOUT_S", "0.0", "STARTUP_TIMEOUT_S"),
    ("STARTUP_SPEED_WINDOW_MAX", "0.7", "STARTUP_SPEED_WINDOW_MAX"),  # below MIN 0.8
    ("MOTOR_LD_H", "0.0", "MOTOR_LD_H"),                       # with Lq 0 too
    ("MOTOR_LQ_H", "0.0", "MOTOR_LQ_H"),
    ("MOTOR_INERTIA_KGM2", "-1e-5", "MOTOR_INERTIA_KGM2"),
    ("MOTOR_COULOMB_NM", "-0.01", "MOTOR_COULOMB_NM"),
    ("PWM_DEADTIME_S", "-1e-6", "PWM_DEADTIME_S"),
    ("CONTROL_SLOW_DIVIDER", "0", "CONTROL_SLOW_DIVIDER"),
    ("STALL_TICKS", "32000", "STALL_TICKS"),                  # 2 x (it + 64) > 16 bits
    ("MOTOR_MAX_SPEED_RPM", "300.0", "DEADTIME_EFFECTIVE_S"),  # no speed above the dead time
]


def compile_with(cc, src, work, text):
    parms = os.path.join(work, "userparms_case.h")
    with open(parms, "w") as f:
        f.write(text)
    tu = os.path.join(work, "tu.c")
    with open(tu, "w") as f:
        f.write('#include "foc/controller.h"\n')
    r = subprocess.run([cc, "-std=c11", "-fsyntax-only", "-I", os.path.join(src, "include"),
                        '-DFOC_USERPARMS_FILE="%s"' % parms, tu],
                       capture_output=True, text=True)
    return r.returncode, r.stderr


def main():
    cc, src, work = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    template = open(os.path.join(src, "userparms.h.in")).read()
    fails = 0
    rc, err = compile_with(cc, src, work, template)
    if rc != 0:
        print("FAIL the template itself does not compile:\n" + err)
        return 1
    print("ok   the template compiles")
    for name, value, want in CASES:
        text, n = re.subn(r"(#define %s\s+)\S+" % name, lambda m: m.group(1) + value, template)
        if name == "MOTOR_LD_H":
            text = re.sub(r"(#define MOTOR_LQ_H\s+)\S+", lambda m: m.group(1) + "0.0", text)
        if n != 1:
            print("FAIL %s not found once in the template" % name)
            fails += 1
            continue
        rc, err = compile_with(cc, src, work, text)
        if rc == 0:
            print("FAIL %s = %s builds" % (name, value))
            fails += 1
        elif want not in err:
            print("FAIL %s = %s stops the build without naming %s:\n%s" % (name, value, want,
                                                                            err[:600]))
            fails += 1
        else:
            first = next((l for l in err.splitlines() if "error" in l), "")
            print("ok   %s = %s: %s" % (name, value, first.split("error:")[-1].strip()[:100]))
    print("bad_userparms: %d of %d cases fail" % (fails, len(CASES)))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
