/* The libFuzzer target: any bytes through the loader, as they come and with their CRC
 * made right (random bytes almost never pass the CRC, which guards every deeper check).
 * It traps when the two ways of checking jump targets disagree, when a refusal points
 * outside the file, or when an accepted program breaks what the loader promises. */
#include <stdlib.h>
#include <string.h>

#include "../rl1vm.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static uint8_t bitmap[RL1_BITMAP_SIZE(0xFFFFu)];

static uint32_t crc32_of(const uint8_t *data, size_t size)
{
    uint32_t crc = 0xFFFFFFFFu;
    size_t i;
    int bit;
    for (i = 0; i < size; i++) {
        crc ^= (i >= 8 && i < 12) ? 0u : data[i];
        for (bit = 0; bit < 8; bit++) {
            crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
        }
    }
    return ~crc;
}

static void check(const uint8_t *data, uint32_t size)
{
    rl1_program program, rescanned;
    uint32_t offset, rescanned_offset, code_offset;
    int i;
    rl1_refusal status = rl1_load(&program, data, size, bitmap, sizeof bitmap, &offset);
    rl1_refusal again = rl1_load(&rescanned, data, size, NULL, 0, &rescanned_offset);
    if (status != again || offset != rescanned_offset || offset > size) {
        __builtin_trap();
    }
    if (status != RL1_ACCEPTED) {
        return;
    }
    /* What the VM will rely on without checking: the sections inside the file, every
     * handler inside the code. */
    if (program.code + program.code_size > data + size
        || (program.lines && program.lines > data + size)
        || (program.digest && program.digest + 16 > data + size)) {
        __builtin_trap();
    }
    for (i = 0; i < 4; i++) {
        if (program.handlers[i] != RL1_ABSENT && program.handlers[i] >= program.code_size) {
            __builtin_trap();
        }
    }
    /* Lines never decrease along the code (spec/ilc.md 4.4); the first 256 offsets,
     * since each lookup walks the map. */
    for (code_offset = 1; code_offset <= program.code_size && code_offset < 256u;
         code_offset++) {
        if (rl1_line_at(&program, (uint16_t)code_offset)
            < rl1_line_at(&program, (uint16_t)(code_offset - 1))) {
            __builtin_trap();
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    uint8_t *copy;
    uint32_t crc;
    if (size > 0x100000u) {
        return 0;
    }
    check(data, (uint32_t)size);
    if (size >= 12) {
        copy = malloc(size);
        if (!copy) {
            return 0;
        }
        memcpy(copy, data, size);
        crc = crc32_of(copy, size);
        copy[8] = (uint8_t)crc;
        copy[9] = (uint8_t)(crc >> 8);
        copy[10] = (uint8_t)(crc >> 16);
        copy[11] = (uint8_t)(crc >> 24);
        check(copy, (uint32_t)size);
        free(copy);
    }
    return 0;
}
