/* Run control on the host (make -C vm/c run-control): rl1_abort from the main loop, from
 * a callback and from a signal handler (an interrupt's stand-in); callbacks that call
 * rl1_step or rl1_vm_init on the VM that called them; a never-ending program given more
 * budget between steps. The programs are the .rob files of test/run_control, compiled by rl1c
 * --emit c; the device is a fake that counts its callbacks and does, from one of them,
 * what a test asks. Prints what differs; exits 1 if anything does. */
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/time.h>

#include "../rl1vm.h"

extern const uint8_t count_ilc[];   /* count.rob: ends with C = 14 after 14 (KYC) */
extern const uint32_t count_ilc_size;
extern const uint8_t patrol_ilc[];  /* patrol.rob: (MOV 3,3), then (TIM 5) forever */
extern const uint32_t patrol_ilc_size;

#define VAR_C 2u
#define COUNT_KYC 0u      /* code offsets in count.ilc and patrol.ilc (rl1c dis) */
#define COUNT_END 17u
#define PATROL_TIM 10u

/* What a callback does besides answering. */
enum action { NOTHING, STEP_AGAIN, INIT_AGAIN, ABORT };
enum callback { BEGIN, CALL, START, POLL, STOP, END, CALLBACKS };

typedef struct fake {
    unsigned calls[CALLBACKS];
    enum callback where;    /* the callback that acts */
    enum action action;
    unsigned when;          /* on its call number `when` (1 the first) */
    unsigned busy_polls;    /* polls answering busy before each answer */
    unsigned polls;
    rl1_state nested;       /* what a nested rl1_step answered */
    rl1_vm *vm;
    const rl1_program *program;
    const rl1_hardware *hw;
} fake;

static void act(fake *f, enum callback which)
{
    f->calls[which]++;
    if (f->where != which || f->calls[which] != f->when) {
        return;
    }
    switch (f->action) {
    case STEP_AGAIN: f->nested = rl1_step(f->vm, f->program, f->hw, 100); break;
    case INIT_AGAIN: rl1_vm_init(f->vm, 1000); break;
    case ABORT: rl1_abort(&f->vm->mailbox); break;
    case NOTHING: break;
    }
}

static rl1_status fake_begin(void *ctx) { act(ctx, BEGIN); return RL1_OK; }
static rl1_status fake_stop(void *ctx) { act(ctx, STOP); return RL1_OK; }
static rl1_status fake_end(void *ctx) { act(ctx, END); return RL1_OK; }

static rl1_status fake_call(void *ctx, uint8_t opcode, const int16_t *args, rl1_reading *out)
{
    (void)opcode;
    (void)args;
    (void)out;
    act(ctx, CALL);
    return RL1_OK;
}

static rl1_status fake_start(void *ctx, uint8_t opcode, const int16_t *args)
{
    fake *f = ctx;
    (void)opcode;
    (void)args;
    act(f, START);
    f->polls = 0;
    return RL1_OK;
}

static rl1_status fake_poll(void *ctx, rl1_reading *out)
{
    fake *f = ctx;
    (void)out;
    act(f, POLL);
    return f->polls++ < f->busy_polls ? RL1_BUSY : RL1_OK;
}

static unsigned passed, failed;

static void expect(const char *test, const char *what, long got, long expected)
{
    if (got == expected) {
        return;
    }
    printf("%s: %s is %ld, expected %ld\n", test, what, got, expected);
    failed++;
}

typedef struct run {
    rl1_program program;
    rl1_vm vm;
    rl1_hardware hw;
    fake device;
} run;

/* A run of `file` ready to step, its device acting as the test asks. */
static void start(run *r, const uint8_t *file, uint32_t size, enum callback where,
                  enum action action, unsigned when)
{
    uint32_t error_offset;
    rl1_hardware hw = {NULL, fake_begin, fake_call, fake_start, fake_poll, fake_stop,
                       fake_end};
    memset(r, 0, sizeof *r);
    if (rl1_load(&r->program, file, size, NULL, 0, &error_offset) != RL1_ACCEPTED) {
        printf("the test's program is refused at offset %lu\n", (unsigned long)error_offset);
        failed++;
    }
    rl1_vm_init(&r->vm, 1000000u);
    hw.ctx = &r->device;
    r->hw = hw;
    r->device.where = where;
    r->device.action = action;
    r->device.when = when;
    r->device.vm = &r->vm;
    r->device.program = &r->program;
    r->device.hw = &r->hw;
}

static rl1_state step(run *r, uint32_t n)
{
    return rl1_step(&r->vm, &r->program, &r->hw, n);
}

/* Steps of 5 instructions until the run is over, or `limit` steps. */
static rl1_state finish(run *r, unsigned limit)
{
    rl1_state state = RL1_RUNNING;
    while (limit-- && (state == RL1_RUNNING || state == RL1_WAITING)) {
        state = step(r, 5);
    }
    return state;
}

/* The run is over with `fault` at code offset `pc`, the vehicle stopped once, end once. */
static void expect_fault(const char *test, run *r, rl1_state state, rl1_fault fault,
                         uint16_t pc)
{
    expect(test, "the state", state, RL1_FAULTED);
    expect(test, "vm.state", r->vm.state, RL1_FAULTED);
    expect(test, "the fault", r->vm.fault, fault);
    expect(test, "pc", r->vm.pc, pc);
    expect(test, "stops", r->device.calls[STOP], 1);
    expect(test, "ends", r->device.calls[END], 1);
    expect(test, "a step after it", step(r, 5), RL1_FAULTED);
    expect(test, "stops after a step more", r->device.calls[STOP], 1);
}

static void test_count_ends(void)
{
    run r;
    start(&r, count_ilc, count_ilc_size, CALL, NOTHING, 0);
    expect("count", "the state", finish(&r, 1000), RL1_ENDED);
    expect("count", "C", r.vm.V[VAR_C], 14);
}

/* A callback that steps the VM again: C was 1 and the run ENDED; now the step faults at
 * the call whose callback did it, and the nested step did nothing. */
static void test_step_from_call(void)
{
    run r;
    start(&r, count_ilc, count_ilc_size, CALL, STEP_AGAIN, 1);
    expect_fault("rl1_step from call", &r, finish(&r, 1000), RL1_FAULT_DEVICE, COUNT_KYC);
    expect("rl1_step from call", "the nested step", r.device.nested, RL1_FAULTED);
    expect("rl1_step from call", "C", r.vm.V[VAR_C], 0);
    expect("rl1_step from call", "executed", (long)r.vm.executed, 1);
}

static void test_init_from_call(void)
{
    run r;
    start(&r, count_ilc, count_ilc_size, CALL, INIT_AGAIN, 3);
    expect_fault("rl1_vm_init from call", &r, finish(&r, 1000), RL1_FAULT_DEVICE, COUNT_KYC);
}

static void test_step_from_poll(void)
{
    run r;
    start(&r, patrol_ilc, patrol_ilc_size, POLL, STEP_AGAIN, 4);
    r.device.busy_polls = 2;
    expect_fault("rl1_step from poll", &r, finish(&r, 1000), RL1_FAULT_DEVICE, PATROL_TIM);
    expect("rl1_step from poll", "the nested step", r.device.nested, RL1_FAULTED);
}

static void test_step_from_begin(void)
{
    run r;
    start(&r, count_ilc, count_ilc_size, BEGIN, STEP_AGAIN, 1);
    expect_fault("rl1_step from begin", &r, finish(&r, 1000), RL1_FAULT_DEVICE, 0xFFFFu);
    expect("rl1_step from begin", "executed", (long)r.vm.executed, 0);
}

static void test_step_from_end(void)
{
    run r;
    start(&r, count_ilc, count_ilc_size, END, STEP_AGAIN, 1);
    expect_fault("rl1_step from end", &r, finish(&r, 1000), RL1_FAULT_DEVICE, COUNT_END);
    expect("rl1_step from end", "C", r.vm.V[VAR_C], 14);
}

/* The fault's own stop calls rl1_step: the fault stays the one that stopped the run. */
static void test_step_from_stop(void)
{
    run r;
    start(&r, patrol_ilc, patrol_ilc_size, STOP, STEP_AGAIN, 1);
    r.device.busy_polls = 1;
    (void)step(&r, 8);
    rl1_abort(&r.vm.mailbox);
    expect_fault("rl1_step from stop", &r, step(&r, 5), RL1_FAULT_ABORTED, PATROL_TIM);
}

/* From the main loop, between steps, with the TIM in progress: the next step polls no
 * more and faults at the TIM. */
static void test_abort_waiting(void)
{
    run r;
    unsigned polls;
    start(&r, patrol_ilc, patrol_ilc_size, CALL, NOTHING, 0);
    r.device.busy_polls = 1000;
    expect("abort while waiting", "the state", step(&r, 100), RL1_WAITING);
    rl1_abort(&r.vm.mailbox);
    rl1_abort(&r.vm.mailbox); /* twice is once */
    polls = r.device.calls[POLL];
    expect_fault("abort while waiting", &r, step(&r, 100), RL1_FAULT_ABORTED, PATROL_TIM);
    expect("abort while waiting", "polls after it", (long)(r.device.calls[POLL] - polls), 0);
}

/* From a callback, as an interrupt handler would while the call runs: taken at the
 * call's event point, in the same step. */
static void test_abort_from_call(void)
{
    run r;
    start(&r, count_ilc, count_ilc_size, CALL, ABORT, 3);
    expect_fault("abort from call", &r, step(&r, 1000), RL1_FAULT_ABORTED, COUNT_KYC);
    expect("abort from call", "C", r.vm.V[VAR_C], 2);
    expect("abort from call", "calls", r.device.calls[CALL], 3);
}

/* Before the first step: begin is called (a loss from before is dropped, an abort not),
 * then the run faults before its first instruction. */
static void test_abort_before_begin(void)
{
    run r;
    start(&r, count_ilc, count_ilc_size, CALL, NOTHING, 0);
    rl1_abort(&r.vm.mailbox);
    expect_fault("abort before begin", &r, step(&r, 100), RL1_FAULT_ABORTED, 0);
    expect("abort before begin", "begins", r.device.calls[BEGIN], 1);
    expect("abort before begin", "executed", (long)r.vm.executed, 0);
}

/* Over a pending lost line (mode 2, MOV): the abort wins, and is not dropped. */
static void test_abort_over_loss(void)
{
    run r;
    start(&r, patrol_ilc, patrol_ilc_size, CALL, NOTHING, 0);
    r.device.busy_polls = 1000;
    expect("abort over a loss", "the state", step(&r, 100), RL1_WAITING);
    expect("abort over a loss", "the post", rl1_post_line_lost(&r.vm.mailbox, 2, RL1_MOV), 1);
    rl1_abort(&r.vm.mailbox);
    expect("abort over a loss", "a post after it", rl1_post_line_lost(&r.vm.mailbox, 2, RL1_MOV),
           0);
    expect_fault("abort over a loss", &r, step(&r, 100), RL1_FAULT_ABORTED, PATROL_TIM);
}

static void test_abort_after_end(void)
{
    run r;
    start(&r, count_ilc, count_ilc_size, CALL, NOTHING, 0);
    expect("abort after the end", "the state", finish(&r, 1000), RL1_ENDED);
    rl1_abort(&r.vm.mailbox);
    expect("abort after the end", "the state after", step(&r, 100), RL1_ENDED);
    expect("abort after the end", "stops", r.device.calls[STOP], 0);
}

/* An interrupt: SIGALRM's handler aborts the patrol while the main loop steps it. */
static run signalled;

static void on_alarm(int signal_number)
{
    (void)signal_number;
    rl1_abort(&signalled.vm.mailbox);
}

static void test_abort_from_signal(void)
{
    struct itimerval timer = {{0, 0}, {0, 20000}}; /* once, in 20 ms */
    rl1_state state = RL1_RUNNING;
    unsigned long steps = 0;
    start(&signalled, patrol_ilc, patrol_ilc_size, CALL, NOTHING, 0);
    signal(SIGALRM, on_alarm);
    setitimer(ITIMER_REAL, &timer, NULL);
    while ((state == RL1_RUNNING || state == RL1_WAITING) && steps < 2000000000ul) {
        state = step(&signalled, 3);
        signalled.vm.executed = 0; /* a patrol: never the budget */
        steps++;
    }
    expect_fault("abort from a signal", &signalled, state, RL1_FAULT_ABORTED,
                 signalled.vm.pc);
    expect("abort from a signal", "the fault's pc is an instruction of the loop",
           signalled.vm.pc >= PATROL_TIM, 1);
}

/* The budget bounds a run: a patrol meets it. Set back between steps, it bounds the
 * instructions since, and the patrol runs ten times its budget and more. */
static void test_patrol_budget(void)
{
    run r;
    uint32_t total = 0;
    rl1_state state = RL1_RUNNING;
    start(&r, patrol_ilc, patrol_ilc_size, CALL, NOTHING, 0);
    r.vm.budget = 1000;
    expect("patrol's budget", "the state", finish(&r, 100000), RL1_FAULTED);
    expect("patrol's budget", "the fault", r.vm.fault, RL1_FAULT_BUDGET);
    start(&r, patrol_ilc, patrol_ilc_size, CALL, NOTHING, 0);
    r.vm.budget = 1000;
    while (total < 10000u && (state == RL1_RUNNING || state == RL1_WAITING)) {
        uint32_t before = r.vm.executed;
        state = step(&r, 100);
        total += r.vm.executed - before;
        r.vm.executed = 0; /* topped up: the next 1000 instructions may run */
    }
    expect("patrol topped up", "the state", state, RL1_RUNNING);
    expect("patrol topped up", "instructions run", total >= 10000u, 1);
}

/* vm/c/README.md's snapshot, made between steps and restored after a reset (a new
 * device) as it says: the count goes on to 14 as if nothing had happened. */
static void test_snapshot_running(void)
{
    run r, restored;
    rl1_vm snapshot;
    start(&r, count_ilc, count_ilc_size, CALL, NOTHING, 0);
    expect("snapshot", "the state", step(&r, 23), RL1_RUNNING);
    memcpy(&snapshot, &r.vm, sizeof snapshot);
    start(&restored, count_ilc, count_ilc_size, CALL, NOTHING, 0);
    memcpy(&restored.vm, &snapshot, sizeof snapshot);
    restored.vm.begun = 0;
    restored.vm.mailbox.posted = restored.vm.mailbox.taken = 0;
    expect("snapshot", "the restored run", finish(&restored, 1000), RL1_ENDED);
    expect("snapshot", "C", restored.vm.V[VAR_C], 14);
    expect("snapshot", "begins after the reset", restored.device.calls[BEGIN], 1);
    expect("snapshot", "(KYC) after the reset", restored.device.calls[CALL],
           14 - r.device.calls[CALL]);
    expect("snapshot", "executed", (long)restored.vm.executed, 99);
}

/* Taken while a (TIM) waits: the reset ended it, so the restored run starts it again. */
static void test_snapshot_waiting(void)
{
    run r, restored;
    rl1_vm snapshot;
    uint8_t shape;
    start(&r, patrol_ilc, patrol_ilc_size, CALL, NOTHING, 0);
    r.device.busy_polls = 1000;
    expect("snapshot while waiting", "the state", step(&r, 100), RL1_WAITING);
    memcpy(&snapshot, &r.vm, sizeof snapshot);
    start(&restored, patrol_ilc, patrol_ilc_size, CALL, NOTHING, 0);
    memcpy(&restored.vm, &snapshot, sizeof snapshot);
    restored.vm.begun = 0;
    restored.vm.mailbox.posted = restored.vm.mailbox.taken = 0;
    restored.vm.pc = (uint16_t)(restored.vm.pc
                                - rl1_op_length(restored.vm.waiting, restored.program.minor,
                                                &shape));
    restored.vm.waiting = 0;
    restored.vm.executed -= 1;
    expect("snapshot while waiting", "pc", restored.vm.pc, PATROL_TIM);
    expect("snapshot while waiting", "the restored run", step(&restored, 4), RL1_RUNNING);
    expect("snapshot while waiting", "(TIM) started again", restored.device.calls[START], 2);
    expect("snapshot while waiting", "executed", (long)restored.vm.executed,
           (long)r.vm.executed + 3);
    expect("snapshot while waiting", "C", restored.vm.V[VAR_C], 1);
}

/* Runs one test: it passes when nothing it expects differs. */
static void check(void (*test)(void))
{
    unsigned before = failed;
    test();
    passed += failed == before;
}

int main(void)
{
    check(test_count_ends);
    check(test_step_from_call);
    check(test_init_from_call);
    check(test_step_from_poll);
    check(test_step_from_begin);
    check(test_step_from_end);
    check(test_step_from_stop);
    check(test_abort_waiting);
    check(test_abort_from_call);
    check(test_abort_before_begin);
    check(test_abort_over_loss);
    check(test_abort_after_end);
    check(test_abort_from_signal);
    check(test_patrol_budget);
    check(test_snapshot_running);
    check(test_snapshot_waiting);
    printf("run control: %u passed, %u failed\n", passed, failed);
    return failed != 0;
}
