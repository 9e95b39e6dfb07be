/*
 * dsPIC33FJ port: the pure logic behind the port functions, kept apart
 * from the special-function registers so a host test can run it.
 *
 * The run-time port functions (port.h) touch a handful of registers: the
 * three duty-cycle registers, the override register, the fault flag, the
 * fault pin and four ADC buffers.  They reach them through dspic_regs_t,
 * a set of pointers; on the target the pointers hold the SFR addresses
 * (dspic33fj.c), in a test they point at plain variables.  Everything
 * else here is arithmetic on register values, written for a 16-bit `int`
 * (XC16) as well as a 32-bit one: every product is formed in int32_t or
 * uint32_t, and no signed value is shifted left.
 *
 * Register facts used (dsPIC33FJ32MC202/204 data sheet and the dsPIC33F
 * family reference manual, section 14 "Motor Control PWM", section 16
 * "Analog-to-Digital Converter"):
 *  - ADC signed fractional format (AD1CON1.FORM = 3): the 10-bit code c
 *    (0..1023, 0 V..AVdd) is returned as (c - 512) x 64 in a 16-bit word,
 *    "sddd dddd dd00 0000", i.e. -32768..32704 as int16_t.
 *  - MCPWM in continuous up/down count mode (PTMOD = 2): the time base
 *    counts 0..PTPER..0, one PWM period is 2 (PTPER + 1) instruction
 *    cycles (Tcy), PTPER = Fcy / (2 Fpwm) - 1.  A PxDCy value compares
 *    with the time base at twice its resolution (PDC<15:1> against PTMR,
 *    PDC<0> selects the half-cycle edge), so 100 % duty is
 *    PDC = 2 (PTPER + 1): one PDC count is one Tcy of high-side on-time.
 *  - P1OVDCON: POVDxH/L (bits 13..8) = 1 lets the PWM generator drive the
 *    pin; 0 overrides it with POUTxH/L (bits 5..0).  Bit order, high to
 *    low: 3H 3L 2H 2L 1H 1L.
 *  - Fault A in latched mode (P1FLTACON.FLTAM = 0): the pin going low
 *    drives the outputs to their fault states (all inactive here) in
 *    hardware and sets IFS3.FLTA1IF (bit 15); the outputs stay there
 *    until the pin is high again and the flag is cleared.
 *  - P1DTCON1 dead time unit A: DTAPS<7:6> prescaler 1, 2, 4, 8 Tcy,
 *    DTA<5:0> count 0..63.
 *  - UART with BRGH = 1: baud = Fcy / (4 (UxBRG + 1)).
 */
#ifndef DSPIC_LOGIC_H
#define DSPIC_LOGIC_H

#include <stdint.h>
#include "foc/port.h"

/* P1OVDCON values. */
#define DSPIC_OVD_PWM 0x3F00u       /* all six pins driven by the PWM */
#define DSPIC_OVD_ALL_OFF 0x0000u   /* all six overridden inactive */
#define DSPIC_OVD_LOW_SIDES 0x0015u /* overridden: POUT1L, 2L, 3L on */

/* IFS3 bit of the fault A flag. */
#define DSPIC_IFS3_FLTA1IF 0x8000u

/* The registers the run-time port functions read and write. */
typedef struct {
    volatile uint16_t *pdc[3];          /* P1DC1, P1DC2, P1DC3 */
    volatile uint16_t *ovdcon;          /* P1OVDCON */
    volatile uint16_t *ifs3;            /* holds FLTA1IF */
    volatile const uint16_t *fault_port; /* PORTx of the fault pin */
    uint16_t fault_pin_mask;            /* its bit; the pin is active low */
    volatile const uint16_t *adcbuf[4]; /* ADC1BUF0..3 */
} dspic_regs_t;

/* Which ADC buffer holds which signal, and the board's analog facts. */
typedef struct {
    const dspic_regs_t *regs;
    uint16_t pdc_full;      /* PDC value of 100 % duty, 2 (PTPER + 1) */
    uint8_t buf_ia;         /* ADC1BUFn of phase A current */
    uint8_t buf_ib;         /* ADC1BUFn of phase B current */
    uint8_t buf_vdc;        /* ADC1BUFn of the bus voltage */
    uint8_t buf_pot;        /* ADC1BUFn of the potentiometer */
    uint8_t current_inverted; /* 1: the amplifier output falls when */
                              /* current flows into the motor */
} dspic_port_cfg_t;

/* ---------------------------------------------------- ADC scaling -- */
/* Signed fractional ADC word -> phase current, Q15 of the current full
 * scale, positive into the motor.  The mid-scale code 512 (the amplifier's
 * nominal zero) reads 0; the amplifier's own offset stays in (the core
 * calibrates it).  inverted = 1 negates (saturating: code 0, word -32768,
 * reads +32767). */
q15_t dspic_adc_current_q15(uint16_t word, uint8_t inverted);

/* Signed fractional ADC word of a unipolar signal (0 V..AVdd) -> Q15
 * fraction of the ADC full scale, code x 32: 0..32736. */
q15_t dspic_adc_unipolar_q15(uint16_t word);

/* ----------------------------------------------------------- PWM -- */
/* PTPER for a PWM frequency in up/down count mode, prescaler 1:1,
 * truncated (the period is never longer than asked); 0 outside 2..0x7FFE
 * (the range where 2 (PTPER + 1) fits a 16-bit PDC). */
uint16_t dspic_pwm_ptper(uint32_t fcy_hz, uint32_t fpwm_hz);

/* PDC value of 100 % duty for a PTPER (0xFFFF at most). */
uint16_t dspic_pwm_pdc_full(uint16_t ptper);

/* Q15 duty (fraction of the period, [0, 32767]) -> PDC value in
 * [0, pdc_full], rounded to nearest; negative duties give 0. */
uint16_t dspic_duty_to_pdc(q15_t duty, uint16_t pdc_full);

/* P1DTCON1 low byte (DTAPS, DTA) for a dead time of at least `tcy`
 * instruction cycles, with the finest prescaler that reaches it;
 * 0xFFFF if it exceeds 63 x 8 Tcy. */
uint16_t dspic_deadtime_dtcon(uint16_t tcy);

/* Dead time in Tcy that a P1DTCON1 low byte gives. */
uint16_t dspic_deadtime_tcy(uint16_t dtcon);

/* ---------------------------------------------------------- UART -- */
/* UxBRG for a baud rate with BRGH = 1, rounded to nearest; 0xFFFF when
 * out of range. */
uint16_t dspic_uart_brg(uint32_t fcy_hz, uint32_t baud);

/* ----------------------------------------- run-time port functions -- */
/* These implement port.h on the registers of `cfg`. */
void dspic_read_samples(const dspic_port_cfg_t *cfg, foc_samples_t *s);
void dspic_set_duties(const dspic_port_cfg_t *cfg, const foc_duty_t *d);

/* Outputs to the PWM generator, unless the fault latch holds them off. */
void dspic_pwm_enable(const dspic_port_cfg_t *cfg);
/* All six switches off (override), at once. */
void dspic_pwm_disable(const dspic_port_cfg_t *cfg);
/* Low sides on, high sides off, unless the fault latch holds them off. */
void dspic_low_sides_on(const dspic_port_cfg_t *cfg);

/* 1 while the fault flag is set or the fault pin is active. */
uint8_t dspic_fault_latched(const dspic_port_cfg_t *cfg);
/* Clears the fault flag if the pin is inactive, after overriding all
 * outputs off (so they stay off until enabled); nothing while the pin is
 * active. */
void dspic_fault_clear(const dspic_port_cfg_t *cfg);

/* ------------------------------------------- execution-time stats -- */
/* Minimum, maximum and mean of a duration in timer ticks; the mean is
 * published every 2^DSPIC_STATS_LOG2 samples (the sum cannot overflow:
 * 2^10 x 65535 < 2^32). */
#define DSPIC_STATS_LOG2 10u
typedef struct {
    uint16_t min;
    uint16_t max;
    uint16_t avg;   /* mean of the last complete window, 0 before */
    uint32_t sum;
    uint16_t count;
} dspic_stats_t;

void dspic_stats_reset(dspic_stats_t *st);
/* Adds one duration (end - start of a wrapping 32-bit time base;
 * clamped to 65535 ticks). */
void dspic_stats_add(dspic_stats_t *st, uint32_t start, uint32_t end);

#endif /* DSPIC_LOGIC_H */
