/* The bridge HAL on POSIX: the host's end of a pseudo-terminal as the UART, the simulated ADXL355
 * (adxl355_model.h) as the SPI bus, CLOCK_MONOTONIC as the microsecond clock. */
#ifndef PTY_HAL_H
#define PTY_HAL_H

#include <stdbool.h>
#include <stddef.h>

/* Opens the pseudo-terminal (both ends raw: no echo, no line editing, no CR/LF translation) and
 * copies the path of the end a serial client opens into `path`. False (errno set) on failure. */
bool pty_hal_open(char *path, size_t path_size);

/* The descriptor to wait on for bytes from the client. */
int pty_hal_fd(void);

/* True if bytes already read from the descriptor wait for bridge_hal_uart_read(). */
bool pty_hal_pending(void);

#endif
