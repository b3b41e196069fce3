/* The simulated ICM-42688-P (see icm42688_model.h for what it models and its numbers). */
#include "icm42688_model.h"

#include <stdbool.h>
#include <string.h>

#include "model_random.h"

#define REG_COUNT 0x80u
#define REG_DEVICE_CONFIG 0x11u
#define REG_TEMP_DATA1 0x1Du
#define REG_ACCEL_DATA_X1 0x1Fu
#define REG_GYRO_DATA_X1 0x25u
#define REG_FIFO_CONFIG 0x16u
#define REG_INT_STATUS 0x2Du
#define REG_FIFO_COUNTH 0x2Eu
#define REG_FIFO_COUNTL 0x2Fu
#define REG_FIFO_DATA 0x30u
#define REG_SIGNAL_PATH_RESET 0x4Bu
#define REG_INTF_CONFIG0 0x4Cu
#define REG_PWR_MGMT0 0x4Eu
#define REG_GYRO_CONFIG0 0x4Fu
#define REG_ACCEL_CONFIG0 0x50u
#define REG_FIFO_CONFIG1 0x5Fu
#define REG_WHO_AM_I 0x75u
#define REG_BANK_SEL 0x76u

#define WHO_AM_I 0x47u
#define SPI_READ 0x80u
#define SOFT_RESET 0x01u
#define INT_STATUS_RESET_DONE 0x10u
#define INT_STATUS_DATA_RDY 0x08u
#define INT_STATUS_FIFO_FULL 0x02u
#define FIFO_FLUSH 0x02u
#define INTF_CONFIG0_RESET 0x30u
#define FIFO_PACKETS 128u
#define PACKET_BYTES 16u
#define PACKET3_HEADER 0x68u
#define MODE_LOW_NOISE 0x03u
#define CONFIG0_RESET 0x06u
#define DATA_INVALID (-32768)

static struct {
    icm_model_config config;
    uint8_t regs[REG_COUNT]; /* bank 0's stored values (the data registers are made when read) */
    bool measuring;          /* either sensor on */
    uint64_t start_ns;       /* when sample 0 appears */
    uint64_t period_ns;
    uint64_t seen;           /* samples that have appeared since measuring began */
    bool data_ready;
    bool reset_done;         /* RESET_DONE pending until read, from reset_done_us on */
    uint64_t reset_done_us;
    uint32_t temperature_stream;
    /* The FIFO: the sample index of each packet it holds, oldest first (a ring), how many, the bytes of the oldest
     * already read, FIFO_FULL pending until INT_STATUS is read, and the samples it has looked at. */
    uint64_t fifo_sample[FIFO_PACKETS];
    uint32_t fifo_head;
    uint32_t fifo_packets;
    uint32_t fifo_offset;
    bool fifo_full;
    uint64_t fifo_seen;
} icm;

int32_t icm_model_noise_lsb(uint32_t seed, uint64_t word, int32_t amplitude_lsb)
{
    const uint32_t h = hash32((uint32_t)word + seed);

    return (int32_t)(h % (uint32_t)(2 * amplitude_lsb + 1)) - amplitude_lsb;
}

/* a / b rounded to the nearest integer, halves away from zero (b > 0). */
static int64_t divide_rounded(int64_t a, int64_t b)
{
    return a >= 0 ? (a + b / 2) / b : -((-a + b / 2) / b);
}

/* ACCEL_FS_SEL 0..3 = +-16, 8, 4, 2 g (4..7 are reserved: as +-16 g). */
static int64_t accel_lsb_per_g(void)
{
    const unsigned fs_sel = icm.regs[REG_ACCEL_CONFIG0] >> 5;

    return fs_sel <= 3u ? (int64_t)2048 << fs_sel : 2048;
}

/* GYRO_FS_SEL 0..7 = +-2000 .. +-15.625 dps: the data sheet's LSB/(dps), times 10. */
static int64_t gyro_lsb_per_10dps(void)
{
    static const int64_t lsb[8] = {164, 328, 655, 1310, 2620, 5243, 10486, 20972};

    return lsb[icm.regs[REG_GYRO_CONFIG0] >> 5];
}

/* The output data rate's period from ACCEL_CONFIG0's ODR code (see the header). */
static uint64_t period_ns(void)
{
    static const uint64_t periods[16] = {
        1000000u, 31250u, 62500u, 125000u, 250000u, 500000u, 1000000u, 5000000u,
        10000000u, 20000000u, 40000000u, 80000000u, 160000000u, 320000000u, 640000000u, 2000000u,
    };

    return periods[icm.regs[REG_ACCEL_CONFIG0] & 0x0Fu];
}

static bool accel_on(void)
{
    return (icm.regs[REG_PWR_MGMT0] & 0x03u) == MODE_LOW_NOISE;
}

static bool gyro_on(void)
{
    return ((icm.regs[REG_PWR_MGMT0] >> 2) & 0x03u) == MODE_LOW_NOISE;
}

/* The FIFO takes packets (packet 3) while both sensors measure, its mode is not bypass and FIFO_CONFIG1 enables
 * the accelerometer and the gyroscope (not the 20-bit packet). */
static bool fifo_takes_packets(void)
{
    return accel_on() && gyro_on() && (icm.regs[REG_FIFO_CONFIG] & 0xC0u) != 0u
           && (icm.regs[REG_FIFO_CONFIG1] & 0x13u) == 0x03u;
}

/* Sample `sample` into the FIFO: stop-on-full drops it when the FIFO is full, stream mode the oldest; FIFO_FULL
 * is set when the FIFO is full as it comes. */
static void fifo_add(uint64_t sample)
{
    if (icm.fifo_packets == FIFO_PACKETS) {
        icm.fifo_full = true;
        if ((icm.regs[REG_FIFO_CONFIG] & 0xC0u) != 0x40u) {
            return;
        }
        icm.fifo_head = (icm.fifo_head + 1u) % FIFO_PACKETS; /* stream: the oldest goes */
        icm.fifo_packets -= 1u;
        icm.fifo_offset = 0u;
    }
    icm.fifo_sample[(icm.fifo_head + icm.fifo_packets) % FIFO_PACKETS] = sample;
    icm.fifo_packets += 1u;
    if (icm.fifo_packets == FIFO_PACKETS) {
        icm.fifo_full = true;
    }
}

static void fifo_flush(void)
{
    icm.fifo_head = 0u;
    icm.fifo_packets = 0u;
    icm.fifo_offset = 0u;
}

/* Samples are counted afresh from now: sample 0 one period later. */
static void start_counting(uint64_t now_us)
{
    icm.period_ns = period_ns();
    icm.start_ns = now_us * 1000u + icm.period_ns;
    icm.seen = 0;
    icm.fifo_seen = 0;
    icm.data_ready = false;
}

static void advance(uint64_t now_us)
{
    const uint64_t now_ns = now_us * 1000u;

    if (!icm.measuring || now_ns < icm.start_ns) {
        return;
    }
    const uint64_t due = (now_ns - icm.start_ns) / icm.period_ns + 1u;
    if (due > icm.seen) {
        icm.seen = due;
        icm.data_ready = true;
    }
    if (!fifo_takes_packets()) {
        icm.fifo_seen = due;
        return;
    }
    const bool stream = (icm.regs[REG_FIFO_CONFIG] & 0xC0u) == 0x40u;
    if (stream && due - icm.fifo_seen > FIFO_PACKETS) { /* the last FIFO_PACKETS push out all before them */
        icm.fifo_full = true;
        icm.fifo_seen = due - FIFO_PACKETS;
    }
    for (; icm.fifo_seen < due; ++icm.fifo_seen) {
        if (!stream && icm.fifo_packets == FIFO_PACKETS) { /* stop-on-full: every later one dropped */
            icm.fifo_full = true;
            icm.fifo_seen = due;
            break;
        }
        fifo_add(icm.fifo_seen);
    }
}

static void reset_registers(uint64_t now_us)
{
    memset(icm.regs, 0, sizeof icm.regs);
    icm.regs[REG_WHO_AM_I] = WHO_AM_I;
    icm.regs[REG_GYRO_CONFIG0] = CONFIG0_RESET;
    icm.regs[REG_ACCEL_CONFIG0] = CONFIG0_RESET;
    icm.regs[REG_INTF_CONFIG0] = INTF_CONFIG0_RESET;
    icm.measuring = false;
    icm.fifo_full = false;
    fifo_flush();
    icm.seen = 0;
    icm.data_ready = false;
    icm.reset_done = true;
    icm.reset_done_us = now_us + ICM_MODEL_RESET_US;
}

void icm_model_init(const icm_model_config *config, uint64_t now_us)
{
    memset(&icm, 0, sizeof icm);
    icm.config = *config;
    icm.temperature_stream = config->seed * 40503u + 7u;
    if (icm.temperature_stream == 0u) { /* xorshift needs a non-zero state */
        icm.temperature_stream = 1u;
    }
    reset_registers(now_us);
    icm.reset_done_us = now_us; /* at power-up the reset is long done */
}

static void put_word(uint8_t *at, int64_t value)
{
    const int64_t clipped = value > 32767 ? 32767 : value < -32767 ? -32767 : value;
    const uint16_t bits = (uint16_t)(clipped & 0xFFFF);

    at[0] = (uint8_t)(bits >> 8);
    at[1] = (uint8_t)(bits & 0xFFu);
}

static int16_t temperature_code(void)
{
    const double exact = (icm.config.temperature_c - 25.0) * ICM_MODEL_TEMPERATURE_LSB_PER_C;
    const int rounded = exact >= 0.0 ? (int)(exact + 0.5) : -(int)(-exact + 0.5);

    return (int16_t)(rounded + (int)(next_random(&icm.temperature_stream) % 3u) - 1);
}

/* Sample `sample`'s six words, accelerometer x, y, z then gyroscope x, y, z, big-endian at `at` (12 bytes), of
 * each sensor that is on when `have`, -32768 (no data) otherwise. */
static void put_sample(uint8_t *at, bool have, uint64_t sample)
{
    static const int64_t gravity_ug[3] = {ICM_MODEL_GRAVITY_UG_X, ICM_MODEL_GRAVITY_UG_Y, ICM_MODEL_GRAVITY_UG_Z};
    static const int64_t rate_mdps[3] = {ICM_MODEL_RATE_MDPS_X, ICM_MODEL_RATE_MDPS_Y, ICM_MODEL_RATE_MDPS_Z};
    const int64_t accel_lsb = accel_lsb_per_g();
    const int64_t gyro_lsb = gyro_lsb_per_10dps();
    const int32_t accel_noise = (int32_t)divide_rounded(ICM_MODEL_ACCEL_NOISE_UG * accel_lsb, 1000000);
    const int32_t gyro_noise = (int32_t)divide_rounded(ICM_MODEL_GYRO_NOISE_MDPS * gyro_lsb, 10000);

    for (unsigned axis = 0; axis < 3u; ++axis) {
        uint8_t *accel_at = &at[2u * axis];
        uint8_t *gyro_at = &at[6u + 2u * axis];
        /* -32768 (no data) is written as is; a reading is clipped to -32767..32767 */
        if (have && accel_on()) {
            put_word(accel_at, divide_rounded(gravity_ug[axis] * accel_lsb, 1000000)
                                   + icm_model_noise_lsb(icm.config.seed, 6u * sample + axis, accel_noise));
        } else {
            accel_at[0] = 0x80u;
            accel_at[1] = 0x00u;
        }
        if (have && gyro_on()) {
            put_word(gyro_at, divide_rounded(rate_mdps[axis] * gyro_lsb, 10000)
                                  + icm_model_noise_lsb(icm.config.seed, 6u * sample + 3u + axis, gyro_noise));
        } else {
            gyro_at[0] = 0x80u;
            gyro_at[1] = 0x00u;
        }
    }
}

/* The data registers as of now: TEMP_DATA, then the newest sample of each sensor that is on. */
static void make_data(uint8_t *regs)
{
    put_word(&regs[REG_TEMP_DATA1], temperature_code());
    put_sample(&regs[REG_ACCEL_DATA_X1], icm.measuring && icm.seen > 0u, icm.seen - 1u);
}

/* Sample `sample`'s FIFO packet: header, the sample's words, the temperature in the packet's 8 bits
 * (TEMP_DATA / 64, without the registers' read noise), the timestamp in 30/32 us ticks since the sensors came on. */
static void make_packet(uint8_t packet[PACKET_BYTES], uint64_t sample)
{
    const double exact = (icm.config.temperature_c - 25.0) * ICM_MODEL_TEMPERATURE_LSB_PER_C / 64.0;
    const int rounded = exact >= 0.0 ? (int)(exact + 0.5) : -(int)(-exact + 0.5);
    const uint64_t ticks = (sample + 1u) * icm.period_ns * 30u / 32000u;

    packet[0] = PACKET3_HEADER;
    put_sample(&packet[1], true, sample);
    packet[13] = (uint8_t)(int8_t)(rounded > 127 ? 127 : rounded < -128 ? -128 : rounded);
    packet[14] = (uint8_t)((ticks >> 8) & 0xFFu);
    packet[15] = (uint8_t)(ticks & 0xFFu);
}

/* `count` bytes from the FIFO's read port: its packets, oldest first, then 0xFF once it is empty. */
static void read_fifo(uint8_t *in, size_t count)
{
    uint8_t packet[PACKET_BYTES];

    for (size_t i = 0; i < count; ++i) {
        if (icm.fifo_packets == 0u) {
            in[i] = 0xFFu;
            continue;
        }
        make_packet(packet, icm.fifo_sample[icm.fifo_head]);
        in[i] = packet[icm.fifo_offset];
        if (++icm.fifo_offset == PACKET_BYTES) {
            icm.fifo_offset = 0u;
            icm.fifo_head = (icm.fifo_head + 1u) % FIFO_PACKETS;
            icm.fifo_packets -= 1u;
        }
    }
}

static bool in_bank_0(size_t reg)
{
    return (icm.regs[REG_BANK_SEL] & 0x07u) == 0u || reg == REG_BANK_SEL;
}

static void read_registers(uint8_t address, uint8_t *in, size_t in_len, uint64_t now_us)
{
    uint8_t regs[REG_COUNT];
    const bool reset_done = icm.reset_done && now_us >= icm.reset_done_us;

    if (address == REG_FIFO_DATA && in_bank_0(REG_FIFO_DATA)) {
        read_fifo(in, in_len); /* a burst from FIFO_DATA stays on it */
        return;
    }
    memcpy(regs, icm.regs, sizeof regs);
    make_data(regs);
    regs[REG_INT_STATUS] = (uint8_t)((reset_done ? INT_STATUS_RESET_DONE : 0u)
                                     | (icm.data_ready ? INT_STATUS_DATA_RDY : 0u)
                                     | (icm.fifo_full ? INT_STATUS_FIFO_FULL : 0u));
    const uint32_t fifo_bytes = icm.fifo_packets * PACKET_BYTES - icm.fifo_offset;
    regs[REG_FIFO_COUNTH] = (uint8_t)(fifo_bytes >> 8);
    regs[REG_FIFO_COUNTL] = (uint8_t)(fifo_bytes & 0xFFu);
    regs[REG_FIFO_DATA] = 0xFFu; /* within a burst from below it: not modelled, read as empty */
    regs[REG_DEVICE_CONFIG] &= (uint8_t)~SOFT_RESET;
    for (size_t i = 0; i < in_len; ++i) {
        const size_t reg = address + i;
        in[i] = (reg < REG_COUNT && in_bank_0(reg)) ? regs[reg] : 0u;
    }
    if (address <= REG_INT_STATUS && REG_INT_STATUS < address + in_len && in_bank_0(REG_INT_STATUS)) {
        icm.data_ready = false; /* reading INT_STATUS clears it, and FIFO_FULL */
        icm.fifo_full = false;
        if (reset_done) {
            icm.reset_done = false;
        }
    }
}

static bool read_only(size_t reg)
{
    return (REG_TEMP_DATA1 <= reg && reg <= REG_FIFO_DATA) || reg == REG_WHO_AM_I;
}

static void write_register(size_t reg, uint8_t value, uint64_t now_us)
{
    if (reg >= REG_COUNT || !in_bank_0(reg) || read_only(reg)) {
        return; /* read-only, another bank, or no register: ignored */
    }
    if (reg == REG_DEVICE_CONFIG && (value & SOFT_RESET)) {
        reset_registers(now_us);
        return;
    }
    if (reg == REG_SIGNAL_PATH_RESET) { /* write-to-clear: it reads 0 */
        if (value & FIFO_FLUSH) {
            fifo_flush();
        }
        return;
    }
    icm.regs[reg] = value;
    const bool measuring = accel_on() || gyro_on();
    if (reg == REG_PWR_MGMT0 && measuring != icm.measuring) {
        icm.measuring = measuring;
        if (measuring) {
            start_counting(now_us);
        }
    } else if ((reg == REG_GYRO_CONFIG0 || reg == REG_ACCEL_CONFIG0) && icm.measuring) {
        start_counting(now_us); /* a new rate or range: counted afresh */
    }
}

void icm_model_spi(const uint8_t *out, size_t out_len, uint8_t *in, size_t in_len, uint64_t now_us)
{
    if (out_len == 0) {
        return;
    }
    const uint8_t address = (uint8_t)(out[0] & 0x7Fu);
    advance(now_us);
    if (out[0] & SPI_READ) {
        read_registers(address, in, in_len, now_us);
        return;
    }
    /* A write: every byte on MOSI after the address, the zeros clocked out while reading included. */
    for (size_t i = 1; i < out_len + in_len; ++i) {
        write_register(address + i - 1u, i < out_len ? out[i] : 0u, now_us);
    }
    if (in_len > 0) {
        memset(in, 0, in_len);
    }
}
