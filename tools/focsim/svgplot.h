/*
 * Stacked multi-panel time plot written as a standalone SVG file.
 *
 * All panels share the time axis (drawn under the last panel, "time (s)").
 * Each panel has a title, a y axis labelled with its unit, round-number
 * ticks (1, 2 or 5 x 10^n) with grid lines, a line at zero when zero is in
 * range, and a legend to its right.  Bands shade time spans in every panel
 * (e.g. the controller state); each distinct label gets its own light colour
 * (labels containing "fault", any case, get light red).  The labels are
 * listed in a legend under the title and written inside their bands in a
 * labelled strip above the first panel when they fit; bands too short to
 * see are widened to a few pixels.
 *
 * Series are decimated to the minimum and maximum of each pixel column, so
 * any input size gives at most two points per column (< 2000 per series)
 * and short spikes stay visible.  NaN or infinite values break the line;
 * an isolated finite point is drawn as a dot.  Text is XML-escaped.
 */
#ifndef FOCSIM_SVGPLOT_H
#define FOCSIM_SVGPLOT_H

#include <stddef.h>

/* One line; `y` has the n points of svg_write's time vector.  `color` is any
 * SVG colour; NULL picks one from a default palette by series index. */
typedef struct {
    const char *label;
    const char *color;
    const double *y;
} svg_series_t;

typedef struct {
    const char *title;
    const char *unit; /* y axis label, e.g. "A"; NULL or "" for none */
    const svg_series_t *series;
    size_t nseries;
} svg_panel_t;

/* Shaded time span; colour chosen per distinct label. */
typedef struct {
    double t0_s, t1_s;
    const char *label;
} svg_band_t;

/* Writes the plot to `path`.  `t` holds n non-decreasing times (s); the
 * time axis spans t[0] .. t[n-1], extended to the next tick when that is
 * within 1 % (a run sampled up to just before its end time), or 1 s from
 * t[0] if the span is empty (0 .. 1 s without samples).  Labels and titles
 * may be NULL.  Returns 0 on success, -1 on I/O or allocation error. */
int svg_write(const char *path, const char *title, const double *t, size_t n,
              const svg_panel_t *panels, size_t npanels,
              const svg_band_t *bands, size_t nbands);

#endif /* FOCSIM_SVGPLOT_H */
