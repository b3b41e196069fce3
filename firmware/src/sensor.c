/* The ADXL355's SPI framing and the agreed temperature read. */
#include "sensor.h"

#include "bridge_hal.h"

void sensor_read(uint8_t address, uint8_t *dst, size_t count)
{
    const uint8_t command = (uint8_t)((address << 1) | 1u);

    bridge_hal_spi_transfer(&command, 1, dst, count);
}

void sensor_write(uint8_t address, uint8_t value)
{
    const uint8_t frame[2] = {(uint8_t)(address << 1), value};

    bridge_hal_spi_transfer(frame, sizeof frame, NULL, 0);
}

/* TEMP2 carries bits 11..8 in its low nibble (the high nibble is reserved), TEMP1 bits 7..0. */
static uint16_t raw_temperature(const uint8_t pair[2])
{
    return (uint16_t)(((pair[0] & 0x0Fu) << 8) | pair[1]);
}

static bool agree(uint16_t a, uint16_t b)
{
    const uint16_t difference = a > b ? (uint16_t)(a - b) : (uint16_t)(b - a);

    return difference <= SENSOR_TEMPERATURE_AGREE_LSB;
}

/*
 * TEMP2 and TEMP1 are not double-buffered: a burst can straddle an update that carries into the
 * high nibble and come back 256 LSB (~28 degC) off. Two reads in a row that agree cannot both have
 * torn the same way except by a rare coincidence; keep the later, as the host driver does.
 */
bool sensor_agreed_temperature(uint8_t pair[2])
{
    uint8_t reading[2];
    uint16_t previous = 0;

    for (unsigned read = 0; read < SENSOR_TEMPERATURE_READS; ++read) {
        sensor_read(SENSOR_REG_TEMP2, reading, sizeof reading);
        const uint16_t raw = raw_temperature(reading);
        if (read > 0 && agree(raw, previous)) {
            pair[0] = reading[0];
            pair[1] = reading[1];
            return true;
        }
        previous = raw;
    }
    return false;
}
