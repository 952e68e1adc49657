/* result_digest.c — the run-to-run stable content hash of a result file
 * (contract in result_digest.h). */
#include "result_digest.h"

#include "api/digest.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* One part: name, NUL, byte length as uint64 LE, bytes. */
static int feed(pk_sha256 *ctx, const char *name, const void *bytes, uint64_t n)
{
    unsigned char len[8];
    for (int i = 0; i < 8; i++)
        len[i] = (unsigned char)(n >> (8 * i));
    int rc = pk_sha256_update(ctx, name, strlen(name) + 1);
    rc |= pk_sha256_update(ctx, len, sizeof len);
    if (n)
        rc |= pk_sha256_update(ctx, bytes, (size_t)n);
    return rc;
}

/* A numeric dataset read as mem_type (a fixed little-endian type, so the
 * bytes are the same on any host) into the hash; -1 when absent. */
static int feed_dataset(pk_sha256 *ctx, hid_t file, const char *path, hid_t mem_type)
{
    hid_t d = H5Dopen2(file, path, H5P_DEFAULT);
    if (d < 0)
        return -1;
    hid_t s = H5Dget_space(d);
    hssize_t n = s >= 0 ? H5Sget_simple_extent_npoints(s) : -1;
    size_t size = H5Tget_size(mem_type);
    void *buf = n >= 0 ? malloc((size_t)(n ? n : 1) * size) : NULL;
    int rc =
        buf && (n == 0 || H5Dread(d, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0) ? 0 : -1;
    if (rc == 0)
        rc = feed(ctx, path, buf, (uint64_t)n * size);
    free(buf);
    if (s >= 0)
        H5Sclose(s);
    H5Dclose(d);
    return rc;
}

/* A scalar string dataset (its text up to the first NUL); NULL when absent. */
static char *read_string(hid_t file, const char *path)
{
    hid_t d = H5Dopen2(file, path, H5P_DEFAULT);
    if (d < 0)
        return NULL;
    hid_t t = H5Dget_type(d);
    char *text = NULL;
    if (t >= 0 && H5Tget_class(t) == H5T_STRING && !H5Tis_variable_str(t)) {
        size_t n = H5Tget_size(t);
        text = calloc(n + 1, 1);
        if (text && H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, text) < 0) {
            free(text);
            text = NULL;
        }
    }
    if (t >= 0)
        H5Tclose(t);
    H5Dclose(d);
    return text;
}

int pk_result_digest_compute(hid_t file, char hex[65])
{
    char *job = read_string(file, "/parameters/job");
    pk_sha256 *ctx = job ? pk_sha256_new() : NULL;
    int rc = ctx ? 0 : -1;
    if (rc == 0) {
        rc |= feed(ctx, "/parameters/job", job, strlen(job));
        rc |= feed_dataset(ctx, file, "/particles/grains/box/edges", H5T_IEEE_F64LE);
        rc |= feed_dataset(ctx, file, "/particles/grains/position", H5T_IEEE_F64LE);
        rc |= feed_dataset(ctx, file, "/particles/grains/radius", H5T_IEEE_F64LE);
        rc |= feed_dataset(ctx, file, "/particles/grains/species", H5T_STD_I32LE);
    }
    unsigned char md[32];
    if (rc == 0)
        rc = pk_sha256_final(ctx, md); /* frees ctx */
    else
        pk_sha256_free(ctx);
    if (rc == 0)
        pk_hex(md, sizeof md, hex);
    else
        hex[0] = 0;
    free(job);
    return rc;
}

int pk_result_digest_file(const char *path, char hex[65])
{
    int rc = -1;
    H5E_BEGIN_TRY
    {
        hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
        if (f >= 0) {
            rc = pk_result_digest_compute(f, hex);
            H5Fclose(f);
        }
    }
    H5E_END_TRY
    return rc;
}

int pk_result_digest_stored(const char *path, char hex[65])
{
    int rc = -1;
    H5E_BEGIN_TRY
    {
        hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
        char *s = f >= 0 ? read_string(f, "/parameters/result_digest") : NULL;
        if (s && strlen(s) == 64) {
            memcpy(hex, s, 65);
            rc = 0;
        }
        free(s);
        if (f >= 0)
            H5Fclose(f);
    }
    H5E_END_TRY
    return rc;
}
