/* Host-only entry points for the differential tests (tests/c/), which call them through
 * ctypes: the loader's own interface needs a struct that Python need not mirror. */
#include "../rl1vm.h"

int rl1_test_load(const uint8_t *file, uint32_t size, size_t bitmap_size,
                  uint32_t *error_offset);
uint16_t rl1_test_line_at(const uint8_t *file, uint32_t size, uint16_t code_offset);

static uint8_t bitmap[RL1_BITMAP_SIZE(0xFFFFu)];

/* The loader's status for `file`, given a bitmap of `bitmap_size` bytes (0: none). */
int rl1_test_load(const uint8_t *file, uint32_t size, size_t bitmap_size,
                  uint32_t *error_offset)
{
    rl1_program program;
    return (int)rl1_load(&program, file, size, bitmap_size ? bitmap : NULL, bitmap_size,
                         error_offset);
}

/* The source line of `code_offset` in a file the loader accepts; 0 if it refuses it. */
uint16_t rl1_test_line_at(const uint8_t *file, uint32_t size, uint16_t code_offset)
{
    rl1_program program;
    uint32_t error_offset;
    if (rl1_load(&program, file, size, bitmap, sizeof bitmap, &error_offset) != RL1_OK) {
        return 0;
    }
    return rl1_line_at(&program, code_offset);
}
