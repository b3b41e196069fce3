/* The request line from the HAL's bytes (see line.h for its rules). */
#include "line.h"

#include <stdbool.h>

#include "bridge.h"
#include "bridge_hal.h"

/* A host writes a request in one go: the start of a line left this long without its end is a previous
 * client's, or noise from plugging in, and would spoil the next client's first request. */
#define STALE_LINE_US 1000000u

static char text[BRIDGE_LINE_MAX + 1];
static size_t length; /* bytes so far, CRs aside; stored up to BRIDGE_LINE_MAX, counted up to one more */
static bool unprintable;
static uint32_t session;
static uint64_t last_byte_us;

void line_forget(void)
{
    length = 0;
    unprintable = false;
}

static line_status take_byte(uint8_t byte)
{
    const uint64_t now = bridge_hal_micros();
    const uint32_t client = bridge_hal_uart_session();

    if (length > 0 && (client != session || now - last_byte_us > STALE_LINE_US)) {
        line_forget(); /* the start of a line whose client went away, or left it */
    }
    if (length == 0) {
        session = client;
    }
    last_byte_us = now;
    if (byte == '\n') {
        const line_status status = length > BRIDGE_LINE_MAX ? LINE_TOO_LONG
                                   : unprintable            ? LINE_UNPRINTABLE
                                                            : LINE_REQUEST;
        text[length > BRIDGE_LINE_MAX ? BRIDGE_LINE_MAX : length] = '\0';
        line_forget();
        return status;
    }
    if (byte == '\r') {
        return LINE_INCOMPLETE; /* a terminal's CR LF ends a line like LF alone */
    }
    if (byte < ' ' || byte > '~') {
        unprintable = true; /* a NUL would also cut the line short unseen */
    }
    if (length < BRIDGE_LINE_MAX) {
        text[length] = (char)byte;
    }
    if (length <= BRIDGE_LINE_MAX) {
        ++length;
    }
    return LINE_INCOMPLETE;
}

line_status line_take(size_t budget)
{
    for (size_t taken = 0; taken < budget; ++taken) {
        const int received = bridge_hal_uart_read();
        if (received < 0) {
            return LINE_INCOMPLETE;
        }
        const line_status status = take_byte((uint8_t)received);
        if (status != LINE_INCOMPLETE) {
            return status;
        }
    }
    return LINE_INCOMPLETE;
}

char *line_text(void)
{
    return text;
}

uint32_t line_session(void)
{
    return session;
}
