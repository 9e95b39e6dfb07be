#!/usr/bin/env python3
"""tune.py: userparms.h for a motor on a board, from two descriptions.

    python3 tools/tune.py --motor motors/hurst075.ini \
        --board boards/dspicdem_mclv/board.ini [--out userparms.h]

Reads a motor description and a board description (INI files in physical
units, format in docs/new-motor.md), derives the loop gains, observer gains,
start-up values and field-weakening settings with the formulas below, checks
every limit the firmware's fixed-point formats impose (the static assertions
of include/foc/config.h, and a few physical ones), prints a report of
derived quantities, and writes the template userparms.h.in with its values
replaced.  Comments and parameters the tool does not derive are kept as the
template has them; a value that does not change keeps its spelling, so the
output for the template's own motor and board is the template itself.

On any impossible input it prints what is wrong and which field to change,
exits with status 1 and writes nothing.  Python 3 standard library only.

Formulas (SI units; p pole pairs, psi flux linkage, fs PWM frequency):
  star equivalent      R, L = line-to-line / 2 (star or delta);
                       delta phase values / 3
  Ke (V peak L-L/krpm) = Vrms x sqrt(2) = psi x sqrt(3) x p x 1000 x 2pi/60
                       = 1000 / Kv (Kv, speed constant: rpm per V peak L-L)
  flux from Kt         psi = Kt / (1.5 p) per A peak, Kt / (1.5 sqrt(2) p)
                       per A rms
  top speed            n_top = max(max speed, 2 x nominal speed) (AN1292's
                       field-weakening goal: twice the nominal speed)
  SPEED_BASE_RPM       4/3 n_top rounded up (to 1000 rpm from 1000 rpm on)
  CURRENT_LIMIT_A      motor max current, else 1.5 x rated (2 digits)
  current PI           Kp = Lq wc, Ki = Rs wc (PI zero on the winding pole:
                       first-order loop of bandwidth wc); default
                       fc = max(1 kHz, electrical frequency at n_top),
                       at most fs/16
  speed PI             Kt = 1.5 p psi; Kp = J wb / Kt, Ki = Kp wb / 4
                       (default wb = min(600, max(50, w_L)) rad/s, w_L the
                       bandwidth an inductance error of 50 % leaves stable:
                       speed_bw_for_inductance_error)
  Luenberger observer  error poles s^2 + (Rs/L - K1) s + K2/L: critically
                       damped at wo: K2 = L wo^2, K1 = Rs/L - 2 wo, with
                       wo where the steady angle error that the EMF
                       model's Euler rotation leaves is zero at n_top (about
                       0.32 fs: observer_bw, observer_angle_error_deg);
                       reported, and at most 1 deg when given by hand;
                       F1, F2 the template's, or the nearest power of two
                       that fits
  Luenberger PLL       ST's Kp = 532 fe/fs, Ki = 1506742 fe/fs^2 (fe the
                       maximum electrical rpm; template expressions): with
                       the phase detector normalised, natural frequency
                       sqrt(72.2 fe) rad/s, damping 0.006 sqrt(fe) at the
                       maximum speed; below it the natural frequency
                       falls in proportion to the speed at that damping
                       (luenberger.h)
  PLL (AN1292)         the angle loop's gain is |w| itself (eq. 2), so its
                       bandwidth follows the speed; back-EMF filter 0.2 ms
                       (AN1292), shorter where the top speed would leave
                       the loop under 30 deg of phase margin
                       (pll_emf_filter_s: 3.46 / w_e,top); speed filter
                       the template's 1 ms
  flux estimator       the template's: correction FLUX_CORR_PER_SPEED x
                       |w_e| (+ FLUX_CORR_MIN_RAD_S), flux learning
                       FLUX_MAG_PER_SPEED x |w_e|, both following the speed
                       by themselves; speed observer poles at
                       FLUX_SPEED_OBS_BW_RAD_S (800 rad/s, above every
                       speed loop the tool derives: 600 at most); formats
                       checked
  low speed, start-up  n_low: speed whose phase back-EMF is 15 % of the
                       voltage base Vdc/sqrt(3) = PLL_LOW_SPEED_RPM =
                       STARTUP_FINAL_SPEED_RPM; minimum 1/2, sensored
                       hand-over 0.6 of it; start-up current
                       min(0.9 rated, 0.75 limit); align time 6 periods of
                       the rotor swinging on the align current,
                       wn = sqrt(1.5 p^2 psi I / J); ramp time
                       max(0.25 s, 20 J w_final / (Kt I)); time-out
                       max(1 s, 2 x (align + ramp))
  field weakening      FW_START_RPM = nominal, FW_END_RPM = 3/4 speed base,
                       FW_ID_MAX_A = 0.8 limit; voltage PI Ki = wfw / (w_nom
                       Ld) (default wfw = 160 rad/s, within the format),
                       Kp = Ki x 0.625 ms; TUNING ramp n_top / 40 per second
  board                slow divider fs / 2 kHz; over-/under-voltage 4/3 and
                       2/3 of the bus; brake resistor on/off 5/8 and 3/8 of
                       the way to the over-voltage; hysteresis bus / 24;
                       calibration 1024 PWM periods rounded up to 10 ms
  unknown inertia      J = rated torque / 20000 rad/s^2; friction 1 % of the
                       rated torque (Coulomb), 0.32 % per 1000 rpm (viscous)
Derived values are written with 4 significant digits; the values meant to be
tuned on the motor (start-up, field-weakening PI, limits) with 2.
"""

import argparse
import ast
import configparser
import difflib
import math
import os
import re
import sys
import tempfile

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SQRT3 = math.sqrt(3.0)
RPM = 2.0 * math.pi / 60.0          # rad/s per rpm

DEFAULT_SPEED_BW = 600.0            # rad/s, unless the motor needs less:
L_ERROR_ENVELOPE = 0.5              # |plant L / parameter - 1| the estimators must bear
SPEED_LAG_PHASE = 0.3               # rad the fake speed of an L error may cost the speed loop
SPEED_BW_MIN = 50.0                 # rad/s: the fan at 37 lost the follow checks (seeds 2039, 3131),
                                    # at 150 it hunted on a 3 % resistance error (docs/safety.md)
CURRENT_DIST_RATIO = 0.5            # config.h's default: the current PIs' disturbance pole / wc
DEFAULT_FW_BW = 160.0               # rad/s
PLL_EMF_FILTER_S = 0.2e-3           # AN1292's back-EMF filter, unless the top speed needs less:
PLL_PHASE_MARGIN_DEG = 30.0         # the PLL estimator's angle loop at the top speed, at least
OBSERVER_ERR_MAX_DEG = 1.0          # the Luenberger observer's steady angle error at n_top, at most
FW_PI_TIME_S = 0.625e-3             # Kp / Ki of the field-weakening PI
SAMPLES_PER_TURN_MIN = 20.0         # PWM periods per electrical turn at max_speed_rpm
EMF_LOW_FRACTION = 0.15             # back-EMF / voltage base at n_low


class InputError(Exception):
    """An input the firmware cannot work with; the message says why."""


# ------------------------------------------------------- descriptions --

MOTOR_FIELDS = {
    "name": "motor name",
    "pole_pairs": "pole pairs (poles / 2)",
    "connection": "star or delta",
    "rl_measured": "line-to-line or phase: how rs_ohm and the inductances are given",
    "rs_ohm": "stator resistance, ohm",
    "ls_h": "inductance, H (or ld_h and lq_h)",
    "ld_h": "d-axis inductance, H",
    "lq_h": "q-axis inductance, H",
    "ke_vpk_ll_per_krpm": "back-EMF constant, V peak line-to-line per 1000 rpm",
    "ke_vrms_ll_per_krpm": "back-EMF constant, V rms line-to-line per 1000 rpm",
    "flux_linkage_wb": "magnet flux linkage, Wb (peak, per phase)",
    "kv_rpm_per_v": "Kv, rpm per volt of line-to-line peak back-EMF",
    "speed_constant_rpm_per_v": "speed constant, rpm per volt line-to-line peak (as Kv)",
    "kt_nm_per_a_rms": "torque constant, Nm per A rms of phase current",
    "kt_nm_per_a_peak": "torque constant, Nm per A peak of phase current",
    "nominal_speed_rpm": "rated speed, rpm",
    "max_speed_rpm": "maximum speed, rpm",
    "rated_current_a_rms": "rated phase current, A rms",
    "rated_current_a_peak": "rated phase current, A peak",
    "max_current_a_peak": "largest allowed phase current, A peak",
    "inertia_kgm2": "rotor inertia, kg m^2",
    "viscous_nm_per_krpm": "viscous friction, Nm per 1000 rpm",
    "coulomb_nm": "dry friction, Nm",
    "notes": "free text for the header of userparms.h",
}

BOARD_FIELDS = {
    "name": "board name",
    "vdc_nominal_v": "DC bus, V",
    "vdc_full_scale_v": "bus voltage at ADC full scale, V",
    "vdc_divider_ratio": "bus divider ratio (ADC volts per bus volt)",
    "current_full_scale_a": "phase current at ADC full scale, A peak",
    "shunt_ohm": "shunt resistance, ohm",
    "amp_gain": "current amplifier gain (output centred at adc_vref_v / 2)",
    "adc_bits": "ADC resolution, bits",
    "adc_vref_v": "ADC reference, V",
    "temp_v_at_0c": "temperature sensor output at 0 degC, V",
    "temp_v_per_degc": "temperature sensor slope, V/degC",
    "pwm_frequency_hz": "PWM frequency (control rate), Hz",
    "deadtime_s": "dead time, s",
    "slow_divider": "PWM periods per slow tick",
    "overvoltage_v": "over-voltage trip, V",
    "undervoltage_v": "under-voltage trip, V",
    "brake_on_v": "brake resistor on, V",
    "brake_off_v": "brake resistor off, V",
    "notes": "free text for the header of userparms.h",
}


def ke_of_flux(psi, p):
    """Ke, V peak line-to-line per 1000 rpm, of the flux linkage psi (Wb)."""
    return psi * SQRT3 * p * 1000.0 * RPM


# The back-EMF constant: exactly one of these keys, each turned into Ke (V
# peak line-to-line per 1000 rpm) from its value v and the pole pairs p.
# Kv: 1000 rpm give 1000 / Kv V peak line-to-line; Kt = 1.5 p psi per A
# peak, sqrt(2) times that per A rms.
KE_KEYS = {
    "ke_vpk_ll_per_krpm": lambda v, p: v,
    "ke_vrms_ll_per_krpm": lambda v, p: v * math.sqrt(2.0),
    "flux_linkage_wb": ke_of_flux,
    "kv_rpm_per_v": lambda v, p: 1000.0 / v,
    "speed_constant_rpm_per_v": lambda v, p: 1000.0 / v,
    "kt_nm_per_a_rms": lambda v, p: ke_of_flux(v / (1.5 * math.sqrt(2.0) * p), p),
    "kt_nm_per_a_peak": lambda v, p: ke_of_flux(v / (1.5 * p), p),
}

HINTS = {
    "poles": "give pole_pairs = poles / 2",
    "rs": "the field is rs_ohm", "ls": "the field is ls_h",
    "ke": "give one of " + ", ".join(KE_KEYS),
    "kv": "the field is kv_rpm_per_v",
    "kt": "give kt_nm_per_a_rms or kt_nm_per_a_peak",
}


def observer_angle_error_deg(rs, l, fs, k1, k2, we):
    """The Luenberger observer's steady angle error (deg) at the electrical
    speed we (rad/s): the angle of its corrected EMF estimate (what its PLL
    locks to) against the EMF of the period it estimates.

    The observer turns its EMF estimate by h = w Ts each period with ST's
    forward Euler step (1 + j h), ahead in amplitude by h^2/2 and behind in
    phase by h^3/3 per period; its innovation absorbs that with a steady
    error.  With every quantity a phasor of z = exp(j h), the turned
    estimate is off by the fraction
        eps = (r - z)(z - g p) / ((z - r)(z - g p) + r q z),   r = 1 + j h,
    g = exp(-Rs Ts/L), p = 1 + K1 Ts, q = K2 Ts (1 - g)/Rs, and the
    corrected one (before the turn) by (1 + eps) z / r: the angle
    arg(1 + eps) + h - atan(h), to the lowest order
    h^3 ((1/2 - 5 (1 - g p)/6) / q + 1/3).  Exact for the firmware's
    discrete equations (the test simulates them)."""
    ts = 1.0 / fs
    g = math.exp(-rs * ts / l)
    gp = g * (1.0 + k1 * ts)
    q = k2 * ts * (1.0 - g) / rs
    h = we * ts
    z = complex(math.cos(h), math.sin(h))
    r = complex(1.0, h)
    eps = (r - z) * (z - gp) / ((z - r) * (z - gp) + r * q * z)
    return math.degrees(math.atan2(eps.imag, 1.0 + eps.real) + h - math.atan(h))


def observer_bw(rs, l, fs, we_top):
    """The Luenberger observer's bandwidth wo (rad/s), critically damped
    (K1 = Rs/L - 2 wo, K2 = L wo^2), from the winding, the PWM rate and the
    electrical speed at the top speed: where observer_angle_error_deg is
    zero at we_top, found by bisection over wo Ts in [0.2, 0.45] (the error
    falls through zero there: 1.8 deg at 0.28 fs, -1.0 at 0.36 fs on the
    drone motor at 12000 rpm); about 0.32 fs on a motor whose electrical
    time constant is long against Ts, up to 0.35 fs where Rs Ts/L is 0.07
    (the Hurst075 at 20 kHz).  Below that point the error grows as
    h^3 / (wo Ts)^2: ST's fixed 6661.5 rad/s (0.33 fs on the Hurst075 at
    20 kHz, 0.14 fs at 48 kHz) left 11.2 deg on the drone motor at 8000
    rpm.  Below the top speed the error left is of order h^5: a tenth of
    a degree or less."""
    def err(u):
        wo = u * fs
        return observer_angle_error_deg(rs, l, fs, rs / l - 2.0 * wo, l * wo * wo, we_top)
    lo, hi = 0.2, 0.45
    if err(lo) * err(hi) > 0.0:
        return (lo if abs(err(lo)) < abs(err(hi)) else hi) * fs
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        if err(lo) * err(mid) <= 0.0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi) * fs


def pll_phase_margin_deg(tau, we):
    """Phase margin (deg) of the PLL estimator's angle loop at the
    electrical speed we (rad/s) with the back-EMF filter tau (s).

    Eq. 2 of AN1292 makes the speed (Eqf - sgn(w) Edf) / KFi with
    Ed = -|E| sin(d): the angle error d feeds back with the gain |w| through
    the first-order filter, L(s) = |w| / (s (1 + s tau)), so the loop's
    bandwidth follows the speed by itself and only the filter's lag at the
    crossover wc (wc sqrt(1 + (wc tau)^2) = we) sets the margin,
    90 - atan(wc tau)."""
    x2 = (math.sqrt(1.0 + 4.0 * (we * tau) ** 2) - 1.0) / 2.0   # (wc tau)^2
    return 90.0 - math.degrees(math.atan(math.sqrt(x2)))


def pll_emf_filter_s(we_top):
    """AN1292's 0.2 ms back-EMF filter, shortened where the electrical
    speed at the top speed would leave the angle loop less than
    PLL_PHASE_MARGIN_DEG (wc tau = tan(90 - margin), tau = wc tau sqrt(1 +
    (wc tau)^2) / we_top: 3.46 / we_top at 30 deg, i.e. from 17300 rad/s
    on).  Shorter than it needs is noisier: on the drone motor at 8000 rpm,
    44 us instead of 0.2 ms gave 0.32 deg RMS instead of 0.28."""
    x = math.tan(math.radians(90.0 - PLL_PHASE_MARGIN_DEG))
    return min(PLL_EMF_FILTER_S, x * math.sqrt(1.0 + x * x) / we_top)


def speed_bw_for_inductance_error(p, psi, j, lq):
    """The fastest speed loop (rad/s) that an inductance error leaves stable.

    Every estimator subtracts L i from the flux (or L di/dt from the
    EMF): with the plant's L off by dL its angle is off by dL iq / psi,
    so its speed by (dL / psi) diq/dt / p.  The speed PI (Kp = J wb / Kt)
    turns that fake speed back into current: a derivative path of time
    constant tau = J wb dL / (Kt p psi).  Kept to tau wb <= SPEED_LAG_PHASE
    (its phase at the crossover), with dL the envelope's L_ERROR_ENVELOPE x Lq:
    wb^2 <= SPEED_LAG_PHASE 1.5 p^2 psi^2 / (J dL).  Motors whose Lq I is
    large beside psi (the drone motor: 1.1) need a slower speed loop
    (torture campaign, docs/safety.md)."""
    d_l = L_ERROR_ENVELOPE * lq
    return math.sqrt(SPEED_LAG_PHASE * 1.5 * p * p * psi * psi / (j * d_l))


class Description:
    """One INI section with typed, checked reads; messages name the field."""

    def __init__(self, path, section, fields):
        self.path, self.section, self.fields = path, section, fields
        cp = configparser.ConfigParser(interpolation=None,
                                       inline_comment_prefixes=("#", ";"))
        cp.optionxform = str    # keys as written: [userparms] names are upper case
        try:
            with open(path, encoding="utf-8") as f:
                cp.read_file(f)
        except OSError as e:
            raise InputError("%s: cannot read: %s" % (path, e.strerror))
        except configparser.Error as e:
            raise InputError("%s: not an INI file: %s" % (path, str(e).splitlines()[0]))
        if not cp.has_section(section):
            raise InputError("%s: no [%s] section" % (path, section))
        extra = [s for s in cp.sections() if s not in (section, "userparms")]
        if extra:
            raise InputError("%s: unknown section [%s] (only [%s] and [userparms])" % (
                path, extra[0], section))
        self.values = {k.lower(): v for k, v in cp.items(section)}
        # [userparms]: template parameters set as they are, after the tool's
        self.overrides = dict(cp.items("userparms")) if cp.has_section("userparms") else {}
        for key, value in self.overrides.items():
            if not re.match(r"^[A-Z_][A-Z0-9_]*$", key) or not value.strip():
                raise InputError("%s: [userparms] %s = %s: a userparms.h name (upper case) "
                                 "and a value" % (path, key, value))
        for key in self.values:
            if key not in fields:
                close = difflib.get_close_matches(key, fields, 1)
                hint = HINTS.get(key) or ("did you mean %s?" % close[0] if close else
                                          "known fields: " + ", ".join(fields))
                raise InputError("%s: [%s] %s: unknown field (%s)" % (path, section, key, hint))

    def where(self, key):
        return "%s: [%s] %s" % (self.path, self.section, key)

    def has(self, key):
        return self.values.get(key, "").strip() != ""

    def text(self, key, default=None):
        if not self.has(key):
            if default is None:
                raise InputError("%s: missing (%s)" % (self.where(key), self.fields[key]))
            return default
        return " ".join(self.values[key].split())

    def number(self, key, required=True, positive=True, default=None):
        if not self.has(key):
            if required:
                raise InputError("%s: missing (%s)" % (self.where(key), self.fields[key]))
            return default
        raw = self.values[key].strip()
        try:
            v = float(raw)
        except ValueError:
            raise InputError("%s = %s: not a number (%s)" % (self.where(key), raw,
                                                              self.fields[key]))
        if not math.isfinite(v):
            raise InputError("%s = %s: not a finite number" % (self.where(key), raw))
        if positive and v <= 0.0:
            raise InputError("%s = %s: must be greater than 0 (%s)" % (self.where(key), raw,
                                                                       self.fields[key]))
        return v

    def integer(self, key, lo, hi, required=True):
        v = self.number(key, required=required)
        if v is None:
            return None
        if v != int(v) or not lo <= v <= hi:
            raise InputError("%s = %s: must be a whole number %d..%d (%s)" % (
                self.where(key), self.values[key].strip(), lo, hi, self.fields[key]))
        return int(v)

    def one_of(self, keys):
        given = [k for k in keys if self.has(k)]
        if len(given) != 1:
            what = "none" if not given else ", ".join(given)
            raise InputError("%s: give exactly one of %s (%s given)" % (
                self.path + ": [" + self.section + "]", ", ".join(keys), what))
        return given[0]


def read_motor(path):
    m = Description(path, "motor", MOTOR_FIELDS)
    out = {"name": m.text("name"), "notes": m.text("notes", ""), "where": m.where,
           "overrides": m.overrides, "path": path}
    out["pole_pairs"] = m.integer("pole_pairs", 1, 64)
    connection = m.text("connection").lower()
    if connection not in ("star", "delta"):
        raise InputError("%s = %s: must be star or delta" % (m.where("connection"), connection))
    measured = m.text("rl_measured").lower()
    if measured not in ("line-to-line", "phase"):
        raise InputError("%s = %s: must be line-to-line or phase" % (
            m.where("rl_measured"), measured))
    # Equivalent star, per phase: a line-to-line measurement sees two star
    # phases in series (star), or one delta phase parallel to two (delta),
    # i.e. twice the equivalent star phase in both cases; a delta phase is
    # three times its equivalent star phase.
    factor = 0.5 if measured == "line-to-line" else (1.0 / 3.0 if connection == "delta" else 1.0)
    out["connection"], out["rl_measured"], out["rl_factor"] = connection, measured, factor
    out["rs"] = m.number("rs_ohm") * factor
    if m.has("ls_h"):
        if m.has("ld_h") or m.has("lq_h"):
            raise InputError("%s: give ls_h or ld_h and lq_h, not both" % m.where("ls_h"))
        out["ld"] = out["lq"] = m.number("ls_h") * factor
    else:
        if not (m.has("ld_h") and m.has("lq_h")):
            raise InputError("%s: missing (inductance, H: ls_h, or ld_h and lq_h)" %
                             m.where("ls_h"))
        out["ld"] = m.number("ld_h") * factor
        out["lq"] = m.number("lq_h") * factor
    p = out["pole_pairs"]
    key = m.one_of(list(KE_KEYS))
    out["ke"] = KE_KEYS[key](m.number(key), p)
    out["ke_source"] = "%s = %s" % (key, m.values[key].strip())
    out["nominal"] = m.number("nominal_speed_rpm")
    out["max"] = m.number("max_speed_rpm")
    if out["max"] < out["nominal"]:
        raise InputError("%s = %g: below nominal_speed_rpm = %g" % (
            m.where("max_speed_rpm"), out["max"], out["nominal"]))
    key = m.one_of(["rated_current_a_rms", "rated_current_a_peak"])
    out["rated"] = m.number(key) * (math.sqrt(2.0) if key.endswith("rms") else 1.0)
    out["rated_key"] = key
    out["max_current"] = m.number("max_current_a_peak", required=False)
    out["inertia"] = m.number("inertia_kgm2", required=False)
    out["viscous"] = m.number("viscous_nm_per_krpm", required=False, positive=False)
    out["coulomb"] = m.number("coulomb_nm", required=False, positive=False)
    for k in ("viscous", "coulomb"):
        if out[k] is not None and out[k] < 0.0:
            raise InputError("%s: must be >= 0" % m.where(k + ("_nm_per_krpm" if k == "viscous"
                                                                else "_nm")))
    return out


def read_board(path):
    b = Description(path, "board", BOARD_FIELDS)
    out = {"name": b.text("name"), "notes": b.text("notes", ""), "where": b.where,
           "overrides": b.overrides, "path": path}
    out["vdc"] = b.number("vdc_nominal_v")
    out["adc_bits"] = b.integer("adc_bits", 8, 16)
    out["vref"] = b.number("adc_vref_v")
    if b.one_of(["vdc_full_scale_v", "vdc_divider_ratio"]) == "vdc_full_scale_v":
        out["vdc_fs"] = b.number("vdc_full_scale_v")
    else:
        ratio = b.number("vdc_divider_ratio")
        if ratio >= 1.0:
            raise InputError("%s = %g: a divider ratio is below 1 (ADC volts per bus volt)" %
                             (b.where("vdc_divider_ratio"), ratio))
        out["vdc_fs"] = out["vref"] / ratio
    if b.has("current_full_scale_a"):
        if b.has("shunt_ohm") or b.has("amp_gain"):
            raise InputError("%s: give current_full_scale_a or shunt_ohm and amp_gain, not "
                             "both" % b.where("current_full_scale_a"))
        out["i_fs"] = b.number("current_full_scale_a")
    else:
        if not (b.has("shunt_ohm") and b.has("amp_gain")):
            raise InputError("%s: missing (give current_full_scale_a, or shunt_ohm and "
                             "amp_gain)" % b.where("current_full_scale_a"))
        # bipolar amplifier centred at half the reference: +-Vref/2 swing
        out["i_fs"] = out["vref"] / 2.0 / (b.number("shunt_ohm") * b.number("amp_gain"))
    if b.has("temp_v_at_0c") != b.has("temp_v_per_degc"):
        raise InputError("%s: give temp_v_at_0c and temp_v_per_degc together" %
                         b.where("temp_v_per_degc"))
    out["temp0"] = b.number("temp_v_at_0c", required=False, positive=False)
    out["temp_slope"] = b.number("temp_v_per_degc", required=False)
    out["fs"] = b.number("pwm_frequency_hz")
    out["deadtime"] = b.number("deadtime_s", positive=False)
    if out["deadtime"] < 0.0:
        raise InputError("%s: must be >= 0" % b.where("deadtime_s"))
    if out["deadtime"] == 0.0:
        print("tune.py: warning: %s = 0: no dead time, so dead-time compensation has "
              "nothing to compensate (it adds nothing)" % b.where("deadtime_s"),
              file=sys.stderr)
    if out["deadtime"] * out["fs"] >= 0.1:
        raise InputError("%s = %g s: %.0f %% of the PWM period (1/%g Hz); it must stay under "
                         "10 %%" % (b.where("deadtime_s"), out["deadtime"],
                                    100.0 * out["deadtime"] * out["fs"], out["fs"]))
    out["slow_divider"] = b.integer("slow_divider", 1, 100, required=False)
    for k in ("overvoltage_v", "undervoltage_v", "brake_on_v", "brake_off_v"):
        out[k] = b.number(k, required=False)
    return out


# ------------------------------------------------------------ numbers --

def sig(x, digits):
    """x rounded to `digits` significant digits."""
    return float("%.*g" % (digits, x)) if x != 0.0 else 0.0


def ceil_step(x):
    """x rounded up to a round number: 1000 rpm steps from 1000 on."""
    step = 1000.0 if x >= 1000.0 else (100.0 if x >= 100.0 else 10.0)
    return math.ceil(x / step - 1e-9) * step


def fmt(x):
    """C literal of a float, the template's style: 2000.0, 0.75, 4.8e-6."""
    neg = x < 0.0
    x = abs(x)
    if x == 0.0:
        s = "0.0"
    elif 1e-2 <= x < 1e7:
        s = repr(x)
        if "e" in s:
            s = "%.1f" % x
    else:
        e = int(math.floor(math.log10(x)))
        mant = x / 10.0 ** e
        if mant >= 9.99999999:
            mant, e = mant / 10.0, e + 1
        m = repr(float("%.6g" % mant))
        s = "%se%d" % (m, e)
    return "(-%s)" % s if neg else s


def literal_value(text):
    """Number of a C literal such as 2.0e-6, (-12000.0), 10; None if not."""
    t = text.strip()
    while t.startswith("(") and t.endswith(")"):
        t = t[1:-1].strip()
    try:
        return float(t)
    except ValueError:
        return None


# ------------------------------------------------------------ template --

DEFINE_RE = re.compile(r"^(#define\s+)([A-Z_][A-Z0-9_]*)(\s+)(\S+)(.*)$")


def read_template(path):
    try:
        with open(path, encoding="utf-8") as f:
            return f.read().split("\n")
    except OSError as e:
        raise InputError("%s: cannot read the template: %s" % (path, e.strerror))


def template_values(lines):
    """{name: value text} of single-line #defines, and expressions."""
    values, exprs = {}, {}
    k = 0
    while k < len(lines):
        line = lines[k]
        m = re.match(r"^#define\s+([A-Z_][A-Z0-9_]*)\s*(.*)$", line)
        if m:
            body = m.group(2)
            while body.rstrip().endswith("\\") and k + 1 < len(lines):
                k += 1
                body = body.rstrip()[:-1] + " " + lines[k]
            body = re.sub(r"/\*.*?\*/", "", body).strip()
            values[m.group(1)] = body
        k += 1
    return values


def eval_expr(text, env):
    """Value of a C arithmetic expression of numbers and known names."""
    text = re.sub(r"(\d)[fFlLuU]+\b", r"\1", text)
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError:
        return None

    def ev(n):
        if isinstance(n, ast.Expression):
            return ev(n.body)
        if isinstance(n, ast.Constant) and isinstance(n.value, (int, float)):
            return float(n.value)
        if isinstance(n, ast.Name):
            if n.id not in env:
                raise KeyError(n.id)
            return env[n.id]
        if isinstance(n, ast.UnaryOp) and isinstance(n.op, (ast.USub, ast.UAdd)):
            v = ev(n.operand)
            return -v if isinstance(n.op, ast.USub) else v
        if isinstance(n, ast.BinOp) and isinstance(n.op, (ast.Add, ast.Sub, ast.Mult, ast.Div)):
            a, b = ev(n.left), ev(n.right)
            if isinstance(n.op, ast.Add):
                return a + b
            if isinstance(n.op, ast.Sub):
                return a - b
            if isinstance(n.op, ast.Mult):
                return a * b
            return a / b
        raise KeyError("?")
    try:
        return ev(tree)
    except (KeyError, ZeroDivisionError):
        return None


def resolve(values, out):
    """Numbers of every template value (after `out`), expressions evaluated."""
    env = {}
    for name, text in values.items():
        v = literal_value(text)
        if v is not None:
            env[name] = v
    for name, v in out.items():
        if isinstance(v, (int, float)):
            env[name] = float(v)
    for _ in range(3):
        for name, text in values.items():
            if name not in env and name not in out:
                v = eval_expr(text, env)
                if v is not None:
                    env[name] = v
    return env


# ------------------------------------------------------------- tuning --

def choose(motor, board, opt):
    """The values the tool writes: {name: (value, digits)}; digits 0 for
    integers and None for text kept as it is."""
    p = motor["pole_pairs"]
    rs, ld, lq, ke = motor["rs"], motor["ld"], motor["lq"], motor["ke"]
    psi = ke / SQRT3 / (1000.0 * p * RPM)
    kt = 1.5 * p * psi
    rated = motor["rated"]
    fs = board["fs"]
    v_base = board["vdc"] / SQRT3
    out = {}

    def put(name, value, digits=4):
        out[name] = (value if digits == 0 else sig(value, digits), digits)

    # motor
    put("MOTOR_POLE_PAIRS", p, 0)
    put("MOTOR_RS_OHM", rs)
    put("MOTOR_LD_H", ld)
    put("MOTOR_LQ_H", lq)
    put("MOTOR_KE_VPK_PER_KRPM", ke)
    put("MOTOR_NOMINAL_SPEED_RPM", motor["nominal"], 6)
    put("MOTOR_MAX_SPEED_RPM", motor["max"], 6)
    put("MOTOR_RATED_CURRENT_A", rated)
    t_rated = kt * rated
    estimated = []
    if motor["inertia"] is None:
        motor["inertia"] = sig(t_rated / 20000.0, 2)
        estimated.append("inertia %.2g kg m^2" % motor["inertia"])
    if motor["viscous"] is None:
        motor["viscous"] = sig(0.0032 * t_rated, 2)
        estimated.append("viscous friction %.2g Nm/krpm" % motor["viscous"])
    if motor["coulomb"] is None:
        motor["coulomb"] = sig(0.01 * t_rated, 2)
        estimated.append("dry friction %.2g Nm" % motor["coulomb"])
    j = motor["inertia"]
    put("MOTOR_INERTIA_KGM2", j)
    put("MOTOR_VISCOUS_NM_PER_KRPM", motor["viscous"])
    put("MOTOR_COULOMB_NM", motor["coulomb"])

    # board
    put("BOARD_VDC_NOMINAL_V", board["vdc"], 6)
    put("BOARD_VDC_FULL_SCALE_V", board["vdc_fs"], 6)
    put("BOARD_CURRENT_FULL_SCALE_A", board["i_fs"], 4)
    put("BOARD_ADC_BITS", board["adc_bits"], 0)
    put("BOARD_ADC_VREF_V", board["vref"], 6)
    if board["temp0"] is not None:
        put("BOARD_TEMP_V_AT_0C", board["temp0"], 6)
        put("BOARD_TEMP_V_PER_DEGC", board["temp_slope"], 6)
    put("PWM_FREQUENCY_HZ", fs, 6)
    put("PWM_DEADTIME_S", board["deadtime"], 6)
    divider = board["slow_divider"] or max(1, min(100, int(round(fs / 2000.0))))
    put("CONTROL_SLOW_DIVIDER", divider, 0)
    t_slow = divider / fs

    # speeds: the electrical frequency at the highest speed the controller
    # runs (max_speed_rpm: every command is clamped to it) must leave enough
    # PWM periods per electrical turn; n_top, which may be higher (AN1292's
    # field-weakening goal of twice the nominal speed), only scales the bases
    n_top = max(motor["max"], 2.0 * motor["nominal"])
    fe_top = n_top * p / 60.0
    fe_max = motor["max"] * p / 60.0
    if fe_max * SAMPLES_PER_TURN_MIN > fs:
        raise InputError(
            "electrical frequency %.0f Hz at max_speed_rpm %.0f rpm (%s, x %d pole pairs) is "
            "too high for the PWM rate: %s = %g Hz gives only %.1f PWM periods per electrical "
            "turn, and the estimators and the current loop need at least %.0f (the rotor "
            "turns %.0f electrical degrees per period at most: the estimators' angle step, "
            "the inverse Park's advance and the loop's delay all grow with it): raise "
            "pwm_frequency_hz to %.0f Hz or lower max_speed_rpm to %.0f rpm" % (
                fe_max, motor["max"], motor["where"]("max_speed_rpm"), p,
                board["where"]("pwm_frequency_hz"), fs, fs / fe_max, SAMPLES_PER_TURN_MIN,
                360.0 / SAMPLES_PER_TURN_MIN, SAMPLES_PER_TURN_MIN * fe_max,
                60.0 * fs / (SAMPLES_PER_TURN_MIN * p)))
    base = ceil_step(4.0 / 3.0 * n_top)
    put("SPEED_BASE_RPM", base, 6)

    # current limit and loop
    if motor["max_current"] is not None:
        limit, limit_src = motor["max_current"], motor["where"]("max_current_a_peak")
    else:
        limit, limit_src = sig(1.5 * rated, 2), "1.5 x rated current (%s)" % \
            motor["where"](motor["rated_key"])
    if rated >= board["i_fs"]:
        raise InputError("rated current %.3g A peak (%s) is not below the board's full-scale "
                         "current %.3g A: the ADC cannot measure it; use a board with a larger "
                         "full scale (smaller shunt or gain)" % (
                             rated, motor["where"](motor["rated_key"]), board["i_fs"]))
    if limit >= board["i_fs"]:
        raise InputError("current limit %.3g A peak (%s) is not below the board's full-scale "
                         "current %.3g A (%s): the ADC cannot measure it; lower the limit "
                         "(max_current_a_peak) or use a board with a larger full scale" % (
                             limit, limit_src, board["i_fs"],
                             board["where"]("current_full_scale_a")))
    put("CURRENT_LIMIT_A", limit, 2)
    limit = out["CURRENT_LIMIT_A"][0]
    fc = opt.current_bw_hz
    if fc is None:
        fc = min(max(1000.0, fe_top), fs / 16.0)
    elif not 0.0 < fc <= fs / 10.0:
        raise InputError("--current-bw-hz %g: must be in (0, fs/10 = %g Hz]" % (fc, fs / 10.0))
    wc = 2.0 * math.pi * fc
    put("CURRENT_KP_V_PER_A", lq * wc)
    put("CURRENT_KI_V_PER_AS", rs * wc)

    # speed loop
    wb = opt.speed_bw_rad_s
    if wb is None:
        wb = min(DEFAULT_SPEED_BW,
                 max(SPEED_BW_MIN, speed_bw_for_inductance_error(p, psi, j, lq)))
    if not 0.0 < wb <= wc / 4.0:
        raise InputError("--speed-bw-rad-s %g: must be in (0, current-loop bandwidth / 4 = "
                         "%.0f rad/s]" % (wb, wc / 4.0))
    if wb * t_slow > 0.3:
        raise InputError("--speed-bw-rad-s %g: too fast for the slow tick (%g Hz): at most "
                         "%.0f rad/s" % (wb, 1.0 / t_slow, 0.3 / t_slow))
    kp_speed = j * wb / kt * RPM
    put("SPEED_KP_A_PER_RPM", kp_speed)
    put("SPEED_KI_A_PER_RPM_S", kp_speed * wb / 4.0)

    # observers
    put("PLL_EMF_FILTER_TIME_S", pll_emf_filter_s(fe_top * 2.0 * math.pi))
    # the observer's winding model is Lq (config.h FOC_LUEN_LS_H: the
    # extended-EMF form), so its poles are placed with Lq
    wo = opt.observer_bw_rad_s or observer_bw(rs, lq, fs, fe_top * 2.0 * math.pi)
    put("LUENBERGER_K1_PER_S", rs / lq - 2.0 * wo)
    put("LUENBERGER_K2_V_PER_AS", lq * wo * wo)

    # low speed, start-up
    n_low = sig(EMF_LOW_FRACTION * v_base / psi / p / RPM, 2)
    put("PLL_LOW_SPEED_RPM", n_low, 2)
    put("STARTUP_FINAL_SPEED_RPM", n_low, 2)
    put("STARTUP_MIN_SPEED_RPM", 0.5 * n_low, 2)
    put("SENSORED_HANDOVER_RPM", 0.6 * n_low, 2)
    i_start = sig(min(0.9 * rated, 0.75 * limit), 2)
    for name in ("STARTUP_ALIGN_CURRENT_A", "STARTUP_CURRENT_FIRST_A",
                 "STARTUP_CURRENT_FINAL_A"):
        put(name, i_start, 2)
    wn = math.sqrt(1.5 * p * p * psi * i_start / j)
    align = sig(max(0.05, 6.0 * 2.0 * math.pi / wn), 2)
    ramp = sig(max(0.25, 20.0 * j * n_low * RPM / (kt * i_start)), 2)
    put("STARTUP_ALIGN_TIME_S", align, 2)
    put("STARTUP_RAMP_TIME_S", ramp, 2)
    put("STARTUP_TIMEOUT_S", max(1.0, 2.0 * (align + ramp)), 2)

    # field weakening
    put("FW_ID_MAX_A", 0.8 * limit, 2)
    put("FW_START_RPM", motor["nominal"], 6)
    put("FW_END_RPM", 0.75 * base, 6)
    ki_fw = opt.fw_bw_rad_s / (motor["nominal"] * p * RPM * ld)
    ki_fw_max = 0.9 * board["i_fs"] / (v_base * t_slow)   # Q15 format: Ki per tick < 1 pu
    fw_note = ""
    if ki_fw > ki_fw_max:
        fw_note = " (limited by the fixed-point format from %.0f rad/s)" % opt.fw_bw_rad_s
        ki_fw = ki_fw_max
    put("FW_VOLTAGE_KI_A_PER_VS", ki_fw, 2)
    put("FW_VOLTAGE_KP_A_PER_V", out["FW_VOLTAGE_KI_A_PER_VS"][0] * FW_PI_TIME_S, 2)
    put("TUNING_RAMP_RPM_PER_S", n_top / 40.0, 2)

    # supervision, bus
    vdc = board["vdc"]
    ov = board["overvoltage_v"] or 4.0 / 3.0 * vdc
    put("OVERVOLTAGE_V", ov)
    put("UNDERVOLTAGE_V", board["undervoltage_v"] or 2.0 / 3.0 * vdc)
    put("BUS_HYSTERESIS_V", vdc / 24.0, 2)
    put("BRAKE_RESISTOR_ON_V", board["brake_on_v"] or vdc + 5.0 / 8.0 * (ov - vdc))
    put("BRAKE_RESISTOR_OFF_V", board["brake_off_v"] or vdc + 3.0 / 8.0 * (ov - vdc))
    put("CALIB_TIME_S", math.ceil(1024.0 / fs / 0.01 - 1e-9) * 0.01, 2)

    if opt.estimator:
        out["FOC_ESTIMATOR"] = ("FOC_EST_" + opt.estimator.upper(), None)

    info = {"psi": psi, "kt": kt, "t_rated": t_rated, "n_top": n_top, "fe_top": fe_top,
            "fc": fc, "wb": wb, "wo": wo, "limit": limit, "estimated": estimated,
            "fw_note": fw_note, "v_base": v_base}
    return out, info


def fit_luenberger_f(env):
    """F1, F2: the template's, or the power of two nearest to it whose
    observer constants fit their formats (config.h); None if none does."""
    def c_values(f1, f2):
        e = dict(env)
        e["LUENBERGER_F1"], e["LUENBERGER_F2"] = f1, f2
        return derive(e)

    def ok1(d):
        return (d["C1"] >= 1.0 and d["C1"] < 32767.0 and 16.0 <= d["C5"] < 32767.0 and
                16.0 <= d["C3"] < 32767.0 and -32767.0 < d["C2"] <= -16.0 and
                d["C1"] - d["C2"] + d["C3"] + d["C5"] + d["F1"] < 65535.0)

    def ok2(d):
        return 16.0 <= d["C4"] < 32767.0 and 1.5 * d["F2"] + d["C4"] < 65535.0

    powers = [2.0 ** k for k in range(4, 15)]
    f1_0, f2_0 = env["LUENBERGER_F1"], env["LUENBERGER_F2"]
    near = lambda x0: sorted(powers, key=lambda f: (abs(math.log2(f / x0)), -f))
    f1 = next((f for f in near(f1_0) if ok1(c_values(f, f2_0))), None)
    f2 = next((f for f in near(f2_0) if ok2(c_values(f1 or f1_0, f))), None)
    return f1, f2


# ---------------------------------------------- config.h, in Python --

def gain_shift(x):
    s = 0
    while s < 15 and x >= 2.0 ** s:
        s += 1
    return s


def norm_ok(x):
    return 1.0 / 32768.0 <= x < 16384.0


def derive(e):
    """The per-unit quantities config.h derives, from numbers `e`."""
    d = {}
    ts = 1.0 / e["PWM_FREQUENCY_HZ"]
    d["ts"] = ts
    d["t_slow"] = ts * e["CONTROL_SLOW_DIVIDER"]
    ib = e["BOARD_CURRENT_FULL_SCALE_A"]
    vb = e["BOARD_VDC_NOMINAL_V"] / SQRT3
    p = e["MOTOR_POLE_PAIRS"]
    web = e["SPEED_BASE_RPM"] * p * RPM
    psi = e["MOTOR_KE_VPK_PER_KRPM"] / SQRT3 / (1000.0 * p * RPM)
    rs, ld, lq = e["MOTOR_RS_OHM"], e["MOTOR_LD_H"], e["MOTOR_LQ_H"]
    d.update(ib=ib, vb=vb, web=web, psi=psi)
    d["dtheta"] = 65536.0 * web / (2.0 * math.pi) * ts
    d["cur_kp"] = e["CURRENT_KP_V_PER_A"] * ib / vb
    # the current PIs' integral gain as config.h makes it (two degrees of
    # freedom: the disturbance pole at max(Ki/Kp, CURRENT_DIST_RATIO wc))
    kp, ki = e["CURRENT_KP_V_PER_A"], e["CURRENT_KI_V_PER_AS"]
    dist = max(ki / kp, CURRENT_DIST_RATIO * kp / lq)
    kref = lq * (dist - ki / kp)
    d["cur_kref"] = kref
    d["cur_ki"] = (dist * (kp - kref) if kref > 0.0 else ki) * ts * ib / vb
    d["spd_kp"] = e["SPEED_KP_A_PER_RPM"] * e["SPEED_BASE_RPM"] / ib
    d["spd_ki"] = e["SPEED_KI_A_PER_RPM_S"] * d["t_slow"] * e["SPEED_BASE_RPM"] / ib
    d["ramp"] = e["SPEED_RAMP_RPM_PER_S"] * d["t_slow"] / e["SPEED_BASE_RPM"]
    d["rs_pu"] = rs * ib / vb
    d["lsdt_pu"] = lq * ib / (vb * ts)
    d["kfi"] = psi * web / vb
    d["pll_inv_kfi"] = 2.0 / d["kfi"]
    # Luenberger (its model is on Lq: the extended back-EMF, luenberger.h)
    ls = lq
    x = rs * ts / ls
    zoh = 1.0 - x / 2.0 + x * x / 6.0 - x ** 3 / 24.0 + x ** 4 / 120.0
    g = x * zoh
    b = ts / ls * zoh
    eb = d["kfi"] * vb
    f1, f2 = e["LUENBERGER_F1"], e["LUENBERGER_F2"]
    k1, k2 = e["LUENBERGER_K1_PER_S"], e["LUENBERGER_K2_V_PER_AS"]
    d.update(F1=f1, F2=f2, luen_x=x)
    d["C1"] = f1 * g
    d["C2"] = f1 * k1 * ts
    d["C3"] = f1 * b * eb / ib
    d["C4"] = f2 * k2 * ts * ib / eb
    d["C5"] = f1 * b * vb / ib
    d["C6"] = 65536.0 * web * ts
    d["det"] = (1.0 + k1 * ts) * (1.0 - g)
    d["k2tb"] = k2 * ts * b
    n_top = max(e["MOTOR_MAX_SPEED_RPM"], 2.0 * e["MOTOR_NOMINAL_SPEED_RPM"])
    d["pll_margin_top_deg"] = pll_phase_margin_deg(e["PLL_EMF_FILTER_TIME_S"], n_top * p * RPM)
    d["luen_err_top_deg"] = observer_angle_error_deg(rs, ls, e["PWM_FREQUENCY_HZ"], k1, k2,
                                                     n_top * p * RPM)
    unit = 32768.0 / d["dtheta"]
    d["lpll_kp"] = e.get("LUENBERGER_PLL_KP", 1.0) / 16384.0 * unit
    d["lpll_ki"] = e.get("LUENBERGER_PLL_KI", 1e-3) / 65536.0 * unit
    # flux estimator
    base0 = vb / web
    peak0 = (psi + lq * ib) / base0
    shift = gain_shift(2.0 * peak0)
    fbase = base0 * 2.0 ** shift
    d["flux_shift"] = shift
    d["flux_ls"] = lq * ib / fbase
    d["flux_kint"] = web * ts * 131072.0 / 2.0 ** shift
    d["flux_corr_min"] = e["FLUX_CORR_MIN_RAD_S"] * ts
    d["flux_corr_speed"] = e["FLUX_CORR_PER_SPEED"] * web * ts
    d["flux_mag_speed"] = e["FLUX_MAG_PER_SPEED"] * web * ts
    wo = e["FLUX_SPEED_OBS_BW_RAD_S"]
    rad_count = 2.0 * math.pi / 65536.0
    q31 = 2147483648.0 / web
    accel = 1.5 * p * p * psi * ib / e["MOTOR_INERTIA_KGM2"]
    d["sobs_l1"] = 3.0 * wo * ts
    d["sobs_l2"] = 3.0 * wo * wo * ts * rad_count * q31
    d["sobs_l3"] = wo ** 3 * ts * rad_count / accel * 134217728.0
    d["sobs_ff"] = accel * ts * q31 / 32768.0
    # field weakening
    d["fw_kp"] = e["FW_VOLTAGE_KP_A_PER_V"] * vb / ib
    d["fw_ki"] = e["FW_VOLTAGE_KI_A_PER_VS"] * d["t_slow"] * vb / ib
    vfw = vb * e["VOLTAGE_LIMIT_FRACTION"] * e["FW_VOLTAGE_MARGIN"]
    d["vfw"] = vfw
    d["fw_max_rpm"] = float("inf") if ld * e["FW_ID_MAX_A"] >= psi else \
        vfw / (psi - ld * e["FW_ID_MAX_A"]) / p / RPM
    span = (e["FW_END_RPM"] - e["FW_START_RPM"]) / e["SPEED_BASE_RPM"] * 32768.0
    d["fw_pos"] = 256.0 * 17 / span if span > 0 else float("inf")
    return d


def checks(e, d):
    """(condition, message) of config.h's static assertions that the motor
    and board decide, and a few physical ones, in the terms of the
    descriptions; the first that fails is reported."""
    ls_note = ("Ls = %.4g H, Rs = %.4g ohm, Ts = %.4g s, voltage base %.4g V, current base "
               "%.4g A" % (e["MOTOR_LQ_H"], e["MOTOR_RS_OHM"], d["ts"], d["vb"], d["ib"]))
    emf_base = d["kfi"] * d["vb"]
    c = [
        # board and bases
        (e["BOARD_VDC_NOMINAL_V"] < e["BOARD_VDC_FULL_SCALE_V"],
         "the bus voltage vdc_nominal_v (%.4g V) must be below the bus ADC full scale "
         "(%.4g V: vdc_full_scale_v, or adc_vref_v / vdc_divider_ratio)" % (
             e["BOARD_VDC_NOMINAL_V"], e["BOARD_VDC_FULL_SCALE_V"])),
        (e["CURRENT_LIMIT_A"] < e["BOARD_CURRENT_FULL_SCALE_A"],
         "CURRENT_LIMIT_A must be below BOARD_CURRENT_FULL_SCALE_A"),
        (e["UNDERVOLTAGE_V"] + e["BUS_HYSTERESIS_V"] < e["BOARD_VDC_NOMINAL_V"] and
         e["OVERVOLTAGE_V"] - e["BUS_HYSTERESIS_V"] > e["BOARD_VDC_NOMINAL_V"],
         "the bus thresholds must bracket vdc_nominal_v (%.4g V) by more than the hysteresis "
         "(%.4g V): under-voltage %.4g V, over-voltage %.4g V" % (
             e["BOARD_VDC_NOMINAL_V"], e["BUS_HYSTERESIS_V"], e["UNDERVOLTAGE_V"],
             e["OVERVOLTAGE_V"])),
        (1.2 * e["OVERVOLTAGE_V"] < e["BOARD_VDC_FULL_SCALE_V"],
         "the bus ADC full scale (%.4g V: vdc_full_scale_v, or adc_vref_v / vdc_divider_ratio) "
         "must exceed 1.2 x the over-voltage trip (1.2 x %.4g V = %.4g V), so that the bus "
         "stays measurable through a regenerative rise past the trip: set overvoltage_v "
         "(default 4/3 x vdc_nominal_v) lower, at least vdc_nominal_v + %.4g V of hysteresis, "
         "or use a divider with a larger full scale" % (
             e["BOARD_VDC_FULL_SCALE_V"], e["OVERVOLTAGE_V"], 1.2 * e["OVERVOLTAGE_V"],
             e["BUS_HYSTERESIS_V"])),
        (e["BRAKE_RESISTOR_OFF_V"] < e["BRAKE_RESISTOR_ON_V"],
         "brake_off_v must be below brake_on_v"),
        (e["MOTOR_MAX_SPEED_RPM"] < e["SPEED_BASE_RPM"],
         "SPEED_BASE_RPM must exceed MOTOR_MAX_SPEED_RPM"),
        (d["dtheta"] < 16384.0,
         "the speed base x pole pairs is too high for pwm_frequency_hz (more than 90 "
         "electrical degrees per PWM period)"),
        (e["CALIB_TIME_S"] * e["PWM_FREQUENCY_HZ"] >= 1024.0,
         "CALIB_TIME_S must cover at least 1024 PWM periods"),
        # motor constants in per unit
        (d["rs_pu"] < 32768.0, "rs_ohm (%.4g ohm) is too high for the per-unit format of the "
         "board (x current base / voltage base overflows)" % e["MOTOR_RS_OHM"]),
        (2.0 * d["lsdt_pu"] < 32768.0, "the inductance is too high: Ls/Ts x current base / "
         "voltage base overflows its format (%s)" % ls_note),
        (d["kfi"] < 32768.0, "the back-EMF constant is too high (KFi overflows)"),
        (d["kfi"] > 1.0 / 8192.0 and 4.0 * d["pll_inv_kfi"] < 32768.0,
         "the back-EMF constant (%.4g V peak L-L per krpm) is too low for the speed base and "
         "the bus voltage (1/KFi overflows)" % e["MOTOR_KE_VPK_PER_KRPM"]),
        (d["fw_max_rpm"] >= e["MOTOR_NOMINAL_SPEED_RPM"],
         "the motor cannot reach its nominal speed (%.0f rpm) on a %.4g V bus: its back-EMF "
         "there is %.4g V peak per phase against %.4g V the inverter gives, and even with "
         "field weakening (Id = -%.3g A) the estimate is %.0f rpm; check the back-EMF "
         "constant and its unit, or use a higher bus voltage" % (
             e["MOTOR_NOMINAL_SPEED_RPM"], e["BOARD_VDC_NOMINAL_V"],
             d["psi"] * e["MOTOR_NOMINAL_SPEED_RPM"] * e["MOTOR_POLE_PAIRS"] * RPM, d["vfw"],
             e["FW_ID_MAX_A"], d["fw_max_rpm"])),
        (e["STARTUP_FINAL_SPEED_RPM"] < e["MOTOR_MAX_SPEED_RPM"],
         "the back-EMF constant (%.4g V peak L-L per krpm) is too low for the bus voltage: "
         "the back-EMF reaches 15 %% of the phase voltage Vdc/sqrt(3) only at %.0f rpm, above "
         "max_speed_rpm (%.0f): the estimators would never see it" % (
             e["MOTOR_KE_VPK_PER_KRPM"], e["STARTUP_FINAL_SPEED_RPM"],
             e["MOTOR_MAX_SPEED_RPM"])),
        (e["STARTUP_ALIGN_CURRENT_A"] <= e["CURRENT_LIMIT_A"],
         "start-up currents must be within CURRENT_LIMIT_A"),
        (e["STARTUP_MIN_SPEED_RPM"] < e["STARTUP_FINAL_SPEED_RPM"] *
         e["STARTUP_SPEED_WINDOW_MAX"],
         "STARTUP_MIN_SPEED_RPM cannot be reached by the open-loop ramp"),
        # loops
        (d["cur_kp"] < 32768.0, "CURRENT_KP_V_PER_A overflows its per-unit format: the "
         "inductance is too high for the board's voltage and current bases (%s)" % ls_note),
        (e["CURRENT_KI_V_PER_AS"] * d["ts"] * d["ib"] / d["vb"] < 1.0,
         "CURRENT_KI_V_PER_AS too high: Ki per PWM period must be < 1 per unit (rs_ohm too "
         "high for the board, or the current bandwidth)"),
        (d["cur_ki"] / d["cur_kp"] < 1.0, "the winding time constant Ls/Rs is shorter than a "
         "PWM period: the current PI's anti-windup gain overflows (%s)" % ls_note),
        (d["spd_kp"] < 32768.0 and d["spd_ki"] < 32768.0,
         "the speed PI gains overflow their format: inertia_kgm2 (%.4g kg m^2) too high for "
         "the torque constant and the board's current base" % e["MOTOR_INERTIA_KGM2"]),
        (d["spd_ki"] / d["spd_kp"] < 1.0, "speed PI: Ki/Kp too high for the slow tick"),
        (d["ramp"] < 0.5, "SPEED_RAMP_RPM_PER_S too high for the slow tick"),
        (0.0 <= e["FW_ID_MAX_A"] <= e["CURRENT_LIMIT_A"],
         "FW_ID_MAX_A must be within [0, CURRENT_LIMIT_A]"),
        (0.0 < d["fw_kp"] < 32768.0 and d["fw_ki"] < 1.0 and d["fw_ki"] / d["fw_kp"] < 1.0,
         "FW_VOLTAGE_KP_A_PER_V / FW_VOLTAGE_KI_A_PER_VS out of range"),
        (0.0 < e["FW_START_RPM"] < e["FW_END_RPM"] < e["SPEED_BASE_RPM"],
         "need 0 < FW_START_RPM < FW_END_RPM < SPEED_BASE_RPM"),
        (d["fw_pos"] < 32768.0, "FW_END_RPM - FW_START_RPM too small"),
        # Luenberger observer (F1, F2 already the best powers of two)
        (d["luen_x"] < 0.5, "the winding time constant Ls/Rs is below 2 PWM periods: too "
         "short for the Luenberger observer (%s)" % ls_note),
        (16.0 <= d["C5"] < 32767.0, "the inductance is too high for the fixed-point format "
         "(is ls_h in henry, not millihenry?): the Luenberger observer's voltage constant "
         "C5 = F1 Ts/Ls x voltage base / current base is below 16 for every F1 up to 16384 "
         "(%s)" % ls_note),
        (d["C1"] >= 1.0, "rs_ohm is too low for the inductance: the winding time constant "
         "Ls/Rs (%.3g s) is too long for the observer's format (C1 = F1 (1 - exp(-Rs Ts/Ls)) "
         "below 1 with F1 up to 16384; %s)" % (e["MOTOR_LQ_H"] / e["MOTOR_RS_OHM"], ls_note)),
        (16.0 <= d["C3"] < 32767.0, "the back-EMF at the speed base (%.4g V) is out of range "
         "for the Luenberger observer's format against the inductance (C3 = F1 Ts/Ls x EMF "
         "base / current base; %s)" % (emf_base, ls_note)),
        (-32767.0 < d["C2"] <= -16.0, "--observer-bw-rad-s out of range for "
         "pwm_frequency_hz (observer constant C2 = F1 K1 Ts)"),
        (d["C1"] - d["C2"] + d["C3"] + d["C5"] + d["F1"] < 65535.0,
         "the Luenberger observer's current update could overflow 32 bits (F1)"),
        (16.0 <= d["C4"] < 32767.0 and 1.5 * d["F2"] + d["C4"] < 65535.0,
         "the Luenberger observer's EMF gain C4 = F2 K2 Ts x current base / EMF base is out "
         "of range for every F2: K2 = Ls wo^2 = %.4g V/(A s) against the back-EMF at the "
         "speed base (%.4g V): the inductance is too high or the back-EMF constant too low "
         "(or change --observer-bw-rad-s)" % (e["LUENBERGER_K2_V_PER_AS"], emf_base)),
        (d["C6"] < 32767.0, "the speed base x pole pairs is too high for pwm_frequency_hz "
         "(Luenberger observer: over 0.5 rad per PWM period)"),
        # config.h's current PIs (two degrees of freedom, CURRENT_DIST_RATIO)
        (d["cur_ki"] < 0.5, "the current PIs' integral gain, with config.h's "
         "CURRENT_DIST_RATIO (%g), exceeds 0.5 per unit per PWM period: the inductance or "
         "rs_ohm too high for the board, or the current bandwidth (%s)"
         % (CURRENT_DIST_RATIO, ls_note)),
        (d["cur_kref"] < e["CURRENT_KP_V_PER_A"], "CURRENT_DIST_RATIO too high for the current "
         "PI's gains: the reference's gain must stay positive"),
        (-1.0 < d["det"] < 1.0 and 0.0 < d["k2tb"] < 2.0 * (1.0 + d["det"]),
         "the Luenberger observer's error dynamics are unstable at pwm_frequency_hz "
         "(lower --observer-bw-rad-s)"),
        (d["pll_margin_top_deg"] >= PLL_PHASE_MARGIN_DEG - 0.5,
         "PLL_EMF_FILTER_TIME_S (%.3g s) leaves the PLL estimator's angle loop %.0f deg of "
         "phase margin at the top speed; at least %g: shorten it" % (
             e["PLL_EMF_FILTER_TIME_S"], d["pll_margin_top_deg"], PLL_PHASE_MARGIN_DEG)),
        (abs(d["luen_err_top_deg"]) <= OBSERVER_ERR_MAX_DEG,
         "the Luenberger observer's EMF model (its Euler rotation) leaves %.2f deg of angle "
         "error at the top speed with K1 = %.4g 1/s, K2 = %.4g V/(A s); at most %g deg: "
         "leave --observer-bw-rad-s at its default, or raise pwm_frequency_hz" % (
             d["luen_err_top_deg"], e["LUENBERGER_K1_PER_S"], e["LUENBERGER_K2_V_PER_AS"],
             OBSERVER_ERR_MAX_DEG)),
        (0.0 < d["lpll_kp"] < 32768.0 and 1.0 / 32768.0 < d["lpll_ki"] < 1.0,
         "LUENBERGER_PLL_KP / LUENBERGER_PLL_KI out of range for this motor and PWM rate"),
        # flux estimator
        (d["flux_shift"] <= 14 and d["flux_ls"] < 0.5,
         "the inductance or the back-EMF constant is out of range for the flux estimator's "
         "format"),
        (d["flux_kint"] < 8192.0 and norm_ok(d["flux_kint"]),
         "the speed base x pole pairs / pwm_frequency_hz is out of range for the flux "
         "integrator"),
        (d["flux_corr_min"] <= 0.5 and d["flux_corr_speed"] < 1.0 and
         d["flux_mag_speed"] < 0.5,
         "the flux estimator's correction gains are too high for the speed base at "
         "pwm_frequency_hz"),
        (d["sobs_l1"] < 0.5 and norm_ok(d["sobs_l2"]) and norm_ok(d["sobs_l3"]) and
         norm_ok(d["sobs_ff"]),
         "the flux estimator's speed observer is out of range for inertia_kgm2 (%.4g kg m^2) "
         "and the board's current base" % e["MOTOR_INERTIA_KGM2"]),
    ]
    if "DEADTIME_COMP_CURRENT_A" in e:
        c.append((e["BOARD_CURRENT_FULL_SCALE_A"] / e["DEADTIME_COMP_CURRENT_A"] < 32768.0,
                  "DEADTIME_COMP_CURRENT_A too small for the board's current base"))
    return c


# ------------------------------------------------------------- output --

def header_block(motor, board, opt, info, motor_path, board_path):
    def rel(path):
        a = os.path.abspath(path)
        return os.path.relpath(a, REPO) if a.startswith(REPO + os.sep) else a

    def wrap(first, text, width=77):
        lines, line = [], " * " + first
        for word in text.split():
            if len(line) + 1 + len(word) > width:
                lines.append(line)
                line = " *   " + word
            else:
                line += " " + word
        lines.append(line)
        return lines

    out = wrap("Motor:", "%s, described in %s%s" % (
        motor["name"], rel(motor_path), ": " + motor["notes"] if motor["notes"] else "."))
    out += wrap("Board:", "%s, described in %s%s" % (
        board["name"], rel(board_path), ": " + board["notes"] if board["notes"] else "."))
    how = "current loop %g Hz, speed loop %g rad/s, observer %g rad/s" % (
        info["fc"], info["wb"], info["wo"])
    flags = [f for f, on in (("OPEN_LOOP_FUNCTIONING", opt.open_loop_functioning),
                             ("TUNING", opt.tuning), ("explicit FW tables", opt.fw_tables)) if on]
    if flags:
        how += "; " + ", ".join(flags)
    if info["estimated"]:
        how += "; estimated (not in the motor file): " + ", ".join(info["estimated"])
    pinned = sorted(set(motor["overrides"]) | set(board["overrides"]))
    if pinned:
        how += "; as the descriptions' [userparms] set them: " + ", ".join(pinned)
    out += wrap("Written by tools/tune.py:", how + ".")
    return out


def fw_tables(e, d):
    """Explicit initial field-weakening tables (AN1292's three), the same
    values config.h derives, for tuning entry by entry."""
    ids = []
    vfw = d["vb"] * e["VOLTAGE_LIMIT_FRACTION"] * e["FW_VOLTAGE_MARGIN"]
    for i in range(18):
        rpm = e["FW_START_RPM"] + i * (e["FW_END_RPM"] - e["FW_START_RPM"]) / 17.0
        we = rpm * e["MOTOR_POLE_PAIRS"] * RPM
        raw = (vfw / we - d["psi"]) / e["MOTOR_LD_H"]
        ids.append(min(0.0, max(-e["FW_ID_MAX_A"], raw)))

    def table(name, entries):
        lines, line = ["#define %s" % name + " " * max(1, 27 - len(name)) + "\\"], "    {"
        for k, s in enumerate(entries):
            item = " " + s + ("," if k < len(entries) - 1 else " }")
            if len(line) + len(item) > 76:
                lines.append(line + " " * (78 - len(line)) + "\\")
                line = "     "
            line += item
        lines.append(line)
        return lines
    out = ["/* Initial tables (tools/tune.py --fw-tables): Id in amperes, 1/KFi as a",
           " * ratio to nominal, Ls/(2 Ls0); entry i at FW_START_RPM + i/17 x",
           " * (FW_END_RPM - FW_START_RPM).  Tune them in TUNING mode. */"]
    out += table("FW_ID_TABLE", ["FOC_I_Q15(%.3f)" % (v if abs(v) >= 5e-4 else 0.0)
                                 for v in ids])
    out += table("FW_INVKFI_TABLE", ["FOC_FW_INVKFI_Q(1.0)"] * 18)
    out += table("FW_LS_TABLE", ["Q15(0.5)"] * 18)
    return out


def render(lines, values, header, extra_after_fw_end):
    out, replaced = [], set()
    k, n = 0, len(lines)
    in_header = False
    while k < n:
        line = lines[k]
        if line.startswith(" * Motor:") and header is not None:
            out.extend(header)
            in_header = True
            k += 1
            continue
        if in_header:
            if line.strip() in ("*", "*/"):
                in_header = False
            else:
                k += 1
                continue
        m = DEFINE_RE.match(line)
        if m and m.group(2) in values:
            name = m.group(2)
            value, digits = values[name]
            old = m.group(4)
            if digits is None:
                new = value
            elif digits == 0:
                new = str(int(value))
            else:
                old_v = literal_value(old)
                new = old if old_v is not None and old_v == value else fmt(value)
            rest = m.group(5)
            if rest.strip():
                col = len(m.group(1) + m.group(2) + m.group(3) + old) + \
                    (len(rest) - len(rest.lstrip()))
                head = m.group(1) + m.group(2) + m.group(3) + new
                rest = " " * max(1, col - len(head)) + rest.lstrip()
            line = m.group(1) + m.group(2) + m.group(3) + new + rest
            replaced.add(name)
        out.append(line)
        if m and m.group(2) == "FW_END_RPM" and extra_after_fw_end:
            out.extend(extra_after_fw_end)
        k += 1
    return out, replaced


def set_flag(lines, name, on):
    """`/* #define NAME */` <-> `#define NAME`."""
    if not on:
        return lines
    for k, line in enumerate(lines):
        if line.strip() == "/* #define %s */" % name:
            lines[k] = "#define %s" % name
            return lines
        if line.strip() == "#define %s" % name:
            return lines
    raise InputError("template: no '/* #define %s */' line" % name)


def report(motor, board, e, d, info, f):
    p = e["MOTOR_POLE_PAIRS"]
    psi, rs, l = d["psi"], e["MOTOR_RS_OHM"], e["MOTOR_LQ_H"]
    vlim = d["vb"] * e["VOLTAGE_LIMIT_FRACTION"]
    w0 = vlim / psi
    # rated current on q: (Rs I + w psi)^2 + (w L I)^2 = Vlim^2
    i = e["MOTOR_RATED_CURRENT_A"]
    a, b, c = psi ** 2 + (l * i) ** 2, 2.0 * rs * i * psi, (rs * i) ** 2 - vlim ** 2
    w1 = (-b + math.sqrt(b * b - 4 * a * c)) / (2 * a)
    idm = e["FW_ID_MAX_A"]
    vfw = vlim * e["FW_VOLTAGE_MARGIN"]
    ld = e["MOTOR_LD_H"]
    fw_max = "unlimited by the voltage (Ld x FW_ID_MAX_A >= flux)" if ld * idm >= psi else \
        "%.0f rpm" % (vfw / (psi - ld * idm) / p / RPM)
    # with the q current the current limit leaves beside Id (the voltage
    # (psi - Ld Id, Lq Iq) x w, resistance aside)
    i_ref_max = e["CURRENT_LIMIT_A"] * (1.0 - e.get("CURRENT_REF_MARGIN", 0.10))
    iq_left = math.sqrt(max(0.0, i_ref_max ** 2 - idm ** 2))
    fw_loaded = vfw / math.hypot(psi - ld * idm, l * iq_left) / p / RPM
    # MTPA at the rated current (mtpa.h): id = (psi - sqrt(psi^2 + 8 dL^2 I^2)) / (4 dL)
    dl = l - ld
    mtpa = None
    if dl > 0.0:
        id_m = (psi - math.sqrt(psi * psi + 8.0 * dl * dl * i * i)) / (4.0 * dl)
        gain = (psi - dl * id_m) * math.sqrt(i * i - id_m * id_m) / (psi * i) - 1.0
        mtpa = ("MTPA at rated current", "Id %.3g A, torque per ampere +%.2f %% over Id = 0" % (
            id_m, 100.0 * gain))
    tau = l / rs
    z = sorted(abs(r) for r in roots2(1.0, -(d["det"] + 1.0 - d["k2tb"]), d["det"]))
    rows = [
        ("flux linkage", "%.4g Wb (Ke %.4g V peak L-L per krpm, %s)" % (
            psi, e["MOTOR_KE_VPK_PER_KRPM"], motor["ke_source"])),
        ("star equivalent", "Rs %.4g ohm, Ld %.4g mH, Lq %.4g mH (%s, %s values)" % (
            rs, ld * 1e3, l * 1e3, motor["connection"], motor["rl_measured"])),
        ("torque constant", "%.4g Nm/A peak; rated %.3g A peak = %.3g Nm" % (
            info["kt"], i, info["kt"] * i)),
        ("electrical time constant", "%.3g ms (Lq/Rs) = %.1f PWM periods" % (
            tau * 1e3, tau * e["PWM_FREQUENCY_HZ"])),
        ("base speed at %.4g V" % e["BOARD_VDC_NOMINAL_V"],
         "%.0f rpm no load, %.0f rpm at rated current (|V| %.3g V)" % (
             w0 / p / RPM, w1 / p / RPM, vlim)),
        ("max. field-weakening speed", "%s estimate (no load, Id = -%.3g A)%s; %.0f rpm with "
         "Iq %.3g A" % (
            fw_max, idm, "" if ld * idm >= psi or vfw / (psi - ld * idm) / p / RPM >=
            info["n_top"] else "; below the top speed %.0f rpm" % info["n_top"],
            fw_loaded, iq_left)),
    ] + ([mtpa] if mtpa else []) + [
        ("electrical frequency", "%.1f Hz at %.0f rpm: %.1f PWM periods per turn" % (
            info["fe_top"], info["n_top"], e["PWM_FREQUENCY_HZ"] / info["fe_top"])),
        ("speed base", "%.0f rpm (%.0f electrical degrees per PWM period)" % (
            e["SPEED_BASE_RPM"], d["dtheta"] * 360.0 / 65536.0)),
        ("current loop", "%.0f Hz: Kp %.4g V/A, Ki %.4g V/(A s)" % (
            info["fc"], e["CURRENT_KP_V_PER_A"], e["CURRENT_KI_V_PER_AS"])),
        ("speed loop", "%.0f rad/s: Kp %.4g A/rpm, Ki %.4g A/(rpm s)" % (
            info["wb"], e["SPEED_KP_A_PER_RPM"], e["SPEED_KI_A_PER_RPM_S"])),
        ("PLL estimator", "back-EMF filter %.3g ms: angle loop phase margin %.0f deg at %.0f "
         "rpm" % (e["PLL_EMF_FILTER_TIME_S"] * 1e3, d["pll_margin_top_deg"], info["n_top"])),
        ("Luenberger observer", "%.0f rad/s: K1 %.4g 1/s, K2 %.4g V/(A s); discrete poles "
         "%.3f, %.3f; F1 %d, F2 %d; angle error %.2f deg at %.0f rpm" % (
             info["wo"], e["LUENBERGER_K1_PER_S"], e["LUENBERGER_K2_V_PER_AS"], z[-1], z[0],
             e["LUENBERGER_F1"], e["LUENBERGER_F2"], d["luen_err_top_deg"], info["n_top"])),
        ("field weakening", "Id max %.3g A, voltage PI Kp %.3g A/V, Ki %.3g A/(V s)%s" % (
            idm, e["FW_VOLTAGE_KP_A_PER_V"], e["FW_VOLTAGE_KI_A_PER_VS"], info["fw_note"])),
        ("start-up", "align %.3g A for %.3g s, ramp to %.0f rpm in %.3g s, time-out %.3g s" % (
            e["STARTUP_ALIGN_CURRENT_A"], e["STARTUP_ALIGN_TIME_S"],
            e["STARTUP_FINAL_SPEED_RPM"], e["STARTUP_RAMP_TIME_S"], e["STARTUP_TIMEOUT_S"])),
        ("current limit", "%.3g A peak (board full scale %.4g A)" % (
            e["CURRENT_LIMIT_A"], e["BOARD_CURRENT_FULL_SCALE_A"])),
    ]
    for k, v in rows:
        print("  %-27s %s" % (k, v), file=f)
    for w in info["estimated"]:
        print("  note: estimated, not in the motor file: %s" % w, file=f)
    if e["CURRENT_LIMIT_A"] < i:
        print("  note: the current limit is below the rated current: less than the rated "
              "torque", file=f)
    if w0 / p / RPM < e["MOTOR_NOMINAL_SPEED_RPM"]:
        print("  note: the nominal speed needs field weakening at this bus voltage", file=f)


def roots2(a, b, c):
    disc = b * b - 4 * a * c
    if disc >= 0:
        r = math.sqrt(disc)
        return [(-b + r) / (2 * a), (-b - r) / (2 * a)]
    m = math.sqrt(c / a)
    return [m, m]


def main(argv=None):
    ap = argparse.ArgumentParser(
        description="Writes userparms.h for a motor on a board (docs/new-motor.md).")
    ap.add_argument("--motor", required=True, help="motor description (INI)")
    ap.add_argument("--board", required=True, help="board description (INI)")
    ap.add_argument("--out", default="userparms.h", help="output file (default userparms.h)")
    ap.add_argument("--template", default=os.path.join(REPO, "userparms.h.in"))
    ap.add_argument("--current-bw-hz", type=float, default=None,
                    help="current-loop bandwidth (default max(1 kHz, electrical frequency "
                    "at the top speed), at most fs/16)")
    ap.add_argument("--speed-bw-rad-s", type=float, default=None,
                    help="speed-loop bandwidth (default %g rad/s, or less where the motor's "
                    "inductance error would destabilise it)" % DEFAULT_SPEED_BW)
    ap.add_argument("--observer-bw-rad-s", type=float, default=None,
                    help="Luenberger observer error poles (critically damped); default "
                    "where the EMF model's Euler rotation leaves no angle error at the top "
                    "speed, about 0.32 fs")
    ap.add_argument("--fw-bw-rad-s", type=float, default=DEFAULT_FW_BW,
                    help="field-weakening voltage loop at the nominal speed")
    ap.add_argument("--estimator", choices=["pll", "luenberger", "flux"])
    ap.add_argument("--open-loop-functioning", action="store_true",
                    help="enable OPEN_LOOP_FUNCTIONING (first spin)")
    ap.add_argument("--tuning", action="store_true", help="enable TUNING (slow ramp)")
    ap.add_argument("--fw-tables", action="store_true",
                    help="write the initial field-weakening tables explicitly")
    ap.add_argument("--check", action="store_true", help="report only, write nothing")
    opt = ap.parse_args(argv)
    try:
        for name in ("speed_bw_rad_s", "observer_bw_rad_s", "fw_bw_rad_s"):
            if getattr(opt, name) is not None and not getattr(opt, name) > 0.0:
                raise InputError("--%s must be > 0" % name.replace("_", "-"))
        motor = read_motor(opt.motor)
        board = read_board(opt.board)
        lines = read_template(opt.template)
        tv = template_values(lines)
        values, info = choose(motor, board, opt)
        missing = [n for n in values if n not in tv]
        if missing:
            raise InputError("%s: no #define %s (template too old for this tool?)" % (
                opt.template, missing[0]))
        env = resolve(tv, {k: v for k, (v, dg) in values.items() if dg is not None})
        f1, f2 = fit_luenberger_f(env)      # None: none fits (the checks say why)
        values["LUENBERGER_F1"] = (int(f1 or env["LUENBERGER_F1"]), 0)
        values["LUENBERGER_F2"] = (int(f2 or env["LUENBERGER_F2"]), 0)
        for source in (board, motor):       # the motor's win
            for name, text in source["overrides"].items():
                if name not in tv:
                    raise InputError("%s: [userparms] %s: no such parameter in %s" % (
                        source["path"], name, opt.template))
                v = literal_value(text)
                if v is not None and name in values and values[name][1] == 0:
                    # an integer parameter (pole pairs, ADC bits...): 5.0 is 5
                    if not math.isfinite(v) or v != int(v):
                        raise InputError("%s: [userparms] %s = %s: must be a whole number" % (
                            source["path"], name, text.strip()))
                    values[name] = (int(v), 0)
                else:
                    values[name] = (v, 6) if v is not None else (" ".join(text.split()), None)
        env = resolve(tv, {k: v for k, (v, dg) in values.items() if dg is not None})
        d = derive(env)
        for ok, msg in checks(env, d):
            if not ok:
                raise InputError("%s (motor %s, board %s)" % (msg, opt.motor, opt.board))
        header = header_block(motor, board, opt, info, opt.motor, opt.board)
        extra = fw_tables(env, d) if opt.fw_tables else []
        out, replaced = render(lines, values, header, extra)
        out = set_flag(out, "OPEN_LOOP_FUNCTIONING", opt.open_loop_functioning)
        out = set_flag(out, "TUNING", opt.tuning)
        if not any(l.startswith(" * Motor:") for l in lines):
            raise InputError("%s: no ' * Motor:' header line to replace" % opt.template)
    except InputError as err:
        print("tune.py: error: %s" % err, file=sys.stderr)
        print("tune.py: nothing written", file=sys.stderr)
        return 1
    print("tune.py: %s on %s" % (motor["name"], board["name"]))
    report(motor, board, env, d, info, sys.stdout)
    if opt.check:
        return 0
    text = "\n".join(out)
    # a temporary file renamed over the target: never a half-written file
    target = os.path.abspath(opt.out)
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(dir=os.path.dirname(target), prefix=".tune-")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, target)
    except OSError as err:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)
        print("tune.py: error: cannot write %s: %s" % (opt.out, err.strerror or err),
              file=sys.stderr)
        print("tune.py: nothing written", file=sys.stderr)
        return 1
    print("wrote %s" % opt.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
