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
 * only when stored (two's complement, spec/ilc.md section 13). No table in static data
 * but constant ones: the calls' descriptors (rl1vm.h), which tell the call path all that
 * differs from one call to another, and the threaded dispatch's (RL1_THREADED, never
 * built for size).
 */
#include "rl1vm.h"

#define NO_PC 0xFFFFu  /* pc of a fault before the first instruction */
/* vm->state once a callback called rl1_step on the VM that called it (RL1_IN_STEP before):
 * the step under way faults when the callback returns. */
#define REENTERED 5u


void rl1_vm_init(rl1_vm *vm, uint32_t budget)
{
    unsigned char *byte = (unsigned char *)vm;
    size_t i;
    for (i = 0; i < sizeof *vm; i++) { /* no memset: freestanding */
        byte[i] = 0;
    }
    vm->budget = budget;
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

/* The calls that read something back: the VM takes their reading after the callback
 * (the others' is not looked at). Every call's is cleared before: a test of the
 * descriptor would cost as much as the clearing. */
#define READS (RL1_CALL_SETS_R | RL1_CALL_PAIRS)

/* A reading with every field zero, stored field by field: an initializer of the whole
 * struct becomes a call to memset on Cortex-M0 (gcc at any level) and with clang at -O0,
 * and the VM calls no library function (vm/c/README.md). */
static void clear_reading(rl1_reading *out)
{
    out->result = 0;
    out->writes[0] = 0;
    out->writes[1] = 0;
    out->writes[2] = 0;
    out->writes[3] = 0;
}

/* Whether a callback broke in on the step under way: called rl1_step on this VM (the
 * state is REENTERED) or rl1_vm_init (it is 0). Checked after each callback the run
 * goes on from; the run then faults device-error (rl1vm.h, "What a callback may do"). */
static bool broken_in(const rl1_vm *vm)
{
    return vm->state != (uint8_t)RL1_IN_STEP;
}

/* Inlined at each call, where gcc -Os would call a function out of line: on the call
 * path a call costs more instructions than the function's body. */
#if defined(__GNUC__)
#define ALWAYS_INLINE __attribute__((always_inline)) inline
#else
#define ALWAYS_INLINE
#endif

/* The signed byte at p + k: two's complement, as every conversion to int16_t here
 * (spec/ilc.md 13). */
#define S8_AT(p, k) ((int16_t)(int8_t)RL1_BYTE((p) + (k)))

/* A variable argument's value, from its index in *arg, into *arg: false when it is out
 * of its parameter's range. */
static ALWAYS_INLINE bool variable_argument(const int16_t *V, const rl1_param_range *range,
                                            int16_t *arg)
{
    int16_t value = V[*arg];
    if (!rl1_in_range(range, value)) {
        return false;
    }
    *arg = value;
    return true;
}

/* The `arity` (1 to 3) arguments of call `op` (descriptor `call`) from its operands at
 * `at` (the mask, then the arguments: 2 bytes each, a byte in a compact call) into
 * `args`, left to right: the end of the call's operands, or NULL when a variable is out
 * of its parameter's range (section 9, step 2; which one does not matter, the fault is
 * the call's). First each argument's field, a constant's value or a variable's index:
 * an index is 0 to 52, which reads the same as a signed byte and as a full call's i16
 * (its high byte is 0: the verifier checked it), so that the fields need no look at the
 * mask. Then, when there are variables, their values (the mask has no bit at or above
 * the arity: checked too). Unrolled, the last argument first, each at fixed offsets. */
static const uint8_t *arguments(const int16_t *V, uint8_t op, rl1_descriptor call,
                                uint8_t arity, const uint8_t *at, int16_t *args)
{
    uint8_t mask = RL1_BYTE(at);
    const rl1_param_range *range;
    if (op & RL1_COMPACT_CALL_BIT) {
        switch (arity) {
        case 3: args[2] = S8_AT(at, 3); /* fall through */
        case 2: args[1] = S8_AT(at, 2); /* fall through */
        default: args[0] = S8_AT(at, 1);
        }
        at += arity;
    } else {
        switch (arity) {
        case 3: args[2] = (int16_t)RL1_U16(at + 5); /* fall through */
        case 2: args[1] = (int16_t)RL1_U16(at + 3); /* fall through */
        default: args[0] = (int16_t)RL1_U16(at + 1);
        }
        at += 2u * arity;
    }
    if (mask) {
        range = rl1_call_ranges((uint8_t)(op & ~RL1_COMPACT_CALL_BIT), call);
        if (((mask & 1u) && !variable_argument(V, range, &args[0]))
            || ((mask & 2u) && !variable_argument(V, range + 1, &args[1]))
            || ((mask & 4u) && !variable_argument(V, range + 2, &args[2]))) {
            return NULL;
        }
    }
    return at + 1;
}

/* Two reserved variables from a reading: a word's load and store where a word may lie at
 * any even address (Cortex-M3 and M4, x86), 5 Cortex-M3 instructions fewer for IMG; else
 * a field each (gcc calls memcpy for it on Cortex-M0, and on AVR it costs 20 cycles). */
#if defined(__GNUC__) && (defined(__ARM_FEATURE_UNALIGNED) || defined(__x86_64__))
#define COPY_PAIR(to, from) __builtin_memcpy((to), (from), 2u * sizeof(int16_t))
#define PAIR_IS_A_WORD 1
#else
#define COPY_PAIR(to, from) ((to)[0] = (from)[0], (to)[1] = (from)[1])
#define PAIR_IS_A_WORD 0
#endif

/* A reading of two pairs of reserved variables: IMG's, which also sets R and has no range
 * to check (tests/c/test_c_descriptors.py holds it so). */
#define TWO_PAIRS (2u << RL1_CALL_PAIRS_SHIFT)

/* Takes what call `op` (descriptor `call`, READS), finished, read: false, writing
 * nothing, when its result is outside its documented range (12.5), a device error; else
 * writes its reserved variables, then R (spec/ilc.md section 9, steps 5-6). */
static bool take_reading(rl1_vm *vm, uint8_t op, rl1_descriptor call,
                         const rl1_reading *out)
{
    /* the fields where they lie in the descriptor: tested there, no shift is needed */
    unsigned pairs = call & RL1_CALL_PAIRS, result = call & RL1_CALL_RESULT;
    const int16_t *from = out->writes;
    int16_t *to;
#if PAIR_IS_A_WORD
    /* IMG's five values after one test, where the path below tests each part of the
     * reading: Cortex-M3 IMG 64 -> 58 instructions. Where a pair is two fields, the path
     * below takes them: this one would cost Cortex-M0 24 bytes of flash. */
    if (call & TWO_PAIRS) {
        to = &vm->V[rl1_call_first(op, call)];
        COPY_PAIR(to, from);
        COPY_PAIR(to + 2, from + 2);
        vm->R = out->result;
        return true;
    }
#endif
    /* every checked range starts at 0 (isa_table.py): a negative result is above high */
    if (result && (uint16_t)out->result
                      > (uint16_t)RL1_RESULT_HIGH(result >> RL1_CALL_RESULT_SHIFT)) {
        return false;
    }
    if (pairs) { /* one, or two where a pair is two fields: rl1_reading has four writes */
        to = &vm->V[rl1_call_first(op, call)];
        COPY_PAIR(to, from);
        if (pairs > 1u << RL1_CALL_PAIRS_SHIFT) {
            COPY_PAIR(to + 2, from + 2);
        }
    }
    if (call & RL1_CALL_SETS_R) {
        vm->R = out->result;
    }
    return true;
}

/* The event point (section 9): takes a pending lost line and moves *pc to the handler
 * Table 4 names for it (mode 2: MOV :98, MVI :99; mode 3: MOV :96, MVI :97; no other
 * mode jumps). The fault missing-handler when that handler is absent; the fault aborted
 * when the event is rl1_abort's. */
static rl1_fault take_event(rl1_vm *vm, const rl1_program *program, uint16_t *pc)
{
    uint8_t event, mode, entry;
    if (!rl1_take_line_lost(&vm->mailbox, &event)) {
        return RL1_FAULT_NONE;
    }
    mode = RL1_EVENT_MODE(event);
    if (mode != 2u && mode != 3u) { /* rl1_abort's event has mode 127 */
        return event == RL1_ABORT_EVENT ? RL1_FAULT_ABORTED : RL1_FAULT_NONE;
    }
    entry = (uint8_t)((mode == 2u ? 2u : 0u) + RL1_EVENT_COMMAND(event));
    if (program->handlers[entry] == RL1_ABSENT) {
        return RL1_FAULT_MISSING_HANDLER;
    }
    *pc = program->handlers[entry];
    return RL1_FAULT_NONE;
}

/* rl1_abort asked for the run to end: its event is pending. */
static bool abort_pending(const rl1_vm *vm)
{
    return vm->mailbox.posted != vm->mailbox.taken && vm->mailbox.event == RL1_ABORT_EVENT;
}

/* Stops the vehicle and ends the run with fault `kind` at code offset `at` (12.3); `end`
 * is not called again when it is its answer that faulted. The fault is set before the
 * callbacks run, so that they can tell a fault's stop and end from others. */
static rl1_state fault(rl1_vm *vm, const rl1_hardware *hw, rl1_fault kind, uint16_t at,
                       bool ended)
{
    vm->fault = (uint8_t)kind;
    vm->pc = at;
    if (hw->stop(hw->ctx) != RL1_OK) {
        vm->stop_failed = 1;
    }
    if (!ended) {
        (void)hw->end(hw->ctx); /* the fault is reported whatever it answers */
    }
    return RL1_FAULTED;
}

/* The run has reached END at `at` (or the code's end: `at` is then code_size). */
static rl1_state ended(rl1_vm *vm, const rl1_hardware *hw, uint16_t at)
{
    return hw->end(hw->ctx) != RL1_OK || broken_in(vm)
        ? fault(vm, hw, RL1_FAULT_DEVICE, at, true) : RL1_ENDED;
}

/* The instructions run in all: `before` the step and `ran` in it. The count stops at
 * UINT32_MAX rather than wrap, so that a run given a budget near 2^32 still faults at its
 * next jump or call once past it, as the reference VM, which counts on, does (rl1vm.h). */
static uint32_t counted(uint32_t before, uint32_t ran)
{
    uint32_t sum = before + ran;
    return sum < before ? UINT32_MAX : sum;
}

/* The operand bytes of the instruction at ip. */
#define U8_AT(k) RL1_BYTE(ip + (k))
#define U16_AT(k) RL1_U16(ip + (k))
#define VAR_AT(k) V[U8_AT(k)]
#define S8(k) S8_AT(ip, k)

/* How one instruction hands over to the next. A switch in a loop has one indirect jump
 * for all instructions, which the host's branch predictor guesses from little; GCC and
 * clang can instead end each case with a jump of its own through a table of label
 * addresses ("threaded" dispatch, as Lua and CPython do), each predicted from the case
 * it ends. On the computation of bench/c_speed.py that is 25 ms against 35 (gcc 12,
 * x86-64). Built for size the table is not worth its flash, nor on AVR, whose start-up
 * code would copy it to RAM; define RL1_THREADED as 0 to keep the switch anyway.
 *
 * Every case is CASE(opcode): a case label and, threaded, the label op_<opcode> the
 * table points at (the compiler refuses a table entry without its case, and
 * -Wunused-label a case missing from the table). Threaded, each case counts itself
 * (left--), which leaves the jump that ends a case two instructions long, a byte's load
 * and the jump: short enough for GCC to keep one in each case rather than merge them
 * all into one, which would give the gain back. */
#if defined(__OPTIMIZE_SIZE__) && !defined(RL1_COMPACT)
#define RL1_COMPACT 1
#endif
#if !defined(RL1_THREADED)
#if defined(__GNUC__) && !defined(RL1_COMPACT) && !defined(__AVR__)
#define RL1_THREADED 1
#else
#define RL1_THREADED 0
#endif
#endif
#if !defined(RL1_EXECUTED_IN_CALLS)
#define RL1_EXECUTED_IN_CALLS 0
#endif
#if RL1_THREADED && defined(RL1_COMPACT)
#error "RL1_THREADED needs a case of its own for each instruction: not with RL1_COMPACT"
#endif
#if RL1_THREADED
#define COUNTED(label) label: left--;
/* The jump to the instruction at ip, through the table. The empty asm names the line the
 * case is written on, which makes each case's end unlike every other's: else gcc merges
 * the ends that read alike (the conditional jumps' above all) into one, which each then
 * reaches with a jump more (its crossjumping; x86-64: 10.97 -> 10.69 host instructions
 * an instruction that is not a call, bench/c_host_cost.py). */
#define DISPATCH()                                                                       \
    __extension__({                                                                      \
        __asm__("" : : "i"(__LINE__));                                                  \
        goto *targets[RL1_BYTE(ip)];                                                     \
    })
/* A jump taken to `to`. While left >= near (neither the budget nor the step's limit is
 * near, so `stop` is the code's end, which every target lies before) and no event is
 * pending, the jump dispatches itself: one comparison of each, where the shared path at
 * `jump` costs 4 host instructions more (bench/c_host_cost.py); the shared path marked
 * unlikely, so that gcc lays the dispatch out as the fall-through (x86-64: 10.98 -> 10.93
 * host instructions an instruction that is not a call). `taken` is vm->mailbox.taken,
 * which only the VM writes, kept in a local: a load fewer. */
#define JUMP_TO(to)                                                                      \
    target = (to);                                                                       \
    if (__builtin_expect(left < near || vm->mailbox.posted != taken, 0)) {               \
        goto jump;                                                                       \
    }                                                                                    \
    ip = code + target;                                                                  \
    DISPATCH()
#define CASE(op) case op: COUNTED(op_##op)
/* One statement (no do-while, whose body would take the `continue`). */
#define NEXT()                                                                           \
    if (ip >= stop) { /* the limit or the end is near: the loop's head looks */          \
        continue;                                                                        \
    } else                                                                               \
        DISPATCH()
#else
#define COUNTED(label)
#define CASE(op) case op:
#define NEXT() continue
#define JUMP_TO(to) target = (to); goto jump
#endif

/* acc = first op second, for the seven operators of one operand kind, opcodes `o0`..`o6`
 * (spec/ilc.md 8.2: base + the operator's index), each its own case: a second dispatch
 * on the operator would cost as much. */
#define BITWISE_CASES(o0, o1, o2, o3, o4, first, second, size)                           \
    CASE(o0) acc = (uint16_t)((uint16_t)(first) + (second)); ip += (size); NEXT();       \
    CASE(o1) acc = (uint16_t)((uint16_t)(first) - (second)); ip += (size); NEXT();       \
    CASE(o2) acc = (uint16_t)((uint16_t)(first) & (second)); ip += (size); NEXT();       \
    CASE(o3) acc = (uint16_t)((uint16_t)(first) | (second)); ip += (size); NEXT();       \
    CASE(o4) acc = (uint16_t)((uint16_t)(first) ^ (second)); ip += (size); NEXT()
#define OPERATOR_CASES(o0, o1, o2, o3, o4, o5, o6, first, second, size)                  \
    BITWISE_CASES(o0, o1, o2, o3, o4, first, second, size);                              \
    CASE(o5) acc = shifted((uint16_t)(first), (int16_t)(second), true); ip += (size); NEXT(); \
    CASE(o6) acc = shifted((uint16_t)(first), (int16_t)(second), false); ip += (size); NEXT()

/* The operators on acc and a variable or an immediate (format 1.0). Built for size, the
 * two shifts go to `compute` below, as the superinstructions do: the other five stay
 * cases of their own, so that the switch keeps enough cases for gcc -Os to make it a
 * jump table (with fewer it makes a tree of comparisons, 10 instructions to reach a
 * call on Cortex-M3 where the table takes 3). */
#ifdef RL1_COMPACT
#define ALU_CASES(o0, o1, o2, o3, o4, o5, o6, second, size)                               \
    BITWISE_CASES(o0, o1, o2, o3, o4, acc, second, size);                                \
    CASE(o5) CASE(o6) operand = (second); ip += (size); goto compute
#else
#define ALU_CASES(o0, o1, o2, o3, o4, o5, o6, second, size)                               \
    OPERATOR_CASES(o0, o1, o2, o3, o4, o5, o6, acc, second, size)
#endif

/* The load-and-operate superinstructions (format 1.2): acc = first op second, the
 * operator in the low 3 bits as in OPERATOR_CASES; also the operations on R (`first` is
 * then acc). Built for size (-Os, or RL1_COMPACT defined), each kind only decodes its
 * operands and the operators are one switch for all of them: on Cortex-M3 that is 296
 * bytes of flash fewer, which keeps the VM and verifier within 4 KB. Otherwise each is a
 * case of its own, which the host's branch predictor prefers (the computation of
 * bench/c_speed.py at -O2, with the switch: 67 ms against 79). The vectors run every
 * way: the targets build with -Os, the clang sanitizer build defines RL1_COMPACT, and
 * gcc's runs threaded and with RL1_THREADED=0. */
#ifdef RL1_COMPACT
#define COMPUTE_CASES(o0, o1, o2, o3, o4, o5, o6, first, second, size)                   \
    CASE(o0) CASE(o1) CASE(o2) CASE(o3) CASE(o4) CASE(o5) CASE(o6)                       \
        acc = (uint16_t)(first);                                                         \
        operand = (second);                                                              \
        ip += (size);                                                                    \
        goto compute
#else
#define COMPUTE_CASES OPERATOR_CASES
#endif

/* A conditional jump to the target at ip + 2 when `value` (V[v], v at ip + 1) passes
 * `test`. `value` is a local: the code is uint8_t, a character type that may alias V, so
 * reading V[v] back after a store would reload both. */
#define JUMP_IF(value, test)                                                              \
    if ((value) test 0) {                                                                \
        JUMP_TO(U16_AT(2));                                                              \
    }                                                                                    \
    ip += 4;                                                                             \
    NEXT()

/* Where the dispatch loop must look at the step's limit and the code's end: at the end
 * when the limit cannot come first (each instruction takes at least a byte, so a
 * straight run from ip meets the end within end - ip instructions); else at every
 * instruction (`code`, which every ip passes). Set as the step starts; a jump keeps it
 * while left >= code_size, which holds it true wherever the jump goes, and else sets it
 * to `code` (below `near`). */
#define STOP (left >= (uint32_t)(end - ip) ? end : code)

/* Runs at most n instructions from code offset `at`, the instruction at hand: vm->pc, or
 * the call in progress (12.2), which is first polled once (vm->pc is then past it). The
 * hot state lives in locals and goes back into *vm at every exit: pc, acc, and the
 * instructions run (n - left). `ip` stays on an instruction's first byte until it is
 * done, so that a fault or an end points at it. */
static rl1_state run(rl1_vm *vm, const rl1_program *program, const rl1_hardware *hw,
                     uint32_t n, uint16_t at)
{
#if RL1_THREADED
    /* Each valid opcode's case (the verifier refuses the others). The empty asm makes
     * the table's address opaque, so that it stays in a register rather than being
     * remade in each case's jump, which would then be too long to keep in the case. */
    __extension__ static const void *const table[256] = {
#define TARGET(o) [o] = &&op_##o
#define TARGETS7(o0, o1, o2, o3, o4, o5, o6)                                              \
        TARGET(o0), TARGET(o1), TARGET(o2), TARGET(o3), TARGET(o4), TARGET(o5), TARGET(o6)
        TARGET(RL1_OP_END), TARGET(RL1_OP_LDV), TARGET(RL1_OP_LDI), TARGET(RL1_OP_LDR),
        TARGET(RL1_OP_STV), TARGET(RL1_OP_INC), TARGET(RL1_OP_DEC), TARGET(RL1_OP_MOVV),
        TARGET(RL1_OP_MOVI), TARGET(RL1_OP_MOVR), TARGET(RL1_OP_MOVB),
        TARGETS7(RL1_OP_ADDV, RL1_OP_SUBV, RL1_OP_ANDV, RL1_OP_ORV, RL1_OP_XORV,
                 RL1_OP_SHLV, RL1_OP_SHRV),
        TARGETS7(RL1_OP_ADDI, RL1_OP_SUBI, RL1_OP_ANDI, RL1_OP_ORI, RL1_OP_XORI,
                 RL1_OP_SHLI, RL1_OP_SHRI),
        TARGETS7(RL1_OP_ADDR, RL1_OP_SUBR, RL1_OP_ANDR, RL1_OP_ORR, RL1_OP_XORR,
                 RL1_OP_SHLR, RL1_OP_SHRR),
        TARGET(RL1_OP_JMP), TARGET(RL1_OP_JZ), TARGET(RL1_OP_JGT), TARGET(RL1_OP_JLT),
        TARGET(RL1_OP_DJGT), TARGET(RL1_OP_SJZ), TARGET(RL1_OP_SJGT), TARGET(RL1_OP_SJLT),
        [RL1_OP_FIRST_CALL ... RL1_OP_LAST_CALL] = &&op_call,
        [RL1_OP_MVIS ... RL1_OP_FZOS] = &&op_call, /* the compact calls */
        TARGETS7(RL1_OP_ADDVV, RL1_OP_SUBVV, RL1_OP_ANDVV, RL1_OP_ORVV, RL1_OP_XORVV,
                 RL1_OP_SHLVV, RL1_OP_SHRVV),
        TARGETS7(RL1_OP_ADDVI, RL1_OP_SUBVI, RL1_OP_ANDVI, RL1_OP_ORVI, RL1_OP_XORVI,
                 RL1_OP_SHLVI, RL1_OP_SHRVI),
        TARGETS7(RL1_OP_ADDRV, RL1_OP_SUBRV, RL1_OP_ANDRV, RL1_OP_ORRV, RL1_OP_XORRV,
                 RL1_OP_SHLRV, RL1_OP_SHRRV),
        TARGETS7(RL1_OP_ADDRI, RL1_OP_SUBRI, RL1_OP_ANDRI, RL1_OP_ORRI, RL1_OP_XORRI,
                 RL1_OP_SHLRI, RL1_OP_SHRRI)
#undef TARGETS7
#undef TARGET
    };
    const void *const *targets = table;
    __asm__("" : "+r"(targets));
#endif
    const uint8_t *const code = program->code, *const end = code + program->code_size;
    const uint8_t *ip = code + at;
    int16_t *const V = vm->V;
    int16_t *variable, value;
    uint16_t acc = (uint16_t)vm->acc, target = 0;
    uint32_t left = n, before = vm->executed;
    /* The watchdog (section 9): more than `budget` run in all once left < over_below. */
    uint32_t room = before > vm->budget ? 0u : vm->budget - before;
    uint32_t over_below = n > room ? n - room : 0u;
    /* Below it, a jump looks at both: the budget and the step's limit may be near. */
    uint32_t near = over_below > program->code_size ? over_below : program->code_size;
    const uint8_t *stop = STOP;
    rl1_fault kind = RL1_FAULT_NONE;
    rl1_state state = RL1_RUNNING;
    /* vm->mailbox.taken, which only the VM writes (take_event, then this copy again): an
     * event point compares the post count with it, a load fewer where it stays in a
     * register (the host's jumps with the switch: 17.43 -> 17.23 host instructions an
     * instruction that is not a call; on Cortex-M3 it is spilled) */
    uint8_t taken = vm->mailbox.taken;
    /* a call's */
    const uint8_t *next;
    int16_t args[3];
    const int16_t *given; /* args, or NULL for a call without arguments */
    rl1_reading out;
    rl1_status status;
    rl1_descriptor call;
    uint8_t op, arity;
#ifdef RL1_COMPACT
    uint16_t operand;
#endif
    if (vm->waiting) { /* its opcode as in the code: a compact call's too */
        op = (uint8_t)(vm->waiting & ~RL1_COMPACT_CALL_BIT);
        call = rl1_call_descriptor(op);
        next = code + vm->pc;
        /* cleared here, so that a call started in this step, whose waiting is 0 already,
         * stores nothing when its poll is done; a busy poll sets it again */
        vm->waiting = 0;
        goto poll;
    }
    for (;;) {
        if (ip >= stop) { /* one comparison an instruction while the limit is far */
            if (left == 0u) { /* the step's limit */
                break;
            }
            if (ip >= end) { /* past the last instruction: (END), not counted */
                state = RL1_ENDED;
                break;
            }
        }
        op = RL1_BYTE(ip);
#if RL1_THREADED
        __extension__({ goto *targets[op]; }); /* each case counts itself */
#else
        left--;
#endif
        switch (op) {
        CASE(RL1_OP_END)
            state = RL1_ENDED;
            break;
        CASE(RL1_OP_LDV) acc = (uint16_t)VAR_AT(1); ip += 2; NEXT();       /* v */
        CASE(RL1_OP_LDI) acc = U16_AT(1); ip += 3; NEXT();                 /* i */
        CASE(RL1_OP_LDR) acc = (uint16_t)vm->R; ip += 1; NEXT();
        CASE(RL1_OP_STV) VAR_AT(1) = (int16_t)acc; ip += 2; NEXT();        /* v */
        CASE(RL1_OP_INC)                                                     /* v */
            variable = &VAR_AT(1);
            *variable = (int16_t)(uint16_t)((uint16_t)*variable + 1u);
            ip += 2;
            NEXT();
        CASE(RL1_OP_DEC)                                                     /* v */
            variable = &VAR_AT(1);
            *variable = (int16_t)(uint16_t)((uint16_t)*variable - 1u);
            ip += 2;
            NEXT();
        /* The superinstructions of format 1.2 (the verifier refuses them in older files). */
        CASE(RL1_OP_MOVV) VAR_AT(1) = VAR_AT(2); ip += 3; NEXT();          /* v, w */
        CASE(RL1_OP_MOVI) VAR_AT(1) = (int16_t)U16_AT(2); ip += 4; NEXT(); /* v, i */
        CASE(RL1_OP_MOVR) VAR_AT(1) = vm->R; ip += 2; NEXT();              /* v */
        CASE(RL1_OP_MOVB) VAR_AT(1) = S8(2); ip += 3; NEXT();           /* v, b */
        ALU_CASES(RL1_OP_ADDV, RL1_OP_SUBV, RL1_OP_ANDV, RL1_OP_ORV, RL1_OP_XORV,
                  RL1_OP_SHLV, RL1_OP_SHRV, (uint16_t)VAR_AT(1), 2);
        ALU_CASES(RL1_OP_ADDI, RL1_OP_SUBI, RL1_OP_ANDI, RL1_OP_ORI, RL1_OP_XORI,
                  RL1_OP_SHLI, RL1_OP_SHRI, U16_AT(1), 3);
        COMPUTE_CASES(RL1_OP_ADDR, RL1_OP_SUBR, RL1_OP_ANDR, RL1_OP_ORR, RL1_OP_XORR,
                      RL1_OP_SHLR, RL1_OP_SHRR, acc, (uint16_t)vm->R, 1);
        CASE(RL1_OP_JMP) JUMP_TO(U16_AT(1));                                 /* a */
        CASE(RL1_OP_JZ) JUMP_IF(VAR_AT(1), ==);                              /* v, a */
        CASE(RL1_OP_JGT) JUMP_IF(VAR_AT(1), >);                              /* v, a */
        CASE(RL1_OP_JLT) JUMP_IF(VAR_AT(1), <);                              /* v, a */
        CASE(RL1_OP_DJGT)                                                    /* v, a */
            variable = &VAR_AT(1);
            value = (int16_t)(uint16_t)((uint16_t)*variable - 1u);
            *variable = value;
            JUMP_IF(value, >);
        CASE(RL1_OP_SJZ) value = (int16_t)acc; VAR_AT(1) = value; JUMP_IF(value, ==);
        CASE(RL1_OP_SJGT) value = (int16_t)acc; VAR_AT(1) = value; JUMP_IF(value, >);
        CASE(RL1_OP_SJLT) value = (int16_t)acc; VAR_AT(1) = value; JUMP_IF(value, <);
        COMPUTE_CASES(RL1_OP_ADDVV, RL1_OP_SUBVV, RL1_OP_ANDVV, RL1_OP_ORVV, RL1_OP_XORVV,
                      RL1_OP_SHLVV, RL1_OP_SHRVV, VAR_AT(1), (uint16_t)VAR_AT(2), 3);
        COMPUTE_CASES(RL1_OP_ADDVI, RL1_OP_SUBVI, RL1_OP_ANDVI, RL1_OP_ORVI, RL1_OP_XORVI,
                      RL1_OP_SHLVI, RL1_OP_SHRVI, VAR_AT(1), U16_AT(2), 4);
        COMPUTE_CASES(RL1_OP_ADDRV, RL1_OP_SUBRV, RL1_OP_ANDRV, RL1_OP_ORRV, RL1_OP_XORRV,
                      RL1_OP_SHLRV, RL1_OP_SHRRV, vm->R, (uint16_t)VAR_AT(1), 2);
        COMPUTE_CASES(RL1_OP_ADDRI, RL1_OP_SUBRI, RL1_OP_ANDRI, RL1_OP_ORRI, RL1_OP_XORRI,
                      RL1_OP_SHLRI, RL1_OP_SHRRI, vm->R, U16_AT(1), 3);
        /* The calls, the compact ones (format 1.3) among them, and no other opcode: the
         * verifier refuses the others. The default, so that the compact calls (above
         * the other cases) need no comparison of their own. */
        default:
            COUNTED(op_call)
            /* A call (section 9, steps 2-6), its descriptor telling all that differs. */
            if (left < over_below) {
                kind = RL1_FAULT_BUDGET;
                break;
            }
            op = RL1_BYTE(ip); /* not set by a threaded jump */
            /* a compact call (format 1.3) is its call with a byte an argument: the
             * descriptor and the callbacks see the call's own opcode */
            call = rl1_call_descriptor((uint8_t)(op & ~RL1_COMPACT_CALL_BIT));
            arity = call & RL1_CALL_ARITY;
            next = ip + 1;
            given = NULL;
            if (arity) {
                next = arguments(V, op, call, arity, next, args);
                if (next == NULL) {
                    kind = RL1_FAULT_ARGUMENT_RANGE;
                    break;
                }
                given = args;
            }
            op &= (uint8_t)~RL1_COMPACT_CALL_BIT;
            /* pc past the call while its callbacks run: the line of the call under way is
             * the one before it (vm/native.py's current_line) */
            vm->pc = (uint16_t)(next - code);
#if RL1_EXECUTED_IN_CALLS
            /* the instructions run so far, the call included, for a device that times
             * them (the simulator's clock, vm/drive.py's drive_clocked): about 12
             * instructions a call on Cortex-M3, which firmware does not pay */
            vm->executed = counted(before, n - left);
#endif
            if (call & RL1_CALL_STARTED) {
                if (hw->start(hw->ctx, op, given) != RL1_OK) {
                    kind = RL1_FAULT_DEVICE;
                    break;
                }
            poll:
                clear_reading(&out);
                status = hw->poll(hw->ctx, &out);
                if (status != RL1_OK) { /* one comparison when it is done */
                    if (status == RL1_BUSY && !broken_in(vm)) {
                        vm->waiting = RL1_BYTE(ip); /* as in the code: a compact call's too */
                        vm->acc = (int16_t)acc;
                        vm->executed = counted(before, n - left);
                        return RL1_WAITING;
                    }
                    kind = RL1_FAULT_DEVICE;
                    break;
                }
            } else {
                clear_reading(&out);
                if (hw->call(hw->ctx, op, given, &out) != RL1_OK) {
                    kind = RL1_FAULT_DEVICE;
                    break;
                }
            }
            /* a device error: an ERROR (above), a callback that broke in, or a reading
             * out of its documented range (then nothing is written) */
            if (broken_in(vm)
                || ((call & READS)
                    && !take_reading(vm, (uint8_t)(RL1_BYTE(ip) & ~RL1_COMPACT_CALL_BIT),
                                     call, &out))) {
                kind = RL1_FAULT_DEVICE;
                break;
            }
            if (vm->mailbox.posted != taken) { /* the event point */
                target = vm->pc;
#ifdef RL1_COMPACT
                goto event_point; /* the jumps': shared, built for size */
#else
                /* one of its own: shared, it keeps `left` out of a register in the
                 * jumps' path on the host (x86-64: 3% more instructions in all) */
                kind = take_event(vm, program, &target);
                taken = vm->mailbox.taken;
                if (kind != RL1_FAULT_NONE) {
                    break;
                }
                if (left < near) { /* a handler: as after a jump */
                    stop = code;
                }
                ip = code + target;
                NEXT();
#endif
            }
            /* no jump: `stop` holds (left falls by one, ip gains one at least) */
            ip = next;
            NEXT();
        }
        break;

#ifdef RL1_COMPACT
    compute: /* a load-and-operate instruction's operator: the low 3 bits of op */
        switch (op & 7u) {
        case 0: acc = (uint16_t)(acc + operand); break;
        case 1: acc = (uint16_t)(acc - operand); break;
        case 2: acc = (uint16_t)(acc & operand); break;
        case 3: acc = (uint16_t)(acc | operand); break;
        case 4: acc = (uint16_t)(acc ^ operand); break;
        case 5: acc = shifted(acc, (int16_t)operand, true); break;
        default: acc = shifted(acc, (int16_t)operand, false); break; /* 6 */
        }
        NEXT();
#endif

    jump: /* a jump taken: the watchdog, then the event point (section 9) */
        if (left < near) {
            if (left < over_below) {
                kind = RL1_FAULT_BUDGET;
                break;
            }
            stop = code; /* the step's limit may come before the code's end */
        }
#ifdef RL1_COMPACT
    event_point: /* a call's too, after the watchdog before it (section 9) */
#endif
        if (vm->mailbox.posted != taken) {
            kind = take_event(vm, program, &target);
            taken = vm->mailbox.taken;
            if (kind != RL1_FAULT_NONE) {
                break;
            }
#ifdef RL1_COMPACT
            if (left < near) { /* a handler, after a call: as after a jump */
                stop = code;
            }
#endif
        }
        ip = code + target;
        NEXT();
    }
    vm->pc = (uint16_t)(ip - code);
    vm->acc = (int16_t)acc;
    vm->executed = counted(before, n - left);
    if (kind != RL1_FAULT_NONE) {
        return fault(vm, hw, kind, vm->pc, false);
    }
    return state == RL1_ENDED ? ended(vm, hw, vm->pc) : state;
}

/* A step of a run that is neither over nor in a step already (vm->state RL1_IN_STEP). */
static rl1_state step(rl1_vm *vm, const rl1_program *program, const rl1_hardware *hw,
                      uint32_t n)
{
    uint16_t at;
    uint8_t shape;
    if (!vm->begun) {
        uint8_t posted = vm->mailbox.posted;
        vm->begun = 1;
        if (hw->begin(hw->ctx) != RL1_OK || broken_in(vm)) {
            return fault(vm, hw, RL1_FAULT_DEVICE, NO_PC, false);
        }
        if (vm->mailbox.event != RL1_ABORT_EVENT) {
            vm->mailbox.taken = posted; /* a loss before the program is not its own */
        }
    }
    /* the instruction at hand: the call in progress (pc is past it), or the next */
    at = vm->waiting
         ? (uint16_t)(vm->pc - rl1_op_length(vm->waiting, program->minor, &shape))
         : vm->pc;
    if (abort_pending(vm)) {
        return fault(vm, hw, RL1_FAULT_ABORTED, at, false);
    }
    return run(vm, program, hw, n, at);
}

rl1_state rl1_step(rl1_vm *vm, const rl1_program *program, const rl1_hardware *hw,
                   uint32_t n)
{
    rl1_state state = (rl1_state)vm->state;
    if (state >= RL1_IN_STEP) { /* from a callback of the step under way: it faults */
        vm->state = REENTERED;
        return RL1_FAULTED;
    }
    if (state >= RL1_ENDED) { /* ENDED or FAULTED */
        return state;
    }
    vm->state = RL1_IN_STEP;
    state = step(vm, program, hw, n);
    vm->state = (uint8_t)state;
    return state;
}
