/* The scripted device of the conformance vectors (spec/vectors/README.md, "The scripted
 * device"; vm/scripted.py is the reference) behind the hardware callbacks of
 * rl1_hardware.h: host and target runners alike run the run vectors on it. Like
 * vm/hardware.py's Blocking adapter, a built-in that takes device time runs to its end
 * when started; its poll then answers RL1_BUSY `busy_polls` times before the answer, so
 * that the runners exercise the VM's waiting as well. Nothing is stored per call: each
 * command goes to `record`, which the runner compares with the expected trace. */
#ifndef SCRIPTED_H
#define SCRIPTED_H

#include "../rl1vm.h"

/* One line of a sensor script, as the vectors' text form writes it. */
/* REPEAT_AFTER_LAST: the script's "after_last": "repeat" (a call past the readings
 * gets the last one again, or zeros); without it such a call fails (a device error). */
enum script_kind {
    SENSOR, LOSS_TIME, LOSS_DURING, LOSS_INSTRUCTION, FAIL, STOP_FAILS, REPEAT_AFTER_LAST
};

typedef struct script_item {
    uint8_t kind;     /* enum script_kind */
    uint8_t key;      /* SENSOR and FAIL: the opcode; LOSS_DURING: RL1_MOV or RL1_MVI */
    int32_t value[4]; /* the reading (INP: port, value); a time; N and A; an instruction */
} script_item;

#define TRACE_LINE_LOST 0x100u /* trace calls besides the opcodes */
#define TRACE_STOP 0x101u

typedef struct trace_entry {
    uint32_t time;
    uint16_t call;    /* an opcode, TRACE_LINE_LOST or TRACE_STOP */
    uint8_t nargs, nresult;
    int16_t args[3];
    int16_t result[4];
} trace_entry;

/* Where the script's items are (copied out one at a time with `read`: on AVR they are
 * in flash). */
typedef struct script {
    const script_item *items;
    uint16_t count;
    void (*read)(script_item *item, const script_item *from);
} script;

#define INP_PORTS 8u /* the distinct ports a script reads */

typedef struct scripted {
    script script;
    rl1_mailbox *mailbox;   /* where lost lines go: the VM's */
    void (*record)(void *sink, const trace_entry *entry);
    void *sink;
    uint8_t busy_polls;     /* how many polls answer busy before the answer */
    /* the device's state */
    uint32_t time;
    uint8_t mode;
    uint8_t motion;         /* 0: none; else 1 + RL1_MOV or RL1_MVI */
    bool motion_ends;
    uint32_t motion_nth, motion_start, motion_end;
    uint32_t moves[2];      /* MOV and MVI calls so far */
    uint16_t arrivals[0x5Eu - 0x40u]; /* calls of each form so far, by opcode */
    uint8_t ports[INP_PORTS];
    uint16_t port_reads[INP_PORTS];
    uint8_t port_count;
    bool failing;           /* the waiting built-in under way fails at its end */
    rl1_status started;     /* what the waiting built-in answers */
    rl1_reading reading;
    uint8_t polls;          /* busy answers given for it so far */
} scripted;

/* Empties `device` for a run of `s`, posting into `mailbox`. */
void scripted_init(scripted *device, const script *s, rl1_mailbox *mailbox);

/* The callbacks, with the device as ctx. */
void scripted_hardware(rl1_hardware *hw, scripted *device);

/* The line is lost now (a loss after instruction N, made by the runner). */
bool scripted_lose_line(scripted *device);

#endif
