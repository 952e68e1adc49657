/* fuzz_http.c — libFuzzer harness of the 'http' target (target_http.h):
 * whole HTTP requests into the running service. */
#include "target_http.h"
#include "targets.h"

FUZZ_SANITIZER_OPTIONS

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_http(data, size);
    return 0;
}
