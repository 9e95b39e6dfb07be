/* Scenario language parser: accepted forms, ordering, end time, and one
 * line-numbered error per kind of mistake. */
#include "scenario.h"
#include "testkit.h"

#include <math.h>
#include <stdio.h>

/* Parses `text` expecting success; on failure reports the message. */
static int parse_ok(const char *text, scn_t *s)
{
    char err[256];
    const int rc = scn_parse_text(text, "t.scn", s, err, sizeof err);
    TK_CHECK(rc == 0, "unexpected parse error: %s", err);
    return rc;
}

static void case_parse_all_commands(void)
{
    static const char text[] =
        "0 start\n"
        "0.1 speed -1500.5\n"
        "0.2 load 0.05\n"
        "0.3 lock\n"
        "0.4 unlock\n"
        "0.5 vdc 24\n"
        "0.6 temp -20\n"
        "0.7 overcurrent\n"
        "0.8 ack\n"
        "0.9 angle 90\n"
        "1 spin -300\n"
        "1.1 plant rs 0.28\n"
        "1.2 plant ld 1e-4\n"
        "1.3 plant lq 2.5e-4\n"
        "1.4 plant flux 0.0066\n"
        "1.5 plant j 7.1e-6\n"
        "1.6 plant b 0\n"
        "1.7 plant deadtime 1e-6\n"
        "1.8 plant noise 2\n"
        "1.9 plant buscap 4.7e-4\n"
        "2 plant brakeres 10\n"
        "2.1 stop\n"
        "2.2 end\n";
    static const struct {
        scn_kind_t kind;
        scn_plant_t plant;
        double value;
    } want[] = {
        { SCN_START, SCN_PLANT_RS, 0 },     { SCN_SPEED, SCN_PLANT_RS, -1500.5 },
        { SCN_LOAD, SCN_PLANT_RS, 0.05 },   { SCN_LOCK, SCN_PLANT_RS, 0 },
        { SCN_UNLOCK, SCN_PLANT_RS, 0 },    { SCN_VDC, SCN_PLANT_RS, 24 },
        { SCN_TEMP, SCN_PLANT_RS, -20 },    { SCN_OVERCURRENT, SCN_PLANT_RS, 0 },
        { SCN_ACK, SCN_PLANT_RS, 0 },       { SCN_ANGLE, SCN_PLANT_RS, 90 },
        { SCN_SPIN, SCN_PLANT_RS, -300 },   { SCN_PLANT, SCN_PLANT_RS, 0.28 },
        { SCN_PLANT, SCN_PLANT_LD, 1e-4 },  { SCN_PLANT, SCN_PLANT_LQ, 2.5e-4 },
        { SCN_PLANT, SCN_PLANT_FLUX, 0.0066 }, { SCN_PLANT, SCN_PLANT_J, 7.1e-6 },
        { SCN_PLANT, SCN_PLANT_B, 0 },      { SCN_PLANT, SCN_PLANT_DEADTIME, 1e-6 },
        { SCN_PLANT, SCN_PLANT_NOISE, 2 },  { SCN_PLANT, SCN_PLANT_BUSCAP, 4.7e-4 },
        { SCN_PLANT, SCN_PLANT_BRAKERES, 10 }, { SCN_STOP, SCN_PLANT_RS, 0 },
        { SCN_END, SCN_PLANT_RS, 0 },
    };
    const size_t nwant = sizeof want / sizeof want[0];
    scn_t s;
    if (parse_ok(text, &s) != 0) {
        return;
    }
    TK_CHECK(s.count == nwant, "count=%zu", s.count);
    for (size_t i = 0; i < s.count && i < nwant; i++) {
        const scn_event_t *e = &s.events[i];
        TK_CHECK(e->kind == want[i].kind, "event %zu: kind %s", i,
                 scn_kind_name(e->kind));
        TK_CHECK(e->kind != SCN_PLANT || e->plant == want[i].plant,
                 "event %zu: plant %s", i, scn_plant_name(e->plant));
        TK_CHECK(e->value == want[i].value, "event %zu: value %g", i, e->value);
        TK_CHECK(e->line == (int)i + 1, "event %zu: line %d", i, e->line);
        TK_CHECK(fabs(e->t_s - 0.1 * (double)i) < 1e-12, "event %zu: t %g", i,
                 e->t_s);
    }
    TK_CHECK(s.end_s == 2.2, "end=%g", s.end_s);
    TK_CHECK(strcmp(scn_kind_name(SCN_OVERCURRENT), "overcurrent") == 0, "name");
    TK_CHECK(strcmp(scn_plant_name(SCN_PLANT_DEADTIME), "deadtime") == 0, "name");
    scn_free(&s);
    TK_CHECK(s.events == NULL && s.count == 0, "scn_free leaves it empty");
}

static void case_parse_comments_and_blanks(void)
{
    static const char text[] =
        "# whole-line comment\n"
        "\n"
        "   \t  \n"
        "  0\tstart   # trailing comment\r\n"
        "#0 stop\n"
        "0.5  speed\t1000#no space before the comment\n"
        "   # indented comment\n"
        "1e-3 ack"; /* no final newline */
    scn_t s;
    if (parse_ok(text, &s) != 0) {
        return;
    }
    TK_CHECK(s.count == 3, "count=%zu", s.count);
    if (s.count == 3) {
        TK_CHECK(s.events[0].kind == SCN_START && s.events[0].line == 4,
                 "start at line %d", s.events[0].line);
        TK_CHECK(s.events[1].kind == SCN_ACK && s.events[1].line == 8,
                 "ack at line %d", s.events[1].line);
        TK_CHECK(s.events[2].kind == SCN_SPEED && s.events[2].value == 1000.0,
                 "speed %g", s.events[2].value);
    }
    scn_free(&s);
}

/* Sorted by time; equal times keep file order. */
static void case_sort_is_stable(void)
{
    static const char text[] =
        "1 speed 1\n"
        "0 start\n"
        "1 speed 2\n"
        "0.5 load 0.1\n"
        "1 speed 3\n"
        "0 vdc 12\n"
        "1 speed 4\n";
    static const int want_lines[] = { 2, 6, 4, 1, 3, 5, 7 };
    scn_t s;
    if (parse_ok(text, &s) != 0) {
        return;
    }
    TK_CHECK(s.count == 7, "count=%zu", s.count);
    for (size_t i = 0; i < s.count && i < 7; i++) {
        TK_CHECK(s.events[i].line == want_lines[i], "position %zu: line %d", i,
                 s.events[i].line);
    }
    scn_free(&s);
}

static void case_end_time(void)
{
    static const struct {
        const char *text;
        double end_s;
    } cases[] = {
        { "0 start\n3 end\n1 stop\n", 3.0 },      /* explicit, not last line */
        { "0 start\n2 stop\n1 speed 5\n", 2.5 },  /* last event + 0.5 s */
        { "\xEF\xBB\xBF" "0 start\n", 0.5 },      /* byte-order mark */
        { "1 end\n1 stop\n", 1.0 },               /* event at the end time */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        scn_t s;
        if (parse_ok(cases[i].text, &s) != 0) {
            continue;
        }
        TK_CHECK(fabs(s.end_s - cases[i].end_s) < 1e-12, "case %zu: end %g",
                 i, s.end_s);
        scn_free(&s);
    }
}

/* Every kind of mistake fails with its line number and says what is wrong. */
static void case_errors_name_the_line(void)
{
    static const struct {
        const char *text;
        const char *message; /* expected message, after "bad.scn:" */
    } cases[] = {
        { "0 start\n\n# c\n0.1 sped 100\n", "4: unknown command 'sped'" },
        { "0 speed\n", "1: 'speed': missing argument (usage: <t> speed <rpm>)" },
        { "0 plant rs\n", "1: 'plant': missing argument" },
        { "0 start\n0 start now\n", "2: 'start': extra field 'now'" },
        { "0 load 1 2 3 4\n", "1: 'load': extra field '2'" },
        { "0 plant rs 1 2\n", "1: 'plant': extra field '2'" },
        { "start\n", "1: missing time before 'start'" },
        { "0 vdc twelve\n", "1: vdc: 'twelve' is not a number" },
        { "0 speed 12x\n", "1: speed: '12x' is not a number" },
        { "x start\n", "1: time: 'x' is not a number" },
        { "0.5\n", "1: missing command after time '0.5'" },
        { "-0.1 start\n", "1: time: must be >= 0, got '-0.1'" },
        { "0 speed inf\n", "1: speed: 'inf' is not a finite number" },
        { "0 speed nan\n", "1: speed: 'nan' is not a finite number" },
        { "0 load 1e999\n", "1: load: '1e999' is not a finite number" },
        { "0 speed 0x10\n", "1: speed: '0x10' is not a decimal number" },
        { "0 plant rz 1\n", "1: unknown plant parameter 'rz'" },
        { "0 vdc 0\n", "1: vdc: must be > 0, got '0'" },
        { "0 load -0.5\n", "1: load: must be >= 0, got '-0.5'" },
        { "0 temp -300\n", "1: temp: must be > -273.15" },
        { "0 plant j 0\n", "1: plant j: must be > 0, got '0'" },
        { "0 plant flux -1\n", "1: plant flux: must be > 0" },
        { "0 plant noise -1\n", "1: plant noise: must be >= 0" },
        { "1 end\n2 end\n", "2: second 'end' (first at line 1)" },
        { "0 start\n3 stop\n1 end\n", "2: 'stop' at 3 s is after 'end' at 1 s" },
        { "# nothing\n", " no events: an empty scenario simulates nothing" },
        { "", " no events" },
        { "0 start\n1e9 end\n", "2: the simulation would end at 1e+09 s, beyond 3600 s" },
        { "0 start\n4000 stop\n", " the simulation would end at 4000.5 s, beyond 3600 s" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char err[256] = "";
        char want[128];
        scn_t s = { NULL, 7, 1.0 };
        const int rc = scn_parse_text(cases[i].text, "bad.scn", &s, err,
                                      sizeof err);
        snprintf(want, sizeof want, "bad.scn:%s", cases[i].message);
        TK_CHECK(rc == -1, "case %zu accepted", i);
        TK_CHECK(strncmp(err, want, strlen(want)) == 0,
                 "case %zu: got \"%s\", want \"%s...\"", i, err, want);
        TK_CHECK(s.events == NULL && s.count == 0, "case %zu: not left empty",
                 i);
    }
    /* A tiny buffer truncates the message but stays terminated. */
    char tiny[8];
    scn_t s;
    TK_CHECK(scn_parse_text("0 bogus\n", "bad.scn", &s, tiny, sizeof tiny) ==
                 -1 && strcmp(tiny, "bad.scn") == 0,
             "tiny buffer: \"%s\"", tiny);
}

static void case_parse_file(void)
{
    const char *path = "test_scenario_file.scn";
    FILE *f = fopen(path, "wb");
    TK_CHECK(f != NULL, "cannot create %s", path);
    if (f == NULL) {
        return;
    }
    fputs("0 start\r\n0.2 speed 500\r\n", f);
    fclose(f);
    char err[256] = "";
    scn_t s;
    TK_CHECK(scn_parse_file(path, &s, err, sizeof err) == 0, "%s", err);
    TK_CHECK(s.count == 2 && s.end_s == 0.7, "count %zu end %g", s.count,
             s.end_s);
    scn_free(&s);

    /* A NUL byte must not silently cut the file short. */
    f = fopen(path, "wb");
    TK_CHECK(f != NULL, "cannot create %s", path);
    if (f != NULL) {
        fwrite("0 start\n0 st\0op\n", 1, 16, f);
        fclose(f);
        TK_CHECK(scn_parse_file(path, &s, err, sizeof err) == -1 &&
                     strcmp(err, "test_scenario_file.scn:2: NUL byte in the "
                                 "file") == 0,
                 "NUL: \"%s\"", err);
    }
    remove(path);

    TK_CHECK(scn_parse_file("no/such/dir/x.scn", &s, err, sizeof err) == -1 &&
                 strncmp(err, "no/such/dir/x.scn: cannot open", 30) == 0,
             "missing file: \"%s\"", err);
}

/* The plant options of issue 13: every name parses to its parameter and
 * value, `realistic` without a value; a value after `realistic`, a gain
 * of -100 % or less and a zero thermal time constant are errors. */
static void case_parse_plant_options(void)
{
    static const struct {
        const char *name;
        scn_plant_t plant;
        double value;
    } want[] = {
        { "switched", SCN_PLANT_SWITCHED, 1 },     { "midsample", SCN_PLANT_MIDSAMPLE, 1 },
        { "gaina", SCN_PLANT_GAIN_A, 0.02 },       { "gainb", SCN_PLANT_GAIN_B, -0.02 },
        { "gainc", SCN_PLANT_GAIN_C, 0 },          { "offseta", SCN_PLANT_OFFSET_A, -3 },
        { "offsetb", SCN_PLANT_OFFSET_B, 2.5 },    { "offsetc", SCN_PLANT_OFFSET_C, 1 },
        { "drifta", SCN_PLANT_DRIFT_A, 0.5 },      { "driftb", SCN_PLANT_DRIFT_B, -0.5 },
        { "driftc", SCN_PLANT_DRIFT_C, 0.25 },     { "emf5", SCN_PLANT_EMF5, 0.03 },
        { "emf7", SCN_PLANT_EMF7, 0.01 },          { "cogging", SCN_PLANT_COGGING, 0.004 },
        { "coggingperiods", SCN_PLANT_COGGING_PERIODS, 60 },
        { "rth", SCN_PLANT_RTH, 12 },              { "thermaltau", SCN_PLANT_THERMAL_TAU, 600 },
        { "ldsat", SCN_PLANT_LD_SAT, 3 },          { "lqsat", SCN_PLANT_LQ_SAT, 2 },
        { "realistic", SCN_PLANT_REALISTIC, 0 },
    };
    const size_t n = sizeof want / sizeof want[0];
    for (size_t i = 0; i < n; i++) {
        char text[64];
        if (want[i].plant == SCN_PLANT_REALISTIC) {
            snprintf(text, sizeof text, "0 plant %s\n", want[i].name);
        } else {
            snprintf(text, sizeof text, "0 plant %s %g\n", want[i].name, want[i].value);
        }
        scn_t s;
        if (parse_ok(text, &s) != 0) {
            continue;
        }
        TK_CHECK(s.count == 1 && s.events[0].kind == SCN_PLANT &&
                     s.events[0].plant == want[i].plant && s.events[0].value == want[i].value,
                 "%s", text);
        TK_CHECK(strcmp(scn_plant_name(want[i].plant), want[i].name) == 0, "name %s",
                 want[i].name);
        scn_free(&s);
    }
    static const struct {
        const char *text;
        const char *message;
    } bad[] = {
        { "0 plant realistic 1\n", "1: 'plant': extra field '1'" },
        { "0 plant gaina -1\n", "1: plant gaina: must be > -1, got '-1'" },
        { "0 plant thermaltau 0\n", "1: plant thermaltau: must be > 0, got '0'" },
        { "0 plant switched\n", "1: 'plant': missing argument" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char err[256] = "";
        char expect[128];
        scn_t s;
        const int rc = scn_parse_text(bad[i].text, "bad.scn", &s, err, sizeof err);
        snprintf(expect, sizeof expect, "bad.scn:%s", bad[i].message);
        TK_CHECK(rc == -1, "%s accepted", bad[i].text);
        TK_CHECK(strncmp(err, expect, strlen(expect)) == 0, "got '%s'", err);
    }
}

TK_CASES(TK_CASE(case_parse_all_commands), TK_CASE(case_parse_comments_and_blanks),
         TK_CASE(case_sort_is_stable), TK_CASE(case_end_time),
         TK_CASE(case_errors_name_the_line), TK_CASE(case_parse_file),
         TK_CASE(case_parse_plant_options))
