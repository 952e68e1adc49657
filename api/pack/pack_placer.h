/* pack_placer.h — the placement algorithms of the 'pack' process.
 *
 * The pack process draws sizes (core/psd/psd), hands them to one placer, audits
 * the result and writes the file.  A placer is one row of the table
 * (api/pack/pack_placers.c, or pk_placer_register) plus one file api/pack/pack_place_<name>.c: its
 * option table fills its options struct (pack_options.h) from its parameter
 * object of the inputs (e.g. "edmd": {...}) once per job, and the placer reads
 * them from job->opt; it runs its core/ algorithm and reports common statistics plus any algorithm-specific
 * observables as a JSON object, which the writer stores under
 * /observables/<name>/ (numbers, integers, strings, arrays of numbers). */
#ifndef PK_PACK_PLACER_H
#define PK_PACK_PLACER_H

#include <jansson.h>

#include "api/results/h5_units.h"
#include "core/space/gap_audit.h"
#include "pack_job.h"
#include "core/space/particles.h"
#include "core/psd/psd.h"
#include "core/rsa/rsa.h"

struct pk_h5;

typedef struct pk_place_stats {
    pk_stop_reason reason;
    const char *termination; /* the placer's name of the criterion that stopped it (edmd:
                              * pressure, delta_phi, stall, target, …), or NULL: the
                              * reason's name (pk_stop_reason_name) */
    int phi_own;             /* 1: the grains grew to a φ of their own (edmd relative growth
                              * until jammed): no φ target and no φ of the mix exist */
    size_t placed, requested;
    double seconds;
    json_t *obs; /* algorithm-specific observables (new reference) or NULL */
    /* Placers that fill their own domain (tetfill: a mesh) report it here:
     * the box written to the file and audited, and its true measure. */
    int has_domain;
    pk_box domain_box;
    double domain_measure;
    double overlap_tol; /* overlaps the placer allows by design (0 = hard grains) */
    int walls_touch;    /* 1: Δd between grains only, grains may touch the walls
                           * (edmd "wall_gap": "none", Titscher §6.3); 0: walls ≥ Δd/2 */
    int goal_reached;   /* 1: the stop reason is what the job asked for (edmd
                           * "until": "jammed" and jammed at its own test: the reduced
                           * pressure, or the Δφ test the job chose), though not
                           * PK_STOP_COMPLETE */
    int short_delta_d;  /* 1: the placer could not reach the job's Δd (edmd shell
                           * growth): the result is audited at audit_delta_d, the gap
                           * it guarantees, and the placer's warning says so */
    double audit_delta_d;
    char warning[512]; /* a placer's own "stopped short" sentence, or "" */
    /* Bulk datasets too large for obs (e.g. the mesh): written under
     * /observables/<algorithm>/ by write_extra, released by free_extra. */
    void *extra;
    int (*write_extra)(struct pk_h5 *h, const char *prefix, void *extra);
    void (*free_extra)(void *extra);
} pk_place_stats;

typedef struct pk_placer {
    const char *name; /* the "algorithm" value */
    /* Capabilities, read by the pack process instead of the placer's name: */
    int own_sizes;   /* 1 = the placer makes its own sizes: no grading, no size draw */
    int fills_mesh;  /* 1 = it places into "domain": {"mesh"} (else a box only);
                       * "algorithm": "auto" takes it for a mesh */
    int has_history; /* 1 = its observables hold "history": {events, time, phi,
                       * reduced_pressure} (the "history" picture; the model's
                       * history_stored) */
    /* 1 when the job grows the grains until jammed: the given sizes are
     * ratios, so the plan's shell-fill bound (φ with the Δd shells < 1) does
     * not apply (the placer's check bounds it instead).  NULL = never. */
    int (*grows_until_jammed)(const pk_pack_job *job);
    const pk_option_table *options; /* fills job->opt (pack_options.h), or NULL */
    /* The units of its observables (names relative to /observables/<name>/,
     * h5_units.h); an observable not listed is written without one. */
    const pk_unit_row *units;
    /* Semantic checks of the placer's own inputs (schema already passed),
     * after the plan's (the plan is made); may be NULL.  With job->prepare
     * it may leave in *prepared what it built for the run (plan->prepared),
     * freed by release. */
    void (*check)(const pk_pack_job *job, const pk_pack_plan *plan, void **prepared,
                  pk_schema_errors *errs);
    void (*release)(void *prepared);
    /* Place the grains (diameters sz->d, descending) into job->box, appending
     * to p (initialised, dim = job->dim), in the run context run (its
     * monitor, started; its checkpoint file).  0 when the run ended cleanly
     * for whatever reason (st->reason), -1 on failure with err. */
    int (*place)(const pk_pack_job *job, const pk_pack_plan *plan, const pk_sizes *sz,
                 const pk_run_ctx *run, pk_particles *p, pk_place_stats *st, char *err,
                 size_t errlen);
} pk_placer;

/* The verdict of a placed, audited packing (api/job_verdict.h): sets
 * "complete" and adds "warnings" or "failure" to summary.  phi: the solid
 * fraction reached; delta_d: the gap audited. */
void pk_pack_verdict(const pk_pack_job *job, const pk_pack_plan *plan, const pk_place_stats *st,
                     const pk_particles *p, const pk_gap_report *gap, double phi, double delta_d,
                     json_t *summary);

/* What stopped the placer: st->termination, else the reason's name. */
const char *pk_place_termination(const pk_place_stats *st);

/* The i-th placer of the table (from 0; NULL past the last): the built-in
 * ones (pack_placers.c), then the registered ones. */
const pk_placer *pk_placer_at(size_t i);
const pk_placer *pk_placer_find(const char *name);
/* Add a placer to the table and its name to the "algorithm" enum of the pack
 * inputs schema (so validation and the process description offer it).  At
 * start-up only, before any thread reads the table or the schema.  0, or -1
 * when p lacks a name or place, its name is taken or the table is full. */
int pk_placer_register(const pk_placer *p);
/* The first placer of the table that fills a mesh (there is one). */
const pk_placer *pk_placer_filling_mesh(void);

#endif
