/*
 * focsim scenario language.
 *
 * One command per line; `#` starts a comment (whole line or trailing); blank
 * lines are ignored; fields are separated by spaces or tabs (CRLF line ends
 * are accepted).  Every command starts with the time, in seconds, at which
 * it is applied (a non-negative finite decimal number: `0`, `0.25`, `1e-3`):
 *
 *   <t> start                  start the drive
 *   <t> stop                   stop the drive
 *   <t> speed <rpm>            speed reference, mechanical rpm, signed
 *   <t> load <Nm>              passive (braking) load torque magnitude, >= 0
 *   <t> lock                   hold the rotor at standstill
 *   <t> unlock                 release the rotor
 *   <t> vdc <volts>            DC source voltage, > 0
 *   <t> temp <degC>            temperature, > -273.15
 *   <t> overcurrent            trigger the hardware overcurrent input
 *   <t> ack                    acknowledge a fault
 *   <t> angle <deg>            set the rotor angle
 *   <t> spin <rpm>             drive the rotor externally at <rpm>, signed
 *   <t> plant <param> <value>  change a motor-model parameter, SI units:
 *          rs (ohm, > 0)   ld, lq (H, > 0)   flux (Wb, > 0)
 *          j (kg m^2, > 0) b (N m s/rad, >= 0)
 *          deadtime (s, >= 0)  noise (ADC codes sigma, >= 0)
 *          buscap (DC-link capacitance, F, >= 0; 0 = stiff bus)
 *          brakeres (brake resistor, ohm, > 0)
 *        plant options (README.md, "Plant options"):
 *          switched (0/1: the bridge's switching states, not the average)
 *          midsample (0/1: the ADC samples at mid-period, not the start)
 *          gaina, gainb, gainc (current-sensor gain error, fraction, > -1)
 *          offseta, offsetb, offsetc (ADC offset step, codes)
 *          drifta, driftb, driftc (ADC offset drift, codes/s)
 *          emf5, emf7 (back-EMF harmonic, fraction of the fundamental, >= 0)
 *          cogging (N m, >= 0)   coggingperiods (per mechanical turn, > 0)
 *          rth (winding thermal resistance, K/W, >= 0; 0 = Rs constant)
 *          thermaltau (winding thermal time constant, s, > 0)
 *          ldsat, lqsat (saturation current of each axis, A, >= 0;
 *          0 = linear)
 *   <t> plant realistic        the realistic set: switched, midsample,
 *          noise 2, the board's dead time, gains +2/-2/0 %, emf5 0.03,
 *          emf7 0.01 (takes no value)
 *   <t> commission             self-commissioning from IDLE (commission.h;
 *                              the summary's id_* keys)
 *   <t> end                    end of the simulation (at most one)
 *
 * Events are sorted by time; events with equal times keep their file order.
 * The simulation ends at the `end` time, at most SCN_MAX_END_S; without
 * `end` it ends 0.5 s after the last event.  An event later than `end`
 * is an error, since it would never be applied; so is a scenario without
 * events.  A UTF-8 byte-order mark at the start is skipped.
 *
 * Anything else (unknown command or plant parameter, missing or extra field,
 * non-numeric or non-finite number, negative time, value out of its physical
 * range) makes the parse fail with "name:line: what".
 */
#ifndef FOCSIM_SCENARIO_H
#define FOCSIM_SCENARIO_H

#include <stddef.h>

/* The latest `end` accepted, s (an hour: 57.6 M PWM periods at 16 kHz). */
#define SCN_MAX_END_S 3600.0

typedef enum {
    SCN_START, SCN_STOP, SCN_SPEED, SCN_LOAD, SCN_LOCK, SCN_UNLOCK, SCN_VDC,
    SCN_TEMP, SCN_OVERCURRENT, SCN_ACK, SCN_ANGLE, SCN_SPIN, SCN_PLANT, SCN_COMMISSION,
    SCN_END
} scn_kind_t;

typedef enum {
    SCN_PLANT_RS, SCN_PLANT_LD, SCN_PLANT_LQ, SCN_PLANT_FLUX, SCN_PLANT_J,
    SCN_PLANT_B, SCN_PLANT_COULOMB, SCN_PLANT_DEADTIME, SCN_PLANT_NOISE,
    SCN_PLANT_BUSCAP, SCN_PLANT_BRAKERES,
    SCN_PLANT_SWITCHED, SCN_PLANT_MIDSAMPLE,
    SCN_PLANT_GAIN_A, SCN_PLANT_GAIN_B, SCN_PLANT_GAIN_C,
    SCN_PLANT_OFFSET_A, SCN_PLANT_OFFSET_B, SCN_PLANT_OFFSET_C,
    SCN_PLANT_DRIFT_A, SCN_PLANT_DRIFT_B, SCN_PLANT_DRIFT_C,
    SCN_PLANT_EMF5, SCN_PLANT_EMF7, SCN_PLANT_COGGING, SCN_PLANT_COGGING_PERIODS,
    SCN_PLANT_RTH, SCN_PLANT_THERMAL_TAU, SCN_PLANT_LD_SAT, SCN_PLANT_LQ_SAT,
    SCN_PLANT_REALISTIC
} scn_plant_t;

typedef struct {
    double t_s;
    scn_kind_t kind;
    scn_plant_t plant; /* SCN_PLANT only (SCN_PLANT_RS otherwise) */
    double value;      /* the command's number; 0 for commands without one */
    int line;          /* 1-based line in the scenario text */
} scn_event_t;

/* `events` holds every command of the file, `end` included, sorted. */
typedef struct {
    scn_event_t *events;
    size_t count;
    double end_s;
} scn_t;

/* 0 on success; on failure -1, *out empty, and a message "name:line: what"
 * in err (truncated to errlen; err may be NULL when errlen is 0).  `name`
 * only labels the messages. */
int scn_parse_text(const char *text, const char *name, scn_t *out, char *err,
                   size_t errlen);

/* Reads and parses a file; messages are prefixed with `path`. */
int scn_parse_file(const char *path, scn_t *out, char *err, size_t errlen);

/* Releases the events and leaves *s empty. */
void scn_free(scn_t *s);

/* The scenario keyword: "start", "speed", ... ("?" if out of range). */
const char *scn_kind_name(scn_kind_t k);

/* The plant parameter keyword: "rs", "ld", ... ("?" if out of range). */
const char *scn_plant_name(scn_plant_t p);

#endif /* FOCSIM_SCENARIO_H */
