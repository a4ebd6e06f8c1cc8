/* ticks_common.c: the markers and the output of a tick program, on any port. */
#include <string.h>

#include "ticks_port.h"

#if defined(__GNUC__)
#define TICKS_NOINLINE __attribute__((noinline))
#else
#define TICKS_NOINLINE
#endif

/* the markers write a volatile, so that no compiler folds them away */
static volatile long ticks_current;

TICKS_NOINLINE void ticks_begin(long tick)
{
    ticks_current = tick;
}

TICKS_NOINLINE void ticks_end(long tick)
{
    ticks_current = -tick - 1;
}

static void write_unsigned(unsigned long value)
{
    char text[24];
    char* at = text + sizeof text - 1;
    *at = '\0';
    do {
        *--at = (char)('0' + value % 10);
        value /= 10;
    } while (value != 0);
    ticks_write(at);
}

void ticks_write_tick(long tick, int status)
{
    ticks_write("tick ");
    write_unsigned((unsigned long)tick);
    ticks_write(status == 0 ? " 0" : status == 1 ? " 1" : status == 3 ? " 3" : " 4");
}

void ticks_write_bits(double value)
{
    static const char digits[] = "0123456789abcdef";
    unsigned char bytes[sizeof value];
    unsigned long long bits = 0;
    char text[18];
    int k;
    memcpy(bytes, &value, sizeof value);
    for (k = (int)sizeof value - 1; k >= 0; --k) { /* little-endian on both ports */
        bits = (bits << 8) | bytes[k];
    }
    text[0] = ' ';
    for (k = 0; k < 16; ++k) {
        text[16 - k] = digits[(bits >> (4 * k)) & 0xfu];
    }
    text[17] = '\0';
    ticks_write(text);
}

void ticks_write_end_of_line(void)
{
    ticks_write("\n");
}

void ticks_write_count(const char* label, unsigned long count)
{
    ticks_write(label);
    ticks_write(" ");
    write_unsigned(count);
    ticks_write("\n");
}
