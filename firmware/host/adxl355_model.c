/* The simulated ADXL355 (see adxl355_model.h for what it models and its numbers). */
#include "adxl355_model.h"

#include <stdbool.h>
#include <string.h>

#include "model_random.h"

#define REG_COUNT 0x30u
#define REG_STATUS 0x04u
#define REG_FIFO_ENTRIES 0x05u
#define REG_TEMP2 0x06u
#define REG_TEMP1 0x07u
#define REG_XDATA3 0x08u
#define REG_FIFO_DATA 0x11u
#define REG_FIRST_WRITABLE 0x1Eu
#define REG_FILTER 0x28u
#define REG_FIFO_SAMPLES 0x29u
#define REG_RANGE 0x2Cu
#define REG_POWER_CTL 0x2Du
#define REG_RESET 0x2Fu

#define RESET_CODE 0x52u
#define STATUS_NVM_BUSY 0x10u
#define STATUS_FIFO_OVR 0x04u
#define STATUS_FIFO_FULL 0x02u
#define STATUS_DATA_RDY 0x01u
#define POWER_CTL_STANDBY 0x01u
#define ENTRY_X_MARKER 0x01u
#define ENTRY_EMPTY 0x02u
#define FIFO_ENTRIES 96u
#define TEAR_LSB 256

static struct {
    model_config config;
    uint8_t regs[REG_COUNT];
    uint8_t fifo[FIFO_ENTRIES][3];
    unsigned fifo_head;  /* oldest entry */
    unsigned fifo_count;
    bool overflow;
    uint64_t start_us;   /* when sample 0's X entry appears */
    uint64_t period_us;
    uint64_t next_entry; /* index of the next entry to appear, since measuring began */
    uint64_t nvm_busy_until_us;
    uint32_t tear_stream;
    uint32_t temperature_stream;
    int tear_sign;
} part;

static int64_t lsb_per_g(unsigned range_code)
{
    return range_code == 3u ? 64000 : range_code == 2u ? 128000 : 256000; /* 0 is reserved: as 1 */
}

int32_t model_noise_lsb(uint32_t seed, uint64_t entry, unsigned range_code)
{
    /* MODEL_NOISE_UG in LSB, rounded: 25.6 -> 26, 12.8 -> 13, 6.4 -> 6 */
    const int64_t amplitude = (lsb_per_g(range_code) * MODEL_NOISE_UG + 500000) / 1000000;
    const uint32_t h = hash32((uint32_t)entry + seed);
    return (int32_t)((int64_t)(h % (uint32_t)(2 * amplitude + 1)) - amplitude);
}

static bool measuring(void)
{
    return (part.regs[REG_POWER_CTL] & POWER_CTL_STANDBY) == 0;
}

static unsigned range_code(void)
{
    return part.regs[REG_RANGE] & 0x03u;
}

/* The entry's 20-bit code, left-justified in 3 bytes, flags in the low nibble. */
static void make_entry(uint64_t entry, uint8_t bytes[3])
{
    static const int64_t gravity_ug[3] = {MODEL_GRAVITY_UG_X, MODEL_GRAVITY_UG_Y, MODEL_GRAVITY_UG_Z};
    const unsigned axis = (unsigned)(entry % 3u);
    const int64_t code = gravity_ug[axis] * lsb_per_g(range_code()) / 1000000
                         + model_noise_lsb(part.config.seed, entry, range_code());
    const uint32_t bits = (uint32_t)code & 0xFFFFFu;

    bytes[0] = (uint8_t)(bits >> 12);
    bytes[1] = (uint8_t)(bits >> 4);
    bytes[2] = (uint8_t)(((bits & 0x0Fu) << 4) | (axis == 0u ? ENTRY_X_MARKER : 0u));
}

static void push_entry(uint64_t entry)
{
    if (part.fifo_count == FIFO_ENTRIES) {
        part.fifo_head = (part.fifo_head + 1u) % FIFO_ENTRIES; /* the oldest is lost */
        --part.fifo_count;
        part.overflow = true;
    }
    uint8_t *slot = part.fifo[(part.fifo_head + part.fifo_count) % FIFO_ENTRIES];
    make_entry(entry, slot);
    ++part.fifo_count;
    if (entry % 3u == 2u) { /* a whole sample: the data registers follow it */
        for (unsigned axis = 0; axis < 3u; ++axis) {
            make_entry(entry - 2u + axis, &part.regs[REG_XDATA3 + 3u * axis]);
            part.regs[REG_XDATA3 + 3u * axis + 2u] &= 0xF0u;
        }
    }
}

/* How many entries have appeared by `now_us` since measuring began. */
static uint64_t entries_due(uint64_t now_us)
{
    if (now_us < part.start_us) {
        return 0;
    }
    const uint64_t elapsed = now_us - part.start_us;
    const uint64_t sample = elapsed / part.period_us;
    const uint64_t within = elapsed - sample * part.period_us;
    return 3u * sample + 1u + (within >= MODEL_AXIS_DELAY_US) + (within >= 2u * MODEL_AXIS_DELAY_US);
}

static void advance(uint64_t now_us)
{
    if (!measuring()) {
        return;
    }
    const uint64_t due = entries_due(now_us);
    if (due - part.next_entry > FIFO_ENTRIES) {
        /* Unlooked-at for longer than the FIFO lasts: only the newest 96 entries can be in it. */
        part.next_entry = due - FIFO_ENTRIES;
        part.fifo_count = 0;
        part.overflow = true;
    }
    while (part.next_entry < due) {
        push_entry(part.next_entry++);
    }
}

static void clear_fifo(void)
{
    part.fifo_head = 0;
    part.fifo_count = 0;
    part.overflow = false;
}

static void reset_registers(uint64_t now_us)
{
    memset(part.regs, 0, sizeof part.regs);
    part.regs[0] = 0xADu;
    part.regs[1] = 0x1Du;
    part.regs[2] = 0xEDu;
    part.regs[3] = 0x01u;
    part.regs[REG_FIFO_SAMPLES] = 0x60u;
    part.regs[REG_RANGE] = 0x81u;
    part.regs[REG_POWER_CTL] = POWER_CTL_STANDBY;
    clear_fifo();
    part.nvm_busy_until_us = now_us + MODEL_NVM_BUSY_US;
}

void model_init(const model_config *config, uint64_t now_us)
{
    memset(&part, 0, sizeof part);
    part.config = *config;
    part.tear_stream = config->seed * 2654435761u + 1u;
    part.temperature_stream = config->seed * 40503u + 7u;
    if (part.tear_stream == 0u) { /* xorshift needs a non-zero state */
        part.tear_stream = 1u;
    }
    if (part.temperature_stream == 0u) {
        part.temperature_stream = 1u;
    }
    part.tear_sign = 1;
    reset_registers(now_us);
    part.nvm_busy_until_us = 0;
}

static uint16_t temperature_raw(bool both_halves)
{
    const double exact = MODEL_TEMPERATURE_INTERCEPT_LSB
                         + MODEL_TEMPERATURE_SLOPE_LSB_PER_C * (part.config.temperature_c - 25.0);
    int raw = (int)(exact + 0.5) + (int)(next_random(&part.temperature_stream) % 3u) - 1;
    /* A draw only for a read of both halves: other reads leave the stream of tears alone. */
    if (both_halves && part.config.tear_rate > 0.0
        && (double)(next_random(&part.tear_stream) >> 8) / 16777216.0 < part.config.tear_rate) {
        raw += part.tear_sign * TEAR_LSB;
        part.tear_sign = -part.tear_sign;
    }
    return (uint16_t)(raw < 0 ? 0 : raw > 0xFFF ? 0xFFF : raw);
}

static uint8_t status_now(uint64_t now_us)
{
    return (uint8_t)((now_us < part.nvm_busy_until_us ? STATUS_NVM_BUSY : 0u)
                     | (part.overflow ? STATUS_FIFO_OVR : 0u)
                     | (part.fifo_count >= (part.regs[REG_FIFO_SAMPLES] & 0x7Fu) ? STATUS_FIFO_FULL : 0u)
                     | (part.fifo_count >= 3u ? STATUS_DATA_RDY : 0u));
}

/* FIFO_DATA does not auto-increment: each entry read is taken out (when its first byte goes). */
static void read_fifo(uint8_t *in, size_t in_len)
{
    static const uint8_t empty[3] = {0, 0, ENTRY_EMPTY};
    const uint8_t *entry = empty;

    for (size_t i = 0; i < in_len; ++i) {
        if (i % 3u == 0u) {
            entry = empty;
            if (part.fifo_count > 0) {
                entry = part.fifo[part.fifo_head];
                part.fifo_head = (part.fifo_head + 1u) % FIFO_ENTRIES;
                --part.fifo_count;
            }
        }
        in[i] = entry[i % 3u];
    }
}

static void read_registers(uint8_t address, uint8_t *in, size_t in_len, uint64_t now_us)
{
    const bool has_status = address <= REG_STATUS && REG_STATUS < address + in_len;
    const bool has_temperature = address <= REG_TEMP2 && REG_TEMP1 < address + in_len;
    const uint16_t temperature = temperature_raw(has_temperature);

    part.regs[REG_STATUS] = status_now(now_us);
    part.regs[REG_FIFO_ENTRIES] = (uint8_t)part.fifo_count;
    part.regs[REG_TEMP2] = (uint8_t)(temperature >> 8);
    part.regs[REG_TEMP1] = (uint8_t)(temperature & 0xFFu);
    for (size_t i = 0; i < in_len; ++i) {
        const size_t reg = address + i;
        in[i] = (reg < REG_COUNT && reg != REG_FIFO_DATA && reg != REG_RESET) ? part.regs[reg] : 0u;
    }
    if (has_status) {
        part.overflow = false; /* reading STATUS clears FIFO_OVR */
    }
}

/* ODR_LPF: codes 11..15 are reserved; taken as the slowest, 10 (3.906 Hz). */
static unsigned odr_code(void)
{
    const unsigned code = part.regs[REG_FILTER] & 0x0Fu;
    return code > 10u ? 10u : code;
}

static void write_register(size_t reg, uint8_t value, uint64_t now_us)
{
    if (reg == REG_RESET) {
        if (value == RESET_CODE) {
            reset_registers(now_us);
        }
        return;
    }
    if (reg < REG_FIRST_WRITABLE || reg >= REG_COUNT) {
        return; /* read-only or no register: the part ignores it */
    }
    if ((reg == REG_RANGE || reg == REG_FILTER) && measuring()) {
        return;
    }
    const bool was_measuring = measuring();
    part.regs[reg] = value;
    if (reg == REG_POWER_CTL && was_measuring != measuring()) {
        clear_fifo();
        part.period_us = 250u << odr_code(); /* 4000 Hz >> code */
        part.start_us = now_us + part.period_us;
        part.next_entry = 0;
    }
}

void model_spi(const uint8_t *out, size_t out_len, uint8_t *in, size_t in_len, uint64_t now_us)
{
    if (out_len == 0) {
        return;
    }
    const uint8_t address = (uint8_t)(out[0] >> 1);
    advance(now_us);
    if (out[0] & 1u) {
        if (address == REG_FIFO_DATA) {
            read_fifo(in, in_len);
        } else {
            read_registers(address, in, in_len, now_us);
        }
        return;
    }
    for (size_t i = 1; i < out_len; ++i) {
        write_register(address + i - 1u, out[i], now_us);
    }
}
