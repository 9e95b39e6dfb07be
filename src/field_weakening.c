#include "foc/field_weakening.h"
#include "foc/config.h"

/* cppcheck-suppress misra-c2012-20.7 ; F analyser false positive */
#define FW_ENTRY_8(f, i)                                                       \
    f((i)), f((i) + 1), f((i) + 2), f((i) + 3), f((i) + 4), f((i) + 5), f((i) + 6), f((i) + 7)

#ifdef FW_ID_TABLE
static const q15_t id_table[] = FW_ID_TABLE;
#else
static const q15_t id_table[] = { FW_ENTRY_8(FOC_FW_ID_AT, 0), FW_ENTRY_8(FOC_FW_ID_AT, 8),
                                  /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
                                  FOC_FW_ID_AT(16), FOC_FW_ID_AT(17) };
#endif

#define NOMINAL_INVKFI(i) FOC_PLL_INVKFI
#define NOMINAL_LS(i) Q15(0.5)
#ifdef FW_INVKFI_TABLE
static const q15_t invkfi_table[] = FW_INVKFI_TABLE;
#else
static const q15_t invkfi_table[] = { FW_ENTRY_8(NOMINAL_INVKFI, 0), FW_ENTRY_8(NOMINAL_INVKFI, 8),
                                      FOC_PLL_INVKFI, FOC_PLL_INVKFI };
#endif
#ifdef FW_LS_TABLE
static const q15_t ls_table[] = FW_LS_TABLE;
#else
static const q15_t ls_table[] = { FW_ENTRY_8(NOMINAL_LS, 0), FW_ENTRY_8(NOMINAL_LS, 8),
                                  /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
                                  Q15(0.5), Q15(0.5) };
#endif

FOC_STATIC_ASSERT(sizeof id_table / sizeof id_table[0] == (unsigned)FOC_FW_TABLE_SIZE &&
                  sizeof invkfi_table / sizeof invkfi_table[0] == (unsigned)FOC_FW_TABLE_SIZE &&
                  sizeof ls_table / sizeof ls_table[0] == (unsigned)FOC_FW_TABLE_SIZE,
                  "FW_ID_TABLE, FW_INVKFI_TABLE and FW_LS_TABLE need 18 entries each");

static const foc_pi_gains_t fw_gains =
    FOC_PI_GAINS(FOC_FW_KP_MANT, FOC_FW_KP_SHIFT, FOC_FW_KI, 0, FOC_FW_KC);

void foc_fw_init(foc_fw_t *fw)
{
    fw->mode = (uint8_t)FW_MODE;
    fw->mtpa = (uint8_t)(FOC_SALIENT != 0);
    foc_pi_init(&fw->pi, (q15_t)-FOC_FW_ID_MAX, 0);
    fw->gains = foc_pi_tune_of(&fw_gains);
    foc_fw_reset(fw);
}

void foc_fw_reset(foc_fw_t *fw)
{
    foc_pi_preset(&fw->pi, 0);
    fw->id_ref = 0;
    fw->inv_kfi = FOC_PLL_INVKFI;
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    fw->ls_scale = Q15(0.5);
}

/* Table position of a speed, in 1/256 of an entry, within
 * [0, 256 x (size - 1)]: the index can never leave the tables. */
static int32_t table_position(q15_t speed_ref)
{
    const int32_t above = (int32_t)foc_abs_q15(speed_ref) - FOC_FW_START;
    if (above <= 0) {
        return 0;
    }
    const int32_t last = 256L * (FOC_FW_TABLE_SIZE - 1);
    const int32_t pos = foc_mul_q15_shift(foc_sat_q15(above), FOC_FW_POS_MANT, FOC_FW_POS_SHIFT);
    return pos > last ? last : pos;
}

/* Linear interpolation at `pos` (1/256 entry); |difference x 255| < 2^24. */
static q15_t lookup(const q15_t *table, int32_t pos)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t i = pos >> 8;
    const int32_t frac = pos & 255;
    if (frac == 0) {
        return table[i];
    }
    const int32_t diff = (int32_t)table[i + 1] - (int32_t)table[i];
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return (q15_t)(table[i] + ((diff * frac) >> 8));
}

q15_t foc_fw_step(foc_fw_t *fw, q15_t speed_ref, q15_t v_mag, q15_t v_max)
{
    switch (fw->mode) {
    case FW_MODE_TABLE: {
        const int32_t pos = table_position(speed_ref);
        fw->id_ref = lookup(id_table, pos);
        fw->inv_kfi = lookup(invkfi_table, pos);
        fw->ls_scale = lookup(ls_table, pos);
        break;
    }
    case FW_MODE_VOLTAGE: {
        /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
        const q15_t target = foc_mul_q15(v_max, FOC_FW_MARGIN);
        const foc_pi_gains_t g = foc_pi_gains_with(&fw->gains, &fw_gains);
        fw->id_ref = foc_pi_step(&fw->pi, &g, foc_sub_q15(target, v_mag));
        break;
    }
    default:
        fw->id_ref = 0;
        break;
    }
    return fw->id_ref;
}
