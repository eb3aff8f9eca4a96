/* Start-up for the AVR conformance run under simavr: avr-libc's start-up, the output on
 * USART0 (simavr prints it), the cases read from flash with the LPM instruction, and
 * sleep with interrupts off, which ends the simulation. */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/pgmspace.h>
#include <avr/sleep.h>

#include "target.h"

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

int main(void)
{
    UCSR0B = _BV(TXEN0);
    (void)target_run();
    loop_until_bit_is_set(UCSR0A, TXC0);
    cli();
    sleep_cpu();
    return 0;
}
