/*
 * Phase-current offset calibration and conversion to the stator frame.
 *
 * Input: the port's samples (Q15 of the current base, offset included).
 * The offsets are the mean of 2^FOC_CALIB_PERIODS_LOG2 samples taken with
 * the bridge off (zero current); during RUN each valid phase has its offset
 * removed and the two or three valid phases go through Clarke.
 */
#ifndef FOC_CURRENT_SENSE_H
#define FOC_CURRENT_SENSE_H

#include <stdint.h>
#include "foc/port.h"
#include "foc/transforms.h"

typedef struct {
    foc_abc_t offset;    /* Q15 per phase */
    int32_t sum[3];      /* calibration sums, Q15 x 2^log2 count */
    uint16_t count;      /* samples summed so far */
    uint8_t calibrated;  /* 1 once offsets are valid */
} foc_current_sense_t;

/* Forgets the offsets and restarts the calibration. */
void foc_cs_calib_start(foc_current_sense_t *cs);

/* Adds one period's samples (bridge off); sets `calibrated` when done. */
void foc_cs_calib_add(foc_current_sense_t *cs, const foc_samples_t *s);

/* Offset-corrected alpha/beta current, Q15 of the current base, from the
 * valid phases; with fewer than two valid (no clean sampling window this
 * period) it returns `previous`. */
foc_ab_t foc_cs_alphabeta(const foc_current_sense_t *cs, const foc_samples_t *s,
                          foc_ab_t previous);

#endif /* FOC_CURRENT_SENSE_H */
