/* Listing 1, the paper's sample program (examples/sample.rob), on a fake vehicle that
 * prints on the serial port (115200 baud) each command the program gives, and whose
 * camera answers from a table: the readings of examples/sample.sensors.json, so the
 * calls are those of
 *
 *     rl1c run examples/sample.rob --sensors examples/sample.sensors.json
 *
 * Replace the callbacks with your vehicle's (vm/c/README.md: "Write the callbacks").
 * listing1_ilc.c beside this file is the program, in flash:
 *
 *     rl1c sample.rob --emit c --progmem --c-name listing1_ilc -o listing1_ilc.c
 */
#include <RL1VM.h>

#if defined(__AVR__)
#include <avr/sleep.h>
#endif

extern "C" {
extern const uint8_t listing1_ilc[];  // PROGMEM
extern const uint32_t listing1_ilc_size;
}

/* What the camera sees at each IMG, in call order: area, x, y, angle. */
static const int16_t images[][4] PROGMEM = {
    {120, 128, 90, 0}, {150, 128, 90, 0}, {185, 128, 90, 0},
    {60, 100, 80, 0}, {60, 160, 80, 0},
    {40, 145, 100, 0}, {40, 140, 100, 0}, {40, 128, 100, 0}, {40, 128, 100, 0},
    {40, 128, 100, 0},
    {45, 128, 110, 0}, {50, 131, 125, 0}, {55, 126, 140, 0}, {60, 128, 155, 0},
    {65, 129, 165, 0},
    {30, 128, 100, 0}, {70, 128, 100, 0}, {105, 128, 100, 0},
};
static const uint8_t image_count = sizeof images / sizeof images[0];

/* The built-ins' names by opcode from RL1_OP_FRE (spec/ilc.md 8.3), five characters each. */
static const char names[] PROGMEM =
    "FRE  HLD  ORG  MVI  MOV  STR  STL  STX  ROT  TRC  TIM  KYC  KYO  SCN  IMG  "
    "CAM ZCAM UCAM DCAM ACAM PCAM RULT AULT BULT CULT DLMP  INP  OUT  FZO  FZI  ";

/* The fake vehicle's state: what it is doing, and how far the camera's table is read. */
struct Vehicle {
    uint8_t command;     // the started built-in, polled until done
    uint8_t busy_polls;  // polls left before it is done
    uint8_t images_read;
};
static Vehicle vehicle;

/* Prints the call as rl1c run does: its name, then its arguments ("CAM A 90", "MOV 3,3"). */
static void print_call(uint8_t opcode, const int16_t *args)
{
    const char *name = names + 5 * (opcode - RL1_OP_FRE);
    for (uint8_t k = 0; k < 5 && (k < 3 || pgm_read_byte(name + 4) != ' '); k++) {
        Serial.write(pgm_read_byte(name + k));  // the selector, if any, is the fifth
    }
    uint8_t arity = rl1_call_arity(opcode);
    for (uint8_t k = 0; k < arity; k++) {
        Serial.print(k == 0 ? ' ' : ',');
        Serial.print(args[k]);
    }
}

static rl1_status begin(void *) { return RL1_OK; }

/* FRE HLD MOV TRC KYC KYO SCN LMP INP OUT FZO FZI: done at once. This vehicle has no
 * odometry, port or fuzzy unit to read: KYO, INP and FZI are device errors. */
static rl1_status call(void *, uint8_t opcode, const int16_t *args, rl1_reading *)
{
    print_call(opcode, args);
    Serial.println();
    return opcode == RL1_OP_KYO || opcode == RL1_OP_INP || opcode == RL1_OP_FZI
        ? RL1_ERROR : RL1_OK;
}

/* ORG MVI STR STL STX ROT TIM IMG CAM* ULT*: started here, done after one busy poll. */
static rl1_status start(void *ctx, uint8_t opcode, const int16_t *args)
{
    Vehicle *v = static_cast<Vehicle *>(ctx);
    print_call(opcode, args);
    v->command = opcode;
    v->busy_polls = 1;
    return RL1_OK;
}

static rl1_status poll(void *ctx, rl1_reading *out)
{
    Vehicle *v = static_cast<Vehicle *>(ctx);
    if (v->busy_polls > 0) {
        v->busy_polls--;
        return RL1_BUSY;
    }
    rl1_status status = RL1_OK;
    if (v->command == RL1_OP_IMG) {
        if (v->images_read == image_count) {
            status = RL1_ERROR;  // past the table: nothing more to see
        } else {
            const int16_t *image = images[v->images_read++];
            out->result = static_cast<int16_t>(pgm_read_word(&image[0]));
            Serial.print(" ->");
            for (uint8_t k = 0; k < 4; k++) {
                out->writes[k] = static_cast<int16_t>(pgm_read_word(&image[k]));
                Serial.print(' ');
                Serial.print(out->writes[k]);
            }
        }
    } else if (v->command == RL1_OP_CAMR || (v->command >= RL1_OP_ULTA
                                              && v->command <= RL1_OP_ULTD)) {
        status = RL1_ERROR;  // no camera position sensor, no ultrasonic sensor
    }
    Serial.println();
    return status;
}

static rl1_status stop(void *) { Serial.println(F("stop")); return RL1_OK; }
static rl1_status end(void *) { return RL1_OK; }

static const rl1_hardware hardware = {&vehicle, begin, call, start, poll, stop, end};

static rl1_program program;
static rl1_vm vm;
static bool running;

void setup()
{
    Serial.begin(115200);
    uint8_t bitmap[RL1_BITMAP_SIZE(512)];  // scratch for the loader, free after it
    uint32_t where;
    rl1_refusal refusal = rl1_load(&program, listing1_ilc, listing1_ilc_size, bitmap,
                                   sizeof bitmap, &where);
    if (refusal != RL1_ACCEPTED) {
        Serial.print(F("refused: rule "));  // spec/ilc.md section 10
        Serial.print(refusal);
        Serial.print(F(" at offset "));
        Serial.println(where);
        return;
    }
    rl1_vm_init(&vm, 10000000UL);
    running = true;
}

/* Once the run is over, the board has nothing left to do: it sleeps for good. */
static void halt()
{
    Serial.flush();
#if defined(__AVR__)
    set_sleep_mode(SLEEP_MODE_PWR_DOWN);
    sleep_enable();
    cli();
    sleep_cpu();
#endif
    running = false;
}

static void print_variables()
{
    static const char letters[] PROGMEM =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz@";
    Serial.print(F("variables:"));
    for (uint8_t k = 0; k < sizeof vm.V / sizeof vm.V[0]; k++) {
        if (vm.V[k] != 0) {
            Serial.print(' ');
            Serial.write(pgm_read_byte(letters + k));
            Serial.print('=');
            Serial.print(vm.V[k]);
        }
    }
    Serial.println();
}

void loop()
{
    if (!running) {
        return;
    }
    // At most 200 instructions, then the main loop's other work (none here).
    rl1_state state = rl1_step(&vm, &program, &hardware, 200);
    if (state == RL1_ENDED || state == RL1_FAULTED) {
        if (state == RL1_ENDED) {
            Serial.print(F("ended after "));
        } else {
            Serial.print(F("fault "));  // 10..13: rl1c run's exit statuses
            Serial.print(vm.fault);
            Serial.print(F(" at line "));
            Serial.print(vm.pc == 0xFFFFu ? 0 : rl1_line_at(&program, vm.pc));
            Serial.print(F(" after "));
        }
        Serial.print(vm.executed);
        Serial.println(F(" instructions"));
        print_variables();
        halt();
    }
}
