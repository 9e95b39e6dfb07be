/*
 * MTPA d current (foc/mtpa.h) against the double-precision closed form, and
 * the closed form against the definition: the largest torque per ampere.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "foc/mtpa.h"
#include "testkit.h"

/* k = 2 (Lq - Ld) / psi per unit of current, Q12: from a trace of saliency
 * up to the format's end (8.0). */
static const q15_t k_set[] = { 1, 41, 2163, 4096, 12288, 32767 };

/* The closed form, per unit (psi = 2 / k in per-unit flux):
 * id = psi/(2 dL) - sqrt(psi^2/(4 dL^2) + iq^2) = (1 - sqrt(1 + (k iq)^2)) / k. */
static double id_closed_form(double iq, double k)
{
    const double x = k * fabs(iq);
    return -fabs(iq) * x / (1.0 + sqrt(1.0 + x * x));
}

/* Torque per unit of psi, 1.5 p aside: (psi + (Ld - Lq) id) iq / psi =
 * (1 - k id / 2) iq. */
static double torque(double id, double iq, double k)
{
    return (1.0 - 0.5 * k * id) * iq;
}

/* Every q current on a stride, both signs, each k: within 4 LSB of the
 * closed form on the quantised k (x held at 8.0 as the block says). */
static void case_matches_closed_form(void)
{
    int worst = 0;
    for (unsigned n = 0; n < sizeof k_set / sizeof k_set[0]; n++) {
        const double k = k_set[n] / 4096.0;
        for (int32_t iq = -32768; iq <= 32767; iq += 7) {
            const q15_t id = foc_mtpa_id_q15((q15_t)iq, k_set[n]);
            const double iq_pu = iq / 32768.0;
            double x = k * fabs(iq_pu);
            if (x > 32767.0 / 4096.0) {
                x = 32767.0 / 4096.0;
            }
            const double ref = -fabs(iq_pu) * x / (1.0 + sqrt(1.0 + x * x)) * 32768.0;
            const int err = (int)fabs(id - ref);
            worst = (err > worst) ? err : worst;
            TK_CHECK(id <= 0 && (iq == 0 || -(int32_t)id < labs((long)iq)), "k %d iq %ld: id %d", k_set[n],
                     (long)iq, id);
        }
    }
    TK_CHECK(worst <= 4, "worst error %d LSB", worst);
}

/* A round rotor (k = 0) keeps id = 0; the sign of iq does not matter;
 * |id| grows with |iq|. */
static void case_round_rotor_sign_monotone(void)
{
    for (int32_t iq = -32768; iq <= 32767; iq += 3) {
        TK_CHECK(foc_mtpa_id_q15((q15_t)iq, 0) == 0, "k = 0, iq %ld", (long)iq);
    }
    for (int32_t iq = 1; iq <= 32767; iq += 5) {
        TK_CHECK(foc_mtpa_id_q15((q15_t)iq, 2163) == foc_mtpa_id_q15((q15_t)-iq, 2163),
                 "sign, iq %ld", (long)iq);
        TK_CHECK(foc_mtpa_id_q15((q15_t)iq, 2163) <= foc_mtpa_id_q15((q15_t)(iq - 1), 2163),
                 "monotone, iq %ld", (long)iq);
    }
    TK_CHECK(foc_mtpa_id_q15(-32768, 32767) < 0, "full scale, most salient");
}

/* The closed form is the MTPA point: on the circle of its current, moving
 * the current angle either way by 0.1 deg loses torque; and it gains over
 * id = 0 (the torture's interior-magnet motor, k = 0.528 per 10 A: +0.29 %
 * at 2.9 A, the figure of tests/salient). */
static void case_closed_form_is_max_torque_per_amp(void)
{
    for (unsigned n = 0; n < sizeof k_set / sizeof k_set[0]; n++) {
        const double k = k_set[n] / 4096.0;
        for (double iq = 0.05; iq < 1.0; iq += 0.05) {
            const double id = id_closed_form(iq, k);
            const double i = hypot(id, iq);
            const double beta = atan2(-id, iq);
            const double t0 = torque(id, iq, k);
            for (int s = -1; s <= 1; s += 2) {
                const double b = beta + s * 0.1 * 3.14159265358979 / 180.0;
                TK_CHECK(torque(-i * sin(b), i * cos(b), k) <= t0, "k %g iq %g", k, iq);
            }
            TK_CHECK(t0 >= torque(0.0, i, k), "k %g iq %g: below id = 0", k, iq);
        }
    }
    const double k_ipm = 2.0 * (13.5e-3 - 11.5e-3) * 10.0 / 0.07581;
    const double iq = 0.2898, id = id_closed_form(0.2898, k_ipm);
    const double i = hypot(id, iq);
    const double gain = torque(id, iq, k_ipm) / torque(0.0, i, k_ipm) - 1.0;
    TK_CHECK(gain > 0.0027 && gain < 0.0031, "IPM gain %.4f %%", 100.0 * gain);
}

TK_CASES(TK_CASE(case_matches_closed_form), TK_CASE(case_round_rotor_sign_monotone),
         TK_CASE(case_closed_form_is_max_torque_per_amp))
