/*
 * Phase-current offset calibration and conversion to the stator frame.
 *
 * Input: the port's samples (Q15 of the current base, offset included).
 * The offsets are the mean of 2^count_log2 samples (foc_cs_calib_start) taken with
 * the bridge off (zero current); during RUN each valid phase has its offset
 * removed and the two or three valid phases go through Clarke.
 */
#ifndef FOC_CURRENT_SENSE_H
#define FOC_CURRENT_SENSE_H

#include <stdint.h>
#include "foc/gain_balance.h"
#include "foc/port.h"
#include "foc/transforms.h"

typedef struct {
    foc_abc_t offset;    /* Q15 per phase */
    int32_t sum[3];      /* calibration sums, Q15 x 2^log2 count */
    uint16_t count;      /* samples summed so far */
    uint8_t count_log2;  /* of the samples to sum (at most 14) */
    uint8_t calibrated;  /* 1 once offsets are valid */
} foc_current_sense_t;

/* Forgets the offsets and restarts the calibration over 2^count_log2
 * periods (FOC_CALIB_PERIODS_LOG2 for a start; commissioning's longer:
 * FOC_COMM_CALIB_PERIODS_LOG2). */
void foc_cs_calib_start(foc_current_sense_t *cs, uint8_t count_log2);

/* Adds one period's samples (bridge off); sets `calibrated` when done. */
void foc_cs_calib_add(foc_current_sense_t *cs, const foc_samples_t *s);

/* Offset-corrected alpha/beta current, Q15 of the current base, from the
 * valid phases, with the sensors' learned gain mismatch taken out
 * (gain_balance.h); with fewer than two valid (no clean sampling window
 * this period) it returns `previous`. */
static inline foc_ab_t foc_cs_alphabeta(const foc_current_sense_t *cs, const foc_gain_balance_t *gb,
                                        const foc_samples_t *s, foc_ab_t previous)
{
    const q15_t a = foc_sub_q15(s->i_a, cs->offset.a);
    const q15_t b = foc_sub_q15(s->i_b, cs->offset.b);
    const q15_t c = foc_sub_q15(s->i_c, cs->offset.c);
    foc_ab_t ab;
    switch (s->phases & (FOC_PHASE_A | FOC_PHASE_B | FOC_PHASE_C)) {
    case FOC_PHASE_A | FOC_PHASE_B:
        ab = foc_clarke2_q15(a, b);
        break;
    case FOC_PHASE_B | FOC_PHASE_C:
        ab = foc_clarke2_q15(foc_sat_q15(-(int32_t)b - (int32_t)c), b);
        break;
    case FOC_PHASE_A | FOC_PHASE_C:
        ab = foc_clarke2_q15(a, foc_sat_q15(-(int32_t)a - (int32_t)c));
        break;
    case FOC_PHASE_A | FOC_PHASE_B | FOC_PHASE_C: {
        const foc_abc_t abc = { a, b, c };
        ab = foc_clarke3_q15(abc);
        break;
    }
    default:
        return previous;
    }
    return foc_gb_correct(gb, ab);
}

/* The same, out of line, for callers outside the per-period path (the
 * current loop inlines the one above). */
foc_ab_t foc_cs_read(const foc_current_sense_t *cs, const foc_gain_balance_t *gb, const foc_samples_t *s,
                     foc_ab_t previous);

#endif /* FOC_CURRENT_SENSE_H */
