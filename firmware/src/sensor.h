/*
 * The part on the HAL's SPI: which one it is (found by its identity register, each part probed in its
 * own framing), the SPI framing of register reads and writes for that part, and, for the ADXL355, the
 * registers and bits the capture uses and the temperature read that survives TEMP2/TEMP1 tearing.
 */
#ifndef SENSOR_H
#define SENSOR_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* ADXL355 registers (its capture's). */
#define SENSOR_REG_STATUS 0x04u
#define SENSOR_REG_FIFO_ENTRIES 0x05u
#define SENSOR_REG_TEMP2 0x06u
#define SENSOR_REG_FIFO_DATA 0x11u
#define SENSOR_REG_FILTER 0x28u
#define SENSOR_REG_FIFO_SAMPLES 0x29u
#define SENSOR_REG_RANGE 0x2Cu
#define SENSOR_REG_POWER_CTL 0x2Du
#define SENSOR_REG_RESET 0x2Fu
/* Register addresses are 7 bits for both parts: the ADXL355's command byte is the address shifted
 * left once, the ICM-42688-P's is the address with bit 7 as the read flag. */
#define SENSOR_REG_LAST 0x7Fu

#define SENSOR_STATUS_FIFO_OVR 0x04u
#define SENSOR_POWER_CTL_STANDBY 0x01u
#define SENSOR_ADXL_SAMPLE_BYTES 9u

/* ICM-42688-P registers (bank 0) and bits its capture uses (docs/instruments.md, "TDK ICM-42688-P"). */
#define SENSOR_ICM_REG_DEVICE_CONFIG 0x11u
#define SENSOR_ICM_REG_FIFO_CONFIG 0x16u
#define SENSOR_ICM_REG_TEMP_DATA1 0x1Du
#define SENSOR_ICM_REG_INT_STATUS 0x2Du
#define SENSOR_ICM_REG_FIFO_DATA 0x30u
#define SENSOR_ICM_REG_SIGNAL_PATH_RESET 0x4Bu
#define SENSOR_ICM_REG_INTF_CONFIG0 0x4Cu
#define SENSOR_ICM_REG_PWR_MGMT0 0x4Eu
#define SENSOR_ICM_REG_GYRO_CONFIG0 0x4Fu
#define SENSOR_ICM_REG_ACCEL_CONFIG0 0x50u
#define SENSOR_ICM_REG_FIFO_CONFIG1 0x5Fu
#define SENSOR_ICM_REG_BANK_SEL 0x76u
#define SENSOR_ICM_PWR_LOW_NOISE 0x0Fu
#define SENSOR_ICM_FIFO_FLUSH 0x02u
#define SENSOR_ICM_INT_FIFO_FULL 0x02u
/* Packet 3: header, accelerometer, gyroscope, temperature, timestamp; its header 0b0110_10xx. */
#define SENSOR_ICM_PACKET_BYTES 16u
#define SENSOR_ICM_PACKET3_HEADER 0x68u
#define SENSOR_ICM_PACKET3_MASK 0xFCu

/* A FIFO entry is one axis: 3 bytes, the 20-bit value left-justified, flags in the low nibble. */
#define SENSOR_FIFO_ENTRIES 96u
#define SENSOR_ENTRY_BYTES 3u
#define SENSOR_ENTRY_X_MARKER 0x01u
#define SENSOR_ENTRY_EMPTY 0x02u

/* Temperature reads that agree: a torn read is a whole TEMP2 step (256 LSB) off, noise a few LSB. */
#define SENSOR_TEMPERATURE_AGREE_LSB 16u
#define SENSOR_TEMPERATURE_READS 10u

/* What sensor_detect() found: the part's name as the greeting says it ("adxl355", "icm42688p", or
 * "none" where no part answered), and whether the bridge captures blocks of it (C and G). */
typedef struct {
    const char *name;
    bool found;
    bool captures;
} sensor_identity;

/* The FIFO a capture drains: none, the ADXL355's (one axis an entry), the ICM-42688-P's (16-byte packets). */
typedef enum {
    SENSOR_FIFO_NONE,
    SENSOR_FIFO_ADXL355,
    SENSOR_FIFO_ICM42688
} sensor_fifo;

/*
 * Which part is on the bus: the ICM-42688-P's WHO_AM_I (0x75 = 0x47, read as 0xF5), then the ADXL355's
 * DEVID_AD (0x00 = 0xAD, read as 0x01). In that order because the ICM probe reaches an ADXL355 as a read
 * of its register 0x7A, which changes nothing; the ADXL355 probe would reach an ICM-42688-P as a write.
 * A part found before whose registers are banked (the ICM-42688-P) gets bank 0 selected first, so a
 * client that left it in another bank does not hide it. True if the part differs from the last found.
 */
bool sensor_detect(void);

/* The part found by the last sensor_detect() ("none" before the first). */
sensor_identity sensor_part(void);

/* The FIFO of the part found, and the bytes of one sample as it gives them (0: none). */
sensor_fifo sensor_fifo_kind(void);
uint32_t sensor_fifo_sample_bytes(void);
/* The register a burst of which takes samples out of the part's FIFO (a capture's own), and whether a write to
 * `address` changes what the FIFO holds (so it ends a running capture). Only with a part that captures. */
uint8_t sensor_fifo_data(void);
bool sensor_changes_the_stream(uint8_t address);

/*
 * The register map of the part found, as the bridge enforces it (docs/instruments.md, "The serial bridge
 * protocol": what each request that breaks it is answered). Only with a part found.
 */
/* The highest register address the part has (the ADXL355: RESET 0x2F; the ICM-42688-P: all of 0x00..0x7F). */
uint8_t sensor_last_register(void);
/* True if a burst from `address` reads that register again and again (the ADXL355's FIFO_DATA), so a burst of
 * any length from it stays inside the map. */
bool sensor_burst_stays(uint8_t address);
/* True if `address` is read-only in the bank selected now: bank 0's facts (the part's table); in another bank
 * (the ICM-42688-P's 1..4, selected by a W to REG_BANK_SEL) nothing is known, so nothing is refused. */
bool sensor_read_only(uint8_t address);
/* True if `address` may be written only while the part is in standby (the ADXL355's RANGE and FILTER). */
bool sensor_standby_only(uint8_t address);
/* True if the part is in standby (the ADXL355: POWER_CTL's STANDBY bit, read now). */
bool sensor_in_standby(void);

/* `count` registers from `address` in one burst, framed for the part found (from the ADXL355's
 * FIFO_DATA the part does not auto-increment: the burst drains the FIFO). Only with a part found. */
void sensor_read(uint8_t address, uint8_t *dst, size_t count);

/* One register, framed for the part found (a write to the part's bank select also notes the bank). Only with a
 * part found. */
void sensor_write(uint8_t address, uint8_t value);

/* ADXL355: TEMP2, TEMP1 read until two reads in a row agree within SENSOR_TEMPERATURE_AGREE_LSB; the
 * later read goes to `pair`. False if SENSOR_TEMPERATURE_READS reads never agreed (`pair` untouched). */
bool sensor_agreed_temperature(uint8_t pair[2]);

#endif
