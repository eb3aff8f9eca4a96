/* Not part of the VM: a symbol as large as the VM's state struct, whose size
 * bench/c_size.py reads from the object's symbol table for each target. */
#include "../rl1vm.h"

extern char rl1_vm_size_probe[sizeof(rl1_vm)];
char rl1_vm_size_probe[sizeof(rl1_vm)];
