/*
 * dsPIC33FJ32MC204 configuration bits for the dsPICDEM MCLV (XC16
 * `#pragma config` names; see the "Configuration bits" table of the data
 * sheet and docs/boards/dspicdem_mclv.md).  Only XC16 reads them; the host
 * compile check (`make dspic-check`) sees only a placeholder declaration.
 */
#include <xc.h>

#ifdef __XC16__
/* FGS: no code protection */
#pragma config GWRP = OFF
#pragma config GSS = OFF

/* FOSCSEL: start on the internal FRC; main switches to XT + PLL */
#pragma config FNOSC = FRC
#pragma config IESO = OFF

/* FOSC: 8 MHz crystal (XT); clock switching and the fail-safe clock
 * monitor on (a failing crystal traps: outputs off, reset); peripheral
 * pin select locked once (IOL1WAY) */
#pragma config POSCMD = XT
#pragma config OSCIOFNC = OFF
#pragma config IOL1WAY = ON
#pragma config FCKSM = CSECME

/* FWDT: 32 kHz / 32 / 64 = 64 ms; enabled by software (RCON.SWDTEN) once
 * the controller runs, so a debugger halt at start-up does not reset */
#pragma config WDTPOST = PS64
#pragma config WDTPRE = PR32
#pragma config WINDIS = OFF
#pragma config FWDTEN = OFF

/* FPOR: 128 ms power-up timer; PWM outputs active high on both sides (the
 * MCLV gate drivers); PWM pins tri-stated at reset, under the port pins
 * until the MCPWM takes them */
#pragma config FPWRT = PWR128
#pragma config ALTI2C = OFF
#pragma config LPOL = ON
#pragma config HPOL = ON
#pragma config PWMPIN = ON

/* FICD: the PIM wires PGEC3/PGED3 (RB6/RB5) to the ICSP header */
#pragma config ICS = PGD3
#pragma config JTAGEN = OFF

#else
/* ISO C wants at least one declaration in a translation unit. */
typedef int dspic_config_bits_host_check;
#endif
