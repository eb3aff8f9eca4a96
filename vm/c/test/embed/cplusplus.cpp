// The VM embedded in C++: rl1vm.h and rl1_hardware.h declare the C functions in
// extern "C", so this file links with rl1vm.c and rl1vm_load.c compiled as C, and with
// a program written by rl1c --emit c (whose two definitions are C too). It runs the
// program to its end and prints what the vehicle was told and the variables it set;
// tests/c/test_embedding.py builds it with g++ and checks the output.
#include <cstdio>

#include "rl1vm.h"

extern "C" const uint8_t program_ilc[];
extern "C" const uint32_t program_ilc_size;

namespace {

struct Vehicle {
    int calls = 0;
    int16_t left = 0, right = 0;
};

rl1_status begin(void *) { return RL1_OK; }

rl1_status call(void *ctx, uint8_t opcode, const int16_t *args, rl1_reading *out)
{
    Vehicle &vehicle = *static_cast<Vehicle *>(ctx);
    vehicle.calls++;
    switch (opcode) {
    case RL1_OP_MOV:
        vehicle.left = args[0];
        vehicle.right = args[1];
        return RL1_OK;
    case RL1_OP_INP:
        out->result = static_cast<int16_t>(args[0] * 10);
        return RL1_OK;
    default:
        return RL1_ERROR;
    }
}

rl1_status start(void *, uint8_t, const int16_t *) { return RL1_ERROR; }
rl1_status poll(void *, rl1_reading *) { return RL1_ERROR; }
rl1_status stop(void *) { return RL1_OK; }
rl1_status end(void *) { return RL1_OK; }

}  // namespace

int main()
{
    rl1_program program;
    uint32_t where = 0;
    rl1_refusal refusal = rl1_load(&program, program_ilc, program_ilc_size, nullptr, 0,
                                   &where);
    if (refusal != RL1_ACCEPTED) {
        std::printf("refused %d at %lu\n", static_cast<int>(refusal),
                    static_cast<unsigned long>(where));
        return 1;
    }
    Vehicle vehicle;
    const rl1_hardware hardware = {&vehicle, begin, call, start, poll, stop, end};
    rl1_vm vm;
    rl1_vm_init(&vm, 1000);
    rl1_state state;
    do {
        state = rl1_step(&vm, &program, &hardware, 3);
    } while (state == RL1_RUNNING || state == RL1_WAITING);
    std::printf("state %d fault %d, %d calls, MOV %d %d, A=%d B=%d C=%d\n",
                static_cast<int>(state), static_cast<int>(vm.fault), vehicle.calls,
                vehicle.left, vehicle.right, vm.V[0], vm.V[1], vm.V[2]);
    return 0;
}
