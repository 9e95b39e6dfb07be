#include "foc/bus.h"
#include "foc/config.h"

#define COMP_ONE_Q14 ((int32_t)16384)
#define COMP_MAX_Q14 ((int32_t)32767) /* 2.0: the bus at half its nominal value */

static void derive_limits(foc_bus_t *bus)
{
    const q15_t vdc = foc_lpf_out(&bus->vdc);
    /* comp = nominal / vdc, Q14; a bus below half nominal saturates it (the
     * under-voltage fault trips well before). 16384 x 32767 fits int32_t. */
    int32_t comp = COMP_MAX_Q14;
    if ((int32_t)vdc * 2 > FOC_VDC_NOMINAL) {
        comp = (COMP_ONE_Q14 * FOC_VDC_NOMINAL) / vdc;
    }
    if (comp > COMP_MAX_Q14) {
        comp = COMP_MAX_Q14;
    }
    bus->comp_q14 = (int16_t)comp;
    /* v_max = min(vdc / nominal, 1) x limit = limit / max(comp, 1). */
    if (comp < COMP_ONE_Q14) {
        comp = COMP_ONE_Q14;
    }
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    bus->v_max = (q15_t)(((int32_t)FOC_VOLTAGE_LIMIT * COMP_ONE_Q14) / comp);
}

void foc_bus_init(foc_bus_t *bus, q15_t vdc)
{
    foc_lpf_init(&bus->vdc, vdc);
    derive_limits(bus);
}

void foc_bus_update(foc_bus_t *bus, q15_t vdc)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    (void)foc_lpf_step(&bus->vdc, vdc, FOC_VDC_FILTER_K);
    derive_limits(bus);
}
