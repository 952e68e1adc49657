/* edmd_walls.h — EDMD with walls that do not see the Δd/2 shell.
 *
 * The engine (core/edmd/edmd.h) reflects the simulated sphere, shell included, at
 * the walls, so every wall clearance of its result is ≥ Δd/2 (spec §1.7
 * [D]).  Titscher & Unger require the gap Δd only *between* grains (§3,
 * §6.3: "a minimal distance Δd between the particles"; §8: the particles
 * "now have a distance Δd between each other"), and their A16 example
 * (a = 80 mm, Δd = 1 mm, φ_M = 53.5 %) is out of reach with the extra Δd/2
 * at the walls (tests/unit/test_edmd_titscher.c).
 *
 * pk_edmd_run_shell_in_walls runs the engine in the box widened by w on each
 * side of every walled axis, so the shell may reach w into a wall: a grain
 * whose shell is h ≥ w at the stop keeps a true-surface clearance ≥ h − w.
 * With w = Δd/2 of the job and a run that reaches that Δd, the grains stay
 * inside b and may touch its walls.  φ values (target and statistics) refer
 * to b, not to the widened box. */
#ifndef PK_EDMD_WALLS_H
#define PK_EDMD_WALLS_H

#include "edmd.h"

/* As pk_edmd_run on box b with walls widened by w >= 0 (w = 0: plain
 * pk_edmd_run).  Positions of p (in b, unless prm->start_zero) in and out
 * are in the coordinates of b. */
int pk_edmd_run_shell_in_walls(const pk_box *b, double w, pk_particles *p,
                               const pk_edmd_params *prm, pk_monitor *mon, pk_edmd_stats *st);

/* A run whose shell h stopped short of w leaves grains up to w − h through
 * the walls of b.  Scales the walled coordinates of p about the box centre,
 * axis by axis, by the largest factor s_k <= 1 that brings every true
 * surface inside b (clearance >= 0); pair distances shrink by at most that
 * factor, so a gap g becomes >= g − (1 − s)(r_i + r_j + g): the caller
 * measures the gap that holds afterwards.  Returns the smallest factor (1 when
 * every grain was inside). */
double pk_edmd_pull_inside(const pk_box *b, pk_particles *p);

#endif
