/* Splitting a request line into words, and the protocol's two kinds of number. */
#ifndef PARSE_H
#define PARSE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Splits `line` in place at runs of spaces into at most `max_words` words; returns how many there
 * were, or max_words + 1 if there were more (the rest is not split). */
size_t parse_words(char *line, char *words[], size_t max_words);

/* 1 or 2 hex digits (either case) -> 0..255. */
bool parse_hex_byte(const char *text, uint8_t *value);

/* Decimal digits only (any number of them: leading zeros are fine), no sign, value <= max (max < 2^32 / 10). */
bool parse_decimal(const char *text, uint32_t max, uint32_t *value);

#endif
