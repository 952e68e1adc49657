/* test_placer_added.c — a method added in its own file with one table row
 * (docs/architecture.md, "Add a packing method"): the "lattice" placer puts
 * the drawn grains on a square (cubic) lattice of pitch d_max + Δd.  It is
 * registered by pk_placer_register and nothing else is edited.
 *
 * Without arguments: the unit checks (the table finds it, the schema and the
 * process description offer it, a job naming it validates, a mesh is refused
 * since it declares no fills_mesh).  With a packd command as arguments
 * (run, validate, serve, inspect) this binary is packd with the placer
 * registered: tests/integration/test_placer_added.sh runs jobs through
 * `run` and through the daemon (whose workers exec this binary again). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/http/http_process_doc.h"
#include "api/pack/pack_placer.h"
#include "api/process.h"
#include "check.h"
#include "daemon/cli/cli.h"

/* Site k of a lattice with n sites per axis: its centre on every axis. */
static void site(int dim, const int *n, size_t k, double pitch, const pk_box *b, double *x)
{
    for (int a = 0; a < dim; a++) {
        size_t i = k % (size_t)n[a];
        k /= (size_t)n[a];
        /* walled: the lattice centred between the walls; periodic: from 0 */
        double off = b->periodic[a] ? 0 : 0.5 * (b->L[a] - n[a] * pitch);
        x[a] = off + (i + 0.5) * pitch;
    }
}

static int place_lattice(const pk_pack_job *job, const pk_pack_plan *plan, const pk_sizes *sz,
                         const pk_run_ctx *run, pk_particles *p, pk_place_stats *st, char *err,
                         size_t errlen)
{
    (void)plan, (void)run;
    const double pitch = (sz->n ? sz->d[0] : 0) + job->delta_d;
    int n[3] = {1, 1, 1};
    size_t sites = 1;
    for (int a = 0; a < job->dim; a++) {
        n[a] = pitch > 0 ? (int)floor(job->box.L[a] / pitch) : 0;
        sites *= (size_t)n[a];
    }
    size_t placed = 0;
    for (; placed < sz->n && placed < sites; placed++) {
        double x[3];
        site(job->dim, n, placed, pitch, &job->box, x);
        if (pk_particles_push(p, x, 0.5 * sz->d[placed], sz->species[placed]) == (size_t)-1) {
            snprintf(err, errlen, "out of memory");
            return -1;
        }
    }
    *st = (pk_place_stats){.reason = placed == sz->n ? PK_STOP_COMPLETE : PK_STOP_SATURATED,
                           .placed = placed,
                           .requested = sz->n};
    st->obs = json_pack("{s:f,s:I}", "pitch", pitch, "sites", (json_int_t)sites);
    return 0;
}

static const pk_unit_row lattice_units[] = {{"pitch", PK_U_LENGTH}, {NULL}};

static const pk_placer lattice = {
    .name = "lattice", .units = lattice_units, .place = place_lattice};

static json_t *job(const char *domain)
{
    char text[600];
    snprintf(text, sizeof text,
             "{\"dim\": 2, \"domain\": %s, \"grading\": {\"type\": \"fuller\", \"q\": 0.5, "
             "\"d_max\": 2}, \"d_min\": 1, \"delta_d\": 0.1, \"phi\": {\"value\": 0.2, "
             "\"refers_to\": \"resolved\"}, "
             "\"algorithm\": \"lattice\"}",
             domain);
    return json_loads(text, 0, NULL);
}

static const pk_check_ctx local = {0};

static size_t parse_errors(json_t *in)
{
    pk_schema_errors errs = {0};
    size_t n = pk_process_validate_inputs(pk_process_find("pack"), in, &local, &errs);
    for (size_t i = 0; i < errs.n && i < 3; i++)
        fprintf(stderr, "  %s: %s\n", errs.items[i].pointer, errs.items[i].message);
    pk_schema_errors_free(&errs);
    return n;
}

static void test_registered(void)
{
    CHECK(pk_placer_find("lattice") == &lattice);
    CHECK(pk_placer_register(&lattice) == -1); /* a name once */
    json_t *d = pk_process_description(pk_process_find("pack"));
    char *text = json_dumps(d, 0);
    CHECK_MSG(text && strstr(text, "\"lattice\""), "the description offers it");
    free(text);
    json_decref(d);
}

static void test_validates(void)
{
    json_t *box = job("{\"box\": {\"size\": [20, 20], \"periodic\": false}}");
    CHECK(parse_errors(box) == 0);
    json_decref(box);
    /* it declares no fills_mesh: a mesh domain is refused at /domain */
    json_t *mesh = job("{\"mesh\": {\"file\": \"tests/data/meshes/cube22.msh\"}}");
    CHECK(parse_errors(mesh) > 0);
    json_decref(mesh);
}

int main(int argc, char **argv)
{
    if (pk_placer_register(&lattice) != 0) {
        fprintf(stderr, "cannot register the lattice placer\n");
        return 2;
    }
    static const struct {
        const char *name;
        int (*fn)(int, char **);
    } commands[] = {{"run", cmd_run},
                    {"validate", cmd_validate},
                    {"serve", cmd_serve},
                    {"inspect", cmd_inspect}};
    for (size_t i = 0; argc > 1 && i < sizeof commands / sizeof *commands; i++)
        if (!strcmp(argv[1], commands[i].name))
            return commands[i].fn(argc - 1, argv + 1);
    if (argc > 1)
        return 64;
    RUN(test_registered);
    RUN(test_validates);
    return check_summary();
}
