/*
 * Fault set: one bit per fault class, the first one latched.  A fault stays
 * in the set until acknowledged (the controller decides when an
 * acknowledge is allowed).
 */
#ifndef FOC_FAULTS_H
#define FOC_FAULTS_H

#include <stdint.h>

typedef enum {
    FOC_FAULT_NONE = 0,
    FOC_FAULT_OVERCURRENT = 1u << 0,    /* hardware fault input, or the */
                                        /* sampled current beyond its trip */
    FOC_FAULT_OVERVOLTAGE = 1u << 1,
    FOC_FAULT_UNDERVOLTAGE = 1u << 2,
    FOC_FAULT_OVERTEMP = 1u << 3,
    FOC_FAULT_STARTUP_FAILED = 1u << 4,
    FOC_FAULT_SPEED_FEEDBACK = 1u << 5, /* the rotor does not follow */
    FOC_FAULT_OVERSPEED = 1u << 6,
    FOC_FAULT_MOTOR_OVERLOAD = 1u << 7, /* I2t: the winding would overheat */
    FOC_FAULT_COMMISSION_FAILED = (uint16_t)1u << 8 /* a commissioning step failed */
                                          /* (controller.h comm.failed_step) */
} foc_fault_t;

typedef struct {
    uint16_t active; /* bit set of foc_fault_t */
    uint16_t first;  /* the first fault raised since the last clear */
} foc_faults_t;

void foc_faults_clear(foc_faults_t *f);
void foc_faults_raise(foc_faults_t *f, foc_fault_t fault);

/* "NONE", "OVERCURRENT", ... for one fault bit (or the first of a set). */
const char *foc_fault_name(uint16_t fault);

#endif /* FOC_FAULTS_H */
