#include "foc/deadtime.h"
#include "foc/config.h"

/* One phase's voltage error: -V_dt x clamp(i / I_soft, -1, 1). */
static q15_t phase_error(q15_t i)
{
    const q15_t ratio = foc_mul_q15_shift(i, FOC_DT_INV_SOFT_MANT, FOC_DT_INV_SOFT_SHIFT);
    return foc_mul_q15(ratio, (q15_t)-FOC_DT_VOLTAGE);
}

foc_ab_t foc_deadtime_error_ab(foc_abc_t i)
{
    const foc_abc_t e = { phase_error(i.a), phase_error(i.b), phase_error(i.c) };
    return foc_clarke3_q15(e); /* the common mode never reaches the windings */
}
