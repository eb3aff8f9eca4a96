/* A run vector (spec/vectors/README.md) in C, and the runner that checks one on the
 * scripted device: the host runner (host_vectors.c, from the .txt files) and the
 * emulated targets' (target_run.c, from generated arrays in flash) share it. */
#ifndef VECTOR_H
#define VECTOR_H

#include "scripted.h"

typedef struct vector {
    const uint8_t *ilc;
    uint32_t ilc_size;
    const script_item *script;
    const trace_entry *trace;
    const int16_t *variables;   /* 53 */
    uint32_t budget, executed;
    uint16_t script_count, trace_count;
    uint16_t line;              /* the fault's source line; 0: none or unknown */
    uint8_t fault;              /* rl1_fault */
} vector;

/* From the platform: copies `size` bytes of a vector's data (in flash on AVR); prints;
 * marks the free stack below the caller's frame, and says how much of it was written
 * since (the host's need not: 0). */
void harness_read(void *to, const void *from, size_t size);
void harness_print(const char *text);
void harness_stack_paint(void);
uint32_t harness_stack_depth(void);

void harness_print_number(uint32_t value);

/* Runs vector `v` in steps of at most `slice` instructions, its waiting built-ins
 * answering busy `busy_polls` times, and compares everything observable with the
 * expected run: prints what differs (after `name`) and returns false when anything
 * does. `bitmap` is the loader's scratch; *stack gets the deepest stack the stepping
 * used (rl1_step and the scripted device's callbacks). */
bool vector_run(const vector *v, const char *name, uint32_t slice, uint8_t busy_polls,
                uint8_t *bitmap, size_t bitmap_size, uint32_t *stack);

#endif
