/* Driver of the dsPIC33 estimator's hand-worked case (see hand.c): 100
 * calls, 90 of them saturating; prints steps=100. */
#include <stdio.h>

#include "hand.h"

int main(void)
{
    mac_t m = { 1000, 0, 1000000L };
    int32_t sum = 0;
    for (int i = 0; i < 100; i++) {
        sum += mac_step(&m, 100);
    }
    printf("sum=%ld\nsteps=100\n", (long)sum);
    return 0;
}
