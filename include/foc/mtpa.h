/*
 * Maximum torque per ampere (MTPA) of a salient rotor (Lq > Ld): the d
 * current that, for a q current iq, gives the most torque per ampere,
 *
 *   id = psi / (2 dL) - sqrt(psi^2 / (4 dL^2) + iq^2),   dL = Lq - Ld,
 *
 * written without the large quotient psi / dL (infinite for a round rotor):
 *
 *   id = -|iq| r(x),   x = k |iq|,   k = 2 dL / psi,
 *   r(x) = x / (1 + sqrt(1 + x^2))   (0 <= r < 1, r ~ x / 2 for small x).
 *
 * The torque 1.5 p (psi + (Ld - Lq) id) iq then gains the reluctance share
 * (Lq - Ld) |id| iq (docs/estimators.md, "Salient rotors").
 *
 * Units: currents Q15 of the current base; k = FOC_MTPA_K_Q12 (config.h), Q12
 * per unit of current (k < 8); x Q12 held at 8.0 (a rotor that salient at
 * the ADC's full scale gets r(8) = 0.88 of its optimum there); r Q15.  One
 * 32-bit square root and one 32-bit division: the slow tick's, not the
 * PWM period's.
 */
#ifndef FOC_MTPA_H
#define FOC_MTPA_H

#include "foc/q15.h"

/* The MTPA d current for the q current `iq` (either sign), <= 0, with
 * |id| < |iq|; 0 when k_q12 is 0 (a round rotor). */
q15_t foc_mtpa_id_q15(q15_t iq, q15_t k_q12);

#endif /* FOC_MTPA_H */
