/* How the library builds the VM on each board, since an Arduino library cannot give the
 * compiler flags of vm/c/README.md: every file of the library includes this first.
 *
 * On AVR, flash is not in the data address space: the .ilc file is a PROGMEM array
 * (rl1c --emit c --progmem) within the first 64 KiB of flash, and every byte of it is
 * read with pgm_read_byte. The switches must not become lookup tables, which avr-gcc
 * would put in .rodata and so in RAM (-fno-tree-switch-conversion). On the other
 * boards flash is memory-mapped: a plain load reads it. */
#ifndef RL1VM_CONFIG_H
#define RL1VM_CONFIG_H

#if defined(__AVR__)
#include <avr/pgmspace.h>
#define RL1_READ_BYTE(p) pgm_read_byte(p)
#pragma GCC optimize("no-tree-switch-conversion")
#endif

#endif
