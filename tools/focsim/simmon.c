/* focsim's monitor script runner; see simmon.h. */
#include "simmon.h"

#include <ctype.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>

/* The monitor's write callback has no context: one output at a time. */
static FILE *out_file;

static void write_out(const char *s, size_t n)
{
    if (out_file != NULL) {
        fwrite(s, 1, n, out_file);
    }
}

static void free_cmds(simmon_t *m)
{
    for (size_t i = 0; i < m->count; i++) {
        free(m->cmds[i].text);
    }
    free(m->cmds);
    m->cmds = NULL;
    m->count = 0;
}

/* One script line; 1 if it holds a command, 0 if blank or a comment, -1 on
 * error (message in err). */
static int parse_line(char *line, double prev_t, simmon_cmd_t *cmd, char *err,
                      size_t errlen)
{
    line[strcspn(line, "\r\n")] = '\0';
    char *p = line;
    while (isspace((unsigned char)*p)) {
        p++;
    }
    if (*p == '\0' || *p == '#') {
        return 0;
    }
    char *end = NULL;
    errno = 0;
    const double t = strtod(p, &end);
    if (end == p || errno != 0 || !(t >= 0.0) || !isspace((unsigned char)*end)) {
        snprintf(err, errlen, "expected '<time_s> <command>'");
        return -1;
    }
    if (t < prev_t) {
        snprintf(err, errlen, "time %g is before the previous line's", t);
        return -1;
    }
    while (isspace((unsigned char)*end)) {
        end++;
    }
    if (*end == '\0') {
        snprintf(err, errlen, "no command after the time");
        return -1;
    }
    cmd->t_s = t;
    cmd->text = malloc(strlen(end) + 1);
    if (cmd->text == NULL) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    strcpy(cmd->text, end);
    return 1;
}

static int read_script(simmon_t *m, const char *path, char *err, size_t errlen)
{
    FILE *f = fopen(path, "r");
    if (f == NULL) {
        snprintf(err, errlen, "cannot read %s: %s", path, strerror(errno));
        return -1;
    }
    size_t cap = 0;
    char line[512];
    char why[160];
    unsigned lineno = 0;
    int rc = 0;
    while (rc == 0 && fgets(line, sizeof line, f) != NULL) {
        lineno++;
        if (strchr(line, '\n') == NULL && !feof(f)) {
            snprintf(err, errlen, "%s:%u: line too long", path, lineno);
            rc = -1;
            break;
        }
        if (m->count == cap) {
            cap = cap ? 2 * cap : 16;
            simmon_cmd_t *c = realloc(m->cmds, cap * sizeof *c);
            if (c == NULL) {
                snprintf(err, errlen, "out of memory");
                rc = -1;
                break;
            }
            m->cmds = c;
        }
        const double prev_t = m->count ? m->cmds[m->count - 1].t_s : 0.0;
        const int got = parse_line(line, prev_t, &m->cmds[m->count], why, sizeof why);
        if (got < 0) {
            snprintf(err, errlen, "%s:%u: %s", path, lineno, why);
            rc = -1;
        } else {
            m->count += (size_t)got;
        }
    }
    fclose(f);
    return rc;
}

int simmon_open(simmon_t *m, const char *script, const char *out_path,
                foc_ctrl_t *ctrl, char *err, size_t errlen)
{
    m->cmds = NULL;
    m->count = 0;
    m->next = 0;
    m->out = NULL;
    if (read_script(m, script, err, errlen) != 0) {
        free_cmds(m);
        return -1;
    }
    if (out_path == NULL || strcmp(out_path, "-") == 0) {
        m->out = stdout;
    } else {
        m->out = fopen(out_path, "wb"); /* CR LF as the UART sends them */
        if (m->out == NULL) {
            snprintf(err, errlen, "cannot write %s: %s", out_path, strerror(errno));
            free_cmds(m);
            return -1;
        }
    }
    out_file = m->out;
    foc_scope_init(&m->scope, ctrl, m->buf, (uint16_t)SIMMON_SCOPE_SAMPLES);
    foc_mon_init(&m->mon, ctrl, &m->scope, NULL, write_out);
    return 0;
}

void simmon_run(simmon_t *m, double t_s)
{
    while (m->next < m->count && m->cmds[m->next].t_s <= t_s) {
        for (const char *p = m->cmds[m->next].text; *p != '\0'; p++) {
            foc_mon_feed(&m->mon, (uint8_t)*p);
        }
        foc_mon_feed(&m->mon, (uint8_t)'\r');
        foc_mon_feed(&m->mon, (uint8_t)'\n');
        while (foc_mon_poll(&m->mon) != 0u) {
        }
        m->next++;
    }
}

int simmon_close(simmon_t *m)
{
    int rc = 0;
    if (m->out != NULL) {
        if (m->out == stdout) {
            rc = fflush(stdout) != 0 ? -1 : 0;
        } else {
            const int failed = ferror(m->out);
            rc = (fclose(m->out) != 0 || failed) ? -1 : 0;
        }
    }
    m->out = NULL;
    out_file = NULL;
    free_cmds(m);
    return rc;
}
