/*
 * Register stub of the dsPIC33FJ32MC204, for `make dspic-check` only.
 *
 * With Microchip XC16, <xc.h> includes the device header p33FJ32MC204.h
 * (selected by -mcpu=33FJ32MC204), which declares every special-function
 * register (SFR) and its bit fields.  XC16 is not needed to check that the
 * port and board compile: this file stands in for <xc.h> on a host
 * compiler (gcc, or avr-gcc for a 16-bit `int` like XC16's).  It was
 * written from the register names of the dsPIC33FJ32MC202/204 data sheet
 * and the dsPIC33F family reference manual (sections 7 Oscillator, 11
 * Timers, 14 Motor Control PWM, 16 ADC, 17 UART, 10 I/O Ports with
 * Peripheral Pin Select); only the SFRs and bits the port and the board
 * use are declared, with the XC16 spellings (`P1TCON`, `P1TCONbits.PTEN`,
 * `IFS0bits.AD1IF`, `ADC1BUF0`...).
 *
 * Differences from XC16's header, none of which the port relies on:
 * SFRs are `uint16_t` here (XC16: `unsigned int`, also 16 bits); bit
 * fields are `unsigned int` fields (so a host struct is 32 bits wide);
 * registers are ordinary variables defined in stub_regs.c instead of
 * fixed addresses from the linker script; the compiler built-ins are
 * functions that only record what they were asked.  Nothing here runs on
 * a target: the check compiles and links, it does not execute.
 */
#ifndef DSPIC_STUB_XC_H
#define DSPIC_STUB_XC_H

#include <stdint.h>

#ifdef __XC16__
#error "hal/dspic33fj/stub/xc.h is the host stand-in; XC16 must use its own <xc.h>"
#endif

/* cppcheck-suppress misra-c2012-21.1 ; D5 toolchain name */
#define __dsPIC33FJ32MC204__ 1
#define DSPIC_STUB 1

/* --------------------------------------------------- CPU and system -- */
extern volatile uint16_t SR;
extern volatile uint16_t CORCON;
extern volatile uint16_t DISICNT;

extern volatile uint16_t RCON;
typedef struct {
    unsigned int POR : 1;
    unsigned int BOR : 1;
    unsigned int IDLE : 1;
    unsigned int SLEEP : 1;
    unsigned int WDTO : 1;
    unsigned int SWDTEN : 1;
    unsigned int SWR : 1;
    unsigned int EXTR : 1;
    unsigned int VREGS : 1;
    unsigned int CM : 1;
    unsigned int : 4;
    unsigned int IOPUWR : 1;
    unsigned int TRAPR : 1;
} RCONBITS;
extern volatile RCONBITS RCONbits;

/* ------------------------------------------------------- oscillator -- */
extern volatile uint16_t OSCCON;
typedef struct {
    unsigned int OSWEN : 1;
    unsigned int LPOSCEN : 1;
    unsigned int : 1;
    unsigned int CF : 1;
    unsigned int : 1;
    unsigned int LOCK : 1;
    unsigned int IOLOCK : 1;
    unsigned int CLKLOCK : 1;
    unsigned int NOSC : 3;
    unsigned int : 1;
    unsigned int COSC : 3;
    unsigned int : 1;
} OSCCONBITS;
extern volatile OSCCONBITS OSCCONbits;

extern volatile uint16_t CLKDIV;
typedef struct {
    unsigned int PLLPRE : 5;
    unsigned int : 1;
    unsigned int PLLPOST : 2;
    unsigned int FRCDIV : 3;
    unsigned int DOZEN : 1;
    unsigned int DOZE : 3;
    unsigned int ROI : 1;
} CLKDIVBITS;
extern volatile CLKDIVBITS CLKDIVbits;

extern volatile uint16_t PLLFBD; /* PLLDIV<8:0>: M = PLLDIV + 2 */
extern volatile uint16_t OSCTUN;

/* ------------------------------------------------------- interrupts -- */
extern volatile uint16_t INTCON1;
typedef struct {
    unsigned int : 1;
    unsigned int OSCFAIL : 1;
    unsigned int STKERR : 1;
    unsigned int ADDRERR : 1;
    unsigned int MATHERR : 1;
    unsigned int : 10;
    unsigned int NSTDIS : 1;
} INTCON1BITS;
extern volatile INTCON1BITS INTCON1bits;

extern volatile uint16_t IFS0;
typedef struct {
    unsigned int INT0IF : 1;
    unsigned int IC1IF : 1;
    unsigned int OC1IF : 1;
    unsigned int T1IF : 1;
    unsigned int : 1;
    unsigned int IC2IF : 1;
    unsigned int OC2IF : 1;
    unsigned int T2IF : 1;
    unsigned int T3IF : 1;
    unsigned int SPI1EIF : 1;
    unsigned int SPI1IF : 1;
    unsigned int U1RXIF : 1;
    unsigned int U1TXIF : 1;
    unsigned int AD1IF : 1;
    unsigned int : 2;
} IFS0BITS;
extern volatile IFS0BITS IFS0bits;

extern volatile uint16_t IEC0;
typedef struct {
    unsigned int INT0IE : 1;
    unsigned int IC1IE : 1;
    unsigned int OC1IE : 1;
    unsigned int T1IE : 1;
    unsigned int : 1;
    unsigned int IC2IE : 1;
    unsigned int OC2IE : 1;
    unsigned int T2IE : 1;
    unsigned int T3IE : 1;
    unsigned int SPI1EIE : 1;
    unsigned int SPI1IE : 1;
    unsigned int U1RXIE : 1;
    unsigned int U1TXIE : 1;
    unsigned int AD1IE : 1;
    unsigned int : 2;
} IEC0BITS;
extern volatile IEC0BITS IEC0bits;

/* IFS3: FLTA1IF (bit 15) is set when fault input A goes active; with the
 * fault in latched mode the PWM outputs stay in their fault states until
 * the input is inactive and this flag is cleared. */
extern volatile uint16_t IFS3;
typedef struct {
    unsigned int : 8;
    unsigned int QEI1IF : 1;
    unsigned int PWM1IF : 1;
    unsigned int : 5;
    unsigned int FLTA1IF : 1;
} IFS3BITS;
extern volatile IFS3BITS IFS3bits;

extern volatile uint16_t IEC3;
typedef struct {
    unsigned int : 8;
    unsigned int QEI1IE : 1;
    unsigned int PWM1IE : 1;
    unsigned int : 5;
    unsigned int FLTA1IE : 1;
} IEC3BITS;
extern volatile IEC3BITS IEC3bits;

extern volatile uint16_t IPC0;
typedef struct {
    unsigned int INT0IP : 3;
    unsigned int : 1;
    unsigned int IC1IP : 3;
    unsigned int : 1;
    unsigned int OC1IP : 3;
    unsigned int : 1;
    unsigned int T1IP : 3;
    unsigned int : 1;
} IPC0BITS;
extern volatile IPC0BITS IPC0bits;

extern volatile uint16_t IPC3;
typedef struct {
    unsigned int U1TXIP : 3;
    unsigned int : 1;
    unsigned int AD1IP : 3;
    unsigned int : 9;
} IPC3BITS;
extern volatile IPC3BITS IPC3bits;

/* ----------------------------------------------------------- timers -- */
extern volatile uint16_t TMR1;
extern volatile uint16_t PR1;
extern volatile uint16_t T1CON;
extern volatile uint16_t TMR2;
extern volatile uint16_t TMR3HLD; /* TMR3 latched when TMR2 is read (T32) */
extern volatile uint16_t TMR3;
extern volatile uint16_t PR2;
extern volatile uint16_t PR3;
extern volatile uint16_t T2CON; /* TON<15> TSIDL<13> TGATE<6> TCKPS<5:4> */
extern volatile uint16_t T3CON; /* T32<3> (T2CON only) TCS<1> */
typedef struct {
    unsigned int : 1;
    unsigned int TCS : 1;
    unsigned int : 1;
    unsigned int T32 : 1;
    unsigned int TCKPS : 2;
    unsigned int TGATE : 1;
    unsigned int : 6;
    unsigned int TSIDL : 1;
    unsigned int : 1;
    unsigned int TON : 1;
} T2CONBITS;
extern volatile T2CONBITS T2CONbits;

/* ------------------------------------------------ motor control PWM1 -- */
extern volatile uint16_t P1TCON; /* PTEN<15> PTSIDL<13> PTOPS<7:4> */
typedef struct {                 /* PTCKPS<3:2> PTMOD<1:0> */
    unsigned int PTMOD : 2;
    unsigned int PTCKPS : 2;
    unsigned int PTOPS : 4;
    unsigned int : 5;
    unsigned int PTSIDL : 1;
    unsigned int : 1;
    unsigned int PTEN : 1;
} P1TCONBITS;
extern volatile P1TCONBITS P1TCONbits;

extern volatile uint16_t P1TMR;  /* PTDIR<15> PTMR<14:0> */
extern volatile uint16_t P1TPER; /* PTPER<14:0> */
extern volatile uint16_t P1SECMP; /* SEVTDIR<15> SEVTCMP<14:0> */
extern volatile uint16_t PWM1CON1; /* PMOD3:1<10:8> PEN3H:1H<6:4> PEN3L:1L<2:0> */
extern volatile uint16_t PWM1CON2; /* SEVOPS<11:8> IUE<2> OSYNC<1> UDIS<0> */
extern volatile uint16_t P1DTCON1; /* DTBPS<15:14> DTB<13:8> DTAPS<7:6> DTA<5:0> */
extern volatile uint16_t P1DTCON2; /* DTS3A<5> DTS3I<4> ... DTS1I<0> */
extern volatile uint16_t P1FLTACON; /* FAOV3H..FAOV1L<13:8> FLTAM<7> FAEN3:1<2:0> */
extern volatile uint16_t P1OVDCON; /* POVD3H..POVD1L<13:8> POUT3H..POUT1L<5:0> */
extern volatile uint16_t P1DC1;
extern volatile uint16_t P1DC2;
extern volatile uint16_t P1DC3;

/* -------------------------------------------------------------- ADC1 -- */
extern volatile uint16_t ADC1BUF0;
extern volatile uint16_t ADC1BUF1;
extern volatile uint16_t ADC1BUF2;
extern volatile uint16_t ADC1BUF3;
#define ADCBUF0 ADC1BUF0
#define ADCBUF1 ADC1BUF1
#define ADCBUF2 ADC1BUF2
#define ADCBUF3 ADC1BUF3
extern volatile uint16_t AD1CON1; /* ADON<15> ADSIDL<13> AD12B<10> FORM<9:8> */
typedef struct {                  /* SSRC<7:5> SIMSAM<3> ASAM<2> SAMP<1> DONE<0> */
    unsigned int DONE : 1;
    unsigned int SAMP : 1;
    unsigned int ASAM : 1;
    unsigned int SIMSAM : 1;
    unsigned int : 1;
    unsigned int SSRC : 3;
    unsigned int FORM : 2;
    unsigned int AD12B : 1;
    unsigned int : 2;
    unsigned int ADSIDL : 1;
    unsigned int : 1;
    unsigned int ADON : 1;
} AD1CON1BITS;
extern volatile AD1CON1BITS AD1CON1bits;
extern volatile uint16_t AD1CON2;   /* VCFG<15:13> CSCNA<10> CHPS<9:8> SMPI<5:2> */
extern volatile uint16_t AD1CON3;   /* ADRC<15> SAMC<12:8> ADCS<7:0> */
extern volatile uint16_t AD1CHS123; /* CH123NB<10:9> CH123SB<8> CH123NA<2:1> CH123SA<0> */
extern volatile uint16_t AD1CHS0;   /* CH0NB<15> CH0SB<12:8> CH0NA<7> CH0SA<4:0> */
extern volatile uint16_t AD1PCFGL;  /* PCFG8:0, 1 = digital */
extern volatile uint16_t AD1CSSL;

/* ------------------------------------------------------------- UART1 -- */
extern volatile uint16_t U1MODE; /* UARTEN<15> BRGH<3> PDSEL<2:1> STSEL<0> */
extern volatile uint16_t U1STA;  /* UTXEN<10> UTXBF<9> TRMT<8> OERR<1> URXDA<0> */
typedef struct {
    unsigned int URXDA : 1;
    unsigned int OERR : 1;
    unsigned int FERR : 1;
    unsigned int PERR : 1;
    unsigned int RIDLE : 1;
    unsigned int ADDEN : 1;
    unsigned int URXISEL : 2;
    unsigned int TRMT : 1;
    unsigned int UTXBF : 1;
    unsigned int UTXEN : 1;
    unsigned int UTXBRK : 1;
    unsigned int : 1;
    unsigned int UTXISEL0 : 1;
    unsigned int UTXINV : 1;
    unsigned int UTXISEL1 : 1;
} U1STABITS;
extern volatile U1STABITS U1STAbits;
extern volatile uint16_t U1TXREG;
extern volatile uint16_t U1RXREG;
extern volatile uint16_t U1BRG;

/* -------------------------------------------------------- I/O ports -- */
extern volatile uint16_t TRISA;
extern volatile uint16_t PORTA;
extern volatile uint16_t LATA;
extern volatile uint16_t TRISB;
extern volatile uint16_t PORTB;
extern volatile uint16_t LATB;
extern volatile uint16_t TRISC;
extern volatile uint16_t PORTC;
extern volatile uint16_t LATC;

/* Peripheral pin select: inputs name the RPn pin a function reads,
 * outputs name the function an RPn pin drives (U1TX = 3). */
extern volatile uint16_t RPINR12;
typedef struct {
    unsigned int FLTA1R : 5;
    unsigned int : 11;
} RPINR12BITS;
extern volatile RPINR12BITS RPINR12bits;

extern volatile uint16_t RPINR18;
typedef struct {
    unsigned int U1RXR : 5;
    unsigned int : 3;
    unsigned int U1CTSR : 5;
    unsigned int : 3;
} RPINR18BITS;
extern volatile RPINR18BITS RPINR18bits;

extern volatile uint16_t RPOR10;
typedef struct {
    unsigned int RP20R : 5;
    unsigned int : 3;
    unsigned int RP21R : 5;
    unsigned int : 3;
} RPOR10BITS;
extern volatile RPOR10BITS RPOR10bits;

/* --------------------------------------------------------- built-ins -- */
/* XC16 built-ins the port uses (documented in the XC16 user's guide), as
 * host functions; ClrWdt() and Nop() are macros of XC16's device header. */
void __builtin_write_OSCCONH(uint8_t value);
void __builtin_write_OSCCONL(uint8_t value);
void __builtin_disi(uint16_t cycles);
void dspic_stub_clrwdt(void);
void dspic_stub_nop(void);
void dspic_stub_reset(void);
#define ClrWdt() dspic_stub_clrwdt()
#define Nop() dspic_stub_nop()

#endif /* DSPIC_STUB_XC_H */
