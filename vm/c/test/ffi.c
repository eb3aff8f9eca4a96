/* Host-only entry points for Python (rl1.vm.native, and the tests of tests/c/), which
 * calls them through ctypes: the loader's checks on a file alone, and the VM's start and
 * its mailbox, whose inline functions ctypes cannot call. */
#include <stddef.h>

#include "../rl1vm.h"

int rl1_test_load(const uint8_t *file, uint32_t size, size_t bitmap_size,
                  uint32_t *error_offset);
uint16_t rl1_test_line_at(const uint8_t *file, uint32_t size, uint16_t code_offset);
void rl1_ffi_layout(uint32_t *out);
int rl1_ffi_start(rl1_vm *vm, rl1_program *program, const uint8_t *file, uint32_t size,
                  uint32_t budget, uint32_t *error_offset);
int rl1_ffi_post(rl1_vm *vm, uint8_t mode, uint8_t command);
void rl1_ffi_abort(rl1_vm *vm);

static uint8_t bitmap[RL1_BITMAP_SIZE(0xFFFFu)];

/* The loader's status for `file`, given a bitmap of `bitmap_size` bytes (0: none). */
int rl1_test_load(const uint8_t *file, uint32_t size, size_t bitmap_size,
                  uint32_t *error_offset)
{
    rl1_program program;
    return (int)rl1_load(&program, file, size, bitmap_size ? bitmap : NULL, bitmap_size,
                         error_offset);
}

/* The source line of `code_offset` in a file the loader accepts; 0 if it refuses it. */
uint16_t rl1_test_line_at(const uint8_t *file, uint32_t size, uint16_t code_offset)
{
    rl1_program program;
    uint32_t error_offset;
    if (rl1_load(&program, file, size, bitmap, sizeof bitmap, &error_offset)
        != RL1_ACCEPTED) {
        return 0;
    }
    return rl1_line_at(&program, code_offset);
}

/* The sizes and offsets Python's mirror of the structures must have. */
void rl1_ffi_layout(uint32_t *out)
{
    out[0] = sizeof(rl1_vm);
    out[1] = offsetof(rl1_vm, mailbox);
    out[2] = offsetof(rl1_vm, pc);
    out[3] = offsetof(rl1_vm, executed);
    out[4] = offsetof(rl1_vm, state);
    out[5] = offsetof(rl1_vm, fault);
    out[6] = offsetof(rl1_vm, stop_failed);
    out[7] = sizeof(rl1_hardware);
    out[8] = sizeof(rl1_reading);
    out[9] = sizeof(rl1_program);
}

/* Loads `file` (which must stay in place) into *program and makes `vm` ready to run
 * it; the loader's refusal otherwise. */
int rl1_ffi_start(rl1_vm *vm, rl1_program *program, const uint8_t *file, uint32_t size,
                  uint32_t budget, uint32_t *error_offset)
{
    rl1_refusal refusal = rl1_load(program, file, size, bitmap, sizeof bitmap,
                                   error_offset);
    if (refusal == RL1_ACCEPTED) {
        rl1_vm_init(vm, budget);
    }
    return (int)refusal;
}

/* rl1_post_line_lost, for a device written in Python. */
int rl1_ffi_post(rl1_vm *vm, uint8_t mode, uint8_t command)
{
    return rl1_post_line_lost(&vm->mailbox, mode, command);
}

/* rl1_abort, for a Python caller. */
void rl1_ffi_abort(rl1_vm *vm)
{
    rl1_abort(&vm->mailbox);
}
