/*
 * A simulated ADXL355 at register level, for the host build: what the bridge core talks to over
 * the host HAL's "SPI". Its samples follow the HAL's clock (the monotonic clock, or the board clock of
 * pty_hal.h), so the core's draining is tested against time as it passes, as on a board.
 *
 * What it models (and the numbers a test can rely on):
 *   - identity DEVID_AD 0xAD, DEVID_MST 0x1D, PARTID 0xED, REVID 0x01;
 *   - RESET (0x2F) with 0x52: every register to its reset value, standby, FIFO empty, and STATUS
 *     NVM_BUSY for MODEL_NVM_BUSY_US;
 *   - RANGE (0x2C, reset 0x81) and FILTER (0x28, ODR_LPF in bits 3..0: 4000 Hz >> code) written only
 *     in standby (a write while measuring is ignored, as a part that takes them only in standby);
 *   - POWER_CTL (0x2D, reset 0x01): standby clears the FIFO; measuring starts sample 0 one output
 *     period later;
 *   - the 96-entry FIFO: sample k's X entry appears at start + k / ODR, its Y and Z entries
 *     MODEL_AXIS_DELAY_US and twice that later (so a drain can catch a sample half written); a
 *     full FIFO loses its oldest entry and sets FIFO_OVR, which reading STATUS clears; reading an
 *     empty FIFO gives entries with the empty flag; XDATA..ZDATA hold the last whole sample;
 *   - the signal: a fixed gravity vector (MODEL_GRAVITY_UG_*) plus noise uniform within
 *     +-MODEL_NOISE_UG rounded to whole LSB (26, 13, 6 LSB at +-2, 4, 8 g), a deterministic
 *     function of the entry's index since measuring began (model_noise_lsb), so a test can check a
 *     capture sample by sample for gaps;
 *   - temperature: the raw value of the configured temperature (1885 LSB at 25 degC, -9.05 LSB/degC)
 *     plus noise of -1, 0 or +1 LSB; a burst reading both TEMP2 and TEMP1 tears with the configured
 *     probability, 256 LSB off, the sign alternating from one torn read to the next (so two torn
 *     reads in a row never agree, and at rate 1 no two reads do).
 * Not modelled: activity detection, interrupts, offsets' effect, self test, the high-pass filter,
 * I2C. Register 0x11 read inside a burst that starts below it reads 0.
 */
#ifndef ADXL355_MODEL_H
#define ADXL355_MODEL_H

#include <stddef.h>
#include <stdint.h>

#define MODEL_GRAVITY_UG_X 200000
#define MODEL_GRAVITY_UG_Y (-400000)
#define MODEL_GRAVITY_UG_Z 894000
#define MODEL_NOISE_UG 100
#define MODEL_AXIS_DELAY_US 40u
#define MODEL_NVM_BUSY_US 2000u
#define MODEL_TEMPERATURE_INTERCEPT_LSB 1885.0
#define MODEL_TEMPERATURE_SLOPE_LSB_PER_C (-9.05)

typedef struct {
    double temperature_c; /* what TEMP2/TEMP1 say, within 1 LSB */
    double tear_rate;     /* share of TEMP2+TEMP1 bursts that tear, 0..1 */
    uint32_t seed;        /* of the acceleration noise (and the streams of tears and temperature noise) */
} model_config;

void model_init(const model_config *config, uint64_t now_us);

/* One SPI transaction as bridge_hal_spi_transfer() describes it, at time `now_us`. */
void model_spi(const uint8_t *out, size_t out_len, uint8_t *in, size_t in_len, uint64_t now_us);

/* The noise (LSB) of FIFO entry `entry` (3 * sample + axis, counted from the start of measuring) at
 * RANGE code `range_code`: lowbias32 hash of (entry + seed), reduced to -A..A. */
int32_t model_noise_lsb(uint32_t seed, uint64_t entry, unsigned range_code);

#endif
