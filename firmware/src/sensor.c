/* The parts the bridge knows, their SPI framing, and the ADXL355's agreed temperature read. */
#include "sensor.h"

#include "bridge_hal.h"

/* No register: a part's unused entry in its lists below (addresses are 7 bits). */
#define NONE 0xFFu

/* Registers first..last. */
typedef struct {
    uint8_t first;
    uint8_t last;
} register_span;

/*
 * One part: how a register access is framed (the command byte is (address << shift) | read_flag for a
 * read, address << shift for a write, then the value), the register and value that identify it, the
 * bank select register written 0 before probing again (0: the part has no banks), whether the bridge
 * captures blocks of it (C and G: the ADXL355's FIFO), and its register map as the bridge enforces it:
 * its last register, the register a burst does not move on from, bank 0's read-only registers, and the
 * registers written only in standby with the power register and bit that say so.
 */
typedef struct {
    sensor_identity identity;
    sensor_fifo fifo;
    uint8_t stream_registers[9]; /* writes that end a running capture (NONE: unused) */
    uint8_t shift;
    uint8_t read_flag;
    uint8_t identity_register;
    uint8_t identity_value;
    uint8_t bank_select;
    uint8_t last_register;
    uint8_t burst_stays;
    register_span read_only[2];
    uint8_t standby_only[2];
    uint8_t power_register;
    uint8_t standby_bit;
} sensor_part_entry;

/*
 * Probed in this order (see sensor_detect in sensor.h). The register facts: the ADXL355's from its data sheet's
 * map (docs/instruments.md; RESET 0x2F is its last register, 0x00..0x1D are identity, status, data, FIFO_DATA
 * and reserved, RANGE and FILTER change only in standby); the ICM-42688-P's as the project models bank 0
 * (accelcal_rig/instruments/icm42688.py: TEMP_DATA1..INT_STATUS and WHO_AM_I read-only; the whole 7-bit
 * address space, as its data sheet's map pages were not read).
 */
static const sensor_part_entry parts[] = {
    {{"icm42688p", true, true}, SENSOR_FIFO_ICM42688,
     {SENSOR_ICM_REG_DEVICE_CONFIG, SENSOR_ICM_REG_FIFO_CONFIG, SENSOR_ICM_REG_SIGNAL_PATH_RESET,
      SENSOR_ICM_REG_INTF_CONFIG0, SENSOR_ICM_REG_PWR_MGMT0, SENSOR_ICM_REG_GYRO_CONFIG0, SENSOR_ICM_REG_ACCEL_CONFIG0,
      SENSOR_ICM_REG_FIFO_CONFIG1, SENSOR_ICM_REG_BANK_SEL},
     0u, 0x80u, 0x75u, 0x47u, 0x76u, /* WHO_AM_I; REG_BANK_SEL */
     0x7Fu, SENSOR_ICM_REG_FIFO_DATA, {{0x1Du, SENSOR_ICM_REG_FIFO_DATA}, {0x75u, 0x75u}}, {NONE, NONE}, NONE, 0u},
    {{"adxl355", true, true}, SENSOR_FIFO_ADXL355,
     {SENSOR_REG_FIFO_SAMPLES, SENSOR_REG_POWER_CTL, SENSOR_REG_RESET, NONE, NONE, NONE, NONE, NONE, NONE},
     1u, 0x01u, 0x00u, 0xADu, 0x00u, /* DEVID_AD */
     0x2Fu, SENSOR_REG_FIFO_DATA, {{0x00u, 0x1Du}, {NONE, NONE}},
     {SENSOR_REG_FILTER, SENSOR_REG_RANGE}, SENSOR_REG_POWER_CTL, SENSOR_POWER_CTL_STANDBY},
};
#define PART_COUNT (sizeof parts / sizeof parts[0])

static const sensor_identity nothing = {"none", false, false};
static const sensor_part_entry *found;
/* The bank the part's bank select holds, as the bridge last wrote it (0 at reset and after every probe). */
static uint8_t bank;

static void read_framed(const sensor_part_entry *part, uint8_t address, uint8_t *dst, size_t count)
{
    const uint8_t command = (uint8_t)((address << part->shift) | part->read_flag);

    bridge_hal_spi_transfer(&command, 1, dst, count);
}

static void write_framed(const sensor_part_entry *part, uint8_t address, uint8_t value)
{
    const uint8_t frame[2] = {(uint8_t)(address << part->shift), value};

    bridge_hal_spi_transfer(frame, sizeof frame, NULL, 0);
}

bool sensor_detect(void)
{
    const sensor_part_entry *before = found;

    if (before != NULL && before->bank_select != 0u) {
        write_framed(before, before->bank_select, 0u);
    }
    bank = 0u;
    found = NULL;
    for (size_t i = 0; i < PART_COUNT && found == NULL; ++i) {
        uint8_t value = 0;
        read_framed(&parts[i], parts[i].identity_register, &value, 1);
        if (value == parts[i].identity_value) {
            found = &parts[i];
        }
    }
    return found != before;
}

sensor_identity sensor_part(void)
{
    return found != NULL ? found->identity : nothing;
}

sensor_fifo sensor_fifo_kind(void)
{
    return found != NULL ? found->fifo : SENSOR_FIFO_NONE;
}

uint32_t sensor_fifo_sample_bytes(void)
{
    switch (sensor_fifo_kind()) {
    case SENSOR_FIFO_ADXL355:
        return SENSOR_ADXL_SAMPLE_BYTES;
    case SENSOR_FIFO_ICM42688:
        return SENSOR_ICM_PACKET_BYTES;
    default:
        return 0u;
    }
}

uint8_t sensor_fifo_data(void)
{
    return sensor_fifo_kind() == SENSOR_FIFO_ICM42688 ? SENSOR_ICM_REG_FIFO_DATA : SENSOR_REG_FIFO_DATA;
}

bool sensor_changes_the_stream(uint8_t address)
{
    if (found == NULL) {
        return false;
    }
    for (size_t i = 0; i < sizeof found->stream_registers; ++i) {
        if (found->stream_registers[i] != NONE && found->stream_registers[i] == address) {
            return true;
        }
    }
    return false;
}

void sensor_read(uint8_t address, uint8_t *dst, size_t count)
{
    if (found != NULL) {
        read_framed(found, address, dst, count);
    }
}

void sensor_write(uint8_t address, uint8_t value)
{
    if (found != NULL) {
        write_framed(found, address, value);
        if (found->bank_select != 0u && address == found->bank_select) {
            bank = value & 0x07u; /* REG_BANK_SEL: the bank in bits 2:0 */
        }
    }
}

uint8_t sensor_last_register(void)
{
    return found != NULL ? found->last_register : 0u;
}

bool sensor_burst_stays(uint8_t address)
{
    return found != NULL && address == found->burst_stays;
}

bool sensor_read_only(uint8_t address)
{
    if (found == NULL || bank != 0u) {
        return false;
    }
    for (size_t i = 0; i < sizeof found->read_only / sizeof found->read_only[0]; ++i) {
        if (found->read_only[i].first <= address && address <= found->read_only[i].last) {
            return true;
        }
    }
    return false;
}

bool sensor_standby_only(uint8_t address)
{
    return found != NULL && (address == found->standby_only[0] || address == found->standby_only[1]);
}

bool sensor_in_standby(void)
{
    uint8_t power;

    if (found == NULL || found->power_register == NONE) {
        return false;
    }
    sensor_read(found->power_register, &power, 1);
    return (power & found->standby_bit) != 0u;
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
