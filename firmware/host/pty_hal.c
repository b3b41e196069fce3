/* The bridge HAL on POSIX (see pty_hal.h). */
#define _XOPEN_SOURCE 600

#include "pty_hal.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>
#if defined(__linux__)
#include <sys/inotify.h>
#endif

#include "adxl355_model.h"
#include "icm42688_model.h"
#include "bridge.h"
#include "bridge_hal.h"

static int master = -1;
/* The client's end stays open here too, so the path keeps working between clients: with no slave
 * open, reads of the master fail (EIO) until someone opens it again. */
static int slave = -1;
static uint8_t inbox[512];
static size_t inbox_next;
static size_t inbox_used;
/* The client end's opens and closes by other processes (Linux's inotify on its path; -1: not watched), and
 * how many were seen: the session (bridge_hal_uart_session). */
static int clients = -1;
static uint32_t session;

/* The board clock (pty_hal_use_board_clock): its value at the last mark, and at that mark the monotonic
 * clock, the thread's CPU time and its run_delay (all in microseconds). */
static struct {
    bool on;
    int schedstat; /* /proc/self/schedstat */
    uint64_t now_us;
    uint64_t wall_us;
    uint64_t cpu_us;
    uint64_t waited_us;
    sig_atomic_t continuations; /* SIGCONTs counted at the last mark */
} board = {false, -1, 0, 0, 0, 0, 0};
/* SIGCONTs so far (a stalled board each), counted by the handler. */
static volatile sig_atomic_t continuations;

static bool make_raw(int fd)
{
    struct termios settings;

    if (tcgetattr(fd, &settings) != 0) {
        return false;
    }
    settings.c_iflag &= ~(tcflag_t)(IGNBRK | BRKINT | PARMRK | ISTRIP | INLCR | IGNCR | ICRNL | IXON | IXOFF);
    settings.c_oflag &= ~(tcflag_t)OPOST;
    settings.c_lflag &= ~(tcflag_t)(ECHO | ECHONL | ICANON | ISIG | IEXTEN);
    settings.c_cflag &= ~(tcflag_t)(CSIZE | PARENB);
    settings.c_cflag |= CS8;
    settings.c_cc[VMIN] = 1;
    settings.c_cc[VTIME] = 0;
    return tcsetattr(fd, TCSANOW, &settings) == 0;
}

bool pty_hal_open(char *path, size_t path_size)
{
    master = posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) {
        return false;
    }
    const char *name = ptsname(master);
    if (name == NULL || strlen(name) + 1 > path_size) {
        return false;
    }
    strcpy(path, name);
    slave = open(path, O_RDWR | O_NOCTTY);
    if (slave < 0 || !make_raw(slave) || !make_raw(master)) {
        return false;
    }
    const int flags = fcntl(master, F_GETFL);
    if (flags < 0 || fcntl(master, F_SETFL, flags | O_NONBLOCK) != 0) {
        return false;
    }
#if defined(__linux__)
    /* Watched from here on: this process's own open of the client end above is no client's. */
    clients = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    if (clients >= 0 && inotify_add_watch(clients, path, IN_OPEN | IN_CLOSE) < 0) {
        close(clients);
        clients = -1;
    }
#endif
    return true;
}

int pty_hal_fd(void)
{
    return master;
}

int pty_hal_clients_fd(void)
{
    return clients;
}

/* Takes the opens and closes of the client end seen since the last look. On any, a new session begins, and
 * what the client end still holds unread from us is dropped: it was for the client that went. (What a client
 * sent and we have not read yet is kept: it may be the next client's first request.) */
static void notice_clients(void)
{
#if defined(__linux__)
    union { /* room for many events, aligned for them */
        struct inotify_event event;
        char bytes[16 * sizeof(struct inotify_event)];
    } events;
    bool changed = false;

    while (clients >= 0 && read(clients, events.bytes, sizeof events.bytes) > 0) {
        changed = true;
    }
    if (changed) {
        ++session;
        (void)tcflush(slave, TCIFLUSH);
        printf("session %lu\n", (unsigned long)session); /* for tests that wait until the bridge saw a client go */
        (void)fflush(stdout);
    }
#endif
}

uint32_t bridge_hal_uart_session(void)
{
    notice_clients();
    return session;
}

bool pty_hal_pending(void)
{
    return inbox_next < inbox_used;
}

int bridge_hal_uart_read(void)
{
    notice_clients(); /* a client's coming or going is taken before any byte it sent after */
    if (inbox_next == inbox_used) {
        const ssize_t got = read(master, inbox, sizeof inbox);
        if (got <= 0) {
            return -1; /* nothing waiting (EAGAIN), or no client (EIO): the same to the core */
        }
        inbox_next = 0;
        inbox_used = (size_t)got;
    }
    return inbox[inbox_next++];
}

static uint64_t clock_us(clockid_t clock)
{
    struct timespec now;

    clock_gettime(clock, &now);
    return (uint64_t)now.tv_sec * 1000000u + (uint64_t)now.tv_nsec / 1000u;
}

/* The process's run_delay: how long it has waited, runnable, for a CPU. The second of the three numbers
 * in /proc/<pid>/schedstat (nanoseconds), which is up to date while the process runs; re-read from the
 * start on every call (the file is made afresh). */
static bool read_waited_us(uint64_t *waited)
{
    char text[128];
    const ssize_t got = pread(board.schedstat, text, sizeof text - 1u, 0);

    if (got <= 0) {
        return false;
    }
    text[got] = '\0';
    char *end;
    char *after;
    errno = 0;
    (void)strtoull(text, &end, 10);
    const unsigned long long run_delay_ns = strtoull(end, &after, 10);
    if (errno != 0 || after == end) {
        return false;
    }
    *waited = (uint64_t)(run_delay_ns / 1000u);
    return true;
}

/* The wall clock, and the SIGCONTs counted when it was read: every one of them came before the reading, every
 * later one after it. (A SIGCONT between the reading and the look at the count would otherwise be taken for a
 * stop inside an interval that ended before it, and the stop's time counted in none.) */
static uint64_t wall_after_continuations(sig_atomic_t *seen)
{
    for (;;) {
        const sig_atomic_t before = continuations;
        const uint64_t wall = clock_us(CLOCK_MONOTONIC);
        if (continuations == before) {
            *seen = before;
            return wall;
        }
    }
}

/* Moves the board clock on to now. The time since the last mark counts as the CPU time used in it, plus
 * (for a sleep asked to last at most `sleep_limit_us`; none: -1) the time asleep up to that limit, plus
 * all the time neither running nor waiting for a CPU if the process was stopped meanwhile. */
static void mark_board_clock(int64_t sleep_limit_us)
{
    sig_atomic_t seen;
    const uint64_t wall = wall_after_continuations(&seen);
    const uint64_t cpu = clock_us(CLOCK_THREAD_CPUTIME_ID);
    uint64_t waited = board.waited_us;
    (void)read_waited_us(&waited); /* on a failed read, no waiting is seen */

    const uint64_t cpu_used = cpu - board.cpu_us;
    const uint64_t not_idle = cpu_used + (waited - board.waited_us);
    const uint64_t idle = wall - board.wall_us > not_idle ? wall - board.wall_us - not_idle : 0u;
    uint64_t counted = cpu_used;
    if (seen != board.continuations) {
        counted += idle;
    } else if (sleep_limit_us > 0) {
        counted += idle < (uint64_t)sleep_limit_us ? idle : (uint64_t)sleep_limit_us;
    }
    board.now_us += counted;
    board.wall_us = wall;
    board.cpu_us = cpu;
    board.waited_us = waited;
    board.continuations = seen;
}

static void on_continue(int signal_number)
{
    (void)signal_number;
    ++continuations;
}

bool pty_hal_use_board_clock(void)
{
    struct sigaction action;

    memset(&action, 0, sizeof action);
    action.sa_handler = on_continue;
    sigemptyset(&action.sa_mask);
    board.schedstat = open("/proc/self/schedstat", O_RDONLY);
    if (board.schedstat < 0 || !read_waited_us(&board.waited_us) || sigaction(SIGCONT, &action, NULL) != 0) {
        fputs("bridge-host: --clock board needs a readable /proc/self/schedstat (Linux)\n", stderr);
        return false;
    }
    board.now_us = board.wall_us = clock_us(CLOCK_MONOTONIC);
    board.cpu_us = clock_us(CLOCK_THREAD_CPUTIME_ID);
    board.on = true;
    return true;
}

int pty_hal_poll(struct pollfd *fds, nfds_t count, int timeout_ms)
{
    if (board.on) {
        mark_board_clock(-1);
    }
    const int ready = poll(fds, count, timeout_ms);
    if (board.on) {
        mark_board_clock(timeout_ms < 0 ? INT64_MAX : (int64_t)timeout_ms * 1000);
    }
    return ready;
}

void bridge_hal_uart_write(const uint8_t *bytes, size_t len)
{
    /* The session as the caller last saw it, not a fresh look: a client's going noticed here would flush the
     * port and then send these bytes, the rest of its reply, to whoever opens it next. What is written before
     * the next look is dropped by that look's flush. */
    const uint32_t client = session;

    while (len > 0) {
        const ssize_t sent = write(master, bytes, len);
        if (sent > 0) {
            bytes += sent;
            len -= (size_t)sent;
        } else if (sent < 0 && (errno == EAGAIN || errno == EINTR)) {
            /* The client is not reading fast enough: wait for room, keeping the capture drained, unless the
             * client goes meanwhile (it closed the port, with the rest of the reply unread). */
            struct pollfd room[2] = {{master, POLLOUT, 0}, {clients, POLLIN, 0}};
            (void)pty_hal_poll(room, 2, 1);
            bridge_idle();
            if (bridge_hal_uart_session() != client) {
                return;
            }
        } else {
            return; /* the terminal is gone: nobody to tell */
        }
    }
}

uint64_t bridge_hal_micros(void)
{
    if (!board.on) {
        return clock_us(CLOCK_MONOTONIC);
    }
    mark_board_clock(-1);
    return board.now_us;
}

static pty_hal_part bus_part = PTY_HAL_PART_ADXL355;
static FILE *spi_log;

void pty_hal_use_part(pty_hal_part part)
{
    bus_part = part;
}

bool pty_hal_log_spi(const char *path)
{
    spi_log = fopen(path, "a");
    return spi_log != NULL;
}

static void log_bytes(const uint8_t *bytes, size_t len)
{
    for (size_t i = 0; i < len; ++i) {
        fprintf(spi_log, "%02X", bytes[i]);
    }
}

void bridge_hal_spi_transfer(const uint8_t *out, size_t out_len, uint8_t *in, size_t in_len)
{
    const uint64_t now = bridge_hal_micros();

    switch (bus_part) {
    case PTY_HAL_PART_ADXL355:
        model_spi(out, out_len, in, in_len, now);
        break;
    case PTY_HAL_PART_ICM42688P:
        icm_model_spi(out, out_len, in, in_len, now);
        break;
    case PTY_HAL_PART_NONE:
        if (in_len > 0) {
            memset(in, 0, in_len);
        }
        break;
    }
    if (spi_log != NULL) {
        log_bytes(out, out_len);
        fputc(':', spi_log);
        log_bytes(in, in_len);
        fputc('\n', spi_log);
        fflush(spi_log);
    }
}

const char *bridge_hal_board_name(void)
{
    return "host";
}
