/*
 * focsim's default scenario, derived from the motor the build is for
 * (userparms.h), so that `make sim` exercises any motor at its own speeds
 * and torque rather than the Hurst075's numbers (tools/scenarios/default.scn
 * stays the Hurst075's, which the PIL compares):
 *
 *   start; half the nominal speed; the nominal speed; half the rated torque
 *   (1.5 p psi x MOTOR_RATED_CURRENT_A) as a load; a quarter of the nominal
 *   speed (at least 1.5 x the lowest sensorless speed); the load off; stop.
 *
 * Each step waits for the reference's ramp (SPEED_RAMP_RPM_PER_S, or the
 * acceleration half the current limit gives the parameter's inertia if
 * slower) plus 0.4 s; the first for the start-up (alignment and ramp) too.
 */
#ifndef FOCSIM_DEFAULT_SCENARIO_H
#define FOCSIM_DEFAULT_SCENARIO_H

#include <stddef.h>

/* The scenario's text into buf (len bytes); the number of characters
 * written, as snprintf, or -1. */
int sim_default_scenario(char *buf, size_t len);

#endif /* FOCSIM_DEFAULT_SCENARIO_H */
