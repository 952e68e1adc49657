/* edmd_mem.c — the engine's per-grain arrays on 2 MB pages where the system
 * offers them.  Contract: edmd_big_calloc / edmd_big_hint in
 * core/edmd/edmd_state.h.
 *
 * Events are scattered over the box, so at 10^6 grains nearly every record
 * an event touches is a TLB miss on 4 KB pages (hundreds of MB of arrays);
 * on 2 MB pages the whole state fits the second-level TLB.  The one
 * platform call of core/edmd: madvise(MADV_HUGEPAGE) (Linux, transparent
 * huge pages in "madvise" mode); elsewhere, or when refused, the same
 * arrays on ordinary pages (measurements: docs/perf/edmd.md). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "edmd_state.h"

/* Arrays from this size on are worth a huge page (smaller ones stay in the
 * caches anyway). */
#define BIG_MIN (4u << 20)
#define HUGE_PAGE ((size_t)2 << 20)

void edmd_big_hint(void *p, size_t bytes)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (!p || bytes < BIG_MIN)
        return;
    /* the whole huge pages inside [p, p + bytes) */
    const uintptr_t a = ((uintptr_t)p + HUGE_PAGE - 1) & ~(uintptr_t)(HUGE_PAGE - 1);
    const uintptr_t b = ((uintptr_t)p + bytes) & ~(uintptr_t)(HUGE_PAGE - 1);
    if (b > a)
        (void)madvise((void *)a, b - a, MADV_HUGEPAGE); /* advice: a refusal changes nothing */
#else
    (void)p;
    (void)bytes;
#endif
}

void *edmd_big_calloc(size_t n, size_t size)
{
    if (n && size > SIZE_MAX / n)
        return NULL;
    size_t bytes = n * size;
    if (bytes == 0)
        bytes = 64;
    if (bytes < BIG_MIN) {
        bytes = (bytes + 63) & ~(size_t)63;
        void *p = aligned_alloc(64, bytes);
        if (p)
            memset(p, 0, bytes);
        return p;
    }
    bytes = (bytes + HUGE_PAGE - 1) & ~(HUGE_PAGE - 1);
    void *p = aligned_alloc(HUGE_PAGE, bytes);
    if (!p)
        return NULL;
    edmd_big_hint(p, bytes); /* before the first touch: the pages fault in huge */
    memset(p, 0, bytes);
    return p;
}
