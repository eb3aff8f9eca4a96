/* A fake vehicle for vm/c/README.md's embedding code (vehicle.h): it prints each
 * command it is given, one line each, and answers every image with the same reading,
 * which takes Listing 1 (examples/sample.rob) through its main path to its end. Each
 * started command answers busy once before it is done, so that the main loop sees
 * RL1_WAITING. Output goes to standard output on the host, to USART0 on AVR (simavr
 * prints it); on AVR the run ends, after main returns, asleep with interrupts off,
 * which ends the simulation. */
#include "vehicle.h"

#ifdef __AVR__
#include <avr/io.h>
#else
#include <stdio.h>
#endif

static uint8_t started;     /* the started command's opcode; 0: none */
static uint8_t busy_polls;  /* polls that answered busy for it */

static void print(const char *text)
{
#ifdef __AVR__
    for (; *text; text++) {
        loop_until_bit_is_set(UCSR0A, UDRE0);
        UDR0 = (uint8_t)*text;
    }
#else
    fputs(text, stdout);
#endif
}

static void print_number(int32_t value)
{
    char digits[12];
    char *p = digits + sizeof digits - 1;
    uint32_t magnitude = value < 0 ? 0u - (uint32_t)value : (uint32_t)value;
    *p = '\0';
    do {
        *--p = (char)('0' + magnitude % 10u);
        magnitude /= 10u;
    } while (magnitude);
    if (value < 0) {
        *--p = '-';
    }
    print(p);
}

/* "what n1 n2 ...\n" */
static void print_line(const char *what, const int16_t *numbers, uint8_t count)
{
    uint8_t k;
    print(what);
    for (k = 0; k < count; k++) {
        print(" ");
        print_number(numbers[k]);
    }
    print("\n");
}

void board_init(void)
{
#ifdef __AVR__
    UCSR0B = _BV(TXEN0);
#endif
}

void motors_idle(void) { print("idle\n"); }
void motors_set(int16_t left, int16_t right)
{
    int16_t speeds[2];
    speeds[0] = left;
    speeds[1] = right;
    print_line("MOV", speeds, 2);
}
void motors_free(void) { print("FRE\n"); }
void motors_brake(void) { print("brake\n"); }
void tracing_mode(int16_t mode) { print_line("TRC", &mode, 1); }
void camera_scene(int16_t scene) { print_line("SCN", &scene, 1); }
int16_t odo_centre(void) { return 0; }
int16_t odo_right(void) { return 0; }
int16_t odo_left(void) { return 0; }
int16_t port_read(int16_t port) { return (int16_t)(port & 0xFF); }

bool command_start(uint8_t opcode, const int16_t *args)
{
    int16_t numbers[4];
    uint8_t k, arity = rl1_call_arity(opcode);
    numbers[0] = opcode;
    for (k = 0; k < arity; k++) {
        numbers[k + 1u] = args[k];
    }
    print_line("start", numbers, (uint8_t)(arity + 1u));
    started = opcode;
    busy_polls = 0;
    return true;
}

bool command_done(void)
{
    return busy_polls++ > 0u;
}

bool command_failed(void)
{
    return false;
}

/* An image of a bright object ahead and far down the picture (Listing 1 then leaves
 * each of its loops at once). */
void command_reading(rl1_reading *out)
{
    if (started == RL1_OP_IMG) {
        out->result = 200; /* area */
        out->writes[0] = 10;  /* w */
        out->writes[1] = 128; /* x */
        out->writes[2] = 200; /* y */
        out->writes[3] = 20;  /* z */
    }
    started = 0;
}

void do_other_work(void) {}

void report_refusal(rl1_refusal refusal, uint32_t where)
{
    int16_t numbers[2];
    numbers[0] = (int16_t)refusal;
    numbers[1] = (int16_t)where;
    print_line("refused", numbers, 2);
}

void report_fault(uint8_t fault, uint16_t line, uint8_t stop_failed)
{
    int16_t numbers[3];
    numbers[0] = fault;
    numbers[1] = (int16_t)line;
    numbers[2] = stop_failed;
    print_line("fault", numbers, 3);
}

void report_ended(uint32_t executed)
{
    print("ended after ");
    print_number((int32_t)executed);
    print(" instructions\n");
}

#ifdef __AVR__
/* Run by avr-libc's exit once main returns: the last byte sent, sleep with interrupts
 * off, which ends simavr's run. */
__attribute__((naked, used, section(".fini1"))) static void halt(void)
{
    loop_until_bit_is_set(UCSR0A, TXC0);
    __asm__ volatile("cli\n\tsleep");
}
#endif
