/*
 * Sine, cosine and atan2 on 16-bit angles (65536 counts = one turn).
 * Both use a table with linear interpolation; see foc/trig.h for accuracy.
 * Sine and cosine are inline in foc/trig.h (the fast step calls them every
 * period); their table is here.
 */
#include "foc/trig.h"

/* 90 degrees, in angle counts. */
#define QUARTER_TURN 16384u

/*
 * sin over one quarter wave, 128 steps of 128 counts (512 points per turn):
 * foc_sin_table[i] = min(32767, round(32768 sin(2 pi i / 512))), i = 0..128,
 * computed with
 *   python3 -c "import math; print([min(32767, round(32768 *
 *               math.sin(2 * math.pi * i / 512))) for i in range(129)])"
 * The last entry repeats point 128 so that index 128 can be read with a zero
 * fraction without a special case.  Q15.
 */
const int16_t foc_sin_table[130] = {
        0,   402,   804,  1206,  1608,  2009,  2411,  2811,
     3212,  3612,  4011,  4410,  4808,  5205,  5602,  5998,
     6393,  6787,  7180,  7571,  7962,  8351,  8740,  9127,
     9512,  9896, 10279, 10660, 11039, 11417, 11793, 12167,
    12540, 12910, 13279, 13646, 14010, 14373, 14733, 15091,
    15447, 15800, 16151, 16500, 16846, 17190, 17531, 17869,
    18205, 18538, 18868, 19195, 19520, 19841, 20160, 20475,
    20788, 21097, 21403, 21706, 22006, 22302, 22595, 22884,
    23170, 23453, 23732, 24008, 24279, 24548, 24812, 25073,
    25330, 25583, 25833, 26078, 26320, 26557, 26791, 27020,
    27246, 27467, 27684, 27897, 28106, 28311, 28511, 28707,
    28899, 29086, 29269, 29448, 29622, 29792, 29957, 30118,
    30274, 30425, 30572, 30715, 30853, 30986, 31114, 31238,
    31357, 31471, 31581, 31686, 31786, 31881, 31972, 32058,
    32138, 32214, 32286, 32352, 32413, 32470, 32522, 32568,
    32610, 32647, 32679, 32706, 32729, 32746, 32758, 32766,
    32767, 32767
};


/*
 * atan over one octant, 32 steps of the ratio r = min/max in [0, 1]:
 * ATAN_TABLE[i] = round(atan(i / 32) * 32768 / pi) angle counts, i = 0..32,
 * computed with
 *   python3 -c "import math; print([round(math.atan(i / 32) * 32768 /
 *               math.pi) for i in range(33)])"
 * The last entry repeats point 32 (r = 1 read with a zero fraction).
 */
static const uint16_t ATAN_TABLE[34] = {
       0,  326,  651,  975, 1297, 1617, 1933, 2246,
    2555, 2860, 3159, 3453, 3742, 4025, 4302, 4572,
    4836, 5094, 5344, 5589, 5826, 6058, 6282, 6500,
    6712, 6917, 7117, 7310, 7498, 7679, 7856, 8026,
    8192, 8192
};

/* atan(num / den) in angle counts, [0, 8192], for 0 <= num <= den, den > 0. */
static uint16_t octant_atan(uint32_t num, uint32_t den)
{
    /* The one division: ratio Q15 in [0, 32768], rounded.  den <= 32768
     * and the quotient fits 16 bits: a 32/16-bit divide instruction. */
    const uint32_t r = (num * 32768u + (den >> 1)) / den;
    const uint32_t i = r >> 10;                      /* table step, 0..32 */
    const uint32_t frac = r & 1023u;                 /* 10 bits */
    const uint32_t y0 = ATAN_TABLE[i];               /* counts */
    const uint32_t dy = ATAN_TABLE[i + 1u] - y0;     /* counts, 0..326 */
    return (uint16_t)(y0 + ((dy * frac + 512u) >> 10));
}

uint16_t foc_atan2_q15(q15_t y, q15_t x)
{
    /* Magnitudes as unsigned, so that -32768 gives 32768. */
    const uint32_t ax = (x < 0) ? (uint32_t)(-(int32_t)x) : (uint32_t)x;
    const uint32_t ay = (y < 0) ? (uint32_t)(-(int32_t)y) : (uint32_t)y;
    uint16_t a; /* angle in the first quadrant, counts, [0, QUARTER_TURN] */

    if (ax == 0u && ay == 0u) {
        return 0u;
    }
    if (ay <= ax) {
        a = octant_atan(ay, ax);
    } else {
        a = (uint16_t)(QUARTER_TURN - octant_atan(ax, ay));
    }
    /* Mirror into the quadrant of (x, y); the angle wraps modulo 2^16. */
    if (x < 0) {
        a = (uint16_t)(2u * QUARTER_TURN - a);
    }
    if (y < 0) {
        a = (uint16_t)(0u - a);
    }
    return a;
}
