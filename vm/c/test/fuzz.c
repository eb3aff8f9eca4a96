/* The libFuzzer target: any bytes through the loader and, when it accepts them, the VM.
 * The bytes go to the loader as they come and with their CRC made right (random bytes
 * almost never pass the CRC, which guards every deeper check). It traps when the two
 * ways of checking jump targets disagree, when a refusal points outside the file, or
 * when an accepted program breaks what the loader promises; then it runs the program
 * twice on a random device whose answers (errors, busy polls, readings, lost lines) come
 * from a generator seeded by the bytes, once in one step and once in random steps, and
 * traps when the VM breaks a rule of spec/ilc.md section 12 (a step's count, the budget's
 * bound, a state after the end) or when the two runs differ; the sliced run is also
 * restored from a snapshot taken between two of its steps, a waiting call's among them,
 * into another rl1_vm, which must end as the run did. */
#include <stdlib.h>
#include <string.h>

#include "../rl1vm.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define GOING(state) ((state) == RL1_RUNNING || (state) == RL1_WAITING)
#define MAX_STEPS 200000u /* a run's steps: far more than a budget below 4096 needs */

static uint8_t bitmap[RL1_BITMAP_SIZE(0xFFFFu)];

static uint32_t crc32_of(const uint8_t *data, size_t size)
{
    uint32_t crc = 0xFFFFFFFFu;
    size_t i;
    int bit;
    for (i = 0; i < size; i++) {
        crc ^= (i >= 8 && i < 12) ? 0u : data[i];
        for (bit = 0; bit < 8; bit++) {
            crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
        }
    }
    return ~crc;
}

/* The random device: every answer from a xorshift generator. */
typedef struct device {
    uint32_t state;
    rl1_mailbox *mailbox;
    uint8_t busy;       /* busy answers given in a row */
} device;

static uint32_t next(device *d)
{
    d->state ^= d->state << 13;
    d->state ^= d->state >> 17;
    d->state ^= d->state << 5;
    return d->state;
}

/* Now and then a lost line, in any mode (modes 0 and 1 must not jump); more rarely an
 * emergency stop, from inside a callback as an interrupt handler would. */
static void maybe_lose(device *d)
{
    uint32_t r = next(d);
    if ((r & 7u) == 0u) {
        (void)rl1_post_line_lost(d->mailbox, (uint8_t)((r >> 3) & 3u), (uint8_t)((r >> 5) & 1u));
    } else if ((r & 511u) == 1u) {
        rl1_abort(d->mailbox);
    }
}

static rl1_status answer(device *d, bool may_be_busy)
{
    uint32_t r = next(d) & 63u;
    maybe_lose(d);
    if (may_be_busy && r < 16u && d->busy < 5u) {
        d->busy++;
        return RL1_BUSY;
    }
    d->busy = 0;
    return r == 63u ? RL1_ERROR : RL1_OK;
}

static void read_values(device *d, rl1_reading *out)
{
    uint8_t k;
    out->result = (int16_t)(next(d) % 1100u) - 100; /* INP and CAM R sometimes out of range */
    for (k = 0; k < 4u; k++) {
        out->writes[k] = (int16_t)(uint16_t)next(d);
    }
}

static rl1_status begin(void *ctx)
{
    return answer(ctx, false);
}

static rl1_status call(void *ctx, uint8_t opcode, const int16_t *args, rl1_reading *out)
{
    uint8_t shape;
    if (opcode < 0x40u || opcode > 0x5Du || (rl1_op_length(opcode, 0, &shape) > 1u) != (args != NULL)) {
        __builtin_trap(); /* only calls, with arguments when they have any */
    }
    read_values(ctx, out);
    return answer(ctx, false);
}

static rl1_status start(void *ctx, uint8_t opcode, const int16_t *args)
{
    return call(ctx, opcode, args, &(rl1_reading){0, {0, 0, 0, 0}}) == RL1_ERROR ? RL1_ERROR
                                                                                 : RL1_OK;
}

static rl1_status poll(void *ctx, rl1_reading *out)
{
    read_values(ctx, out);
    return answer(ctx, true);
}

#define TO_THE_END 0xFFFFFFFFu /* go's `until`: no step number stops it */

/* Steps *vm to its end (or to step number `until`) on `hw`, in one step or in steps of
 * sizes from *slicer; checks each step's rules. */
static rl1_state go(const rl1_program *program, const rl1_hardware *hw, rl1_vm *vm,
                    device *slicer, bool sliced, uint32_t *steps, uint32_t until)
{
    rl1_state state = (rl1_state)vm->state;
    uint32_t before, n;
    while (GOING(state) && *steps != until) {
        n = sliced ? next(slicer) % 9u : 0xFFFFFFFFu;
        before = vm->executed;
        state = rl1_step(vm, program, hw, n);
        if ((state == RL1_RUNNING && vm->executed - before != n) || vm->executed - before > n
            || (vm->pc > program->code_size && vm->pc != 0xFFFFu) || ++*steps > MAX_STEPS) {
            __builtin_trap();
        }
    }
    return state;
}

/* Runs `program` with the device seeded by `seed`: in one step (slices 0) or in steps of
 * random sizes; checks each step's rules, and leaves the final state in *vm. Sliced, it
 * also takes a snapshot (the VM's state, the device's, the slicer's) at a random step,
 * a waiting call's among them, and runs a copy of the VM restored from it to the end:
 * the copy must end exactly as the run did (spec/ilc.md 12.1: the state is all). */
static void run(const rl1_program *program, uint32_t seed, bool sliced, rl1_vm *vm)
{
    device d = {seed | 1u, NULL, 0};
    device slicer = {seed ^ 0x9E3779B9u, NULL, 0};
    device saved_d, saved_slicer;
    rl1_hardware hw = {NULL, begin, call, start, poll, NULL, NULL};
    uint32_t budget = 1u + (seed % 4000u), steps = 0, saved_steps;
    uint32_t snapshot_at = 1u + (seed >> 12) % 64u;
    rl1_state state, again;
    rl1_vm saved, restored;
    hw.ctx = &d;
    hw.stop = begin;
    hw.end = begin;
    rl1_vm_init(vm, budget);
    d.mailbox = &vm->mailbox;
    slicer.state |= 1u;
    state = go(program, &hw, vm, &slicer, sliced, &steps, sliced ? snapshot_at : TO_THE_END);
    saved = *vm;
    saved_d = d;
    saved_slicer = slicer;
    saved_steps = steps;
    state = go(program, &hw, vm, &slicer, sliced, &steps, TO_THE_END);
    /* The budget is passed by less than the code's instructions (spec/ilc.md 9). */
    if (vm->executed > budget + program->code_size
        || (vm->fault != RL1_FAULT_NONE) != (state == RL1_FAULTED)
        || (vm->pc == 0xFFFFu && (state != RL1_FAULTED || vm->executed != 0u))) {
        __builtin_trap();
    }
    again = rl1_step(vm, program, &hw, 5);
    if (again != state) {
        __builtin_trap();
    }
    if (sliced) {
        restored = saved;
        d = saved_d;
        d.mailbox = &restored.mailbox;
        slicer = saved_slicer;
        again = go(program, &hw, &restored, &slicer, true, &saved_steps, TO_THE_END);
        /* rl1_vm has no padding on the hosts that fuzz (128 bytes of fields) */
        if (again != state || memcmp(&restored, vm, sizeof restored) != 0) {
            __builtin_trap();
        }
    }
}

static void check(const uint8_t *data, uint32_t size)
{
    rl1_program program, rescanned;
    rl1_vm whole, sliced;
    uint32_t offset, rescanned_offset, code_offset;
    int i;
    rl1_refusal status = rl1_load(&program, data, size, bitmap, sizeof bitmap, &offset);
    rl1_refusal again = rl1_load(&rescanned, data, size, NULL, 0, &rescanned_offset);
    if (status != again || offset != rescanned_offset || offset > size) {
        __builtin_trap();
    }
    if (status != RL1_ACCEPTED) {
        return;
    }
    /* What the VM will rely on without checking: the sections inside the file, every
     * handler inside the code. */
    if (program.code + program.code_size > data + size
        || (program.lines && program.lines > data + size)
        || (program.digest && program.digest + 16 > data + size)) {
        __builtin_trap();
    }
    for (i = 0; i < 4; i++) {
        if (program.handlers[i] != RL1_ABSENT && program.handlers[i] >= program.code_size) {
            __builtin_trap();
        }
    }
    /* Lines never decrease along the code (spec/ilc.md 4.4); the first 256 offsets,
     * since each lookup walks the map. */
    for (code_offset = 1; code_offset <= program.code_size && code_offset < 256u;
         code_offset++) {
        if (rl1_line_at(&program, (uint16_t)code_offset)
            < rl1_line_at(&program, (uint16_t)(code_offset - 1))) {
            __builtin_trap();
        }
    }
    /* Stepping changes nothing of the run (spec/ilc.md 12.1). */
    run(&program, crc32_of(data, size), false, &whole);
    run(&program, crc32_of(data, size), true, &sliced);
    if (whole.executed != sliced.executed || whole.fault != sliced.fault
        || whole.pc != sliced.pc || whole.stop_failed != sliced.stop_failed
        || memcmp(whole.V, sliced.V, sizeof whole.V) != 0) {
        __builtin_trap();
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    uint8_t *copy;
    uint32_t crc;
    if (size > 0x100000u) {
        return 0;
    }
    check(data, (uint32_t)size);
    if (size >= 12) {
        copy = malloc(size);
        if (!copy) {
            return 0;
        }
        memcpy(copy, data, size);
        crc = crc32_of(copy, size);
        copy[8] = (uint8_t)crc;
        copy[9] = (uint8_t)(crc >> 8);
        copy[10] = (uint8_t)(crc >> 16);
        copy[11] = (uint8_t)(crc >> 24);
        check(copy, (uint32_t)size);
        free(copy);
    }
    return 0;
}
