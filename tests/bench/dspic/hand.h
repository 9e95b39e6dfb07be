/* The dsPIC33 estimator's hand-worked case: see hand.c. */
#ifndef DSPIC_HAND_H
#define DSPIC_HAND_H

#include <stdint.h>

typedef struct {
    int16_t k;
    int32_t acc;
    int32_t limit;
} mac_t;

int32_t mac_step(mac_t *m, int16_t x);

#endif
