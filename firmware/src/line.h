/*
 * The request line, assembled from the HAL's bytes by the protocol's line rules (docs/instruments.md, "The
 * serial bridge protocol"): a line ends at LF; a CR is dropped wherever it is; more than BRIDGE_LINE_MAX bytes
 * (CRs aside) make it too long, and a byte outside printable ASCII (0x20..0x7E) makes it unprintable, and either
 * is answered once, when its LF comes. The start of a line is dropped when its client goes (the HAL's session
 * changes) or leaves it without its LF for a second.
 */
#ifndef LINE_H
#define LINE_H

#include <stddef.h>
#include <stdint.h>

typedef enum {
    LINE_INCOMPLETE,  /* no line has ended (no byte waiting, or no LF yet) */
    LINE_REQUEST,     /* a line to answer: line_text() */
    LINE_TOO_LONG,    /* more than BRIDGE_LINE_MAX bytes before its LF */
    LINE_UNPRINTABLE  /* a byte that is not printable ASCII */
} line_status;

/* Forget the line begun. */
void line_forget(void);

/* Take bytes from the HAL, at most `budget`, until a line ends; what ended. */
line_status line_take(size_t budget);

/* The line that ended as LINE_REQUEST, NUL-terminated, without its CRs and LF (split in place by its reader);
 * good until the next line_take. */
char *line_text(void);

/* The HAL's session (bridge_hal_uart_session) as the line that ended began: the client its reply is for. */
uint32_t line_session(void);

#endif
