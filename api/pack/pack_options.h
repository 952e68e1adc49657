/* pack_options.h — each placer's options as its table fills them (the table
 * is in the placer's file, pk_placer.options; api/schemas/option_table.h). */
#ifndef PK_PACK_OPTIONS_H
#define PK_PACK_OPTIONS_H

#include <stddef.h>
#include <stdint.h>

#include "core/edmd/edmd.h"
#include "core/tetfill/tetfill.h"

typedef struct pk_rsa_options {
    uint64_t max_failed_draws; /* "rsa": {"max_failed_draws"} */
    int draws;                 /* "rsa": {"draws"}: pk_rsa_draws */
    int wall_gap;              /* "rsa": {"wall_gap"}: pk_rsa_wall_gap */
} pk_rsa_options;

typedef struct pk_edmd_options {
    pk_edmd_params prm;   /* the engine's knobs (preset: pk_edmd_params_default); delta
                                * NAN = chosen from the drawn sizes (pk_edmd_start_delta) */
    int maximize_delta_d; /* "maximize": "delta_d" (implies growth shell, until jammed) */
    int wall_gap_none;    /* "wall_gap": "none" */
} pk_edmd_options;

typedef struct pk_tetfill_options {
    pk_tetfill_params prm;      /* the filler's knobs (preset: pk_tetfill_defaults) */
    double r_min, r_max, ratio; /* 0 = not given (the radii rule of the placer) */
    size_t max_tets;
} pk_tetfill_options;

/* The options of the job's placer (the one its "algorithm" names). */
typedef union pk_placer_options {
    pk_rsa_options rsa;
    pk_edmd_options edmd;
    pk_tetfill_options tetfill;
} pk_placer_options;

#endif
