/* fuzz_tetgen.c — libFuzzer harness of the 'tetgen' target (targets.h). */
#include "targets.h"

FUZZ_SANITIZER_OPTIONS

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_tetgen(data, size);
    return 0;
}
