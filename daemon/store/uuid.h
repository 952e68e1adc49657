/* uuid.h — random job ids: RFC 9562 (formerly RFC 4122) version 4 UUIDs,
 * 122 bits from the kernel's CSPRNG (getrandom), lower-case text form
 * xxxxxxxx-xxxx-4xxx-Vxxx-xxxxxxxxxxxx with V one of 8, 9, a, b. */
#ifndef PK_UUID_H
#define PK_UUID_H

#define PK_UUID_LEN 36 /* characters, without the NUL */

/* A new UUID into out (PK_UUID_LEN + 1 bytes); 0, or -1 when the kernel
 * gives no random bytes (out = ""). */
int pk_uuid4(char out[PK_UUID_LEN + 1]);

#endif
