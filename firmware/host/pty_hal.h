/* The bridge HAL on POSIX: the host's end of a pseudo-terminal as the UART, a simulated part as the SPI
 * bus (the ADXL355 of adxl355_model.h, the ICM-42688-P of icm42688_model.h, or nothing), CLOCK_MONOTONIC
 * as the microsecond clock (or the board clock: see pty_hal_use_board_clock), and on Linux the opens and
 * closes of the pseudo-terminal's client end as the session (a client coming or going, as DTR on a board). */
#ifndef PTY_HAL_H
#define PTY_HAL_H

#include <poll.h>
#include <stdbool.h>
#include <stddef.h>

/* What sits on the simulated SPI bus. */
typedef enum {
    PTY_HAL_PART_ADXL355,   /* adxl355_model.h (the default) */
    PTY_HAL_PART_ICM42688P, /* icm42688_model.h */
    PTY_HAL_PART_NONE       /* nothing: every byte read is 0x00 */
} pty_hal_part;

/* The part the SPI transfers go to (its model initialised by the caller). */
void pty_hal_use_part(pty_hal_part part);

/* Appends every SPI transaction to the file at `path`, one line each, flushed: the bytes sent, a colon,
 * the bytes received, both in upper-case hex (a read of WHO_AM_I: "F5:47"; a write: "4E0F:").
 * False (errno set) if the file cannot be opened. */
bool pty_hal_log_spi(const char *path);

/* Opens the pseudo-terminal (both ends raw: no echo, no line editing, no CR/LF translation) and
 * copies the path of the end a serial client opens into `path`. False (errno set) on failure. */
bool pty_hal_open(char *path, size_t path_size);

/* The descriptor to wait on for bytes from the client. */
int pty_hal_fd(void);

/* The descriptor to wait on for the client end being opened or closed by another process (Linux's inotify;
 * -1 where it is not watched, which poll() ignores). bridge_hal_uart_session() counts those, and on each drops
 * what the client end still holds unread from the bridge. */
int pty_hal_clients_fd(void);

/* From now on, bridge_hal_micros() (the core's clock, and so the model's) is the board clock: the time
 * a board running only this firmware would have seen. It moves on by the CPU time the process uses, by
 * each sleep in pty_hal_poll up to the timeout it asked for, and by the whole time the process was
 * stopped (SIGSTOP: a stalled board); not by the time it waited for a CPU (Linux's run_delay, from
 * /proc/self/schedstat), nor by a sleep's overrun (a late timer, a virtual machine's stolen time). On a
 * busy PC the process can wait longer than the FIFO lasts (8 ms at 4 kHz), and on CLOCK_MONOTONIC the
 * model would then lose samples no board would lose. It never runs ahead of CLOCK_MONOTONIC.
 * False (and a message on stderr) if /proc/self/schedstat cannot be read. */
bool pty_hal_use_board_clock(void);

/* poll(), and on the board clock, a sleep that counts for `timeout_ms` at most. */
int pty_hal_poll(struct pollfd *fds, nfds_t count, int timeout_ms);

/* True if bytes already read from the descriptor wait for bridge_hal_uart_read(). */
bool pty_hal_pending(void);

#endif
