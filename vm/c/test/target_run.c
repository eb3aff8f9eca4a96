/* Loads every conformance case, with a bitmap and by rescan, and compares the status
 * and error offset with the host's; prints one line per difference and a summary. */
#include "target.h"

static uint8_t bitmap[RL1_BITMAP_SIZE(4096)];

static void print_number(uint32_t value)
{
    char text[11];
    uint8_t i = sizeof text - 1u;
    text[i] = '\0';
    do {
        text[--i] = (char)('0' + (char)(value % 10u));
        value /= 10u;
    } while (value != 0u);
    target_print(text + i);
}

uint16_t target_run(void)
{
    uint16_t n, failures = 0;
    uint8_t mode;
    for (n = 0; n < target_case_count; n++) {
        const target_case *c = &target_cases[n];
        uint32_t start = target_case_field(&c->start), size = target_case_field(&c->size);
        uint32_t status = target_case_field(&c->status);
        uint32_t offset = target_case_field(&c->offset);
        for (mode = 0; mode < 2u; mode++) {
            rl1_program program;
            uint32_t where = 0;
            rl1_refusal got = rl1_load(&program, target_blob + start, size,
                                      mode ? NULL : bitmap, mode ? 0u : sizeof bitmap,
                                      &where);
            if ((uint32_t)got != status || (got != RL1_ACCEPTED && where != offset)) {
                target_print("case ");
                print_number(n);
                target_print(mode ? " (rescan): status " : " (bitmap): status ");
                print_number((uint32_t)got);
                target_print(" at ");
                print_number(where);
                target_print(", host says ");
                print_number(status);
                target_print(" at ");
                print_number(offset);
                target_print("\n");
                failures++;
            }
        }
    }
    target_print("conformance: ");
    print_number(2u * target_case_count - failures);
    target_print(" passed, ");
    print_number(failures);
    target_print(" failed\n");
    return failures;
}
