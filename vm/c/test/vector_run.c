/* Checks one run vector on the scripted device (vector.h), stepping the VM as
 * vm/drive.py does: to exactly each instruction count the script loses the line after,
 * then to its end. */
#include "vector.h"

#define GOING(state) ((state) == RL1_RUNNING || (state) == RL1_WAITING)

#define NO_DIFFERENCE 0xFFFFu

/* The trace as it comes, against the expected one. */
typedef struct checker {
    const vector *v;
    uint16_t received;
    uint16_t differs_at;  /* the first entry that differs, or NO_DIFFERENCE */
} checker;

void harness_print_number(uint32_t value)
{
    char text[12];
    uint8_t i = sizeof text - 1u;
    bool negative = value > 0x7FFFFFFFu;
    if (negative) {
        value = 0u - value;
    }
    text[i] = '\0';
    do {
        text[--i] = (char)('0' + (char)(value % 10u));
        value /= 10u;
    } while (value != 0u);
    if (negative) {
        text[--i] = '-';
    }
    harness_print(text + i);
}

static void say(const char *name, const char *what, uint32_t got, uint32_t expected)
{
    harness_print(name);
    harness_print(": ");
    harness_print(what);
    harness_print(" ");
    harness_print_number(got);
    harness_print(", expected ");
    harness_print_number(expected);
    harness_print("\n");
}

static bool same_entry(const trace_entry *a, const trace_entry *b)
{
    uint8_t k;
    if (a->time != b->time || a->call != b->call || a->nargs != b->nargs
        || a->nresult != b->nresult) {
        return false;
    }
    for (k = 0; k < a->nargs; k++) {
        if (a->args[k] != b->args[k]) {
            return false;
        }
    }
    for (k = 0; k < a->nresult; k++) {
        if (a->result[k] != b->result[k]) {
            return false;
        }
    }
    return true;
}

static void check_entry(void *sink, const trace_entry *entry)
{
    checker *c = (checker *)sink;
    trace_entry expected;
    if (c->differs_at == NO_DIFFERENCE) {
        if (c->received < c->v->trace_count) {
            harness_read(&expected, &c->v->trace[c->received], sizeof expected);
        }
        if (c->received >= c->v->trace_count || !same_entry(entry, &expected)) {
            c->differs_at = c->received;
        }
    }
    c->received++;
}

static void read_item(script_item *to, const script_item *from)
{
    harness_read(to, from, sizeof *to);
}

/* Steps until `count` instructions have run (a call in progress polled to its end),
 * or the run is over. */
static rl1_state step_to(rl1_vm *vm, const rl1_program *program, const rl1_hardware *hw,
                         uint32_t count, uint32_t slice)
{
    rl1_state state = (rl1_state)vm->state;
    while (GOING(state) && (vm->executed < count || state == RL1_WAITING)) {
        uint32_t n = count - vm->executed;
        state = rl1_step(vm, program, hw, n < slice ? n : slice);
    }
    return state;
}

/* Loses the line after each instruction count the script names, in increasing order. */
static rl1_state drive(rl1_vm *vm, const rl1_program *program, const rl1_hardware *hw,
                       scripted *device, uint32_t slice)
{
    script_item item;
    uint32_t last = 0, at;
    bool first = true, found;
    uint16_t i;
    rl1_state state = (rl1_state)vm->state;
    for (;;) {
        found = false;
        at = 0;
        for (i = 0; i < device->script.count; i++) {
            device->script.read(&item, &device->script.items[i]);
            if (item.kind == LOSS_INSTRUCTION && (first || (uint32_t)item.value[0] > last)
                && (!found || (uint32_t)item.value[0] < at)) {
                at = (uint32_t)item.value[0];
                found = true;
            }
        }
        if (!found) {
            break;
        }
        state = step_to(vm, program, hw, at, slice);
        if (!GOING(state)) {
            return state;
        }
        for (i = 0; i < device->script.count; i++) { /* each loss at that count */
            device->script.read(&item, &device->script.items[i]);
            if (item.kind == LOSS_INSTRUCTION && (uint32_t)item.value[0] == at) {
                (void)scripted_lose_line(device);
            }
        }
        last = at;
        first = false;
    }
    while (GOING(state)) {
        state = rl1_step(vm, program, hw, slice);
    }
    return state;
}

bool vector_run(const vector *v, const char *name, uint32_t slice, uint8_t busy_polls,
                uint8_t *bitmap, size_t bitmap_size, uint32_t *stack)
{
    rl1_program program;
    rl1_vm vm;
    rl1_hardware hw;
    scripted device;
    script s;
    checker c;
    uint32_t where;
    uint16_t line = 0;
    uint8_t k;
    bool ok = true;
    rl1_refusal refusal = rl1_load(&program, v->ilc, v->ilc_size, bitmap, bitmap_size,
                                   &where);
    if (refusal != RL1_ACCEPTED) {
        say(name, "refused by rule", (uint32_t)refusal, 0);
        return false;
    }
    s.items = v->script;
    s.count = v->script_count;
    s.read = read_item;
    c.v = v;
    c.received = 0;
    c.differs_at = NO_DIFFERENCE;
    rl1_vm_init(&vm, v->budget);
    scripted_init(&device, &s, &vm.mailbox);
    device.record = check_entry;
    device.sink = &c;
    device.busy_polls = busy_polls;
    scripted_hardware(&hw, &device);
    harness_stack_paint();
    (void)drive(&vm, &program, &hw, &device, slice);
    *stack = harness_stack_depth();
    if (vm.fault != v->fault) {
        say(name, "fault", (uint32_t)vm.fault, v->fault);
        ok = false;
    }
    if (vm.fault != RL1_FAULT_NONE && vm.pc != 0xFFFFu) {
        line = rl1_line_at(&program, vm.pc);
    }
    if (line != v->line) {
        say(name, "fault line", line, v->line);
        ok = false;
    }
    if (vm.executed != v->executed) {
        say(name, "instructions executed", vm.executed, v->executed);
        ok = false;
    }
    for (k = 0; k < 53u; k++) {
        int16_t expected;
        harness_read(&expected, &v->variables[k], sizeof expected);
        if (vm.V[k] != expected) {
            say(name, "variable index", k, 0);
            say(name, "  value", (uint32_t)(int32_t)vm.V[k], (uint32_t)(int32_t)expected);
            ok = false;
            break;
        }
    }
    if (c.differs_at != NO_DIFFERENCE || c.received != v->trace_count) {
        say(name, "trace: entries received", c.received, v->trace_count);
        say(name, "trace: first difference at entry", c.differs_at, 0);
        ok = false;
    }
    return ok;
}
