/*
 * Capture: drain the part's FIFO into a static buffer of whole samples, as the part's FIFO gives them.
 *
 * Draining happens from capture_service(), called from the main loop and between reply chunks,
 * every BRIDGE_DRAIN_PERIOD_US. Two FIFOs:
 *
 * ADXL355: each drain reads STATUS and FIFO_ENTRIES in one burst; FIFO_OVR latches until STATUS is read,
 * so seeing it clear at every drain, and once more after the last sample, proves no sample was lost
 * anywhere in the capture. Entries are taken one axis at a time: a sample the part is still writing (X in
 * the FIFO, Y and Z not yet) stays half-built in its slot of the buffer until the next drain brings the rest.
 *
 * ICM-42688-P: the host set the FIFO up (packet 3 of both sensors, stop-on-full); each drain reads
 * INT_STATUS and FIFO_COUNTH/L in one burst from INT_STATUS: FIFO_FULL (cleared by that read) set means a
 * sample may have been dropped since the drain before. Whole 16-byte packets go straight into the buffer,
 * each header checked; packets beyond the count wanted stay in the FIFO. A full FIFO after the last packet
 * wanted drops only later samples: no check after it is needed.
 */
#include "capture.h"

#include "bridge.h"
#include "bridge_hal.h"
#include "sensor.h"

static uint8_t samples[BRIDGE_CAPTURE_BYTES];
static uint8_t fifo_bytes[SENSOR_FIFO_ENTRIES * SENSOR_ENTRY_BYTES];

static struct {
    capture_state state;
    sensor_fifo fifo;
    uint32_t wanted;
    uint32_t have;
    uint8_t axes_of_next; /* ADXL355: entries (0..2) of the sample being built */
    bool synced;          /* ADXL355: an X entry was seen: entries before it belong to a sample from before */
    uint64_t last_drain_us;
    uint8_t end_temperature[2];
    const char *reason;
    bool servicing;
} capture;

/* A refusal or a reason that carries register values ("... (FIFO_CONFIG 00, FIFO_CONFIG1 00)"). */
static char message[96];

static void append(size_t *at, const char *text)
{
    while (*text != '\0' && *at + 1u < sizeof message) {
        message[(*at)++] = *text++;
    }
    message[*at] = '\0';
}

static void append_hex(size_t *at, uint8_t value)
{
    static const char digits[] = "0123456789ABCDEF";
    const char pair[3] = {digits[value >> 4], digits[value & 0x0Fu], '\0'};

    append(at, pair);
}

uint32_t capture_capacity(void)
{
    /* Constant divisions: a Cortex-M0+ has no divide instruction, and the core takes nothing from a runtime. */
    switch (sensor_fifo_kind()) {
    case SENSOR_FIFO_ADXL355:
        return BRIDGE_CAPTURE_BYTES / SENSOR_ADXL_SAMPLE_BYTES;
    case SENSOR_FIFO_ICM42688:
        return BRIDGE_CAPTURE_BYTES / SENSOR_ICM_PACKET_BYTES;
    default:
        return 0u;
    }
}

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

/* ---------------------------------------------------------------- ADXL355 */

/* Read and drop what the FIFO holds now, then read STATUS so a stale FIFO_OVR is cleared. In that
 * order: clearing the flag first would let an overflow of the still-full FIFO set it again. */
static void adxl_empty(void)
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

/* The last sample is in: one more look at FIFO_OVR covers the time since the last drain began. */
static void adxl_finish(void)
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
static void adxl_take_entry(const uint8_t entry[3])
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
    uint8_t *slot = &samples[capture.have * SENSOR_ADXL_SAMPLE_BYTES + capture.axes_of_next * SENSOR_ENTRY_BYTES];
    slot[0] = entry[0];
    slot[1] = entry[1];
    slot[2] = entry[2];
    if (++capture.axes_of_next == 3) {
        capture.axes_of_next = 0;
        if (++capture.have == capture.wanted) {
            adxl_finish();
        }
    }
}

static void adxl_drain(void)
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
        adxl_take_entry(&fifo_bytes[i * SENSOR_ENTRY_BYTES]);
    }
}

/* ---------------------------------------------------------------- ICM-42688-P */

/* Both sensors in low-noise mode, and the FIFO on in packets of both: NULL, or the refusal. */
static const char *icm_not_ready(void)
{
    uint8_t power;
    uint8_t fifo_config;
    uint8_t fifo_config1;

    sensor_read(SENSOR_ICM_REG_PWR_MGMT0, &power, 1);
    if ((power & 0x0Fu) != SENSOR_ICM_PWR_LOW_NOISE) {
        return "capture needs the part measuring";
    }
    sensor_read(SENSOR_ICM_REG_FIFO_CONFIG, &fifo_config, 1);
    sensor_read(SENSOR_ICM_REG_FIFO_CONFIG1, &fifo_config1, 1);
    if ((fifo_config & 0xC0u) != 0u && (fifo_config1 & 0x13u) == 0x03u) {
        return NULL;
    }
    size_t at = 0;
    append(&at, "capture needs the FIFO on with both sensors (FIFO_CONFIG ");
    append_hex(&at, fifo_config);
    append(&at, ", FIFO_CONFIG1 ");
    append_hex(&at, fifo_config1);
    append(&at, ")");
    return message;
}

/* INT_STATUS, then FIFO_COUNT in bytes (COUNTH read first, in the same burst). */
static uint16_t icm_status_and_count(uint8_t *status)
{
    uint8_t burst[3];

    sensor_read(SENSOR_ICM_REG_INT_STATUS, burst, sizeof burst);
    *status = burst[0];
    return (uint16_t)((burst[1] << 8) | burst[2]);
}

/* Flush the FIFO, then read INT_STATUS and the count: a stale FIFO_FULL cleared, and the data sheet's first
 * count after a flush (0) read. */
static void icm_empty(void)
{
    uint8_t status;

    sensor_write(SENSOR_ICM_REG_SIGNAL_PATH_RESET, SENSOR_ICM_FIFO_FLUSH);
    (void)icm_status_and_count(&status);
}

static bool icm_temperature(uint8_t pair[2])
{
    sensor_read(SENSOR_ICM_REG_TEMP_DATA1, pair, 2);
    return true;
}

static void icm_drain(void)
{
    uint8_t status;
    uint32_t packets = icm_status_and_count(&status) / SENSOR_ICM_PACKET_BYTES;

    if (status & SENSOR_ICM_INT_FIFO_FULL) {
        end(CAPTURE_LOST, "FIFO overflowed");
        return;
    }
    if (packets > capture.wanted - capture.have) {
        packets = capture.wanted - capture.have;
    }
    while (packets > 0u && capture.state == CAPTURE_RUNNING) {
        const uint32_t burst = packets < BRIDGE_MAX_READ / SENSOR_ICM_PACKET_BYTES
                                   ? packets : BRIDGE_MAX_READ / SENSOR_ICM_PACKET_BYTES;
        uint8_t *slot = &samples[capture.have * SENSOR_ICM_PACKET_BYTES];
        sensor_read(SENSOR_ICM_REG_FIFO_DATA, slot, burst * SENSOR_ICM_PACKET_BYTES);
        for (uint32_t i = 0; i < burst; ++i) {
            const uint8_t header = slot[i * SENSOR_ICM_PACKET_BYTES];
            if ((header & SENSOR_ICM_PACKET3_MASK) != SENSOR_ICM_PACKET3_HEADER) {
                size_t at = 0;
                append(&at, "FIFO packets out of step (header ");
                append_hex(&at, header);
                append(&at, ")");
                end(CAPTURE_LOST, message);
                return;
            }
        }
        capture.have += burst;
        packets -= burst;
    }
    if (capture.state == CAPTURE_RUNNING && capture.have == capture.wanted) {
        (void)icm_temperature(capture.end_temperature);
        end(CAPTURE_COMPLETE, "");
    }
}

/* ---------------------------------------------------------------- either part */

const char *capture_start(uint32_t count, uint8_t temperature[2])
{
    capture_reset();
    capture.fifo = sensor_fifo_kind();
    if (capture.fifo == SENSOR_FIFO_ICM42688) {
        const char *refusal = icm_not_ready();
        if (refusal != NULL) {
            return refusal;
        }
        icm_empty();
        (void)icm_temperature(temperature);
    } else {
        if (sensor_in_standby()) {
            return "capture needs the part measuring";
        }
        adxl_empty();
        if (!sensor_agreed_temperature(temperature)) {
            return "temperature: TEMP2/TEMP1 did not agree in 10 reads (tearing)";
        }
    }
    capture.wanted = count;
    capture.axes_of_next = 0;
    capture.synced = false;
    capture.last_drain_us = bridge_hal_micros();
    capture.state = CAPTURE_RUNNING;
    return NULL;
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
    if (capture.fifo == SENSOR_FIFO_ICM42688) {
        icm_drain();
    } else {
        adxl_drain();
    }
    capture.servicing = false;
}

void capture_stop(uint8_t address)
{
    if (capture.state == CAPTURE_RUNNING) {
        size_t at = 0;
        append(&at, "capture stopped: register 0x");
        append_hex(&at, address);
        append(&at, " written");
        end(CAPTURE_FAILED, message);
    }
}

void capture_saw_status(uint8_t address, uint32_t count, const uint8_t *data)
{
    if (capture.state != CAPTURE_RUNNING) {
        return;
    }
    const uint8_t status_register =
        capture.fifo == SENSOR_FIFO_ICM42688 ? SENSOR_ICM_REG_INT_STATUS : SENSOR_REG_STATUS;
    const uint8_t overflow = capture.fifo == SENSOR_FIFO_ICM42688 ? SENSOR_ICM_INT_FIFO_FULL : SENSOR_STATUS_FIFO_OVR;
    if (address <= status_register && status_register < address + count && (data[status_register - address] & overflow)) {
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
    view->sample_bytes = sensor_fifo_sample_bytes();
    view->end_temperature[0] = capture.end_temperature[0];
    view->end_temperature[1] = capture.end_temperature[1];
    view->reason = capture.reason;
}
