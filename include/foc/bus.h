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
 * The slow tick filters one sample and takes the reciprocal (one
 * division); the fast step checks every sample against the filtered bus,
 * and one more than 1/16 off (a step: a supply switched, a contactor, a
 * regenerating load let go) restarts the filter there and derives the
 * limits at once.  Filtered on the slow tick only, a step from 16.9 to
 * 24 V at the drone's maximum speed gave the winding 1.4 x the voltage
 * asked for a millisecond and the current 1.08 x the limit (campaign seed
 * 146).  (A slow tick the fast step preempts may write its older figures
 * after the restart's: the step is still there at the next period, which
 * restarts again.)
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
} foc_bus_t;

/* Starts the filter at `vdc` (Q15 of the bus full scale, >= 0) and
 * derives v_max and comp_q14 from it. */
void foc_bus_init(foc_bus_t *bus, q15_t vdc);

/* Slow tick: filters one bus sample, updates v_max and comp_q14. */
void foc_bus_update(foc_bus_t *bus, q15_t vdc);

/* Fast step: a sample (>= 0) more than 1/16 off the filtered bus restarts
 * the filter there (foc_bus_init). */
static inline void foc_bus_check_step(foc_bus_t *bus, q15_t vdc)
{
    const int32_t was = foc_lpf_out(&bus->vdc);
    const int32_t step = ((int32_t)vdc - was) * 16;
    if (step > was || step < -was) {
        foc_bus_init(bus, vdc);
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
