/*
 * Space-vector modulation: the sector table (the modulator is inline in
 * foc/svm.h).
 */
#include "foc/svm.h"

/* Sector by the phases holding the largest and the smallest value
 * (0 = a, 1 = b, 2 = c): a max / c min is [0, 60) deg, b max / c min is
 * [60, 120) deg, and so on.  The diagonal is the zero vector. */
const uint8_t foc_svm_sector_of[3][3] = {
    /* min: a  b  c */
    { 1, 6, 1 }, /* max a */
    { 3, 1, 2 }, /* max b */
    { 4, 5, 1 }, /* max c */
};
