/* run_summary.c — the end of `packd run` (run_summary.h). */
#include <stdlib.h>
#include <string.h>

#include "run_line.h"
#include "run_summary.h"

void pk_run_summary_drop_series(json_t *summary)
{
    const char *key;
    json_t *v;
    void *tmp;
    json_object_foreach_safe (summary, tmp, key, v) {
        if (!strcmp(key, "history"))
            json_object_del(summary, key);
        else if (json_is_object(v))
            pk_run_summary_drop_series(v);
    }
}

void pk_run_summary_gap_text(double gap, long long pairs_below, char *out, size_t n)
{
    snprintf(out, n, "%.9g", gap);
    /* a violation is below Δd − tol (tol ≈ 1e-12 of the box): only its
     * exact digits keep it from reading as the bound itself */
    for (int digits = 10; pairs_below > 0 && digits <= 17 && strtod(out, NULL) != gap; digits++)
        snprintf(out, n, "%.*g", digits, gap);
}

static const char *str(const json_t *o, const char *key)
{
    const char *s = json_string_value(json_object_get(o, key));
    return s ? s : "";
}

static double num(const json_t *o, const char *key)
{
    return json_number_value(json_object_get(o, key));
}

static void pack_lines(FILE *f, const json_t *s, const char *phi)
{
    fprintf(f, "  grains    %lld placed of %lld requested\n",
            (long long)json_integer_value(json_object_get(s, "count_placed")),
            (long long)json_integer_value(json_object_get(s, "count_requested")));
    /* a packing grown to its own φ (until jammed) has no target and no φ of the mix */
    if (json_is_number(json_object_get(s, "phi_target_resolved")))
        fprintf(f, "  %s %.4f resolved (target %.4f), %.4f of the mix (target %.4f)\n", phi,
                num(s, "phi_resolved"), num(s, "phi_target_resolved"), num(s, "phi_mix"),
                num(s, "phi_target_mix"));
    else if (json_is_number(json_object_get(s, "phi_resolved")))
        fprintf(f, "  %s %.4f resolved\n", phi, num(s, "phi_resolved"));
    if (json_is_number(json_object_get(s, "smallest_gap"))) {
        long long below = json_integer_value(json_object_get(s, "pairs_below_delta_d"));
        char gap[32];
        pk_run_summary_gap_text(num(s, "smallest_gap"), below, gap, sizeof gap);
        fprintf(f, "  gap       smallest %s, %lld pairs below the minimum\n", gap, below);
    }
}

static void homogenize_lines(FILE *f, const json_t *s)
{
    fprintf(f, "  RVE       %lld grains, %lld contacts, %lld rattlers\n",
            (long long)json_integer_value(json_object_get(s, "rve_particles")),
            (long long)json_integer_value(json_object_get(s, "contacts")),
            (long long)json_integer_value(json_object_get(s, "rattlers")));
    json_t *audit = json_object_get(s, "audit");
    fprintf(f, "  steps     %lld (%lld not converged)%s\n",
            (long long)json_integer_value(json_object_get(s, "steps")),
            (long long)json_integer_value(json_object_get(s, "steps_not_converged")),
            !audit                                               ? ""
                : json_is_true(json_object_get(audit, "passed")) ? ", audit passed"
                                                                 : ", audit FAILED");
}

static void fe2_lines(FILE *f, const json_t *s)
{
    fprintf(f, "  mesh      %lld nodes, %lld elements, %lld Gauss points × %lld grains\n",
            (long long)json_integer_value(json_object_get(s, "nodes")),
            (long long)json_integer_value(json_object_get(s, "elements")),
            (long long)json_integer_value(json_object_get(s, "gauss_points")),
            (long long)json_integer_value(json_object_get(s, "rve_particles")));
    json_t *d = json_object_get(s, "dilatancy_percent_per_step");
    fprintf(f, "  steps     %lld of %lld, %lld Newton iterations, %lld cuts",
            (long long)json_integer_value(json_object_get(s, "steps")),
            (long long)json_integer_value(json_object_get(s, "steps_requested")),
            (long long)json_integer_value(json_object_get(s, "newton_iterations_total")),
            (long long)json_integer_value(json_object_get(s, "step_cuts_total")));
    if (json_array_size(d))
        fprintf(f, "; dilatancy %.4g %%",
                json_number_value(json_array_get(d, json_array_size(d) - 1)));
    fputc('\n', f);
}

void pk_run_summary_print(FILE *f, const json_t *s, const char *output, const char *xdmf,
                          double seconds, int utf8)
{
    const char *process = str(s, "process"), *algo = str(s, "algorithm");
    const char *reason = str(s, "termination_reason");
    int failed = json_is_string(json_object_get(s, "failure"));
    int complete = json_is_true(json_object_get(s, "complete"));
    fprintf(f, "%s", process);
    if (*algo || json_is_string(json_object_get(s, "boundary_condition")))
        fprintf(f, " (%s)", *algo ? algo : str(s, "boundary_condition"));
    fprintf(f, ": %s, %s", failed ? "FAILED" : "successful", complete ? "complete" : "incomplete");
    if (*reason && strcmp(reason, "complete") != 0)
        fprintf(f, " (%s)", reason);
    fputc('\n', f);
    if (!strcmp(process, "homogenize"))
        homogenize_lines(f, s);
    else if (!strcmp(process, "fe2"))
        fe2_lines(f, s);
    else
        pack_lines(f, s, utf8 ? "φ        " : "phi      "); /* 9 columns */
    json_t *choice = json_object_get(s, "auto");            /* "algorithm": "auto": what and why */
    if (choice)
        fprintf(f, "  auto      %s: %s\n", str(choice, "algorithm"), str(choice, "reason"));
    char t[32];
    pk_run_line_duration(seconds, t, sizeof t);
    fprintf(f, "  time      %s\n", t);
    json_t *w = json_object_get(s, "warnings");
    size_t i;
    json_t *v;
    json_array_foreach (w, i, v)
        fprintf(f, "  %-9s %s\n", i ? "" : "warnings", json_string_value(v));
    if (failed)
        fprintf(f, "  failure   %s\n", str(s, "failure"));
    fprintf(f, "  output    %s%s\n", output, failed ? " (partial)" : "");
    if (xdmf)
        fprintf(f, "  xdmf      %s\n", xdmf);
}
