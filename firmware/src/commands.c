/* The requests ?, R, W, C and G: parsed strictly, answered with exactly one line. R and W are framed for
 * the part found on SPI (sensor.h); C and G exist for a part the bridge captures (the ADXL355). */
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

/* ADXL355-BRIDGE 3 part=<name>[ capture=4096] <free text>: capture= only where C and G work. The part is
 * looked for again on every greeting (a sensor powered after the board, or another one plugged in). */
static void greet(void)
{
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
        reply_decimal(BRIDGE_CAPTURE_SAMPLES);
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

static bool covers(uint8_t address, uint32_t count, uint8_t reg)
{
    return address <= reg && reg < address + count;
}

static void read_registers(const char *address_text, const char *count_text)
{
    static uint8_t data[BRIDGE_MAX_READ];
    uint8_t address;
    uint32_t count;

    if (!parse_hex_byte(address_text, &address) || address > SENSOR_REG_LAST) {
        reply_error("R: address must be hex 00..7F");
        return;
    }
    if (!parse_decimal(count_text, BRIDGE_MAX_READ, &count) || count == 0) {
        reply_error("R: count must be decimal 1..288");
        return;
    }
    if (!part_found()) {
        return;
    }
    /* A burst from FIFO_DATA takes samples out of the FIFO: during a capture they belong to it. */
    if (capture_running() && covers(address, count, SENSOR_REG_FIFO_DATA)) {
        reply_error("R: FIFO_DATA is being captured (fetch with G)");
        return;
    }
    sensor_read(address, data, count);
    if (covers(address, count, SENSOR_REG_STATUS)) {
        capture_saw_status(data[SENSOR_REG_STATUS - address]);
    }
    reply_char('=');
    reply_hex(data, count);
    reply_end();
}

/* Registers whose write changes or ends the stream a running capture is taking. */
static bool changes_the_stream(uint8_t address)
{
    return address == SENSOR_REG_FILTER || address == SENSOR_REG_FIFO_SAMPLES || address == SENSOR_REG_RANGE
        || address == SENSOR_REG_POWER_CTL || address == SENSOR_REG_RESET;
}

static void write_register(const char *address_text, const char *value_text)
{
    uint8_t address;
    uint8_t value;

    if (!parse_hex_byte(address_text, &address) || address > SENSOR_REG_LAST) {
        reply_error("W: address must be hex 00..7F");
        return;
    }
    if (!parse_hex_byte(value_text, &value)) {
        reply_error("W: value must be hex 00..FF");
        return;
    }
    if (!part_found()) {
        return;
    }
    if (changes_the_stream(address)) {
        capture_stop("capture stopped: FILTER, FIFO_SAMPLES, RANGE, POWER_CTL or RESET written during it");
    }
    sensor_write(address, value);
    reply_char('=');
    reply_end();
}

static void start_capture(const char *count_text)
{
    uint32_t count;
    uint8_t temperature[2];

    if (!part_captures()) {
        return;
    }
    if (!parse_decimal(count_text, BRIDGE_CAPTURE_SAMPLES, &count) || count == 0) {
        capture_reset();
        reply_error("capture count must be decimal 1..4096 (capture=4096)");
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
static void fetch_capture(const char *first_text)
{
    uint32_t first;
    capture_view view;

    if (!part_captures()) {
        return;
    }
    if (!parse_decimal(first_text, BRIDGE_CAPTURE_SAMPLES, &first)) {
        reply_error("G: first must be decimal 0..4096");
        return;
    }
    capture_get(&view);
    if (view.state == CAPTURE_NONE) {
        reply_error("G: no capture (start one with C)");
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
        reply_hex(&view.samples[first * BRIDGE_SAMPLE_BYTES], (size_t)(view.have - first) * BRIDGE_SAMPLE_BYTES);
    }
    if (view.state == CAPTURE_COMPLETE) {
        reply_char('T');
        reply_hex(view.end_temperature, sizeof view.end_temperature);
    }
    reply_end();
}

void command_execute(char *line)
{
    char *words[MAX_WORDS];
    const size_t count = parse_words(line, words, MAX_WORDS);

    if (count == 0) {
        return; /* a blank line is no request: nothing to answer */
    }
    const char *verb = words[0];
    const bool one_letter = verb[0] != '\0' && verb[1] == '\0';
    if (one_letter && verb[0] == '?' && count == 1) {
        greet();
    } else if (one_letter && verb[0] == 'R' && count == 3) {
        read_registers(words[1], words[2]);
    } else if (one_letter && verb[0] == 'W' && count == 3) {
        write_register(words[1], words[2]);
    } else if (one_letter && verb[0] == 'C' && count == 2) {
        start_capture(words[1]);
    } else if (one_letter && verb[0] == 'G' && count == 2) {
        fetch_capture(words[1]);
    } else {
        reply_error("unknown request (? R W C G)");
    }
}
