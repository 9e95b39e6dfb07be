#include "foc/current_sense.h"
#include "foc/config.h"

void foc_cs_calib_start(foc_current_sense_t *cs, uint8_t count_log2)
{
    cs->count_log2 = count_log2;
    cs->offset.a = 0;
    cs->offset.b = 0;
    cs->offset.c = 0;
    cs->sum[0] = 0;
    cs->sum[1] = 0;
    cs->sum[2] = 0;
    cs->count = 0;
    cs->calibrated = 0;
}

/* Mean of the sum, rounded: |sum| <= 2^15 x 2^14 fits int32_t. */
static q15_t mean_of(int32_t sum, uint8_t log2)
{
    /* cppcheck-suppress [misra-c2012-10.1, misra-c2012-10.7] ; D1 Q-format shift */
    return foc_sat_q15((sum + ((int32_t)1 << (log2 - 1u))) >> log2);
}

void foc_cs_calib_add(foc_current_sense_t *cs, const foc_samples_t *s)
{
    if (cs->calibrated != 0u) {
        return;
    }
    /* A 3-shunt port reads all three phases while the bridge is off. */
    cs->sum[0] += s->i_a;
    cs->sum[1] += s->i_b;
    cs->sum[2] += s->i_c;
    cs->count++;
    if (cs->count >= (uint16_t)(1u << cs->count_log2)) {
        cs->offset.a = mean_of(cs->sum[0], cs->count_log2);
        cs->offset.b = mean_of(cs->sum[1], cs->count_log2);
        cs->offset.c = mean_of(cs->sum[2], cs->count_log2);
        cs->calibrated = 1;
    }
}

foc_ab_t foc_cs_read(const foc_current_sense_t *cs, const foc_gain_balance_t *gb, const foc_samples_t *s,
                     foc_ab_t previous)
{
    return foc_cs_alphabeta(cs, gb, s, previous);
}
