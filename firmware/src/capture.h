/*
 * The bridge's own capture (protocol version 2): the FIFO emptied, then the next n samples drained
 * from it into a static buffer as they come, for the host to fetch by index at its leisure. The buffer's
 * bytes are fixed (BRIDGE_CAPTURE_BYTES); how many samples that is depends on the part's FIFO.
 */
#ifndef CAPTURE_H
#define CAPTURE_H

#include <stdbool.h>
#include <stdint.h>

typedef enum {
    CAPTURE_NONE,     /* no capture since start-up, or the last `C` was refused */
    CAPTURE_RUNNING,  /* draining the FIFO */
    CAPTURE_COMPLETE, /* all samples in, end temperature read */
    CAPTURE_LOST,     /* samples were lost (FIFO overflow, or its entries out of step): ended */
    CAPTURE_FAILED    /* ended otherwise (see the reason): the end temperature, a reconfiguration */
} capture_state;

/* What a fetch needs to know, as of now. */
typedef struct {
    capture_state state;
    uint32_t have;               /* whole samples in the buffer */
    uint32_t wanted;
    const uint8_t *samples;      /* `have` samples of `sample_bytes` each, as the part's FIFO gives them */
    uint32_t sample_bytes;
    uint8_t end_temperature[2];  /* the part's temperature registers as the last sample came (CAPTURE_COMPLETE) */
    const char *reason;          /* why it ended (CAPTURE_LOST, CAPTURE_FAILED) */
} capture_view;

/* Forget any capture. */
void capture_reset(void);

/* The most samples a capture of the part found holds: the buffer's bytes over its sample's (0: no capture). */
uint32_t capture_capacity(void);

/* Forget the last capture, then start one of `count` samples (1..capture_capacity(), checked by the
 * caller). NULL and the start temperature in `temperature`, or why it was refused. */
const char *capture_start(uint32_t count, uint8_t temperature[2]);

/* Drain the FIFO if a capture is running and a drain is due. Does nothing re-entrantly. */
void capture_service(void);

/* End a running capture: the host wrote `address`, which changes what the FIFO holds. */
void capture_stop(uint8_t address);

/* The host read `count` registers from `address` itself while a capture may be running: where they cover the
 * part's status register (the ADXL355's STATUS, the ICM-42688-P's INT_STATUS) the read cleared its overflow
 * flag, so the capture must look at the bit or it would miss an overflow. */
void capture_saw_status(uint8_t address, uint32_t count, const uint8_t *data);

bool capture_running(void);

void capture_get(capture_view *view);

#endif
