#include "foc/faults.h"

void foc_faults_clear(foc_faults_t *f)
{
    f->active = 0;
    f->first = 0;
}

void foc_faults_raise(foc_faults_t *f, foc_fault_t fault)
{
    if (f->active == 0u) {
        f->first = (uint16_t)fault;
    }
    f->active = (uint16_t)(f->active | (uint16_t)fault);
}

const char *foc_fault_name(uint16_t fault)
{
    static const char *const names[] = {
        "OVERCURRENT", "OVERVOLTAGE", "UNDERVOLTAGE",
        "OVERTEMP", "STARTUP_FAILED", "SPEED_FEEDBACK", "OVERSPEED", "MOTOR_OVERLOAD",
        "COMMISSION_FAILED",
    };
    for (unsigned bit = 0; bit < sizeof names / sizeof names[0]; bit++) {
        if ((fault & ((unsigned)1u << bit)) != 0u) {
            return names[bit];
        }
    }
    return "NONE";
}
