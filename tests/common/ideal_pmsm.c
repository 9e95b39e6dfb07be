/* Ideal-machine signals for the estimator unit tests: ideal_pmsm.h. */
#include "ideal_pmsm.h"

#include <math.h>

#define PI_D 3.14159265358979323846
#define TWO_PI (2.0 * PI_D)

static void current_ab(double theta, double id, double iq, double *ia, double *ib)
{
    *ia = id * cos(theta) - iq * sin(theta);
    *ib = id * sin(theta) + iq * cos(theta);
}

/* psi_ab = ((Ld id + psi_m) + j Lq iq) e^(j theta), Wb. */
static void stator_flux(const ideal_pmsm_params_t *p, double theta, double id, double iq,
                        double *fa, double *fb)
{
    const double fd = p->ld_h * id + p->flux_wb;
    const double fq = p->lq_h * iq;
    *fa = fd * cos(theta) - fq * sin(theta);
    *fb = fd * sin(theta) + fq * cos(theta);
}

q15_t ideal_q15(double x)
{
    const double r = floor(x * 32768.0 + 0.5);
    return (q15_t)(r > 32767.0 ? 32767 : r < -32768.0 ? -32768 : r);
}

void ideal_pmsm_sample(ideal_pmsm_t *m)
{
    current_ab(m->theta_rad, m->id_a, m->iq_a, &m->i_ab_a[0], &m->i_ab_a[1]);
    m->i_now.alpha = ideal_q15((m->i_ab_a[0] + m->i_off_a[0]) / m->p.i_base_a);
    m->i_now.beta = ideal_q15((m->i_ab_a[1] + m->i_off_a[1]) / m->p.i_base_a);
}

void ideal_pmsm_init(ideal_pmsm_t *m, const ideal_pmsm_params_t *p, double theta_rad,
                     double we_rad_s, double id_a, double iq_a)
{
    m->p = *p;
    m->t_s = 0.0;
    m->theta_rad = fmod(theta_rad, TWO_PI);
    m->we_rad_s = we_rad_s;
    m->id_a = id_a;
    m->iq_a = iq_a;
    m->i_off_a[0] = m->i_off_a[1] = 0.0;
    m->v_off_v[0] = m->v_off_v[1] = 0.0;
    m->v_ab_v[0] = m->v_ab_v[1] = 0.0;
    m->v_last.alpha = m->v_last.beta = 0;
    ideal_pmsm_sample(m);
}

void ideal_pmsm_period(ideal_pmsm_t *m, double accel_rad_s2, double iq_end_a)
{
    const double ts = m->p.ts_s;
    const double h = ts / IDEAL_PMSM_SUBSTEPS;
    double fa0, fb0, fa1, fb1, sum_a = 0.0, sum_b = 0.0;
    stator_flux(&m->p, m->theta_rad, m->id_a, m->iq_a, &fa0, &fb0);
    for (int n = 0; n < IDEAL_PMSM_SUBSTEPS; n++) {
        const double t = (n + 0.5) * h;
        const double th = m->theta_rad + m->we_rad_s * t + 0.5 * accel_rad_s2 * t * t;
        const double iq = m->iq_a + (iq_end_a - m->iq_a) * t / ts;
        double ia, ib;
        current_ab(th, m->id_a, iq, &ia, &ib);
        sum_a += ia;
        sum_b += ib;
    }
    m->theta_rad = fmod(m->theta_rad + m->we_rad_s * ts + 0.5 * accel_rad_s2 * ts * ts, TWO_PI);
    m->we_rad_s += accel_rad_s2 * ts;
    m->iq_a = iq_end_a;
    m->t_s += ts;
    stator_flux(&m->p, m->theta_rad, m->id_a, m->iq_a, &fa1, &fb1);
    m->v_ab_v[0] = m->p.rs_ohm * sum_a / IDEAL_PMSM_SUBSTEPS + (fa1 - fa0) / ts;
    m->v_ab_v[1] = m->p.rs_ohm * sum_b / IDEAL_PMSM_SUBSTEPS + (fb1 - fb0) / ts;
    m->v_last.alpha = ideal_q15((m->v_ab_v[0] + m->v_off_v[0]) / m->p.v_base_v);
    m->v_last.beta = ideal_q15((m->v_ab_v[1] + m->v_off_v[1]) / m->p.v_base_v);
    ideal_pmsm_sample(m);
}

double ideal_pmsm_angle_err_deg(uint16_t estimate, const ideal_pmsm_t *m)
{
    return remainder(estimate * (360.0 / 65536.0) - m->theta_rad * 180.0 / PI_D, 360.0);
}
