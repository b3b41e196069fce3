/* The main-loop entry points: a request line assembled from the HAL's bytes, then answered. */
#include "bridge.h"

#include <stddef.h>
#include <stdint.h>

#include "bridge_hal.h"
#include "capture.h"
#include "commands.h"
#include "reply.h"
#include "sensor.h"

/* The longest request is "R 7F 288" or "C 4096"; 40 leaves room for stray spaces. */
#define REQUEST_MAX 40u

/* A host writes a request in one go: the start of a line left this long without its end is a previous
 * client's, or noise from plugging in, and would spoil the next client's first request. */
#define STALE_LINE_US 1000000u

static char line[REQUEST_MAX + 1];
static size_t line_used;
static bool line_too_long;
static bool line_unprintable;
static uint64_t last_byte_us;

static void forget_line(void)
{
    line_used = 0;
    line_too_long = false;
    line_unprintable = false;
}

void bridge_init(void)
{
    forget_line();
    capture_reset();
    (void)sensor_detect();
}

static void answer_line(void)
{
    line[line_used] = '\0';
    if (line_too_long) {
        reply_error("request too long");
    } else if (line_unprintable) {
        reply_error("request has bytes that are not printable ASCII");
    } else {
        command_execute(line);
    }
    forget_line();
}

/* One received byte; true once a whole line has been answered. */
static bool take_byte(char c)
{
    const uint64_t now = bridge_hal_micros();

    if ((line_used > 0 || line_unprintable) && now - last_byte_us > STALE_LINE_US) {
        forget_line();
    }
    last_byte_us = now;
    if (c == '\n') {
        answer_line();
        return true;
    }
    if (c == '\r') {
        return false; /* a terminal's CR LF ends a line like LF alone */
    }
    if ((c < ' ' && c != '\t') || (unsigned char)c > '~') {
        line_unprintable = true; /* a NUL would also cut the line short unseen */
    } else if (line_used < REQUEST_MAX) {
        line[line_used++] = c;
    } else {
        line_too_long = true;
    }
    return false;
}

void bridge_poll(void)
{
    capture_service();
    /* At most one request, and a bounded number of bytes, per poll: a flood of input cannot keep
     * the loop from draining. */
    for (size_t taken = 0; taken < REQUEST_MAX + 2u; ++taken) {
        const int received = bridge_hal_uart_read();
        if (received < 0 || take_byte((char)received)) {
            return;
        }
    }
}

void bridge_idle(void)
{
    capture_service();
}

bool bridge_capturing(void)
{
    return capture_running();
}
