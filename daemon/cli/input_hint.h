/* input_hint.h — what to do about a job's missing input file: an RVE is the
 * result of a pack job, so `packd run` and `packd validate` name the pack
 * jobs beside the job file (examples/homogenize/rve-rsa-2d.json for the
 * homogenize examples) and the command that makes the file. */
#ifndef PK_INPUT_HINT_H
#define PK_INPUT_HINT_H

#include <jansson.h>
#include <stdio.h>

#include "api/schemas/json_schema.h"

/* For each error of rule "rve" at ".../rve/file" whose file does not exist
 * while the job file's folder holds pack jobs, one line on f: "packd: rve-2d.h5 is the result of a pack job: run
 * examples/homogenize/rve-rsa-2d.json first: packd run
 * examples/homogenize/rve-rsa-2d.json -o rve-2d.h5". */
void cli_hint_missing_inputs(FILE *f, const char *job_path, const json_t *job,
                             const pk_schema_errors *errs);

#endif
