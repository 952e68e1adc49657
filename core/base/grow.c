/* grow.c — arrays that grow together; the contract is in grow.h. */
#include "grow.h"

#include <stdlib.h>
#include <string.h>

int pk_grow(const pk_grow_item *items, size_t n_items, size_t cap)
{
    int rc = 0;
    for (size_t k = 0; k < n_items; k++) {
        if (!items[k].ptr_addr)
            continue;
        void *old; /* the pointer read and written as bytes: any T * */
        memcpy(&old, items[k].ptr_addr, sizeof old);
        void *p = realloc(old, (cap ? cap : 1) * items[k].elem);
        if (!p) {
            rc = -1;
            continue;
        }
        memcpy(items[k].ptr_addr, &p, sizeof p);
    }
    return rc;
}

size_t pk_grow_cap(size_t cap, size_t need, size_t first)
{
    size_t c = cap ? 2 * cap : first;
    return c < need ? need : c;
}
