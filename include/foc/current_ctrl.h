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

/* One PWM period with the q voltage given instead of regulated: Vd from
 * the d PI, Vq = `vq` limited to the circle.  In the forced frame of the
 * start-up this lets the back-EMF of a rotor swinging about the forced
 * angle drive currents through Rs: electrical damping, which a q current
 * loop would cancel.  Only while |Iq| <= iq_max: beyond, the proportional
 * gain pulls it back.  The q integrator follows Vq, so switching back to
 * foc_cc_step() is bumpless. */
foc_dq_t foc_cc_step_vq(foc_current_ctrl_t *cc, q15_t id_ref, q15_t id_meas, q15_t vq,
                        q15_t iq_meas, q15_t iq_max, q15_t v_max);

/* Presets both integrators to a voltage (hand-over to another frame). */
void foc_cc_preset(foc_current_ctrl_t *cc, foc_dq_t v);

#endif /* FOC_CURRENT_CTRL_H */
