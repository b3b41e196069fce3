/* Reply buffering and number formatting, without libc (no printf, no division). */
#include "reply.h"

#include "bridge.h"
#include "bridge_hal.h"

static uint8_t pending[BRIDGE_REPLY_CHUNK];
static size_t pending_used;
static uint32_t client; /* the HAL's session of the client the reply is for */

void reply_to(uint32_t session)
{
    client = session;
}

static void flush(void)
{
    /* Once the client has gone, the rest of its reply goes nowhere: not to whoever holds the line next (the HAL
     * has dropped what it still held of it). */
    if (pending_used > 0 && bridge_hal_uart_session() == client) {
        bridge_hal_uart_write(pending, pending_used);
    }
    pending_used = 0;
    bridge_idle(); /* a drain is due every millisecond; a chunk may have taken that long */
}

void reply_char(char c)
{
    pending[pending_used++] = (uint8_t)c;
    if (pending_used == sizeof pending) {
        flush();
    }
}

void reply_text(const char *text)
{
    while (*text != '\0') {
        reply_char(*text++);
    }
}

void reply_hex(const uint8_t *bytes, size_t count)
{
    static const char digits[] = "0123456789ABCDEF";

    for (size_t i = 0; i < count; ++i) {
        reply_char(digits[bytes[i] >> 4]);
        reply_char(digits[bytes[i] & 0x0Fu]);
    }
}

/* By subtracting powers of ten: a Cortex-M0+ has no divide instruction, and this is no hot path. */
void reply_decimal(uint32_t value)
{
    static const uint32_t powers[] = {1000000000u, 100000000u, 10000000u, 1000000u, 100000u,
                                      10000u,      1000u,      100u,      10u,      1u};
    int started = 0;

    for (size_t i = 0; i < sizeof powers / sizeof powers[0]; ++i) {
        char digit = '0';
        while (value >= powers[i]) {
            value -= powers[i];
            ++digit;
        }
        if (digit != '0' || started || powers[i] == 1u) {
            reply_char(digit);
            started = 1;
        }
    }
}

void reply_end(void)
{
    reply_char('\n');
    flush();
}

void reply_error(const char *text)
{
    reply_char('!');
    reply_text(text);
    reply_end();
}
