/* The RL/I VM: runs a program rl1_load verified, in steps (spec/ilc.md sections 8, 9
 * and 12; vm/machine.py is the reference, and every vector pins the two together).
 *
 * The code is read in place (from flash) with RL1_READ_BYTE; the verifier has checked
 * every opcode, operand, jump target and handler entry, so the VM checks nothing about
 * the code, only what exists at run time: a variable argument's range, what the device
 * answers, the watchdog budget and lost-line events.
 *
 * Portability: `int` may be 16 bits (AVR). `acc` is kept as a uint16_t bit pattern, so
 * that +, - and the shifts wrap without signed overflow; a value becomes an int16_t
 * only when stored (two's complement, spec/ilc.md section 13). No table in static data.
 */
#include "rl1vm.h"

#define NO_PC 0xFFFFu  /* fault_pc of a fault before the first instruction */

/* The reserved variables the sensing calls write (spec/ilc.md 8.3), by index. */
#define VAR_S 44u
#define VAR_U 46u
#define VAR_W 48u

/* The opcodes the VM treats apart from the generic call. */
#define OP_KYO 0x4Cu
#define OP_IMG 0x4Eu
#define OP_CAMR 0x54u
#define OP_ULTA 0x55u
#define OP_ULTD 0x58u
#define OP_INP 0x5Au
#define OP_FZI 0x5Du

void rl1_vm_init(rl1_vm *vm, const rl1_program *program, const rl1_hardware *hardware,
                 uint32_t budget)
{
    unsigned char *byte = (unsigned char *)vm;
    size_t i;
    uint8_t k;
    for (i = 0; i < sizeof *vm; i++) { /* no memset: freestanding */
        byte[i] = 0;
    }
    vm->code = program->code;
    vm->code_size = program->code_size;
    for (k = 0; k < 4u; k++) {
        vm->handlers[k] = program->handlers[k];
    }
    vm->budget = budget;
    vm->hw = hardware;
}

/* x shifted by `count` places, left or right (spec/language.md 7.2): a count of 16 or
 * more gives 0, or the sign for a right shift; a negative count shifts the other way
 * (-32768 by 32768 places). Never a shift by the raw count, which could be undefined. */
static uint16_t shifted(uint16_t x, int16_t count, bool left)
{
    uint16_t places = (uint16_t)count;
    if (count < 0) {
        left = !left;
        places = (uint16_t)(0u - places);
    }
    if (places >= 16u) {
        return (!left && (x & 0x8000u)) ? (uint16_t)0xFFFFu : (uint16_t)0u;
    }
    if (left) {
        return (uint16_t)((uint32_t)x << places);
    }
    if (x & 0x8000u) { /* arithmetic: shift the complement, a non-negative value */
        return (uint16_t)~((uint16_t)~x >> places);
    }
    return (uint16_t)(x >> places);
}

/* Whether built-in `op` takes device time, so is started and polled (12.2): ORG MVI
 * STR STL STX ROT TIM IMG, every CAM and ULT form. */
static bool takes_time(uint8_t op)
{
    return op == 0x42u || op == 0x43u || (op >= 0x45u && op <= 0x48u) || op == 0x4Au
           || (op >= OP_IMG && op <= OP_ULTD);
}

/* Takes a finished call's answer: false for a device error (an ERROR, or a value out of
 * its documented range, 12.5: then nothing is written); else writes the reserved
 * variables, then R (spec/ilc.md section 9, steps 4-6). */
static bool finish(rl1_vm *vm, uint8_t op, rl1_status status, const rl1_reading *out)
{
    uint8_t first = 0, count = 0, k;
    if (status != RL1_OK) {
        return false;
    }
    if (op == OP_KYO) {
        first = VAR_U; /* u, v */
        count = 2;
    } else if (op == OP_IMG) {
        first = VAR_W; /* w, x, y, z */
        count = 4;
    } else if (op == OP_FZI) {
        first = VAR_S; /* s, t */
        count = 2;
    } else if ((op == OP_CAMR && (out->result < 0 || out->result > 784))
               || (op == OP_INP && (out->result < 0 || out->result > 255))) {
        return false;
    }
    for (k = 0; k < count; k++) {
        vm->V[first + k] = out->writes[k];
    }
    if (op == OP_KYO || op == OP_IMG || (op >= OP_CAMR && op <= OP_ULTD) || op == OP_INP) {
        vm->R = out->result;
    }
    return true;
}

/* The call `op` whose operands start at `operands` (section 9, steps 2-6): a fault, or
 * RL1_FAULT_NONE with vm->waiting set when its first poll answered busy. */
static rl1_fault call(rl1_vm *vm, uint8_t op, const uint8_t *operands)
{
    const rl1_hardware *hw = vm->hw;
    int16_t args[3];
    rl1_reading out = {0, {0, 0, 0, 0}};
    rl1_status status;
    uint8_t shape, length = rl1_op_length(op, 0, &shape), mask, k;
    uint8_t arity = shape == RL1_SHAPE_ARGS ? (uint8_t)((length - 2u) / 2u) : 0u;
    if (arity) {
        mask = RL1_BYTE(operands);
        for (k = 0; k < arity; k++) { /* left to right; the first out of range faults */
            uint16_t field = RL1_U16(operands + 1u + 2u * k);
            if (((unsigned)mask >> k) & 1u) {
                args[k] = vm->V[field];
                if (!rl1_arg_in_range(op, k, args[k])) {
                    return RL1_FAULT_ARGUMENT_RANGE;
                }
            } else {
                args[k] = (int16_t)field;
            }
        }
    }
    if (takes_time(op)) {
        if (hw->start(hw->ctx, op, arity ? args : NULL) != RL1_OK) {
            return RL1_FAULT_DEVICE;
        }
        status = hw->poll(hw->ctx, &out);
        if (status == RL1_BUSY) {
            vm->waiting = op;
            return RL1_FAULT_NONE;
        }
    } else {
        status = hw->call(hw->ctx, op, arity ? args : NULL, &out);
    }
    return finish(vm, op, status, &out) ? RL1_FAULT_NONE : RL1_FAULT_DEVICE;
}

/* The event point (section 9): takes a pending lost line and moves *pc to the handler
 * Table 4 names for it (mode 2: MOV :98, MVI :99; mode 3: MOV :96, MVI :97; no other
 * mode jumps). False when that handler is absent: the fault missing-handler. */
static bool take_event(rl1_vm *vm, uint16_t *pc)
{
    uint8_t event, mode, entry;
    if (!rl1_take_line_lost(&vm->mailbox, &event)) {
        return true;
    }
    mode = RL1_EVENT_MODE(event);
    if (mode != 2u && mode != 3u) {
        return true;
    }
    entry = (uint8_t)((mode == 2u ? 2u : 0u) + RL1_EVENT_COMMAND(event));
    if (vm->handlers[entry] == RL1_ABSENT) {
        return false;
    }
    *pc = vm->handlers[entry];
    return true;
}

/* Stops the vehicle and ends the run with fault `kind` at code offset `at` (12.3); `end`
 * is not called again when it is its answer that faulted. */
static rl1_state fault(rl1_vm *vm, rl1_fault kind, uint16_t at, bool ended)
{
    const rl1_hardware *hw = vm->hw;
    if (hw->stop(hw->ctx) != RL1_OK) {
        vm->stop_failed = 1;
    }
    if (!ended) {
        (void)hw->end(hw->ctx); /* the fault is reported whatever it answers */
    }
    vm->fault = kind;
    vm->fault_pc = at;
    vm->state = RL1_FAULTED;
    return RL1_FAULTED;
}

/* The run has reached END at `at` (or the code's end: `at` is then code_size). */
static rl1_state ended(rl1_vm *vm, uint16_t at)
{
    const rl1_hardware *hw = vm->hw;
    vm->state = RL1_ENDED;
    if (hw->end(hw->ctx) != RL1_OK) {
        return fault(vm, RL1_FAULT_DEVICE, at, true);
    }
    return RL1_ENDED;
}

/* The length of the call instruction `op`: a call in progress is at pc minus it. */
static uint16_t call_length(uint8_t op)
{
    uint8_t shape;
    return rl1_op_length(op, 0, &shape);
}

/* Resumes a call in progress (12.2): polls it once. */
static rl1_state resume(rl1_vm *vm)
{
    const rl1_hardware *hw = vm->hw;
    rl1_reading out = {0, {0, 0, 0, 0}};
    uint8_t op = vm->waiting;
    uint16_t at = (uint16_t)(vm->pc - call_length(op));
    rl1_status status = hw->poll(hw->ctx, &out);
    if (status == RL1_BUSY) {
        return RL1_WAITING;
    }
    vm->waiting = 0;
    vm->state = RL1_RUNNING;
    if (!finish(vm, op, status, &out)) {
        return fault(vm, RL1_FAULT_DEVICE, at, false);
    }
    if (!take_event(vm, &vm->pc)) {
        return fault(vm, RL1_FAULT_MISSING_HANDLER, at, false);
    }
    return RL1_RUNNING;
}

/* Runs at most n instructions from vm->pc. The hot state lives in locals and goes back
 * into *vm at every exit: pc, acc, and the instructions run (n - left). */
static rl1_state run(rl1_vm *vm, uint32_t n)
{
    const uint8_t *code = vm->code;
    int16_t *V = vm->V;
    uint16_t pc = vm->pc, at = 0, acc = (uint16_t)vm->acc, x = 0, target;
    uint16_t code_size = vm->code_size;
    uint32_t left = n, before = vm->executed, budget = vm->budget;
    rl1_fault kind = RL1_FAULT_NONE;
    uint8_t op;
    rl1_state state = RL1_RUNNING;
    for (;;) {
        if (left == 0u) {
            state = RL1_RUNNING;
            break;
        }
        if (pc >= code_size) { /* past the last instruction: (END), not counted */
            at = pc;
            state = RL1_ENDED;
            break;
        }
        at = pc;
        op = RL1_BYTE(code + pc);
        left--;
        switch (op) {
        case 0x00: /* END */
            state = RL1_ENDED;
            break;
        case 0x01: /* LDV v */
            acc = (uint16_t)V[RL1_BYTE(code + pc + 1u)];
            pc = (uint16_t)(pc + 2u);
            continue;
        case 0x02: /* LDI i */
            acc = RL1_U16(code + pc + 1u);
            pc = (uint16_t)(pc + 3u);
            continue;
        case 0x03: /* LDR */
            acc = (uint16_t)vm->R;
            pc = (uint16_t)(pc + 1u);
            continue;
        case 0x04: /* STV v */
            V[RL1_BYTE(code + pc + 1u)] = (int16_t)acc;
            pc = (uint16_t)(pc + 2u);
            continue;
        case 0x05: /* INC v */
        case 0x06: /* DEC v */
            x = RL1_BYTE(code + pc + 1u);
            V[x] = (int16_t)(uint16_t)((uint16_t)V[x] + (op == 0x05u ? 1u : 0xFFFFu));
            pc = (uint16_t)(pc + 2u);
            continue;
        case 0x10: case 0x11: case 0x12: case 0x13: case 0x14: case 0x15: case 0x16:
            x = (uint16_t)V[RL1_BYTE(code + pc + 1u)]; /* the ...V arithmetic */
            pc = (uint16_t)(pc + 2u);
            goto arithmetic;
        case 0x18: case 0x19: case 0x1A: case 0x1B: case 0x1C: case 0x1D: case 0x1E:
            x = RL1_U16(code + pc + 1u); /* the ...I arithmetic */
            pc = (uint16_t)(pc + 3u);
            goto arithmetic;
        case 0x20: case 0x21: case 0x22: case 0x23: case 0x24: case 0x25: case 0x26:
            x = (uint16_t)vm->R; /* the ...R arithmetic */
            pc = (uint16_t)(pc + 1u);
            goto arithmetic;
        case 0x30: /* JMP a */
            target = RL1_U16(code + pc + 1u);
            goto jump;
        case 0x07: /* MOVV v, w (format 1.2, as the others below) */
            V[RL1_BYTE(code + pc + 1u)] = V[RL1_BYTE(code + pc + 2u)];
            pc = (uint16_t)(pc + 3u);
            continue;
        case 0x08: /* MOVI v, i */
            V[RL1_BYTE(code + pc + 1u)] = (int16_t)RL1_U16(code + pc + 2u);
            pc = (uint16_t)(pc + 4u);
            continue;
        case 0x09: /* MOVR v */
            V[RL1_BYTE(code + pc + 1u)] = vm->R;
            pc = (uint16_t)(pc + 2u);
            continue;
        case 0x31: case 0x32: case 0x33: /* JZ, JGT, JLT v, a */
        case 0x34: /* DJGT v, a: V[v]--, then JGT */
        case 0x35: case 0x36: case 0x37: /* SJZ, SJGT, SJLT v, a: V[v] = acc, then JZ ... */
            x = RL1_BYTE(code + pc + 1u);
            if (op == 0x34u) {
                V[x] = (int16_t)(uint16_t)((uint16_t)V[x] - 1u);
            } else if (op >= 0x35u) {
                V[x] = (int16_t)acc;
            }
            x = (uint16_t)V[x];
            op = (uint8_t)(op == 0x34u ? 0x32u : op >= 0x35u ? op - 4u : op); /* JZ JGT JLT */
            if (op == 0x31u ? x == 0u : op == 0x32u ? (x != 0u && x < 0x8000u) : x >= 0x8000u) {
                target = RL1_U16(code + pc + 2u);
                goto jump;
            }
            pc = (uint16_t)(pc + 4u);
            continue;
        default: /* a call: the verifier let no other opcode through */
            if (before + (n - left) > budget) {
                kind = RL1_FAULT_BUDGET;
                break;
            }
            vm->executed = before + (n - left);
            pc = (uint16_t)(pc + call_length(op));
            vm->pc = pc;
            kind = call(vm, op, code + at + 1u);
            if (kind != RL1_FAULT_NONE) {
                break;
            }
            if (vm->waiting) {
                vm->acc = (int16_t)acc;
                vm->state = RL1_WAITING;
                return RL1_WAITING;
            }
            if (!take_event(vm, &pc)) {
                kind = RL1_FAULT_MISSING_HANDLER;
                break;
            }
            continue;
        }
        break;

    arithmetic: /* acc op x, with the operator in the opcode's low 3 bits */
        switch (op & 7u) {
        case 0: acc = (uint16_t)(acc + x); break;
        case 1: acc = (uint16_t)(acc - x); break;
        case 2: acc &= x; break;
        case 3: acc |= x; break;
        case 4: acc ^= x; break;
        case 5: acc = shifted(acc, (int16_t)x, true); break;
        default: acc = shifted(acc, (int16_t)x, false); break;
        }
        continue;

    jump: /* a jump taken: the watchdog, then the event point (section 9) */
        if (before + (n - left) > budget) {
            kind = RL1_FAULT_BUDGET;
            break;
        }
        pc = target;
        if (vm->mailbox.posted != vm->mailbox.taken && !take_event(vm, &pc)) {
            kind = RL1_FAULT_MISSING_HANDLER;
            break;
        }
    }
    vm->pc = pc;
    vm->acc = (int16_t)acc;
    vm->executed = before + (n - left);
    if (kind != RL1_FAULT_NONE) {
        return fault(vm, kind, at, false);
    }
    return state == RL1_ENDED ? ended(vm, at) : state;
}

rl1_state rl1_step(rl1_vm *vm, uint32_t n)
{
    const rl1_hardware *hw = vm->hw;
    if (vm->state == RL1_ENDED || vm->state == RL1_FAULTED) {
        return vm->state;
    }
    if (!vm->begun) {
        vm->begun = 1;
        if (hw->begin(hw->ctx) != RL1_OK) {
            return fault(vm, RL1_FAULT_DEVICE, NO_PC, false);
        }
        vm->mailbox.taken = vm->mailbox.posted; /* a loss before the program is not its own */
    }
    if (vm->waiting) {
        rl1_state state = resume(vm);
        if (state != RL1_RUNNING) {
            return state;
        }
    }
    return run(vm, n);
}
