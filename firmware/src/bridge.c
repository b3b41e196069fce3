/* The main-loop entry points: a request line taken from the HAL's bytes (line.c), then answered. */
#include "bridge.h"

#include "capture.h"
#include "commands.h"
#include "line.h"
#include "reply.h"
#include "sensor.h"

void bridge_init(void)
{
    line_forget();
    capture_reset();
    (void)sensor_detect();
}

void bridge_poll(void)
{
    capture_service();
    /* At most one request, and a bounded number of bytes, per poll: a flood of input cannot keep the loop
     * from draining. */
    const line_status status = line_take(BRIDGE_LINE_MAX + 2u);

    if (status == LINE_INCOMPLETE) {
        return;
    }
    reply_to(line_session());
    if (status == LINE_TOO_LONG) {
        reply_error("line too long");
    } else if (status == LINE_UNPRINTABLE) {
        reply_error("not printable ASCII");
    } else {
        command_execute(line_text());
    }
}

void bridge_idle(void)
{
    capture_service();
}

bool bridge_capturing(void)
{
    return capture_running();
}
