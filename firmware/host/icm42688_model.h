/*
 * A simulated TDK ICM-42688-P at register level (user bank 0), for the host build: what the bridge core
 * talks to over the host HAL's "SPI" with `bridge-host --part icm42688p`. Its samples follow the HAL's
 * clock, as the ADXL355 model's do. Facts from accelcal_rig/instruments/icm42688.py and
 * docs/instruments.md ("TDK ICM-42688-P"), which cites a source for each.
 *
 * What it models (and the numbers a test can rely on):
 *   - SPI framing: the first byte is the address in bits 6:0, bit 7 set for a read; bursts
 *     auto-increment; a write takes every byte after the address (the zeros clocked out while the
 *     master reads count too: they are on MOSI), a read returns the registers;
 *   - WHO_AM_I (0x75) 0x47, read-only; REG_BANK_SEL (0x76, bits 2:0): only bank 0 is modelled, in
 *     another bank every register but REG_BANK_SEL reads 0 and writes to them are ignored;
 *   - DEVICE_CONFIG (0x11) with bit 0 (SOFT_RESET): every register to its reset value (both CONFIG0
 *     0x06, PWR_MGMT0 0x00: sensors off); INT_STATUS RESET_DONE (bit 4) sets ICM_MODEL_RESET_US later
 *     (and is set at power-up);
 *   - GYRO_CONFIG0 (0x4F), ACCEL_CONFIG0 (0x50): FS_SEL bits 7:5, ODR bits 3:0; both sensors sample at
 *     ACCEL_CONFIG0's rate (ODR codes 1..11 = 32 kHz .. 12.5 Hz, 15 = 500 Hz, 12..14 the low-power
 *     6.25 .. 1.5625 Hz, 0 as the reset value's 1 kHz); a write while measuring starts the count of
 *     samples again;
 *   - PWR_MGMT0 (0x4E): the accelerometer is on when ACCEL_MODE (bits 1:0) is 3 (low noise), the
 *     gyroscope when GYRO_MODE (bits 3:2) is 3; sample 0 comes one period after the first of them comes
 *     on, sample k k periods after it; a sensor that is off (or before sample 0) reads -32768;
 *   - the data registers TEMP_DATA1 (0x1D) .. GYRO_DATA_Z0 (0x2A), 16-bit big-endian, hold the newest
 *     sample; INT_STATUS (0x2D) DATA_RDY (bit 3) is set by each new sample; reading INT_STATUS clears
 *     it and RESET_DONE; 0x2B, 0x2C (TMST_FSYNC) read 0;
 *   - the signal: sample k's accelerometer codes are the gravity vector ICM_MODEL_GRAVITY_UG_* and its
 *     gyroscope's the rate ICM_MODEL_RATE_MDPS_* at the configured full scale, each rounded to whole
 *     LSB, plus noise uniform within +-ICM_MODEL_ACCEL_NOISE_UG (+-16 LSB at +-2 g) and
 *     +-ICM_MODEL_GYRO_NOISE_MDPS (+-3 LSB at +-2000 dps) rounded to whole LSB: the lowbias32 hash of
 *     (6k + word + seed), word 0..2 the accelerometer's x, y, z and 3..5 the gyroscope's (as
 *     icm_model_noise_lsb), so a test can recompute every sample;
 *   - temperature: TEMP_DATA = round((T - 25) * 132.48) for the configured T, plus -1, 0 or +1 LSB,
 *     whatever the power mode;
 *   - the FIFO: while both sensors are on, FIFO_CONFIG (0x16) is not bypass and FIFO_CONFIG1 (0x5F) enables
 *     the accelerometer and the gyroscope (not HIRES), sample k also goes to the FIFO as packet 3 (16 bytes:
 *     header 0x68, the sample's six words as the data registers would hold them, the temperature as
 *     round((T - 25) * 132.48 / 64) without the read noise, the timestamp (k + 1) * period * 30/32 in us
 *     ticks, low 16 bits); it holds 128 packets; stop-on-full (FIFO_MODE 10 or 11) drops new samples once
 *     full, stream (01) the oldest; FIFO_FULL (INT_STATUS bit 1) is set when it is full as a sample comes, and
 *     cleared by reading INT_STATUS; FIFO_COUNTH/L (0x2E/0x2F) the bytes held, big-endian (INTF_CONFIG0 0x4C
 *     at its reset value 0x30; other values not modelled); a burst from FIFO_DATA (0x30) stays on it and
 *     reads packet bytes in order, 0xFF once empty (within a burst from below it, 0xFF); SIGNAL_PATH_RESET
 *     (0x4B) bit 1 flushes it and reads 0. TEMP_DATA1..FIFO_DATA are read-only.
 * Not modelled: interrupts, FSYNC, filters, offsets, self test, the low-power modes' behaviour, the
 * gyroscope's start-up time, 20-bit packets, I2C, banks 1..4.
 */
#ifndef ICM42688_MODEL_H
#define ICM42688_MODEL_H

#include <stddef.h>
#include <stdint.h>

#define ICM_MODEL_GRAVITY_UG_X 200000
#define ICM_MODEL_GRAVITY_UG_Y (-400000)
#define ICM_MODEL_GRAVITY_UG_Z 894000
#define ICM_MODEL_RATE_MDPS_X 250
#define ICM_MODEL_RATE_MDPS_Y (-150)
#define ICM_MODEL_RATE_MDPS_Z 100
#define ICM_MODEL_ACCEL_NOISE_UG 1000
#define ICM_MODEL_GYRO_NOISE_MDPS 200
#define ICM_MODEL_RESET_US 1000u
#define ICM_MODEL_TEMPERATURE_LSB_PER_C 132.48

typedef struct {
    double temperature_c; /* what TEMP_DATA says, within 1 LSB */
    uint32_t seed;        /* of the noise */
} icm_model_config;

void icm_model_init(const icm_model_config *config, uint64_t now_us);

/* One SPI transaction as bridge_hal_spi_transfer() describes it, at time `now_us`. */
void icm_model_spi(const uint8_t *out, size_t out_len, uint8_t *in, size_t in_len, uint64_t now_us);

/* The noise (LSB) of data word `word` (6 * sample + 0..2 accel x, y, z, 3..5 gyro x, y, z) at an
 * amplitude of `amplitude_lsb`: lowbias32 hash of (word + seed), reduced to -A..A. */
int32_t icm_model_noise_lsb(uint32_t seed, uint64_t word, int32_t amplitude_lsb);

#endif
