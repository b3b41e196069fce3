/*
 * The hardware abstraction the bridge core runs on: everything the core needs from a board.
 *
 * A board (boards/<board>/) or the host build (host/) provides these six functions; the core
 * (src/) provides bridge.h. Nothing else crosses the line, so the core builds freestanding.
 *
 * Threading: the core calls these from one context only (the main loop, through bridge_poll(), and
 * bridge_idle() when a board calls it while waiting). None of them is called from an interrupt.
 */
#ifndef BRIDGE_HAL_H
#define BRIDGE_HAL_H

#include <stddef.h>
#include <stdint.h>

/*
 * One SPI transaction with the sensor (SPI mode 0, MSB first): chip select asserted, `out_len`
 * bytes of `out` clocked out (what comes back meanwhile is discarded), then `in_len` bytes clocked
 * in while zeros go out, then chip select released. Either length may be 0 (`in` may then be NULL).
 *
 * Half duplex on purpose: every access to either part the core knows (ADXL355, ICM-42688-P) is a
 * command byte (and for a write, the value) followed by data read back, so no caller needs the bytes
 * received during the command byte.
 */
void bridge_hal_spi_transfer(const uint8_t *out, size_t out_len, uint8_t *in, size_t in_len);

/* The next byte received from the host (0..255), or -1 if none is waiting. Never blocks. */
int bridge_hal_uart_read(void);

/*
 * Send all `len` bytes to the host. It may wait for room in the transmit buffer; while it waits it
 * should call bridge_idle() (bridge.h), so a capture keeps draining the sensor's FIFO however slowly
 * the host reads. The core never hands it more than BRIDGE_REPLY_CHUNK bytes at a time.
 */
void bridge_hal_uart_write(const uint8_t *bytes, size_t len);

/*
 * Which client holds the line: a number that changes whenever a client closes the port or another opens it
 * (USB CDC: DTR falling or rising; the host build: its pseudo-terminal's client end closed or opened). By the
 * time the number has changed, the HAL has dropped what it still held for the client that went, as far as
 * it can. The core then sends nothing more of that client's reply, and drops the start of its request, so
 * the next client never reads the rest of a reply it did not ask for. A board that cannot tell returns 0.
 */
uint32_t bridge_hal_uart_session(void);

/* A monotonic microsecond clock (its zero is arbitrary). 64 bits: it never wraps in practice. */
uint64_t bridge_hal_micros(void);

/* A short name of the board, shown in the greeting's free text (e.g. "rp2040", "host"). */
const char *bridge_hal_board_name(void);

#endif
