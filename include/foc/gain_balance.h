/*
 * Current-sensor gain balance: the slow tick learns the sensors' gain
 * mismatch in RUN, the fast step takes it out of every measurement.
 *
 * Sensors whose gains differ (shunts and amplifiers within +-2 %) turn a
 * balanced current i (complex: alpha + j beta) into g0 i + G conj(i): the
 * second term is a negative sequence.  The current loop regulates what it
 * measures, so it drives -G conj(i) / g0 through the winding: twice the
 * electrical frequency in the rotor frame (Hurst075, sensors +2 / -2 %,
 * 2000 rpm at 0.86 A: id 94 mA peak without this block).  Two
 * shunts of gains 1 + ea, 1 + eb give G = d (1 + j / sqrt 3) with
 * d = (ea - eb) / 2, and a turn of d / sqrt 3 rad of the whole current,
 * which no measurement tells from the machine's.
 *
 * The fast step uses i_c = i_m - Gh conj(i_m).  Where Gh != G the winding
 * carries a negative sequence, whose current In and voltage Vn the
 * balanced machine (its back-EMF a positive sequence) relates through
 * Zn = Rs - j w L (L = (Ld + Lq) / 2, the sequence turning at -w).  In the
 * rotor frame they are the components at -2 theta of the current and of
 * the voltage command; taken from their means over 128 ticks (64 ms on
 * the Hurst075's board) and turned back by
 * e^{j 2 theta}:
 *     D = Zn In - Vn = Zn (G - Gh) conj(I) = W (G - Gh)
 * with I the mean dq current, whatever share of it the current loop
 * rejects.  Each tick takes 2^-rate of the normalized step
 * D conj(W) / |W|^2 (|W|^2 rounded down to a power of two: within a
 * factor 2), rate growing from 8 to 11 as it learns (gain_balance.c); the
 * other components average out (the positive sequence, the 6th harmonic
 * of the dead time and the EMF, noise).  It learns where it can see G:
 * |W| >= 1/32 of 2^FOC_GB_Z_SHIFT per-unit (the Hurst075 from about
 * 0.32 A at 1000 rpm), twice the electrical frequency turning at least
 * once in 16 ticks (the means reject it; a lag left by a transient turns
 * away) and below 0.3 x the tick rate (no alias): config.h
 * FOC_GB_MIN_SPEED, FOC_GB_MAX_SPEED; and where the voltage's deviation
 * from its mean (noise through the current PI, a transient's lag) stays
 * within |W| / 2.8 in RMS over 16 ticks, else it holds until 128 ticks
 * after.  The
 * gains are the board's, so Gh stays from run to run, within +-1/8.
 *
 * Measured (tests/unit/test_gain_balance.c, a double-precision loop):
 * without noise Gh within 0.5-2.7 % of the closed form, two shunts or
 * three; with 2 codes of noise within 3-13 % after 4 s, the true negative
 * sequence at 0.05-0.17 of the unbalanced one.  Hurst075 on `plant
 * realistic` (test_sensored): id 76.6 mA peak at 2000 rpm loaded.
 *
 * Units: currents Q15 of the current base, voltages Q15 of the voltage
 * base, speed Q15 of the speed base; impedances Q15 of 2^FOC_GB_Z_SHIFT
 * per-unit (config.h); Gh Q15 (read by the fast step) and Q27 (learned).
 */
#ifndef FOC_GAIN_BALANCE_H
#define FOC_GAIN_BALANCE_H

#include "foc/lpf.h"
#include "foc/transforms.h"

typedef struct {
    foc_lpf_q15_t vd, vq; /* [slow] the voltage command's mean, Q15 */
    foc_lpf_q15_t id, iq; /* [slow] the current's, Q15 */
    int32_t vn_power;     /* [slow] |its deviation|^2 over 16 ticks, Q29 */
    int32_t g_re_q27;     /* [slow] Gh, Q27, within [-1/8, 1/8) */
    int32_t g_im_q27;
    q15_t g_re;           /* [slow] the same in Q15, read by the fast */
    q15_t g_im;           /* step (a torn pair: two ticks' mix) */
    uint16_t learned;     /* [slow] learning ticks so far (saturates) */
    uint8_t hold;         /* [slow] ticks left without learning */
} foc_gain_balance_t;

/* Gh zero (foc_init). */
void foc_gb_init(foc_gain_balance_t *gb);

/* The means restart at `v` and `i` (RUN's first tick). */
void foc_gb_follow(foc_gain_balance_t *gb, foc_dq_t v, foc_dq_t i);

/* One slow tick in RUN: `theta` the angle of the last period's Park, `v`
 * its voltage command, `i` its current, `speed` the frame's speed. */
void foc_gb_tick(foc_gain_balance_t *gb, uint16_t theta, foc_dq_t v, foc_dq_t i, q15_t speed);

/* The measured stator current with the learned mismatch taken out:
 * i - Gh conj(i), saturated.  |Gh| <= 1/8, so each product sum stays
 * below 2^28. */
static inline foc_ab_t foc_gb_correct(const foc_gain_balance_t *gb, foc_ab_t i)
{
    const int32_t gr = gb->g_re;
    const int32_t gi = gb->g_im;
    const int32_t a = i.alpha;
    const int32_t b = i.beta;
    foc_ab_t out;
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    out.alpha = foc_sat_q15(a - ((gr * a + gi * b + 0x4000) >> 15));
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    out.beta = foc_sat_q15(b - ((gi * a - gr * b + 0x4000) >> 15));
    return out;
}

#endif /* FOC_GAIN_BALANCE_H */
