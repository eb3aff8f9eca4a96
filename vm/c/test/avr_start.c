/* Start-up for the AVR conformance run under simavr: avr-libc's start-up, the output on
 * USART0 (simavr prints it), the cases read from flash with the LPM instruction, and
 * sleep with interrupts off, which ends the simulation. */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/pgmspace.h>
#include <avr/sleep.h>

#include <string.h>

#include "target.h"

void harness_read(void *to, const void *from, size_t size);

#define PAINT 0xA5u
extern uint8_t __heap_start; /* the end of .bss */
static uint8_t *painted_top; /* the highest painted byte */
static uint8_t *stack_mark;  /* about the caller's stack pointer: depths count from it */

void target_print(const char *text)
{
    for (; *text; text++) {
        loop_until_bit_is_set(UCSR0A, UDRE0);
        UDR0 = (uint8_t)*text;
    }
}

uint32_t target_case_field(const uint32_t *field)
{
    return pgm_read_dword(field);
}

void harness_read(void *to, const void *from, size_t size)
{
    memcpy_P(to, from, size);
}

/* Paints the stack from 32 bytes below this frame down to the end of .bss. */
void target_stack_paint(void)
{
    uint8_t here = 0;
    uint8_t *p;
    stack_mark = &here;
    painted_top = (uint8_t *)((uintptr_t)&here - 32u);
    for (p = painted_top; p >= &__heap_start; p--) {
        *p = PAINT;
    }
}

uint32_t target_stack_depth(void)
{
    const uint8_t *p = &__heap_start;
    while (p <= painted_top && *p == PAINT) {
        p++;
    }
    return (uint32_t)(stack_mark - p); /* the unpainted gap counts as used */
}

int main(void)
{
    UCSR0B = _BV(TXEN0);
    (void)target_run();
    loop_until_bit_is_set(UCSR0A, TXC0);
    cli();
    sleep_cpu();
    return 0;
}
