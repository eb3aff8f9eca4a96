/* rl1_hardware.h: the RL/I VM's hardware interface and step call, for C firmware.
 *
 * Normative: spec/ilc.md, section 12, says what each declaration means; this header is
 * its exact C shape, and vm/hardware.py and vm/machine.py are the Python reference.
 * C99; no allocation; nothing here blocks.
 */
#ifndef RL1_HARDWARE_H
#define RL1_HARDWARE_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- What every callback answers --------------------------------------------------- */

typedef enum {
    RL1_OK = 0,    /* done (a poll or a call: `out` holds what a sensing built-in read) */
    RL1_BUSY = 1,  /* only from poll: the built-in is still taking device time */
    RL1_ERROR = 2  /* the device failed or refused: a device-error fault */
} rl1_status;

/* What a built-in gives back when it is done. The VM reads only the fields the form
 * has (spec/ilc.md 8.3: "writes", and "R = result"), and checks each against its
 * documented range before writing anything (12.5). */
typedef struct {
    int16_t result;     /* R: KYO centre, IMG area, CAM R position, ULT distance, INP data */
    int16_t writes[4];  /* the reserved variables in the order of the "writes" column:
                           KYO u v; IMG w x y z; FZI s t */
} rl1_reading;

/* The vehicle. One dispatch per kind of callback; a callback runs inside rl1_step, so
 * what it may do with the VM is said at rl1_step below; the built-in is named by its opcode
 * (0x40..0x5D, spec/ilc.md 8.3: one opcode per form, CAM and ULT selectors included;
 * vm/c/rl1vm.h names them RL1_OP_FRE .. RL1_OP_FZI),
 * `args` holds its arguments in parameter order, already range-checked (as many as the
 * form's arity; NULL when it has none). */
typedef struct {
    void *ctx;  /* handed to every callback */
    /* A program is about to run its first instruction (12.3). */
    rl1_status (*begin)(void *ctx);
    /* A built-in that takes no device time: FRE HLD MOV TRC KYC KYO SCN LMP INP OUT FZO
     * FZI. Answers RL1_OK (with `out` filled for KYO, INP, FZI) or RL1_ERROR. */
    rl1_status (*call)(void *ctx, uint8_t opcode, const int16_t *args, rl1_reading *out);
    /* A built-in that takes device time: ORG MVI STR STL STX ROT TIM IMG CAM* ULT*.
     * Answers RL1_OK (started) or RL1_ERROR; never RL1_BUSY. */
    rl1_status (*start)(void *ctx, uint8_t opcode, const int16_t *args);
    /* The started built-in: RL1_BUSY, RL1_OK (with `out` filled for IMG, CAM R, ULT) or
     * RL1_ERROR. A TIM or MVI during which the device posted a lost line answers RL1_OK
     * at its next poll (12.4). */
    rl1_status (*poll)(void *ctx, rl1_reading *out);
    /* Stop the vehicle now: a fault (12.5). */
    rl1_status (*stop)(void *ctx);
    /* The program is over: after (END), or after a fault and its stop (12.3). */
    rl1_status (*end)(void *ctx);
} rl1_hardware;

/* ---- Lost lines: a one-slot mailbox, written from an interrupt ----------------------- */

/* Single producer (the device, from an interrupt or a task), single consumer (the VM).
 * Only the device writes `event` and `posted`, only the VM writes `taken`; every field is
 * one byte, so each read and write is atomic on any microcontroller. On a multi-core or
 * out-of-order processor, add a release barrier between the two writes of
 * rl1_post_line_lost and an acquire barrier after its first read in rl1_take_line_lost. */
typedef struct {
    volatile uint8_t event;   /* RL1_EVENT(mode, command), valid while posted != taken */
    volatile uint8_t posted;  /* counts posts, modulo 256 */
    volatile uint8_t taken;   /* counts takes, modulo 256 */
} rl1_mailbox;

#define RL1_MOV 0
#define RL1_MVI 1
#define RL1_EVENT(mode, command) ((uint8_t)(((mode) << 1) | (command)))  /* mode 2 or 3 */
#define RL1_EVENT_MODE(event) ((uint8_t)((event) >> 1))
#define RL1_EVENT_COMMAND(event) ((uint8_t)((event) & 1))

/* The device posts a line lost in tracing mode 2 or 3 while `command` was the motion in
 * effect (modes 0 and 1 are the device's alone: nothing is posted). Returns 1 when
 * posted, 0 when an event is already pending: that loss is dropped, not queued. */
static inline int rl1_post_line_lost(rl1_mailbox *box, uint8_t mode, uint8_t command) {
    if (box->posted != box->taken) return 0;
    box->event = RL1_EVENT(mode, command);
    box->posted = (uint8_t)(box->posted + 1);
    return 1;
}

/* An emergency stop, from the main loop or an interrupt handler (never blocks, calls
 * nothing): the run's next step, or the event point under way in one (after a call or
 * a jump taken), stops the vehicle through `stop` and `end` and ends the run with the
 * fault RL1_FAULT_ABORTED, at the call in progress or the instruction at hand. It is
 * posted into the mailbox as an event of its own, over a pending lost line (which it
 * makes moot) and never dropped; a second abort before the first is taken adds nothing.
 * The device is the only other writer of the mailbox, and may interrupt this: the loop
 * writes the event again until a loss posted in between is overwritten. An abort after
 * the run is over (ENDED: END leaves the motion in effect, 12.3) is never taken: stop the
 * vehicle yourself then. */
#define RL1_ABORT_EVENT 0xFFu  /* no RL1_EVENT: mode 127 */
static inline void rl1_abort(rl1_mailbox *box) {
    if (box->posted != box->taken && box->event == RL1_ABORT_EVENT) return;
    do {
        box->event = RL1_ABORT_EVENT;
        box->posted = (uint8_t)(box->posted + 1);
    } while (box->event != RL1_ABORT_EVENT);
}

/* The VM takes the pending event, if any: 1 and *event set, or 0. */
static inline int rl1_take_line_lost(rl1_mailbox *box, uint8_t *event) {
    uint8_t posted = box->posted;
    if (posted == box->taken) return 0;
    *event = box->event;
    box->taken = posted;
    return 1;
}

/* ---- The VM's state and its step call ------------------------------------------------ */

typedef enum {
    RL1_RUNNING = 0,  /* the step ran its n instructions: step again */
    RL1_WAITING = 1,  /* a built-in is taking device time: step again to poll it */
    RL1_ENDED = 2,    /* (END), or past the last instruction */
    RL1_FAULTED = 3,  /* `fault` and `pc` say what and where */
    RL1_IN_STEP = 4   /* never returned: vm->state while a step runs (what callbacks see) */
} rl1_state;

typedef enum {  /* the values are rl1c run's exit statuses */
    RL1_FAULT_NONE = 0,
    RL1_FAULT_ARGUMENT_RANGE = 10,
    RL1_FAULT_MISSING_HANDLER = 11,
    RL1_FAULT_BUDGET = 12,
    RL1_FAULT_DEVICE = 13,  /* also: a callback broke the rules of rl1_step below */
    RL1_FAULT_ABORTED = 14  /* rl1_abort: the emergency stop */
} rl1_fault;



/* The verified program (spec/ilc.md 10), as the implementation's loader makes it
 * (vm/c/rl1vm.h defines ours): the VM reads its code and its handler table. Read only,
 * so it may sit wherever the firmware likes; so may the rl1_hardware table (in flash). */
typedef struct rl1_program rl1_program;

/* Everything a run needs to resume, and nothing else: 128 bytes with 32-bit pointers
 * and alignment, 127 on AVR. What is read only (the program, the hardware table) is not
 * in it, but given to every step. Zero it, set the budget, then step. */
typedef struct {
    /* the machine (spec/ilc.md 8.1) */
    int16_t V[53];
    int16_t acc;
    int16_t R;
    uint16_t pc;                /* code offset of the next instruction; after a fault, of
                                   the faulting one (0xFFFF: before the first) */
    uint32_t executed;          /* instructions run, the one that faulted included. A
                                   run that never ends (a patrol) is given more by
                                   setting it back between steps: the budget then
                                   bounds what runs after (vm/c/README.md). It
                                   stops at 2^32 - 1 rather than wrap */
    uint32_t budget;            /* any u32; rl1c takes 1 .. 2^31 - 1 (12.6) */
    rl1_mailbox mailbox;        /* the device posts here */
    /* the run */
    uint8_t waiting;            /* opcode of the call in progress, 0 for none */
    uint8_t state;              /* an rl1_state */
    uint8_t fault;              /* an rl1_fault: what went wrong, at pc */
    uint8_t begun;              /* begin() has been called */
    uint8_t stop_failed;        /* the stop after the fault answered RL1_ERROR */
} rl1_vm;

/* Run at most n instructions of `program` on `hw` (n = 0: only poll a call in progress)
 * and say where the run stands. Every step of a run must be given the same program and
 * hardware. Once RL1_ENDED or RL1_FAULTED, a step does nothing and says so again.
 *
 * Inside a callback (which runs inside a step), vm->state reads RL1_IN_STEP and the
 * locals of the step hold what is not yet written back: vm->acc is stale; vm->pc is just
 * past the call under way (so that rl1_line_at(program, vm->pc - 1) names its source
 * line); vm->executed counts the instructions run, the call included, when the VM is
 * built with RL1_EXECUTED_IN_CALLS=1 (a simulator's build), and is stale otherwise; a call writes its reserved variables and R only after its
 * callback returns. A callback may read vm->V, post into vm->mailbox and call rl1_abort; it must
 * not call rl1_step or rl1_vm_init on the VM that called it: the nested rl1_step does
 * nothing and returns RL1_FAULTED, and when the callback returns the step faults
 * (RL1_FAULT_DEVICE at the call, or at END for `end`; `begin`: before the first
 * instruction; a fault's own stop and end: its fault stays). rl1_vm_init would also have
 * zeroed the variables. A step never waits: when it returns RL1_WAITING, nothing will
 * change until the device finishes the call in progress, so a main loop may sleep until
 * the device says so (the interrupt that ends the motion, the timer of a TIM) and then
 * step; stepping sooner only polls. */
rl1_state rl1_step(rl1_vm *vm, const rl1_program *program, const rl1_hardware *hw,
                   uint32_t n);

#ifdef __cplusplus
}
#endif

#endif /* RL1_HARDWARE_H */
