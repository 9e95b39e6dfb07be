/*
 * DC-bus voltage: filtering, the voltage limit it allows, and modulation
 * compensation.
 *
 * The voltage base is fixed at the nominal bus (Vdc_nominal / sqrt(3)), so
 * when the bus sags the same per-unit voltage needs a larger modulation
 * index: the SVM input is v x (Vdc_nominal / Vdc_measured), and the
 * controllers are limited to Vmax = min(Vdc / Vdc_nominal, 1) x
 * VOLTAGE_LIMIT_FRACTION so that product stays inside the linear range.
 * Above the nominal bus the extra voltage is not used (the per-unit range
 * ends at 1.0).
 *
 * The fast step owns it: every CONTROL_SLOW_DIVIDER periods (a slow tick)
 * it filters one sample and takes the reciprocal (one division); a sample
 * more than 1/16 off the filtered bus (a step: a supply switched, a
 * contactor, a regenerating load let go) restarts the filter there at
 * once.  Filtered on the slow tick only, a step from 16.9 to 24 V at the
 * drone's maximum speed gave the winding 1.4 x the voltage asked for a
 * millisecond and the current 1.08 x the limit (campaign seed 146).
 */
#ifndef FOC_BUS_H
#define FOC_BUS_H

#include "foc/config.h"
#include "foc/lpf.h"
#include "foc/transforms.h"

typedef struct {
    foc_lpf_q15_t vdc;  /* filtered bus, Q15 of BOARD_VDC_FULL_SCALE_V */
    q15_t v_max;        /* |Vdq| limit, Q15 of the voltage base */
    int16_t comp_q14;   /* Vdc_nominal / Vdc, Q14, in [0.5, 2] */
    uint8_t period;     /* periods since the last filtered sample */
} foc_bus_t;

/* Starts the filter at `vdc` (Q15 of the bus full scale, >= 0) and
 * derives v_max and comp_q14 from it. */
void foc_bus_init(foc_bus_t *bus, q15_t vdc);

/* v_max and comp_q14 from the filtered bus (one division). */
void foc_bus_derive(foc_bus_t *bus);

/* Fast step, every period: a bus sample (>= 0) into the filter once a
 * slow tick, or a step's at once (the filter restarted at it); v_max and
 * comp_q14 derived from the filter after either. */
static inline void foc_bus_update(foc_bus_t *bus, q15_t vdc)
{
    const q15_t was = foc_lpf_out(&bus->vdc);
    const int32_t step = (int32_t)vdc - was;
    if (step * 16 > was || step * 16 < -was) {
        foc_lpf_init(&bus->vdc, vdc);
        foc_bus_derive(bus);
        bus->period = 1u;
    } else if (bus->period == 0u) {
        /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
        (void)foc_lpf_step(&bus->vdc, vdc, FOC_VDC_FILTER_K);
        foc_bus_derive(bus);
        bus->period = 1u;
    } else {
        bus->period = (bus->period + 1u >= (uint8_t)CONTROL_SLOW_DIVIDER) ? 0u : (uint8_t)(bus->period + 1u);
    }
}

/* Scales a voltage command (Q15 of the voltage base) to the SVM input:
 * v x comp / 2^14, rounded and saturated; |v x comp| < 2^30. */
static inline foc_ab_t foc_bus_compensate(const foc_bus_t *bus, foc_ab_t v)
{
    foc_ab_t out;
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    out.alpha = foc_sat_q15(((int32_t)v.alpha * bus->comp_q14 + (int32_t)8192) >> 14);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    out.beta = foc_sat_q15(((int32_t)v.beta * bus->comp_q14 + (int32_t)8192) >> 14);
    return out;
}

#endif /* FOC_BUS_H */
