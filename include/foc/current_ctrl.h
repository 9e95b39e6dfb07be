/*
 * d/q current controllers with the voltage-limit circle, d-axis priority
 * (AN1292 figure 9): Vd is limited to +-Vmax, then Vq to
 * +-sqrt(Vmax^2 - Vd^2), so the flux-producing (field-weakening) component
 * always gets the voltage it asks for and |Vdq| <= Vmax.
 *
 * Units: currents Q15 of the current base, voltages Q15 of the voltage
 * base (Vdc_nominal / sqrt(3)); Vmax comes from the bus block.
 */
#ifndef FOC_CURRENT_CTRL_H
#define FOC_CURRENT_CTRL_H

#include "foc/pi.h"
#include "foc/transforms.h"

typedef struct {
    foc_pi_q15_t pi_d;
    foc_pi_q15_t pi_q;
} foc_current_ctrl_t;

/* Gains from userparms.h; integrators cleared. */
void foc_cc_init(foc_current_ctrl_t *cc);

/* Clears both integrators (outputs start from zero voltage). */
void foc_cc_reset(foc_current_ctrl_t *cc);

/* One PWM period: voltage command for reference and measured currents. */
foc_dq_t foc_cc_step(foc_current_ctrl_t *cc, foc_dq_t i_ref, foc_dq_t i_meas,
                     q15_t v_max);

#endif /* FOC_CURRENT_CTRL_H */
