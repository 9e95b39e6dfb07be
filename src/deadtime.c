#include "foc/deadtime.h"
#include "foc/config.h"

/* One phase's voltage error: -V_dt x clamp(i / band, -1, 1); the band's
 * inverse as a gain (mantissa, shift). */
static q15_t phase_error(q15_t i, q15_t inv_band, uint8_t shift)
{
    const q15_t ratio = foc_mul_q15_shift(i, inv_band, shift);
    return foc_mul_q15(ratio, (q15_t)-FOC_DT_VOLTAGE);
}

/* The common mode never reaches the windings: Clarke drops it. */
static foc_ab_t error_ab(foc_abc_t i, q15_t inv_band, uint8_t shift)
{
    const foc_abc_t e = { phase_error(i.a, inv_band, shift), phase_error(i.b, inv_band, shift),
                          phase_error(i.c, inv_band, shift) };
    return foc_clarke3_q15(e);
}

foc_ab_t foc_deadtime_error_ab(foc_abc_t i)
{
    return error_ab(i, FOC_DT_INV_RIPPLE_MANT, FOC_DT_INV_RIPPLE_SHIFT);
}

foc_ab_t foc_deadtime_correction_ab(foc_abc_t i_ref)
{
    const foc_ab_t e = error_ab(i_ref, FOC_DT_INV_SOFT_MANT, FOC_DT_INV_SOFT_SHIFT);
    const foc_ab_t c = { foc_sat_q15(-(int32_t)e.alpha), foc_sat_q15(-(int32_t)e.beta) };
    return c;
}
