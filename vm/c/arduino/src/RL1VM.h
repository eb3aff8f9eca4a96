/* RL1VM: the RL/I VM of vm/c (vm/c/README.md says how to embed it), as an Arduino
 * library. `#include <RL1VM.h>`, then use what rl1vm.h and rl1_hardware.h declare:
 * rl1_load, rl1_vm_init, rl1_step and the rl1_hardware callbacks. */
#ifndef RL1VM_ARDUINO_H
#define RL1VM_ARDUINO_H

#include "RL1VM_config.h"
#include "rl1vm.h"

#endif
