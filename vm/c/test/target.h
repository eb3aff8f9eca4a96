/* The conformance run on an emulated target (make -C vm/c targets): the cases that
 * target_cases.py generates, and what each target's start-up file provides. */
#ifndef TARGET_H
#define TARGET_H

#include <stdint.h>

#include "../rl1vm.h"

#ifndef TARGET_FLASH
#define TARGET_FLASH /* flash and data share one address space: nothing to say */
#endif

typedef struct target_case {
    uint32_t start, size;   /* in target_blob */
    uint32_t status, offset; /* what the Python verifier answers */
} target_case;

extern const uint8_t target_blob[];
extern const target_case target_cases[];
extern const uint16_t target_case_count;

/* From the target's start-up file. */
void target_print(const char *text);
uint32_t target_case_field(const uint32_t *field); /* reads a case's field from flash */
void target_stack_paint(void);      /* marks the free stack below the caller's frame */
uint32_t target_stack_depth(void);  /* how much of it has been written since */

/* Runs every case of the image (target_run.c: the loader's; target_vectors.c: the run
 * vectors'); returns the number that differ from the host. */
uint16_t target_run(void);

/* Writes `value` in decimal at `at` (no C library on a target); returns the end. */
static inline char *target_decimal(char *at, uint32_t value)
{
    char digits[11];
    uint8_t n = 0;
    do {
        digits[n++] = (char)('0' + value % 10u);
        value /= 10u;
    } while (value);
    while (n) {
        *at++ = digits[--n];
    }
    return at;
}

#endif
