/*
 * PMSM + inverter + DC bus + current-sense model.  The equations and
 * conventions are in pmsm_model.h; this file adds the numerical choices.
 *
 * State vector integrated by RK4: rotor-frame currents, mechanical speed,
 * electrical angle (unwrapped within a period), bus voltage, and the time
 * integrals of the winding voltages (for the period-average vd/vq report).
 * Within one PWM period the phase-to-DC-minus voltages are fixed in the
 * stator frame; the derivative evaluation turns them into the rotor frame
 * with the angle at that instant.
 *
 * Discontinuities (diode commutation, dead-time polarity, dry friction) are
 * kept out of the RK4 right-hand side: a discrete mode is fixed at the start
 * of each substep.  Mode changes inside a substep are located by linear
 * interpolation of a guard quantity between the ends of a trial step:
 * diode turn-off (a conducting current reaching zero), diode turn-on (a
 * floating terminal reaching a rail, or the back-EMF spread reaching Vdc),
 * the rotor stopping (speed reaching zero) and break-away (torque reaching
 * dry friction).  The substep is integrated up to the crossing, a current
 * or speed that reached zero is set to exactly zero, the new mode taken
 * and the rest of the substep integrated.  The dead-time error is a
 * continuous function of each phase current (deadtime_fraction: full
 * outside the PWM-ripple band, proportional inside it, as the average over
 * a period of a rippling current is).  Dead time only shortens a pulse
 * that exists: the effective duty stays within [0, 1].
 *
 * Bridge off (all switches open): each phase is in one of three states:
 * lower diode on (i > 0, terminal at 0 V), upper diode on (i < 0, terminal
 * at Vdc) or blocked (i = 0, terminal floating).  With one phase blocked the
 * two others carry opposite currents and the floating terminal voltage is
 * the Lagrange multiplier that keeps the blocked current at zero; when it
 * leaves [0, Vdc] that phase's diode starts conducting (RK4 keeps the
 * rotating constraint only to truncation error, so the blocked current is
 * projected back to zero after each step).  With all phases blocked the
 * currents stay exactly zero until the spread of the phase back-EMFs (the
 * line-line EMF) exceeds Vdc; then the phases with the highest and lowest
 * EMF start conducting.  Diodes are ideal (no forward drop).
 *
 * DC bus with capacitance: the source feeds the capacitor through an ideal
 * diode and a small resistance (SOURCE_R_OHM, raised to 2 substeps / C for
 * small capacitors so that the explicit integration stays stable and
 * accurate).  The inverter's bus current is sum(d_x * i_x) with the
 * dead-time corrected duties (lossless switches), the upper-diode currents
 * with the bridge off, and zero with the low sides on.  The bus is not
 * clamped at 0 V (the bridge diodes would do that; irrelevant unless the
 * source is set to 0 with a loaded bus).
 */
#include "pmsm_model.h"

#include <math.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#define PHASES 3
/* The integration's inner functions are inlined into the RK4 step (half
 * of the model's time was calls and moving their arguments). */
#if defined(__GNUC__)
#define MODEL_INLINE static inline __attribute__((always_inline))
#else
#define MODEL_INLINE static inline
#endif
/* The switching bridge's RK4 step, the model's hot spot, also compiled for
 * AVX where the processor has it (picked at load time): the same scalar
 * double operations in three-operand form, without SSE2's register copies.
 * Contraction into FMA stays off (C11 mode), so the results are the same. */
#if defined(__GNUC__) && defined(__x86_64__) && defined(__linux__)
#define MODEL_CLONES __attribute__((target_clones("avx", "default")))
#else
#define MODEL_CLONES
#endif
/* Bound on located mode changes per substep (a few are physically
 * possible: diode commutations and a rotor stop).  Beyond it the rest of
 * the substep is integrated without event location. */
#define MAX_EVENTS_PER_SUBSTEP 8

static const double PI = 3.14159265358979323846;
static const double SQRT3 = 1.73205080756887729353;

/* Source-to-bus connection: a bench supply with short leads. */
static const double SOURCE_R_OHM = 0.05;
/* A phase current within this of zero counts as not conducting; after a
 * located diode turn-off the current is exactly zero, so this only absorbs
 * rounding. */
static const double PHASE_ZERO_A = 1e-9;
/* xorshift32 has the fixed point 0; seed 0 uses this instead. */
static const uint32_t SEED_FOR_ZERO = 0x9E3779B9u;

/* Stator axis of each phase: A at 0, B at +120, C at -120 electrical deg. */
static const double PHASE_COS[PHASES] = { 1.0, -0.5, -0.5 };
static const double PHASE_SIN[PHASES] = { 0.0, 0.86602540378443864676,
                                          -0.86602540378443864676 };

enum { X_ID, X_IQ, X_WM, X_THETA, X_VDC, X_VD_INT, X_VQ_INT, X_COUNT };

/* Rotation by a small angle d: cos(d) and sin(d) by their Taylor series up
 * to d^10 / d^11, exact to rounding (the next terms are below 4e-20) for
 * |d| <= SMALL_ANGLE_RAD.  Beyond it the angle is evaluated directly. */
static const double SMALL_ANGLE_RAD = 0.125;
/* A new reference angle is taken at a substep's start once the angle has
 * moved this far from the present one (a substep moves it by at most
 * 0.04 rad at 3000 rad/s electrical, 20 kHz, 4 substeps). */
static const double REBASE_ANGLE_RAD = 0.0625;

/* What one period's integration evaluates often: the model, reciprocals of
 * the parameters it divides by, and a reference angle with its cosine and
 * sine, from which the angles of the RK4 stages are reached by a small
 * rotation (sin/cos of the state angle was most of the model's time). */
typedef struct {
    const pmsm_model_t *m;
    const double *duty;        /* the bridge legs' duties: m->duty, or a */
                               /* switched segment's 0/1 states */
    double rs;                 /* winding resistance at its present */
                               /* temperature, ohm */
    double inv_ld, inv_lq;     /* 1/H (unsaturated) */
    int saturates;             /* ld_sat_a or lq_sat_a set */
    double band_per_v;         /* dead-time ripple band per bus volt, A/V */
    double dt_frac;            /* t_dead * f_pwm */
    double inv_j;              /* 1/kg m^2 */
    double inv_cap;            /* 1/F (bus capacitor, if any) */
    double inv_source_r;       /* 1/ohm (source to bus capacitor) */
    double theta0, c0, s0;     /* reference angle, cos, sin */
} integ_t;

/* Duty a phase loses to the dead time, signed by its current.  The phase
 * current carries PWM ripple, so within the ripple band it crosses zero
 * during the period and the average loss fades in proportionally; outside
 * it the loss is the full t_dead x f_pwm.  Band half-width: half the
 * peak-to-peak ripple at 50 % duty with 2/3 of the bus across the winding,
 * (2/3) Vdc / (8 L f_pwm) (0.052 A for the Hurst075 at 24 V, 20 kHz). */
/* v > hi ? hi : (v < lo ? lo : v), NaN passed through, without branches
 * where SSE2 is there: MINSD/MAXSD return their second operand when the
 * comparison fails, which is exactly the conditional's result. */
MODEL_INLINE double clamp_to(double v, double lo, double hi)
{
#if defined(__SSE2__)
    const __m128d upper = _mm_min_sd(_mm_set_sd(hi), _mm_set_sd(v)); /* hi < v ? hi : v */
    return _mm_cvtsd_f64(_mm_max_sd(_mm_set_sd(lo), upper));        /* lo > u ? lo : u */
#else
    const double upper = v > hi ? hi : v;
    return upper < lo ? lo : upper;
#endif
}

MODEL_INLINE double deadtime_fraction(const integ_t *c, double inv_band, double i)
{
    const double ratio = inv_band > 0.0 ? i * inv_band : (i > 0.0) - (i < 0.0);
    /* dt_frac * clamp(ratio, -1, 1), with branches on purpose: outside the
     * band (nearly always) the result does not wait for the current, so an
     * RK4 stage's chain of dependent operations is short (dt_frac * +-1 is
     * exact: the same values) */
    if (ratio > 1.0) {
        return c->dt_frac;
    }
    if (ratio < -1.0) {
        return -c->dt_frac;
    }
    return c->dt_frac * ratio;
}

/* 1 / band for the bus voltage vdc (0 when the band is 0 or undefined). */
MODEL_INLINE double deadtime_inv_band(const integ_t *c, double vdc)
{
    const double band = c->band_per_v * vdc;
    return band > 0.0 ? 1.0 / band : 0.0;
}

/* Discrete state held constant over one integration interval. */
typedef struct {
    /* bridge off: +1 lower diode on (i > 0, 0 V), -1 upper diode on
     * (i < 0, Vdc), 0 blocked (i = 0, floating) */
    int diode[PHASES];
    /* free rotor: direction of motion +1/-1, 0 stuck (stiction) */
    int motion;
} discrete_mode_t;

/* Unit vectors of the phase axes seen from the rotor frame; the phase
 * current is i_x = id * d[x] + iq * q[x] (amplitude-invariant Park). */
typedef struct {
    double d[PHASES];
    double q[PHASES];
} phase_axes_t;

typedef struct {
    double ud_v, uq_v;          /* winding voltages, rotor frame */
    double did_dt, diq_dt;      /* A/s */
    double bus_current_a;       /* drawn by the inverter from the bus */
    double float_v;             /* terminal voltage of the one blocked phase */
} electrical_t;

static int sign_of(double v)
{
    return (v > 0.0) - (v < 0.0);
}

static phase_axes_t axes_from(double c, double s)
{
    phase_axes_t ax;
    for (int x = 0; x < PHASES; x++) {
        /* axis angle phi_x - theta: cos(phi - th), sin(phi - th) */
        ax.d[x] = PHASE_COS[x] * c + PHASE_SIN[x] * s;
        ax.q[x] = PHASE_SIN[x] * c - PHASE_COS[x] * s;
    }
    return ax;
}

static phase_axes_t phase_axes(double theta_e_rad)
{
    return axes_from(cos(theta_e_rad), sin(theta_e_rad));
}

static void integ_rebase(integ_t *c, double theta_e_rad)
{
    c->theta0 = theta_e_rad;
    c->c0 = cos(theta_e_rad);
    c->s0 = sin(theta_e_rad);
}

static double source_r_ohm(const pmsm_model_t *m)
{
    const double substep_s = 1.0 / (m->p.pwm_hz * m->p.substeps);
    const double r_min_ohm = 2.0 * substep_s / m->p.bus_cap_f;
    return SOURCE_R_OHM > r_min_ohm ? SOURCE_R_OHM : r_min_ohm;
}

/* cos and sin of the state's angle at the start of a period, computed
 * once for pmsm_sample and pmsm_step_period (and the host's probes). */
static void start_cos_sin(pmsm_model_t *m, double *co, double *si)
{
    if (!m->trig_valid || m->trig_theta != m->s.theta_e_rad) {
        m->trig_theta = m->s.theta_e_rad;
        m->trig_cos = cos(m->trig_theta);
        m->trig_sin = sin(m->trig_theta);
        m->trig_valid = 1;
    }
    *co = m->trig_cos;
    *si = m->trig_sin;
}

void pmsm_cos_sin(pmsm_model_t *m, double *cos_theta, double *sin_theta)
{
    start_cos_sin(m, cos_theta, sin_theta);
}

/* Winding resistance at its temperature rise: copper's resistance grows
 * by rs_tempco_per_k per kelvin (0.0039/K near 20 C: IEC 60228's
 * 0.00393). */
static double winding_rs_ohm(const pmsm_model_t *m)
{
    return m->p.rs_ohm * (1.0 + m->p.rs_tempco_per_k * m->winding_rise_k);
}

double pmsm_rs_ohm(const pmsm_model_t *m)
{
    return winding_rs_ohm(m);
}

static void integ_init(integ_t *c, pmsm_model_t *m, double theta_e_rad)
{
    const pmsm_params_t *p = &m->p;
    const double l_h = 0.5 * (p->ld_h + p->lq_h);
    c->m = m;
    c->duty = m->duty;
    c->rs = winding_rs_ohm(m);
    c->inv_ld = 1.0 / p->ld_h;
    c->inv_lq = 1.0 / p->lq_h;
    c->saturates = p->ld_sat_a > 0.0 || p->lq_sat_a > 0.0;
    c->band_per_v = (2.0 / 3.0) / (8.0 * l_h * p->pwm_hz);
    /* the switched bridge has its dead time in the segments' states */
    c->dt_frac = p->switched ? 0.0 : p->deadtime_s * p->pwm_hz;
    c->inv_j = 1.0 / p->j_kgm2;
    c->inv_cap = p->bus_cap_f > 0.0 ? 1.0 / p->bus_cap_f : 0.0;
    c->inv_source_r = p->bus_cap_f > 0.0 ? 1.0 / source_r_ohm(m) : 0.0;
    if (theta_e_rad == m->s.theta_e_rad) {
        c->theta0 = theta_e_rad;
        start_cos_sin(m, &c->c0, &c->s0);
    } else {
        integ_rebase(c, theta_e_rad);
    }
}

MODEL_INLINE void small_rotation(double d, double *cd, double *sd)
{
    const double d2 = d * d;
    *cd = 1.0 + d2 * (-1.0 / 2 + d2 * (1.0 / 24 + d2 * (-1.0 / 720 + d2 * (1.0 / 40320 +
               d2 * (-1.0 / 3628800)))));
    *sd = d * (1.0 + d2 * (-1.0 / 6 + d2 * (1.0 / 120 + d2 * (-1.0 / 5040 +
               d2 * (1.0 / 362880 + d2 * (-1.0 / 39916800))))));
}

/* phase_axes(theta) through the reference angle of c. */
static phase_axes_t integ_axes(const integ_t *c, double theta_e_rad)
{
    const double d = theta_e_rad - c->theta0;
    if (fabs(d) > SMALL_ANGLE_RAD) {
        return phase_axes(theta_e_rad);
    }
    double cd;
    double sd;
    small_rotation(d, &cd, &sd);
    return axes_from(c->c0 * cd - c->s0 * sd, c->s0 * cd + c->c0 * sd);
}

/* cos and sin of theta through the reference angle of c. */
MODEL_INLINE void integ_cos_sin(const integ_t *c, double theta_e_rad, double *cos_th,
                          double *sin_th)
{
    const double d = theta_e_rad - c->theta0;
    if (fabs(d) > SMALL_ANGLE_RAD) {
        *cos_th = cos(theta_e_rad);
        *sin_th = sin(theta_e_rad);
        return;
    }
    double cd;
    double sd;
    small_rotation(d, &cd, &sd);
    *cos_th = c->c0 * cd - c->s0 * sd;
    *sin_th = c->s0 * cd + c->c0 * sd;
}

static void phase_currents(const phase_axes_t *ax, double id_a, double iq_a,
                           double i_a[PHASES])
{
    for (int x = 0; x < PHASES; x++) {
        i_a[x] = id_a * ax->d[x] + iq_a * ax->q[x];
    }
}

MODEL_INLINE double clamp01(double v)
{
    return clamp_to(v, 0.0, 1.0);
}

MODEL_INLINE double friction_nm(const pmsm_model_t *m)
{
    return m->p.coulomb_nm + m->load_nm;
}

/* Magnetic saturation of one axis (d or q), without cross-saturation:
 * the incremental inductance dpsi/di falls with the axis current,
 *   L(i) = L0 / (1 + (i / i_sat)^2)            (i_sat = 0: L0, linear),
 * a Lorentzian fit of the measured L(i) shape (Lq at 2 x i_sat is L0 / 5),
 * so the axis flux linkage, its integral, is
 *   psi(i) = L0 i_sat atan(i / i_sat)          (V s; L0 i when linear)
 * and the apparent inductance psi / i = L0 atan(x) / x, x = i / i_sat.
 * The voltage equations use the incremental inductance for di/dt and the
 * flux linkage for the rotational EMF and the torque: psi_d depends on id
 * only and psi_q on iq only, so the field is conservative and the torque
 * 1.5 p (psi_d iq - psi_q id) (with the magnet's share) balances the
 * stored energy exactly. */
MODEL_INLINE double axis_flux(double l0_h, double i_sat_a, double i_a)
{
    return i_sat_a > 0.0 ? l0_h * i_sat_a * atan(i_a / i_sat_a) : l0_h * i_a;
}

MODEL_INLINE double axis_inductance(double l0_h, double i_sat_a, double i_a)
{
    if (!(i_sat_a > 0.0)) {
        return l0_h;
    }
    const double x = i_a / i_sat_a;
    return l0_h / (1.0 + x * x);
}

/* The windings' (reluctance) share of the torque over 1.5 p:
 * psi_d(id) iq - psi_q(iq) id, which is (Ld - Lq) id iq when linear. */
MODEL_INLINE double winding_torque_term(const pmsm_params_t *p, double id_a, double iq_a)
{
    if (!(p->ld_sat_a > 0.0) && !(p->lq_sat_a > 0.0)) {
        return (p->ld_h - p->lq_h) * id_a * iq_a;
    }
    return axis_flux(p->ld_h, p->ld_sat_a, id_a) * iq_a -
           axis_flux(p->lq_h, p->lq_sat_a, iq_a) * id_a;
}

/* The magnet's back-EMF per unit electrical speed in the rotor frame,
 * V s/rad (e_dq = we (kd, kq)).  With 5th and 7th harmonics of h5 and h7
 * of the fundamental in each phase's EMF,
 *   e_a = -we flux (sin th + h5 sin 5th + h7 sin 7th),
 * the 5th (negative sequence) and 7th (positive) both turn at 6 we in the
 * rotor frame: kd = -flux (h5 + h7) sin 6th, kq = flux (1 + (h7 - h5)
 * cos 6th).  The magnet's torque is 1.5 p (kd id + kq iq) (power balance
 * e.i = Te wm), so the harmonics' torque ripple follows from the same
 * numbers. */
MODEL_INLINE void magnet_emf_per_speed(const pmsm_params_t *p, double co, double si,
                                       double *kd, double *kq)
{
    if (p->emf_h5 == 0.0 && p->emf_h7 == 0.0) {
        *kd = 0.0;
        *kq = p->flux_wb;
        return;
    }
    /* cos 6th + j sin 6th = (co + j si)^6 */
    const double c2 = co * co - si * si;
    const double s2 = 2.0 * co * si;
    const double c3 = c2 * co - s2 * si;
    const double s3 = s2 * co + c2 * si;
    const double c6 = c3 * c3 - s3 * s3;
    const double s6 = 2.0 * c3 * s3;
    *kd = -p->flux_wb * (p->emf_h5 + p->emf_h7) * s6;
    *kq = p->flux_wb * (1.0 + (p->emf_h7 - p->emf_h5) * c6);
}

/* Cogging torque, N m: -cogging_nm sin(N th_m), N = cogging_periods per
 * mechanical turn.  N is a multiple of the pole count for any slot count
 * (LCM(slots, poles)), so it is a function of the electrical angle,
 * sin((N / p) th_e), with N / p rounded to a whole number; detents at
 * th_e = 0. */
MODEL_INLINE double cogging_torque_nm(const pmsm_params_t *p, double theta_e_rad)
{
    if (p->cogging_nm == 0.0) {
        return 0.0;
    }
    const double per_electrical = round((double)p->cogging_periods / p->pole_pairs);
    return -p->cogging_nm * sin(per_electrical * theta_e_rad);
}

/* Torque on the rotor at electrical angle th (cos and sin given), N m. */
MODEL_INLINE double rotor_torque(const pmsm_params_t *p, double id_a, double iq_a,
                                 double theta_e_rad, double co, double si)
{
    double kd;
    double kq;
    magnet_emf_per_speed(p, co, si, &kd, &kq);
    return 1.5 * p->pole_pairs * (kq * iq_a + kd * id_a + winding_torque_term(p, id_a, iq_a)) +
           cogging_torque_nm(p, theta_e_rad);
}

double pmsm_torque(const pmsm_params_t *p, double id_a, double iq_a, double theta_e_rad)
{
    return rotor_torque(p, id_a, iq_a, theta_e_rad, cos(theta_e_rad), sin(theta_e_rad));
}

/* Torque at state x (cos and sin through c's reference angle). */
static double state_torque(const integ_t *c, const double x[X_COUNT])
{
    double co;
    double si;
    integ_cos_sin(c, x[X_THETA], &co, &si);
    return rotor_torque(&c->m->p, x[X_ID], x[X_IQ], x[X_THETA], co, si);
}

/* The switching bridge in the stator frame, shared by electrical_pwm()
 * and the RK4 kernel deriv_pwm_s(): the phase currents from the dq
 * current, the duties less the dead-time loss of each, the winding voltage
 * (the rotated alpha/beta voltage: Clarke drops the floating star point's
 * common mode), the current derivatives and the bus current. */
typedef struct {
    double ud_v, uq_v, did_dt, diq_dt, bus_current_a;
} pwm_winding_t;

MODEL_INLINE pwm_winding_t pwm_winding(const integ_t *c, const double duty[PHASES],
                                       double inv_band, double vdc, double co, double si,
                                       double id, double iq, double we, double rs, double ld,
                                       double lq, double kd, double kq)
{
    const double i_alpha = id * co - iq * si;
    const double i_beta = id * si + iq * co;
    const double half_sqrt3 = 0.5 * SQRT3;
    const double i0 = i_alpha;
    const double i1 = -0.5 * i_alpha + half_sqrt3 * i_beta;
    const double i2 = -0.5 * i_alpha - half_sqrt3 * i_beta;
    const double d0 = clamp01(duty[0] - deadtime_fraction(c, inv_band, i0));
    const double d1 = clamp01(duty[1] - deadtime_fraction(c, inv_band, i1));
    const double d2 = clamp01(duty[2] - deadtime_fraction(c, inv_band, i2));
    const double v0 = vdc * d0;
    const double v1 = vdc * d1;
    const double v2 = vdc * d2;
    const double v_alpha = (2.0 / 3.0) * (v0 - 0.5 * (v1 + v2));
    const double v_beta = (1.0 / SQRT3) * (v1 - v2);
    pwm_winding_t w;
    w.ud_v = v_alpha * co + v_beta * si;
    w.uq_v = -v_alpha * si + v_beta * co;
    /* winding voltage that would hold the currents constant */
    const pmsm_params_t *p = &c->m->p;
    const double we_psi_q = c->saturates ? we * axis_flux(lq, p->lq_sat_a, iq) : we * lq * iq;
    const double psi_d = c->saturates ? axis_flux(ld, p->ld_sat_a, id) : ld * id;
    const double hold_d = rs * id - we_psi_q + we * kd;
    const double hold_q = rs * iq + we * (psi_d + kq);
    const double inv_ld = c->saturates ? 1.0 / axis_inductance(ld, p->ld_sat_a, id) : c->inv_ld;
    const double inv_lq = c->saturates ? 1.0 / axis_inductance(lq, p->lq_sat_a, iq) : c->inv_lq;
    w.did_dt = (w.ud_v - hold_d) * inv_ld;
    w.diq_dt = (w.uq_v - hold_q) * inv_lq;
    w.bus_current_a = 0.0;
    w.bus_current_a += d0 * i0;
    w.bus_current_a += d1 * i1;
    w.bus_current_a += d2 * i2;
    return w;
}

/* electrical() with the bridge switching: the same equations through the
 * stator frame (the phase currents from i_alpha/i_beta, the winding
 * voltage as the rotated alpha/beta voltage), which needs a fraction of the
 * arithmetic of the per-phase axes. */
MODEL_INLINE electrical_t electrical_pwm(const integ_t *c, const double x[X_COUNT])
{
    const pmsm_model_t *m = c->m;
    const pmsm_params_t *p = &m->p;
    const double id = x[X_ID];
    const double iq = x[X_IQ];
    const double we = p->pole_pairs * x[X_WM];
    const double vdc = x[X_VDC];
    double co;
    double si;
    integ_cos_sin(c, x[X_THETA], &co, &si);
    double kd;
    double kq;
    magnet_emf_per_speed(p, co, si, &kd, &kq);
    const pwm_winding_t w = pwm_winding(c, c->duty, deadtime_inv_band(c, vdc), vdc, co, si, id,
                                        iq, we, c->rs, p->ld_h, p->lq_h, kd, kq);
    electrical_t e = { 0 };
    e.ud_v = w.ud_v;
    e.uq_v = w.uq_v;
    e.did_dt = w.did_dt;
    e.diq_dt = w.diq_dt;
    e.bus_current_a = w.bus_current_a;
    return e;
}

/* Winding voltages and current derivatives for the given mode and state. */
static electrical_t electrical(const integ_t *c, const discrete_mode_t *dm,
                               const double x[X_COUNT])
{
    const pmsm_model_t *m = c->m;
    if (m->bridge == PMSM_BRIDGE_PWM) {
        return electrical_pwm(c, x);
    }
    const pmsm_params_t *p = &m->p;
    const double id = x[X_ID];
    const double iq = x[X_IQ];
    const double we = p->pole_pairs * x[X_WM];
    const double vdc = x[X_VDC];
    double co;
    double si;
    integ_cos_sin(c, x[X_THETA], &co, &si);
    double kd;
    double kq;
    magnet_emf_per_speed(p, co, si, &kd, &kq);
    /* winding voltage that would hold the currents constant */
    const double we_psi_q =
        c->saturates ? we * axis_flux(p->lq_h, p->lq_sat_a, iq) : we * p->lq_h * iq;
    const double psi_d = c->saturates ? axis_flux(p->ld_h, p->ld_sat_a, id) : p->ld_h * id;
    const double hold_d = c->rs * id - we_psi_q + we * kd;
    const double hold_q = c->rs * iq + we * (psi_d + kq);
    const double ld = axis_inductance(p->ld_h, p->ld_sat_a, id);
    const double lq = axis_inductance(p->lq_h, p->lq_sat_a, iq);
    if (m->bridge == PMSM_BRIDGE_OFF && dm->diode[0] == 0 && dm->diode[1] == 0 &&
        dm->diode[2] == 0) {
        /* every phase blocked: what the general case below gives, without
         * the phase axes it does not use then */
        electrical_t e = { 0 };
        e.ud_v = hold_d;
        e.uq_v = hold_q;
        return e;
    }
    const phase_axes_t ax = axes_from(co, si);
    double i_ph[PHASES];
    phase_currents(&ax, id, iq, i_ph);

    electrical_t e = { 0 };
    int blocked = -1;
    int n_blocked = 0;
    for (int ph = 0; ph < PHASES; ph++) {
        double v_terminal = 0.0;
        if (m->bridge == PMSM_BRIDGE_OFF) {
            if (dm->diode[ph] == 0) {
                blocked = ph;
                n_blocked++;
                continue;
            }
            if (dm->diode[ph] < 0) {
                v_terminal = vdc;
                e.bus_current_a += i_ph[ph];
            }
        }
        /* amplitude-invariant Clarke of the terminal voltages drops the
         * common mode, i.e. the floating star point */
        e.ud_v += 2.0 / 3.0 * v_terminal * ax.d[ph];
        e.uq_v += 2.0 / 3.0 * v_terminal * ax.q[ph];
    }

    if (n_blocked >= 2) {
        /* no path for current: it stays at zero, windings see the EMF */
        e.ud_v = hold_d;
        e.uq_v = hold_q;
        return e;
    }
    double gd = e.ud_v - hold_d;
    double gq = e.uq_v - hold_q;
    if (n_blocked == 1) {
        /* The floating terminal adds mu * axis to the winding voltage, mu
         * chosen so that d/dt (i . axis) = 0 (the axis turns at -we in the
         * rotor frame). */
        const double ad = ax.d[blocked];
        const double aq = ax.q[blocked];
        const double mu = -(ad * gd / ld + aq * gq / lq +
                            we * (aq * id - ad * iq)) /
                          (ad * ad / ld + aq * aq / lq);
        e.ud_v += mu * ad;
        e.uq_v += mu * aq;
        gd += mu * ad;
        gq += mu * aq;
        e.float_v = 1.5 * mu;
    }
    e.did_dt = c->saturates ? gd / ld : gd * c->inv_ld;
    e.diq_dt = c->saturates ? gq / lq : gq * c->inv_lq;
    return e;
}

/* pwm: the bridge is switching (a constant where inlined, so that the
 * switching case is compiled on its own). */
MODEL_INLINE void derivative(const integ_t *c, const discrete_mode_t *dm,
                             const double x[X_COUNT], double dx[X_COUNT],
                             const int pwm)
{
    const pmsm_model_t *m = c->m;
    const pmsm_params_t *p = &m->p;
    const electrical_t e = pwm ? electrical_pwm(c, x) : electrical(c, dm, x);
    dx[X_ID] = e.did_dt;
    dx[X_IQ] = e.diq_dt;
    dx[X_WM] = 0.0;
    dx[X_THETA] = 0.0;
    if (m->rotor != PMSM_ROTOR_LOCKED) {
        dx[X_THETA] = p->pole_pairs * x[X_WM];
    }
    if (m->rotor == PMSM_ROTOR_FREE && dm->motion != 0) {
        const double te = state_torque(c, x);
        dx[X_WM] = (te - p->b_nm_per_rad_s * x[X_WM] -
                    friction_nm(m) * dm->motion) * c->inv_j;
    }
    dx[X_VDC] = 0.0;
    if (p->bus_cap_f > 0.0) {
        const double vdc = x[X_VDC];
        const double i_source = fmax(0.0, (p->vdc_source_v - vdc) *
                                          c->inv_source_r);
        const double i_brake = m->brake_resistor_on ? vdc / p->brake_r_ohm
                                                    : 0.0;
        dx[X_VDC] = (i_source - e.bus_current_a - i_brake) * c->inv_cap;
    }
    dx[X_VD_INT] = e.ud_v;
    dx[X_VQ_INT] = e.uq_v;
}

MODEL_INLINE void rk4_step(const integ_t *c, const discrete_mode_t *dm,
                           const double x[X_COUNT], double h, double out[X_COUNT],
                           const int pwm)
{
    double k1[X_COUNT], k2[X_COUNT], k3[X_COUNT], k4[X_COUNT], tmp[X_COUNT];
    derivative(c, dm, x, k1, pwm);
    for (int n = 0; n < X_COUNT; n++) tmp[n] = x[n] + 0.5 * h * k1[n];
    derivative(c, dm, tmp, k2, pwm);
    for (int n = 0; n < X_COUNT; n++) tmp[n] = x[n] + 0.5 * h * k2[n];
    derivative(c, dm, tmp, k3, pwm);
    for (int n = 0; n < X_COUNT; n++) tmp[n] = x[n] + h * k3[n];
    derivative(c, dm, tmp, k4, pwm);
    for (int n = 0; n < X_COUNT; n++) {
        out[n] = x[n] + h / 6.0 * (k1[n] + 2.0 * k2[n] + 2.0 * k3[n] + k4[n]);
    }
}

/* The switching bridge's derivative (derivative() with pwm = 1, the same
 * operations in the same order) with everything that is constant over an
 * RK4 step loaded once: this case is nearly all of a simulation's time. */
typedef struct {
    const integ_t *c;
    double duty[PHASES];
    double rs, ld, lq, pp, b, inv_j, fric_motion, torque_k;
    double inv_band;      /* stiff bus: for the step's (constant) voltage */
    int stiff_bus;
    int theta_moves;      /* rotor not locked */
    int wm_moves;         /* free rotor in motion */
    const pmsm_params_t *p;
    const pmsm_model_t *m;
} pwm_step_t;

/* The switching bridge's derivative: derivative() with pwm = 1, the same
 * operations in the same order, on scalars so that an RK4 step keeps its
 * state in registers. */
typedef struct {
    double id, iq, wm, th, vdc, vd, vq;
} pwm_dx_t;

MODEL_INLINE pwm_dx_t deriv_pwm_s(const pwm_step_t *k, double id, double iq, double wm,
                                  double th, double vdc)
{
    const integ_t *c = k->c;
    const double we = k->pp * wm;
    double co;
    double si;
    integ_cos_sin(c, th, &co, &si);
    const double inv_band = k->stiff_bus ? k->inv_band : deadtime_inv_band(c, vdc);
    double kd;
    double kq;
    magnet_emf_per_speed(k->p, co, si, &kd, &kq);
    const pwm_winding_t w =
        pwm_winding(c, k->duty, inv_band, vdc, co, si, id, iq, we, k->rs, k->ld, k->lq, kd, kq);
    pwm_dx_t dx;
    dx.vd = w.ud_v;
    dx.vq = w.uq_v;
    dx.id = w.did_dt;
    dx.iq = w.diq_dt;
    dx.th = k->theta_moves ? k->pp * wm : 0.0;
    dx.wm = 0.0;
    if (k->wm_moves) {
        const double te = k->torque_k * (kq * iq + kd * id + winding_torque_term(k->p, id, iq)) +
                          cogging_torque_nm(k->p, th);
        dx.wm = (te - k->b * wm - k->fric_motion) * c->inv_j;
    }
    dx.vdc = 0.0;
    if (!k->stiff_bus) {
        const pmsm_params_t *p = k->p;
        const double i_source = fmax(0.0, (p->vdc_source_v - vdc) * c->inv_source_r);
        const double i_brake = k->m->brake_resistor_on ? vdc / p->brake_r_ohm : 0.0;
        dx.vdc = (i_source - w.bus_current_a - i_brake) * c->inv_cap;
    }
    return dx;
}

MODEL_CLONES
static void rk4_pwm(const integ_t *c, const discrete_mode_t *dm,
                    const double x[X_COUNT], double h, double out[X_COUNT])
{
    const pmsm_model_t *m = c->m;
    const pmsm_params_t *p = &m->p;
    pwm_step_t k;
    k.c = c;
    k.m = m;
    k.p = p;
    for (int ph = 0; ph < PHASES; ph++) {
        k.duty[ph] = c->duty[ph];
    }
    k.rs = c->rs;
    k.ld = p->ld_h;
    k.lq = p->lq_h;
    k.pp = p->pole_pairs;
    k.b = p->b_nm_per_rad_s;
    k.inv_j = c->inv_j;
    k.fric_motion = friction_nm(m) * dm->motion;
    k.torque_k = 1.5 * p->pole_pairs;
    k.stiff_bus = !(p->bus_cap_f > 0.0);
    k.inv_band = deadtime_inv_band(c, x[X_VDC]);
    k.theta_moves = m->rotor != PMSM_ROTOR_LOCKED;
    k.wm_moves = m->rotor == PMSM_ROTOR_FREE && dm->motion != 0;
    const double hh = 0.5 * h;
    const double x_id = x[X_ID], x_iq = x[X_IQ], x_wm = x[X_WM], x_th = x[X_THETA],
                 x_vdc = x[X_VDC];
    const pwm_dx_t k1 = deriv_pwm_s(&k, x_id, x_iq, x_wm, x_th, x_vdc);
    const pwm_dx_t k2 = deriv_pwm_s(&k, x_id + hh * k1.id, x_iq + hh * k1.iq,
                                    x_wm + hh * k1.wm, x_th + hh * k1.th, x_vdc + hh * k1.vdc);
    const pwm_dx_t k3 = deriv_pwm_s(&k, x_id + hh * k2.id, x_iq + hh * k2.iq,
                                    x_wm + hh * k2.wm, x_th + hh * k2.th, x_vdc + hh * k2.vdc);
    const pwm_dx_t k4 = deriv_pwm_s(&k, x_id + h * k3.id, x_iq + h * k3.iq,
                                    x_wm + h * k3.wm, x_th + h * k3.th, x_vdc + h * k3.vdc);
    const double h6 = h / 6.0;
    out[X_ID] = x_id + h6 * (k1.id + 2.0 * k2.id + 2.0 * k3.id + k4.id);
    out[X_IQ] = x_iq + h6 * (k1.iq + 2.0 * k2.iq + 2.0 * k3.iq + k4.iq);
    out[X_WM] = x_wm + h6 * (k1.wm + 2.0 * k2.wm + 2.0 * k3.wm + k4.wm);
    out[X_THETA] = x_th + h6 * (k1.th + 2.0 * k2.th + 2.0 * k3.th + k4.th);
    out[X_VDC] = x_vdc + h6 * (k1.vdc + 2.0 * k2.vdc + 2.0 * k3.vdc + k4.vdc);
    out[X_VD_INT] = x[X_VD_INT] + h6 * (k1.vd + 2.0 * k2.vd + 2.0 * k3.vd + k4.vd);
    out[X_VQ_INT] = x[X_VQ_INT] + h6 * (k1.vq + 2.0 * k2.vq + 2.0 * k3.vq + k4.vq);
}

static void rk4(const integ_t *c, const discrete_mode_t *dm,
                const double x[X_COUNT], double h, double out[X_COUNT])
{
    if (c->m->bridge == PMSM_BRIDGE_PWM) {
        rk4_pwm(c, dm, x, h, out);
    } else {
        rk4_step(c, dm, x, h, out, 0);
    }
}

/* Guards: quantities that stay positive while a discrete mode holds.  Per
 * phase (bridge off): a conducting phase's current, signed by its diode;
 * the margin of the one blocked phase's floating terminal voltage to the
 * rails.  All phases blocked: the margin of Vdc over the back-EMF spread.
 * Free rotor: the speed signed by the direction of motion, or at rest the
 * margin of dry friction over the torque. */
enum { GUARD_ALL_BLOCKED = PHASES, GUARD_ROTOR, GUARD_COUNT };

/* Forced transition when a guard has been reached (located by
 * interpolation, so the state is only approximately at the boundary). */
enum { FORCE_NONE = -1 };

/* Spread of the phase back-EMFs (the largest line-line EMF) at zero
 * current, and the phases with the highest and lowest EMF. */
static double emf_spread_v(const integ_t *c, const double x[X_COUNT],
                           int *hi, int *lo)
{
    const pmsm_model_t *m = c->m;
    const double we = m->p.pole_pairs * x[X_WM];
    *hi = 0;
    *lo = 0;
    if (we == 0.0) {
        return 0.0; /* rotor at rest: what the loop below gives, sooner */
    }
    double co;
    double si;
    integ_cos_sin(c, x[X_THETA], &co, &si);
    double kd;
    double kq;
    magnet_emf_per_speed(&m->p, co, si, &kd, &kq);
    const phase_axes_t ax = axes_from(co, si);
    double emf_v[PHASES];
    for (int ph = 0; ph < PHASES; ph++) {
        emf_v[ph] = we * kq * ax.q[ph] + we * kd * ax.d[ph];
        *hi = emf_v[ph] > emf_v[*hi] ? ph : *hi;
        *lo = emf_v[ph] < emf_v[*lo] ? ph : *lo;
    }
    return emf_v[*hi] - emf_v[*lo];
}

/* Bridge off: which diodes conduct, from the currents and, for phases at
 * zero current, from the voltage their terminal would float to.  Zeroes
 * the currents when fewer than two phases conduct (rounding residue).
 * force: a guard reached by interpolation whose turn-on is to happen. */
static void decide_diodes(const integ_t *c, double x[X_COUNT],
                          discrete_mode_t *dm, int force)
{
    const phase_axes_t ax = integ_axes(c, x[X_THETA]);
    double i_ph[PHASES];
    phase_currents(&ax, x[X_ID], x[X_IQ], i_ph);
    int n_on = 0;
    for (int ph = 0; ph < PHASES; ph++) {
        dm->diode[ph] = fabs(i_ph[ph]) > PHASE_ZERO_A ? sign_of(i_ph[ph]) : 0;
        n_on += dm->diode[ph] != 0;
    }
    const double vdc = x[X_VDC];
    if (n_on < 2) {
        memset(dm->diode, 0, sizeof dm->diode);
        x[X_ID] = 0.0;
        x[X_IQ] = 0.0;
        int hi;
        int lo;
        if (emf_spread_v(c, x, &hi, &lo) > vdc || force == GUARD_ALL_BLOCKED) {
            dm->diode[hi] = -1; /* current leaves the motor into DC+ */
            dm->diode[lo] = +1; /* and returns from DC- */
        }
    } else if (n_on == 2) {
        const electrical_t e = electrical(c, dm, x);
        for (int ph = 0; ph < PHASES; ph++) {
            if (dm->diode[ph] != 0) {
                continue;
            }
            const int forced = force == ph;
            if (e.float_v > vdc || (forced && e.float_v > 0.5 * vdc)) {
                dm->diode[ph] = -1;
            } else if (e.float_v < 0.0 || forced) {
                dm->diode[ph] = +1;
            }
        }
    }
}

static discrete_mode_t decide_mode(const integ_t *c, double x[X_COUNT],
                                   int force)
{
    const pmsm_model_t *m = c->m;
    discrete_mode_t dm;
    memset(&dm, 0, sizeof dm);
    if (m->bridge == PMSM_BRIDGE_OFF) {
        decide_diodes(c, x, &dm, force);
    }
    if (m->rotor == PMSM_ROTOR_FREE) {
        dm.motion = sign_of(x[X_WM]);
        if (dm.motion == 0) {
            /* at rest: breaks away only if the torque beats dry friction */
            const double te = state_torque(c, x);
            const int breaks_away =
                fabs(te) > friction_nm(m) || force == GUARD_ROTOR;
            dm.motion = breaks_away ? sign_of(te) : 0;
        }
    }
    return dm;
}

static void guards(const integ_t *c, const discrete_mode_t *dm,
                   const double x[X_COUNT], double g[GUARD_COUNT])
{
    const pmsm_model_t *m = c->m;
    memset(g, 0, GUARD_COUNT * sizeof g[0]);
    if (m->bridge == PMSM_BRIDGE_OFF) {
        const int n_on = (dm->diode[0] != 0) + (dm->diode[1] != 0) +
                         (dm->diode[2] != 0);
        const double vdc = x[X_VDC];
        if (n_on == 0) {
            int hi;
            int lo;
            g[GUARD_ALL_BLOCKED] = vdc - emf_spread_v(c, x, &hi, &lo);
        }
        phase_axes_t ax = { { 0.0, 0.0, 0.0 }, { 0.0, 0.0, 0.0 } };
        double i_ph[PHASES] = { 0.0, 0.0, 0.0 };
        if (n_on > 0) {
            ax = integ_axes(c, x[X_THETA]);
            phase_currents(&ax, x[X_ID], x[X_IQ], i_ph);
        }
        for (int ph = 0; ph < PHASES && n_on > 0; ph++) {
            if (dm->diode[ph] != 0) {
                g[ph] = dm->diode[ph] * i_ph[ph];
            } else {
                const double float_v = electrical(c, dm, x).float_v;
                g[ph] = fmin(float_v, vdc - float_v);
            }
        }
    }
    if (m->rotor == PMSM_ROTOR_FREE) {
        g[GUARD_ROTOR] =
            dm->motion != 0
                ? dm->motion * x[X_WM]
                : friction_nm(m) - fabs(state_torque(c, x));
    }
}

/* Earliest guard crossing between x0 and x1 as a fraction of the
 * interval (linear interpolation); returns the guard index or -1. */
static int first_crossing(const integ_t *c, const discrete_mode_t *dm,
                          const double x0[X_COUNT], const double x1[X_COUNT],
                          double *fraction)
{
    const pmsm_model_t *m = c->m;
    *fraction = 1.0;
    if (m->bridge != PMSM_BRIDGE_OFF) {
        /* only the rotor's guard can be crossed (guards() with the bridge
         * driven, without its other, zero, entries) */
        if (m->rotor != PMSM_ROTOR_FREE) {
            return -1;
        }
        double g[2];
        for (int k = 0; k < 2; k++) {
            const double *xk = k == 0 ? x0 : x1;
            g[k] = dm->motion != 0
                       ? dm->motion * xk[X_WM]
                       : friction_nm(m) - fabs(state_torque(c, xk));
        }
        if (g[0] > 0.0 && g[1] <= 0.0) {
            *fraction = g[0] / (g[0] - g[1]);
            return GUARD_ROTOR;
        }
        return -1;
    }
    double g0[GUARD_COUNT], g1[GUARD_COUNT];
    guards(c, dm, x0, g0);
    guards(c, dm, x1, g1);
    int first = -1;
    for (int k = 0; k < GUARD_COUNT; k++) {
        if (g0[k] > 0.0 && g1[k] <= 0.0) {
            const double f = g0[k] / (g0[k] - g1[k]);
            if (first < 0 || f < *fraction) {
                first = k;
                *fraction = f;
            }
        }
    }
    return first;
}

/* Removes one phase's current, keeping the other two balanced. */
static void remove_phase_current(const integ_t *c, double x[X_COUNT], int ph)
{
    const phase_axes_t ax = integ_axes(c, x[X_THETA]);
    const double i_x = x[X_ID] * ax.d[ph] + x[X_IQ] * ax.q[ph];
    x[X_ID] -= i_x * ax.d[ph];
    x[X_IQ] -= i_x * ax.q[ph];
}

/* At a guard crossing: a diode turning off or a rotor stopping has its
 * current or speed set to exactly zero; a turn-on or break-away is forced
 * into the next mode. */
static discrete_mode_t cross_guard(const integ_t *c,
                                   const discrete_mode_t *dm, int guard,
                                   double x[X_COUNT])
{
    if (guard == GUARD_ROTOR) {
        if (dm->motion == 0) {
            return decide_mode(c, x, GUARD_ROTOR);
        }
        x[X_WM] = 0.0;
        return decide_mode(c, x, FORCE_NONE);
    }
    if (guard == GUARD_ALL_BLOCKED || dm->diode[guard] == 0) {
        return decide_mode(c, x, guard);
    }
    int others_blocked = 0;
    for (int ph = 0; ph < PHASES; ph++) {
        others_blocked |= ph != guard && dm->diode[ph] == 0;
    }
    if (others_blocked) {
        /* the last two conducting phases carry the same current */
        x[X_ID] = 0.0;
        x[X_IQ] = 0.0;
    } else {
        remove_phase_current(c, x, guard);
    }
    return decide_mode(c, x, FORCE_NONE);
}

/* Bridge off with one phase blocked: RK4 keeps the (rotating) constraint
 * only to its truncation error; project the drift away so that the blocked
 * current stays at rounding level. */
static void hold_blocked_phase(const integ_t *c,
                               const discrete_mode_t *dm, double x[X_COUNT])
{
    const pmsm_model_t *m = c->m;
    if (m->bridge != PMSM_BRIDGE_OFF) {
        return;
    }
    int blocked = -1;
    int n_blocked = 0;
    for (int ph = 0; ph < PHASES; ph++) {
        if (dm->diode[ph] == 0) {
            blocked = ph;
            n_blocked++;
        }
    }
    if (n_blocked == 1) {
        remove_phase_current(c, x, blocked);
    }
}

static void integrate_substep(integ_t *c, double x[X_COUNT], double h)
{
    if (fabs(x[X_THETA] - c->theta0) > REBASE_ANGLE_RAD) {
        integ_rebase(c, x[X_THETA]);
    }
    discrete_mode_t dm = decide_mode(c, x, FORCE_NONE);
    double remaining_s = h;
    for (int events = 0; remaining_s > 0.0; events++) {
        double end[X_COUNT];
        rk4(c, &dm, x, remaining_s, end);
        double fraction = 1.0;
        const int guard = events < MAX_EVENTS_PER_SUBSTEP
                              ? first_crossing(c, &dm, x, end, &fraction)
                              : -1;
        if (guard < 0) {
            memcpy(x, end, sizeof end);
            hold_blocked_phase(c, &dm, x);
            return;
        }
        rk4(c, &dm, x, remaining_s * fraction, end);
        memcpy(x, end, sizeof end);
        hold_blocked_phase(c, &dm, x);
        dm = cross_guard(c, &dm, guard, x);
        remaining_s *= 1.0 - fraction;
    }
}

static double wrap_angle(double theta_rad)
{
    const double wrapped = fmod(theta_rad, 2.0 * PI);
    return wrapped < 0.0 ? wrapped + 2.0 * PI : wrapped;
}

void pmsm_default_params(pmsm_params_t *p)
{
    memset(p, 0, sizeof *p);
    /* Hurst DMB0224C10002 ("Hurst075") datasheet values. */
    p->pole_pairs = 5;
    p->rs_ohm = 2.54;
    p->ld_h = 1.92e-3;
    p->lq_h = 1.92e-3;
    /* Ke = 7.24 Vpk line-to-line per 1000 rpm; per phase (star) the peak
     * EMF is Ke / sqrt(3) = we * flux at 1000 rpm. */
    const double ke_vpk_ll_per_krpm = 7.24;
    const double we_per_krpm_rad_s = 2.0 * PI * 1000.0 / 60.0 * p->pole_pairs;
    p->flux_wb = ke_vpk_ll_per_krpm / (SQRT3 * we_per_krpm_rad_s);
    /* Inertia and friction are not published: assumed values of the
     * right order for this frame size (no load attached). */
    p->j_kgm2 = 4.8e-6;
    p->b_nm_per_rad_s = 3.0e-6;
    p->coulomb_nm = 1.0e-3;
    p->pwm_hz = 20000.0;
    p->deadtime_s = 0.0;
    p->vdc_source_v = 24.0;
    p->bus_cap_f = 0.0;
    p->brake_r_ohm = 10.0;
    p->adc_bits = 10;
    p->current_fs_a = 4.4;
    p->noise_codes = 0.0;
    p->seed = 1;
    p->substeps = 4;
    p->cogging_periods = 60; /* 12 slots, 10 poles: LCM = 60 (assumed) */
    p->thermal_tau_s = 600.0;
    p->rs_tempco_per_k = 0.0039;
}

void pmsm_init(pmsm_model_t *m, const pmsm_params_t *p)
{
    memset(m, 0, sizeof *m);
    m->p = *p;
    if (m->p.substeps < 1) {
        m->p.substeps = 1;
    }
    m->s.vdc_v = p->vdc_source_v;
    m->bridge = PMSM_BRIDGE_OFF;
    m->bridge_next = PMSM_BRIDGE_OFF;
    m->bridge_at_s = -1.0;
    for (int ph = 0; ph < PHASES; ph++) {
        m->duty[ph] = 0.5;
        m->duty_next[ph] = 0.5;
    }
    m->rotor = PMSM_ROTOR_FREE;
    m->rng = p->seed != 0 ? p->seed : SEED_FOR_ZERO;
}

void pmsm_set_duties(pmsm_model_t *m, double da, double db, double dc)
{
    m->duty_next[0] = clamp01(da);
    m->duty_next[1] = clamp01(db);
    m->duty_next[2] = clamp01(dc);
}

void pmsm_set_bridge(pmsm_model_t *m, pmsm_bridge_t mode)
{
    m->bridge_next = mode;
}

void pmsm_set_bridge_now(pmsm_model_t *m, pmsm_bridge_t mode)
{
    m->bridge = mode;
    m->bridge_next = mode;
    m->bridge_at_s = -1.0;
}

void pmsm_set_bridge_at(pmsm_model_t *m, pmsm_bridge_t mode, double at_s)
{
    m->bridge_next = mode;
    if (at_s < 1.0 / m->p.pwm_hz) {
        m->bridge_at_s = at_s;
        m->bridge_at_mode = mode;
    }
}

/* Records the phase currents of state x in the extremes since the last
 * sample. */
static void note_extremes(pmsm_model_t *m, const integ_t *c, const double x[X_COUNT])
{
    double co;
    double si;
    integ_cos_sin(c, x[X_THETA], &co, &si);
    const phase_axes_t ax = axes_from(co, si);
    double i_ph[PHASES];
    phase_currents(&ax, x[X_ID], x[X_IQ], i_ph);
    for (int ph = 0; ph < PHASES; ph++) {
        m->i_min_a[ph] = fmin(m->i_min_a[ph], i_ph[ph]);
        m->i_max_a[ph] = fmax(m->i_max_a[ph], i_ph[ph]);
    }
}

/* Integrates len_s with the active bridge in equal RK4 substeps no longer
 * than the period's (1 / (pwm_hz x substeps)); a whole period takes
 * exactly `substeps` of them. */
static void integrate_span(integ_t *c, double x[X_COUNT], double len_s)
{
    const pmsm_params_t *p = &c->m->p;
    const int n = (int)ceil(len_s * p->pwm_hz * p->substeps - 1e-9);
    const int steps = n > 1 ? n : 1;
    const double h = len_s / steps;
    for (int k = 0; k < steps; k++) {
        integrate_substep(c, x, h);
    }
}

/* Switched bridge: is leg ph's command high at time t into the period?
 * Centre-aligned PWM with the sampling instant in the middle of the
 * low-side on-time: the high-side command is centred on mid-period when
 * the ADC samples at the period start, on the period boundary when it
 * samples at mid-period (the pattern is periodic: before the start it is
 * this period's). */
static int leg_command_high(const pmsm_model_t *m, int ph, double t_s)
{
    const double d = m->duty[ph];
    const double period_s = 1.0 / m->p.pwm_hz;
    const double from_mid = fabs(t_s - 0.5 * period_s);
    if (m->p.sample_mid_period) {
        return from_mid >= 0.5 * (1.0 - d) * period_s;
    }
    return from_mid < 0.5 * d * period_s;
}

/* Switched bridge: leg ph's two command edges in the period, the times
 * its command rises and falls (or falls and rises); 0 edges at a duty of
 * 0 or 1. */
static int leg_edges(const pmsm_model_t *m, int ph, double edges[2])
{
    const double d = m->duty[ph];
    const double period_s = 1.0 / m->p.pwm_hz;
    const double half_w = 0.5 * (m->p.sample_mid_period ? 1.0 - d : d) * period_s;
    edges[0] = 0.5 * period_s - half_w;
    edges[1] = 0.5 * period_s + half_w;
    return (d > 0.0 && d < 1.0) ? 2 : 0;
}

/* Switched bridge: what leg ph's terminal is at time t, as a duty of 1
 * (DC+) or 0 (DC-).  Dead time: a switch turns on deadtime_s after its
 * command rises and off at once, so during deadtime_s after each command
 * edge both switches are off and the current's free-wheeling diode sets
 * the terminal: DC- for a current into the motor (i > 0, or 0), DC+ for
 * a current out of it.  Average over a period, -sgn(i) Vdc t_dead f_pwm
 * per leg, the average model's dead-time error.  A pulse shorter than
 * the dead time never turns its switch on (the timers' dead-time units:
 * STM32 RM0008 "Complementary outputs and dead-time insertion"), so the
 * diode holds from its first edge to t_dead after its second: the error
 * stays t_dead f_pwm, not twice the pulse.  (The edges of the period
 * before are taken at this period's duty.)  `edges`, `n`: leg_edges'. */
static double leg_state(const pmsm_model_t *m, int ph, const double edges[2], int n, double t_s,
                        double i_a)
{
    const double period_s = 1.0 / m->p.pwm_hz;
    for (int e = 0; e < n; e++) {
        if (fmod(t_s - edges[e] + period_s, period_s) < m->p.deadtime_s) {
            return i_a < 0.0 ? 1.0 : 0.0;
        }
    }
    return leg_command_high(m, ph, t_s);
}

/* Switched bridge from t0_s to t1_s into the period: split at every
 * command edge and every end of a dead time, each segment integrated with
 * its legs fixed at DC+ or DC- (the diode's rail taken from the current
 * at the segment's start, so a current crossing zero within a dead time
 * is not located). */
static void integrate_switched(pmsm_model_t *m, integ_t *c, double x[X_COUNT], double t0_s,
                               double t1_s)
{
    const double period_s = 1.0 / m->p.pwm_hz;
    double cut[2 + 4 * PHASES];
    int n = 0;
    cut[n++] = t0_s;
    cut[n++] = t1_s;
    double edges[PHASES][2];
    int n_edges[PHASES];
    for (int ph = 0; ph < PHASES; ph++) {
        n_edges[ph] = leg_edges(m, ph, edges[ph]);
        for (int e = 0; e < n_edges[ph]; e++) {
            const double t[2] = { edges[ph][e], fmod(edges[ph][e] + m->p.deadtime_s, period_s) };
            for (int k = 0; k < 2; k++) {
                if (t[k] > t0_s && t[k] < t1_s) {
                    cut[n++] = t[k];
                }
            }
        }
    }
    for (int i = 1; i < n; i++) { /* insertion sort of at most 14 times */
        for (int j = i; j > 0 && cut[j - 1] > cut[j]; j--) {
            const double tmp = cut[j];
            cut[j] = cut[j - 1];
            cut[j - 1] = tmp;
        }
    }
    for (int i = 0; i + 1 < n; i++) {
        if (!(cut[i + 1] > cut[i])) {
            continue;
        }
        double co;
        double si;
        integ_cos_sin(c, x[X_THETA], &co, &si);
        const phase_axes_t ax = axes_from(co, si);
        double i_ph[PHASES];
        phase_currents(&ax, x[X_ID], x[X_IQ], i_ph);
        const double mid_s = 0.5 * (cut[i] + cut[i + 1]);
        double legs[PHASES];
        for (int ph = 0; ph < PHASES; ph++) {
            legs[ph] = leg_state(m, ph, edges[ph], n_edges[ph], mid_s, i_ph[ph]);
        }
        c->duty = legs;
        integrate_span(c, x, cut[i + 1] - cut[i]);
        c->duty = m->duty;
        note_extremes(m, c, x);
    }
}
/* Integrates the present period from period_pos_s to t_end_s into it,
 * with the bridge of the whole span. */
static void advance_span(pmsm_model_t *m, double t_end_s)
{
    const double t0_s = m->period_pos_s;
    if (!(t_end_s > t0_s)) {
        return;
    }
    double x[X_COUNT] = { m->s.id_a, m->s.iq_a, m->s.wm_rad_s, m->s.theta_e_rad,
                          m->s.vdc_v, m->vd_int_vs, m->vq_int_vs };
    integ_t c;
    integ_init(&c, m, x[X_THETA]);
    if (m->p.switched && m->bridge == PMSM_BRIDGE_PWM) {
        integrate_switched(m, &c, x, t0_s, t_end_s);
    } else {
        integrate_span(&c, x, t_end_s - t0_s);
        note_extremes(m, &c, x);
    }
    m->s.id_a = x[X_ID];
    m->s.iq_a = x[X_IQ];
    m->s.wm_rad_s = x[X_WM];
    m->s.theta_e_rad = wrap_angle(x[X_THETA]);
    m->s.vdc_v = x[X_VDC];
    m->vd_int_vs = x[X_VD_INT];
    m->vq_int_vs = x[X_VQ_INT];
    m->period_pos_s = t_end_s;
}

/* Integrates the present period from period_pos_s to t_end_s into it; a
 * bridge switch set within it (pmsm_set_bridge_at) splits the span. */
static void advance_to(pmsm_model_t *m, double t_end_s)
{
    if (m->bridge_at_s >= 0.0 && m->bridge_at_s < t_end_s) {
        advance_span(m, m->bridge_at_s);
        m->bridge = m->bridge_at_mode;
        m->bridge_at_s = -1.0;
    }
    advance_span(m, t_end_s);
}

/* First-order thermal model of the winding (one node, ambient constant):
 *   tau d(rise)/dt = Rth P - rise,   P = 1.5 Rs(rise) (id^2 + iq^2),
 * the copper loss of the amplitude-invariant dq currents at the period's
 * end (the PWM ripple's share is left out), held over the period, whose
 * exact step is rise += (Rth P - rise)(1 - exp(-T / tau)).  Steady rise
 * P Rth.  Off when thermal_r_k_per_w is 0. */
static void heat_winding(pmsm_model_t *m, double period_s)
{
    if (m->p.thermal_r_k_per_w <= 0.0) {
        return;
    }
    const double i2 = m->s.id_a * m->s.id_a + m->s.iq_a * m->s.iq_a;
    const double loss_w = 1.5 * winding_rs_ohm(m) * i2;
    const double target_k = m->p.thermal_r_k_per_w * loss_w;
    m->winding_rise_k += (target_k - m->winding_rise_k) * -expm1(-period_s / m->p.thermal_tau_s);
}

void pmsm_run_to_sample(pmsm_model_t *m)
{
    advance_to(m, m->p.sample_mid_period ? 0.5 / m->p.pwm_hz : 0.0);
}

void pmsm_step_period(pmsm_model_t *m)
{
    const double period_s = 1.0 / m->p.pwm_hz;
    advance_to(m, period_s);
    m->vd_last_v = m->vd_int_vs / period_s;
    m->vq_last_v = m->vq_int_vs / period_s;
    m->vd_int_vs = 0.0;
    m->vq_int_vs = 0.0;
    m->period_pos_s = 0.0;
    m->time_s += period_s;
    heat_winding(m, period_s);
    for (int ph = 0; ph < PHASES; ph++) {
        m->offset_drift_codes[ph] += m->p.offset_drift_codes_per_s[ph] * period_s;
    }
    m->bridge = m->bridge_next;
    memcpy(m->duty, m->duty_next, sizeof m->duty);
}

static double uniform_open01(uint32_t *state)
{
    /* xorshift32 (Marsaglia): never 0 from a non-zero state */
    uint32_t v = *state;
    v ^= v << 13;
    v ^= v >> 17;
    v ^= v << 5;
    *state = v;
    return (double)v / 4294967296.0;
}

static double gaussian(uint32_t *state)
{
    /* Box-Muller, cosine branch only */
    const double u1 = uniform_open01(state);
    const double u2 = uniform_open01(state);
    return sqrt(-2.0 * log(u1)) * cos(2.0 * PI * u2);
}

static int32_t adc_code(const pmsm_model_t *m, int ph, double i_a,
                        double noise_codes)
{
    const pmsm_params_t *p = &m->p;
    const double half_scale = (double)(1L << (p->adc_bits - 1)); /* 2^(bits-1), exact */
    const double full_code = 2.0 * half_scale - 1.0;
    const double ideal = half_scale +
                         i_a * (1.0 + p->gain_error[ph]) / p->current_fs_a *
                             half_scale +
                         p->offset_codes[ph] + m->offset_drift_codes[ph] + noise_codes;
    const double code = floor(ideal + 0.5);
    return (int32_t)(code < 0.0 ? 0.0 : (code > full_code ? full_code : code));
}

void pmsm_sample(pmsm_model_t *m, pmsm_sample_t *out)
{
    const pmsm_params_t *p = &m->p;
    double co;
    double si;
    start_cos_sin(m, &co, &si);
    const phase_axes_t ax = axes_from(co, si);
    double i_ph[PHASES];
    int32_t code[PHASES];
    phase_currents(&ax, m->s.id_a, m->s.iq_a, i_ph);
    for (int ph = 0; ph < PHASES; ph++) {
        /* without noise the generator still advances, as it would have */
        double noise = 0.0;
        if (p->noise_codes != 0.0) {
            noise = p->noise_codes * gaussian(&m->rng);
        } else {
            (void)uniform_open01(&m->rng);
            (void)uniform_open01(&m->rng);
        }
        code[ph] = adc_code(m, ph, i_ph[ph], noise);
    }
    out->ia_a = i_ph[0];
    out->ib_a = i_ph[1];
    out->ic_a = i_ph[2];
    out->ia_code = code[0];
    out->ib_code = code[1];
    out->ic_code = code[2];
    out->vdc_v = m->s.vdc_v;
    out->theta_e_rad = m->s.theta_e_rad;
    out->speed_rpm = m->s.wm_rad_s * 60.0 / (2.0 * PI);
    out->torque_nm = rotor_torque(p, m->s.id_a, m->s.iq_a, m->s.theta_e_rad, co, si);
    out->vd_v = m->vd_last_v;
    out->vq_v = m->vq_last_v;
    for (int ph = 0; ph < PHASES; ph++) {
        out->i_min_a[ph] = fmin(m->i_min_a[ph], i_ph[ph]);
        out->i_max_a[ph] = fmax(m->i_max_a[ph], i_ph[ph]);
        m->i_min_a[ph] = i_ph[ph];
        m->i_max_a[ph] = i_ph[ph];
    }
}

void pmsm_set_rotor_angle(pmsm_model_t *m, double theta_e_rad)
{
    /* the stator currents are continuous: keep them, re-express in the
     * new rotor frame */
    const double c0 = cos(m->s.theta_e_rad);
    const double s0 = sin(m->s.theta_e_rad);
    const double i_alpha = m->s.id_a * c0 - m->s.iq_a * s0;
    const double i_beta = m->s.id_a * s0 + m->s.iq_a * c0;
    const double theta = wrap_angle(theta_e_rad);
    const double c1 = cos(theta);
    const double s1 = sin(theta);
    m->s.id_a = i_alpha * c1 + i_beta * s1;
    m->s.iq_a = -i_alpha * s1 + i_beta * c1;
    m->s.theta_e_rad = theta;
}

void pmsm_set_rotor_mode(pmsm_model_t *m, pmsm_rotor_mode_t mode,
                         double spin_rpm)
{
    m->rotor = mode;
    m->spin_rpm = spin_rpm;
    if (mode == PMSM_ROTOR_SPIN) {
        m->s.wm_rad_s = spin_rpm * 2.0 * PI / 60.0;
    } else if (mode == PMSM_ROTOR_LOCKED) {
        m->s.wm_rad_s = 0.0;
    }
}

void pmsm_set_load(pmsm_model_t *m, double load_nm)
{
    m->load_nm = fabs(load_nm);
}

void pmsm_set_vdc(pmsm_model_t *m, double vdc_source_v)
{
    m->p.vdc_source_v = vdc_source_v;
    if (m->p.bus_cap_f <= 0.0) {
        m->s.vdc_v = vdc_source_v;
    }
}

void pmsm_set_brake_resistor(pmsm_model_t *m, int on)
{
    m->brake_resistor_on = on != 0;
}
