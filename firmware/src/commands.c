/* The requests ?, R, W, C and G: parsed strictly, answered with exactly one line. R and W are framed for
 * the part found on SPI (sensor.h); C and G exist for a part the bridge captures (the ADXL355, the ICM-42688-P).
 *
 * Each request is checked in the order docs/instruments.md gives ("The serial bridge protocol", its table of
 * refusals): the verb and its number of words; a part that has the request; the arguments; the part's
 * register map; the state (a capture, standby). The first check that fails is the answer. */
#include "commands.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "bridge.h"
#include "bridge_hal.h"
#include "capture.h"
#include "parse.h"
#include "reply.h"
#include "sensor.h"

#define MAX_WORDS 3u

/* ADXL355-BRIDGE 3 part=<name>[ capture=<samples>] <free text>: capture= only where C and G work. The part is
 * looked for again on every greeting (a sensor powered after the board, or another one plugged in). */
static void greet(char *const *arguments)
{
    (void)arguments;
    if (sensor_detect()) {
        capture_reset(); /* a capture of another part (or of none) means nothing now */
    }
    const sensor_identity part = sensor_part();

    reply_text("ADXL355-BRIDGE ");
    reply_decimal(BRIDGE_PROTOCOL_VERSION);
    reply_text(" part=");
    reply_text(part.name);
    if (part.captures) {
        reply_text(" capture=");
        reply_decimal(capture_capacity());
    }
    reply_text(" accelcal-rig reference firmware " BRIDGE_FIRMWARE_VERSION " (");
    reply_text(bridge_hal_board_name());
    reply_char(')');
    reply_end();
}

/* R, W, C and G need a part on the bus; false (and the refusal sent) if none answered. */
static bool part_found(void)
{
    if (!sensor_part().found) {
        reply_error("no sensor on SPI: no ICM-42688-P WHO_AM_I nor ADXL355 DEVID_AD answered (? looks again)");
        return false;
    }
    return true;
}

/* C and G need a part the bridge captures; false (and the refusal sent) if it does not. */
static bool part_captures(void)
{
    if (!part_found()) {
        return false;
    }
    if (!sensor_part().captures) {
        reply_char('!');
        reply_text("capture: not supported for ");
        reply_text(sensor_part().name);
        reply_end();
        return false;
    }
    return true;
}

/* "!<before> 0x<address><after>" */
static void refuse_register(const char *before, uint8_t address, const char *after)
{
    reply_char('!');
    reply_text(before);
    reply_text(" 0x");
    reply_hex(&address, 1);
    reply_text(after);
    reply_end();
}

/* The address word: 1 or 2 hex digits, 00..7F; false (and the refusal sent) otherwise. */
static bool address_of(const char *text, uint8_t *address)
{
    if (!parse_hex_byte(text, address) || *address > SENSOR_REG_LAST) {
        reply_error("bad address (hex 00..7F)");
        return false;
    }
    return true;
}

static bool covers(uint8_t address, uint32_t count, uint8_t reg)
{
    return address <= reg && reg < address + count;
}

static void read_registers(char *const *arguments)
{
    static uint8_t data[BRIDGE_MAX_READ];
    uint8_t address;
    uint32_t count;

    if (!part_found() || !address_of(arguments[0], &address)) {
        return;
    }
    if (!parse_decimal(arguments[1], BRIDGE_MAX_READ, &count) || count == 0) {
        reply_error("bad count (decimal 1..288)");
        return;
    }
    /* The registers a burst reads run from its address on, except from one the part does not move on from. */
    const uint32_t last = sensor_burst_stays(address) ? address : address + count - 1u;
    if (last > sensor_last_register()) {
        const uint32_t missing = address > sensor_last_register() ? address : sensor_last_register() + 1u;
        refuse_register("no register", (uint8_t)missing, "");
        return;
    }
    /* A burst from FIFO_DATA takes samples out of the FIFO: during a capture they belong to it. */
    if (capture_running() && covers(address, count, sensor_fifo_data())) {
        reply_error("FIFO_DATA is being captured (fetch with G)");
        return;
    }
    sensor_read(address, data, count);
    capture_saw_status(address, count, data);
    reply_char('=');
    reply_hex(data, count);
    reply_end();
}

static void write_register(char *const *arguments)
{
    uint8_t address;
    uint8_t value;

    if (!part_found() || !address_of(arguments[0], &address)) {
        return;
    }
    if (!parse_hex_byte(arguments[1], &value)) {
        reply_error("bad value (hex 00..FF)");
        return;
    }
    if (address > sensor_last_register()) {
        refuse_register("no register", address, "");
        return;
    }
    if (sensor_read_only(address)) {
        refuse_register("read-only register", address, "");
        return;
    }
    if (sensor_standby_only(address) && !sensor_in_standby()) {
        refuse_register("register", address, " changes only in standby");
        return;
    }
    if (capture_running() && sensor_changes_the_stream(address)) {
        capture_stop(address);
    }
    sensor_write(address, value);
    reply_char('=');
    reply_end();
}

static void start_capture(char *const *arguments)
{
    uint32_t count;
    uint8_t temperature[2];

    if (!part_captures()) {
        return;
    }
    capture_reset(); /* a C forgets the capture before it, even when it is refused */
    if (!parse_decimal(arguments[0], capture_capacity(), &count) || count == 0) {
        reply_char('!');
        reply_text("bad count (decimal 1..");
        reply_decimal(capture_capacity());
        reply_char(')');
        reply_end();
        return;
    }
    const char *refusal = capture_start(count, temperature);
    if (refusal != NULL) {
        reply_error(refusal);
        return;
    }
    reply_char('=');
    reply_hex(temperature, sizeof temperature);
    reply_end();
}

static void reply_progress(const capture_view *view)
{
    reply_text(" after ");
    reply_decimal(view->have);
    reply_text(" of ");
    reply_decimal(view->wanted);
    reply_text(" samples");
}

/*
 * What the buffer holds now from `first` on. The view is taken once: samples captured while the
 * reply goes out wait for the next fetch, and the end temperature is sent only if the capture was
 * already complete, so `T` always means every sample up to the count was in this reply or before.
 */
static void fetch_capture(char *const *arguments)
{
    uint32_t first;
    capture_view view;

    if (!part_captures()) {
        return;
    }
    if (!parse_decimal(arguments[0], capture_capacity(), &first)) {
        reply_char('!');
        reply_text("bad first (decimal 0..");
        reply_decimal(capture_capacity());
        reply_char(')');
        reply_end();
        return;
    }
    capture_get(&view);
    if (view.state == CAPTURE_NONE) {
        reply_error("no capture (start one with C)");
        return;
    }
    if (view.state == CAPTURE_LOST || view.state == CAPTURE_FAILED) {
        reply_char('!');
        reply_text(view.state == CAPTURE_LOST ? "overflow: " : "");
        reply_text(view.reason);
        reply_progress(&view);
        reply_end();
        return;
    }
    reply_char('=');
    if (first < view.have) {
        reply_hex(&view.samples[first * view.sample_bytes], (size_t)(view.have - first) * view.sample_bytes);
    }
    if (view.state == CAPTURE_COMPLETE) {
        reply_char('T');
        reply_hex(view.end_temperature, sizeof view.end_temperature);
    }
    reply_end();
}

/* Each request: its verb, its number of words with the verb, what a wrong number is answered, and its reader
 * (given the words after the verb). */
static const struct {
    char verb;
    size_t words;
    const char *usage;
    void (*answer)(char *const *arguments);
} requests[] = {
    {'?', 1u, "usage: ?", greet},
    {'R', 3u, "usage: R <addr> <count>", read_registers},
    {'W', 3u, "usage: W <addr> <value>", write_register},
    {'C', 2u, "usage: C <count>", start_capture},
    {'G', 2u, "usage: G <first>", fetch_capture},
};

void command_execute(char *line)
{
    char *words[MAX_WORDS];
    const size_t count = parse_words(line, words, MAX_WORDS);

    if (count == 0) {
        return; /* a blank line is no request: nothing to answer */
    }
    const char *verb = words[0];
    for (size_t i = 0; i < sizeof requests / sizeof requests[0]; ++i) {
        if (verb[0] == requests[i].verb && verb[1] == '\0') {
            if (count == requests[i].words) {
                requests[i].answer(&words[1]);
            } else {
                reply_error(requests[i].usage);
            }
            return;
        }
    }
    reply_error("unknown request (? R W C G)");
}
