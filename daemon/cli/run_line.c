/* run_line.c — the live progress line of `packd run` (run_line.h). */
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include "run_line.h"

static int locale_is_utf8(void)
{
    const char *v[] = {"LC_ALL", "LC_CTYPE", "LANG"};
    for (int i = 0; i < 3; i++) {
        const char *s = getenv(v[i]);
        if (s && *s)
            return strstr(s, "UTF-8") || strstr(s, "utf-8") || strstr(s, "UTF8") ||
                strstr(s, "utf8");
    }
    return 0;
}

void pk_run_line_init(pk_run_line *l, FILE *tty)
{
    memset(l, 0, sizeof *l);
    l->t0 = pk_wall_seconds();
    l->utf8 = locale_is_utf8();
    const char *term = getenv("TERM");
    if (!tty || !isatty(fileno(tty)) || (term && !strcmp(term, "dumb")))
        return;
    l->tty = tty;
    struct winsize ws;
    l->cols = ioctl(fileno(tty), TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 ? ws.ws_col : 80;
    l->fraction = l->phi = l->eta_s = -1;
    l->delta_d = 0;
}

void pk_run_line_duration(double s, char *out, size_t n)
{
    if (s < 60)
        snprintf(out, n, "%.1f s", s);
    else if (s < 3600)
        snprintf(out, n, "%d min %02d s", (int)(s / 60), (int)s % 60);
    else
        snprintf(out, n, "%d h %02d min", (int)(s / 3600), (int)(s / 60) % 60);
}

/* Bytes of a UTF-8 string that fill at most cols characters on the screen
 * (continuation bytes take none). */
static size_t screen_cut(const char *s, int cols)
{
    int w = 0;
    size_t i = 0;
    for (; s[i]; i++) {
        if (((unsigned char)s[i] & 0xc0) == 0x80)
            continue;
        if (w == cols)
            break;
        w++;
    }
    return i;
}

void pk_run_line_draw(pk_run_line *l, const pk_progress *p)
{
    if (!l->tty)
        return;
    double now = pk_wall_seconds();
    const char *stage = p->stage ? p->stage : "";
    const char *inner = NULL;
    if (p->fraction >= 0 || !l->outer[0]) {
        if (strcmp(l->outer, stage) != 0)
            l->t_outer = now - p->elapsed_s;
        snprintf(l->outer, sizeof l->outer, "%s", stage);
        l->fraction = p->fraction;
        l->phi = p->phi;
        l->done = p->done;
        l->total = p->total;
        l->eta_s = p->eta_s;
        l->delta_d = p->delta_d;
    } else if (strcmp(stage, l->outer) != 0)
        inner = stage;
    char line[256], t[32];
    int k = snprintf(line, sizeof line, "%s", l->outer);
    if (l->fraction >= 0)
        k += snprintf(line + k, sizeof line - (size_t)k, " %3.0f%%", 100 * l->fraction);
    if (l->delta_d > 0) /* shell growth: the gap grows, φ stays */
        k += snprintf(line + k, sizeof line - (size_t)k, "  %s %.4g", l->utf8 ? "Δd" : "delta_d",
                      l->delta_d);
    else if (l->phi >= 0)
        k +=
            snprintf(line + k, sizeof line - (size_t)k, "  %s %.4f", l->utf8 ? "φ" : "phi", l->phi);
    else if (l->total > 0)
        k += snprintf(line + k, sizeof line - (size_t)k, "  %s%zu/%zu",
                      !strcmp(l->outer, "homogenize") ? "step " : "", l->done, l->total);
    if (inner)
        k += snprintf(line + k, sizeof line - (size_t)k, "  (%s)", inner);
    pk_run_line_duration(now - l->t0, t, sizeof t);
    k += snprintf(line + k, sizeof line - (size_t)k, "  %s", t);
    /* the stage's own estimate, else a linear one from its fraction */
    double eta = l->eta_s;
    if (eta < 0 && l->fraction >= 0.02 && l->fraction < 1)
        eta = (now - l->t_outer) * (1 - l->fraction) / l->fraction;
    if (eta >= 0) {
        pk_run_line_duration(eta, t, sizeof t);
        snprintf(line + k, sizeof line - (size_t)k, ", ~%s left", t);
    }
    size_t cut = screen_cut(line, l->cols > 1 ? l->cols - 1 : 1);
    /* \r and "erase to end of line" (ECMA-48 EL): the line redrawn in place */
    fprintf(l->tty, "\r%.*s\033[K", (int)cut, line);
    fflush(l->tty);
    l->drawn = 1;
}

void pk_run_line_clear(pk_run_line *l)
{
    if (!l->tty || !l->drawn)
        return;
    fputs("\r\033[K", l->tty);
    fflush(l->tty);
    l->drawn = 0;
}
