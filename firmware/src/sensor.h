/*
 * The ADXL355 over the HAL's SPI: register addresses and bits the core uses, burst reads and writes,
 * and the temperature read that survives TEMP2/TEMP1 tearing.
 */
#ifndef SENSOR_H
#define SENSOR_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define SENSOR_REG_STATUS 0x04u
#define SENSOR_REG_FIFO_ENTRIES 0x05u
#define SENSOR_REG_TEMP2 0x06u
#define SENSOR_REG_FIFO_DATA 0x11u
#define SENSOR_REG_FILTER 0x28u
#define SENSOR_REG_FIFO_SAMPLES 0x29u
#define SENSOR_REG_RANGE 0x2Cu
#define SENSOR_REG_POWER_CTL 0x2Du
#define SENSOR_REG_RESET 0x2Fu
/* Register addresses are 7 bits: the SPI command byte is the address shifted left once. */
#define SENSOR_REG_LAST 0x7Fu

#define SENSOR_STATUS_FIFO_OVR 0x04u
#define SENSOR_POWER_CTL_STANDBY 0x01u

/* A FIFO entry is one axis: 3 bytes, the 20-bit value left-justified, flags in the low nibble. */
#define SENSOR_FIFO_ENTRIES 96u
#define SENSOR_ENTRY_BYTES 3u
#define SENSOR_ENTRY_X_MARKER 0x01u
#define SENSOR_ENTRY_EMPTY 0x02u

/* Temperature reads that agree: a torn read is a whole TEMP2 step (256 LSB) off, noise a few LSB. */
#define SENSOR_TEMPERATURE_AGREE_LSB 16u
#define SENSOR_TEMPERATURE_READS 10u

/* `count` registers from `address` in one burst (from FIFO_DATA the part does not auto-increment:
 * the burst drains the FIFO). */
void sensor_read(uint8_t address, uint8_t *dst, size_t count);

/* One register. */
void sensor_write(uint8_t address, uint8_t value);

/* TEMP2, TEMP1 read until two reads in a row agree within SENSOR_TEMPERATURE_AGREE_LSB; the later
 * read goes to `pair`. False if SENSOR_TEMPERATURE_READS reads never agreed (`pair` untouched). */
bool sensor_agreed_temperature(uint8_t pair[2]);

#endif
