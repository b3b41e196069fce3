/*
 * The bridge HAL on an RP2040 with the pico-sdk: SPI0 to the sensor (an ADXL355 or an ICM-42688-P: the
 * core finds which, and frames its accesses for it), USB CDC (the SDK's stdio) to the host, time_us_64()
 * as the clock. Wiring for the ADXL355 (an ICM-42688-P's SPI pins go to the same GPIOs) (Raspberry Pi
 * Pico pin numbers in brackets):
 *   GP16 (21) SPI0 RX  <- ADXL355 MISO      GP18 (24) SPI0 SCK -> ADXL355 SCLK
 *   GP17 (22) CS, a plain GPIO -> ADXL355 CS   GP19 (25) SPI0 TX  -> ADXL355 MOSI
 *   3V3 (36) -> VDDIO and VSUPPLY, GND -> GND (the ADXL355 takes 2.25..3.6 V, no 5 V).
 */
#include <stdint.h>

#include <stdbool.h>

#include "hardware/gpio.h"
#include "hardware/spi.h"
#include "pico/stdio_usb.h"
#include "pico/stdlib.h"

#include "bridge.h"
#include "bridge_hal.h"

#define SENSOR_SPI spi0
#define PIN_MISO 16u
#define PIN_CS 17u
#define PIN_SCK 18u
#define PIN_MOSI 19u
/* The ADXL355 takes up to 10 MHz; 5 MHz leaves margin for flying leads. A whole-FIFO burst
 * (289 bytes) then takes about 0.5 ms. */
#define SPI_HZ 5000000u

void bridge_hal_spi_transfer(const uint8_t *out, size_t out_len, uint8_t *in, size_t in_len)
{
    /* Chip select by hand: the SPI block's own frame select would rise between bytes. */
    gpio_put(PIN_CS, 0);
    if (out_len > 0) {
        spi_write_blocking(SENSOR_SPI, out, out_len); /* waits until sent, discards what came back */
    }
    if (in_len > 0) {
        spi_read_blocking(SENSOR_SPI, 0x00, in, in_len);
    }
    gpio_put(PIN_CS, 1);
}

int bridge_hal_uart_read(void)
{
    const int received = getchar_timeout_us(0);

    return received < 0 ? -1 : (received & 0xFF);
}

/* The SDK's USB stdio waits for room itself (up to PICO_STDIO_USB_STDOUT_TIMEOUT_US) and cannot call
 * bridge_idle() meanwhile; the core's chunks are one USB packet (64 bytes), so a host that is
 * reading frees room within a frame (1 ms), far inside the FIFO's 8 ms at 4 kHz. No CR/LF
 * translation: the protocol's lines end in '\n' alone. */
void bridge_hal_uart_write(const uint8_t *bytes, size_t len)
{
    stdio_put_string((const char *)bytes, (int)len, false, false);
}

/* A client opening the port raises DTR, closing it drops DTR: stdio_usb_connected() follows it. While it is
 * down the SDK's USB stdio sends nothing; what tinyusb still held for the host when it fell is not cleared
 * here (not verified on a board). */
uint32_t bridge_hal_uart_session(void)
{
    static bool connected;
    static uint32_t session;
    const bool now = stdio_usb_connected();

    if (now != connected) {
        connected = now;
        ++session;
    }
    return session;
}

uint64_t bridge_hal_micros(void)
{
    return time_us_64();
}

const char *bridge_hal_board_name(void)
{
    return "rp2040";
}

static void sensor_spi_init(void)
{
    spi_init(SENSOR_SPI, SPI_HZ);
    spi_set_format(SENSOR_SPI, 8, SPI_CPOL_0, SPI_CPHA_0, SPI_MSB_FIRST); /* ADXL355: SPI mode 0 */
    gpio_set_function(PIN_MISO, GPIO_FUNC_SPI);
    gpio_set_function(PIN_SCK, GPIO_FUNC_SPI);
    gpio_set_function(PIN_MOSI, GPIO_FUNC_SPI);
    gpio_init(PIN_CS);
    gpio_put(PIN_CS, 1);
    gpio_set_dir(PIN_CS, GPIO_OUT);
}

int main(void)
{
    stdio_init_all();
    sensor_spi_init();
    bridge_init();
    for (;;) {
        bridge_poll(); /* never sleeps: a capture at 4 kHz needs a drain every few milliseconds */
    }
}
