/* SVG plot writer: well-formed output with all labels, bounded decimation
 * that keeps spikes, NaN gaps, escaping, round ticks, I/O errors.  Each case
 * writes its own file in the working directory and removes it. */
#include "svgplot.h"
#include "testkit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* The whole file as a string, or NULL. */
static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        return NULL;
    }
    fseek(f, 0, SEEK_END);
    const long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = len >= 0 ? malloc((size_t)len + 1) : NULL;
    if (s != NULL) {
        s[fread(s, 1, (size_t)len, f)] = '\0';
    }
    fclose(f);
    return s;
}

/* Minimal XML check: every tag closed in order, one <svg> root, attribute
 * quotes paired, only the five predefined entities.  Returns NULL if the
 * document is fine, else what is wrong. */
static const char *xml_problem(const char *s)
{
    enum { DEPTH = 32, NAME = 32 };
    char stack[DEPTH][NAME];
    int depth = 0;
    int roots = 0;
    for (const char *p = s; *p != '\0'; p++) {
        if (*p == '&') {
            static const char *const entities[] = { "&amp;", "&lt;", "&gt;",
                                                    "&quot;", "&apos;" };
            int known = 0;
            for (size_t i = 0; i < 5; i++) {
                known |= strncmp(p, entities[i], strlen(entities[i])) == 0;
            }
            if (!known) {
                return "bare '&'";
            }
            continue;
        }
        if (*p == '>') {
            return "'>' outside a tag";
        }
        if (*p != '<') {
            continue;
        }
        if (strncmp(p, "<?", 2) == 0) {
            p = strstr(p, "?>");
            if (p == NULL) {
                return "unterminated <?";
            }
            p++;
            continue;
        }
        const char *end = strchr(p, '>');
        if (end == NULL) {
            return "unterminated tag";
        }
        int quotes = 0;
        for (const char *q = p; q < end; q++) {
            quotes += *q == '"';
        }
        if (quotes % 2 != 0) {
            return "unpaired quote in a tag";
        }
        const int closing = p[1] == '/';
        const char *name = p + 1 + closing;
        const size_t len = strcspn(name, " \t\n/>");
        if (len == 0 || len >= NAME) {
            return "bad tag name";
        }
        if (closing) {
            if (depth == 0 || strlen(stack[depth - 1]) != len ||
                strncmp(stack[depth - 1], name, len) != 0) {
                return "closing tag does not match";
            }
            depth--;
        } else if (end[-1] != '/') {
            if (depth == DEPTH) {
                return "too deep";
            }
            roots += depth == 0;
            memcpy(stack[depth], name, len);
            stack[depth++][len] = '\0';
        }
        p = end;
    }
    if (depth != 0) {
        return "unclosed tag";
    }
    return roots == 1 && strstr(s, "<svg xmlns=\"http://www.w3.org/2000/svg\"")
               ? NULL
               : "not one <svg xmlns=...> root";
}

/* Shape of the k-th series path (0-based, in file order). */
typedef struct {
    int found;
    int moves, lines, dots;
    double y_min, y_max; /* of its points, px */
} path_info_t;

static path_info_t series_path(const char *svg, int k)
{
    path_info_t info = { 0, 0, 0, 0, INFINITY, -INFINITY };
    const char *p = svg;
    for (int i = 0; i <= k && p != NULL; i++) {
        p = strstr(p + (i > 0), "class=\"series\"");
    }
    if (p == NULL || (p = strstr(p, " d=\"")) == NULL) {
        return info;
    }
    info.found = 1;
    for (p += 4; *p != '"' && *p != '\0'; p++) {
        if (*p == 'h') {
            info.dots++;
        } else if (*p == 'M' || *p == 'L') {
            double x, y;
            if (sscanf(p + 1, "%lf,%lf", &x, &y) == 2) {
                info.y_min = fmin(info.y_min, y);
                info.y_max = fmax(info.y_max, y);
            }
            *p == 'M' ? info.moves++ : info.lines++;
        }
    }
    return info;
}

/* Writes a one-panel plot of `n` points of y against t = i * dt, reads it
 * back (caller frees) and checks that it is well-formed. */
static char *plot_one(const char *path, const double *y, size_t n, double dt)
{
    double *t = malloc(n * sizeof *t);
    if (t == NULL) {
        return NULL;
    }
    for (size_t i = 0; i < n; i++) {
        t[i] = (double)i * dt;
    }
    const svg_series_t series = { "y", NULL, y };
    const svg_panel_t panel = { "Panel", "A", &series, 1 };
    const int rc = svg_write(path, "One", t, n, &panel, 1, NULL, 0);
    free(t);
    TK_CHECK(rc == 0, "svg_write %s failed", path);
    char *svg = slurp(path);
    remove(path);
    TK_CHECK(svg != NULL, "cannot read back %s", path);
    const char *problem = svg != NULL ? xml_problem(svg) : NULL;
    TK_CHECK(problem == NULL, "%s: %s", path, problem);
    return svg;
}

static void case_svg_has_all_labels(void)
{
    enum { N = 500 };
    static double t[N], speed[N], ref[N], ia[N];
    for (size_t i = 0; i < N; i++) {
        t[i] = (double)i * 1e-3;
        ref[i] = 1000.0;
        speed[i] = 1000.0 * (1.0 - exp(-t[i] / 0.05));
        ia[i] = 2.0 * sin(300.0 * t[i]);
    }
    const svg_series_t s_speed[] = { { "speed ref", "#1f77b4", ref },
                                     { "speed est", NULL, speed } };
    const svg_series_t s_current[] = { { "ia", "red", ia } };
    const svg_panel_t panels[] = { { "Speed", "rpm", s_speed, 2 },
                                   { "Phase current", "A", s_current, 1 } };
    const svg_band_t bands[] = { { 0.0, 0.1, "CALIB" },
                                 { 0.1, 0.3, "RUN" },
                                 { 0.3, 0.35, "FAULT" },
                                 { 0.35, 0.499, "RUN" } };
    const char *path = "test_svg_labels.svg";
    TK_CHECK(svg_write(path, "Start-up test", t, N, panels, 2, bands, 4) == 0,
             "svg_write failed");
    char *svg = slurp(path);
    remove(path);
    if (svg == NULL) {
        TK_CHECK(0, "no output");
        return;
    }
    const char *problem = xml_problem(svg);
    TK_CHECK(problem == NULL, "not well-formed: %s", problem);
    static const char *const expected[] = {
        ">Start-up test</text>", ">Speed</text>", ">Phase current</text>",
        ">rpm</text>", ">A</text>", ">speed ref</text>", ">speed est</text>",
        ">ia</text>", ">time (s)</text>", ">CALIB</text>", ">RUN</text>",
        ">FAULT</text>", "stroke=\"red\"", "class=\"ytick\"", "class=\"ttick\"",
    };
    for (size_t i = 0; i < sizeof expected / sizeof expected[0]; i++) {
        TK_CHECK(strstr(svg, expected[i]) != NULL, "missing %s", expected[i]);
    }
    /* The lane comes first: the band rectangles in band order.  The same
     * label has the same colour, different labels differ. */
    char fill[4][16] = { "", "", "", "" };
    const char *p = svg;
    for (int b = 0; b < 4 && (p = strstr(p, "class=\"band\"")) != NULL; b++) {
        p = strstr(p, "fill=\"");
        if (p != NULL) {
            sscanf(p, "fill=\"%15[^\"]", fill[b]);
        }
    }
    TK_CHECK(strcmp(fill[1], fill[3]) == 0, "RUN %s vs %s", fill[1], fill[3]);
    TK_CHECK(strcmp(fill[0], fill[1]) != 0 && strcmp(fill[1], fill[2]) != 0 &&
                 strcmp(fill[0], fill[2]) != 0,
             "colours %s %s %s", fill[0], fill[1], fill[2]);
    free(svg);
}

static void case_svg_decimation_keeps_spikes(void)
{
    const size_t n = 1000000;
    double *y = malloc(n * sizeof *y);
    if (y == NULL) {
        TK_CHECK(0, "out of memory");
        return;
    }
    for (size_t i = 0; i < n; i++) {
        y[i] = 0.01 * sin((double)i * 0.001);
    }
    y[654321] = 50.0; /* one sample in a million */
    char *svg = plot_one("test_svg_decimation.svg", y, n, 1e-6);
    free(y);
    if (svg == NULL) {
        return;
    }
    const path_info_t info = series_path(svg, 0);
    const int points = info.moves + info.lines;
    TK_CHECK(info.found && points > 500 && points <= 2000, "points=%d", points);
    TK_CHECK(info.moves == 1, "one unbroken line, moves=%d", info.moves);
    /* The flat part sits near the bottom; the spike reaches the top. */
    TK_CHECK(info.y_max - info.y_min > 120.0, "y span %.1f px: spike lost",
             info.y_max - info.y_min);
    TK_CHECK(strlen(svg) < 100000, "file of %zu bytes", strlen(svg));
    free(svg);
}

static void case_svg_nan_breaks_line(void)
{
    enum { N = 100 };
    double y[N];
    for (size_t i = 0; i < N; i++) {
        y[i] = (double)i;
    }
    for (size_t i = 40; i < 60; i++) {
        y[i] = NAN;
    }
    y[70] = INFINITY; /* also a gap */
    y[79] = y[81] = NAN; /* 80 stands alone: a dot */
    char *svg = plot_one("test_svg_nan.svg", y, N, 1e-3);
    if (svg != NULL) {
        const path_info_t info = series_path(svg, 0);
        TK_CHECK(info.moves == 5, "moves=%d", info.moves);
        TK_CHECK(info.moves + info.lines == N - 20 - 3, "points=%d",
                 info.moves + info.lines);
        TK_CHECK(info.dots == 1, "dots=%d", info.dots);
        free(svg);
    }

    /* Decimated: the gap survives too. */
    const size_t big = 200000;
    double *z = malloc(big * sizeof *z);
    if (z == NULL) {
        TK_CHECK(0, "out of memory");
        return;
    }
    for (size_t i = 0; i < big; i++) {
        z[i] = i >= big / 2 && i < big / 2 + big / 10 ? NAN : sin(i * 1e-4);
    }
    svg = plot_one("test_svg_nan_big.svg", z, big, 1e-5);
    free(z);
    if (svg != NULL) {
        const path_info_t info = series_path(svg, 0);
        TK_CHECK(info.moves == 2, "decimated moves=%d", info.moves);
        free(svg);
    }

    /* Nothing finite: an empty path and a default axis, no failure. */
    for (size_t i = 0; i < N; i++) {
        y[i] = NAN;
    }
    svg = plot_one("test_svg_nan_all.svg", y, N, 1e-3);
    if (svg != NULL) {
        const path_info_t info = series_path(svg, 0);
        TK_CHECK(info.found && info.moves + info.lines == 0, "points %d",
                 info.moves + info.lines);
        free(svg);
    }
}

static void case_svg_escapes_text(void)
{
    const double t[2] = { 0.0, 1.0 };
    const double y[2] = { 1.0, 2.0 };
    const svg_series_t series = { "i<sub>d</sub> & \"q\"", "#123456", y };
    const svg_panel_t panel = { "a<b>c", "V&A", &series, 1 };
    const svg_band_t band = { 0.2, 0.8, "<FAULT>" };
    const char *path = "test_svg_escape.svg";
    TK_CHECK(svg_write(path, "x < y & y > z", t, 2, &panel, 1, &band, 1) == 0,
             "svg_write failed");
    char *svg = slurp(path);
    remove(path);
    if (svg == NULL) {
        TK_CHECK(0, "no output");
        return;
    }
    const char *problem = xml_problem(svg);
    TK_CHECK(problem == NULL, "not well-formed: %s", problem);
    static const char *const expected[] = {
        ">x &lt; y &amp; y &gt; z</text>",
        ">i&lt;sub&gt;d&lt;/sub&gt; &amp; &quot;q&quot;</text>",
        ">a&lt;b&gt;c</text>", ">V&amp;A</text>", ">&lt;FAULT&gt;</text>",
    };
    for (size_t i = 0; i < sizeof expected / sizeof expected[0]; i++) {
        TK_CHECK(strstr(svg, expected[i]) != NULL, "missing %s", expected[i]);
    }
    free(svg);
}

/* Tick labels of one class, in file order, parsed; returns how many. */
static size_t tick_values(const char *svg, const char *cls, double *v,
                          size_t max, int *longest)
{
    char key[32];
    snprintf(key, sizeof key, "class=\"%s\"", cls);
    size_t n = 0;
    *longest = 0;
    for (const char *p = strstr(svg, key); p != NULL && n < max;
         p = strstr(p + 1, key)) {
        const char *text = strchr(p, '>') + 1;
        const int len = (int)strcspn(text, "<");
        *longest = len > *longest ? len : *longest;
        v[n++] = strtod(text, NULL);
    }
    return n;
}

/* Equally spaced by 1, 2 or 5 x 10^n. */
static int is_nice_sequence(const double *v, size_t n)
{
    if (n < 3) {
        return 0;
    }
    const double step = v[1] - v[0];
    const double mantissa = step / pow(10.0, floor(log10(step)));
    int ok = fabs(mantissa - 1) < 1e-6 || fabs(mantissa - 2) < 1e-6 ||
             fabs(mantissa - 5) < 1e-6 || fabs(mantissa - 10) < 1e-6;
    for (size_t i = 2; i < n; i++) {
        ok &= fabs(v[i] - v[i - 1] - step) < 1e-9 * fabs(step) + 1e-12;
    }
    return ok;
}

static void case_svg_ticks_are_round(void)
{
    enum { N = 200 };
    double y[N];
    for (size_t i = 0; i < N; i++) {
        y[i] = -3.7 + 13.0 * (double)i / (N - 1); /* -3.7 .. 9.3 */
    }
    /* t = 0 .. 0.0199 s: the axis should end on the round 0.02. */
    char *svg = plot_one("test_svg_ticks.svg", y, N, 1e-4);
    if (svg == NULL) {
        return;
    }
    double v[32];
    int longest;
    size_t n = tick_values(svg, "ytick", v, 32, &longest);
    TK_CHECK(n >= 4 && n <= 8 && is_nice_sequence(v, n), "%zu y ticks", n);
    TK_CHECK(n > 0 && v[0] >= -3.7 - 1.0 && v[n - 1] <= 9.3 + 1.0 &&
                 v[0] <= -2.0 && v[n - 1] >= 8.0,
             "y ticks %g .. %g", v[0], n > 0 ? v[n - 1] : 0);
    TK_CHECK(longest <= 4, "y label of %d chars", longest);

    n = tick_values(svg, "ttick", v, 32, &longest);
    TK_CHECK(n >= 5 && n <= 13 && is_nice_sequence(v, n), "%zu t ticks", n);
    TK_CHECK(n > 0 && v[0] == 0.0 && fabs(v[n - 1] - 0.02) < 1e-12,
             "t ticks %g .. %g", v[0], n > 0 ? v[n - 1] : 0);
    TK_CHECK(longest <= 5, "t label of %d chars", longest);
    TK_CHECK(strstr(svg, ">0.020</text>") != NULL, "0.02 s label");
    free(svg);
}

static void case_svg_edge_inputs_and_io_error(void)
{
    const double y[1] = { 5.0 };
    const double t[1] = { 0.0 };
    const svg_series_t series = { "y", NULL, y };
    const svg_panel_t panel = { "Panel", NULL, &series, 1 };
    TK_CHECK(svg_write("no-such-dir/x.svg", "T", t, 1, &panel, 1, NULL, 0) ==
                 -1,
             "unwritable path accepted");
    /* A full disk shows up only when the buffered output is flushed. */
    FILE *full = fopen("/dev/full", "w");
    if (full != NULL) {
        fclose(full);
        TK_CHECK(svg_write("/dev/full", "T", t, 1, &panel, 1, NULL, 0) == -1,
                 "write error not reported");
    }

    /* One point, no panels, no samples: still a readable document. */
    static const struct {
        size_t n, npanels;
    } shapes[] = { { 1, 1 }, { 1, 0 }, { 0, 1 } };
    for (size_t i = 0; i < sizeof shapes / sizeof shapes[0]; i++) {
        const char *path = "test_svg_edge.svg";
        TK_CHECK(svg_write(path, NULL, t, shapes[i].n, &panel,
                           shapes[i].npanels, NULL, 0) == 0,
                 "shape %zu: svg_write failed", i);
        char *svg = slurp(path);
        remove(path);
        const char *problem = svg != NULL ? xml_problem(svg) : "no output";
        TK_CHECK(problem == NULL, "shape %zu: %s", i, problem);
        TK_CHECK(svg == NULL || strstr(svg, ">time (s)</text>") != NULL,
                 "shape %zu: no time axis", i);
        free(svg);
    }
}

TK_CASES(TK_CASE(case_svg_has_all_labels),
         TK_CASE(case_svg_decimation_keeps_spikes),
         TK_CASE(case_svg_nan_breaks_line), TK_CASE(case_svg_escapes_text),
         TK_CASE(case_svg_ticks_are_round),
         TK_CASE(case_svg_edge_inputs_and_io_error))
