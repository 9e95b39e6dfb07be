/*
 * Space-vector modulation by min-max (zero-sequence) injection.
 *
 * Input: the stator voltage vector (alpha, beta) in Q15 per-unit of the
 * voltage that linear SVM reaches at the present bus voltage, i.e. 1.0 =
 * Vdc/sqrt(3) (the caller scales by the measured bus, see controller).
 * Output: three duty cycles, Q15 fraction of the PWM period in [0, 32767]
 * (high-side on-time / period), and the sector 1..6 of the vector (used by a
 * 3-shunt port to pick the two phases whose low side is on long enough).
 *
 * Inside the hexagon (which contains the linear circle |v| <= 1) the
 * phase-to-phase voltages are exact.  Beyond it the three phase voltages are
 * scaled down together so the duty span is exactly the period: the vector
 * keeps its angle and only its magnitude is reduced.
 */
#ifndef FOC_SVM_H
#define FOC_SVM_H

#include <stdint.h>
#include "foc/transforms.h"

typedef struct {
    q15_t a;        /* Q15 duty, [0, 32767] */
    q15_t b;
    q15_t c;
    uint8_t sector; /* 1..6, sector of the voltage vector, 60 deg each, */
                    /* sector 1 = [0, 60) deg from the alpha axis; the */
                    /* 60/120/.. deg edges are placed within 0.001 deg */
} foc_duty_t;

foc_duty_t foc_svm_q15(foc_ab_t v);

#endif /* FOC_SVM_H */
