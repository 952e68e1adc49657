/* grow.h — several arrays that grow together (structure-of-arrays: a pair
 * list's i, j, branch, length; a particle set's x, r, species).
 *
 * pk_grow reallocates each listed array to cap elements.  On failure it
 * returns -1 and every array keeps valid memory and its old contents (those
 * that did grow keep the larger block), so the owner can free them all and
 * keeps its old capacity. */
#ifndef PK_GROW_H
#define PK_GROW_H

#include <stddef.h>

typedef struct pk_grow_item {
    void *ptr_addr; /* the address of the array's pointer (a T **); NULL: skipped */
    size_t elem;    /* bytes per element, e.g. 3 * sizeof(double) for a row of 3 */
} pk_grow_item;

/* An item for array pointer p (an lvalue) with per values of *p per element. */
#define PK_GROW_ITEM(p, per)                                                                       \
    {                                                                                              \
        (void *)&(p), (per) * sizeof *(p)                                                          \
    }

/* 0, or -1 when an allocation failed (cap 0 counts as 1). */
int pk_grow(const pk_grow_item *items, size_t n_items, size_t cap);

/* The next capacity: twice cap, at least need and at least first. */
size_t pk_grow_cap(size_t cap, size_t need, size_t first);

#endif
