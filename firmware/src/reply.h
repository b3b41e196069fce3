/*
 * Building a reply line: text, hex and decimal go into a small buffer that is handed to the HAL a
 * chunk at a time, servicing the capture between chunks, so a reply of 73 kB (a whole capture in
 * hex) never keeps the FIFO from being drained.
 */
#ifndef REPLY_H
#define REPLY_H

#include <stddef.h>
#include <stdint.h>

/* The replies from now on are for the client of the HAL's `session` (bridge_hal_uart_session): once the session
 * differs (that client went away), nothing more of them is sent. */
void reply_to(uint32_t session);
void reply_char(char c);
void reply_text(const char *text);
/* Each byte as two upper-case hex digits. */
void reply_hex(const uint8_t *bytes, size_t count);
void reply_decimal(uint32_t value);
/* The line's '\n', and everything still buffered sent. */
void reply_end(void);
/* A whole error reply: "!<text>\n". */
void reply_error(const char *text);

#endif
