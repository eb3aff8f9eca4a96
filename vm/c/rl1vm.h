/* rl1vm: the RL/I virtual machine for firmware, in C99 (freestanding).
 *
 * This header and spec/rl1_hardware.h (which it includes: put both folders on the
 * include path) are the whole public interface: the loader and verifier
 * (rl1vm_load.c), every check of spec/ilc.md section 10 made on the file in place (in
 * flash, say) before any of it runs, with the debug line lookup for fault reports; and
 * the VM (rl1vm.c), which steps a verified program (spec/ilc.md section 12) and drives
 * the vehicle through the callbacks of rl1_hardware.h.
 *
 * No allocation, no recursion, no floating point, no static data but constant tables
 * in flash (the calls' descriptors, and the threaded dispatch's in builds for speed:
 * rl1vm.c): all state is in the caller's rl1_program and rl1_vm. Sizes are u32 and
 * every sum of them is checked before it is made, so no file, however damaged, makes the
 * loader read outside it.
 */
#ifndef RL1VM_H
#define RL1VM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rl1_hardware.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Generated from vm/isa.py by `python -m rl1.vm.isa_table --c`: do not edit */

/* The opcodes of spec/ilc.md 8.3. The built-in calls, which the callbacks are
   given, run from RL1_OP_FRE to RL1_OP_FZI: one for each form. */
typedef enum rl1_opcode {
    RL1_OP_END = 0x00,
    RL1_OP_LDV = 0x01,
    RL1_OP_LDI = 0x02,
    RL1_OP_LDR = 0x03,
    RL1_OP_STV = 0x04,
    RL1_OP_INC = 0x05,
    RL1_OP_DEC = 0x06,
    RL1_OP_MOVV = 0x07,
    RL1_OP_MOVI = 0x08,
    RL1_OP_MOVR = 0x09,
    RL1_OP_MOVB = 0x0A,
    RL1_OP_ADDV = 0x10,
    RL1_OP_SUBV = 0x11,
    RL1_OP_ANDV = 0x12,
    RL1_OP_ORV = 0x13,
    RL1_OP_XORV = 0x14,
    RL1_OP_SHLV = 0x15,
    RL1_OP_SHRV = 0x16,
    RL1_OP_ADDI = 0x18,
    RL1_OP_SUBI = 0x19,
    RL1_OP_ANDI = 0x1A,
    RL1_OP_ORI = 0x1B,
    RL1_OP_XORI = 0x1C,
    RL1_OP_SHLI = 0x1D,
    RL1_OP_SHRI = 0x1E,
    RL1_OP_ADDR = 0x20,
    RL1_OP_SUBR = 0x21,
    RL1_OP_ANDR = 0x22,
    RL1_OP_ORR = 0x23,
    RL1_OP_XORR = 0x24,
    RL1_OP_SHLR = 0x25,
    RL1_OP_SHRR = 0x26,
    RL1_OP_JMP = 0x30,
    RL1_OP_JZ = 0x31,
    RL1_OP_JGT = 0x32,
    RL1_OP_JLT = 0x33,
    RL1_OP_DJGT = 0x34,
    RL1_OP_SJZ = 0x35,
    RL1_OP_SJGT = 0x36,
    RL1_OP_SJLT = 0x37,
    RL1_OP_FRE = 0x40,
    RL1_OP_HLD = 0x41,
    RL1_OP_ORG = 0x42,
    RL1_OP_MVI = 0x43,
    RL1_OP_MOV = 0x44,
    RL1_OP_STR = 0x45,
    RL1_OP_STL = 0x46,
    RL1_OP_STX = 0x47,
    RL1_OP_ROT = 0x48,
    RL1_OP_TRC = 0x49,
    RL1_OP_TIM = 0x4A,
    RL1_OP_KYC = 0x4B,
    RL1_OP_KYO = 0x4C,
    RL1_OP_SCN = 0x4D,
    RL1_OP_IMG = 0x4E,
    RL1_OP_CAMZ = 0x4F,
    RL1_OP_CAMU = 0x50,
    RL1_OP_CAMD = 0x51,
    RL1_OP_CAMA = 0x52,
    RL1_OP_CAMP = 0x53,
    RL1_OP_CAMR = 0x54,
    RL1_OP_ULTA = 0x55,
    RL1_OP_ULTB = 0x56,
    RL1_OP_ULTC = 0x57,
    RL1_OP_ULTD = 0x58,
    RL1_OP_LMP = 0x59,
    RL1_OP_INP = 0x5A,
    RL1_OP_OUT = 0x5B,
    RL1_OP_FZO = 0x5C,
    RL1_OP_FZI = 0x5D,
    RL1_OP_ADDVV = 0x60,
    RL1_OP_SUBVV = 0x61,
    RL1_OP_ANDVV = 0x62,
    RL1_OP_ORVV = 0x63,
    RL1_OP_XORVV = 0x64,
    RL1_OP_SHLVV = 0x65,
    RL1_OP_SHRVV = 0x66,
    RL1_OP_ADDVI = 0x68,
    RL1_OP_SUBVI = 0x69,
    RL1_OP_ANDVI = 0x6A,
    RL1_OP_ORVI = 0x6B,
    RL1_OP_XORVI = 0x6C,
    RL1_OP_SHLVI = 0x6D,
    RL1_OP_SHRVI = 0x6E,
    RL1_OP_ADDRV = 0x70,
    RL1_OP_SUBRV = 0x71,
    RL1_OP_ANDRV = 0x72,
    RL1_OP_ORRV = 0x73,
    RL1_OP_XORRV = 0x74,
    RL1_OP_SHLRV = 0x75,
    RL1_OP_SHRRV = 0x76,
    RL1_OP_ADDRI = 0x78,
    RL1_OP_SUBRI = 0x79,
    RL1_OP_ANDRI = 0x7A,
    RL1_OP_ORRI = 0x7B,
    RL1_OP_XORRI = 0x7C,
    RL1_OP_SHLRI = 0x7D,
    RL1_OP_SHRRI = 0x7E,
    RL1_OP_MVIS = 0xC3,
    RL1_OP_MOVS = 0xC4,
    RL1_OP_STRS = 0xC5,
    RL1_OP_STLS = 0xC6,
    RL1_OP_STXS = 0xC7,
    RL1_OP_ROTS = 0xC8,
    RL1_OP_TRCS = 0xC9,
    RL1_OP_TIMS = 0xCA,
    RL1_OP_SCNS = 0xCD,
    RL1_OP_CAMAS = 0xD2,
    RL1_OP_CAMPS = 0xD3,
    RL1_OP_LMPS = 0xD9,
    RL1_OP_INPS = 0xDA,
    RL1_OP_OUTS = 0xDB,
    RL1_OP_FZOS = 0xDC,
    RL1_OP_FIRST_CALL = 0x40,
    RL1_OP_LAST_CALL = 0x5D
} rl1_opcode;

/* A compact call (format 1.3, a byte an argument) is its call's opcode with this bit. */
#define RL1_COMPACT_CALL_BIT 0x80u

/* The device features (spec/ilc.md 4.3): bits of rl1_program's `features`. */
typedef enum rl1_feature {
    RL1_FEATURE_MOTION = 0x01,
    RL1_FEATURE_STEERING = 0x02,
    RL1_FEATURE_CAMERA = 0x04,
    RL1_FEATURE_VISION = 0x08,
    RL1_FEATURE_ULTRASONIC = 0x10,
    RL1_FEATURE_IO = 0x20,
    RL1_FEATURE_FUZZY = 0x40,
    RL1_FEATURES_KNOWN = 0x7F  /* every feature this format defines */
} rl1_feature;

/* Each call's descriptor (spec/ilc.md 8.3 and 12), from vm/language.py: for each
   call from RL1_OP_FIRST_CALL, a u16 in RL1_CALL_DESCRIPTORS of the bits below and,
   in its high byte (RL1_CALL_FIRST_SHIFT), for a call with arguments the index in
   RL1_PARAM_RANGES of its first parameter's range (low, and the span to high:
   rl1_param_range), the others' following it; for one that writes reserved
   variables (none takes arguments), the first of them, the others following it. */
#define RL1_CALL_ARITY 0x03u       /* how many arguments it takes, 0 to 3 */
#define RL1_CALL_STARTED 0x04u     /* it takes device time: started, then polled */
#define RL1_CALL_SETS_R 0x08u      /* its result goes into R */
#define RL1_CALL_PAIRS 0x30u       /* how many pairs of reserved variables it writes,
                                      from rl1_reading's writes */
#define RL1_CALL_PAIRS_SHIFT 4u
#define RL1_CALL_RESULT 0xC0u      /* its result's range: 0 for any, else
                                      0 .. RL1_RESULT_HIGH of it */
#define RL1_CALL_RESULT_SHIFT 6u
#define RL1_CALL_FIRST_SHIFT 8u    /* the high byte: where its ranges or writes start */
#define RL1_RESULT_HIGH(kind) ((kind) == 1u ? 784 : 255)
#define RL1_CALL_COUNT 30
#define RL1_CALL_DESCRIPTORS \
    {0x0000u, 0x0000u, 0x0004u, 0x0007u, 0x0302u, 0x0505u, 0x0605u, 0x0705u, \
     0x0805u, 0x0901u, 0x0A05u, 0x0B00u, 0x2E18u, 0x0B01u, 0x302Cu, 0x0C04u, \
     0x0C04u, 0x0C04u, 0x0C05u, 0x0D05u, 0x0E4Cu, 0x0E0Cu, 0x0E0Cu, 0x0E0Cu, \
     0x0E0Cu, 0x0E01u, 0x0F89u, 0x1002u, 0x1202u, 0x2C10u}
#define RL1_PARAM_COUNT 20
#define RL1_PARAM_RANGES \
    {{-12, 24u}, {-12, 24u}, {-1900, 3800u}, {-12, 24u}, {-12, 24u}, {0, 180u}, \
     {0, 180u}, {-1800, 3600u}, {-360, 720u}, {0, 3u}, {1, 99u}, {0, 7u}, {0, 180u}, \
     {0, 784u}, {0, 1u}, {0, 125u}, {0, 125u}, {0, 255u}, {INT16_MIN, 65535u}, \
     {INT16_MIN, 65535u}}

/* ---- End of the generated constants ---- */

/* Why a file is refused: one code per rule of spec/ilc.md section 10, in the order the
 * rules are checked. vm/ilc.py's Refusal has the same names and numbers (a test holds
 * them equal). The comment says where the error offset points. */
typedef enum rl1_refusal {
    RL1_ACCEPTED = 0,
    RL1_TRUNCATED = 1,          /* the header or a section passes the file's end: the end */
    RL1_BAD_MAGIC = 2,          /* 0 */
    RL1_BAD_MAJOR = 3,          /* 4: a major version other than 1 */
    RL1_BAD_HEADER_SIZE = 4,    /* 12 */
    RL1_BAD_SECTION_SIZE = 5,   /* 16 or 18: handler table not 8, features not 2 */
    RL1_EXTRA_BYTES = 6,        /* the first byte after the last section */
    RL1_BAD_CRC = 7,            /* 8 */
    RL1_REQUIRED_FLAG = 8,      /* 6: a required flag bit this reader does not know */
    RL1_HANDLER_OUTSIDE = 9,    /* the handler entry: not 0xFFFF and not below code_size */
    RL1_UNKNOWN_FEATURE = 10,   /* the features section */
    RL1_DEBUG_CUT_OFF = 11,     /* the debug field that passes the section's end */
    RL1_DEBUG_NAME_UTF8 = 12,   /* the first byte of the name's first bad sequence */
    RL1_DEBUG_NUMBER = 13,      /* a LEB128 number longer than 3 bytes or not shortest */
    RL1_DEBUG_ORDER = 14,       /* the line entry: its offset does not increase */
    RL1_DEBUG_RANGE = 15,       /* the line entry: offset past u16, line not 1..65535 */
    RL1_DEBUG_LEFTOVER = 16,    /* the first byte after the last line entry */
    RL1_UNKNOWN_OPCODE = 17,    /* the opcode */
    RL1_CUT_OFF = 18,           /* the opcode of an instruction the code's end cuts */
    RL1_BAD_VARIABLE = 19,      /* the operand: a variable index above 52 */
    RL1_BAD_MASK = 20,          /* the mask: a bit at or above the call's arity */
    RL1_ARGUMENT_RANGE = 21,    /* the argument: a constant outside its parameter's range */
    RL1_MISSING_FEATURE = 22,   /* the opcode: a call whose feature the header omits */
    RL1_BAD_JUMP = 23,          /* the target operand: not the start of an instruction */
    RL1_BAD_HANDLER = 24,       /* the handler entry: not the start of an instruction */
    RL1_BAD_LINE_ENTRY = 25     /* the line entry: not the start of an instruction */
} rl1_refusal;

/* A verified file, its sections found: everything the VM needs, pointing into the
 * caller's file (which must stay in place while the program is used). */
struct rl1_program {  /* rl1_hardware.h names it rl1_program */
    const uint8_t *code;        /* the code section */
    const uint8_t *lines;       /* the first line entry; NULL without a debug section */
    const uint8_t *source_name; /* UTF-8, not NUL-terminated; NULL without debug */
    const uint8_t *digest;      /* the 16-byte source digest (1.1+); NULL when absent */
    uint16_t code_size;
    uint16_t handlers[4];       /* code offsets of :96..:99; RL1_ABSENT when undefined */
    uint16_t features;          /* bit n: the program needs device feature n */
    uint16_t flags;
    uint16_t line_count;
    uint8_t source_name_size;
    uint8_t minor;              /* the format's minor version the file says */
};

#define RL1_ABSENT 0xFFFFu     /* a handler table entry for a label not defined */

/* The bytes of a jump-target bitmap for code of `code_size` bytes: one bit per code
 * byte, so at most 8192 bytes for the largest code (65535 bytes). */
#define RL1_BITMAP_SIZE(code_size) (((uint32_t)(code_size) + 7u) / 8u)

/* Checks the `size` bytes at `file` (spec/ilc.md section 10) and, when they pass, fills
 * *program. On a refusal returns its code, with the file offset it points at in
 * *error_offset (*program is then undefined).
 *
 * Jump targets, handler entries and line entries must start instructions. With a
 * `bitmap` of at least RL1_BITMAP_SIZE(code_size) bytes (scratch: the loader clears it,
 * and it is free again on return), each such check is one bit, so loading is linear in
 * the file's size. With a smaller one, or NULL, the loader uses no memory for it and
 * rescans the code from its start for each target instead: at most code_size bytes of
 * decoding per jump, handler and line entry (quadratic in the worst case: keep it for
 * small programs or for targets with no RAM to spare). Both give the same answer. */
rl1_refusal rl1_load(rl1_program *program, const uint8_t *file, uint32_t size,
                    uint8_t *bitmap, size_t bitmap_size, uint32_t *error_offset);

/* The source line of the instruction at `code_offset`: the line of the last line entry
 * at or before it (spec/ilc.md 4.4); 0 when unknown (no debug section, or no entry at or
 * before it). It walks the line map, so it costs one pass over it: for fault reports. */
uint16_t rl1_line_at(const rl1_program *program, uint16_t code_offset);

/* Makes `vm` ready for a run with the watchdog `budget` (spec/ilc.md 12.6): every other
 * field zero. Then call rl1_step with the program (loaded by rl1_load) and the hardware
 * until it answers RL1_ENDED or RL1_FAULTED; the device posts lost lines into
 * vm->mailbox with rl1_post_line_lost.
 *
 * Every u32 budget works as in the reference VM (`rl1c run --budget` takes 1 .. 2^31 -
 * 1): the run faults at its first jump or call with more than `budget` instructions run.
 * vm->executed stops at 2^32 - 1 rather than wrap, so a budget near 2^32 is met all the
 * same (the count then reads 2^32 - 1 where the reference VM's goes on). A run that
 * never ends is given more by setting vm->executed back between steps (vm/c/README.md,
 * "Run control"): the budget cannot switch the watchdog off. */
void rl1_vm_init(rl1_vm *vm, uint32_t budget);

/* --- Internal: the instruction set, shared by the loader and the VM ----------------- */

/* How a byte of the file is read: a plain load, unless the build says otherwise. AVR's
 * flash is not in its data address space, so a file kept there (rl1c --emit c
 * --progmem) is read with -DRL1_READ_BYTE(p)=pgm_read_byte(p) -include avr/pgmspace.h
 * (vm/c/README.md). */
#ifndef RL1_READ_BYTE
#define RL1_READ_BYTE(p) (*(p))
#endif
#define RL1_BYTE(p) ((uint8_t)RL1_READ_BYTE(p))
#define RL1_U16(p) ((uint16_t)(RL1_BYTE(p) | ((unsigned)RL1_BYTE((p) + 1) << 8)))

/* The operand shapes of rl1_op_length. */
#define RL1_SHAPE_NONE 0u
#define RL1_SHAPE_VAR 1u      /* v */
#define RL1_SHAPE_IMM 2u      /* i */
#define RL1_SHAPE_ADDR 3u     /* a */
#define RL1_SHAPE_VAR_ADDR 4u /* v, a */
#define RL1_SHAPE_VAR_VAR 5u  /* v, v */
#define RL1_SHAPE_VAR_IMM 6u  /* v, i */
#define RL1_SHAPE_ARGS 7u     /* mask, then 2 bytes an argument */

/* The length of instruction `op` in a file of format minor version `minor`, and its
 * operands' shape; 0 for an opcode unknown in that version. */
uint8_t rl1_op_length(uint8_t op, uint8_t minor, uint8_t *shape);

/* The calls' descriptors and their parameters' ranges (the generated RL1_CALL_DESCRIPTORS
 * and RL1_PARAM_RANGES), defined once in rl1vm_load.c. Constant
 * data: in flash on every target, on AVR in program memory (a table there would
 * otherwise be copied to RAM at start-up), so read only through the functions below. */
#if defined(__AVR__)
#define RL1_IN_FLASH __attribute__((__progmem__))
static inline uint8_t rl1_flash_byte(const uint8_t *p)
{
    uint8_t byte;
    __asm__("lpm %0, Z" : "=r"(byte) : "z"(p));
    return byte;
}
static inline uint16_t rl1_flash_u16(const uint16_t *p) /* AVR is little-endian */
{
    uint16_t word; /* the low byte, then the high one, Z moving on between them */
    __asm__("lpm %A0, Z+\n\tlpm %B0, Z" : "=r"(word), "+z"(p));
    return word;
}
static inline int16_t rl1_flash_i16(const int16_t *p)
{
    return (int16_t)rl1_flash_u16((const uint16_t *)p);
}
#else
#define RL1_IN_FLASH
static inline uint8_t rl1_flash_byte(const uint8_t *p)
{
    return *p;
}
static inline uint16_t rl1_flash_u16(const uint16_t *p)
{
    return *p;
}
static inline int16_t rl1_flash_i16(const int16_t *p)
{
    return *p;
}
#endif

/* A parameter's range: low to low + span. The span, not the high end, so that a value is
 * checked with one comparison (rl1_in_range). */
typedef struct {
    int16_t low;
    uint16_t span;
} rl1_param_range;

extern const uint16_t rl1_call_descriptors[RL1_CALL_COUNT];
extern const rl1_param_range rl1_param_ranges[RL1_PARAM_COUNT];

/* A call's descriptor as the VM holds it while the call runs, and where its parameters'
 * ranges or its written variables start (its high byte, RL1_CALL_FIRST_SHIFT), from the
 * call's opcode `op` (RL1_OP_FRE..RL1_OP_FZI) and that descriptor. A 32-bit target holds
 * the whole u16, one load for both; AVR holds the low byte alone, and reads the high
 * one from flash when it needs it (a u16 held across the callbacks costs it more:
 * vm/c/README.md, "What a call costs"). */
#if defined(__AVR__)
typedef uint8_t rl1_descriptor;
static inline rl1_descriptor rl1_call_descriptor(uint8_t op)
{
    return rl1_flash_byte((const uint8_t *)&rl1_call_descriptors[op - RL1_OP_FIRST_CALL]);
}
static inline uint8_t rl1_call_first(uint8_t op, rl1_descriptor call)
{
    (void)call; /* AVR is little-endian: the high byte is the second */
    return rl1_flash_byte((const uint8_t *)&rl1_call_descriptors[op - RL1_OP_FIRST_CALL] + 1);
}
#else
typedef uint16_t rl1_descriptor;
static inline rl1_descriptor rl1_call_descriptor(uint8_t op)
{
    return rl1_flash_u16(&rl1_call_descriptors[op - RL1_OP_FIRST_CALL]);
}
static inline uint8_t rl1_call_first(uint8_t op, rl1_descriptor call)
{
    (void)op;
    return (uint8_t)(call >> RL1_CALL_FIRST_SHIFT);
}
#endif

/* How many arguments call `op` takes, 0 to 3. */
static inline uint8_t rl1_call_arity(uint8_t op)
{
    return (uint8_t)(rl1_call_descriptor(op) & RL1_CALL_ARITY);
}

/* The ranges of call `op`'s parameters (descriptor `call`), from the first's. */
static inline const rl1_param_range *rl1_call_ranges(uint8_t op, rl1_descriptor call)
{
    return &rl1_param_ranges[rl1_call_first(op, call)];
}

/* Whether `value` lies in `range`, in one comparison: value - low, as unsigned, is at
 * most the span exactly when low <= value <= low + span, whether int has 16 bits or
 * more. Below low the difference wraps past every span: with an unsigned of N >= 32
 * bits to at least 2^N - 65535; of 16 bits to 65536 + value - low, which is above the
 * span (high - low) since value > high - 65536. */
#if defined(__GNUC__) && (defined(__ARM_FEATURE_UNALIGNED) || defined(__x86_64__)) \
    && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
/* Where a word loads from any even address, little-endian (Cortex-M3 and M4, x86-64),
 * the range is one word, span << 16 | low's 16 bits: one load where the halves take two,
 * and one Cortex-M3 comparison with a shifted operand (a variable argument 1 instruction
 * fewer). (value - word) << 16 holds value - low modulo 2^16 in its high half and zeros
 * below, so it is at most the word, whose low half is below 2^16, exactly when that
 * difference is at most the span: exact as with a 16-bit unsigned above. */
static inline bool rl1_in_range(const rl1_param_range *range, int16_t value)
{
    uint32_t word;
    __builtin_memcpy(&word, range, sizeof word);
    return (uint32_t)(((uint32_t)(int32_t)value - word) << 16) <= word;
}
#else
static inline bool rl1_in_range(const rl1_param_range *range, int16_t value)
{
    return (unsigned)value - (unsigned)rl1_flash_i16(&range->low)
           <= rl1_flash_u16(&range->span);
}
#endif

/* The length of a call with `arity` arguments: the opcode alone, or the opcode, the
 * mask and two bytes an argument. */
static inline uint8_t rl1_call_length(uint8_t arity)
{
    return arity ? (uint8_t)(2u + 2u * arity) : 1u;
}

/* Whether `value` lies in the range of parameter `index` of call `op`. */
bool rl1_arg_in_range(uint8_t op, uint8_t index, int16_t value);

#ifdef __cplusplus
}
#endif

#endif
