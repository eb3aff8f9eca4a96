/* A main for the fuzz target without libFuzzer (gcc has none): runs it once on each
 * file named, so that the seeds go through gcc's AddressSanitizer and UBSan as well. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int main(int argc, char **argv)
{
    static uint8_t buffer[1u << 20];
    int i;
    for (i = 1; i < argc; i++) {
        FILE *f = fopen(argv[i], "rb");
        size_t size;
        if (!f) {
            perror(argv[i]);
            return 1;
        }
        size = fread(buffer, 1, sizeof buffer, f);
        fclose(f);
        LLVMFuzzerTestOneInput(buffer, size);
    }
    printf("%d files loaded\n", argc - 1);
    return 0;
}
