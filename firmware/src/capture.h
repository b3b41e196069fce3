/*
 * The bridge's own capture (protocol version 2): the FIFO emptied, then the next n samples drained
 * from it into a static buffer as they come, for the host to fetch by index at its leisure.
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
    const uint8_t *samples;      /* `have` samples of BRIDGE_SAMPLE_BYTES */
    uint8_t end_temperature[2];  /* TEMP2, TEMP1 as the last sample came (CAPTURE_COMPLETE) */
    const char *reason;          /* why it ended (CAPTURE_LOST, CAPTURE_FAILED) */
} capture_view;

/* Forget any capture. */
void capture_reset(void);

/* Forget the last capture, then start one of `count` samples (1..BRIDGE_CAPTURE_SAMPLES, checked by
 * the caller). NULL and the start temperature in `temperature`, or why it was refused. */
const char *capture_start(uint32_t count, uint8_t temperature[2]);

/* Drain the FIFO if a capture is running and a drain is due. Does nothing re-entrantly. */
void capture_service(void);

/* End a running capture: `reason` names what the host did that makes it meaningless. */
void capture_stop(const char *reason);

/* The host read STATUS itself while a capture may be running: reading it clears FIFO_OVR, so the
 * capture must look at the bit or it would miss an overflow. */
void capture_saw_status(uint8_t status);

bool capture_running(void);

void capture_get(capture_view *view);

#endif
