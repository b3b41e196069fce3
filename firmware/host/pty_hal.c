/* The bridge HAL on POSIX (see pty_hal.h). */
#define _XOPEN_SOURCE 600

#include "pty_hal.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "adxl355_model.h"
#include "bridge.h"
#include "bridge_hal.h"

static int master = -1;
/* The client's end stays open here too, so the path keeps working between clients: with no slave
 * open, reads of the master fail (EIO) until someone opens it again. */
static int slave = -1;
static uint8_t inbox[512];
static size_t inbox_next;
static size_t inbox_used;

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
    return flags >= 0 && fcntl(master, F_SETFL, flags | O_NONBLOCK) == 0;
}

int pty_hal_fd(void)
{
    return master;
}

bool pty_hal_pending(void)
{
    return inbox_next < inbox_used;
}

int bridge_hal_uart_read(void)
{
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

void bridge_hal_uart_write(const uint8_t *bytes, size_t len)
{
    while (len > 0) {
        const ssize_t sent = write(master, bytes, len);
        if (sent > 0) {
            bytes += sent;
            len -= (size_t)sent;
        } else if (sent < 0 && (errno == EAGAIN || errno == EINTR)) {
            /* The client is not reading fast enough: wait for room, keeping the capture drained. */
            struct pollfd room = {master, POLLOUT, 0};
            (void)poll(&room, 1, 1);
            bridge_idle();
        } else {
            return; /* the terminal is gone: nobody to tell */
        }
    }
}

uint64_t bridge_hal_micros(void)
{
    struct timespec now;

    clock_gettime(CLOCK_MONOTONIC, &now);
    return (uint64_t)now.tv_sec * 1000000u + (uint64_t)now.tv_nsec / 1000u;
}

void bridge_hal_spi_transfer(const uint8_t *out, size_t out_len, uint8_t *in, size_t in_len)
{
    model_spi(out, out_len, in, in_len, bridge_hal_micros());
}

const char *bridge_hal_board_name(void)
{
    return "host";
}
