/* The board functions vm/c/README.md's embedding code calls, as a fake vehicle gives
 * them (vehicle.c): tests/c/test_embedding.py builds that code, taken from the README
 * as it is written, with this file, on the host and for the ATmega328P under simavr. */
#ifndef VEHICLE_H
#define VEHICLE_H

#include <stdbool.h>
#include <stdint.h>

#include "rl1vm.h"

void board_init(void);
void motors_idle(void);
void motors_set(int16_t left, int16_t right);
void motors_free(void);
void motors_brake(void);
void tracing_mode(int16_t mode);
void camera_scene(int16_t scene);
int16_t odo_centre(void);
int16_t odo_right(void);
int16_t odo_left(void);
int16_t port_read(int16_t port);
bool command_start(uint8_t opcode, const int16_t *args);
bool command_done(void);
bool command_failed(void);
void command_reading(rl1_reading *out);
void do_other_work(void);
void report_refusal(rl1_refusal refusal, uint32_t where);
void report_fault(uint8_t fault, uint16_t line, uint8_t stop_failed);
void report_ended(uint32_t executed);

#endif
