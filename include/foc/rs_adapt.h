/*
 * Online winding-resistance adaptation (slow tick, RUN on the estimator).
 *
 * A winding warms under load (copper +0.39 %/K: +40 % for 100 K), and the
 * estimators' Rs, measured at the alignment, goes stale: its error times
 * the current lies in the back-EMF they estimate.  In field weakening the
 * d current is large, so the error turns the estimated EMF: 11-14 deg of
 * angle at 2000 rpm on the Hurst075 for Rs +40 % (docs/estimators.md,
 * "Resistance drift").
 *
 * In steady state the back-EMF's magnitude does not depend on the frame:
 *   |E|^2 = (vq - Rs iq - w Ld id)^2 + (vd - Rs id + w Lq iq)^2 = (w psi)^2
 * in the estimated frame as in the rotor's, so an angle error drops out.
 * With the build's flux psi (the data sheet's or commissioning's) and the
 * estimated speed, Rs is the value that makes the two sides equal.  The
 * error eps = |E|^2 - (w psi)^2 has the slope d eps / d Rs = -2 (E . i),
 * so each tick takes a Newton step toward eps = 0, 1/64 of it (a time
 * constant of 64 slow ticks on the inputs' 20 ms filters); the converged
 * value does not depend on that step's scale.
 *
 * An Rs error turns the EMF only through the d current (dRs id lies
 * across it; dRs iq only scales it), and Rs shows only where the ohmic
 * drop is a fair part of the EMF: it runs while |id| >= |iq| / 4 (field
 * weakening, MTPA) and |iq| Rs >= |w psi| / 4, and holds otherwise.  A
 * flux error dpsi biases Rs by w dpsi / iq, up to 4 x Rs x dpsi / psi
 * under that gate, so Rs stays within -1/8 .. +1/2 of what the alignment
 * measured (a winding that warms, or cools a little, in one run).
 *
 * Units: voltages Q15 of the voltage base, currents Q15 of the current
 * base, speed Q15 of the speed base, ratios Q14 of the build's value.
 */
#ifndef FOC_RS_ADAPT_H
#define FOC_RS_ADAPT_H

#include "foc/lpf.h"
#include "foc/transforms.h"

typedef struct {
    foc_lpf_q15_t vd, vq; /* filtered voltage command, Q15 (vd, id: */
    foc_lpf_q15_t id, iq; /* also ALIGN's, controller.c align_average) */
    foc_lpf_q15_t speed;  /* filtered speed estimate, Q15 */
    q15_t rs_min_q14;     /* the range around the alignment's Rs, Q14 */
    q15_t rs_max_q14;
} foc_rs_adapt_t;

/* Starts the filters at the present values (RUN's entry) and sets the
 * range from the Rs ratio measured at the alignment, `rs_q14`. */
void foc_rs_adapt_reset(foc_rs_adapt_t *a, foc_dq_t v, foc_dq_t i, q15_t speed, q15_t rs_q14);

/* One slow tick: filters the inputs and returns the Rs ratio to use (Q14,
 * [FOC_RATIO_MIN_Q14, 32767]), `rs_q14` itself where the gate holds it.
 * `ls_q14`: the estimator's inductance ratio. */
q15_t foc_rs_adapt_tick(foc_rs_adapt_t *a, foc_dq_t v, foc_dq_t i, q15_t speed, q15_t rs_q14,
                        q15_t ls_q14);

#endif /* FOC_RS_ADAPT_H */
