/* uuid.c — version 4 UUIDs from getrandom(2) (RFC 9562 §5.4); contract in uuid.h. */
#include "uuid.h"

#include <errno.h>
#include <sys/random.h>
#include <sys/types.h>

#include "api/digest.h"

int pk_uuid4(char out[PK_UUID_LEN + 1])
{
    unsigned char b[16];
    size_t got = 0;
    while (got < sizeof b) { /* blocks only until the pool is first seeded */
        ssize_t k = getrandom(b + got, sizeof b - got, 0);
        if (k > 0)
            got += (size_t)k;
        else if (!(k < 0 && errno == EINTR)) {
            out[0] = 0;
            return -1;
        }
    }
    b[6] = (unsigned char)((b[6] & 0x0f) | 0x40); /* version 4 */
    b[8] = (unsigned char)((b[8] & 0x3f) | 0x80); /* variant 10x (RFC 9562) */
    static const int group[5] = {4, 2, 2, 2, 6};  /* bytes per dash-separated group */
    char *p = out;
    const unsigned char *q = b;
    for (int g = 0; g < 5; g++) {
        if (g)
            *p++ = '-';
        pk_hex(q, (size_t)group[g], p);
        p += 2 * group[g];
        q += group[g];
    }
    return 0;
}
