/*
 * The dsPIC33 estimator's hand-worked case (tests/bench/dspic_est.sh): a
 * saturating multiply-accumulate whose dsPIC33F cycle count is derived by
 * hand from the instruction sequence XC16 would emit under the estimator's
 * model (docs/benchmarks.md, "dsPIC33 estimate"): locals and arguments in
 * W registers, each source access to memory a load or store of its words
 * (no reuse across statements), cycles from DS70157 (16-bit MCU and DSC
 * Programmer's Reference Manual):
 *
 *   m->acc += (int32_t)m->k * x;
 *       MOV [W0+0],W2            load k                       1
 *       MUL.SS W2,W1,W4          16x16 -> 32                  1
 *       MOV [W0+2],W6 / [W0+4],W7  load acc, 2 words          2
 *       ADD W4,W6,W6 / ADDC W5,W7,W7  32-bit add              2
 *       MOV W6,[W0+2] / W7,[W0+4]  store acc, 2 words         2   = 8
 *   if (m->acc > m->limit)
 *       MOV x2                   load acc again               2
 *       MOV x2                   load limit                   2
 *       CP W6,W2 / CPB W7,W3     32-bit compare               2
 *       BRA LE                   1 not taken, 2 taken: 1.5    1.5 = 7.5
 *       m->acc = m->limit;       load limit, store acc        4   (when taken)
 *   return m->acc >> 4;
 *       MOV x2                   load acc                     2
 *       LSR W6,#4,W0 / SL W7,#12,W2 / IOR W2,W0,W0 / ASR W7,#4,W1   4 = 6
 *
 * Per call 8 + 7.5 + 6 = 21.5, plus 4 when the accumulator saturates.
 * hand_main.c: k = 1000, x = 100, limit = 1,000,000, 100 calls: the
 * accumulator passes the limit at the 11th call, so 90 calls saturate:
 * (100 x 21.5 + 90 x 4) / 100 = 25.10 cycles per call.
 */
#include "hand.h"

int32_t mac_step(mac_t *m, int16_t x)
{
    m->acc += (int32_t)m->k * x;
    if (m->acc > m->limit) {
        m->acc = m->limit;
    }
    return m->acc >> 4;
}
