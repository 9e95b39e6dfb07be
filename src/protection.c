#include "foc/protection.h"
#include "foc/config.h"
#include "foc/faults.h"
#include "foc/port.h"

void foc_protection_init(foc_protection_t *p)
{
    p->resistor_enabled = (uint8_t)(BRAKE_RESISTOR_ENABLE != 0);
    p->resistor_on = 0;
    foc_port_brake_resistor(0);
}

static void switch_resistor(foc_protection_t *p, q15_t vdc)
{
    /* on above ON, off below OFF, unchanged in between (hysteresis) */
    uint8_t on = p->resistor_on;
    if (vdc >= FOC_BRAKE_RESISTOR_ON) {
        on = 1;
    } else if (vdc <= FOC_BRAKE_RESISTOR_OFF) {
        on = 0;
    } else {
        /* hold */
    }
    on = (uint8_t)(on & p->resistor_enabled);
    if (on != p->resistor_on) {
        p->resistor_on = on;
        foc_port_brake_resistor(on);
    }
}

static q15_t overvoltage_trip(const foc_protection_t *p)
{
    return (p->resistor_enabled != 0u) ? FOC_OVERVOLTAGE_HARD : FOC_OVERVOLTAGE;
}

uint16_t foc_protection_check(foc_protection_t *p, q15_t vdc, q15_t temp)
{
    uint16_t faults = 0;
    switch_resistor(p, vdc);
    if (vdc >= overvoltage_trip(p)) {
        faults |= (uint16_t)FOC_FAULT_OVERVOLTAGE;
    }
    if (vdc <= FOC_UNDERVOLTAGE) {
        faults |= (uint16_t)FOC_FAULT_UNDERVOLTAGE;
    }
    if (temp >= FOC_OVERTEMP) {
        faults |= (uint16_t)FOC_FAULT_OVERTEMP;
    }
    return faults;
}

uint8_t foc_protection_causes_gone(const foc_protection_t *p, uint16_t faults, q15_t vdc,
                                   q15_t temp)
{
    const q15_t ov_clear = (q15_t)(overvoltage_trip(p) - (FOC_OVERVOLTAGE - FOC_OVERVOLTAGE_CLEAR));
    if ((faults & (uint16_t)FOC_FAULT_OVERVOLTAGE) != 0u && vdc >= ov_clear) {
        return 0;
    }
    if ((faults & (uint16_t)FOC_FAULT_UNDERVOLTAGE) != 0u && vdc <= FOC_UNDERVOLTAGE_CLEAR) {
        return 0;
    }
    if ((faults & (uint16_t)FOC_FAULT_OVERTEMP) != 0u && temp >= FOC_OVERTEMP_CLEAR) {
        return 0;
    }
    return 1;
}
