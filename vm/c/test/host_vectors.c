/* The host runner of the conformance vectors (make -C vm/c test): reads the text form of
 * spec/vectors (*.txt; spec/vectors/README.md), runs every run vector, both its files,
 * in four ways (one step or steps of 1, 3 and 7 instructions, waiting built-ins
 * answering busy 0 to 2 times first) and checks the verifier's files with and without a
 * bitmap. Prints what differs; exits 1 if anything does. With --once, each vector's
 * `ilc` file runs once, in one step (bench/c_speed.py measures that).
 *     host-vectors [--once] spec/vectors/GROUP.txt ... */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vector.h"

static const char *const CALLS[] = {
    "FRE", "HLD", "ORG", "MVI", "MOV", "STR", "STL", "STX", "ROT", "TRC", "TIM", "KYC",
    "KYO", "SCN", "IMG", "CAM_Z", "CAM_U", "CAM_D", "CAM_A", "CAM_P", "CAM_R", "ULT_A",
    "ULT_B", "ULT_C", "ULT_D", "LMP", "INP", "OUT", "FZO", "FZI"};

static const struct way { uint32_t slice; uint8_t busy_polls; } WAYS[] = {
    {0xFFFFFFFFu, 0}, {1, 0}, {3, 1}, {7, 2}};

static uint8_t bitmap[RL1_BITMAP_SIZE(0xFFFFu)];

void harness_read(void *to, const void *from, size_t size)
{
    memcpy(to, from, size);
}

void harness_print(const char *text)
{
    fputs(text, stdout);
}

void harness_stack_paint(void)
{
}

uint32_t harness_stack_depth(void)
{
    return 0; /* measured on the emulated targets */
}

static void fail_input(const char *path, unsigned line, const char *why)
{
    fprintf(stderr, "%s:%u: %s\n", path, line, why);
    exit(2);
}

/* The opcode of a call's trace name, TRACE_LINE_LOST, TRACE_STOP; 0 if none. */
static uint16_t call_of(const char *name)
{
    uint16_t i;
    for (i = 0; i < sizeof CALLS / sizeof *CALLS; i++) {
        if (strcmp(name, CALLS[i]) == 0) {
            return (uint16_t)(0x40u + i);
        }
    }
    return strcmp(name, "LINE_LOST") == 0 ? TRACE_LINE_LOST
           : strcmp(name, "STOP") == 0    ? TRACE_STOP
                                          : 0u;
}

static uint8_t *hex_bytes(const char *hex, uint32_t *size)
{
    size_t n = strlen(hex) / 2, i;
    uint8_t *bytes = malloc(n ? n : 1);
    for (i = 0; bytes && i < n; i++) {
        unsigned value;
        sscanf(hex + 2 * i, "%2x", &value);
        bytes[i] = (uint8_t)value;
    }
    *size = (uint32_t)n;
    return bytes;
}

/* A vector being read: its two files, and what they share. */
typedef struct reading {
    char name[128];
    vector v;
    uint8_t *ilc, *stripped;
    uint32_t ilc_size, stripped_size;
    script_item items[64];
    trace_entry trace[1024];
    int16_t variables[53];
} reading;

static unsigned runs, failed, files, files_failed;
static bool once; /* each vector's ilc file, in one step, and nothing else */

static void run_vector(reading *r)
{
    char label[200];
    size_t w;
    int form;
    for (form = 0; form < (once ? 1 : 2); form++) {
        vector v = r->v;
        v.ilc = form ? r->stripped : r->ilc;
        v.ilc_size = form ? r->stripped_size : r->ilc_size;
        v.line = form ? 0u : r->v.line; /* a stripped file has no line map */
        for (w = 0; w < (once ? 1u : sizeof WAYS / sizeof *WAYS); w++) {
            uint32_t stack;
            snprintf(label, sizeof label, "%s%s (steps of %lu, %u busy polls)", r->name,
                     form ? ".stripped" : ".ilc", (unsigned long)WAYS[w].slice,
                     WAYS[w].busy_polls);
            runs++;
            if (!vector_run(&v, label, WAYS[w].slice, WAYS[w].busy_polls, bitmap,
                            sizeof bitmap, &stack)) {
                failed++;
            }
        }
    }
    free(r->ilc);
    free(r->stripped);
}

/* The rule of spec/ilc.md section 10 that a refusal answers (the vectors name rules). */
static uint32_t rule_of(rl1_refusal refusal, uint32_t size)
{
    if (refusal == RL1_TRUNCATED) { /* the file's start, the header, or a section */
        return size < 6u ? 1u : size < 24u ? 3u : 6u;
    }
    if (refusal <= RL1_BAD_MAJOR) {
        return (uint32_t)refusal - 1u; /* magic 1, major 2 */
    }
    if (refusal <= RL1_BAD_SECTION_SIZE) {
        return (uint32_t)refusal; /* header size 4, section sizes 5 */
    }
    if (refusal <= RL1_UNKNOWN_FEATURE) {
        return (uint32_t)refusal + 1u; /* extra bytes 7 ... features 11, in order */
    }
    if (refusal <= RL1_DEBUG_LEFTOVER) {
        return 12u; /* the debug section */
    }
    if (refusal <= RL1_CUT_OFF) {
        return (uint32_t)refusal - 4u; /* opcode 13, cut off 14 */
    }
    if (refusal <= RL1_ARGUMENT_RANGE) {
        return 15u; /* operands */
    }
    return (uint32_t)refusal - 6u; /* feature 16, jump 17, handler 18, line entry 19 */
}

static void check_file(const char *name, const char *hex, char *verdict)
{
    uint32_t size, where = 0, expected_where = 0, rule = 0;
    uint8_t *data = hex_bytes(hex, &size);
    rl1_program program;
    int pass;
    if (strcmp(strtok(verdict, " "), "refused") == 0) {
        rule = (uint32_t)strtoul(strtok(NULL, " "), NULL, 10);
        expected_where = (uint32_t)strtoul(strtok(NULL, " "), NULL, 10);
    }
    for (pass = 0; pass < 2; pass++) { /* with the bitmap, then by rescan */
        rl1_refusal got = rl1_load(&program, data, size, pass ? NULL : bitmap,
                                   pass ? 0 : sizeof bitmap, &where);
        uint32_t got_rule = got == RL1_ACCEPTED ? 0u : rule_of(got, size);
        files++;
        if (got_rule != rule || (got != RL1_ACCEPTED && where != expected_where)) {
            printf("%s: rule %lu at %lu, expected %lu at %lu\n", name, (unsigned long)got_rule,
                   (unsigned long)where, (unsigned long)rule, (unsigned long)expected_where);
            files_failed++;
        }
    }
    free(data);
}

static long number(void)
{
    char *word = strtok(NULL, " ");
    return word ? strtol(word, NULL, 10) : 0;
}

static void read_file(const char *path, reading *r)
{
    static char text[1 << 22];
    FILE *f = fopen(path, "rb");
    size_t size;
    char *line, *next, *word;
    unsigned number_of_line = 0;
    if (!f) {
        perror(path);
        exit(2);
    }
    size = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[size] = '\0';
    for (line = text; line && *line; line = next) {
        next = strchr(line, '\n');
        if (next) {
            *next++ = '\0';
        }
        number_of_line++;
        word = strtok(line, " ");
        if (!word) {
            continue;
        }
        if (strcmp(word, "vector") == 0) {
            memset(r, 0, sizeof *r);
            snprintf(r->name, sizeof r->name, "%s", strtok(NULL, " "));
            r->v.script = r->items;
            r->v.trace = r->trace;
            r->v.variables = r->variables;
        } else if (strcmp(word, "budget") == 0) {
            r->v.budget = (uint32_t)number();
        } else if (strcmp(word, "ilc") == 0) {
            r->ilc = hex_bytes(strtok(NULL, " "), &r->ilc_size);
        } else if (strcmp(word, "ilc_stripped") == 0) {
            r->stripped = hex_bytes(strtok(NULL, " "), &r->stripped_size);
        } else if (strcmp(word, "sensor") == 0 || strcmp(word, "loss") == 0
                   || strcmp(word, "fail") == 0 || strcmp(word, "stop_fails") == 0
                   || strcmp(word, "after_last") == 0) {
            script_item *item = &r->items[r->v.script_count];
            int k;
            if (r->v.script_count == sizeof r->items / sizeof *r->items) {
                fail_input(path, number_of_line, "more script lines than this runner holds");
            }
            r->v.script_count++;
            if (word[0] == 's' && word[1] == 'e') {
                item->kind = SENSOR;
                item->key = (uint8_t)call_of(strtok(NULL, " "));
            } else if (word[0] == 'l') {
                word = strtok(NULL, " ");
                item->kind = strcmp(word, "time") == 0     ? LOSS_TIME
                             : strcmp(word, "during") == 0 ? LOSS_DURING
                                                           : LOSS_INSTRUCTION;
                if (item->kind == LOSS_DURING) {
                    item->key = strcmp(strtok(NULL, " "), "MOV") == 0 ? RL1_MOV : RL1_MVI;
                }
            } else if (word[0] == 'f') {
                item->kind = FAIL;
                item->key = (uint8_t)call_of(strtok(NULL, " "));
            } else if (word[0] == 'a') {
                if (strcmp(strtok(NULL, " "), "repeat") != 0) {
                    fail_input(path, number_of_line, "after_last is repeat or absent");
                }
                item->kind = REPEAT_AFTER_LAST;
            } else {
                item->kind = STOP_FAILS;
            }
            for (k = 0; k < 4; k++) {
                item->value[k] = (int32_t)number();
            }
        } else if (strcmp(word, "status") == 0) {
            (void)strtok(NULL, " ");
            r->v.fault = (uint8_t)number();
            r->v.line = (uint16_t)number();
        } else if (strcmp(word, "executed") == 0) {
            r->v.executed = (uint32_t)number();
        } else if (strcmp(word, "variables") == 0) {
            int k;
            for (k = 0; k < 53; k++) {
                r->variables[k] = (int16_t)number();
            }
        } else if (strcmp(word, "trace") == 0) {
            trace_entry *e = &r->trace[r->v.trace_count];
            int k;
            if (r->v.trace_count == sizeof r->trace / sizeof *r->trace) {
                fail_input(path, number_of_line, "a longer trace than this runner holds");
            }
            r->v.trace_count++;
            e->time = (uint32_t)number();
            e->call = call_of(strtok(NULL, " "));
            e->nargs = (uint8_t)number();
            for (k = 0; k < e->nargs; k++) {
                e->args[k] = (int16_t)number();
            }
            e->nresult = (uint8_t)number();
            for (k = 0; k < e->nresult; k++) {
                e->result[k] = (int16_t)number();
            }
        } else if (strcmp(word, "end") == 0) {
            run_vector(r);
        } else if (strcmp(word, "file") == 0) {
            char *name = strtok(NULL, " ");
            char *hex = strtok(NULL, " ");
            check_file(name, hex, hex + strlen(hex) + 1);
        } else if (strcmp(word, "rl1-vectors") != 0) {
            fail_input(path, number_of_line, "a line this runner does not know");
        }
    }
}

int main(int argc, char **argv)
{
    static reading r;
    int i = 1;
    if (argc > 1 && strcmp(argv[1], "--once") == 0) {
        once = true;
        i = 2;
    }
    for (; i < argc; i++) {
        read_file(argv[i], &r);
    }
    printf("conformance: %u runs of the run vectors, %u failed; %u loads of the "
           "verifier's files, %u failed\n", runs, failed, files, files_failed);
    return (failed || files_failed || !runs) ? 1 : 0;
}
