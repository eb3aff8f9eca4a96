/* The scripted device (scripted.h), a port of vm/scripted.py's ScriptedDevice with
 * vm/hardware.py's Blocking adapter over it: the same clock, motion, losses, readings
 * and failures, so that a C run and a Python run of a vector give the same trace. */
#include "scripted.h"

#define FIRST_CALL 0x40u
#define STEP_MS 100u          /* a waiting built-in with no duration of its own */
#define ROT_MS_PER_DEGREE 10u

void scripted_init(scripted *device, const script *s, rl1_mailbox *mailbox)
{
    unsigned char *byte = (unsigned char *)device;
    size_t i;
    for (i = 0; i < sizeof *device; i++) {
        byte[i] = 0;
    }
    device->script = *s;
    device->mailbox = mailbox;
}

static bool item_at(const scripted *d, uint16_t index, script_item *item)
{
    if (index >= d->script.count) {
        return false;
    }
    d->script.read(item, &d->script.items[index]);
    return true;
}

/* Records a command at the current time; a script's "fail" makes it fail: RL1_ERROR at
 * once for a built-in that takes no time, at the end of its time for one that does. */
static rl1_status record(scripted *d, uint16_t call, const int16_t *args, uint8_t nargs,
                         const int16_t *result, uint8_t nresult, bool takes_time)
{
    trace_entry entry;
    script_item item;
    uint16_t i, arrived;
    entry.time = d->time;
    entry.call = call;
    entry.nargs = nargs;
    entry.nresult = nresult;
    for (i = 0; i < 3u; i++) {
        entry.args[i] = i < nargs ? args[i] : 0;
    }
    for (i = 0; i < 4u; i++) {
        entry.result[i] = i < nresult ? result[i] : 0;
    }
    d->record(d->sink, &entry);
    if (call >= TRACE_LINE_LOST) {
        return RL1_OK;
    }
    arrived = ++d->arrivals[call - FIRST_CALL];
    for (i = 0; item_at(d, i, &item); i++) {
        if (item.kind == FAIL && item.key == call && item.value[0] == (int32_t)arrived) {
            if (!takes_time) {
                return RL1_ERROR;
            }
            d->failing = true;
        }
    }
    return RL1_OK;
}

/* The reading of a sensing call: the next one of its list (INP: of its port). Past
 * the list, false; or with "after_last": "repeat", the last one again (zeros when there
 * is none). */
static bool next_reading(scripted *d, uint8_t op, int16_t port, int16_t *values)
{
    script_item item, found = {0, 0, {0, 0, 0, 0}};
    uint16_t index, seen = 0, i;
    uint8_t k, first = op == 0x5Au ? 1u : 0u;
    if (op == 0x5Au) {
        for (k = 0; k < d->port_count && d->ports[k] != (uint8_t)port; k++) {
        }
        if (k == d->port_count && k < INP_PORTS) {
            d->ports[d->port_count++] = (uint8_t)port;
        }
        index = d->port_reads[k % INP_PORTS]++;
    } else {
        index = d->arrivals[op - FIRST_CALL];
    }
    for (k = 0; k < 4u; k++) {
        values[k] = 0;
    }
    for (i = 0; item_at(d, i, &item) && seen <= index; i++) {
        if (item.kind == SENSOR && item.key == op && (!first || item.value[0] == port)) {
            found = item;
            seen++;
        }
    }
    for (k = 0; seen && k + first < 4u; k++) {
        values[k] = (int16_t)found.value[k + first];
    }
    if (seen > index) {
        return true;
    }
    for (i = 0; item_at(d, i, &item); i++) {
        if (item.kind == REPEAT_AFTER_LAST) {
            return true;
        }
    }
    return false;
}

/* The time of the next loss that could matter in (time, until]. */
static bool next_loss(const scripted *d, uint32_t until, uint32_t *at)
{
    script_item item;
    uint16_t i;
    bool found = false;
    for (i = 0; item_at(d, i, &item); i++) {
        uint32_t when;
        if (item.kind == LOSS_TIME) {
            when = (uint32_t)item.value[0];
        } else if (item.kind == LOSS_DURING && d->motion == 1u + item.key
                   && (uint32_t)item.value[0] == d->motion_nth) {
            when = d->motion_start + (uint32_t)item.value[1];
        } else {
            continue;
        }
        if (when > d->time && when <= until && (!found || when < *at)) {
            *at = when;
            found = true;
        }
    }
    return found;
}

bool scripted_lose_line(scripted *d)
{
    int16_t mode = d->mode;
    if (!d->motion || d->mode == 0u) {
        return false;
    }
    (void)record(d, TRACE_LINE_LOST, &mode, 1, NULL, 0, false);
    if (d->mode == 1u || d->mailbox->posted != d->mailbox->taken) {
        return false;
    }
    (void)rl1_post_line_lost(d->mailbox, d->mode, (uint8_t)(d->motion - 1u));
    if (d->mode == 2u) {
        d->motion = 0;
    }
    return true;
}

/* Lets `duration` ms pass, meeting motion ends and losses in time order; an
 * interruptible wait ends at the first loss the program must hear. Then a failure the
 * script set for this built-in. */
static rl1_status advance(scripted *d, uint32_t duration, bool interruptible)
{
    uint32_t until = d->time + duration, loss = 0;
    for (;;) {
        bool lost = next_loss(d, until, &loss);
        if (d->motion && d->motion_ends && d->motion_end <= until
            && (!lost || d->motion_end <= loss)) {
            d->time = d->motion_end;
            d->motion = 0;
            continue;
        }
        if (!lost) {
            d->time = until;
            break;
        }
        d->time = loss;
        if (scripted_lose_line(d) && interruptible) {
            break;
        }
    }
    if (d->failing) {
        d->failing = false;
        return RL1_ERROR;
    }
    return RL1_OK;
}

static void start_motion(scripted *d, uint8_t command, bool ends, uint32_t duration)
{
    d->motion = (uint8_t)(1u + command);
    d->motion_nth = d->moves[command];
    d->motion_start = d->time;
    d->motion_ends = ends;
    d->motion_end = d->time + duration;
}

static uint32_t magnitude(int32_t value)
{
    return (uint32_t)(value < 0 ? -value : value);
}

/* Carries out built-in `op` at once (the Blocking adapter's way), filling *out. */
static rl1_status perform(scripted *d, uint8_t op, const int16_t *args, rl1_reading *out)
{
    static const uint8_t nargs[30] = {0, 0, 0, 3, 2, 1, 1, 1, 1, 1, 1, 0, 0, 1, 0,
                                      0, 0, 0, 1, 1, 0, 0, 0, 0, 0, 1, 1, 2, 2, 0};
    int16_t values[4] = {0, 0, 0, 0};
    uint8_t n = nargs[op - FIRST_CALL];
    uint8_t nresult = 0;
    bool waits = op == 0x42u || op == 0x43u || (op >= 0x45u && op <= 0x48u) || op == 0x4Au
                 || (op >= 0x4Eu && op <= 0x58u);
    rl1_status status;
    bool have_reading = true; /* false: a sensing call past its readings */
    uint32_t cm, speed;
    out->result = 0;
    switch (op) {
    case 0x40: case 0x41: /* FRE, HLD: the vehicle stops */
        status = record(d, op, args, n, NULL, 0, false);
        if (status == RL1_OK) {
            d->motion = 0;
        }
        return status;
    case 0x43: /* MVI l, r, cm */
        d->moves[1]++;
        (void)record(d, op, args, n, NULL, 0, true); /* a failure comes at the end */
        cm = magnitude(args[2]);
        speed = magnitude((int32_t)args[0] + args[1]);
        if (cm == 0u) {
            d->motion = 0;
            return advance(d, 0, true);
        }
        if (speed == 0u) {
            return RL1_ERROR; /* it would never end */
        }
        start_motion(d, RL1_MVI, true, (cm * 400u + speed - 1u) / speed);
        return advance(d, d->motion_end - d->time, true);
    case 0x44: /* MOV l, r */
        d->moves[0]++;
        status = record(d, op, args, n, NULL, 0, false);
        if (status != RL1_OK) {
            return status;
        }
        d->motion = 0;
        if (args[0] != 0 || args[1] != 0) {
            start_motion(d, RL1_MOV, false, 0);
        }
        return status;
    case 0x48: /* ROT deg */
        (void)record(d, op, args, n, NULL, 0, true);
        return advance(d, magnitude(args[0]) * ROT_MS_PER_DEGREE, false);
    case 0x49: /* TRC mode */
        status = record(d, op, args, n, NULL, 0, false);
        if (status == RL1_OK) {
            d->mode = (uint8_t)args[0];
        }
        return status;
    case 0x4A: /* TIM tenths */
        (void)record(d, op, args, n, NULL, 0, true);
        return advance(d, magnitude(args[0]) * 100u, true);
    case 0x4C: /* KYO: centre, right (u), left (v) */
        nresult = 3;
        have_reading = next_reading(d, op, 0, values);
        out->result = values[0];
        out->writes[0] = values[1];
        out->writes[1] = values[2];
        break;
    case 0x4E: /* IMG: area (R and w), x, y, z */
        nresult = 4;
        have_reading = next_reading(d, op, 0, values);
        out->result = values[0];
        out->writes[0] = values[0];
        out->writes[1] = values[1];
        out->writes[2] = values[2];
        out->writes[3] = values[3];
        break;
    case 0x54: case 0x55: case 0x56: case 0x57: case 0x58: /* CAM R, ULT A-D */
        nresult = 1;
        have_reading = next_reading(d, op, 0, values);
        out->result = values[0];
        break;
    case 0x5A: /* INP port */
        nresult = 1;
        have_reading = next_reading(d, op, args[0], values);
        out->result = values[0];
        break;
    case 0x5D: /* FZI: s, t */
        nresult = 2;
        have_reading = next_reading(d, op, 0, values);
        out->writes[0] = values[0];
        out->writes[1] = values[1];
        break;
    default:
        break;
    }
    if (!have_reading) { /* recorded without a result, then the device fails */
        (void)record(d, op, args, n, NULL, 0, waits);
        return RL1_ERROR;
    }
    status = record(d, op, args, n, values, nresult, waits);
    if (status != RL1_OK || !waits) {
        return status;
    }
    return advance(d, STEP_MS, false);
}

static rl1_status begin(void *ctx)
{
    (void)ctx;
    return RL1_OK;
}

static rl1_status call(void *ctx, uint8_t opcode, const int16_t *args, rl1_reading *out)
{
    return perform((scripted *)ctx, opcode, args, out);
}

static rl1_status start(void *ctx, uint8_t opcode, const int16_t *args)
{
    scripted *d = (scripted *)ctx;
    d->started = perform(d, opcode, args, &d->reading);
    d->polls = 0;
    return RL1_OK;
}

static rl1_status poll(void *ctx, rl1_reading *out)
{
    scripted *d = (scripted *)ctx;
    if (d->polls < d->busy_polls) {
        d->polls++;
        return RL1_BUSY;
    }
    *out = d->reading;
    return d->started;
}

static rl1_status stop(void *ctx)
{
    scripted *d = (scripted *)ctx;
    script_item item;
    uint16_t i;
    (void)record(d, TRACE_STOP, NULL, 0, NULL, 0, false);
    d->motion = 0;
    for (i = 0; item_at(d, i, &item); i++) {
        if (item.kind == STOP_FAILS) {
            return RL1_ERROR;
        }
    }
    return RL1_OK;
}

static rl1_status end(void *ctx)
{
    (void)ctx;
    return RL1_OK;
}

void scripted_hardware(rl1_hardware *hw, scripted *device)
{
    hw->ctx = device;
    hw->begin = begin;
    hw->call = call;
    hw->start = start;
    hw->poll = poll;
    hw->stop = stop;
    hw->end = end;
}
