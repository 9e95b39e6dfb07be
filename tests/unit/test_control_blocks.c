/*
 * The controller's small blocks on their own: fault set, field weakening,
 * protection thresholds and hysteresis, start-up sequencing, bus
 * compensation, the voltage and current limit circles.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "foc/bus.h"
#include "foc/config.h"
#include "foc/current_ctrl.h"
#include "foc/current_sense.h"
#include "foc/deadtime.h"
#include "foc/faults.h"
#include "foc/field_weakening.h"
#include "foc/protection.h"
#include "foc/speed_ctrl.h"
#include "foc/startup.h"
#include "foc/supervision.h"
#include "testkit.h"

/* The only port function these blocks call. */
static uint8_t resistor_pin;
void foc_port_brake_resistor(uint8_t on)
{
    resistor_pin = on;
}

static void case_faults_first_latched(void)
{
    foc_faults_t f;
    foc_faults_clear(&f);
    TK_CHECK(f.active == 0 && f.first == 0, "cleared");
    foc_faults_raise(&f, FOC_FAULT_OVERTEMP);
    foc_faults_raise(&f, FOC_FAULT_OVERVOLTAGE);
    TK_CHECK(f.first == FOC_FAULT_OVERTEMP, "first %u", f.first);
    TK_CHECK(f.active == (FOC_FAULT_OVERTEMP | FOC_FAULT_OVERVOLTAGE), "set %u", f.active);
    TK_CHECK(strcmp(foc_fault_name(f.first), "OVERTEMP") == 0, "%s", foc_fault_name(f.first));
    TK_CHECK(strcmp(foc_fault_name(0), "NONE") == 0, "none");
    TK_CHECK(strcmp(foc_fault_name(FOC_FAULT_SPEED_FEEDBACK), "SPEED_FEEDBACK") == 0, "sf");
}

/* Table mode.  The default Id table (without FW_ID_TABLE) holds, at each
 * of its 18 speeds from FW_START_RPM to FW_END_RPM, the d current whose
 * no-load voltage w (psi + Ld id) is the field-weakening target Vfw =
 * Vdc / sqrt(3) x VOLTAGE_LIMIT_FRACTION x FW_VOLTAGE_MARGIN, within
 * [-FW_ID_MAX_A, 0].  Checked here by that balance on the current the
 * table gives (not by config.h's expression that builds the table), psi
 * from MOTOR_KE_VPK_PER_KRPM (V peak line to line per 1000 rpm).
 * Hurst075 by hand: Vfw = 24 / 1.7321 x 0.95 x 0.95 = 12.505 V; psi =
 * 7.24 / 1.7321 / (1000 x 5 x 2 pi / 60) = 7.983 mWb; at 4500 rpm (w =
 * 2356.2 rad/s, no-load EMF 18.81 V) id = (12.505 / 2356.2 - 7.983e-3) /
 * 1.92e-3 = -1.394 A, and 2356.2 x (7.983e-3 - 1.92e-3 x 1.394) = 12.505 V;
 * at 2000 rpm (EMF 8.36 V < 12.505 V) none is needed: 0.
 * Below the start the first entry, past the end the last one (the index
 * never leaves the table), linear interpolation in between. */
static q15_t fw_table_at(foc_fw_t *fw, double rpm)
{
    return foc_fw_step(fw, (q15_t)lround(rpm / SPEED_BASE_RPM * 32768.0), 0, Q15(0.9));
}

static void case_fw_table_bounds(void)
{
    foc_fw_t fw;
    foc_fw_init(&fw);
    fw.mode = FW_MODE_TABLE;
    const double pi = 3.14159265358979323846;
    const double amp_per_count = BOARD_CURRENT_FULL_SCALE_A / 32768.0;
    const double psi = MOTOR_KE_VPK_PER_KRPM / sqrt(3.0) / (1000.0 * MOTOR_POLE_PAIRS * 2.0 * pi / 60.0);
    const double v_fw = BOARD_VDC_NOMINAL_V / sqrt(3.0) * VOLTAGE_LIMIT_FRACTION * FW_VOLTAGE_MARGIN;
    const double spacing_rpm = (FW_END_RPM - FW_START_RPM) / 17.0;
#ifndef FW_ID_TABLE
    double worst_v = 0.0;
    for (int i = 0; i < 18; i++) {
        const double rpm = FW_START_RPM + i * spacing_rpm;
        const double w = rpm * MOTOR_POLE_PAIRS * 2.0 * pi / 60.0;
        const double id = fw_table_at(&fw, rpm) * amp_per_count;
        const double v = w * (psi + MOTOR_LD_H * id); /* no-load q voltage */
        if (w * psi <= v_fw) {
            TK_CHECK(id == 0.0, "%.0f rpm: EMF %.3f V within %.3f V, yet id %.4f A", rpm,
                     w * psi, v_fw, id);
        } else if (w * (psi - MOTOR_LD_H * FW_ID_MAX_A) >= v_fw) {
            TK_CHECK(fabs(id + FW_ID_MAX_A) <= amp_per_count,
                     "%.0f rpm: -FW_ID_MAX_A leaves %.3f V, yet id %.4f A", rpm,
                     w * (psi - MOTOR_LD_H * FW_ID_MAX_A), id);
        } else {
            worst_v = fmax(worst_v, fabs(v - v_fw));
            /* within two current counts' worth, w Ld x 2 counts (the
             * entry's rounding and the speed's: 1.2 mV at 4500 rpm on the
             * Hurst075, where 0.21 mV is measured) */
            const double tol_v = w * MOTOR_LD_H * 2.0 * amp_per_count;
            TK_CHECK(fabs(v - v_fw) <= tol_v, "%.0f rpm: id %.4f A leaves %.4f V, want %.4f V +- %.4f V",
                     rpm, id, v, v_fw, tol_v);
        }
    }
    printf("Id table: worst no-load voltage off the target %.2f mV (of %.3f V)\n", worst_v * 1e3,
           v_fw);
#endif
    const q15_t first = fw_table_at(&fw, FW_START_RPM);
    const q15_t last = fw_table_at(&fw, FW_END_RPM);
    TK_CHECK(foc_fw_step(&fw, 0, 0, Q15(0.9)) == first, "at 0: %d, first %d", fw.id_ref, first);
    TK_CHECK(foc_fw_step(&fw, Q15_MAX, 0, Q15(0.9)) == last, "at max: %d", fw.id_ref);
    TK_CHECK(foc_fw_step(&fw, Q15_MIN, 0, Q15(0.9)) == last, "at -max: %d", fw.id_ref);
    /* halfway between entries 15 and 16 (both weakening on the Hurst075:
     * -1.200 and -1.300 A): their mean */
    const q15_t e15 = fw_table_at(&fw, FW_START_RPM + 15.0 * spacing_rpm);
    const q15_t e16 = fw_table_at(&fw, FW_START_RPM + 16.0 * spacing_rpm);
    const q15_t mid = fw_table_at(&fw, FW_START_RPM + 15.5 * spacing_rpm);
    TK_CHECK(fabs(mid - 0.5 * (e15 + e16)) <= 3.0, "interpolated %d between %d and %d", mid, e15,
             e16);
    TK_CHECK(last < 0 && last * amp_per_count >= -FW_ID_MAX_A - amp_per_count, "last entry %d", last);
}

/* Voltage mode: Id stays 0 below the voltage target, goes negative above
 * it, never below -FW_ID_MAX_A. */
static void case_fw_voltage_mode(void)
{
    foc_fw_t fw;
    foc_fw_init(&fw);
    fw.mode = FW_MODE_VOLTAGE;
    for (int k = 0; k < 1000; k++) {
        (void)foc_fw_step(&fw, 0, Q15(0.5), Q15(0.9));
    }
    TK_CHECK(fw.id_ref == 0, "below target: %d", fw.id_ref);
    for (int k = 0; k < 100000; k++) {
        (void)foc_fw_step(&fw, 0, Q15(0.95), Q15(0.9));
    }
    TK_CHECK(fw.id_ref == -FOC_FW_ID_MAX, "saturated: %d", fw.id_ref);
    for (int k = 0; k < 100000; k++) {
        (void)foc_fw_step(&fw, 0, Q15(0.5), Q15(0.9));
    }
    TK_CHECK(fw.id_ref == 0, "recovers: %d", fw.id_ref);
}

/* The readings the thresholds are compared with, worked out here from
 * volts and degrees: the bus as Q15 of BOARD_VDC_FULL_SCALE_V, the
 * temperature sensor's BOARD_TEMP_V_AT_0C + BOARD_TEMP_V_PER_DEGC x degC as
 * Q15 of BOARD_ADC_VREF_V. */
static q15_t vdc_reading(double volts)
{
    return (q15_t)lround(volts / BOARD_VDC_FULL_SCALE_V * 32768.0);
}

static q15_t temp_reading(double degc)
{
    return (q15_t)lround((BOARD_TEMP_V_AT_0C + BOARD_TEMP_V_PER_DEGC * degc) / BOARD_ADC_VREF_V *
                         32768.0);
}

/* Each threshold 1 % either side (a threshold scaled wrong by more than
 * 1 % fails): trips at 1.01 x, not at 0.99 x (under-voltage the other way
 * round), and once tripped its cause is gone only 1 % beyond the
 * hysteresis.  On the Hurst075 board by hand: over-voltage 32 V = 32 /
 * 52.8 x 32768 = 19859 counts, 1 % either side 19661 and 20058;
 * under-voltage 16 V = 9930, 9830 and 10029; over-temperature 100 degC =
 * (0.5 + 0.01 x 100) / 3.3 x 32768 = 14895, 99 and 101 degC 14795 and
 * 14994; clear at 31 V, 17 V and 90 degC. */
static void case_protection_thresholds(void)
{
    foc_protection_t p;
    foc_protection_init(&p);
    p.resistor_enabled = 0;
    const q15_t temp_ok = temp_reading(25.0);
    const q15_t vdc_ok = vdc_reading(BOARD_VDC_NOMINAL_V);
    if (BOARD_VDC_FULL_SCALE_V == 52.8 && OVERVOLTAGE_V == 32.0 && UNDERVOLTAGE_V == 16.0 &&
        BOARD_ADC_VREF_V == 3.3 && OVERTEMP_DEGC == 100.0) {
        TK_CHECK(vdc_reading(32.0) == 19859 && vdc_reading(0.99 * 32.0) == 19661 &&
                     vdc_reading(1.01 * 32.0) == 20058 && vdc_reading(16.0) == 9930,
                 "bus readings %d %d %d %d", vdc_reading(32.0), vdc_reading(0.99 * 32.0),
                 vdc_reading(1.01 * 32.0), vdc_reading(16.0));
        TK_CHECK(temp_reading(100.0) == 14895 && temp_reading(99.0) == 14795 &&
                     temp_reading(101.0) == 14994,
                 "temperature readings %d %d %d", temp_reading(100.0), temp_reading(99.0),
                 temp_reading(101.0));
    }
    TK_CHECK(foc_protection_check(&p, vdc_ok, temp_ok) == 0, "nominal");
    TK_CHECK(foc_protection_check(&p, vdc_reading(1.01 * OVERVOLTAGE_V), temp_ok) ==
                 FOC_FAULT_OVERVOLTAGE, "ov at 1.01 x");
    TK_CHECK(foc_protection_check(&p, vdc_reading(0.99 * OVERVOLTAGE_V), temp_ok) == 0,
             "ov at 0.99 x");
    TK_CHECK(foc_protection_check(&p, vdc_reading(0.99 * UNDERVOLTAGE_V), temp_ok) ==
                 FOC_FAULT_UNDERVOLTAGE, "uv at 0.99 x");
    TK_CHECK(foc_protection_check(&p, vdc_reading(1.01 * UNDERVOLTAGE_V), temp_ok) == 0,
             "uv at 1.01 x");
    TK_CHECK(foc_protection_check(&p, vdc_ok, temp_reading(1.01 * OVERTEMP_DEGC)) ==
                 FOC_FAULT_OVERTEMP, "ot at 1.01 x");
    TK_CHECK(foc_protection_check(&p, vdc_ok, temp_reading(0.99 * OVERTEMP_DEGC)) == 0,
             "ot at 0.99 x");
    /* hysteresis: the cause is gone 1 % beyond the clear level, not 1 %
     * before it */
    const uint16_t ov = FOC_FAULT_OVERVOLTAGE;
    const double ov_clear = OVERVOLTAGE_V - BUS_HYSTERESIS_V;
    TK_CHECK(!foc_protection_causes_gone(&p, ov, vdc_reading(1.01 * ov_clear), temp_ok),
             "ov gone at 1.01 x the clear level");
    TK_CHECK(foc_protection_causes_gone(&p, ov, vdc_reading(0.99 * ov_clear), temp_ok),
             "ov not gone at 0.99 x the clear level");
    const uint16_t uv = FOC_FAULT_UNDERVOLTAGE;
    const double uv_clear = UNDERVOLTAGE_V + BUS_HYSTERESIS_V;
    TK_CHECK(!foc_protection_causes_gone(&p, uv, vdc_reading(0.99 * uv_clear), temp_ok),
             "uv gone at 0.99 x the clear level");
    TK_CHECK(foc_protection_causes_gone(&p, uv, vdc_reading(1.01 * uv_clear), temp_ok),
             "uv not gone at 1.01 x the clear level");
    const uint16_t ot = FOC_FAULT_OVERTEMP;
    const double ot_clear = OVERTEMP_DEGC - TEMP_HYSTERESIS_DEGC;
    TK_CHECK(!foc_protection_causes_gone(&p, ot, vdc_ok, temp_reading(1.01 * ot_clear)),
             "ot gone at 1.01 x the clear level");
    TK_CHECK(foc_protection_causes_gone(&p, ot, vdc_ok, temp_reading(0.99 * ot_clear)),
             "ot not gone at 0.99 x the clear level");
    TK_CHECK(foc_protection_causes_gone(&p, FOC_FAULT_SPEED_FEEDBACK, 0, 0), "no cause");
}

/* With the resistor: on from BRAKE_RESISTOR_ON_V, held between, off from
 * BRAKE_RESISTOR_OFF_V (1 % either side of each); the over-voltage trip
 * moves to 1.2 x OVERVOLTAGE_V (Hurst075 board: 29 V, 27 V, 38.4 V). */
static void case_protection_brake_resistor(void)
{
    foc_protection_t p;
    foc_protection_init(&p);
    p.resistor_enabled = 1;
    const q15_t t = temp_reading(25.0);
    (void)foc_protection_check(&p, vdc_reading(0.5 * (BRAKE_RESISTOR_ON_V + BRAKE_RESISTOR_OFF_V)), t);
    TK_CHECK(resistor_pin == 0, "off below ON");
    (void)foc_protection_check(&p, vdc_reading(0.99 * BRAKE_RESISTOR_ON_V), t);
    TK_CHECK(resistor_pin == 0, "on at 0.99 x ON");
    (void)foc_protection_check(&p, vdc_reading(1.01 * BRAKE_RESISTOR_ON_V), t);
    TK_CHECK(resistor_pin == 1, "off at 1.01 x ON");
    (void)foc_protection_check(&p, vdc_reading(1.01 * BRAKE_RESISTOR_OFF_V), t);
    TK_CHECK(resistor_pin == 1, "not held at 1.01 x OFF");
    (void)foc_protection_check(&p, vdc_reading(0.99 * BRAKE_RESISTOR_OFF_V), t);
    TK_CHECK(resistor_pin == 0, "on at 0.99 x OFF");
    TK_CHECK(foc_protection_check(&p, vdc_reading(1.01 * OVERVOLTAGE_V), t) == 0,
             "trip at 1.01 x OVERVOLTAGE_V with the resistor");
    TK_CHECK(foc_protection_check(&p, vdc_reading(0.99 * 1.2 * OVERVOLTAGE_V), t) == 0,
             "trip at 0.99 x the hard threshold");
    TK_CHECK(foc_protection_check(&p, vdc_reading(1.01 * 1.2 * OVERVOLTAGE_V), t) ==
                 FOC_FAULT_OVERVOLTAGE, "no trip at 1.01 x the hard threshold");
    (void)foc_protection_check(&p, vdc_reading(BOARD_VDC_NOMINAL_V), t);
}

/* Alignment: first half at -90 deg (in the direction of rotation) with a
 * rising current, second half at 0; then the ramp reaches the final speed
 * in STARTUP_RAMP_TIME_S, negative for the reverse direction.
 *
 * The expected values are worked out here in physical units, in double,
 * from userparms.h alone (not from config.h's tick and Q15 macros, which
 * startup.c uses): a slow tick lasts CONTROL_SLOW_DIVIDER / PWM_FREQUENCY_HZ,
 * a current count BOARD_CURRENT_FULL_SCALE_A / 32768 A, a speed count
 * SPEED_BASE_RPM / 32768 rpm, the angle 2^32 per electrical turn.  On the
 * Hurst075 (10 / 20 kHz = 0.5 ms per tick): the 0.12 s alignment is 240
 * ticks, its current 1.5 A reached at 120 ticks and 0.75 A at 60; the
 * 0.25 s ramp is 500 ticks to 500 rpm, 250 rpm at 250 ticks; at 500 rpm
 * (2731 counts of 6000 / 32768 rpm = 500.06 rpm) 5 pole pairs turn
 * 41.672 Hz, 2.0836e-3 of a turn per 50 us period: 8.949e6 of 2^32. */
static void case_startup_sequence(void)
{
    const double tick_s = (double)CONTROL_SLOW_DIVIDER / PWM_FREQUENCY_HZ;
    const double amp_per_count = BOARD_CURRENT_FULL_SCALE_A / 32768.0;
    const double rpm_per_count = SPEED_BASE_RPM / 32768.0;
    for (int dir = -1; dir <= 1; dir += 2) {
        foc_startup_t s;
        foc_startup_begin(&s, (int8_t)dir);
        const uint16_t first = foc_startup_angle(&s);
        TK_CHECK(first == (dir > 0 ? 0xC000u : 0x4000u), "dir %d first angle %u", dir, first);
        /* the alignment: ticks until it reports done, the current at a
         * quarter and at half of STARTUP_ALIGN_TIME_S */
        const unsigned quarter = (unsigned)lround(0.25 * STARTUP_ALIGN_TIME_S / tick_s);
        const unsigned half = (unsigned)lround(0.5 * STARTUP_ALIGN_TIME_S / tick_s);
        unsigned ticks = 0;
        q15_t prev = 0;
        /* the second half: half the current on its first tick, then four
         * times the first half's rise (3/4 of it a sixteenth of a half
         * later, to the tick), the full current from an eighth on */
        const unsigned sixteenth = (unsigned)lround(0.03125 * STARTUP_ALIGN_TIME_S / tick_s);
        const unsigned three_quarters = (unsigned)lround(0.75 * STARTUP_ALIGN_TIME_S / tick_s);
        double i_quarter = -1.0, i_half = -1.0, i_second = -1.0, i_sixteenth = -1.0, i_late = -1.0;
        uint8_t done = 0;
        while (!done && ticks < 100000u) {
            done = foc_startup_align_tick(&s);
            ticks++;
            TK_CHECK(s.current >= prev || ticks > half, "current falls at tick %u", ticks);
            prev = s.current;
            i_quarter = (ticks == quarter) ? s.current * amp_per_count : i_quarter;
            i_half = (ticks == half) ? s.current * amp_per_count : i_half;
            i_second = (ticks == half + 1u) ? s.current * amp_per_count : i_second;
            i_sixteenth = (ticks == half + 1u + sixteenth) ? s.current * amp_per_count : i_sixteenth;
            i_late = (ticks == three_quarters) ? s.current * amp_per_count : i_late;
        }
        TK_CHECK(fabs(ticks * tick_s - STARTUP_ALIGN_TIME_S) <= tick_s,
                 "alignment %u ticks = %.4f s, want %.4f s", ticks, ticks * tick_s,
                 STARTUP_ALIGN_TIME_S);
        /* a linear rise; the per-tick step rounds down (at most 1 % short) */
        TK_CHECK(fabs(i_quarter - 0.5 * STARTUP_ALIGN_CURRENT_A) <= 0.01 * STARTUP_ALIGN_CURRENT_A,
                 "align current at a quarter %.4f A, want %.4f A", i_quarter,
                 0.5 * STARTUP_ALIGN_CURRENT_A);
        TK_CHECK(fabs(i_half - STARTUP_ALIGN_CURRENT_A) <= 0.01 * STARTUP_ALIGN_CURRENT_A,
                 "align current at half %.4f A, want %.4f A", i_half, STARTUP_ALIGN_CURRENT_A);
        TK_CHECK(fabs(i_second - 0.5 * STARTUP_ALIGN_CURRENT_A) <= amp_per_count,
                 "align current at the second half's start %.4f A, want %.4f A", i_second,
                 0.5 * STARTUP_ALIGN_CURRENT_A);
        const double want_sixteenth = STARTUP_ALIGN_CURRENT_A *
                                      (0.5 + 4.0 * sixteenth * tick_s / (0.5 * STARTUP_ALIGN_TIME_S));
        TK_CHECK(fabs(i_sixteenth - want_sixteenth) <= 0.01 * STARTUP_ALIGN_CURRENT_A,
                 "align current a sixteenth into the second half %.4f A, want %.4f A", i_sixteenth,
                 want_sixteenth);
        TK_CHECK(fabs(i_late - STARTUP_ALIGN_CURRENT_A) <= amp_per_count,
                 "align current at three quarters %.4f A, want %.4f A", i_late,
                 STARTUP_ALIGN_CURRENT_A);
        TK_CHECK(foc_startup_angle(&s) == 0u, "aligned at 0");
        TK_CHECK(fabs(s.current * amp_per_count - STARTUP_CURRENT_FIRST_A) <= amp_per_count,
                 "open loop's first current %.4f A, want %.4f A", s.current * amp_per_count,
                 STARTUP_CURRENT_FIRST_A);
        /* the ramp: the speed after k ticks is the final speed x k tick_s /
         * STARTUP_RAMP_TIME_S (one speed count and half a tick's worth of
         * rounding), then the final speed */
        const unsigned ramp_half = (unsigned)lround(0.5 * STARTUP_RAMP_TIME_S / tick_s);
        const unsigned ramp_end = (unsigned)lround(STARTUP_RAMP_TIME_S / tick_s);
        const q15_t final_q15 = (q15_t)lround(STARTUP_FINAL_SPEED_RPM / rpm_per_count);
        const double tol_rpm = rpm_per_count + 0.5 * STARTUP_FINAL_SPEED_RPM * tick_s /
                                                   STARTUP_RAMP_TIME_S;
        for (unsigned k = 1; k <= ramp_end + 10u; k++) {
            foc_startup_ramp_tick(&s, final_q15);
            if (k == ramp_half || k == ramp_end + 10u) {
                const double want =
                    dir * STARTUP_FINAL_SPEED_RPM * fmin(1.0, k * tick_s / STARTUP_RAMP_TIME_S);
                TK_CHECK(fabs(s.speed * rpm_per_count - want) <= tol_rpm,
                         "dir %d, %.4f s into the ramp: %.2f rpm, want %.2f rpm", dir,
                         k * tick_s, s.speed * rpm_per_count, want);
            }
        }
        TK_CHECK(fabs(s.current * amp_per_count - STARTUP_CURRENT_FINAL_A) <= amp_per_count,
                 "final current %.4f A, want %.4f A", s.current * amp_per_count,
                 STARTUP_CURRENT_FINAL_A);
        /* the forced angle turns at the forced speed: electrical turns per
         * PWM period, x 2^32 (within config.h's stated 0.02 %) */
        const double want_step = s.speed * rpm_per_count / 60.0 * MOTOR_POLE_PAIRS /
                                 PWM_FREQUENCY_HZ * 4294967296.0;
        const uint32_t before = s.theta32;
        foc_startup_fast(&s);
        const double step = (double)(int32_t)(s.theta32 - before);
        TK_CHECK(fabs(step - want_step) <= 2e-4 * fabs(want_step),
                 "increment %.0f per period, want %.0f", step, want_step);
    }
}

/* Nominal bus: no compensation; half bus: x2 (saturated); v_max follows. */
static void case_bus_compensation(void)
{
    foc_bus_t bus;
    foc_bus_init(&bus, FOC_VDC_NOMINAL);
    TK_CHECK(abs(bus.comp_q14 - 16384) <= 2, "comp at nominal %d", bus.comp_q14);
    TK_CHECK(abs(bus.v_max - FOC_VOLTAGE_LIMIT) <= 2, "v_max %d", bus.v_max);
    foc_bus_init(&bus, (q15_t)(FOC_VDC_NOMINAL * 3 / 4));
    TK_CHECK(abs(bus.comp_q14 - 21845) <= 4, "comp at 3/4: %d", bus.comp_q14);
    TK_CHECK(abs(bus.v_max - FOC_VOLTAGE_LIMIT * 3 / 4) <= 4, "v_max at 3/4: %d", bus.v_max);
    const foc_ab_t v = { Q15(0.3), Q15(-0.6) };
    const foc_ab_t out = foc_bus_compensate(&bus, v);
    TK_CHECK(abs(out.alpha - Q15(0.4)) <= 2 && abs(out.beta - Q15(-0.8)) <= 2, "%d %d",
             out.alpha, out.beta);
    foc_bus_init(&bus, 100);
    TK_CHECK(bus.comp_q14 == 32767, "collapsed bus: comp %d", bus.comp_q14);
}

/* |Vdq| never exceeds Vmax, and Vd gets what it asks for first. */
static void case_voltage_circle(void)
{
    foc_current_ctrl_t cc;
    foc_cc_init(&cc);
    srand(7);
    int32_t worst = 0;
    for (int k = 0; k < 20000; k++) {
        const foc_dq_t ref = { (q15_t)(rand() % 65536 - 32768), (q15_t)(rand() % 65536 - 32768) };
        const foc_dq_t meas = { 0, 0 };
        const q15_t vmax = (q15_t)(rand() % 32768);
        foc_dq_t v;
        v.d = foc_cc_d_axis(&cc, ref.d, meas.d, vmax, 0);
        v.q = foc_cc_q_axis(&cc, ref.q, meas.q, v.d, vmax, 0);
        const int32_t mag2 = (int32_t)v.d * v.d + (int32_t)v.q * v.q;
        const int32_t over = (int32_t)sqrt((double)mag2) - vmax;
        worst = over > worst ? over : worst;
        TK_CHECK(abs(v.d) <= vmax, "vd %d > vmax %d", v.d, vmax);
    }
    TK_CHECK(worst <= 1, "|Vdq| exceeds Vmax by %ld LSB", (long)worst);
}

/* The forced q axis on a q winding (Rs, Lq of userparms.h, one period per
 * step) whose back-EMF is below the forced voltage by what drives the band
 * through Rs plus 2 V (a rotor slipping behind the forced frame): the q
 * current beyond its band is pulled back to the band's edge (the
 * proportional pull alone leaves 2 V / (Kp + Rs) above it), and once the
 * EMF matches again the pull leaks away, so the forced voltage acts
 * alone. */
static void case_forced_q_holds_band(void)
{
    foc_current_ctrl_t cc;
    foc_cc_init(&cc);
    const double v_base = FOC_V_BASE_V;
    const double i_base = FOC_I_BASE_A;
    const double band_a = 0.5 * CURRENT_LIMIT_A;
    const q15_t iq_max = FOC_I_Q15(band_a);
    const double vq_forced_v = 0.3 * v_base;
    const q15_t vq_forced = Q15(0.3);
    const q15_t v_max = Q15(0.9);
    double iq = 0.0; /* A */
    double emf = vq_forced_v - MOTOR_RS_OHM * band_a - 2.0; /* V */
    q15_t vq = 0;
    for (int k = 0; k < 40000; k++) {
        if (k == 20000) {
            TK_CHECK(fabs(iq - band_a) <= 0.01 * CURRENT_LIMIT_A,
                     "slipping: iq %.3f A for a band of %.3f A (P only: +%.3f A)", iq, band_a,
                     2.0 / (CURRENT_KP_V_PER_A + MOTOR_RS_OHM));
            emf = vq_forced_v - MOTOR_RS_OHM * 0.5 * band_a; /* back in step */
        }
        const q15_t iq_q15 = (q15_t)lround(iq / i_base * 32768.0);
        vq = foc_cc_q_forced(&cc, vq_forced, iq_q15, iq_max, 0, v_max, 0);
        iq += FOC_TS_S / MOTOR_LQ_H * (vq * v_base / 32768.0 - emf - MOTOR_RS_OHM * iq);
    }
    TK_CHECK(abs(vq - vq_forced) <= 1, "in step: vq %d, the forced %d", vq, vq_forced);
    TK_CHECK(fabs(iq - 0.5 * band_a) <= 0.01 * CURRENT_LIMIT_A, "in step: iq %.3f A", iq);
}

/* The q axis closed on a q winding (Rs, Lq, psi of userparms.h; the
 * voltage acts one period after it is computed) with the back-EMF of
 * `true_speed` and the feedforward on `est_speed` (Q15 of
 * SPEED_BASE_RPM) over `n` periods; the largest |iq - iq_ref| in A. */
typedef q15_t (*speed_at_fn)(int k);
static double q_axis_worst_error(speed_at_fn true_speed, speed_at_fn est_speed, double iq_ref_a,
                                 int n, int feedforward)
{
    foc_current_ctrl_t cc;
    foc_cc_init(&cc);
    const double v_base = FOC_V_BASE_V;
    const double emf_per_q15 = FOC_EMF_PER_SPEED_PU * v_base / 32768.0;
    const q15_t iq_ref = FOC_I_Q15(iq_ref_a);
    const foc_dq_t v0 = { 0, (q15_t)lround((MOTOR_RS_OHM * iq_ref_a +
                                            emf_per_q15 * true_speed(0)) / v_base * 32768.0) };
    foc_cc_preset(&cc, v0, est_speed(0));
    double iq = iq_ref_a;
    q15_t vq_applied = v0.q;
    double worst = 0.0;
    for (int k = 0; k < n; k++) {
        if (feedforward) {
            foc_cc_emf_feedforward(&cc, est_speed(k), FOC_EMF_PER_SPEED_MANT, FOC_EMF_PER_SPEED_SHIFT,
                                   FOC_RS_ILIM_V);
        }
        const q15_t vq = foc_cc_q_axis(&cc, iq_ref, FOC_I_Q15(iq), 0, Q15(0.95), 0);
        iq += FOC_TS_S / MOTOR_LQ_H *
              (vq_applied * v_base / 32768.0 - emf_per_q15 * true_speed(k) - MOTOR_RS_OHM * iq);
        vq_applied = vq;
        worst = fmax(worst, fabs(iq - iq_ref_a));
    }
    return worst;
}

/* A jam: from 30 % of the maximum speed to rest in 5 ms (the campaign's
 * dry-friction brake), the estimate following 1 period late. */
static q15_t jam_speed(int k)
{
    const double top = FOC_SPEED_Q15(0.3 * MOTOR_MAX_SPEED_RPM);
    const int stop_periods = (int)(0.005 / FOC_TS_S);
    return (q15_t)((k < 100) ? top : (k < 100 + stop_periods) ? top * (1.0 - (k - 100.0) / stop_periods) : 0);
}
static q15_t jam_speed_late(int k)
{
    return jam_speed(k > 0 ? k - 1 : 0);
}
static q15_t at_rest(int k)
{
    (void)k;
    return 0;
}
/* An estimate that leaves a rotor at rest for 10 ms at 30 % of the
 * maximum speed and falls back (the Luenberger observer losing a slow
 * rotor, torture finding 7). */
static q15_t glitch_speed(int k)
{
    const int len = (int)(0.010 / FOC_TS_S);
    return (q15_t)((k >= 100 && k < 100 + len) ? FOC_SPEED_Q15(0.3 * MOTOR_MAX_SPEED_RPM) : 0);
}

/* The back-EMF feedforward: a jammed rotor's current stays within 1 % of
 * the limit of its reference (without it the EMF ramp leaves an error
 * that decays at Rs / Lq: 2.2 % on the Hurst075), and an estimate that
 * jumps up and falls back on a rotor at rest moves the current by less
 * than the limit (here the proportional gain holds it either way; the
 * torture campaign's finding 7 shows the case where it does not). */
static void case_emf_feedforward(void)
{
    const double iq_ref = 0.9 * CURRENT_LIMIT_A;
    const int n = (int)(0.05 / FOC_TS_S);
    const double jam = q_axis_worst_error(jam_speed, jam_speed_late, iq_ref, n, 1);
    const double jam_without = q_axis_worst_error(jam_speed, jam_speed_late, iq_ref, n, 0);
    TK_CHECK(jam <= 0.01 * CURRENT_LIMIT_A, "jam: %.3f A off the reference (%.3f A without)", jam,
             jam_without);
    const double glitch = q_axis_worst_error(at_rest, glitch_speed, 0.0, n, 1);
    TK_CHECK(glitch <= CURRENT_LIMIT_A, "estimate glitch: %.3f A (limit %.3f A)", glitch,
             CURRENT_LIMIT_A);
}

/* The current PI's two degrees of freedom (config.h): on the d axis of
 * the userparms.h winding (the voltage acting one period late), a
 * reference step of half the limit rises without overshoot, and a back-EMF
 * falling at a steady rate (a jam, no feedforward) leaves at most 3/4 of
 * the plain PI's error r / CURRENT_KI_V_PER_AS.  The reference is slewed
 * as the fast step slews it. */
static void case_current_two_dof(void)
{
    const double v_base = FOC_V_BASE_V;
    const double i_base = FOC_I_BASE_A;
    const q15_t v_max = Q15(0.95);
    /* the reference step */
    foc_current_ctrl_t cc;
    foc_cc_init(&cc);
    const double step_a = 0.5 * CURRENT_LIMIT_A;
    const q15_t ref = FOC_I_Q15(step_a);
    double id = 0.0;
    q15_t vd_applied = 0;
    double peak = 0.0;
    q15_t slewed = 0; /* the reference as the fast step slews it */
    for (int k = 0; k < (int)(0.01 / FOC_TS_S); k++) {
        const q15_t step = (q15_t)FOC_SAT_BITS((int32_t)ref - slewed, FOC_IREF_STEP_BITS);
        slewed = (q15_t)(slewed + step);
        const q15_t vd = foc_cc_d_axis(&cc, slewed, (q15_t)lround(id / i_base * 32768.0), v_max, step);
        id += FOC_TS_S / MOTOR_LQ_H * (vd_applied * v_base / 32768.0 - MOTOR_RS_OHM * id);
        vd_applied = vd;
        peak = fmax(peak, id);
    }
    TK_CHECK(peak <= 1.02 * step_a, "step of %.3f A: peak %.3f A", step_a, peak);
    TK_CHECK(fabs(id - step_a) <= 0.005 * step_a, "step of %.3f A: settles at %.3f A", step_a, id);

    /* the falling back-EMF: from half the voltage base to zero in 5 ms */
    foc_cc_init(&cc);
    const double rate = 0.5 * v_base / 0.005; /* V/s */
    double emf = 0.5 * v_base;
    const foc_dq_t v0 = { (q15_t)lround((emf + MOTOR_RS_OHM * step_a) / v_base * 32768.0), 0 };
    foc_cc_preset(&cc, v0, 0);
    id = step_a;
    vd_applied = v0.d;
    for (int k = 0; k < (int)(0.005 / FOC_TS_S); k++) {
        const q15_t vd = foc_cc_d_axis(&cc, ref, (q15_t)lround(id / i_base * 32768.0), v_max, 0);
        id += FOC_TS_S / MOTOR_LQ_H * (vd_applied * v_base / 32768.0 - emf - MOTOR_RS_OHM * id);
        vd_applied = vd;
        emf -= rate * FOC_TS_S;
    }
    const double plain = rate / CURRENT_KI_V_PER_AS;
    TK_CHECK(fabs(id - step_a) <= 0.75 * plain, "EMF falling at %.0f V/s: %.4f A off (plain PI %.4f A)",
             rate, fabs(id - step_a), plain);
}

/* |Iq| <= sqrt(Ilim^2 - Id^2), 0 when Id takes it all. */
static void case_current_circle(void)
{
    for (int32_t id = -32768; id <= 32767; id += 97) {
        const q15_t iq_max = foc_sc_iq_limit((q15_t)id);
        const double lim = FOC_CURRENT_LIMIT;
        const double expect = fabs((double)id) >= lim ? 0.0 : sqrt(lim * lim - (double)id * id);
        TK_CHECK(fabs(iq_max - expect) <= 1.0, "id %ld: %d vs %.1f", (long)id, iq_max, expect);
    }
}

/* The speed loop hunting: its output held beyond half the limit on its
 * last side (the measured speed off the reference), then from side to
 * side `swings` times, each side held `hold` slow ticks; returns the gain
 * shift left. */
static uint8_t hunt_run(foc_speed_ctrl_t *sc, int swings, int hold)
{
    const q15_t ref = FOC_SPEED_Q15(0.5 * MOTOR_MAX_SPEED_RPM);
    const q15_t dw = FOC_SPEED_Q15(0.5 * MOTOR_MAX_SPEED_RPM);
    int side = (sc->hunt_side < 0) ? -1 : 1;
    for (int k = 0; k <= swings; k++) {
        for (int t = 0; t < hold; t++) {
            (void)foc_sc_step(sc, (q15_t)(ref - side * dw), 0);
        }
        side = -side;
    }
    return sc->gain_shift;
}

/* Four swings, each within FOC_SPEED_HUNT_SWING_TICKS of the last, halve
 * the loop's gains; three do not, nor any number spaced wider; a quarter
 * at most; the next run starts with the design's gains. */
static void case_speed_loop_hunting(void)
{
    const q15_t ref = FOC_SPEED_Q15(0.5 * MOTOR_MAX_SPEED_RPM);
    const int fast = FOC_SPEED_HUNT_SWING_TICKS / 4;
    foc_speed_ctrl_t sc;
    foc_sc_init(&sc);
    sc.target = ref;
    foc_sc_preset(&sc, ref, 0);
    TK_CHECK(hunt_run(&sc, 3, fast) == 0u, "three swings: %u", sc.gain_shift);
    (void)hunt_run(&sc, 0, 2 * FOC_SPEED_HUNT_TRIP_TICKS); /* quiet: the count leaks away */
    TK_CHECK(hunt_run(&sc, 40, FOC_SPEED_HUNT_SWING_TICKS + 1) == 0u, "40 slow swings: %u",
             sc.gain_shift);
    TK_CHECK(hunt_run(&sc, 4, fast) == 1u, "four fast swings: %u", sc.gain_shift);
    TK_CHECK(hunt_run(&sc, 100, fast) == FOC_SPEED_HUNT_SHIFT_MAX, "many: %u", sc.gain_shift);
    /* the proportional step halved with each shift (the integrator at 0) */
    const q15_t e = FOC_SPEED_Q15(0.01 * MOTOR_MAX_SPEED_RPM);
    q15_t y[3];
    for (uint8_t shift = 0; shift <= 2u; shift++) {
        foc_sc_preset(&sc, ref, 0);
        sc.gain_shift = shift;
        y[shift] = foc_sc_step(&sc, (q15_t)(ref - e), 0);
    }
    TK_CHECK(y[0] > 8 && abs(2 * y[1] - y[0]) <= 2 && abs(4 * y[2] - y[0]) <= 4,
             "Kp e: %d, %d, %d", y[0], y[1], y[2]);
    foc_sc_preset(&sc, ref, 0);
    TK_CHECK(sc.gain_shift == 0u && sc.hunt_count == 0u && sc.hunt_side == 0, "preset: design gains");
}

/* Offsets: the mean of 1024 bridge-off samples; then any two valid phases
 * give the same alpha/beta as all three; fewer than two keep the previous
 * value. */
static void case_current_sense(void)
{
    foc_current_sense_t cs;
    foc_cs_calib_start(&cs, FOC_CALIB_PERIODS_LOG2);
    foc_samples_t s = { 0 };
    for (int k = 0; k < 1024; k++) {
        s.i_a = (q15_t)(100 + (k & 1));  /* mean 100.5 -> 101 (rounded) */
        s.i_b = -250;
        s.i_c = 7;
        foc_cs_calib_add(&cs, &s);
    }
    TK_CHECK(cs.calibrated == 1, "calibrated");
    TK_CHECK(cs.offset.a == 101 && cs.offset.b == -250 && cs.offset.c == 7, "offsets %d %d %d",
             cs.offset.a, cs.offset.b, cs.offset.c);
    /* a balanced set 0.5 / -0.2 / -0.3 plus the offsets */
    s.i_a = (q15_t)(Q15(0.5) + 101);
    s.i_b = (q15_t)(Q15(-0.2) - 250);
    s.i_c = (q15_t)(Q15(-0.3) + 7);
    const foc_ab_t prev = { 1234, -4321 };
    foc_gain_balance_t gb;
    foc_gb_init(&gb); /* nothing learned: the sensors taken as matched */
    const uint8_t masks[] = { FOC_PHASE_A | FOC_PHASE_B, FOC_PHASE_B | FOC_PHASE_C,
                              FOC_PHASE_A | FOC_PHASE_C, FOC_PHASE_A | FOC_PHASE_B | FOC_PHASE_C };
    for (size_t m = 0; m < 4; m++) {
        s.phases = masks[m];
        const foc_ab_t ab = foc_cs_alphabeta(&cs, &gb, &s, prev);
        TK_CHECK(abs(ab.alpha - Q15(0.5)) <= 2 && abs(ab.beta - Q15((0.5 - 0.4) / 1.7320508)) <= 3,
                 "mask %u: %d %d", masks[m], ab.alpha, ab.beta);
    }
    s.phases = FOC_PHASE_B;
    const foc_ab_t held = foc_cs_alphabeta(&cs, &gb, &s, prev);
    TK_CHECK(held.alpha == prev.alpha && held.beta == prev.beta, "one phase: %d %d", held.alpha,
             held.beta);
}

/* Dead time: outside the soft band each phase loses V_dt against its
 * current (the vector sum of the three); inside, in proportion; V_dt the
 * one given (the build's, or a measured one 1.5 x as long). */
static void case_deadtime_error(void)
{
    const q15_t big = FOC_I_Q15(1.0);
    const foc_abc_t i = { big, (q15_t)-big, (q15_t)-big };
    const foc_ab_t e = foc_deadtime_error_ab(i, FOC_DT_VOLTAGE);
    /* phases -V, +V, +V: alpha = (2(-V) - V - V)/3 = -4V/3, beta = 0 */
    const double v = FOC_DT_VOLTAGE;
    TK_CHECK(fabs(e.alpha + 4.0 * v / 3.0) <= 2.0 && abs(e.beta) <= 2, "big: %d %d (V %.0f)",
             e.alpha, e.beta, v);
    const foc_ab_t e_long = foc_deadtime_error_ab(i, (q15_t)(3 * FOC_DT_VOLTAGE / 2));
    TK_CHECK(fabs(e_long.alpha + 2.0 * v) <= 2.0 && abs(e_long.beta) <= 2, "1.5 x: %d %d",
             e_long.alpha, e_long.beta);
    const q15_t small = FOC_I_Q15(0.5 * FOC_DT_RIPPLE_BAND_A);
    const foc_abc_t i2 = { small, (q15_t)-small, 0 };
    const foc_ab_t e2 = foc_deadtime_error_ab(i2, FOC_DT_VOLTAGE);
    /* phases -V/2, +V/2, 0: alpha = -V/2, beta = (b - c)/sqrt(3) = V/(2 sqrt(3)) */
    TK_CHECK(fabs(e2.alpha + 0.5 * v) <= 2.0 && fabs(e2.beta - v / (2.0 * 1.7320508)) <= 2.0,
             "in band: %d %d", e2.alpha, e2.beta);
    /* the correction: opposite, with its own (wider) band */
    const q15_t half_comp = FOC_I_Q15(0.5 * DEADTIME_COMP_CURRENT_A);
    const foc_abc_t i3 = { half_comp, (q15_t)-half_comp, 0 };
    const foc_ab_t c3 = foc_deadtime_correction_ab(i3, FOC_DT_VOLTAGE);
    TK_CHECK(fabs(c3.alpha - 0.5 * v) <= 2.0 && fabs(c3.beta + v / (2.0 * 1.7320508)) <= 2.0,
             "correction: %d %d", c3.alpha, c3.beta);
    const foc_ab_t c1 = foc_deadtime_correction_ab(i, FOC_DT_VOLTAGE);
    TK_CHECK(c1.alpha == -e.alpha && c1.beta == -e.beta, "correction outside the band");
    const foc_abc_t zero = { 0, 0, 0 };
    const foc_ab_t e0 = foc_deadtime_error_ab(zero, FOC_DT_VOLTAGE);
    TK_CHECK(e0.alpha == 0 && e0.beta == 0, "zero current: %d %d", e0.alpha, e0.beta);
}

/* The follow check on the speed, not on the distance to the command: a
 * rotor gaining slowly at the current limit (the progress per window) is
 * not a stall, one gaining less than 3/4 of it is, even when the command moves farther away within a window
 * (the distance then grows: a fan accelerating at 122 rpm/s tripped
 * SPEED_FEEDBACK on a new command); a rotor that does not gain trips after
 * two windows whatever the command does; both directions.  On the fast
 * windows (commands above FOC_FOLLOW_SPEED_SPLIT) all four; on the slow
 * ones the stalled rotor (the Hurst075 gains at least 268 rpm per slow
 * window when it follows, more than the slow commands leave room for). */
static uint16_t follow_run(int dir, int gain_per_window, int command_step, unsigned windows,
                           int fast)
{
    foc_supervision_t s;
    foc_sup_init(&s);
    const q15_t iq_max = FOC_CURRENT_LIMIT;
    const int32_t window = fast ? FOC_FOLLOW_FAST_TICKS : FOC_FOLLOW_SLOW_TICKS;
    /* fast: from half the maximum speed; slow: below the split throughout;
     * above 8/7 of the speed either way */
    const int32_t cmd0 =
        fast ? FOC_SPEED_Q15(0.5 * MOTOR_MAX_SPEED_RPM)
             : FOC_FOLLOW_SPEED_SPLIT - 1 - (int32_t)windows * (command_step > 0 ? command_step : 0);
    int32_t speed = 10;
    for (int32_t k = 0; k < (int32_t)windows * window; k++) {
        /* the command steps halfway through each window */
        const int32_t cmd = cmd0 + (((k + window / 2) / window) * command_step);
        speed += ((k % window) == 0) ? gain_per_window : 0;
        const uint16_t f =
            foc_sup_follow(&s, (q15_t)(dir * cmd), (q15_t)(dir * speed), (q15_t)(dir * iq_max));
        if (f != 0u) {
            return f;
        }
    }
    return 0u;
}

static void case_follow_check(void)
{
    /* the policy's progress per fast window in speed counts (rounded
     * down), and the trip below three quarters of it (config.h) */
    const int gain = (int)(FOC_FOLLOW_PROGRESS_RPM(FOC_FOLLOW_FAST_S) * 32768.0 / SPEED_BASE_RPM);
    const int short_of_trip = (int)(0.75 * gain) - 1;
    const int closer = FOC_FOLLOW_SPEED_SPLIT / 16; /* 6 windows: still above 8/7 x 10 */
    for (int dir = -1; dir <= 1; dir += 2) {
        TK_CHECK(follow_run(dir, gain, 0, 6, 1) == 0u, "dir %d: gaining, fixed command", dir);
        TK_CHECK(follow_run(dir, gain, 4 * gain, 6, 1) == 0u,
                 "dir %d: gaining, the command moving away", dir);
        TK_CHECK(follow_run(dir, short_of_trip, 0, 6, 1) == (uint16_t)FOC_FAULT_SPEED_FEEDBACK,
                 "dir %d: gaining less than 3/4 of the progress, fixed command", dir);
        for (int fast = 0; fast <= 1; fast++) {
            TK_CHECK(follow_run(dir, 0, 0, 6, fast) == (uint16_t)FOC_FAULT_SPEED_FEEDBACK,
                     "dir %d, fast %d: stalled, fixed command", dir, fast);
            TK_CHECK(follow_run(dir, 0, -closer, 6, fast) == (uint16_t)FOC_FAULT_SPEED_FEEDBACK,
                     "dir %d, fast %d: stalled, the command coming closer", dir, fast);
        }
    }
}

TK_CASES(TK_CASE(case_deadtime_error), TK_CASE(case_current_sense), TK_CASE(case_faults_first_latched), TK_CASE(case_fw_table_bounds),
         TK_CASE(case_fw_voltage_mode), TK_CASE(case_protection_thresholds),
         TK_CASE(case_protection_brake_resistor), TK_CASE(case_startup_sequence),
         TK_CASE(case_bus_compensation), TK_CASE(case_voltage_circle),
         TK_CASE(case_current_circle), TK_CASE(case_speed_loop_hunting), TK_CASE(case_forced_q_holds_band),
         TK_CASE(case_emf_feedforward), TK_CASE(case_follow_check),
         TK_CASE(case_current_two_dof))
