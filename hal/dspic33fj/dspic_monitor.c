#include "dspic_monitor.h"

void dspic_mon_init(dspic_mon_t *m)
{
    m->line[0] = '\0';
    m->len = 0;
    m->overflow = 0;
}

static char to_lower(char c)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    return (c >= 'A' && c <= 'Z') ? (char)('a' + (uint8_t)(c - 'A')) : c;
}

uint8_t dspic_mon_feed(dspic_mon_t *m, char c, dspic_mon_cmd_t *cmd)
{
    if (c == '\r' || c == '\n') {
        const uint8_t had_text = (uint8_t)(m->len > 0u || m->overflow != 0u);
        if (m->overflow != 0u) {
            cmd->kind = DSPIC_MON_ERR_TOO_LONG;
            cmd->rpm = 0;
        } else if (had_text != 0u) {
            m->line[m->len] = '\0';
            *cmd = dspic_mon_parse(m->line);
        } else {
            /* an empty line: nothing to parse */
        }
        dspic_mon_init(m);
        if (had_text != 0u && cmd->kind == DSPIC_MON_NONE) {
            return 0; /* only blanks */
        }
        return had_text;
    }
    if (m->len >= DSPIC_MON_LINE_MAX) {
        m->overflow = 1;
        return 0;
    }
    m->line[m->len] = to_lower(c);
    m->len++;
    return 0;
}

static const char *skip_blanks(const char *p)
{
    while (*p == ' ' || *p == '\t') {
        p++;
    }
    return p;
}

/* Matches a word followed by a blank or the end; returns the rest. */
static const char *match_word(const char *p, const char *word)
{
    while (*word != '\0') {
        if (*p != *word) {
            return (const char *)0;
        }
        p++;
        word++;
    }
    return (*p == '\0' || *p == ' ' || *p == '\t') ? p : (const char *)0;
}

/* A signed decimal with |v| <= DSPIC_MON_RPM_LIMIT and nothing after it
 * but blanks; returns 1 on success. */
static uint8_t parse_int(const char *p, int32_t *out)
{
    int32_t v = 0;
    uint8_t neg = 0;
    uint8_t digits = 0;
    if (*p == '-' || *p == '+') {
        neg = (uint8_t)(*p == '-');
        p++;
    }
    while (*p >= '0' && *p <= '9') {
        v = v * 10 + (int32_t)(*p - '0');
        if (v > DSPIC_MON_RPM_LIMIT) {
            return 0;
        }
        digits++;
        p++;
    }
    if (digits == 0u || *skip_blanks(p) != '\0') {
        return 0;
    }
    *out = (neg != 0u) ? -v : v;
    return 1;
}

dspic_mon_cmd_t dspic_mon_parse(const char *line)
{
    static const struct {
        const char *word;
        dspic_mon_kind_t kind;
    } simple[] = {
        { "start", DSPIC_MON_START },   { "stop", DSPIC_MON_STOP },
        { "ack", DSPIC_MON_ACK },       { "status", DSPIC_MON_STATUS },
        { "help", DSPIC_MON_HELP },
    };
    dspic_mon_cmd_t cmd = { DSPIC_MON_ERR_UNKNOWN, 0 };
    const char *p = skip_blanks(line);
    const char *rest;
    size_t i;

    if (*p == '\0') {
        cmd.kind = DSPIC_MON_NONE;
        return cmd;
    }
    for (i = 0; i < sizeof simple / sizeof simple[0]; i++) {
        rest = match_word(p, simple[i].word);
        if (rest != (const char *)0 && *skip_blanks(rest) == '\0') {
            cmd.kind = simple[i].kind;
            return cmd;
        }
    }
    rest = match_word(p, "speed");
    if (rest != (const char *)0) {
        const char *arg = skip_blanks(rest);
        const char *after_pot = match_word(arg, "pot");
        if (after_pot != (const char *)0 && *skip_blanks(after_pot) == '\0') {
            cmd.kind = DSPIC_MON_SPEED_POT;
        } else if (parse_int(arg, &cmd.rpm) != 0u) {
            cmd.kind = DSPIC_MON_SPEED;
        } else {
            cmd.kind = DSPIC_MON_ERR_ARGUMENT;
            cmd.rpm = 0;
        }
    }
    return cmd;
}

const char *dspic_mon_reply(dspic_mon_kind_t kind)
{
    switch (kind) {
    case DSPIC_MON_ERR_UNKNOWN:
        return "err unknown command (help)";
    case DSPIC_MON_ERR_ARGUMENT:
        return "err speed needs <rpm> or pot";
    case DSPIC_MON_ERR_TOO_LONG:
        return "err line too long";
    default:
        return "ok";
    }
}

const char *dspic_mon_help(void)
{
    return "start | stop | ack | speed <rpm> | speed pot | status";
}

void dspic_mon_put_str(char *buf, size_t size, size_t *len, const char *s)
{
    if (size == 0u) {
        return;
    }
    while (*s != '\0' && *len + 1u < size) {
        buf[*len] = *s;
        (*len)++;
        s++;
    }
    buf[*len] = '\0';
}

void dspic_mon_put_int(char *buf, size_t size, size_t *len, int32_t v)
{
    char tmp[12]; /* "-2147483648" */
    uint8_t n = 0;
    /* magnitude as unsigned: no overflow for INT32_MIN */
    uint32_t mag = (v < 0) ? (uint32_t)0 - (uint32_t)v : (uint32_t)v;
    char out[13];
    uint8_t k = 0;
    do {
        tmp[n] = (char)('0' + (uint8_t)(mag % 10u));
        n++;
        mag /= 10u;
    } while (mag != 0u);
    if (v < 0) {
        out[k] = '-';
        k++;
    }
    while (n > 0u) {
        n--;
        out[k] = tmp[n];
        k++;
    }
    out[k] = '\0';
    dspic_mon_put_str(buf, size, len, out);
}

void dspic_mon_put_hex16(char *buf, size_t size, size_t *len, uint16_t v)
{
    static const char hex[] = "0123456789ABCDEF";
    char out[7];
    out[0] = '0';
    out[1] = 'x';
    out[2] = hex[(v >> 12) & 0xFu];
    out[3] = hex[(v >> 8) & 0xFu];
    out[4] = hex[(v >> 4) & 0xFu];
    out[5] = hex[v & 0xFu];
    out[6] = '\0';
    dspic_mon_put_str(buf, size, len, out);
}

static void put_u32(char *buf, size_t size, size_t *len, uint32_t v)
{
    /* values shown here stay far below 2^31 */
    dspic_mon_put_int(buf, size, len, (v > 0x7FFFFFFFuL) ? 0x7FFFFFFFL : (int32_t)v);
}

size_t dspic_mon_format_status(char *buf, size_t size, const dspic_mon_status_t *st)
{
    size_t len = 0;
    if (size == 0u) {
        return 0;
    }
    buf[0] = '\0';
    dspic_mon_put_str(buf, size, &len, "state=");
    dspic_mon_put_str(buf, size, &len, st->state);
    dspic_mon_put_str(buf, size, &len, " faults=");
    dspic_mon_put_hex16(buf, size, &len, st->faults);
    dspic_mon_put_str(buf, size, &len, " first=");
    dspic_mon_put_str(buf, size, &len, st->first_fault);
    dspic_mon_put_str(buf, size, &len, " rpm=");
    dspic_mon_put_int(buf, size, &len, st->speed_rpm);
    dspic_mon_put_str(buf, size, &len, " ref=");
    dspic_mon_put_int(buf, size, &len, st->ref_rpm);
    dspic_mon_put_str(buf, size, &len, " id_ma=");
    dspic_mon_put_int(buf, size, &len, st->id_ma);
    dspic_mon_put_str(buf, size, &len, " iq_ma=");
    dspic_mon_put_int(buf, size, &len, st->iq_ma);
    dspic_mon_put_str(buf, size, &len, " vdc_mv=");
    put_u32(buf, size, &len, st->vdc_mv);
    dspic_mon_put_str(buf, size, &len, " isr_ns=");
    put_u32(buf, size, &len, st->isr_min_ns);
    dspic_mon_put_str(buf, size, &len, "/");
    put_u32(buf, size, &len, st->isr_avg_ns);
    dspic_mon_put_str(buf, size, &len, "/");
    put_u32(buf, size, &len, st->isr_max_ns);
    dspic_mon_put_str(buf, size, &len, (st->fw_range != 0u) ? " range=fw" : " range=normal");
    dspic_mon_put_str(buf, size, &len, (st->pot_source != 0u) ? " src=pot" : " src=uart");
    return len;
}

q15_t dspic_rpm_to_q15(int32_t rpm, int32_t base_rpm)
{
    if (base_rpm <= 0 || base_rpm > 65535L) {
        return 0;
    }
    const uint8_t neg = (uint8_t)(rpm < 0);
    const uint32_t mag = (neg != 0u) ? (uint32_t)0 - (uint32_t)rpm : (uint32_t)rpm;
    if (mag >= (uint32_t)base_rpm) {
        return (neg != 0u) ? Q15_MIN : Q15_MAX;
    }
    /* mag < base <= 65535: mag x 32768 < 2^31 */
    const uint32_t base = (uint32_t)base_rpm;
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    const int32_t q = (int32_t)((mag * 32768u + base / 2u) / base);
    return foc_sat_q15((neg != 0u) ? -q : q);
}

int32_t dspic_q15_to_rpm(q15_t q, int32_t base_rpm)
{
    if (base_rpm <= 0 || base_rpm > 65535L) {
        return 0;
    }
    const uint8_t neg = (uint8_t)(q < 0);
    const uint32_t mag = (uint32_t)((neg != 0u) ? -(int32_t)q : (int32_t)q);
    /* mag <= 32768, base <= 65535: the product fits */
    const int32_t r = (int32_t)((mag * (uint32_t)base_rpm + 16384u) >> 15);
    return (neg != 0u) ? -r : r;
}
