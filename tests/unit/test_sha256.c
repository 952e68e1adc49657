/* test_sha256.c — api/digest.c against the FIPS 180-4 / NIST CAVP example
 * vectors (exact digests: no tolerance), split-update equivalence, and its
 * base64 / base64url against the RFC 4648 §10 test vectors. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "api/digest.h"

static void test_nist_abc(void)
{
    char hex[65];
    pk_sha256_hex("abc", 3, hex);
    CHECK(!strcmp(hex, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"));
}

static void test_nist_empty(void)
{
    char hex[65];
    pk_sha256_hex("", 0, hex);
    CHECK(!strcmp(hex, "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"));
}

static void test_nist_two_blocks(void)
{
    const char *m = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
    char hex[65];
    pk_sha256_hex(m, strlen(m), hex);
    CHECK(!strcmp(hex, "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1"));
}

static void test_nist_million_a_in_odd_chunks(void)
{
    pk_sha256 *s = pk_sha256_new();
    unsigned char d[32], want[32];
    char chunk[997];
    memset(chunk, 'a', sizeof chunk);
    CHECK(s != NULL);
    size_t left = 1000000;
    while (left) {
        size_t n = left < sizeof chunk ? left : sizeof chunk;
        CHECK(pk_sha256_update(s, chunk, n) == 0);
        left -= n;
    }
    CHECK(pk_sha256_final(s, d) == 0);
    CHECK(pk_sha256_from_hex("cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0",
                             want) == 0);
    CHECK(!memcmp(d, want, 32));
}

/* Lengths around the 55/56/64-byte padding boundaries: byte-wise updates must
 * equal one-shot hashing. */
static void test_padding_boundaries(void)
{
    unsigned char msg[130];
    for (size_t i = 0; i < sizeof msg; i++)
        msg[i] = (unsigned char)(i * 7 + 1);
    for (size_t n = 50; n <= 130; n++) {
        char one[65];
        pk_sha256_hex(msg, n, one);
        pk_sha256 *s = pk_sha256_new();
        unsigned char d[32];
        for (size_t i = 0; i < n; i++)
            pk_sha256_update(s, msg + i, 1);
        CHECK(pk_sha256_final(s, d) == 0);
        unsigned char o[32];
        CHECK(pk_sha256_from_hex(one, o) == 0);
        CHECK_MSG(!memcmp(o, d, 32), "n=%zu", n);
    }
}

static void test_file_digest(void)
{
    char path[] = "/tmp/pk_sha256_XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    CHECK(write(fd, "abc", 3) == 3);
    close(fd);
    char hex[65];
    CHECK(pk_sha256_file_hex(path, hex) == 0);
    CHECK(!strcmp(hex, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"));
    unlink(path);
    CHECK(pk_sha256_file_hex(path, hex) == -1);
}

static void test_hex_round_trip(void)
{
    unsigned char d[32], back[32];
    char hex[65];
    for (int i = 0; i < 32; i++)
        d[i] = (unsigned char)(i * 37 + 5);
    pk_hex(d, 32, hex);
    CHECK(strlen(hex) == 64 && pk_sha256_from_hex(hex, back) == 0 && !memcmp(d, back, 32));
    hex[10] = 'g';
    CHECK(pk_sha256_from_hex(hex, back) == -1);
    CHECK(pk_sha256_from_hex("abc", back) == -1);
}

static void test_base64_rfc4648(void)
{
    static const char *in[] = {"", "f", "fo", "foo", "foob", "fooba", "foobar"};
    static const char *want[] = {"", "Zg==", "Zm8=", "Zm9v", "Zm9vYg==", "Zm9vYmE=", "Zm9vYmFy"};
    static const char *want_url[] = {"", "Zg", "Zm8", "Zm9v", "Zm9vYg", "Zm9vYmE", "Zm9vYmFy"};
    char out[16];
    for (int i = 0; i < 7; i++) {
        pk_base64((const unsigned char *)in[i], strlen(in[i]), out);
        CHECK_MSG(!strcmp(out, want[i]), "%s -> %s", in[i], out);
        pk_base64url((const unsigned char *)in[i], strlen(in[i]), out);
        CHECK_MSG(!strcmp(out, want_url[i]), "%s -> %s", in[i], out);
    }
    /* the two alphabets differ in 62 and 63 only */
    const unsigned char hi[3] = {0xfb, 0xff, 0xbf};
    pk_base64(hi, 3, out);
    CHECK(!strcmp(out, "+/+/"));
    pk_base64url(hi, 3, out);
    CHECK(!strcmp(out, "-_-_"));
}

int main(void)
{
    RUN(test_nist_abc);
    RUN(test_nist_empty);
    RUN(test_nist_two_blocks);
    RUN(test_nist_million_a_in_odd_chunks);
    RUN(test_padding_boundaries);
    RUN(test_file_digest);
    RUN(test_hex_round_trip);
    RUN(test_base64_rfc4648);
    return check_summary();
}
