/*
 * Capture: drain the ADXL355's FIFO into a static buffer of whole X, Y, Z samples.
 *
 * Draining happens from capture_service(), called from the main loop and between reply chunks,
 * every BRIDGE_DRAIN_PERIOD_US. Each drain reads STATUS and FIFO_ENTRIES in one burst; FIFO_OVR
 * latches until STATUS is read, so seeing it clear at every drain, and once more after the last
 * sample, proves no sample was lost anywhere in the capture. Entries are taken one axis at a time:
 * a sample the part is still writing (X in the FIFO, Y and Z not yet) stays half-built in its slot
 * of the buffer until the next drain brings the rest.
 */
#include "capture.h"

#include "bridge.h"
#include "bridge_hal.h"
#include "sensor.h"

static uint8_t samples[BRIDGE_CAPTURE_SAMPLES * BRIDGE_SAMPLE_BYTES];
static uint8_t fifo_bytes[SENSOR_FIFO_ENTRIES * SENSOR_ENTRY_BYTES];

static struct {
    capture_state state;
    uint32_t wanted;
    uint32_t have;
    uint8_t axes_of_next; /* entries (0..2) of the sample being built */
    bool synced;          /* an X entry was seen: entries before it belong to a sample from before */
    uint64_t last_drain_us;
    uint8_t end_temperature[2];
    const char *reason;
    bool servicing;
} capture;

void capture_reset(void)
{
    capture.state = CAPTURE_NONE;
    capture.have = 0;
    capture.wanted = 0;
    capture.reason = "";
}

static void end(capture_state state, const char *reason)
{
    capture.state = state;
    capture.reason = reason;
}

/* Read and drop what the FIFO holds now, then read STATUS so a stale FIFO_OVR is cleared. In that
 * order: clearing the flag first would let an overflow of the still-full FIFO set it again. */
static void empty_fifo(void)
{
    uint8_t entries;

    sensor_read(SENSOR_REG_FIFO_ENTRIES, &entries, 1);
    entries &= 0x7Fu;
    if (entries > SENSOR_FIFO_ENTRIES) {
        entries = SENSOR_FIFO_ENTRIES;
    }
    if (entries > 0) {
        sensor_read(SENSOR_REG_FIFO_DATA, fifo_bytes, (size_t)entries * SENSOR_ENTRY_BYTES);
    }
    uint8_t status;
    sensor_read(SENSOR_REG_STATUS, &status, 1);
}

const char *capture_start(uint32_t count, uint8_t temperature[2])
{
    capture_reset();
    if (sensor_in_standby()) {
        return "capture needs the part measuring";
    }
    empty_fifo();
    if (!sensor_agreed_temperature(temperature)) {
        return "temperature: TEMP2/TEMP1 did not agree in 10 reads (tearing)";
    }
    capture.wanted = count;
    capture.axes_of_next = 0;
    capture.synced = false;
    capture.last_drain_us = bridge_hal_micros();
    capture.state = CAPTURE_RUNNING;
    return NULL;
}

/* The last sample is in: one more look at FIFO_OVR covers the time since the last drain began. */
static void finish(void)
{
    uint8_t status;

    sensor_read(SENSOR_REG_STATUS, &status, 1);
    if (status & SENSOR_STATUS_FIFO_OVR) {
        end(CAPTURE_LOST, "FIFO overflowed");
    } else if (!sensor_agreed_temperature(capture.end_temperature)) {
        end(CAPTURE_FAILED, "end temperature: TEMP2/TEMP1 did not agree in 10 reads (tearing)");
    } else {
        end(CAPTURE_COMPLETE, "");
    }
}

/* One FIFO entry (one axis) into the sample being built. */
static void take_entry(const uint8_t entry[3])
{
    const bool is_x = (entry[2] & SENSOR_ENTRY_X_MARKER) != 0;

    if (entry[2] & SENSOR_ENTRY_EMPTY) {
        return; /* read past the data: nothing there */
    }
    if (!capture.synced && !is_x) {
        return; /* the rest of a sample begun before the capture */
    }
    if (is_x != (capture.axes_of_next == 0)) {
        end(CAPTURE_LOST, "FIFO entries out of step (X marker)");
        return;
    }
    capture.synced = true;
    uint8_t *slot = &samples[capture.have * BRIDGE_SAMPLE_BYTES + capture.axes_of_next * SENSOR_ENTRY_BYTES];
    slot[0] = entry[0];
    slot[1] = entry[1];
    slot[2] = entry[2];
    if (++capture.axes_of_next == 3) {
        capture.axes_of_next = 0;
        if (++capture.have == capture.wanted) {
            finish();
        }
    }
}

static void drain(void)
{
    uint8_t status_and_entries[2];

    sensor_read(SENSOR_REG_STATUS, status_and_entries, sizeof status_and_entries);
    if (status_and_entries[0] & SENSOR_STATUS_FIFO_OVR) {
        end(CAPTURE_LOST, "FIFO overflowed");
        return;
    }
    size_t entries = status_and_entries[1] & 0x7Fu;
    if (entries > SENSOR_FIFO_ENTRIES) {
        entries = SENSOR_FIFO_ENTRIES;
    }
    if (entries == 0) {
        return;
    }
    sensor_read(SENSOR_REG_FIFO_DATA, fifo_bytes, entries * SENSOR_ENTRY_BYTES);
    for (size_t i = 0; i < entries && capture.state == CAPTURE_RUNNING; ++i) {
        take_entry(&fifo_bytes[i * SENSOR_ENTRY_BYTES]);
    }
}

void capture_service(void)
{
    if (capture.state != CAPTURE_RUNNING || capture.servicing) {
        return;
    }
    const uint64_t now = bridge_hal_micros();
    if (now - capture.last_drain_us < BRIDGE_DRAIN_PERIOD_US) {
        return;
    }
    capture.servicing = true;
    capture.last_drain_us = now;
    drain();
    capture.servicing = false;
}

void capture_stop(const char *reason)
{
    if (capture.state == CAPTURE_RUNNING) {
        end(CAPTURE_FAILED, reason);
    }
}

void capture_saw_status(uint8_t status)
{
    if (capture.state == CAPTURE_RUNNING && (status & SENSOR_STATUS_FIFO_OVR)) {
        end(CAPTURE_LOST, "FIFO overflowed");
    }
}

bool capture_running(void)
{
    return capture.state == CAPTURE_RUNNING;
}

void capture_get(capture_view *view)
{
    view->state = capture.state;
    view->have = capture.have;
    view->wanted = capture.wanted;
    view->samples = samples;
    view->end_temperature[0] = capture.end_temperature[0];
    view->end_temperature[1] = capture.end_temperature[1];
    view->reason = capture.reason;
}
