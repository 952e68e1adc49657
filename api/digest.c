/* digest.c — SHA-256, hex and base64 through OpenSSL (EVP_sha256,
 * EVP_EncodeBlock); contract in digest.h, known-answer tests in tests/unit/test_sha256.c. */
#include "digest.h"

#include <openssl/evp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct pk_sha256 {
    EVP_MD_CTX *md;
};

pk_sha256 *pk_sha256_new(void)
{
    pk_sha256 *s = malloc(sizeof *s);
    if (s && (s->md = EVP_MD_CTX_new()) && EVP_DigestInit_ex(s->md, EVP_sha256(), NULL))
        return s;
    pk_sha256_free(s);
    return NULL;
}

int pk_sha256_update(pk_sha256 *s, const void *data, size_t n)
{
    return EVP_DigestUpdate(s->md, data, n) ? 0 : -1;
}

int pk_sha256_final(pk_sha256 *s, unsigned char out[32])
{
    unsigned n = 0;
    int ok = EVP_DigestFinal_ex(s->md, out, &n) && n == 32;
    pk_sha256_free(s);
    return ok ? 0 : -1;
}

void pk_sha256_free(pk_sha256 *s)
{
    if (s)
        EVP_MD_CTX_free(s->md);
    free(s);
}

void pk_hex(const unsigned char *d, size_t n, char *hex)
{
    static const char digits[] = "0123456789abcdef";
    for (size_t i = 0; i < n; i++) {
        hex[2 * i] = digits[d[i] >> 4];
        hex[2 * i + 1] = digits[d[i] & 15];
    }
    hex[2 * n] = 0;
}

int pk_sha256_hex(const void *data, size_t n, char hex[65])
{
    unsigned char d[32];
    unsigned len = 0;
    if (!EVP_Digest(data, n, d, &len, EVP_sha256(), NULL) || len != 32) {
        hex[0] = 0;
        return -1;
    }
    pk_hex(d, 32, hex);
    return 0;
}

int pk_sha256_file_hex(const char *path, char hex[65])
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    pk_sha256 *s = pk_sha256_new();
    unsigned char buf[1 << 16];
    size_t n;
    int rc = s ? 0 : -1;
    while (rc == 0 && (n = fread(buf, 1, sizeof buf, f)) > 0)
        rc = pk_sha256_update(s, buf, n);
    if (ferror(f))
        rc = -1;
    fclose(f);
    unsigned char d[32];
    if (!s || pk_sha256_final(s, d) != 0 || rc != 0)
        return -1;
    pk_hex(d, 32, hex);
    return 0;
}

int pk_sha256_from_hex(const char *hex, unsigned char out[32])
{
    for (int i = 0; i < 32; i++) {
        unsigned v = 0;
        for (int j = 0; j < 2; j++) {
            char c = hex[2 * i + j];
            unsigned x = c >= '0' && c <= '9' ? (unsigned)(c - '0')
                : c >= 'a' && c <= 'f'        ? (unsigned)(c - 'a' + 10)
                : c >= 'A' && c <= 'F'        ? (unsigned)(c - 'A' + 10)
                                              : 16u;
            if (x > 15)
                return -1;
            v = v * 16 + x;
        }
        out[i] = (unsigned char)v;
    }
    return hex[64] == 0 ? 0 : -1;
}

void pk_base64(const unsigned char *in, size_t n, char *out)
{
    EVP_EncodeBlock((unsigned char *)out, in, (int)n);
}

void pk_base64url(const unsigned char *in, size_t n, char *out)
{
    pk_base64(in, n, out);
    char *p = out;
    for (; *p && *p != '='; p++)
        *p = *p == '+' ? '-' : *p == '/' ? '_' : *p;
    *p = 0;
}
