/* fuzz_h5_rve.c — libFuzzer harness of the 'h5_rve' target (targets.h). */
#include "targets.h"

FUZZ_SANITIZER_OPTIONS

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_h5_rve(data, size);
    return 0;
}
