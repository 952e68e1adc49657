/* fuzz_request.c — libFuzzer harness of the 'request' target (targets.h). */
#include "targets.h"

FUZZ_SANITIZER_OPTIONS

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_request(data, size);
    return 0;
}
