/*
 * Integer square root, for the voltage circle sqrt(Vmax^2 - Vd^2) and vector
 * magnitudes; the bit length it starts from.  The per-period path compares
 * squares first and takes a root only where a limit really binds.
 */
#ifndef FOC_SQRT_H
#define FOC_SQRT_H

#include <stdint.h>
#include "foc/q15.h"

/* Number of significant bits of x > 0, 1..32 (CLZ where the compiler
 * has it). */
unsigned foc_bit_length(uint32_t x);

/* floor(sqrt(x)) for any 32-bit unsigned x; result fits 16 bits.
 * Newton's iteration from above, seeded from the bit length: three or four
 * 32/16-bit divisions. */
uint16_t foc_isqrt32(uint32_t x);

/* Magnitude of a Q15 vector, Q15, rounded down (never over-estimates),
 * saturated to 32767 (|(-1,-1)| > 1). */
q15_t foc_mag_q15(q15_t x, q15_t y);

#endif /* FOC_SQRT_H */
