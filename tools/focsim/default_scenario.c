#include "default_scenario.h"

#include <math.h>
#include <stdio.h>

#include "foc/config.h"

/* Time for the reference (and a rotor at half the current limit) to go
 * from one speed to another, plus 0.4 s to settle. */
static double step_s(double from_rpm, double to_rpm)
{
    const double accel_limit_rpm_s = 0.5 * FOC_KT_NM_PER_A * CURRENT_LIMIT_A / MOTOR_INERTIA_KGM2 *
                                     60.0 / (2.0 * FOC_PI_D);
    const double accel = fmin(SPEED_RAMP_RPM_PER_S, accel_limit_rpm_s);
    return fabs(to_rpm - from_rpm) / accel + 0.4;
}

/* rpm rounded to 10 */
static double round10(double rpm)
{
    return 10.0 * floor(rpm / 10.0 + 0.5);
}

int sim_default_scenario(char *buf, size_t len)
{
    const double half = round10(0.5 * MOTOR_NOMINAL_SPEED_RPM);
    const double nominal = round10(MOTOR_NOMINAL_SPEED_RPM);
    const double quarter = round10(fmax(0.25 * MOTOR_NOMINAL_SPEED_RPM, 1.5 * STARTUP_MIN_SPEED_RPM));
    const double load_nm = 0.5 * FOC_KT_NM_PER_A * MOTOR_RATED_CURRENT_A;
    const double t1 = 0.1;
    const double t2 = t1 + STARTUP_ALIGN_TIME_S + STARTUP_RAMP_TIME_S + step_s(0.0, half);
    const double t3 = t2 + step_s(half, nominal);
    const double t4 = t3 + 0.4;
    const double t5 = t4 + step_s(nominal, quarter);
    const double t6 = t5 + 0.4;
    const double t_end = t6 + step_s(quarter, 0.0);
    const int n = snprintf(buf, len,
                           "# the default scenario for this build's motor (focsim "
                           "--print-default-scenario)\n"
                           "0 start\n%.3f speed %.0f\n%.3f speed %.0f\n%.3f load %.6g\n"
                           "%.3f speed %.0f\n%.3f load 0\n%.3f stop\n%.3f end\n",
                           t1, half, t2, nominal, t3, load_nm, t4, quarter, t5, t6, t_end);
    return (n < 0 || (size_t)n >= len) ? -1 : n;
}
