/* The .ilc loader and verifier (spec/ilc.md sections 2-8 and 10).
 *
 * It makes the checks of vm/ilc.py and vm/verifier.py in their order, so that a file
 * gets the same refusal at the same file offset from both: the container first (header,
 * sizes, CRC, flags, handlers, features, debug section), then one pass over the code
 * (each instruction's opcode, length, operands and feature), then every jump target,
 * handler entry and line entry against the instruction starts.
 *
 * Portability: `int` may be 16 bits (AVR). So no uint8_t or uint16_t is shifted or
 * added before it is widened to unsigned or uint32_t, signed values are never computed
 * by overflow, and there is no table in static data (on AVR it would be copied to RAM):
 * the instruction set is switch statements, which the compiler keeps in flash.
 */
#include "rl1vm.h"

#define BYTE(p) RL1_BYTE(p)

#define HEADER_SIZE 24u
#define HANDLER_SIZE 8u
#define FEATURE_SIZE 2u
#define DIGEST_SIZE 16u
#define DIGEST_MINOR 1u      /* the first minor version with a source digest */
#define FUSED_MINOR 2u       /* the superinstructions, MOVV ... SJLT and ADDVV ... SHRRI, came in 1.2 */
#define COMPACT_MINOR 3u     /* the compact calls, MVIS ... FZOS, came in 1.3 */
#define KNOWN_MINOR 3u       /* the newest minor version this reader knows */
#define REQUIRED_FLAGS 0x00FFu
#define VARIABLES 53u
#define MAX_U16 0xFFFFu

/* The file being checked, and where the refusal points. */
typedef struct loader {
    const uint8_t *file;
    uint32_t size;
    uint32_t error_offset;
} loader;

static rl1_refusal fail(loader *ld, rl1_refusal status, uint32_t offset)
{
    ld->error_offset = offset;
    return status;
}

static uint16_t u16_at(const uint8_t *p)
{
    return RL1_U16(p);
}

static uint32_t u32_at(const uint8_t *p)
{
    return (uint32_t)BYTE(p) | ((uint32_t)BYTE(p + 1) << 8)
           | ((uint32_t)BYTE(p + 2) << 16) | ((uint32_t)BYTE(p + 3) << 24);
}

/* An i16 operand's value; converting a u16 above 0x7FFF to int16_t would be
 * implementation-defined. */
static int16_t i16_at(const uint8_t *p)
{
    uint16_t u = u16_at(p);
    return u < 0x8000u ? (int16_t)u : (int16_t)((int32_t)u - (int32_t)0x10000L);
}

/* Moves *pos over a field of `length` bytes if the file holds it. *pos never passes
 * the file's size, so `size - *pos` cannot wrap and the sum cannot pass 32 bits. */
static bool advance(const loader *ld, uint32_t *pos, uint32_t length)
{
    if (length > ld->size - *pos) {
        return false;
    }
    *pos += length;
    return true;
}

/* CRC-32 (zlib's): bit by bit, since a 1 KiB table would cost RAM on AVR. */
static uint32_t crc_byte(uint32_t crc, uint8_t byte)
{
    uint8_t bit;
    crc ^= byte;
    for (bit = 0; bit < 8u; bit++) {
        crc = (crc & 1u) ? (crc >> 1) ^ UINT32_C(0xEDB88320) : crc >> 1;
    }
    return crc;
}

static uint32_t file_crc(const loader *ld)
{
    uint32_t crc = UINT32_C(0xFFFFFFFF);
    uint32_t i;
    for (i = 0; i < ld->size; i++) {
        /* The CRC field, bytes 8..11, counts as zero. */
        crc = crc_byte(crc, (i >= 8u && i < 12u) ? 0u : BYTE(ld->file + i));
    }
    return crc ^ UINT32_C(0xFFFFFFFF);
}

/* --- the instruction set (spec/ilc.md 8.3) ----------------------------------------- */

#define NONE RL1_SHAPE_NONE
#define VAR RL1_SHAPE_VAR
#define IMM RL1_SHAPE_IMM
#define ADDR RL1_SHAPE_ADDR
#define VAR_ADDR RL1_SHAPE_VAR_ADDR
#define VAR_VAR RL1_SHAPE_VAR_VAR
#define VAR_IMM RL1_SHAPE_VAR_IMM
#define ARGS RL1_SHAPE_ARGS

/* Four nibbles, the first lowest. */
#define FOUR(a, b, c, d) ((a) | (b) << 4 | (c) << 8 | (unsigned)(d) << 12)

/* The operands of `op`, and 0 bytes for an opcode the file's minor version does not
 * define (a superinstruction in a 1.0 or 1.1 file is unknown there). */
uint8_t rl1_op_length(uint8_t op, uint8_t minor, uint8_t *shape)
{
    uint8_t width = 2u; /* bytes a call's argument */
    *shape = NONE;
    if (minor >= FUSED_MINOR) {
        /* Four kinds in a row, their shapes and lengths a nibble each in a constant
         * (no table: on AVR it would be copied to RAM). MOVV, MOVI, MOVR, MOVB: */
        if (op >= RL1_OP_MOVV && op <= RL1_OP_MOVB) {
            unsigned nibble = 4u * (unsigned)(op - RL1_OP_MOVV);
            *shape = (uint8_t)(FOUR(VAR_VAR, VAR_IMM, VAR, VAR) >> nibble & 15u);
            return (uint8_t)(FOUR(3u, 4u, 2u, 3u) >> nibble & 15u);
        }
        if (op >= RL1_OP_DJGT && op <= RL1_OP_SJLT) {
            *shape = VAR_ADDR; /* DJGT, SJZ, SJGT, SJLT */
            return 4;
        }
        /* The load-and-operate blocks of 8, operator in the low 3 bits (7 is unused):
         * ADDVV ... SHRVV, ADDVI ... SHRVI, ADDRV ... SHRRV, ADDRI ... SHRRI. */
        if (op >= RL1_OP_ADDVV && op <= RL1_OP_SHRRI && (op & 7u) != 7u) {
            unsigned nibble = 4u * (op >> 3 & 3u);
            *shape = (uint8_t)(FOUR(VAR_VAR, VAR_IMM, VAR, IMM) >> nibble & 15u);
            return (uint8_t)(FOUR(3u, 4u, 2u, 3u) >> nibble & 15u);
        }
    }
    if (op == RL1_OP_END || op == RL1_OP_LDR || (op >= RL1_OP_ADDR && op <= RL1_OP_SHRR)) {
        return 1; /* END, LDR, the ...R arithmetic */
    }
    if ((op >= RL1_OP_LDV && op <= RL1_OP_DEC && op != RL1_OP_LDI)
        || (op >= RL1_OP_ADDV && op <= RL1_OP_SHRV)) {
        *shape = VAR; /* LDV, STV, INC, DEC, the ...V arithmetic */
        return 2;
    }
    if (op == RL1_OP_LDI || (op >= RL1_OP_ADDI && op <= RL1_OP_SHRI)) {
        *shape = IMM; /* LDI, the ...I arithmetic */
        return 3;
    }
    if (op == RL1_OP_JMP) {
        *shape = ADDR; /* JMP */
        return 3;
    }
    if (op >= RL1_OP_JZ && op <= RL1_OP_JLT) {
        *shape = VAR_ADDR; /* JZ, JGT, JLT */
        return 4;
    }
    if (minor >= COMPACT_MINOR && (op & RL1_COMPACT_CALL_BIT)) {
        op ^= RL1_COMPACT_CALL_BIT; /* a compact call (1.3): a byte an argument */
        width = 1u;
    }
    if (op >= RL1_OP_FIRST_CALL && op <= RL1_OP_LAST_CALL) {
        uint8_t arity = rl1_call_arity(op);
        *shape = arity ? ARGS : NONE;
        /* a compact call without arguments is no instruction (width - 1 bytes: 0) */
        return arity ? (uint8_t)(2u + (unsigned)width * arity) : (uint8_t)(width - 1u);
    }
    return 0;
}

/* The device feature a call needs (spec/ilc.md 4.3), as its bit; 0 for END, TIM and
 * the instructions that are not calls. */
static uint8_t op_feature(uint8_t op)
{
    switch (op) {
    case RL1_OP_FRE: case RL1_OP_HLD: case RL1_OP_MVI: case RL1_OP_MOV: case RL1_OP_ROT:
    case RL1_OP_TRC: case RL1_OP_KYC: case RL1_OP_KYO:
        return RL1_FEATURE_MOTION;
    case RL1_OP_ORG: case RL1_OP_STR: case RL1_OP_STL: case RL1_OP_STX:
        return RL1_FEATURE_STEERING;
    case RL1_OP_CAMZ: case RL1_OP_CAMU: case RL1_OP_CAMD: case RL1_OP_CAMA: case RL1_OP_CAMP:
    case RL1_OP_CAMR:
        return RL1_FEATURE_CAMERA;
    case RL1_OP_SCN: case RL1_OP_IMG: case RL1_OP_LMP:
        return RL1_FEATURE_VISION;
    case RL1_OP_ULTA: case RL1_OP_ULTB: case RL1_OP_ULTC: case RL1_OP_ULTD:
        return RL1_FEATURE_ULTRASONIC;
    case RL1_OP_INP: case RL1_OP_OUT:
        return RL1_FEATURE_IO;
    case RL1_OP_FZO: case RL1_OP_FZI:
        return RL1_FEATURE_FUZZY;
    default:
        return 0;
    }
}

/* Each call's descriptor and its parameters' ranges (rl1vm.h, generated from
 * vm/language.py): the one copy the loader and the VM share. */
const uint16_t rl1_call_descriptors[RL1_CALL_COUNT] RL1_IN_FLASH = RL1_CALL_DESCRIPTORS;
const rl1_param_range rl1_param_ranges[RL1_PARAM_COUNT] RL1_IN_FLASH = RL1_PARAM_RANGES;

/* Whether `value` lies in the range of parameter `index` of call `op`
 * (spec/language.md section 8). */
bool rl1_arg_in_range(uint8_t op, uint8_t index, int16_t value)
{
    return rl1_in_range(rl1_call_ranges(op, rl1_call_descriptor(op)) + index, value);
}

/* --- the container (spec/ilc.md sections 2-7) -------------------------------------- */

/* One number of the debug section (4.4): LEB128, at most 3 bytes, shortest form. */
static rl1_refusal leb128(loader *ld, uint32_t *pos, uint32_t end, uint32_t *value)
{
    uint32_t start = *pos;
    uint8_t n, byte;
    *value = 0;
    for (n = 0; n < 3u; n++) {
        if (*pos == end) {
            return fail(ld, RL1_DEBUG_CUT_OFF, *pos);
        }
        byte = BYTE(ld->file + (*pos)++);
        *value |= (uint32_t)(byte & 0x7Fu) << (7u * n);
        if (!(byte & 0x80u)) {
            /* A last byte of 0 after another byte: not the shortest form. */
            return (n > 0u && byte == 0u) ? fail(ld, RL1_DEBUG_NUMBER, start) : RL1_ACCEPTED;
        }
    }
    return fail(ld, RL1_DEBUG_NUMBER, start);
}

/* Strict UTF-8 (RFC 3629: no overlong form, no surrogate, nothing past U+10FFFF); the
 * offset of the first bad sequence's lead byte, as Python's decoder reports it. */
static rl1_refusal check_utf8(loader *ld, uint32_t pos, uint32_t end)
{
    while (pos < end) {
        uint8_t lead = BYTE(ld->file + pos);
        uint8_t low = 0x80u, high = 0xBFu; /* the second byte's range (Unicode table 3-7) */
        uint32_t length, i;
        if (lead < 0x80u) {
            pos++;
            continue;
        }
        if (lead >= 0xC2u && lead <= 0xDFu) {
            length = 2;
        } else if (lead >= 0xE0u && lead <= 0xEFu) {
            length = 3;
            low = lead == 0xE0u ? 0xA0u : 0x80u;
            high = lead == 0xEDu ? 0x9Fu : 0xBFu;
        } else if (lead >= 0xF0u && lead <= 0xF4u) {
            length = 4;
            low = lead == 0xF0u ? 0x90u : 0x80u;
            high = lead == 0xF4u ? 0x8Fu : 0xBFu;
        } else {
            return fail(ld, RL1_DEBUG_NAME_UTF8, pos);
        }
        if (length > end - pos) {
            return fail(ld, RL1_DEBUG_NAME_UTF8, pos);
        }
        for (i = 1; i < length; i++) {
            uint8_t byte = BYTE(ld->file + pos + i);
            if (byte < (i == 1u ? low : 0x80u) || byte > (i == 1u ? high : 0xBFu)) {
                return fail(ld, RL1_DEBUG_NAME_UTF8, pos);
            }
        }
        pos += length;
    }
    return RL1_ACCEPTED;
}

/* The debug section from `pos` to `end` (4.4). */
static rl1_refusal check_debug(loader *ld, rl1_program *program, uint32_t pos, uint32_t end)
{
    uint32_t offset = 0, line = 0, offset_delta, line_delta;
    uint16_t index, count;
    rl1_refusal status;
    /* The name's size byte is there: a debug section of size 0 is no debug section. */
    program->source_name_size = BYTE(ld->file + pos++);
    if (end - pos < program->source_name_size) {
        return fail(ld, RL1_DEBUG_CUT_OFF, pos);
    }
    status = check_utf8(ld, pos, pos + program->source_name_size);
    if (status != RL1_ACCEPTED) {
        return status;
    }
    program->source_name = ld->file + pos;
    pos += program->source_name_size;
    if (end - pos < 2u) {
        return fail(ld, RL1_DEBUG_CUT_OFF, pos);
    }
    count = u16_at(ld->file + pos);
    pos += 2;
    program->lines = ld->file + pos;
    program->line_count = count;
    for (index = 0; index < count; index++) {
        uint32_t start = pos;
        status = leb128(ld, &pos, end, &offset_delta);
        if (status == RL1_ACCEPTED) {
            status = leb128(ld, &pos, end, &line_delta);
        }
        if (status != RL1_ACCEPTED) {
            return status;
        }
        if (index > 0u && offset_delta == 0u) {
            return fail(ld, RL1_DEBUG_ORDER, start);
        }
        /* Both sums stay below 2^22: the previous values are u16, a delta below 2^21. */
        offset += offset_delta;
        line += line_delta;
        if (offset > MAX_U16 || line > MAX_U16 || line == 0u) {
            return fail(ld, RL1_DEBUG_RANGE, start);
        }
    }
    if (pos != end) {
        return fail(ld, RL1_DEBUG_LEFTOVER, pos);
    }
    return RL1_ACCEPTED;
}

/* The header and every section but the code's contents (sections 2-7, and the first
 * rows of section 10). Leaves in *code_start the code's file offset. */
static rl1_refusal check_container(loader *ld, rl1_program *program, uint32_t *code_start)
{
    const uint8_t *file = ld->file;
    uint32_t header_size, debug_size, pos, handler_start, debug_start, digest_size;
    uint8_t minor, i;
    bool newer;
    if (ld->size < 6u) {
        return fail(ld, RL1_TRUNCATED, ld->size);
    }
    if (BYTE(file) != 'R' || BYTE(file + 1) != 'L' || BYTE(file + 2) != 'I'
        || BYTE(file + 3) != 'C') {
        return fail(ld, RL1_BAD_MAGIC, 0);
    }
    if (BYTE(file + 4) != 1u) {
        return fail(ld, RL1_BAD_MAJOR, 4);
    }
    if (ld->size < HEADER_SIZE) {
        return fail(ld, RL1_TRUNCATED, ld->size);
    }
    minor = BYTE(file + 5);
    newer = minor > KNOWN_MINOR;
    header_size = u16_at(file + 12);
    if (header_size < HEADER_SIZE || (header_size != HEADER_SIZE && !newer)) {
        return fail(ld, RL1_BAD_HEADER_SIZE, 12);
    }
    if (u16_at(file + 16) != HANDLER_SIZE) {
        return fail(ld, RL1_BAD_SECTION_SIZE, 16);
    }
    if (u16_at(file + 18) != FEATURE_SIZE) {
        return fail(ld, RL1_BAD_SECTION_SIZE, 18);
    }
    program->code_size = u16_at(file + 14);
    debug_size = u32_at(file + 20);
    digest_size = (minor >= DIGEST_MINOR && debug_size != 0u) ? DIGEST_SIZE : 0u;
    /* header, code, handlers and features, debug, digest: each must fit what is left,
     * so that their sum, which can pass 32 bits, is never made unchecked. */
    pos = 0;
    if (!advance(ld, &pos, header_size) || !advance(ld, &pos, program->code_size)
        || !advance(ld, &pos, HANDLER_SIZE + FEATURE_SIZE)
        || !advance(ld, &pos, debug_size) || !advance(ld, &pos, digest_size)) {
        return fail(ld, RL1_TRUNCATED, ld->size);
    }
    if (pos < ld->size && !newer) {
        return fail(ld, RL1_EXTRA_BYTES, pos);
    }
    if (file_crc(ld) != u32_at(file + 8)) {
        return fail(ld, RL1_BAD_CRC, 8);
    }
    program->flags = u16_at(file + 6);
    program->minor = minor;
    if (program->flags & REQUIRED_FLAGS) { /* versions 1.0 and 1.1 define no flag */
        return fail(ld, RL1_REQUIRED_FLAG, 6);
    }
    *code_start = header_size;
    program->code = file + header_size;
    handler_start = header_size + program->code_size;
    for (i = 0; i < 4u; i++) {
        uint16_t entry = u16_at(file + handler_start + 2u * i);
        if (entry != RL1_ABSENT && entry >= program->code_size) {
            return fail(ld, RL1_HANDLER_OUTSIDE, handler_start + 2u * i);
        }
        program->handlers[i] = entry;
    }
    program->features = u16_at(file + handler_start + HANDLER_SIZE);
    if (program->features & ~(unsigned)RL1_FEATURES_KNOWN) {
        return fail(ld, RL1_UNKNOWN_FEATURE, handler_start + HANDLER_SIZE);
    }
    debug_start = handler_start + HANDLER_SIZE + FEATURE_SIZE;
    program->lines = NULL;
    program->source_name = NULL;
    program->source_name_size = 0;
    program->line_count = 0;
    program->digest = digest_size ? file + debug_start + debug_size : NULL;
    return debug_size ? check_debug(ld, program, debug_start, debug_start + debug_size)
                      : RL1_ACCEPTED;
}

/* --- the code (section 8 and the rest of section 10) -------------------------------- */

/* Where instructions start: the bitmap when there is one, else a walk from offset 0
 * over code already checked to be whole instructions. */
typedef struct starts {
    const rl1_program *program;
    uint8_t *bitmap; /* NULL: rescan */
} starts;

static bool starts_instruction(const starts *s, uint16_t target)
{
    uint32_t pos = 0;
    uint8_t shape;
    if (target >= s->program->code_size) {
        return false;
    }
    if (s->bitmap) {
        return ((unsigned)s->bitmap[target >> 3] >> (target & 7u)) & 1u;
    }
    while (pos < target) {
        pos += rl1_op_length(BYTE(s->program->code + pos), s->program->minor, &shape);
    }
    return pos == target;
}

static rl1_refusal check_variable(loader *ld, uint32_t index, uint32_t offset)
{
    return index < VARIABLES ? RL1_ACCEPTED : fail(ld, RL1_BAD_VARIABLE, offset);
}

/* A call's mask and arguments, `width` bytes each; `at` is the mask's file offset. */
static rl1_refusal check_call(loader *ld, uint8_t op, uint8_t width, uint32_t at)
{
    rl1_descriptor call = rl1_call_descriptor(op);
    uint8_t mask = BYTE(ld->file + at), arity = call & RL1_CALL_ARITY, k;
    const rl1_param_range *range = rl1_call_ranges(op, call);
    rl1_refusal status = RL1_ACCEPTED;
    if (mask >> arity) {
        return fail(ld, RL1_BAD_MASK, at);
    }
    for (k = 0; k < arity && status == RL1_ACCEPTED; k++) {
        uint32_t field = at + 1u + (uint32_t)width * k;
        int16_t value = width == 1u ? (int8_t)BYTE(ld->file + field)
                                    : i16_at(ld->file + field);
        if (((unsigned)mask >> k) & 1u) {
            status = check_variable(ld, (uint16_t)value, field);
        } else if (!rl1_in_range(range + k, value)) {
            status = fail(ld, RL1_ARGUMENT_RANGE, field);
        }
    }
    return status;
}

/* Pass 1: every instruction whole, known, with valid operands and its feature listed;
 * marks the instruction starts in the bitmap. */
static rl1_refusal check_instructions(loader *ld, const rl1_program *program, uint32_t base,
                                     uint8_t *bitmap)
{
    uint32_t pos = 0;
    while (pos < program->code_size) {
        uint8_t op = BYTE(program->code + pos), length, feature;
        uint32_t at = base + pos;
        uint8_t shape, width;
        rl1_refusal status = RL1_ACCEPTED;
        length = rl1_op_length(op, program->minor, &shape);
        if (length == 0u) {
            return fail(ld, RL1_UNKNOWN_OPCODE, at);
        }
        if (length > program->code_size - pos) {
            return fail(ld, RL1_CUT_OFF, at);
        }
        /* a compact call (the only opcodes from RL1_COMPACT_CALL_BIT, the high bit): its
         * call's, with a byte an argument */
        width = (uint8_t)(2u - (op >> 7));
        op &= (uint8_t)~RL1_COMPACT_CALL_BIT;
        if (shape == VAR || shape == VAR_ADDR || shape == VAR_VAR || shape == VAR_IMM) {
            status = check_variable(ld, BYTE(ld->file + at + 1u), at + 1u);
        }
        if (status == RL1_ACCEPTED && shape == VAR_VAR) {
            status = check_variable(ld, BYTE(ld->file + at + 2u), at + 2u);
        } else if (shape == ARGS) {
            status = check_call(ld, op, width, at + 1u);
        }
        if (status != RL1_ACCEPTED) {
            return status;
        }
        feature = op_feature(op);
        if (feature & ~(unsigned)program->features) {
            return fail(ld, RL1_MISSING_FEATURE, at);
        }
        if (bitmap) {
            bitmap[pos >> 3] = (uint8_t)(bitmap[pos >> 3] | (1u << (pos & 7u)));
        }
        pos += length;
    }
    return RL1_ACCEPTED;
}

/* Pass 2: jump targets, in code order, then handler entries, then line entries. */
static rl1_refusal check_targets(loader *ld, const rl1_program *program, uint32_t base,
                                const starts *s)
{
    uint32_t pos = 0, at, entry, offset = 0, delta;
    uint16_t index;
    uint8_t i;
    while (pos < program->code_size) {
        uint8_t shape;
        uint8_t length = rl1_op_length(BYTE(program->code + pos), program->minor, &shape);
        at = base + pos + (shape == VAR_ADDR ? 2u : 1u); /* the target operand */
        if ((shape == ADDR || shape == VAR_ADDR)
            && !starts_instruction(s, u16_at(ld->file + at))) {
            return fail(ld, RL1_BAD_JUMP, at);
        }
        pos += length;
    }
    for (i = 0; i < 4u; i++) {
        if (program->handlers[i] != RL1_ABSENT
            && !starts_instruction(s, program->handlers[i])) {
            return fail(ld, RL1_BAD_HANDLER, base + program->code_size + 2u * i);
        }
    }
    if (!program->lines) {
        return RL1_ACCEPTED;
    }
    entry = (uint32_t)(program->lines - ld->file);
    for (index = 0; index < program->line_count; index++) {
        at = entry;
        /* The section is checked: these reads cannot fail. */
        (void)leb128(ld, &entry, ld->size, &delta);
        offset += delta;
        (void)leb128(ld, &entry, ld->size, &delta);
        if (!starts_instruction(s, (uint16_t)offset)) {
            return fail(ld, RL1_BAD_LINE_ENTRY, at);
        }
    }
    return RL1_ACCEPTED;
}

rl1_refusal rl1_load(rl1_program *program, const uint8_t *file, uint32_t size,
                    uint8_t *bitmap, size_t bitmap_size, uint32_t *error_offset)
{
    loader ld;
    starts s;
    uint32_t base = 0, i;
    rl1_refusal status;
    ld.file = file;
    ld.size = size;
    ld.error_offset = 0;
    status = check_container(&ld, program, &base);
    if (status == RL1_ACCEPTED) {
        s.program = program;
        s.bitmap = (bitmap && bitmap_size >= RL1_BITMAP_SIZE(program->code_size)) ? bitmap
                                                                                  : NULL;
        for (i = 0; s.bitmap && i < RL1_BITMAP_SIZE(program->code_size); i++) {
            s.bitmap[i] = 0;
        }
        status = check_instructions(&ld, program, base, s.bitmap);
    }
    if (status == RL1_ACCEPTED) {
        status = check_targets(&ld, program, base, &s);
    }
    *error_offset = ld.error_offset;
    return status;
}

uint16_t rl1_line_at(const rl1_program *program, uint16_t code_offset)
{
    loader ld;
    uint32_t pos = 0, offset = 0, line = 0, delta;
    uint16_t index, found = 0;
    if (!program->lines) {
        return 0;
    }
    /* Reads the verified line map from its first entry; it cannot run past it. */
    ld.file = program->lines;
    ld.size = UINT32_C(0xFFFFFFFF);
    for (index = 0; index < program->line_count; index++) {
        (void)leb128(&ld, &pos, ld.size, &delta);
        offset += delta;
        (void)leb128(&ld, &pos, ld.size, &delta);
        line += delta;
        if (offset > code_offset) {
            break;
        }
        found = (uint16_t)line;
    }
    return found;
}
