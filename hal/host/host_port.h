/*
 * Host port: the motor model plays the inverter, the ADC and the motor
 * behind the same port functions the MCU ports implement (port.h).  The
 * core cannot tell it runs on a PC.
 *
 * Board emulated: the analog scaling of userparms.h (current and bus full
 * scale, ADC resolution, temperature sensor), two shunts on phases A and B
 * (dsPICDEM MCLV) unless three are chosen, a hardware over-current
 * comparator at the current full scale that latches the bridge off, and a
 * fault input that a test can assert.
 */
#ifndef HOST_PORT_H
#define HOST_PORT_H

#include <stdint.h>
#include "foc/q15.h"
#include "pmsm_model.h"

typedef struct {
    pmsm_model_t *model;
    uint8_t phases;            /* FOC_PHASE_* bits read each period */
    uint8_t fault_input;       /* external fault input asserted (test) */
    uint8_t overcurrent_latch; /* hardware latch state */
    uint8_t pwm_enabled;
    double temp_degc;          /* board temperature seen by the sensor */
    double pot_fraction;       /* potentiometer position, [0, 1] */
    q15_t debug[2];            /* last "DAC" outputs */
    uint32_t periods;          /* time base: PWM periods */
    pmsm_sample_t last_sample; /* the model's sample read last */
} host_port_t;

/* Connects the port to a model and resets the port state. */
void host_port_attach(pmsm_model_t *model);

/* The port's state (tests and focsim read and set its fields). */
host_port_t *host_port(void);

#endif /* HOST_PORT_H */
