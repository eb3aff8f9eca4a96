/* Runs the run vectors of the image (target_cases.py writes them: vectors-N.c) on the
 * scripted device, in one step and in steps of 3 instructions with waiting built-ins
 * answering busy once, and prints what differs, a summary, and the deepest stack the
 * stepping used (rl1_step, the runner's stepping loop and the test device's callbacks). */
#include "target.h"
#include "vector.h"

extern const vector target_vectors[];
extern const uint16_t target_vector_count;

static uint8_t bitmap[RL1_BITMAP_SIZE(4096)];

/* A device that answers every callback at once, and OK: the VM's own stack, nearly. */
static rl1_status quiet(void *ctx)
{
    (void)ctx;
    return RL1_OK;
}

static rl1_status quiet_call(void *ctx, uint8_t opcode, const int16_t *args, rl1_reading *out)
{
    (void)ctx;
    (void)opcode;
    (void)args;
    out->result = 0;
    return RL1_OK;
}

static rl1_status quiet_start(void *ctx, uint8_t opcode, const int16_t *args)
{
    (void)ctx;
    (void)opcode;
    (void)args;
    return RL1_OK;
}

static rl1_status quiet_poll(void *ctx, rl1_reading *out)
{
    (void)ctx;
    out->result = 0;
    return RL1_OK;
}

/* The deepest stack rl1_step takes running vector `v`'s program on the quiet device. */
static uint32_t own_stack(const vector *v)
{
    static const rl1_hardware hw = {0, quiet, quiet_call, quiet_start, quiet_poll, quiet,
                                    quiet};
    rl1_program program;
    rl1_vm vm;
    uint32_t where, depth;
    if (rl1_load(&program, v->ilc, v->ilc_size, bitmap, sizeof bitmap, &where)
        != RL1_ACCEPTED) {
        return 0;
    }
    rl1_vm_init(&vm, v->budget);
    target_stack_paint();
    while (rl1_step(&vm, &program, &hw, 1000u) <= RL1_WAITING) {
    }
    depth = target_stack_depth();
    return depth;
}

void harness_print(const char *text)
{
    target_print(text);
}

void harness_stack_paint(void)
{
    target_stack_paint();
}

uint32_t harness_stack_depth(void)
{
    return target_stack_depth();
}

uint16_t target_run(void)
{
    uint16_t n, failures = 0, runs = 0;
    uint32_t deepest = 0, own = 0;
    for (n = 0; n < target_vector_count; n++) {
        vector v;
        char name[8] = "vector ";
        uint8_t way;
        uint32_t depth;
        harness_read(&v, &target_vectors[n], sizeof v);
        for (way = 0; way < 2u; way++) {
            depth = 0;
            if (!vector_run(&v, name, way ? 3u : 0xFFFFFFFFu, way, bitmap, sizeof bitmap,
                            &depth)) {
                target_print("  (that was vector ");
                harness_print_number(n);
                target_print(")\n");
                failures++;
            }
            deepest = depth > deepest ? depth : deepest;
            runs++;
        }
        depth = own_stack(&v);
        own = depth > own ? depth : own;
    }
    target_print("conformance: ");
    harness_print_number((uint32_t)(runs - failures));
    target_print(" passed, ");
    harness_print_number(failures);
    target_print(" failed; stack high-water of rl1_step: ");
    harness_print_number(own);
    target_print(" bytes (");
    harness_print_number(deepest);
    target_print(" with the scripted device)\n");
    return failures;
}
