/*
 * Definitions of the register stub's SFRs and built-ins (xc.h), so that
 * `make dspic-check` can link the port, the board and the core into one
 * host image and catch a missing function.  The image is never run.
 * One definition per declaration of xc.h; keep the two in step.
 */
#include <xc.h>

volatile uint16_t SR;
volatile uint16_t CORCON;
volatile uint16_t DISICNT;
volatile uint16_t RCON;
volatile RCONBITS RCONbits;
volatile uint16_t OSCCON;
volatile OSCCONBITS OSCCONbits;
volatile uint16_t CLKDIV;
volatile CLKDIVBITS CLKDIVbits;
volatile uint16_t PLLFBD;
volatile uint16_t OSCTUN;
volatile uint16_t INTCON1;
volatile INTCON1BITS INTCON1bits;
volatile uint16_t IFS0;
volatile IFS0BITS IFS0bits;
volatile uint16_t IEC0;
volatile IEC0BITS IEC0bits;
volatile uint16_t IFS3;
volatile IFS3BITS IFS3bits;
volatile uint16_t IEC3;
volatile IEC3BITS IEC3bits;
volatile uint16_t IPC0;
volatile IPC0BITS IPC0bits;
volatile uint16_t IPC3;
volatile IPC3BITS IPC3bits;
volatile uint16_t TMR1;
volatile uint16_t PR1;
volatile uint16_t T1CON;
volatile uint16_t TMR2;
volatile uint16_t TMR3HLD;
volatile uint16_t TMR3;
volatile uint16_t PR2;
volatile uint16_t PR3;
volatile uint16_t T2CON;
volatile uint16_t T3CON;
volatile T2CONBITS T2CONbits;
volatile uint16_t P1TCON;
volatile P1TCONBITS P1TCONbits;
volatile uint16_t P1TMR;
volatile uint16_t P1TPER;
volatile uint16_t P1SECMP;
volatile uint16_t PWM1CON1;
volatile uint16_t PWM1CON2;
volatile uint16_t P1DTCON1;
volatile uint16_t P1DTCON2;
volatile uint16_t P1FLTACON;
volatile uint16_t P1OVDCON;
volatile uint16_t P1DC1;
volatile uint16_t P1DC2;
volatile uint16_t P1DC3;
volatile uint16_t ADC1BUF0;
volatile uint16_t ADC1BUF1;
volatile uint16_t ADC1BUF2;
volatile uint16_t ADC1BUF3;
volatile uint16_t AD1CON1;
volatile AD1CON1BITS AD1CON1bits;
volatile uint16_t AD1CON2;
volatile uint16_t AD1CON3;
volatile uint16_t AD1CHS123;
volatile uint16_t AD1CHS0;
volatile uint16_t AD1PCFGL;
volatile uint16_t AD1CSSL;
volatile uint16_t U1MODE;
volatile uint16_t U1STA;
volatile U1STABITS U1STAbits;
volatile uint16_t U1TXREG;
volatile uint16_t U1RXREG;
volatile uint16_t U1BRG;
volatile uint16_t TRISA;
volatile uint16_t PORTA;
volatile uint16_t LATA;
volatile uint16_t TRISB;
volatile uint16_t PORTB;
volatile uint16_t LATB;
volatile uint16_t TRISC;
volatile uint16_t PORTC;
volatile uint16_t LATC;
volatile uint16_t RPINR12;
volatile RPINR12BITS RPINR12bits;
volatile uint16_t RPINR18;
volatile RPINR18BITS RPINR18bits;
volatile uint16_t RPOR10;
volatile RPOR10BITS RPOR10bits;

void __builtin_write_OSCCONH(uint8_t value)
{
    OSCCON = (uint16_t)((OSCCON & 0x00FFu) | (uint16_t)((uint16_t)value << 8));
}

void __builtin_write_OSCCONL(uint8_t value)
{
    OSCCON = (uint16_t)((OSCCON & 0xFF00u) | value);
}

void __builtin_disi(uint16_t cycles)
{
    DISICNT = cycles;
}

void dspic_stub_clrwdt(void)
{
}

void dspic_stub_nop(void)
{
}

void dspic_stub_reset(void)
{
}
