/* The host models' noise, shared by the simulated parts (adxl355_model.c, icm42688_model.c). */
#ifndef MODEL_RANDOM_H
#define MODEL_RANDOM_H

#include <stdint.h>

/* lowbias32 (a well-known 32-bit integer hash): noise as a function of a sample's index, not of a
 * stream's state, so a test can recompute any sample. */
static inline uint32_t hash32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7FEB352Du;
    x ^= x >> 15;
    x *= 0x846CA68Bu;
    x ^= x >> 16;
    return x;
}

/* xorshift32: a stream of draws (tears, temperature noise), each its own state. */
static inline uint32_t next_random(uint32_t *state)
{
    uint32_t x = *state;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    *state = x;
    return x;
}

#endif
