/*
 * Rotor angle and speed source behind one interface: the position sensor
 * (reference for tests) or a sensorless estimator.  The controller calls
 * foc_est_step() once per PWM period with the currents just measured and
 * the voltage applied during the period that just ended.
 *
 * Two outputs: `theta`/`speed` are what the controller uses; `est_theta`/
 * `est_speed` are the selected estimator's own figures (equal to the first
 * pair once closed loop runs on the estimator; during a sensored start they
 * show the estimator converging while the sensor drives).
 */
#ifndef FOC_ESTIMATOR_H
#define FOC_ESTIMATOR_H

#include <stdint.h>
#include "foc/config.h"
#include "foc/flux_est.h"
#include "foc/luenberger.h"
#include "foc/pll_est.h"
#include "foc/sensored.h"
#include "foc/transforms.h"

typedef enum {
    FOC_EST_SENSORED = 0,
    FOC_EST_PLL = 1,        /* AN1292 back-EMF PLL estimator */
    FOC_EST_LUENBERGER = 2, /* ST-style Luenberger observer + PLL */
    FOC_EST_FLUX = 3        /* flux-linkage estimator + speed observer */
} foc_est_kind_t;
FOC_STATIC_ASSERT(FOC_ESTIMATOR >= FOC_EST_SENSORED && FOC_ESTIMATOR <= FOC_EST_FLUX,
                  "FOC_ESTIMATOR must be FOC_EST_PLL, FOC_EST_LUENBERGER, FOC_EST_FLUX or "
                  "FOC_EST_SENSORED");

typedef struct {
    foc_ab_t v_ab;          /* voltage applied in the last period, Q15 */
    foc_ab_t i_ab;          /* current measured now, Q15 */
    q15_t iq_ref;           /* torque command (current), Q15 */
    uint16_t theta_sensor;  /* position sensor, if any */
} foc_est_input_t;

/* The estimators' gains the monitor may write (in IDLE or FAULT only: an
 * observer's gain changed under way could lose the angle), kept over
 * resets and handed to the running estimator at each restart: */
typedef struct {
    q15_t luen_kp;          /* the Luenberger PLL's kp mantissa (shift */
    q15_t luen_ki;          /* FOC_LUEN_PLL_KP_SHIFT) and ki, Q15, 0..32767 */
    q15_t pll_track;        /* the PLL's flux tracking gain, Q14, 0..16383 */
    q15_t flux_corr_min;    /* the flux estimator's correction gain per */
    q15_t flux_corr_speed;  /* period: k_min Ts and c w_base Ts, Q15 */
} foc_est_gains_t;

typedef struct {
    uint8_t kind;           /* foc_est_kind_t (one byte: the struct packs) */
    uint8_t use_sensor;     /* 1: the controller runs on the sensor */
    uint16_t theta;         /* used by the controller, 65536 = 360 deg */
    q15_t speed;            /* used by the controller, Q15 of SPEED_BASE_RPM */
    uint16_t est_theta;     /* the selected estimator's own estimate */
    q15_t est_speed;
    q15_t rs_ratio;         /* [slow] Rs / MOTOR_RS_OHM, Q14: the alignment's */
                            /* measure, kept over restarts */
    q15_t ls_ratio;         /* [slow] Ls / MOTOR_LQ_H, Q14: the same */
    foc_est_gains_t gains;  /* [init] the monitor's, applied at restarts */
    foc_sensored_t sensored;
    union {                 /* one sensorless estimator runs at a time */
        foc_pll_t pll;
        foc_luenberger_t luenberger;
        foc_flux_est_t flux;
    } u;
} foc_estimator_t;

/* The build's gains (config.h). */
void foc_est_gains_init(foc_est_gains_t *g);

/* Selects the estimator (kept over resets); 0, or -1 if
 * that kind is not built (the selection is then unchanged).  Firmware
 * builds contain only FOC_ESTIMATOR (and the sensor); a build with
 * FOC_ALL_ESTIMATORS defined (the host's) contains all of them. */
int foc_est_select(foc_estimator_t *est, foc_est_kind_t kind);

/* Restarts the estimator from angle 0 and standstill with no current in
 * the windings, as after power-up with the rotor position unknown; the
 * sensor's filter from `theta_sensor`; `use_sensor` chooses the source. */
void foc_est_reset(foc_estimator_t *est, uint16_t theta_sensor, uint8_t use_sensor);

/* The sensorless estimator restarted on a rotor whose angle and speed are
 * known (the flying start's probe), with no current in the windings. */
void foc_est_preset(foc_estimator_t *est, uint16_t theta, q15_t speed);

/* Firmware builds only the configured estimator: the others are dead
 * code, so the linker leaves them out.  The host builds them all
 * (focsim --estimator chooses at run time). */
#ifdef FOC_ALL_ESTIMATORS
#define FOC_EST_BUILT(kind) 1
#else
#define FOC_EST_BUILT(kind) ((kind) == FOC_ESTIMATOR || (kind) == FOC_EST_SENSORED)
#endif

/* The selected estimator's own figures, then the ones the controller
 * uses (the sensor's during a sensored start). */
static inline void foc_est_publish(foc_estimator_t *est)
{
    switch (est->kind) {
    case FOC_EST_PLL:
        if (FOC_EST_BUILT(FOC_EST_PLL)) {
            est->est_theta = est->u.pll.theta;
            est->est_speed = foc_pll_speed(&est->u.pll);
        }
        break;
    case FOC_EST_FLUX:
        if (FOC_EST_BUILT(FOC_EST_FLUX)) {
            est->est_theta = est->u.flux.theta;
            est->est_speed = foc_flux_speed(&est->u.flux);
        }
        break;
    case FOC_EST_LUENBERGER:
        if (FOC_EST_BUILT(FOC_EST_LUENBERGER)) {
            est->est_theta = est->u.luenberger.theta;
            est->est_speed = foc_luen_speed(&est->u.luenberger);
        }
        break;
    default:
        est->est_theta = est->sensored.theta;
        est->est_speed = foc_lpf_out(&est->sensored.speed);
        break;
    }
    if (est->use_sensor != 0u) {
        est->theta = est->sensored.theta;
        est->speed = foc_lpf_out(&est->sensored.speed);
    } else {
        est->theta = est->est_theta;
        est->speed = est->est_speed;
    }
}

/* One PWM period; updates all outputs.  Inline: the dispatch is a switch
 * the firmware build reduces to its one estimator. */
static inline void foc_est_step(foc_estimator_t *est, const foc_est_input_t *in)
{
    if (est->use_sensor != 0u) {
        foc_sensored_step(&est->sensored, in->theta_sensor);
    }
    switch (est->kind) {
    case FOC_EST_PLL:
        if (FOC_EST_BUILT(FOC_EST_PLL)) {
            foc_pll_step(&est->u.pll, in->v_ab, in->i_ab);
        }
        break;
    case FOC_EST_FLUX:
        if (FOC_EST_BUILT(FOC_EST_FLUX)) {
            foc_flux_step(&est->u.flux, in->v_ab, in->i_ab, in->iq_ref);
        }
        break;
    case FOC_EST_LUENBERGER:
        if (FOC_EST_BUILT(FOC_EST_LUENBERGER)) {
            foc_luen_step(&est->u.luenberger, in->v_ab, in->i_ab);
        }
        break;
    default:
        break;
    }
    foc_est_publish(est);
}

/* Slow step: the estimator's slow share (the PLL's flux tracking), in
 * every state whose fast step runs it; its reset when a restart is posted.
 * Estimators without one ignore both. */
void foc_est_track_flux(foc_estimator_t *est);
void foc_est_track_reset(foc_estimator_t *est);

/* Rs as a ratio to MOTOR_RS_OHM, Q14 (the alignment's measure), for the
 * estimators that model it (PLL, flux) from now and after restarts. */
void foc_est_set_rs(foc_estimator_t *est, q15_t ratio_q14);

/* Ls as a ratio to MOTOR_LQ_H, Q14 within [0.5, 2) (the alignment's
 * measure on d, both axes scaled alike), for the PLL, the flux estimator
 * and the Luenberger observer (its model's constants, within their
 * formats) from now and after restarts. */
void foc_est_set_ls(foc_estimator_t *est, q15_t ratio_q14);

/* Field weakening's run-time machine constants: 1/KFi as a mantissa of
 * FOC_PLL_INVKFI_SHIFT and Ls/(2 Ls0) in Q15 (0.5 nominal, times the
 * alignment's Ls ratio); estimators that model neither ignore them. */
void foc_est_set_fw(foc_estimator_t *est, q15_t inv_kfi, q15_t ls_scale);

/* 1 if the estimator's back-EMF magnitude is at least `ratio` (Q15) of
 * what its own speed estimate implies (a held rotor that the estimator
 * "sees" turning fails this).  A speed derived from the EMF magnitude
 * itself (PLL) passes by construction.  The flux estimator, which learns
 * the magnet's flux, fails it when that flux is pinned at its range's
 * end (foc_flux_consistent; `ratio` unused). */
uint8_t foc_est_emf_consistent(const foc_estimator_t *est, q15_t ratio);

/* "sensored", "pll", "luenberger", "flux". */
const char *foc_est_name(foc_est_kind_t kind);

#endif /* FOC_ESTIMATOR_H */
