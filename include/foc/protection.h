/*
 * Bus and temperature protection (slow tick, every state): over- and
 * under-voltage on the measured bus, over-temperature from the board's
 * sensor, and the brake resistor.  Thresholds from userparms.h; a fault's
 * cause counts as gone only past the hysteresis (for the acknowledge).
 *
 * With BRAKE_RESISTOR_ENABLE the resistor is on above BRAKE_RESISTOR_ON_V
 * and off below BRAKE_RESISTOR_OFF_V, and over-voltage trips only at
 * 1.2 x OVERVOLTAGE_V (the resistor has failed to hold the bus).
 *
 * Readings are the port's raw samples (bus Q15 of BOARD_VDC_FULL_SCALE_V,
 * temperature Q15 of BOARD_ADC_VREF_V), unfiltered, so a fault trips within
 * one slow tick of its cause.
 */
#ifndef FOC_PROTECTION_H
#define FOC_PROTECTION_H

#include <stdint.h>
#include "foc/q15.h"

typedef struct {
    uint8_t resistor_enabled; /* BRAKE_RESISTOR_ENABLE, changeable */
    uint8_t resistor_on;
} foc_protection_t;

void foc_protection_init(foc_protection_t *p);

/* One slow tick: switches the brake resistor (through the port) and
 * returns the foc_fault_t bits whose cause is present now. */
uint16_t foc_protection_check(foc_protection_t *p, q15_t vdc, q15_t temp);

/* 1 when none of the causes of `faults` is present any more (hysteresis
 * applied); faults without a measurable cause count as gone. */
uint8_t foc_protection_causes_gone(const foc_protection_t *p, uint16_t faults, q15_t vdc,
                                   q15_t temp);

#endif /* FOC_PROTECTION_H */
