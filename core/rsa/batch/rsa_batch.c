#include "rsa_batch.h"
#include "core/base/rng.h"

#include <stdlib.h>
#include <string.h>

#include "rsa_cells.h"
#include "rsa_region.h"

/* Batch size: B = SURVIVORS / (survivors per draw of the last batch), at
 * least B_MIN draws, at most B_MAX (bounded memory: 5 bytes of scratch per
 * region draw, ~130 per attempt — region draws rejected at once make no
 * attempt).  Small batches win: a batch's scratch (~300 KB at 512 survivors)
 * stays in the per-core cache, and each batch's grains are marked before the
 * next batch draws (fewer draws into space just closed).  Survivors per batch
 * against the rate (medians of 4 alternating runs, 3D φ = 0.30, M/s at
 * 10^4 / 10^5 / 10^6 grains; draws per grain at 10^6):
 *   32 768: 0.78 / 0.94 / 1.13 (15.59)    512: 1.20 / 1.21 / 1.19 (15.31)
 *    8 192: 0.89 / 0.99 / 1.15 (15.39)    256: 1.22 / 1.24 / 1.17 (15.27)
 *    1 024: 1.17 / 1.10 / 1.18 (15.29)    128: 1.33 / 1.23 / 1.16 (15.30)
 * (32 768 until the tenth session: meant to share cache lines between the
 * cell-ordered tests of a batch, which at 10^6 grains are too sparse to share
 * them anyway.)  B_MIN 1024 or 2048 instead of 4096: 10^6 no faster. */
#define B_MIN 4096
/* Prefetch distance of the region draws' mark look-up (draws; the draw
 * arrays have this much slack: no bound tests in the look-up loop).  128
 * instead of 64 with batches of 512 survivors: 10^6 grains 1.42 -> 1.45-1.46
 * M/s in two series of 5 alternating runs (the list entry read for the mark's
 * prefetch was the pick's stall, perf); 192 and 256 no better. */
#define PICK_AHEAD 128
#define B_MAX ((size_t)1 << 20)
#define SURVIVORS 512.0
/* Counting sort of attempts by cell: at most this many buckets (contiguous
 * ranges of cell indices), so the scatter writes few streams. */
#define MAX_BUCKETS 4096
/* The store may not be much larger than the run needs (a few fine grains in
 * a huge box keep the per-grain path). */
#define CELLS_PER_GRAIN 64
#define CELLS_FREE 65536
/* Draws come from the open region (rsa_region.h) once a batch accepted fewer
 * than this fraction of its draws and at least REGION_MIN_LEFT grains remain:
 * from there on plain draws are mostly wasted (φ ≈ 0.2 of 0.3 for equal
 * spheres), marking exclusion balls pays. */
#define REGION_SWITCH_ACC 0.2
/* Cost of a draw into a fully covered cell over a list entry's in a compaction. */
#define STALE_PER_PASS 16
#define REGION_MIN_LEFT 256
/* Region cells per store cell and axis: edge ≈ c/2, fine voxels ≈ c/8 in 3D
 * (c/16 in 2D).  Halving the edge again (or 16 steps of the mark table) saved
 * fewer draws than the marks cost more (callgrind, 3D φ = 0.30).  At most
 * REGION_CELLS_PER_GRAIN region cells per grain of the run (12 bytes each). */
#define REGION_SPLIT 2
#define REGION_CELLS_PER_GRAIN 64
/* Obstacles of other sizes (grains placed before the run) are marked only
 * while their exclusion radius is at most this many contact distances (the
 * cost grows with its square; unmarked obstacles only cost draws). */
#define REGION_MAX_OBSTACLE 3.0
/* Steps of the mark table per axis (rsa_region.h): finer steps mark more of
 * each exclusion ball (delta 0.054 c at 8 steps, 0.027 c at 16: 20 % fewer
 * exact tests at φ = 0.30), but the table's steps³ entries cost ~40 000
 * instructions each to make, so steps = cbrt(m / 128) for a run of m grains,
 * between 6 and 16.  Against 8 steps, 3D φ = 0.30: 10^4 grains (6 steps) -4 %
 * instructions, 10^5 (9) ±0, 10^6 (16) -7 % instructions and -5 % last-level
 * misses (callgrind, cachegrind); 16 steps at 10^5 +8 %, 4 steps at 10^5
 * +17 %.  Wall clock at 10^6: no difference beyond the noise (the table, then
 * 4.6 MB, outgrows the L2 cache, marks take longer, draws less). */
#define REGION_STEPS_MIN 6
#define REGION_GRAINS_PER_ENTRY 128.0

/* 1 if a cell store for grains of radius r over this draw range serves the
 * box and stays O(m) for a run of m grains; decided without drawing. */
static int usable(const pk_box *b, double r, double gap, const double *span, size_t m)
{
    uint64_t nc = pk_rsa_cells_count(b, r, gap, span);
    return nc > 0 && nc <= (uint64_t)CELLS_PER_GRAIN * m + CELLS_FREE;
}

typedef struct scratch {
    size_t cap;         /* attempts */
    size_t capd;        /* region draws (rpos, rbit) */
    double *pos;        /* [cap][3] attempts in attempt order */
    uint32_t *rpos;     /* region draws: list position of each draw, then the cell of
                           each draw not rejected at once (in draw order) */
    uint8_t *rbit;      /* its fine voxel (same order as rpos) */
    uint32_t *rdraw;    /* draw number of each draw not rejected at once */
    uint32_t *ord;      /* [cap + 1] draw number of each attempt in its batch
                           (region draws: certain rejections make no attempt) */
    uint32_t *key;      /* bucket of each attempt */
    double *spos;       /* [cap][3] attempts' offsets from their cells' corners
                           (pk_rsa_cells_key_q) in bucket order */
    uint32_t *sidx;     /* attempt index of each sorted entry */
    uint32_t *skey;     /* its cell key */
    uint32_t *kept;     /* sorted positions of the survivors of step 2 */
    uint64_t *sbit;     /* bit a: attempt a survived step 2 */
    int32_t *slot;      /* survivor number of attempt a (set where sbit is) */
    double *surv;       /* [cap][3] survivors in sorted order (before step 2: the
                           attempts' offsets in attempt order) */
    uint32_t *vkey;     /* survivors' keys */
    uint8_t *taken;     /* survivor accepted in step 3 */
    uint32_t *pid;      /* its index in the particle array (set where taken is) */
    uint32_t *count;    /* [MAX_BUCKETS + 1] */
    size_t stale;       /* region draws of the last batch that fell in a fully covered cell */
    /* step 3: hash of the batch's accepted survivors by cell */
    int32_t *head;      /* [power of two >= 2 cap] */
    int32_t *hnext;     /* per survivor */
    uint64_t *hcell;    /* per survivor: its cell */
} scratch;

static void scratch_free(scratch *w)
{
    free(w->pos);
    free(w->ord);
    free(w->rpos);
    free(w->rbit);
    free(w->rdraw);
    free(w->key);
    free(w->spos);
    free(w->sidx);
    free(w->skey);
    free(w->kept);
    free(w->sbit);
    free(w->slot);
    free(w->surv);
    free(w->vkey);
    free(w->taken);
    free(w->pid);
    free(w->count);
    free(w->head);
    free(w->hnext);
    free(w->hcell);
    memset(w, 0, sizeof *w);
}

/* Scratch holds nothing from one batch to the next, so a larger block
 * replaces the old one without a copy (free, then malloc: the heap can hand
 * back pages just freed).  realloc copied each array at each of the plain
 * phase's ~15 steps of growth: 13 000 of 66 000 page faults at 10^6 grains.
 * NULL and *fail set when out of memory (scratch_free still works). */
static void *renew(void *p, size_t bytes, int *fail)
{
    free(p);
    void *q = malloc(bytes ? bytes : 1);
    if (!q)
        *fail = 1;
    return q;
}

/* Capacity for a request of n: at least twice the last, so few renewals. */
static size_t grown(size_t cap, size_t n)
{
    return n > 2 * cap ? n : 2 * cap;
}

/* Room for region batches of B draws (grows only, contents not kept; -1 when
 * out of memory). */
static int scratch_reserve_draws(scratch *w, size_t B)
{
    if (B <= w->capd)
        return 0;
    B = grown(w->capd, B);
    int fail = 0;
    w->rpos = renew(w->rpos, (B + PICK_AHEAD) * sizeof *w->rpos, &fail);
    w->rbit = renew(w->rbit, B, &fail);
    w->rdraw = renew(w->rdraw, B * sizeof *w->rdraw, &fail);
    w->capd = fail ? 0 : B; /* (a failed renewal leaves NULLs: room for nothing) */
    if (fail)
        return -1;
    return 0;
}

/* Room for batches of B attempts (grows only, contents not kept; -1 when out
 * of memory). */
static int scratch_reserve(scratch *w, size_t B)
{
    if (B <= w->cap)
        return 0;
    B = grown(w->cap, B);
    uint64_t hb = 64;
    while (hb < 2 * (uint64_t)B)
        hb <<= 1;
    int fail = 0;
    w->pos = renew(w->pos, 3 * B * sizeof *w->pos, &fail);
    w->ord = renew(w->ord, (B + 1) * sizeof *w->ord, &fail);
    w->key = renew(w->key, B * sizeof *w->key, &fail);
    w->spos = renew(w->spos, 3 * B * sizeof *w->spos, &fail);
    w->sidx = renew(w->sidx, B * sizeof *w->sidx, &fail);
    w->skey = renew(w->skey, B * sizeof *w->skey, &fail);
    w->kept = renew(w->kept, B * sizeof *w->kept, &fail);
    w->sbit = renew(w->sbit, (B / 64 + 1) * sizeof *w->sbit, &fail);
    w->slot = renew(w->slot, B * sizeof *w->slot, &fail);
    w->surv = renew(w->surv, 3 * B * sizeof *w->surv, &fail);
    w->vkey = renew(w->vkey, B * sizeof *w->vkey, &fail);
    w->taken = renew(w->taken, B, &fail);
    w->pid = renew(w->pid, B * sizeof *w->pid, &fail);
    w->count = renew(w->count, (MAX_BUCKETS + 1) * sizeof *w->count, &fail);
    w->head = renew(w->head, hb * sizeof *w->head, &fail);
    w->hnext = renew(w->hnext, B * sizeof *w->hnext, &fail);
    w->hcell = renew(w->hcell, B * sizeof *w->hcell, &fail);
    w->cap = fail ? 0 : B;
    if (fail)
        return -1;
    return 0;
}

static inline uint64_t hash_cell(uint64_t lin, uint64_t mask)
{
    return (lin * 0x9E3779B97F4A7C15ull) >> 20 & mask;
}

/* The batch's occupancy map: bit lin is set while a survivor accepted in
 * this batch lies in (real) cell lin — most survivors have no such neighbour,
 * and 9 (3D) reads of three adjacent bits say so without hashing. */
static inline int occupied(const uint8_t *map, uint64_t lin)
{
    return map[lin >> 3] >> (lin & 7) & 1;
}

/* Step 3's test: is survivor x (key: pk_rsa_cells_key_q) within contact of a
 * survivor accepted earlier in this batch?  Off the seams the neighbours are
 * the fixed offsets of the filter; ghost cells never match a stored cell. */
static int batch_hits(const pk_rsa_cells *C, const scratch *w, const uint8_t *map, uint64_t hmask,
                      const double *x, uint32_t key)
{
    uint64_t nb[27];
    int m;
    if (pk_rsa_cells_seam(C, x)) {
        m = pk_rsa_cells_around(C, x, nb);
    } else {
        const uint64_t lin = pk_rsa_cells_index(key);
        unsigned any = 0;
        for (int r = 0; r < C->nrow; r++)
            any |= pk_rsa_cells_bits3(map, lin + (uint64_t)C->row[r]);
        if (!any)
            return 0;
        const int64_t *off = C->off[pk_rsa_cells_octant(key)];
        for (int q = 0; q < C->noff; q++)
            nb[q] = (uint64_t)((int64_t)lin + off[q]);
        m = C->noff;
    }
    for (int q = 0; q < m; q++)
        for (int32_t j = occupied(map, nb[q]) ? w->head[hash_cell(nb[q], hmask)] : -1; j >= 0;
             j = w->hnext[j])
            if (w->hcell[j] == nb[q] && pk_rsa_cells_close(C, &w->surv[3 * (size_t)j], x))
                return 1;
    return 0;
}

/* Prefetch distance of step 4's marks (accepted grains; -6 % time at 10^6
 * grains, mean of 6 runs — the pick's prefetch above is the large part). */
#define MARK_AHEAD 4
/* Marks in flight: grain q + MARK_AHEAD is located (once: the prefetch and
 * the mark share its spot) and its words fetched while grain q is marked. */
#define MARK_RING 8 /* a power of two > MARK_AHEAD */

static inline void mark_ahead(pk_rsa_region *reg, pk_rsa_region_spot *ring, size_t q,
                              const double *x)
{
    pk_rsa_region_spot *s = &ring[q % MARK_RING];
    *s = pk_rsa_region_locate(reg, x);
    pk_rsa_region_prefetch(reg, *s);
}
/* Prefetch distance of the centres read by region_start's marks (grains):
 * the centres come in cell order from the store, so each one is a miss in the
 * particle array; with it and the mark's rows fetched ahead region_start took
 * ~30 % less time at 10^6 grains, the run 9-11 % less CPU (same marks, same
 * packing).
 * Round 4 also measured, and dropped (10^6 grains, 3D φ = 0.30, CPU time,
 * alternating runs against the kept version):
 *  - marks in blocks of 2×2×2 cells (a 64-byte line each): a mark's lines
 *    37 -> 27, its last-level misses -15 %, but +11 % instructions (block
 *    index arithmetic in the pick, the point and the prefetch): no faster;
 *  - draws from slots weighted by class (a cell with o open fine voxels gets
 *    2^ceil(log2 o) slots, classes rebuilt at compaction, draw = the s-th open
 *    fine voxel): draws per grain 19 -> 8-14, but the rebuilds (two passes,
 *    new pages) cost more: +25 % CPU;
 *  - the same draws from 64 slots with a bound of the cell's open count in
 *    the list entry (the marks' word read only under the bound): -40 % of
 *    those reads, but +6-15 % CPU (the select and an unpredictable branch);
 *  - table marks without the outer cells (|d| = 2: 9 rows instead of 25):
 *    +11 % draws, slower; without words of fewer than 4-12 marked bits:
 *    +1-4 % draws, no faster;
 *  - compacting the list 2-8 times as often, the region switch at a batch
 *    acceptance of 0.12-0.4 instead of 0.2, mark-table steps 4 or 8 at 10^6:
 *    within the noise or slower;
 *  - transparent huge pages for the 290 MB (74 000 page faults, 0.14-0.18 s
 *    of system time): faults -86 %, system time x3-4 on this machine.
 * Round 5 (the memory a 10^6 run touches: 70 000 pages — marks 111 MB,
 * store 58 MB, list 39 MB, particles 36 MB, scratch ~30 MB) measured, and
 * dropped:
 *  - region draws picked through a ring of 2 x 4096 entries a chunk ahead of
 *    their look-ups, keeping only the draws not rejected at once (9.4 MB of
 *    pick arrays -> 1.5 MB, -3 350 faults, same packings): wall and CPU time
 *    unchanged within the noise (4 alternating pairs) — not worth its code;
 *  - the list as a bitmap with ranks and samples (3.5 MB instead of 39 MB,
 *    -8 000 faults, same packings): the select costs ~65 instructions a draw
 *    and a chain of dependent misses: CPU x1.7-2;
 *  - no list until the first compaction (draws from all cells; -17 MB,
 *    -4 700 faults): draws per grain 19.0 -> 23.3, CPU within the noise;
 *  - region cells of the store's edge (REGION_SPLIT 1: -100 MB, -20 000
 *    faults, -0.06 s system): draws per grain 34.7, CPU +15-20 %;
 *  - the marks' block pre-faulted (mmap MAP_POPULATE): the same faults and
 *    system time — the kernel's cost is per page, not per trap.
 *  - transparent huge pages for every malloc (sixth session; this kernel has
 *    THP on madvise: GLIBC_TUNABLES=glibc.malloc.hugetlb=1): 1,836-2,147
 *    faults instead of 70,066, but 0.62-0.74 s of system time (zeroing and
 *    compacting 2 MB pages) against 0.12-0.15 s: 0.63-0.71 against
 *    1.08-1.09 M placements per s (three alternating pairs).  The same
 *    session, quiet machine, no code change: 1.10-1.17 M per s in 5 of 5.
 * Round 6: where a 10^6 run's time goes (3D φ = 0.30, rdtsc per phase, best
 * of 3 on a quiet machine, 2.47 Gcycles): plain draws 16 %; region_start 20 %
 * (its marks 16 %, a third of that the 27 000 first touches of the marks'
 * array, the first compaction 3 %); region draws' pick 20 % (draws 3 %, list
 * and mark look-ups 16 %); point, sort, filter 21 % (the filter 14 %); step 3
 * 5 %; step 4's inserts and marks 18 %; later compactions < 1 % (there is one:
 * the list shrinks 9.7 -> 4.6 M cells).  A page's first touch costs ~2 µs on
 * this machine and unmapping ~0.1 ms per MB: ~0.18 s of the run for its
 * 290 MB.  Kept: marks located once (pk_rsa_region_locate: the prefetch and
 * the mark share the spot) and no bound tests in the pick's look-up loop:
 * -3 % instructions, the same simulated misses (cachegrind), the same
 * packings; wall and CPU time within the noise (5 alternating pairs at a
 * load of 4-5).  Measured and dropped (same packings unless said):
 *  - prefetching only the lines a mark writes (~19 of the ~37 its rows
 *    span): no faster — the marks wait on latency, not on bandwidth;
 *  - tables as runs of adjacent words per row (a switch on the run length):
 *    -30 % of the marks' instructions but slower (the switch mispredicts);
 *  - region cells' coordinates by products with 1/n instead of divisions:
 *    more instructions, the point step no faster;
 *  - the filter's prefetch limited to occupied cells (branches: the run
 *    1.2x slower) or to the cells on the attempt's near sides (the filter
 *    2-3x slower);
 *  - region_start's marks without their rows fetched ahead: slower;
 *  - no marks for the run's last 3-25 % of grains (marks are optional; other
 *    packings): +0.2-18 % draws, no faster;
 *  - step 4's marks limited to cells still listed (counted, not built): 34 %
 *    of their words, but only 21 % of their lines, lie in cells already full
 *    (41 % of the words gain no bit): <= 3 % to gain before a listed-cells
 *    bitmap's cost;
 *  - transparent huge pages for the marks' array: faults -37 %, user time
 *    the same, system time erratic (x1-3);
 *  - one-miss region draws (counted, not built): a copy of the cell's word in
 *    its list entry, taken at compaction, would catch 74 % of the certain
 *    rejections without reading the marks (a 32-bit fold 66 %, an 8-bit
 *    summary of 2x2x2 blocks in spare bits of the entry 51 %, of 4x2x1 blocks
 *    44 %) — but the copy doubles the list (+39 MB, ~+25 ms of first touches
 *    and unmapping) and a summary costs 8-20 operations per listed cell at
 *    each compaction: <= 2 % to gain, within the noise;
 *  - draws weighted by open slots (a list entry per 16 or 32 open fine
 *    voxels, the k-th open voxel drawn): draws x0.3-0.7, but other packings,
 *    a select per draw and popcounts per compaction (round 4's classes:
 *    +25 %): not built.
 * Round 7 (eighth session; 10^6 grains, 3D φ = 0.30, counted: the plain
 * phase places 513 000 grains from 1.27M draws, the region phase 487 000
 * from 17.8M draws, 2.62M attempts (85 % of its draws are certain
 * rejections), 534 000 survivors of step 2).  Kept: the marks OR whole
 * table rows (rsa_region.c: user time 0 to -7 %, the same marks).  Measured
 * and dropped (medians of 4-8 alternating runs, the same packings):
 * PICK_AHEAD 96, 128 or 192 instead of 64 (32: +8 % user time), mark
 * tables of at most 8 or 12 steps instead of 16 (draws per grain 20.8 and
 * 19.6 instead of 19.0): all within the noise.
 * Round 8 (ninth session; 10^6 grains, 3D φ = 0.30; wall time per phase, one
 * run: plain batches 0.08 s, region_start 0.17, picks 0.15, region attempts
 * (point, sort, filter) 0.22, step 3 0.09, step 4 0.17, compactions 0.02).
 * Kept: compaction driven by the draws into fully covered cells (below),
 * 16-byte store records (rsa_cells.h), the marks' pages written before
 * their first read and the marks near a seam by whole rows (rsa_region.c),
 * scratch renewed without realloc's copies — together 95 000 -> 62 000 page
 * faults, system time 0.16-0.20 -> 0.11-0.13 s, user time -1 to -10 %;
 * medians of 8-12 alternating runs, 10^6 grains: 0.85 -> 0.90 and
 * 0.98 -> 1.07 M placements per s in slow states of the machine, 1.03 -> 1.09
 * in a medium one, 1.07 -> 1.17 in a fast one (bench/rsa's case=machine line
 * tells them apart).  Measured
 * and dropped (medians of 4-6 alternating runs): prefetching covered[] in the
 * compaction (34 ms either way, perf); the pick's prefetches as prefetcht2
 * (within the noise); the region switch at a batch acceptance of 0.15-0.3
 * (flat); B_MAX 2^19 or 2^21, SURVIVORS 16 384 or 65 536 (flat or slower);
 * MAX_BUCKETS 1 024 to 262 144 (flat); no counting sort before the filter
 * (user time +5 %).  The pool of cells with two or more grains (2.8 % of
 * the nonempty cells at the end) now takes ~14 % of the filter's samples:
 * a chase the 32-byte records did not make, paid for by half the store.
 * Round 9 (tenth session; 10^6 grains, 3D φ = 0.30; medians of 4-6
 * alternating runs).  Kept: 512 survivors per batch instead of 32 768 (see
 * B_MIN above: 10^6 +4.5 %, 10^5 +31 %, 10^4 +46 %); the 16-bit offsets of
 * two-grain cells (rsa_cells.h: +6 %, the same packings).  Wall time per
 * phase after both, one run in a fast state (0.77 s): picks 0.14 s,
 * region_start 0.15 (its marks 0.08, the marks' first touches ~0.05), step 4
 * of region batches (marks) 0.17, region attempts' filter 0.12, their points
 * and sort 0.04, step 3 0.03, compactions 0.02, the plain phase 0.08.
 * Measured and dropped:
 *  - draws weighted by open fine voxels (cells in 7 classes by their open
 *    count o, 2^ceil(log2 o) slots each, one uniform slot per draw, the s-th
 *    open voxel by a broadword select): draws per grain 15.6 -> 6.6, but a
 *    draw cost 22 instead of 9.5 ns (the same two misses, 3x the
 *    instructions: fewer draws in flight) and a compaction became a
 *    seven-stream scatter over all cells: 10-11 % slower;
 *  - the filter in two passes (the near cells' rows first, the other rows
 *    for the points the first pass kept: 40 % fewer lines fetched): 3 %
 *    slower at 10^6, 16 % at 10^5;
 *  - with 512 survivors: PICK_AHEAD 32 (128: kept, above), MARK_AHEAD 2 or 6, the
 *    filter's look-ahead 4 or 16, STALE_PER_PASS 8 or 32, the region switch
 *    at 0.12, 0.3 or 0.4, mark tables of cbrt(m/64) or cbrt(m/256) steps,
 *    MAX_BUCKETS 256 or 1 024, B_MIN 1 024 or 2 048: all within the noise or
 *    slower; -march=native: the same;
 *  - no list until the first compaction, again (a draw's cell is its
 *    position, one miss instead of two while 30-50 % of the cells are
 *    full): -2 500 faults, draws per grain 15.31 -> 15.70, rate flat;
 *  - the mark table fetched ahead from 256 KB tables on (10^5): flat;
 *  - transparent huge pages for the marks again: the same user time, system
 *    time +0.25 s (a 2 MB page's first touch costs ~4.5 ms here). */
#define START_AHEAD 16
/* Prefetch distance of step 4's store records (grains: sorted by cell, but
 * at 10^6 grains a batch's grains are far apart; -4..-6 % CPU at 10^6 grains,
 * alternating runs; 16 the same). */
#define INSERT_AHEAD 8

/* Region draws, step 1a: pick B (cell, fine voxel) pairs, then look their
 * marks up, dropping the certain rejections: for a below the number returned,
 * draw w->rdraw[a] was not rejected at once; cell w->rpos[a], fine voxel
 * w->rbit[a].  At 10^6 grains a batch's draws are far sparser than the cache
 * lines of the list and of the marks, so in any order each look-up is two
 * misses; fetched ahead (the mark's address needs the list entry fetched
 * earlier) they overlap.  (Before: a
 * counting sort by list position to read both as streams — no fewer misses,
 * since the draws are too sparse to share lines; dropping it and prefetching
 * took 18 % off the run's time at 10^6 grains and 10 % at 10^5, best of 8.) */
static size_t region_pick(const pk_rsa_region *reg, scratch *w, size_t B, pk_rng *rng)
{
    pk_rng g0 = *rng, *g = &g0; /* a local copy: in registers, whatever the stores below */
    for (size_t d = 0; d < B; d++) {
        unsigned bit;
        w->rpos[d] = pk_rsa_region_pick(reg, g, &bit);
        w->rbit[d] = (uint8_t)bit;
    }
    *rng = g0;
    memset(&w->rpos[B], 0, PICK_AHEAD * sizeof *w->rpos); /* the look-ahead past the end:
                                                             list position 0, harmless */
    const uint32_t *list = reg->list;
    const uint64_t *covered = reg->covered;
    size_t open = 0, stale = 0;
    for (size_t d = 0; d < B; d++) {
        __builtin_prefetch(&list[w->rpos[d + PICK_AHEAD]]);
        __builtin_prefetch(&covered[list[w->rpos[d + PICK_AHEAD / 2]]]);
        const uint32_t cell = list[w->rpos[d]];
        const unsigned bit = w->rbit[d];
        /* (open <= d: the entries written here are read no more) */
        w->rpos[open] = cell;
        w->rbit[open] = (uint8_t)bit;
        w->rdraw[open] = (uint32_t)d;
        const uint64_t word = covered[cell];
        open += !(word >> bit & 1);
        stale += word == ~(uint64_t)0;
    }
    w->stale = stale;
    return open;
}

/* Steps 1–2 for B draws: draw, sort by cell bucket, filter against the
 * store.  Plain draws make B attempts; region draws (reg != NULL) skip the
 * certain rejections: *A attempts, w->ord[a] the draw number of attempt a,
 * w->ord[*A] = B.  Returns the number of survivors, SIZE_MAX when out of
 * memory. */
static size_t draw_and_filter(const pk_rsa_cells *C, const double *px, scratch *w, size_t B,
                              int dim, const double *lo, const double *span, pk_rng *rng,
                              int shift, uint32_t nbucket, const pk_rsa_region *reg, size_t *A)
{
    size_t open = 0;
    if (reg) { /* the certain rejections need no room beyond the draw arrays */
        if (scratch_reserve_draws(w, B) != 0)
            return SIZE_MAX;
        open = region_pick(reg, w, B, rng);
        if (scratch_reserve(w, open) != 0)
            return SIZE_MAX;
    } else if (scratch_reserve(w, B) != 0) {
        return SIZE_MAX;
    }
    const double lo0 = lo[0], lo1 = lo[1], lo2 = lo[2], sp0 = span[0], sp1 = span[1];
    const double sp2 = dim == 3 ? span[2] : 0;
    /* local copies: the stores below cannot alias them, so the generator state
     * and the store's geometry stay in registers */
    pk_rng g = *rng;
    const pk_rsa_cells K = *C;
    double *restrict pos = w->pos, *restrict qpos = w->surv;
    uint32_t *restrict keys = w->key, *restrict ord = w->ord;
    size_t a = 0;
    if (reg) {
        for (; a < open; a++) {
            double x[3];
            pk_rsa_region_point(reg, w->rpos[a], w->rbit[a], &g, x);
            memcpy(&pos[3 * a], x, sizeof x);
            keys[a] = pk_rsa_cells_key_q(&K, x, &qpos[3 * a]);
            ord[a] = w->rdraw[a];
        }
        ord[a] = (uint32_t)B;
    } else {
        for (; a < B; a++) {
            /* rsa.c's plain draw: x[k] = lo[k] + span[k]·u, k = 0, 1 (, 2), z = 0 in 2D */
            double x[3];
            x[0] = lo0 + sp0 * pk_rng_uniform(&g);
            x[1] = lo1 + sp1 * pk_rng_uniform(&g);
            x[2] = dim == 3 ? lo2 + sp2 * pk_rng_uniform(&g) : 0;
            memcpy(&pos[3 * a], x, sizeof x);
            keys[a] = pk_rsa_cells_key_q(&K, x, &qpos[3 * a]);
        }
    }
    *rng = g;
    *A = a;
    /* the counts of the cell buckets */
    memset(w->count, 0, (nbucket + 1) * sizeof *w->count);
    for (size_t q = 0; q < a; q++)
        w->count[(pk_rsa_cells_index(w->key[q]) >> shift) + 1]++;
    B = a; /* from here on: attempts */
    for (uint32_t k = 0; k < nbucket; k++)
        w->count[k + 1] += w->count[k];
    for (size_t q = 0; q < B; q++) {
        uint32_t key = w->key[q];
        uint32_t t = w->count[pk_rsa_cells_index(key) >> shift]++;
        memcpy(&w->spos[3 * (size_t)t], &w->surv[3 * q], 3 * sizeof(double)); /* offsets */
        w->sidx[t] = (uint32_t)q;
        w->skey[t] = key;
    }
    size_t S = pk_rsa_cells_filter(C, px, w->spos, w->pos, w->sidx, w->skey, B, w->kept);
    memset(w->sbit, 0, (B / 64 + 1) * sizeof *w->sbit);
    for (size_t j = 0; j < S; j++) {
        uint32_t t = w->kept[j], q = w->sidx[t];
        memcpy(&w->surv[3 * j], &w->pos[3 * (size_t)q], 3 * sizeof(double));
        w->vkey[j] = w->skey[t];
        w->slot[q] = (int32_t)j;
        w->sbit[q >> 6] |= (uint64_t)1 << (q & 63);
    }
    return S;
}

/* Mark the exclusion balls of the grains placed so far (the run's with radius
 * c, earlier obstacles with r + r_j + Δd when not too wide) and list the cells
 * left open.  -1 when out of memory (the run then keeps plain draws).  Marks
 * are optional for correctness: a cancel request cuts the marking short. */
static int region_start(pk_rsa_region *reg, const pk_rsa_cells *C, const pk_box *b, double r,
                        double gap, const double *lo, const double *span,
                        const pk_particles *out, size_t first, size_t m, pk_monitor *mon,
                        pk_progress *pg)
{
    const double c = 2 * r + gap;
    uint64_t cells = 1;
    for (int k = 0; k < b->dim; k++)
        cells *= REGION_SPLIT * (uint64_t)C->n[k];
    if (cells > REGION_CELLS_PER_GRAIN * (uint64_t)m + CELLS_FREE)
        return -1; /* a sparse run: not worth the memory */
    int64_t n[PK_MAXDIM];
    for (int k = 0; k < PK_MAXDIM; k++)
        n[k] = k < b->dim ? REGION_SPLIT * C->n[k] : 1;
    int steps = (int)cbrt((double)m / REGION_GRAINS_PER_ENTRY);
    if (steps < REGION_STEPS_MIN)
        steps = REGION_STEPS_MIN;
    if (steps > PK_RSA_REGION_MAX_STEPS)
        steps = PK_RSA_REGION_MAX_STEPS;
    if (pk_rsa_region_init(reg, b, n, lo, span, c, steps) != 0)
        return -1;
    for (size_t j = 0; j < first; j++) { /* obstacles of other sizes */
        double rad = r + out->r[j] + gap;
        if (rad <= REGION_MAX_OBSTACLE * c)
            pk_rsa_region_cover(reg, &out->x[3 * j], rad);
        if ((j & 0xfff) == 0xfff && pk_monitor_tick(mon, pg, 0))
            break;
    }
    /* the run's grains from the store, in cell order (neighbouring marks share
     * cache lines; in placement order each mark would miss on large runs),
     * listed first so that each grain's centre and its mark's rows can be
     * fetched ahead (START_AHEAD, MARK_AHEAD grains) */
    size_t k = 0;
    uint32_t *ids = malloc((out->n - first + 1) * sizeof *ids); /* (+1: never malloc(0)) */
    if (!ids) {
        pk_rsa_region_free(reg);
        return -1;
    }
    for (int64_t z = 0; z < C->n[2]; z++)
        for (int64_t y = 0; y < C->n[1]; y++) {
            const pk_rsa_cell1 *row =
                &C->cell[C->base + (uint64_t)z * C->stride[2] + (uint64_t)y * C->stride[1]];
            for (int64_t x = 0; x < C->n[0]; x++) {
                const uint32_t a = row[x].id;
                if (a == PK_RSA_CELLS_NONE)
                    continue;
                if (!(a & PK_RSA_CELLS_MORE))
                    ids[k++] = a;
                else
                    for (int32_t e = (int32_t)(a & PK_RSA_CELLS_POOL); e >= 0;
                         e = C->extra[e].next)
                        ids[k++] = C->extra[e].id;
            }
        }
    pk_rsa_region_spot ring[MARK_RING];
    for (size_t q = 0; q < k && q < MARK_AHEAD; q++)
        mark_ahead(reg, ring, q, &out->x[3 * (size_t)ids[q]]);
    for (size_t q = 0; q < k && !(mon && mon->cancelled); q++) {
        if (q + START_AHEAD < k)
            __builtin_prefetch(&out->x[3 * (size_t)ids[q + START_AHEAD]]);
        if (q + MARK_AHEAD < k)
            mark_ahead(reg, ring, q + MARK_AHEAD, &out->x[3 * (size_t)ids[q + MARK_AHEAD]]);
        pk_rsa_region_mark_at(reg, ring[q % MARK_RING]);
        if ((q & 0xfff) == 0xfff)
            pk_monitor_tick(mon, pg, 0);
    }
    free(ids);
    pk_rsa_region_compact(reg);
    return 0;
}

/* Draw number of attempt a (plain draws: every draw is an attempt). */
static inline size_t draw_of(const scratch *w, int region, size_t a)
{
    return region ? w->ord[a] : a;
}

/* The run in batches of attempts (README.md, steps 1-4). */
static pk_stop_reason run_batches(const pk_rsa_batch_env *e, double r, const int32_t *species,
                                  size_t m, const double *lo, const double *span)
{
    const pk_box *b = e->b;
    const pk_rsa_params *prm = e->prm;
    const pk_grid *grid = e->grid;
    pk_rng *rng = e->rng;
    pk_monitor *mon = e->mon;
    pk_progress *pg = e->pg;
    const double box_measure = e->box_measure;
    double *solid = e->solid;
    pk_particles *out = e->out;
    pk_rsa_stats *st = e->st;
    pk_rsa_cells C;
    if (pk_rsa_cells_init(&C, b, r, prm->delta_d, lo, span) != 0)
        return PK_STOP_ERROR;
    scratch w;
    memset(&w, 0, sizeof w);
    uint8_t *map = calloc(C.ncell / 8 + 16, 1);
    if (!map) {
        pk_rsa_cells_free(&C);
        return PK_STOP_ERROR;
    }
    int shift = 0;
    while (((C.ncell - 1) >> shift) >= MAX_BUCKETS)
        shift++;
    const uint32_t nbucket = (uint32_t)((C.ncell - 1) >> shift) + 1;
    int grid_empty = 1;
    for (int l = 0; l < grid->nlevel; l++)
        grid_empty &= grid->lv[l].count == 0;
    const double ball = pk_ball_measure(b->dim, r);
    const size_t first = out->n;
    pk_rsa_region reg;
    memset(&reg, 0, sizeof reg);
    int region = 0, region_allowed = prm->draws == PK_RSA_DRAWS_OPEN;
    uint64_t stale_since = 0; /* draws in fully covered cells since the last compaction */

    pk_stop_reason reason = PK_STOP_COMPLETE;
    size_t placed = 0;
    uint64_t failed = 0;
    double p_surv = 1, p_acc = 1; /* running estimates from the last batch */
    while (placed < m) {
        if (!region && region_allowed && p_acc < REGION_SWITCH_ACC &&
            m - placed >= REGION_MIN_LEFT) {
            region_allowed = 0;
            region = region_start(&reg, &C, b, r, prm->delta_d, lo, span, out, first, m, mon,
                                  pg) == 0;
        }
        if (region && reg.nlist == 0) {
            reason = PK_STOP_SATURATED; /* every fine voxel lies in an exclusion ball */
            break;
        }
        size_t B = prm->test.batch_attempts;
        if (!B) {
            double want = SURVIVORS / p_surv, finish = 2.0 * (double)(m - placed) / p_acc;
            want = want < finish ? want : finish;
            B = want < B_MIN ? B_MIN : (want > (double)B_MAX ? B_MAX : (size_t)want);
        }
        pg->done = st->placed;
        pg->fraction = (double)st->placed / (double)(st->requested ? st->requested : 1);
        pg->phi = *solid / box_measure;
        int cc = pk_monitor_tick(mon, pg, 0);
        if (cc) {
            reason = cc == 2 ? PK_STOP_WALL_TIME : PK_STOP_CANCELLED;
            break;
        }
        pk_rng start = *rng;
        size_t A;
        size_t S = draw_and_filter(&C, out->x, &w, B, b->dim, lo, span, rng, shift, nbucket,
                                   region ? &reg : NULL, &A);
        if (S == SIZE_MAX) {
            reason = PK_STOP_ERROR;
            break;
        }

        /* step 3: attempt order */
        uint64_t hmask = 63;
        while (hmask + 1 < 2 * (uint64_t)S)
            hmask = 2 * hmask + 1;
        memset(w.head, 0xff, (hmask + 1) * sizeof *w.head);
        memset(w.taken, 0, S);
        size_t used = B, acc = 0;
        const uint64_t max_failed = prm->max_failed_draws;
        const size_t nword = (A + 63) / 64;
        size_t a = 0;      /* next attempt of the walk */
        size_t next_d = 0; /* its first draw not yet counted */
        for (;;) {
            /* draws rejected at once or in step 2 count as failures: jump to the next survivor */
            size_t wd = a >> 6;
            uint64_t bits = wd < nword ? w.sbit[wd] & (~(uint64_t)0 << (a & 63)) : 0;
            while (!bits && ++wd < nword)
                bits = w.sbit[wd];
            a = bits ? 64 * wd + (size_t)__builtin_ctzll(bits) : A;
            size_t d = a < A ? draw_of(&w, region, a) : B;
            if ((uint64_t)(d - next_d) >= max_failed - failed) {
                used = next_d + (size_t)(max_failed - failed);
                failed = max_failed;
                reason = PK_STOP_MAX_FAILED_DRAWS;
                break;
            }
            failed += d - next_d;
            if (a == A)
                break;
            size_t cur = a++;
            next_d = d + 1;
            int32_t j = w.slot[cur];
            const double *x = &w.surv[3 * (size_t)j];
            const uint32_t key = w.vkey[j];
            int ok = !batch_hits(&C, &w, map, hmask, x, key) &&
                     (grid_empty || !pk_grid_overlaps(grid, out, x, r));
            if (!ok) {
                if (++failed >= max_failed) {
                    used = next_d;
                    reason = PK_STOP_MAX_FAILED_DRAWS;
                    break;
                }
                continue;
            }
            size_t idx = pk_particles_push(out, x, r, species[placed]);
            if (idx == (size_t)-1 || idx >= PK_RSA_CELLS_MORE) {
                used = next_d;
                reason = PK_STOP_ERROR;
                break;
            }
            w.pid[j] = (uint32_t)idx;
            failed = 0;
            placed++;
            acc++;
            *solid += ball;
            w.taken[j] = 1;
            uint64_t lin = pk_rsa_cells_index(key), h = hash_cell(lin, hmask);
            w.hcell[j] = lin;
            map[lin >> 3] |= (uint8_t)(1u << (lin & 7));
            w.hnext[j] = w.head[h];
            w.head[h] = j;
            if (placed == m) {
                used = next_d;
                break;
            }
        }
        st->draws += used;
        st->placed += acc;
        if (used < B && !region) { /* rewind the stream to just after the last attempt used */
            *rng = start;
            for (size_t q = 0; q < used * (size_t)b->dim; q++)
                pk_rng_next(rng);
        }
        /* (region draws use a varying number of outputs: the stream stays
         * where the batch left it — deterministic, not rewound) */
        p_surv = fmax((double)S / (double)B, 1e-6);
        p_acc = fmax((double)acc / (double)used, 1e-6);
        if (reason != PK_STOP_COMPLETE || placed == m)
            break;
        /* step 4: the store grows between batches only (sorted order: streaming);
         * the region marks the new grains' exclusion balls */
        size_t ntaken = 0;
        for (size_t j = 0; j < S; j++)
            if (w.taken[j])
                w.kept[ntaken++] = (uint32_t)j; /* (free again after step 2) */
        pk_rsa_region_spot ring[MARK_RING];
        for (size_t q = 0; region && q < ntaken && q < MARK_AHEAD; q++)
            mark_ahead(&reg, ring, q, &w.surv[3 * (size_t)w.kept[q]]);
        for (size_t q = 0; q < ntaken; q++) {
            const size_t j = w.kept[q];
            if (q + INSERT_AHEAD < ntaken) {
                const uint32_t key = w.vkey[w.kept[q + INSERT_AHEAD]];
                __builtin_prefetch(&C.cell[pk_rsa_cells_index(key)], 1);
            }
            map[w.hcell[j] >> 3] = 0; /* the occupancy map is empty again */
            if (pk_rsa_cells_insert(&C, &w.surv[3 * j], w.pid[j]) != 0) {
                reason = PK_STOP_ERROR;
                break;
            }
            if (!region)
                continue;
            if (q + MARK_AHEAD < ntaken)
                mark_ahead(&reg, ring, q + MARK_AHEAD, &w.surv[3 * (size_t)w.kept[q + MARK_AHEAD]]);
            pk_rsa_region_mark_at(&reg, ring[q % MARK_RING]);
        }
        if (reason != PK_STOP_COMPLETE)
            break;
        /* Compaction passes over the list once (~1 ns an entry at 10^6 grains:
         * 34 ms for the run's passes over 33 million entries, perf) and ends the
         * draws into fully covered cells (~10 ns each, two misses): compact once
         * those since the last compaction cost about what a pass does (8, 16 and
         * 32 per pass measured alike; 2 and 4 compact too rarely: 19.5 and 17.7
         * draws per grain).  (Before:
         * once the certain rejections since then reached the list's length — one
         * compaction at 10^6 grains, 53 % of the list stale by then; now three:
         * draws per grain 19.0 -> 15.6, user time -2 %, medians of 8 alternating
         * runs.) */
        if (region && (stale_since += w.stale) * STALE_PER_PASS >= reg.nlist) {
            pk_rsa_region_compact(&reg);
            stale_since = 0;
        }
    }
    pk_rsa_region_free(&reg);
    scratch_free(&w);
    free(map);
    pk_rsa_cells_free(&C);
    return reason;
}

int pk_rsa_batch_place(const pk_rsa_batch_env *e, double r, const int32_t *species, size_t m,
                       const double *lo, const double *span, pk_stop_reason *why)
{
    const uint32_t min_run = e->prm->test.batch_min_run;
    if (m < (min_run ? min_run : PK_RSA_BATCH_MIN_RUN) ||
        !usable(e->b, r, e->prm->delta_d, span, m))
        return 0;
    *why = e->enter && e->enter(e->ctx) != 0 ? PK_STOP_ERROR
                                              : run_batches(e, r, species, m, lo, span);
    return 1;
}
