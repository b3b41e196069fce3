/*
 * The sensor serial bridge, protocol version 3: the core's entry points for a board's main loop.
 *
 * The protocol (one ASCII request per line, one reply per request, lines end in '\n'):
 *   ?              -> ADXL355-BRIDGE 3 part=<part> [capture=<samples>] <text>
 *                     part: adxl355, icm42688p (found on SPI by its identity register), or none
 *   R <addr> <n>   -> =<2n hex digits>     n registers from addr in one SPI burst, framed for the part
 *   W <addr> <v>   -> =                    one register
 *   C <n>          -> =<T high><T low>     empty the FIFO, capture the next n samples
 *   G <first>      -> =<hex>[T<T high><T low>]  captured samples from index first on, as the part's FIFO
 *                     gives them (adxl355: 9 bytes each, capture=4096; icm42688p: 16-byte packets, capture=2304)
 *   anything that fails -> !<message>
 * addr and v are hexadecimal, n and first decimal. What each request that fails is answered, and the line
 * rules: docs/instruments.md, "The serial bridge protocol".
 */
#ifndef BRIDGE_H
#define BRIDGE_H

#include <stdbool.h>

#define BRIDGE_PROTOCOL_VERSION 3
#define BRIDGE_FIRMWARE_VERSION "1.3"

/* The capture buffer, 36 kB: 4096 ADXL355 samples of 9 bytes (X, Y, Z FIFO entries of 3 bytes), or 2304
 * ICM-42688-P packets of 16 bytes. */
#define BRIDGE_CAPTURE_BYTES 36864u

/* The longest register burst `R` takes: the whole FIFO, 96 entries of 3 bytes. */
#define BRIDGE_MAX_READ 288u

/* The longest request line, in bytes before its LF (CRs aside): the longest request ("R 7F 288") is 8, so
 * this leaves room for stray spaces and leading zeros; a longer line is refused. */
#define BRIDGE_LINE_MAX 64u

/* Replies go to the HAL in pieces this long, with the capture serviced between them (64: one USB
 * full-speed packet). */
#ifndef BRIDGE_REPLY_CHUNK
#define BRIDGE_REPLY_CHUNK 64u
#endif

/* How often a capture drains the FIFO. The FIFO holds 32 samples: 8 ms at 4 kHz, the fastest rate,
 * so 1 ms leaves seven eighths of it as margin for a slow reply chunk or a long request. */
#ifndef BRIDGE_DRAIN_PERIOD_US
#define BRIDGE_DRAIN_PERIOD_US 1000u
#endif

/* Forget any capture and partial request. Call once before the first bridge_poll(). */
void bridge_init(void);

/* Do what is due: drain the FIFO if a capture is running and the drain period has passed, then
 * read what the host has sent and answer a complete request. Call it from the main loop, often. */
void bridge_poll(void);

/* Service a running capture only (never reads or answers the host). Safe to call from inside
 * bridge_hal_uart_write() while it waits for room; it does nothing when called re-entrantly. */
void bridge_idle(void);

/* True while a capture is running: a main loop may sleep between polls only when this is false. */
bool bridge_capturing(void);

#endif
