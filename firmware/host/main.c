/*
 * bridge-host: the bridge firmware's core on a PC, in front of a simulated ADXL355 or ICM-42688-P, behind
 * a pseudo-terminal. Prints the terminal's path on the first line of stdout, then serves until it is
 * killed (or, with --exit-with-stdin, until its stdin closes: a parent that dies takes it along).
 */
#define _XOPEN_SOURCE 600

#include <errno.h>
#include <poll.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "adxl355_model.h"
#include "icm42688_model.h"
#include "bridge.h"
#include "bridge_hal.h"
#include "pty_hal.h"

static const char usage[] =
    "usage: bridge-host [--part adxl355|icm42688p|none] [--temperature-c DEGC] [--tear-rate SHARE] [--seed N]\n"
    "                   [--clock monotonic|board] [--spi-log FILE] [--exit-with-stdin]\n"
    "  --part           the simulated part on SPI (default adxl355; none: nothing answers)\n"
    "  --temperature-c  what the simulated part's temperature sensor reads (default 25)\n"
    "  --tear-rate      share 0..1 of TEMP2+TEMP1 reads that tear by 256 LSB (default 0; adxl355 only)\n"
    "  --seed           of the simulated noise (default 1)\n"
    "  --clock          monotonic (default): time as it passes; board: the time a board running only\n"
    "                   this firmware would see (CPU time, sleeps as asked, stops), for a busy PC (Linux)\n"
    "  --spi-log        append every SPI transaction to FILE: sent hex, ':', received hex\n"
    "  --exit-with-stdin  exit when stdin reaches its end\n";

typedef struct {
    model_config model;
    pty_hal_part part;
    const char *spi_log;
    bool exit_with_stdin;
    bool board_clock;
} options;

static bool parse_number(const char *text, double low, double high, double *value)
{
    char *end;

    errno = 0;
    *value = strtod(text, &end);
    return errno == 0 && end != text && *end == '\0' && *value >= low && *value <= high;
}

static bool parse_options(int argc, char **argv, options *parsed)
{
    double number;

    parsed->model.temperature_c = 25.0;
    parsed->model.tear_rate = 0.0;
    parsed->model.seed = 1u;
    parsed->part = PTY_HAL_PART_ADXL355;
    parsed->spi_log = NULL;
    parsed->exit_with_stdin = false;
    parsed->board_clock = false;
    for (int i = 1; i < argc; ++i) {
        const bool has_value = i + 1 < argc;
        if (strcmp(argv[i], "--exit-with-stdin") == 0) {
            parsed->exit_with_stdin = true;
        } else if (strcmp(argv[i], "--part") == 0 && has_value
                   && (strcmp(argv[i + 1], "adxl355") == 0 || strcmp(argv[i + 1], "icm42688p") == 0
                       || strcmp(argv[i + 1], "none") == 0)) {
            parsed->part = strcmp(argv[i + 1], "adxl355") == 0     ? PTY_HAL_PART_ADXL355
                           : strcmp(argv[i + 1], "icm42688p") == 0 ? PTY_HAL_PART_ICM42688P
                                                                   : PTY_HAL_PART_NONE;
            ++i;
        } else if (strcmp(argv[i], "--spi-log") == 0 && has_value) {
            parsed->spi_log = argv[i + 1];
            ++i;
        } else if (strcmp(argv[i], "--clock") == 0 && has_value
                   && (strcmp(argv[i + 1], "monotonic") == 0 || strcmp(argv[i + 1], "board") == 0)) {
            parsed->board_clock = strcmp(argv[i + 1], "board") == 0;
            ++i;
        } else if (strcmp(argv[i], "--temperature-c") == 0 && has_value
                   && parse_number(argv[i + 1], -40.0, 125.0, &number)) {
            parsed->model.temperature_c = number;
            ++i;
        } else if (strcmp(argv[i], "--tear-rate") == 0 && has_value && parse_number(argv[i + 1], 0.0, 1.0, &number)) {
            parsed->model.tear_rate = number;
            ++i;
        } else if (strcmp(argv[i], "--seed") == 0 && has_value && parse_number(argv[i + 1], 0.0, 4294967295.0, &number)
                   && number == (double)(uint32_t)number) {
            parsed->model.seed = (uint32_t)number;
            ++i;
        } else {
            return false;
        }
    }
    return parsed->part == PTY_HAL_PART_ADXL355 || parsed->model.tear_rate == 0.0; /* tears: the ADXL355's */
}

/* Until the next thing to do: bytes from the client, a client opening or closing the port, stdin's end, or
 * (while capturing) the next drain. Returns false once stdin has ended and that is to end the program. */
static bool wait_for_work(bool watch_stdin)
{
    struct pollfd watched[3] = {{pty_hal_fd(), POLLIN, 0}, {pty_hal_clients_fd(), POLLIN, 0}, {STDIN_FILENO, POLLIN, 0}};
    const int timeout_ms = pty_hal_pending() ? 0 : bridge_capturing() ? 1 : 50;

    if (pty_hal_poll(watched, watch_stdin ? 3u : 2u, timeout_ms) > 0 && watch_stdin && watched[2].revents != 0) {
        char discarded[64];
        if (read(STDIN_FILENO, discarded, sizeof discarded) <= 0) {
            return false;
        }
    }
    return true;
}

int main(int argc, char **argv)
{
    options parsed;
    char path[256];

    if (!parse_options(argc, argv, &parsed)) {
        fputs(usage, stderr);
        return 2;
    }
    if (parsed.board_clock && !pty_hal_use_board_clock()) {
        return 1;
    }
    if (!pty_hal_open(path, sizeof path)) {
        perror("bridge-host: pseudo-terminal");
        return 1;
    }
    if (parsed.spi_log != NULL && !pty_hal_log_spi(parsed.spi_log)) {
        perror("bridge-host: --spi-log");
        return 1;
    }
    pty_hal_use_part(parsed.part);
    if (parsed.part == PTY_HAL_PART_ICM42688P) {
        const icm_model_config icm = {parsed.model.temperature_c, parsed.model.seed};
        icm_model_init(&icm, bridge_hal_micros());
    } else {
        model_init(&parsed.model, bridge_hal_micros());
    }
    bridge_init();
    printf("%s\n", path);
    fflush(stdout);
    while (wait_for_work(parsed.exit_with_stdin)) {
        bridge_poll();
    }
    return 0;
}
