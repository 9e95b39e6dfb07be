#include "dspic33fj.h"

#include <xc.h>

#include "board.h"
#include "foc/port.h"

#ifdef __XC16__
#define DSPIC_ISR __attribute__((interrupt, no_auto_psv))
#define DSPIC_RESET() __asm__ volatile("reset")
#else
#define DSPIC_ISR
#define DSPIC_RESET() dspic_stub_reset()
#endif
/* Keeps the compiler from caching memory across it. */
#define DSPIC_BARRIER() __asm__ volatile("" ::: "memory")

/* Register values (bit positions in dspic_logic.h and the stub). */
#define P1TCON_UPDOWN 0x0002u     /* PTMOD = 2: continuous up/down */
#define P1TCON_PTEN 0x8000u
#define PWM1CON1_COMPL_ALL 0x0077u /* PEN1H..3H, PEN1L..3L, PMODx = 0 */
#define PWM1CON2_VALUE 0x0000u    /* SEVOPS 1:1, override at once, */
                                  /* duties at the period boundary */
#define P1FLTACON_LATCHED 0x0007u /* FAEN1..3, FLTAM = 0, FAOVxx = 0 */
#define AD1CON1_VALUE 0x036Cu     /* FORM = 3 (signed fractional), */
                                  /* SSRC = 3 (MCPWM special event), */
                                  /* SIMSAM, ASAM, 10-bit */
#define AD1CON1_ADON 0x8000u
#define AD1CON2_VALUE 0x0200u     /* AVdd/AVss, CHPS = 2 (CH0..CH3), */
                                  /* SMPI = 0: one interrupt per sequence */
#define AD1PCFGL_ALL_DIGITAL 0x01FFu
#define T2CON_T32 0x0008u
#define T2CON_TON 0x8000u
#define U1MODE_BRGH 0x0008u       /* 8N1, BRGH = 1 */
#define U1MODE_UARTEN 0x8000u
#define U1STA_UTXEN 0x0400u
#define OSCCON_IOLOCK 0x40u
#define OSCCON_OSWEN 0x01u
#define OSC_PRIPLL 0x03u          /* NOSC/COSC: primary oscillator + PLL */
#define RPOR_U1TX 3u              /* output function number of U1TX */

#define PDC_FULL ((uint16_t)(2u * (BOARD_PTPER + 1u)))

FOC_STATIC_ASSERT(BOARD_U1TX_RP == 20u,
                  "BOARD_U1TX_RP changed: map U1TX in dspic_pps_init() to its RPORn");

static const dspic_regs_t regs = {
    { &P1DC1, &P1DC2, &P1DC3 },
    &P1OVDCON,
    &IFS3,
    &PORTB,
    BOARD_FLTA_PORTB_MASK,
    { &ADC1BUF0, &ADC1BUF1, &ADC1BUF2, &ADC1BUF3 },
};

static const dspic_port_cfg_t cfg = {
    &regs,
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    PDC_FULL,
    BOARD_ADC_BUF_IA,
    BOARD_ADC_BUF_IB,
    BOARD_ADC_BUF_VDC,
    BOARD_ADC_BUF_POT,
    BOARD_CURRENT_INVERTED,
};

static foc_ctrl_t *ctrl;
static uint8_t slow_div;
static volatile uint16_t slow_count;
static volatile uint16_t slow_overruns;
static dspic_stats_t fast_stats; /* ISR-owned; copied under DISI */
static volatile q15_t debug_out[2];
static uint16_t rcon_at_reset;

/* Interrupt and trap handlers (names from the XC16 vector table). */
void DSPIC_ISR _ADC1Interrupt(void);
void DSPIC_ISR _T1Interrupt(void);
void DSPIC_ISR _OscillatorFail(void);
void DSPIC_ISR _AddressError(void);
void DSPIC_ISR _StackError(void);
void DSPIC_ISR _MathError(void);
void DSPIC_ISR _DefaultInterrupt(void);

/* ------------------------------------------------------------ set-up -- */
static void clock_init(void)
{
    /* FRC at reset (FOSCSEL); program the PLL, then switch to XT + PLL. */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    PLLFBD = (uint16_t)(BOARD_PLL_M - 2u);
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    CLKDIV = (uint16_t)(BOARD_PLL_N1 - 2u); /* PLLPOST = 0: N2 = 2 */
    __builtin_write_OSCCONH(OSC_PRIPLL);
    __builtin_write_OSCCONL((uint8_t)(OSCCON | OSCCON_OSWEN));
    while (OSCCONbits.COSC != OSC_PRIPLL) {
    }
    while (OSCCONbits.LOCK != 1u) {
    }
}

static void pps_init(void)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    __builtin_write_OSCCONL((uint8_t)(OSCCON & (uint16_t)~OSCCON_IOLOCK));
    RPINR12bits.FLTA1R = BOARD_FLTA_RP;
    RPINR18bits.U1RXR = BOARD_U1RX_RP;
    RPOR10bits.RP20R = RPOR_U1TX;
    __builtin_write_OSCCONL((uint8_t)(OSCCON | OSCCON_IOLOCK));
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    TRISC = (uint16_t)((TRISC | BOARD_U1RX_TRISC_MASK) & (uint16_t)~BOARD_U1TX_TRISC_MASK);
}

static void pwm_init(void)
{
    P1TCON = 0;
    P1TMR = 0;
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    P1TPER = BOARD_PTPER;
    P1OVDCON = DSPIC_OVD_ALL_OFF; /* first: pins stay off when handed over */
    PWM1CON2 = PWM1CON2_VALUE;
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    P1DTCON1 = dspic_deadtime_dtcon(BOARD_DEADTIME_TCY);
    P1DTCON2 = 0;
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    P1DC1 = (uint16_t)(PDC_FULL / 2u);
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    P1DC2 = (uint16_t)(PDC_FULL / 2u);
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    P1DC3 = (uint16_t)(PDC_FULL / 2u);
    /* counting up (SEVTDIR = 0), just before the top */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    P1SECMP = (uint16_t)(BOARD_PTPER - BOARD_ADC_TRIGGER_OFFSET_TCY);
    P1FLTACON = P1FLTACON_LATCHED;
    PWM1CON1 = PWM1CON1_COMPL_ALL;
    IFS3bits.FLTA1IF = 0;
    P1TCON = (uint16_t)(P1TCON_UPDOWN | P1TCON_PTEN);
}

static void adc_init(void)
{
    AD1CON1 = AD1CON1_VALUE;
    AD1CON2 = AD1CON2_VALUE;
    AD1CON3 = BOARD_ADC_ADCS;
    AD1CHS123 = 0;                 /* CH1 = AN0, CH2 = AN1, CH3 = AN2 */
    AD1CHS0 = BOARD_ADC_CH0_AN;    /* CH0 = AN8 */
    AD1CSSL = 0;
    AD1PCFGL = (uint16_t)(AD1PCFGL_ALL_DIGITAL & (uint16_t)~BOARD_ADC_ANALOG_PINS);
    IFS0bits.AD1IF = 0;
    IPC3bits.AD1IP = BOARD_IPL_FAST;
    AD1CON1 = (uint16_t)(AD1CON1_VALUE | AD1CON1_ADON);
}

static void timers_init(void)
{
    T2CON = 0;
    T3CON = 0;
    TMR3 = 0;
    TMR2 = 0;
    PR3 = 0xFFFFu;
    PR2 = 0xFFFFu;
    T2CON = T2CON_T32;
    T2CON = (uint16_t)(T2CON_T32 | T2CON_TON);

    T1CON = 0; /* Timer1 stays off: its vector is the slow-step interrupt */
    IFS0bits.T1IF = 0;
    IPC0bits.T1IP = BOARD_IPL_SLOW;
}

static void uart_init(void)
{
    U1MODE = U1MODE_BRGH;
    U1BRG = dspic_uart_brg(BOARD_FCY_HZ, BOARD_UART_BAUD);
    U1MODE = (uint16_t)(U1MODE_BRGH | U1MODE_UARTEN);
    U1STA = U1STA_UTXEN;
}

void dspic_init(void)
{
    rcon_at_reset = RCON;
    RCON = 0;
    clock_init();
    pps_init();
    pwm_init();
    adc_init();
    timers_init();
    uart_init();
    dspic_stats_reset(&fast_stats);
}

void dspic_start(foc_ctrl_t *c)
{
    ctrl = c;
    slow_div = 0;
    IFS0bits.T1IF = 0;
    IEC0bits.T1IE = 1;
    IFS0bits.AD1IF = 0;
    IEC0bits.AD1IE = 1;
}

/* ------------------------------------------------------- interrupts -- */
void DSPIC_ISR _ADC1Interrupt(void)
{
    const uint32_t t0 = foc_port_timestamp();
    IFS0bits.AD1IF = 0;
    foc_fast_step(ctrl);
    slow_div++;
    if (slow_div >= (uint8_t)CONTROL_SLOW_DIVIDER) {
        slow_div = 0;
        if (IFS0bits.T1IF != 0u) {
            slow_overruns++; /* the previous slow step has not started */
        }
        IFS0bits.T1IF = 1;
    }
    dspic_stats_add(&fast_stats, t0, foc_port_timestamp());
}

void DSPIC_ISR _T1Interrupt(void)
{
    IFS0bits.T1IF = 0;
    foc_slow_step(ctrl);
    slow_count++;
}

static void trap(void)
{
    P1OVDCON = DSPIC_OVD_ALL_OFF;
    P1TCON = 0;
    DSPIC_RESET();
}

void DSPIC_ISR _OscillatorFail(void)
{
    trap();
}

void DSPIC_ISR _AddressError(void)
{
    trap();
}

void DSPIC_ISR _StackError(void)
{
    trap();
}

void DSPIC_ISR _MathError(void)
{
    trap();
}

void DSPIC_ISR _DefaultInterrupt(void)
{
    trap();
}

/* ------------------------------------------------------- accessors -- */
void dspic_fast_stats(dspic_stats_t *out)
{
    __builtin_disi(0x3FFFu);
    DSPIC_BARRIER();
    *out = fast_stats;
    DSPIC_BARRIER();
    DISICNT = 0;
}

uint16_t dspic_slow_count(void)
{
    return slow_count;
}

uint16_t dspic_slow_overruns(void)
{
    return slow_overruns;
}

void dspic_debug_values(q15_t *ch1, q15_t *ch2)
{
    *ch1 = debug_out[0];
    *ch2 = debug_out[1];
}

uint16_t dspic_reset_cause(void)
{
    return rcon_at_reset;
}

void dspic_watchdog_enable(void)
{
    RCONbits.SWDTEN = 1;
}

void dspic_watchdog_clear(void)
{
    ClrWdt();
}

uint8_t dspic_uart_read(uint8_t *ch)
{
    if (U1STAbits.OERR != 0u) {
        U1STAbits.OERR = 0; /* overrun stops reception until cleared */
    }
    if (U1STAbits.URXDA == 0u) {
        return 0;
    }
    *ch = (uint8_t)(U1RXREG & 0xFFu);
    return 1;
}

uint8_t dspic_uart_write(uint8_t ch)
{
    if (U1STAbits.UTXBF != 0u) {
        return 0;
    }
    U1TXREG = ch;
    return 1;
}

/* --------------------------------------------------------- port.h -- */
void foc_port_read_samples(foc_samples_t *s)
{
    dspic_read_samples(&cfg, s);
}

void foc_port_set_duties(const foc_duty_t *d)
{
    dspic_set_duties(&cfg, d);
}

/* The ADC samples just before the top of the count (P1SECMP, counting
 * up); the duties load at the bottom (PTMR = 0), half a period later:
 * waits (at most a period, Timer2/3 at Fcy) for the time base to count up
 * in its lower half.  An override at once would apply the period's old
 * duties to a turning rotor until then (OSYNC = 1 would act at the top
 * too, in the centre-aligned modes). */
static void wait_for_bottom(void)
{
    const uint32_t t0 = foc_port_timestamp();
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    while (((P1TMR & 0x8000u) != 0u || (P1TMR & 0x7FFFu) >= (uint16_t)(BOARD_PTPER / 2u)) &&
           /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
           foc_port_timestamp() - t0 < 2uL * ((uint32_t)BOARD_PTPER + 1uL)) {
        /* counting down, or up in the upper half */
    }
}

void foc_port_pwm_enable(void)
{
    wait_for_bottom();
    dspic_pwm_enable(&cfg);
}

/* The bottom is also half a period after the sample. */
void foc_port_pwm_enable_at_half(void)
{
    foc_port_pwm_enable();
}

void foc_port_pwm_disable(void)
{
    dspic_pwm_disable(&cfg);
}

void foc_port_low_sides_on(void)
{
    dspic_low_sides_on(&cfg);
}

void foc_port_brake_resistor(uint8_t on)
{
    (void)on; /* the MCLV has no brake resistor */
}

uint8_t foc_port_overcurrent_latched(void)
{
    return dspic_fault_latched(&cfg);
}

void foc_port_overcurrent_clear(void)
{
    dspic_fault_clear(&cfg);
}

void foc_port_debug_out(q15_t ch1, q15_t ch2)
{
    debug_out[0] = ch1;
    debug_out[1] = ch2;
}

uint32_t foc_port_timestamp(void)
{
    uint16_t lo;
    uint16_t hi;
    /* Reading TMR2 latches TMR3 into TMR3HLD: no interrupt in between. */
    __builtin_disi(0x3FFFu);
    lo = TMR2;
    hi = TMR3HLD;
    DISICNT = 0;
    return ((uint32_t)hi << 16) | lo;
}
