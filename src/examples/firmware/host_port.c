/* host_port.c: a tick program's port on a hosted C library: standard output, exit. */
#include <stdio.h>
#include <stdlib.h>

#include "ticks_port.h"

void ticks_write(const char* text)
{
    fputs(text, stdout);
}

void ticks_exit(int status)
{
    fflush(stdout);
    exit(status);
}

unsigned long ticks_stack_used(void)
{
    return 0;
}

int main(void)
{
    ticks_exit(ticks_main());
    return 0;
}
