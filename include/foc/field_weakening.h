/*
 * Field weakening (slow tick): the d-axis current reference above base
 * speed, and (table mode) the estimator's 1/KFi and Ls.
 *
 * FW_MODE_TABLE (AN1292): three 18-entry tables indexed from the speed
 * reference (not the noisy estimate) between FW_START_RPM and FW_END_RPM,
 * linearly interpolated; below the start the first entry, past the end the
 * last entry holds (the index is always within the tables).
 * FW_MODE_VOLTAGE: a PI drives Id in [-FW_ID_MAX_A, 0] so that |Vdq| stays
 * at FW_VOLTAGE_MARGIN x the voltage limit; below base speed |Vdq| is under
 * the target and the PI rests at Id = 0.
 *
 * Units: speed Q15 of SPEED_BASE_RPM; voltages Q15 of the voltage base;
 * Id Q15 of the current base; inv_kfi Q15 mantissa of FOC_PLL_INVKFI_SHIFT;
 * ls_scale = Ls/(2 Ls0) in Q15 (0.5 nominal).
 */
#ifndef FOC_FIELD_WEAKENING_H
#define FOC_FIELD_WEAKENING_H

#include <stdint.h>
#include "foc/pi.h"

typedef enum {
    FW_MODE_OFF = 0,
    FW_MODE_TABLE = 1,
    FW_MODE_VOLTAGE = 2
} foc_fw_mode_t;

typedef struct {
    foc_pi_q15_t pi;   /* voltage mode */
    foc_pi_tune_t gains; /* [init] its kp (0..65535), ki (0..32767) mantissas */
                         /* at the build's exponents (FOC_FW_KP_SHIFT, 0); */
                         /* the monitor writes them */
    q15_t id_ref;
    q15_t inv_kfi;     /* for the estimator (nominal outside table mode) */
    q15_t ls_scale;
    uint8_t mode;      /* foc_fw_mode_t (one byte: `mtpa` takes the */
                       /* struct's padding, no RAM for it) */
    uint8_t mtpa;      /* 1: the controller takes the MTPA d current where */
                       /* it is more negative (salient rotors, FOC_SALIENT; */
                       /* changeable in IDLE); 0: id = 0 below base speed */
} foc_fw_t;

/* Mode from userparms.h (FW_MODE), MTPA on a salient rotor; Id = 0,
 * nominal estimator constants. */
void foc_fw_init(foc_fw_t *fw);

/* Back to Id = 0 (at every start). */
void foc_fw_reset(foc_fw_t *fw);

/* One slow tick; returns the Id reference. `v_mag` is |Vdq| of the last
 * period, `v_max` the present voltage limit. */
q15_t foc_fw_step(foc_fw_t *fw, q15_t speed_ref, q15_t v_mag, q15_t v_max);

#endif /* FOC_FIELD_WEAKENING_H */
