/* Word splitting and number parsing, strict: anything malformed is refused, never guessed. */
#include "parse.h"

static bool is_space(char c)
{
    return c == ' '; /* a tab never gets here: it is no printable ASCII (line.c) */
}

size_t parse_words(char *line, char *words[], size_t max_words)
{
    size_t count = 0;

    while (*line != '\0') {
        while (is_space(*line)) {
            *line++ = '\0';
        }
        if (*line == '\0') {
            break;
        }
        if (count == max_words) {
            return max_words + 1;
        }
        words[count++] = line;
        while (*line != '\0' && !is_space(*line)) {
            ++line;
        }
    }
    return count;
}

static int hex_digit(char c)
{
    if (c >= '0' && c <= '9') {
        return c - '0';
    }
    if (c >= 'A' && c <= 'F') {
        return c - 'A' + 10;
    }
    if (c >= 'a' && c <= 'f') {
        return c - 'a' + 10;
    }
    return -1;
}

bool parse_hex_byte(const char *text, uint8_t *value)
{
    unsigned result = 0;
    size_t length = 0;

    for (; text[length] != '\0'; ++length) {
        const int digit = hex_digit(text[length]);
        if (digit < 0 || length == 2) {
            return false;
        }
        result = (result << 4) | (unsigned)digit;
    }
    if (length == 0) {
        return false;
    }
    *value = (uint8_t)result;
    return true;
}

bool parse_decimal(const char *text, uint32_t max, uint32_t *value)
{
    /* Past `max` the value stops growing, so any number of digits (leading zeros, or a huge number) is read
     * without overflow, and without a division to guard the multiply (a Cortex-M0+ has no divide
     * instruction); `max` is far below 2^32 / 10. */
    uint32_t result = 0;
    size_t length = 0;

    for (; text[length] != '\0'; ++length) {
        const char c = text[length];
        if (c < '0' || c > '9') {
            return false;
        }
        if (result <= max) {
            result = result * 10u + (uint32_t)(c - '0');
        }
    }
    if (length == 0 || result > max) {
        return false;
    }
    *value = result;
    return true;
}
