/* focsim scenario language parser; the language is described in scenario.h. */
#include "scenario.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Smallest accepted value: v >= min, or v > min when `exclusive`. */
typedef struct {
    double min;
    int exclusive;
} bound_t;

#define ANY_VALUE   { -INFINITY, 0 }
#define POSITIVE    { 0.0, 1 }
#define NON_NEG     { 0.0, 0 }
#define ABOVE_ABS_0 { -273.15, 1 }
#define ABOVE_MINUS_1 { -1.0, 1 }

/* The time and command words, at most two arguments (plant), and room for
 * the first extra field so that it can be named in the message. */
enum { MAX_FIELDS = 5 };

typedef struct {
    const char *name;
    const char *usage; /* argument part of the usage text; NULL: no argument */
    bound_t bound;     /* for the numeric argument */
} cmd_spec_t;

/* Indexed by scn_kind_t. */
static const cmd_spec_t commands[] = {
    [SCN_START] = { "start", NULL, ANY_VALUE },
    [SCN_STOP] = { "stop", NULL, ANY_VALUE },
    [SCN_SPEED] = { "speed", "<rpm>", ANY_VALUE },
    [SCN_LOAD] = { "load", "<Nm>", NON_NEG },
    [SCN_LOCK] = { "lock", NULL, ANY_VALUE },
    [SCN_UNLOCK] = { "unlock", NULL, ANY_VALUE },
    [SCN_VDC] = { "vdc", "<volts>", POSITIVE },
    [SCN_TEMP] = { "temp", "<degC>", ABOVE_ABS_0 },
    [SCN_OVERCURRENT] = { "overcurrent", NULL, ANY_VALUE },
    [SCN_ACK] = { "ack", NULL, ANY_VALUE },
    [SCN_ANGLE] = { "angle", "<deg>", ANY_VALUE },
    [SCN_SPIN] = { "spin", "<rpm>", ANY_VALUE },
    [SCN_PLANT] = { "plant", "<param> <value>", ANY_VALUE },
    [SCN_COMMISSION] = { "commission", NULL, ANY_VALUE },
    [SCN_END] = { "end", NULL, ANY_VALUE },
};
#define NUM_COMMANDS (sizeof commands / sizeof commands[0])

typedef struct {
    const char *name;
    bound_t bound;
    int no_value; /* 1: the parameter takes no value (`plant realistic`) */
} plant_spec_t;

/* Indexed by scn_plant_t. */
static const plant_spec_t plant_params[] = {
    [SCN_PLANT_RS] = { "rs", POSITIVE, 0 },
    [SCN_PLANT_LD] = { "ld", POSITIVE, 0 },
    [SCN_PLANT_LQ] = { "lq", POSITIVE, 0 },
    [SCN_PLANT_FLUX] = { "flux", POSITIVE, 0 },
    [SCN_PLANT_J] = { "j", POSITIVE, 0 },
    [SCN_PLANT_B] = { "b", NON_NEG, 0 },
    [SCN_PLANT_COULOMB] = { "coulomb", NON_NEG, 0 },
    [SCN_PLANT_DEADTIME] = { "deadtime", NON_NEG, 0 },
    [SCN_PLANT_NOISE] = { "noise", NON_NEG, 0 },
    [SCN_PLANT_BUSCAP] = { "buscap", NON_NEG, 0 },
    [SCN_PLANT_BRAKERES] = { "brakeres", POSITIVE, 0 },
    [SCN_PLANT_SWITCHED] = { "switched", NON_NEG, 0 },
    [SCN_PLANT_MIDSAMPLE] = { "midsample", NON_NEG, 0 },
    [SCN_PLANT_GAIN_A] = { "gaina", ABOVE_MINUS_1, 0 },
    [SCN_PLANT_GAIN_B] = { "gainb", ABOVE_MINUS_1, 0 },
    [SCN_PLANT_GAIN_C] = { "gainc", ABOVE_MINUS_1, 0 },
    [SCN_PLANT_OFFSET_A] = { "offseta", ANY_VALUE, 0 },
    [SCN_PLANT_OFFSET_B] = { "offsetb", ANY_VALUE, 0 },
    [SCN_PLANT_OFFSET_C] = { "offsetc", ANY_VALUE, 0 },
    [SCN_PLANT_DRIFT_A] = { "drifta", ANY_VALUE, 0 },
    [SCN_PLANT_DRIFT_B] = { "driftb", ANY_VALUE, 0 },
    [SCN_PLANT_DRIFT_C] = { "driftc", ANY_VALUE, 0 },
    [SCN_PLANT_EMF5] = { "emf5", NON_NEG, 0 },
    [SCN_PLANT_EMF7] = { "emf7", NON_NEG, 0 },
    [SCN_PLANT_COGGING] = { "cogging", NON_NEG, 0 },
    [SCN_PLANT_COGGING_PERIODS] = { "coggingperiods", POSITIVE, 0 },
    [SCN_PLANT_RTH] = { "rth", NON_NEG, 0 },
    [SCN_PLANT_THERMAL_TAU] = { "thermaltau", POSITIVE, 0 },
    [SCN_PLANT_LD_SAT] = { "ldsat", NON_NEG, 0 },
    [SCN_PLANT_LQ_SAT] = { "lqsat", NON_NEG, 0 },
    [SCN_PLANT_REALISTIC] = { "realistic", ANY_VALUE, 1 },
};
#define NUM_PLANT_PARAMS (sizeof plant_params / sizeof plant_params[0])

static const bound_t time_bound = NON_NEG;

/* Where messages go and what they are prefixed with. */
typedef struct {
    const char *name;
    int line; /* 0: the message is about the whole file */
    char *err;
    size_t errlen;
} report_t;

/* Writes "name:line: what" (or "name: what") and returns -1. */
static int fail(const report_t *r, const char *fmt, ...)
{
    if (r->errlen == 0) {
        return -1;
    }
    int used = r->line > 0
                   ? snprintf(r->err, r->errlen, "%s:%d: ", r->name, r->line)
                   : snprintf(r->err, r->errlen, "%s: ", r->name);
    if (used >= 0 && (size_t)used < r->errlen) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(r->err + used, r->errlen - (size_t)used, fmt, ap);
        va_end(ap);
    }
    return -1;
}

/* Parses a finite decimal number filling the whole token and checks its
 * lower bound; `what` names the field in messages. */
static int parse_number(const report_t *r, const char *tok, const char *what,
                        bound_t bound, double *out)
{
    char *end;
    const double v = strtod(tok, &end);
    if (end == tok || *end != '\0') {
        return fail(r, "%s: '%s' is not a number", what, tok);
    }
    if (!isfinite(v)) {
        return fail(r, "%s: '%s' is not a finite number", what, tok);
    }
    /* strtod also takes hexadecimal; the language is decimal only. */
    if (tok[strspn(tok, "0123456789.eE+-")] != '\0') {
        return fail(r, "%s: '%s' is not a decimal number", what, tok);
    }
    if (v < bound.min || (bound.exclusive && v == bound.min)) {
        return fail(r, "%s: must be %s %g, got '%s'", what,
                    bound.exclusive ? ">" : ">=", bound.min, tok);
    }
    *out = v;
    return 0;
}

/* Splits `line` in place into whitespace-separated fields, stopping at a
 * comment.  Stores at most MAX_FIELDS and returns how many there are. */
static size_t split_fields(char *line, char *fields[MAX_FIELDS])
{
    static const char blanks[] = " \t\r\v\f";
    char *comment = strchr(line, '#');
    if (comment != NULL) {
        *comment = '\0';
    }
    size_t n = 0;
    char *p = line + strspn(line, blanks);
    while (*p != '\0') {
        char *stop = p + strcspn(p, blanks);
        const int last = *stop == '\0';
        *stop = '\0';
        if (n < MAX_FIELDS) {
            fields[n] = p;
        }
        n++;
        p = last ? stop : stop + 1 + strspn(stop + 1, blanks);
    }
    return n;
}

static int find_command(const char *word)
{
    for (size_t k = 0; k < NUM_COMMANDS; k++) {
        if (strcmp(commands[k].name, word) == 0) {
            return (int)k;
        }
    }
    return -1;
}

static int find_plant_param(const char *word)
{
    for (size_t k = 0; k < NUM_PLANT_PARAMS; k++) {
        if (strcmp(plant_params[k].name, word) == 0) {
            return (int)k;
        }
    }
    return -1;
}

/* Parses the fields of one non-empty line into *ev. */
static int parse_event(const report_t *r, char *fields[MAX_FIELDS],
                       size_t nfields, scn_event_t *ev)
{
    memset(ev, 0, sizeof *ev);
    ev->line = r->line;
    if (find_command(fields[0]) >= 0) {
        return fail(r, "missing time before '%s'", fields[0]);
    }
    if (parse_number(r, fields[0], "time", time_bound, &ev->t_s) != 0) {
        return -1;
    }
    if (nfields < 2) {
        return fail(r, "missing command after time '%s'", fields[0]);
    }
    const int k = find_command(fields[1]);
    if (k < 0) {
        return fail(r, "unknown command '%s'", fields[1]);
    }
    const cmd_spec_t *cmd = &commands[k];
    ev->kind = (scn_kind_t)k;

    const size_t nargs = nfields - 2;
    const int plant = k == SCN_PLANT && nargs > 0 ? find_plant_param(fields[2]) : -1;
    const size_t plant_args = plant >= 0 && plant_params[plant].no_value ? 1 : 2;
    const size_t want = cmd->usage == NULL ? 0 : k == SCN_PLANT ? plant_args : 1;
    if (nargs != want) {
        char usage[64];
        snprintf(usage, sizeof usage, "<t> %s%s%s", cmd->name,
                 want ? " " : "", want ? cmd->usage : "");
        return nargs < want
                   ? fail(r, "'%s': missing argument (usage: %s)", cmd->name,
                          usage)
                   : fail(r, "'%s': extra field '%s' (usage: %s)", cmd->name,
                          fields[2 + want], usage);
    }
    if (want == 0) {
        return 0;
    }
    if (ev->kind != SCN_PLANT) {
        return parse_number(r, fields[2], cmd->name, cmd->bound, &ev->value);
    }
    const int p = plant;
    if (p < 0) {
        return fail(r, "unknown plant parameter '%s' (expected one of README.md's "
                       "focsim plant parameters)", fields[2]);
    }
    ev->plant = (scn_plant_t)p;
    if (plant_params[p].no_value) {
        return 0;
    }
    char what[32];
    snprintf(what, sizeof what, "plant %s", plant_params[p].name);
    return parse_number(r, fields[3], what, plant_params[p].bound, &ev->value);
}

static int push_event(scn_t *s, size_t *capacity, const scn_event_t *ev)
{
    if (s->count == *capacity) {
        const size_t grown = *capacity ? 2 * *capacity : 16;
        scn_event_t *bigger = realloc(s->events, grown * sizeof *bigger);
        if (bigger == NULL) {
            return -1;
        }
        s->events = bigger;
        *capacity = grown;
    }
    s->events[s->count++] = *ev;
    return 0;
}

/* By time, then by line: a stable order even though qsort is not stable. */
static int compare_events(const void *a, const void *b)
{
    const scn_event_t *x = a;
    const scn_event_t *y = b;
    if (x->t_s != y->t_s) {
        return x->t_s < y->t_s ? -1 : 1;
    }
    return (x->line > y->line) - (x->line < y->line);
}

/* Parses every line of the writable copy `text` into *out (unsorted) and
 * sets out->end_s.  On failure *out holds what was parsed so far. */
static int parse_lines(char *text, report_t *r, scn_t *out)
{
    size_t capacity = 0;
    int end_line = 0; /* 0: no `end` yet */
    double last_t = 0.0;
    char *line = text;
    for (r->line = 1; line != NULL; r->line++) {
        char *newline = strchr(line, '\n');
        if (newline != NULL) {
            *newline = '\0';
        }
        char *fields[MAX_FIELDS];
        const size_t nfields = split_fields(line, fields);
        line = newline != NULL ? newline + 1 : NULL;
        if (nfields == 0) {
            continue;
        }
        scn_event_t ev;
        if (parse_event(r, fields, nfields, &ev) != 0) {
            return -1;
        }
        if (ev.kind == SCN_END) {
            if (end_line != 0) {
                return fail(r, "second 'end' (first at line %d)", end_line);
            }
            end_line = ev.line;
            out->end_s = ev.t_s;
        }
        if (push_event(out, &capacity, &ev) != 0) {
            return fail(r, "out of memory");
        }
        last_t = fmax(last_t, ev.t_s);
    }
    if (out->count == 0) {
        r->line = 0;
        return fail(r, "no events: an empty scenario simulates nothing");
    }
    if (end_line == 0) {
        out->end_s = last_t + 0.5;
    }
    if (out->end_s > SCN_MAX_END_S) {
        r->line = end_line; /* 0 without `end`: the last event's time */
        return fail(r, "the simulation would end at %g s, beyond %g s (SCN_MAX_END_S: an "
                       "hour of PWM periods is gigabytes of CSV)", out->end_s, SCN_MAX_END_S);
    }
    if (end_line == 0) {
        return 0;
    }
    /* In file order, so the first offending line is reported. */
    for (size_t i = 0; i < out->count; i++) {
        if (out->events[i].t_s > out->end_s) {
            r->line = out->events[i].line;
            return fail(r, "'%s' at %g s is after 'end' at %g s (line %d)",
                        commands[out->events[i].kind].name,
                        out->events[i].t_s, out->end_s, end_line);
        }
    }
    return 0;
}

int scn_parse_text(const char *text, const char *name, scn_t *out, char *err,
                   size_t errlen)
{
    report_t r = { name, 0, err, errlen };
    if (errlen > 0) {
        err[0] = '\0';
    }
    out->events = NULL;
    out->count = 0;
    out->end_s = 0.0;

    const size_t len = strlen(text);
    char *copy = malloc(len + 1);
    if (copy == NULL) {
        return fail(&r, "out of memory");
    }
    memcpy(copy, text, len + 1);
    /* a UTF-8 byte-order mark (an editor's) is not part of the first line */
    const size_t bom = (strncmp(copy, "\xEF\xBB\xBF", 3) == 0) ? 3u : 0u;
    const int rc = parse_lines(copy + bom, &r, out);
    free(copy);
    if (rc != 0) {
        scn_free(out);
        return -1;
    }

    if (out->count > 1) { /* qsort must not see the NULL of an empty list */
        qsort(out->events, out->count, sizeof *out->events, compare_events);
    }
    return 0;
}

int scn_parse_file(const char *path, scn_t *out, char *err, size_t errlen)
{
    report_t r = { path, 0, err, errlen };
    out->events = NULL;
    out->count = 0;
    out->end_s = 0.0;

    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        return fail(&r, "cannot open: %s", strerror(errno));
    }
    size_t len = 0;
    size_t capacity = 4096;
    char *text = malloc(capacity);
    int rc = text == NULL ? fail(&r, "out of memory") : 0;
    while (rc == 0) {
        len += fread(text + len, 1, capacity - len - 1, f);
        if (ferror(f)) {
            rc = fail(&r, "read error: %s", strerror(errno));
        } else if (feof(f)) {
            break;
        } else if (len + 1 == capacity) {
            char *bigger = realloc(text, 2 * capacity);
            if (bigger == NULL) {
                rc = fail(&r, "out of memory");
            } else {
                text = bigger;
                capacity *= 2;
            }
        }
    }
    fclose(f);
    if (rc == 0) {
        text[len] = '\0';
        /* A NUL would silently end the text early. */
        const char *nul = memchr(text, '\0', len);
        if (nul != NULL) {
            r.line = 1;
            for (const char *p = text; p < nul; p++) {
                r.line += *p == '\n';
            }
            rc = fail(&r, "NUL byte in the file");
        } else {
            rc = scn_parse_text(text, path, out, err, errlen);
        }
    }
    free(text);
    return rc;
}

void scn_free(scn_t *s)
{
    free(s->events);
    s->events = NULL;
    s->count = 0;
    s->end_s = 0.0;
}

const char *scn_kind_name(scn_kind_t k)
{
    return (size_t)k < NUM_COMMANDS ? commands[k].name : "?";
}

const char *scn_plant_name(scn_plant_t p)
{
    return (size_t)p < NUM_PLANT_PARAMS ? plant_params[p].name : "?";
}
