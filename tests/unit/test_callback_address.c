/* test_callback_address.c — which addresses a subscriber callback may reach
 * (daemon/http/callbacks.h): public ones, and private, loopback or
 * link-local ones only where callback_allow lists them. */
#include "check.h"
#include "daemon/http/callbacks.h"

static void test_public_and_private(void)
{
    CHECK(pk_callback_address_ok("93.184.216.34", ""));
    CHECK(pk_callback_address_ok("2606:2800:220:1::248", ""));
    const char *closed[] = {"127.0.0.1",
                            "10.1.2.3",
                            "172.16.0.1",
                            "172.31.255.255",
                            "192.168.1.1",
                            "169.254.169.254",
                            "100.64.0.1",
                            "0.0.0.0",
                            "224.0.0.1",
                            "::1",
                            "::",
                            "fe80::1",
                            "fd00::1",
                            "::ffff:127.0.0.1",
                            "::ffff:10.0.0.1",
                            "not an address"};
    for (size_t i = 0; i < sizeof closed / sizeof *closed; i++)
        CHECK_MSG(!pk_callback_address_ok(closed[i], ""), "%s", closed[i]);
    CHECK(pk_callback_address_ok("172.32.0.1", "")); /* just outside 172.16/12 */
}

static void test_allow_list(void)
{
    CHECK(pk_callback_address_ok("127.0.0.1", "127.0.0.1"));
    CHECK(pk_callback_address_ok("10.0.0.5", "192.168.1.1, 10.0.0.5"));
    CHECK(!pk_callback_address_ok("10.0.0.50", "10.0.0.5")); /* whole addresses only */
    CHECK(!pk_callback_address_ok("127.0.0.1", "127.0.0.10,127.0.0"));
}

int main(void)
{
    RUN(test_public_and_private);
    RUN(test_allow_list);
    return check_summary();
}
