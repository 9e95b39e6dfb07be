/* SVG plot writer; see svgplot.h for what the plot shows. */
#include "svgplot.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Layout, in px. */
enum {
    WIDTH = 1200,
    PLOT_X0 = 84,         /* room for tick labels and the rotated unit */
    UNIT_X = 24,          /* baseline of the rotated unit label */
    LEGEND_WIDTH = 190,   /* right of the plot area */
    TITLE_HEIGHT = 40,
    BAND_LEGEND_HEIGHT = 22,
    BAND_LANE_HEIGHT = 18,
    BAND_LANE_GAP = 6,
    PANEL_TITLE_HEIGHT = 24,
    PANEL_MIN_HEIGHT = 170,
    PANEL_GAP = 14,
    LEGEND_ROW = 18,
    TIME_AXIS_HEIGHT = 48,
    Y_TICKS = 8,          /* labels at most, per panel */
    T_TICKS = 12          /* labels at most */
};
#define PLOT_X1 (WIDTH - LEGEND_WIDTH)
#define Y_MARGIN 0.06 /* of the data range, above and below */
#define PLOT_WIDTH (PLOT_X1 - PLOT_X0)

/* Rough advance of a character of the 11-12 px sans-serif font; used only
 * to decide whether a label fits and to space the band legend. */
#define CHAR_WIDTH 7.0

static const char *const series_palette[] = {
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e",
    "#9467bd", "#8c564b", "#e377c2", "#17becf",
};
/* Light, so that lines stay readable on top; neighbours differ in hue. */
static const char *const band_palette[] = {
    "#dce9fb", "#dcf1d8", "#feedc9", "#eadcf5",
    "#e6e6e6", "#d3efee", "#f3e3d0",
};
static const char fault_band_color[] = "#f7c4c4";
#define N_SERIES_COLORS (sizeof series_palette / sizeof series_palette[0])
#define N_BAND_COLORS (sizeof band_palette / sizeof band_palette[0])

/* Linear map of a data range onto a pixel range. */
typedef struct {
    double v0, v1;   /* data */
    double px0, px1; /* pixels */
} axis_t;

static double to_px(const axis_t *a, double v)
{
    return a->px0 + (v - a->v0) * (a->px1 - a->px0) / (a->v1 - a->v0);
}

/* Text content or attribute value, XML-escaped; characters XML 1.0 cannot
 * hold become '?'. */
static void put_text(FILE *f, const char *s)
{
    for (; s != NULL && *s != '\0'; s++) {
        const unsigned char c = (unsigned char)*s;
        switch (c) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        case '\'': fputs("&apos;", f); break;
        default: fputc(c < 0x20 && c != '\t' ? '?' : c, f); break;
        }
    }
}

/* <text ...attrs>escaped s</text> */
static void put_text_element(FILE *f, double x, double y, const char *attrs,
                             const char *s)
{
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" %s>", x, y, attrs);
    put_text(f, s);
    fputs("</text>\n", f);
}

/* Ticks k * step for k in [*k0, *k1] covering the axis range; integer
 * multiples, so that rounding does not accumulate along the axis. */
static void tick_range(const axis_t *a, double step, long *k0, long *k1)
{
    *k0 = (long)ceil(a->v0 / step - 1e-9);
    *k1 = (long)floor(a->v1 / step + 1e-9);
}

/* The smallest 1, 2 or 5 x 10^n step that puts at most max_ticks ticks in
 * the (finite, non-empty) range of the axis. */
static double nice_step(const axis_t *a, long max_ticks)
{
    static const double mantissas[] = { 1.0, 2.0, 5.0 };
    double decade = pow(10.0, floor(log10((a->v1 - a->v0) / (double)max_ticks)));
    for (;; decade *= 10.0) {
        for (size_t i = 0; i < sizeof mantissas / sizeof mantissas[0]; i++) {
            long k0, k1;
            tick_range(a, mantissas[i] * decade, &k0, &k1);
            if (k1 - k0 + 1 <= max_ticks) {
                return mantissas[i] * decade;
            }
        }
    }
}

/* A tick value with just the decimals its step needs ("0.25", "1500"). */
static void format_tick(char *buf, size_t len, double v, double step)
{
    if (fabs(v) < step * 1e-6) {
        v = 0.0; /* no "-0" or "1e-17" from accumulated rounding */
    }
    const double digits = ceil(-log10(step) - 1e-9);
    if (digits > 6 || fabs(v) >= 1e7) {
        snprintf(buf, len, "%g", v);
    } else {
        snprintf(buf, len, "%.*f", digits > 0 ? (int)digits : 0, v);
    }
}

static int is_fault_label(const char *s)
{
    static const char word[] = "fault";
    for (; s != NULL && *s != '\0'; s++) {
        size_t i = 0;
        while (word[i] != '\0' && tolower((unsigned char)s[i]) == word[i]) {
            i++;
        }
        if (word[i] == '\0') {
            return 1;
        }
    }
    return 0;
}

static int same_label(const char *a, const char *b)
{
    return strcmp(a != NULL ? a : "", b != NULL ? b : "") == 0;
}

/* Fill colour of each band: one palette entry per distinct label, in order
 * of first appearance.  Also flags the first band of each label, so the
 * legend lists each label once. */
static void assign_band_colors(const svg_band_t *bands, size_t nbands,
                               const char **color, unsigned char *first)
{
    size_t distinct = 0;
    for (size_t i = 0; i < nbands; i++) {
        size_t j = 0;
        while (j < i && !same_label(bands[j].label, bands[i].label)) {
            j++;
        }
        first[i] = j == i;
        if (j < i) {
            color[i] = color[j];
        } else if (is_fault_label(bands[i].label)) {
            color[i] = fault_band_color;
        } else {
            color[i] = band_palette[distinct++ % N_BAND_COLORS];
        }
    }
}

/* Decimated polyline state: pen up means the next point starts a new
 * subpath; a subpath of one point gets a zero-length segment so that the
 * round line cap shows it as a dot. */
typedef struct {
    FILE *f;
    int points; /* in the current subpath */
} pen_t;

static void pen_lift(pen_t *p)
{
    if (p->points == 1) {
        fputs(" h0", p->f);
    }
    p->points = 0;
}

static void pen_point(pen_t *p, double x, double y)
{
    fprintf(p->f, "%s%.1f,%.1f", p->points == 0 ? " M" : " L", x, y);
    p->points++;
}

/* Finite samples of one pixel column, and whether non-finite ones come
 * before the first or after the last of them (a gap in the line). */
typedef struct {
    size_t imin, imax;
    int finite;
    int gap_before, gap_after;
} column_t;

static void column_flush(pen_t *p, const column_t *c, const double *t,
                         const double *y, const axis_t *tx, const axis_t *ya)
{
    if (c->gap_before || !c->finite) {
        pen_lift(p);
    }
    if (c->finite) {
        const size_t a = c->imin < c->imax ? c->imin : c->imax;
        const size_t b = c->imin < c->imax ? c->imax : c->imin;
        pen_point(p, to_px(tx, t[a]), to_px(ya, y[a]));
        if (b != a) {
            pen_point(p, to_px(tx, t[b]), to_px(ya, y[b]));
        }
    }
    if (c->gap_after) {
        pen_lift(p);
    }
}

static void put_series(FILE *f, const double *t, const double *y, size_t n,
                       const axis_t *tx, const axis_t *ya, const char *color)
{
    fputs("<path class=\"series\" fill=\"none\" stroke-width=\"1.4\" "
          "stroke-linejoin=\"round\" stroke-linecap=\"round\" stroke=\"", f);
    put_text(f, color);
    fputs("\" d=\"", f);
    pen_t pen = { f, 0 };
    column_t col = { 0, 0, 0, 0, 0 };
    long col_index = -1;
    for (size_t i = 0; i < n; i++) {
        const int ok = isfinite(t[i]) && isfinite(y[i]);
        long here = col_index;
        if (isfinite(t[i])) {
            here = (long)floor(to_px(tx, t[i]) - PLOT_X0);
            here = here < 0 ? 0 : here >= PLOT_WIDTH ? PLOT_WIDTH - 1 : here;
        }
        if (here != col_index && i > 0) {
            column_flush(&pen, &col, t, y, tx, ya);
            memset(&col, 0, sizeof col);
        }
        col_index = here;
        if (!ok) {
            col.gap_before |= !col.finite;
            col.gap_after = col.finite;
        } else if (!col.finite) {
            col.imin = col.imax = i;
            col.finite = 1;
        } else {
            col.imin = y[i] < y[col.imin] ? i : col.imin;
            col.imax = y[i] > y[col.imax] ? i : col.imax;
            col.gap_after = 0;
        }
    }
    if (n > 0) {
        column_flush(&pen, &col, t, y, tx, ya);
    }
    pen_lift(&pen);
    fputs("\"/>\n", f);
}

/* Finite range of all series of a panel plus a margin, so that extreme
 * values stay off the frame; the tick step is returned in *step. */
static axis_t panel_y_axis(const svg_panel_t *p, size_t n, double top,
                           double bottom, double *step)
{
    double lo = INFINITY;
    double hi = -INFINITY;
    for (size_t s = 0; s < p->nseries; s++) {
        for (size_t i = 0; i < n; i++) {
            const double v = p->series[s].y[i];
            if (isfinite(v)) {
                lo = fmin(lo, v);
                hi = fmax(hi, v);
            }
        }
    }
    if (lo > hi) { /* nothing finite */
        lo = -1.0;
        hi = 1.0;
    } else if (hi - lo <= 1e-9 * fmax(fabs(lo), fabs(hi))) {
        const double pad = lo != 0.0 ? 0.1 * fabs(lo) : 1.0;
        lo -= pad;
        hi += pad;
    }
    const double margin = Y_MARGIN * (hi - lo);
    const axis_t a = { lo - margin, hi + margin, bottom, top };
    *step = nice_step(&a, Y_TICKS);
    return a;
}

/* Shades each band over [top, top + height].  In the lane each label is
 * written inside its band when it fits; behind the data the shading is
 * paler, so that long bands do not mute the lines.  Bands shorter than a
 * few pixels (a brief fault) are widened and drawn last, opaque, so that
 * they are not hidden by their neighbours. */
static void put_bands(FILE *f, const axis_t *tx, const svg_band_t *bands,
                      size_t nbands, const char *const *band_color, double top,
                      double height, int lane)
{
    const double min_width = lane ? 3.0 : 2.0;
    for (int narrow_pass = 0; narrow_pass <= 1; narrow_pass++) {
        for (size_t b = 0; b < nbands; b++) {
            double x0 = to_px(tx, fmax(bands[b].t0_s, tx->v0));
            double x1 = to_px(tx, fmin(bands[b].t1_s, tx->v1));
            if (!(x1 >= x0) || (x1 - x0 < min_width) != narrow_pass) {
                continue; /* out of range, reversed, NaN, or other pass */
            }
            if (narrow_pass) {
                x0 = (x0 + x1 - min_width) / 2;
                x1 = x0 + min_width;
            }
            fprintf(f, "<rect class=\"band\" x=\"%.1f\" y=\"%.1f\" "
                       "width=\"%.1f\" height=\"%.1f\" fill=\"%s\" "
                       "fill-opacity=\"%s\"/>\n",
                    x0, top, x1 - x0, height, band_color[b],
                    lane || narrow_pass ? "1" : "0.6");
            const char *label = bands[b].label != NULL ? bands[b].label : "";
            if (lane && x1 - x0 >= CHAR_WIDTH * (double)strlen(label) + 6) {
                put_text_element(f, (x0 + x1) / 2, top + height / 2 + 4,
                                 "class=\"band-label\" font-size=\"11\" "
                                 "fill=\"#333\" text-anchor=\"middle\"",
                                 label);
            }
        }
    }
}

/* A labelled strip of the bands above the first panel: the state timeline. */
static void put_band_lane(FILE *f, const axis_t *tx, const svg_band_t *bands,
                          size_t nbands, const char *const *band_color,
                          double top)
{
    put_bands(f, tx, bands, nbands, band_color, top, BAND_LANE_HEIGHT, 1);
    fprintf(f, "<rect x=\"%d\" y=\"%.1f\" width=\"%d\" height=\"%d\" "
               "fill=\"none\" stroke=\"#808080\"/>\n",
            PLOT_X0, top, PLOT_WIDTH, BAND_LANE_HEIGHT);
}

static const char *series_color(const svg_panel_t *p, size_t s)
{
    return p->series[s].color != NULL ? p->series[s].color
                                      : series_palette[s % N_SERIES_COLORS];
}

static void put_panel(FILE *f, const svg_panel_t *p, const double *t, size_t n,
                      const axis_t *tx, double t_step, double top,
                      double height, const svg_band_t *bands, size_t nbands,
                      const char *const *band_color)
{
    const double bottom = top + height;
    double y_step;
    const axis_t ya = panel_y_axis(p, n, top, bottom, &y_step);

    put_bands(f, tx, bands, nbands, band_color, top, height, 0);
    fputs("<g stroke=\"#e2e2e2\" stroke-width=\"1\">\n", f);
    long tk0, tk1, yk0, yk1;
    tick_range(tx, t_step, &tk0, &tk1);
    tick_range(&ya, y_step, &yk0, &yk1);
    for (long k = tk0; k <= tk1; k++) {
        const double x = to_px(tx, (double)k * t_step);
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\"/>\n",
                x, top, x, bottom);
    }
    for (long k = yk0; k <= yk1; k++) {
        const double y = to_px(&ya, (double)k * y_step);
        fprintf(f, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\"/>\n",
                PLOT_X0, y, PLOT_X1, y);
    }
    fputs("</g>\n", f);
    if (ya.v0 < 0.0 && ya.v1 > 0.0) {
        const double y0 = to_px(&ya, 0.0);
        fprintf(f, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" "
                   "stroke=\"#9a9a9a\" stroke-width=\"1\"/>\n",
                PLOT_X0, y0, PLOT_X1, y0);
    }

    for (size_t s = 0; s < p->nseries; s++) {
        const char *color = series_color(p, s);
        put_series(f, t, p->series[s].y, n, tx, &ya, color);
    }

    fprintf(f, "<rect x=\"%d\" y=\"%.1f\" width=\"%d\" height=\"%.1f\" "
               "fill=\"none\" stroke=\"#808080\"/>\n",
            PLOT_X0, top, PLOT_WIDTH, height);
    for (long k = yk0; k <= yk1; k++) {
        const double v = (double)k * y_step;
        char label[32];
        format_tick(label, sizeof label, v, y_step);
        put_text_element(f, PLOT_X0 - 6, to_px(&ya, v) + 4,
                         "class=\"ytick\" font-size=\"11\" fill=\"#444\" "
                         "text-anchor=\"end\"", label);
    }
    if (p->unit != NULL && p->unit[0] != '\0') {
        const double mid = top + height / 2;
        fprintf(f, "<text class=\"unit\" x=\"%d\" y=\"%.1f\" "
                   "font-size=\"12\" fill=\"#333\" text-anchor=\"middle\" "
                   "transform=\"rotate(-90 %d %.1f)\">",
                UNIT_X, mid, UNIT_X, mid);
        put_text(f, p->unit);
        fputs("</text>\n", f);
    }
    put_text_element(f, PLOT_X0, top - 7,
                     "class=\"panel-title\" font-size=\"13\" "
                     "font-weight=\"bold\" fill=\"#222\"", p->title);

    for (size_t s = 0; s < p->nseries; s++) {
        const char *color = series_color(p, s);
        const double y = top + 14 + LEGEND_ROW * (double)s;
        fprintf(f, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" "
                   "stroke-width=\"3\" stroke=\"", PLOT_X1 + 12, y - 4,
                PLOT_X1 + 34, y - 4);
        put_text(f, color);
        fputs("\"/>\n", f);
        put_text_element(f, PLOT_X1 + 40, y,
                         "class=\"legend\" font-size=\"12\" fill=\"#222\"",
                         p->series[s].label);
    }
}

/* Time tick labels and the axis title under the last panel. */
static void put_time_axis(FILE *f, const axis_t *tx, double step, double y)
{
    long k0, k1;
    tick_range(tx, step, &k0, &k1);
    for (long k = k0; k <= k1; k++) {
        const double v = (double)k * step;
        char label[32];
        format_tick(label, sizeof label, v, step);
        put_text_element(f, to_px(tx, v), y + 15,
                         "class=\"ttick\" font-size=\"11\" fill=\"#444\" "
                         "text-anchor=\"middle\"", label);
    }
    put_text_element(f, (PLOT_X0 + PLOT_X1) / 2.0, y + 36,
                     "class=\"axis-label\" font-size=\"12\" fill=\"#333\" "
                     "text-anchor=\"middle\"", "time (s)");
}

/* One swatch and name per distinct band label, in a row under the title. */
static void put_band_legend(FILE *f, const svg_band_t *bands, size_t nbands,
                            const char *const *band_color,
                            const unsigned char *first, double y)
{
    double x = PLOT_X0;
    for (size_t b = 0; b < nbands; b++) {
        if (!first[b]) {
            continue;
        }
        fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"16\" height=\"11\" "
                   "fill=\"%s\" stroke=\"#999\" stroke-width=\"0.5\"/>\n",
                x, y - 10, band_color[b]);
        put_text_element(f, x + 21, y,
                         "class=\"band-legend\" font-size=\"12\" fill=\"#333\"",
                         bands[b].label);
        x += 21 + CHAR_WIDTH * (double)strlen(bands[b].label != NULL
                                                  ? bands[b].label : "") + 16;
    }
}

static double panel_height(const svg_panel_t *p)
{
    const double legend = 12.0 + LEGEND_ROW * (double)p->nseries;
    return fmax(PANEL_MIN_HEIGHT, legend);
}

int svg_write(const char *path, const char *title, const double *t, size_t n,
              const svg_panel_t *panels, size_t npanels,
              const svg_band_t *bands, size_t nbands)
{
    const char **band_color = malloc((nbands + 1) * sizeof *band_color);
    unsigned char *first = malloc(nbands + 1);
    FILE *f = band_color != NULL && first != NULL ? fopen(path, "w") : NULL;
    if (f == NULL) {
        free(band_color);
        free(first);
        return -1;
    }
    assign_band_colors(bands, nbands, band_color, first);

    axis_t tx = { 0.0, 1.0, PLOT_X0, PLOT_X1 };
    if (n > 0 && isfinite(t[0])) {
        tx.v0 = t[0];
        tx.v1 = n > 1 && isfinite(t[n - 1]) && t[n - 1] > t[0] ? t[n - 1]
                                                            : t[0] + 1.0;
    }
    const double t_step = nice_step(&tx, T_TICKS);
    /* A run sampled up to just before a round end time ends on a tick. */
    const double t_round = ceil(tx.v1 / t_step) * t_step;
    if (t_round - tx.v1 < 0.01 * (tx.v1 - tx.v0)) {
        tx.v1 = t_round;
    }

    const double bands_height =
        nbands > 0 ? BAND_LEGEND_HEIGHT + BAND_LANE_HEIGHT + BAND_LANE_GAP : 0;
    double height = TITLE_HEIGHT + bands_height;
    for (size_t i = 0; i < npanels; i++) {
        height += PANEL_TITLE_HEIGHT + panel_height(&panels[i]) + PANEL_GAP;
    }
    height += TIME_AXIS_HEIGHT - PANEL_GAP;

    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
               "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" "
               "height=\"%.0f\" viewBox=\"0 0 %d %.0f\" "
               "font-family=\"DejaVu Sans, Arial, Helvetica, sans-serif\">\n",
            WIDTH, height, WIDTH, height);
    fputs("<title>", f);
    put_text(f, title);
    fputs("</title>\n", f);
    fprintf(f, "<rect width=\"%d\" height=\"%.0f\" fill=\"white\"/>\n", WIDTH,
            height);
    put_text_element(f, PLOT_X0, 26,
                     "class=\"title\" font-size=\"17\" font-weight=\"bold\" "
                     "fill=\"#111\"", title);

    double y = TITLE_HEIGHT;
    if (nbands > 0) {
        put_band_legend(f, bands, nbands, band_color, first, y + 6);
        put_band_lane(f, &tx, bands, nbands, band_color,
                      y + BAND_LEGEND_HEIGHT);
        y += bands_height;
    }
    for (size_t i = 0; i < npanels; i++) {
        const double h = panel_height(&panels[i]);
        y += PANEL_TITLE_HEIGHT;
        put_panel(f, &panels[i], t, n, &tx, t_step, y, h, bands, nbands,
                  band_color);
        y += h + PANEL_GAP;
    }
    put_time_axis(f, &tx, t_step, y - PANEL_GAP);
    fputs("</svg>\n", f);

    free(band_color);
    free(first);
    const int write_failed = ferror(f);
    return fclose(f) != 0 || write_failed ? -1 : 0;
}
