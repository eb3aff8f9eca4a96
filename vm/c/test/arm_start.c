/* Start-up for the Cortex-M conformance run under qemu-system-arm: a vector table, a
 * reset handler that clears .bss and runs the cases, and ARM semihosting for the output
 * and the exit status (qemu -semihosting). No C library. */
#include "target.h"

extern uint32_t __bss_start__, __bss_end__, __stack_top__;
void reset(void);
void harness_read(void *to, const void *from, size_t size);

#define PAINT 0xA5u
static uint8_t *painted_top; /* the highest painted byte */
static uint8_t *stack_mark;  /* about the caller's stack pointer: depths count from it */

/* Semihosting call `op` with argument `arg` (the ARM semihosting specification). */
static void semihost(uint32_t op, const void *arg)
{
    register uint32_t r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
}

void target_print(const char *text)
{
    semihost(0x04u, text); /* SYS_WRITE0 */
}

uint32_t target_case_field(const uint32_t *field)
{
    return *field;
}

/* gcc may call these for a structure's copy or initialization; there is no C library. */
void *memset(void *to, int value, size_t size);
void *memcpy(void *to, const void *from, size_t size);

void *memset(void *to, int value, size_t size)
{
    uint8_t *out = to;
    while (size--) {
        *out++ = (uint8_t)value;
    }
    return to;
}

void *memcpy(void *to, const void *from, size_t size)
{
    harness_read(to, from, size);
    return to;
}

void harness_read(void *to, const void *from, size_t size)
{
    uint8_t *out = to;
    const uint8_t *in = from;
    while (size--) {
        *out++ = *in++;
    }
}

/* Paints the stack from 64 bytes below this frame down to the end of .bss; nothing
 * else runs meanwhile (no interrupts). */
void target_stack_paint(void)
{
    uint8_t here = 0;
    uint8_t *p;
    stack_mark = &here;
    painted_top = (uint8_t *)((uintptr_t)&here - 64u);
    for (p = painted_top; p >= (uint8_t *)&__bss_end__; p--) {
        *p = PAINT;
    }
}

uint32_t target_stack_depth(void)
{
    const uint8_t *p = (const uint8_t *)&__bss_end__;
    while (p <= painted_top && *p == PAINT) {
        p++;
    }
    return (uint32_t)(stack_mark - p); /* the unpainted gap counts as used */
}

void reset(void)
{
    uint32_t *p;
    for (p = &__bss_start__; p < &__bss_end__; p++) {
        *p = 0;
    }
    /* SYS_EXIT: "application exit" (0x20026) is status 0, anything else 1. */
    semihost(0x18u, (const void *)(target_run() ? 0x20024u : 0x20026u));
    for (;;) {
    }
}

/* The first two words of the vector table: the initial stack pointer, then reset. */
struct vector_table {
    const uint32_t *stack;
    void (*reset)(void);
};

__attribute__((section(".vectors"), used))
static const struct vector_table vectors = {&__stack_top__, reset};
