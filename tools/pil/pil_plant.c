/*
 * The project's motor model (tools/plant/pmsm_model.c, compiled in as it
 * is) with a flat C interface for tools/pil (ctypes).  The processor-in-
 * the-loop run changes duties and bridge modes at the instants the image's
 * timer really changes them (update events, MOE, break), and samples at
 * the instants the ADC really holds, so besides pmsm_step_period it needs
 * to integrate an arbitrary interval with the active duties:
 * pil_advance() does that with the model's own integrator
 * (integrate_substep), the substep length no longer than the model's
 * (1 / (pwm_hz x substeps)).  Nothing of the model is changed.
 */
#include "../plant/pmsm_model.c"

typedef struct {
    pmsm_model_t m;
    double vd_int, vq_int, t_int; /* winding-voltage integrals since the */
                                  /* last pil_take_vdq() */
} pil_plant_t;

static pil_plant_t plant_instance;

void *pil_new(const double *v, int pole_pairs, int adc_bits, unsigned seed);
void pil_set_active(void *h, int bridge, double da, double db, double dc);
void pil_advance(void *h, double dt_s);
void pil_state(void *h, double *out);
void pil_cmd(void *h, int what, double value);
size_t pil_model_size(void);

/* v: rs ld lq flux j b coulomb pwm_hz deadtime vdc current_fs */
void *pil_new(const double *v, int pole_pairs, int adc_bits, unsigned seed)
{
    pmsm_params_t p;
    pmsm_default_params(&p);
    p.rs_ohm = v[0];
    p.ld_h = v[1];
    p.lq_h = v[2];
    p.flux_wb = v[3];
    p.j_kgm2 = v[4];
    p.b_nm_per_rad_s = v[5];
    p.coulomb_nm = v[6];
    p.pwm_hz = v[7];
    p.deadtime_s = v[8];
    p.vdc_source_v = v[9];
    p.current_fs_a = v[10];
    p.pole_pairs = pole_pairs;
    p.adc_bits = adc_bits;
    p.seed = seed;
    memset(&plant_instance, 0, sizeof plant_instance);
    pmsm_init(&plant_instance.m, &p);
    return &plant_instance;
}

/* Duties and bridge mode from now on (not latched: the timer's update
 * event is modelled by the caller). */
void pil_set_active(void *h, int bridge, double da, double db, double dc)
{
    pil_plant_t *pl = h;
    pl->m.bridge = (pmsm_bridge_t)bridge;
    pl->m.bridge_next = (pmsm_bridge_t)bridge;
    pl->m.duty[0] = pl->m.duty_next[0] = clamp01(da);
    pl->m.duty[1] = pl->m.duty_next[1] = clamp01(db);
    pl->m.duty[2] = pl->m.duty_next[2] = clamp01(dc);
}

void pil_advance(void *h, double dt_s)
{
    pil_plant_t *pl = h;
    pmsm_model_t *m = &pl->m;
    if (dt_s <= 0.0) {
        return;
    }
    const double max_sub = 1.0 / (m->p.pwm_hz * m->p.substeps);
    int n = (int)ceil(dt_s / max_sub - 1e-9);
    if (n < 1) {
        n = 1;
    }
    double x[X_COUNT] = { m->s.id_a, m->s.iq_a, m->s.wm_rad_s,
                          m->s.theta_e_rad, m->s.vdc_v, 0.0, 0.0 };
    integ_t c;
    integ_init(&c, m, x[X_THETA]);
    for (int k = 0; k < n; k++) {
        integrate_substep(&c, x, dt_s / n);
    }
    m->s.id_a = x[X_ID];
    m->s.iq_a = x[X_IQ];
    m->s.wm_rad_s = x[X_WM];
    m->s.theta_e_rad = wrap_angle(x[X_THETA]);
    m->s.vdc_v = x[X_VDC];
    pl->vd_int += x[X_VD_INT];
    pl->vq_int += x[X_VQ_INT];
    pl->t_int += dt_s;
    m->time_s += dt_s;
}

/* out: ia ib ic vdc theta_e speed_rpm torque id iq vd_avg vq_avg t */
void pil_state(void *h, double *out)
{
    pil_plant_t *pl = h;
    pmsm_model_t *m = &pl->m;
    const phase_axes_t ax = phase_axes(m->s.theta_e_rad);
    double i_ph[PHASES];
    phase_currents(&ax, m->s.id_a, m->s.iq_a, i_ph);
    out[0] = i_ph[0];
    out[1] = i_ph[1];
    out[2] = i_ph[2];
    out[3] = m->s.vdc_v;
    out[4] = m->s.theta_e_rad;
    out[5] = m->s.wm_rad_s * 60.0 / (2.0 * PI);
    out[6] = pmsm_torque(&m->p, m->s.id_a, m->s.iq_a, m->s.theta_e_rad);
    out[7] = m->s.id_a;
    out[8] = m->s.iq_a;
    out[9] = pl->t_int > 0.0 ? pl->vd_int / pl->t_int : 0.0;
    out[10] = pl->t_int > 0.0 ? pl->vq_int / pl->t_int : 0.0;
    out[11] = m->time_s;
    pl->vd_int = pl->vq_int = pl->t_int = 0.0;
}

/* Scenario commands on the plant: 0 load, 1 lock, 2 unlock, 3 vdc,
 * 4 angle (rad), 5 spin (rpm), 6 brake resistor, 10 + scn_plant_t: a
 * parameter (rs ld lq flux j b deadtime noise buscap brakeres). */
void pil_cmd(void *h, int what, double v)
{
    pmsm_model_t *m = &((pil_plant_t *)h)->m;
    switch (what) {
    case 0: pmsm_set_load(m, v); break;
    case 1: pmsm_set_rotor_mode(m, PMSM_ROTOR_LOCKED, 0.0); break;
    case 2: pmsm_set_rotor_mode(m, PMSM_ROTOR_FREE, 0.0); break;
    case 3: pmsm_set_vdc(m, v); break;
    case 4: pmsm_set_rotor_angle(m, v); break;
    case 5: pmsm_set_rotor_mode(m, PMSM_ROTOR_SPIN, v); break;
    case 6: pmsm_set_brake_resistor(m, v != 0.0); break;
    case 10: m->p.rs_ohm = v; break;
    case 11: m->p.ld_h = v; break;
    case 12: m->p.lq_h = v; break;
    case 13: m->p.flux_wb = v; break;
    case 14: m->p.j_kgm2 = v; break;
    case 15: m->p.b_nm_per_rad_s = v; break;
    case 16: m->p.deadtime_s = v; break;
    case 17: m->p.noise_codes = v; break;
    case 18: m->p.bus_cap_f = v; break;
    case 19: m->p.brake_r_ohm = v; break;
    default: break;
    }
}

size_t pil_model_size(void)
{
    return sizeof(pmsm_model_t);
}

/* ------------------------------------------------------------------ */
/* The plant as userparms.h describes it, as focsim builds it
 * (tools/focsim/sim.c, plant_from_userparms), and the board's analog
 * scaling for the ADC model.  Compiled with -DFOC_USERPARMS_FILE. */
#include "foc/config.h"

void *pil_new_board(unsigned seed, double *board);

/* board out: pwm_hz vdc_full_scale current_full_scale vref temp_v0
 * temp_slope adc_bits deadtime_s vdc_nominal */
void *pil_new_board(unsigned seed, double *board)
{
    const double rad_s_per_krpm = 1000.0 * 2.0 * FOC_PI_D / 60.0;
    const double v[11] = {
        MOTOR_RS_OHM, MOTOR_LD_H, MOTOR_LQ_H, FOC_FLUX_WB, MOTOR_INERTIA_KGM2,
        MOTOR_VISCOUS_NM_PER_KRPM / rad_s_per_krpm, MOTOR_COULOMB_NM,
        PWM_FREQUENCY_HZ, PWM_DEADTIME_S, BOARD_VDC_NOMINAL_V,
        BOARD_CURRENT_FULL_SCALE_A,
    };
    board[0] = PWM_FREQUENCY_HZ;
    board[1] = BOARD_VDC_FULL_SCALE_V;
    board[2] = BOARD_CURRENT_FULL_SCALE_A;
    board[3] = BOARD_ADC_VREF_V;
    board[4] = BOARD_TEMP_V_AT_0C;
    board[5] = BOARD_TEMP_V_PER_DEGC;
    board[6] = BOARD_ADC_BITS;
    board[7] = PWM_DEADTIME_S;
    board[8] = BOARD_VDC_NOMINAL_V;
    board[9] = MOTOR_POLE_PAIRS;
    board[10] = SPEED_BASE_RPM;
    return pil_new(v, MOTOR_POLE_PAIRS, BOARD_ADC_BITS, seed);
}
