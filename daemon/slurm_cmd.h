/* slurm_cmd.h — run one Slurm client command (sbatch, squeue, scancel,
 * scontrol, sacct) and read what it prints.  No shell: argv is executed as
 * given, stdin is /dev/null, stdout and stderr are captured together. */
#ifndef PK_SLURM_CMD_H
#define PK_SLURM_CMD_H

#include <stddef.h>

/* Run argv[0] (found on PATH) with at most timeout_s seconds (then SIGKILL).
 * Returns its exit status (0..255), or -1 when it could not run or was
 * killed; out holds its output (NUL-terminated, cut at n - 1 bytes). */
int pk_slurm_cmd(const char *const argv[], char *out, size_t n, double timeout_s);

/* Does this error text say the controller is unreachable (a transient
 * state: retry), rather than that the request was refused? */
int pk_slurm_unreachable(const char *text);

#endif
