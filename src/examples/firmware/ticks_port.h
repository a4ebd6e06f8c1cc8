/* ticks_port.h: what a tick program (generated per scene by dyadfmu.embedded) needs from
 * the machine it runs on, and the helpers it shares. m4f_start.c is the port for the
 * Cortex-M4F under QEMU (semihosting), host_port.c the one for a Linux host (stdio). */
#ifndef DYADFMU_TICKS_PORT_H
#define DYADFMU_TICKS_PORT_H

/* the port */
void ticks_write(const char* text);
void ticks_exit(int status);
/* the deepest the stack went since reset (bytes), or 0 where the port cannot tell */
unsigned long ticks_stack_used(void);

/* the tick program: its exit status */
int ticks_main(void);

/* ticks_common.c. ticks_begin and ticks_end bracket one tick's evaluation: functions of
 * their own that nothing inlines, whose addresses mark where an instruction trace's tick
 * starts and ends. */
void ticks_begin(long tick);
void ticks_end(long tick);
/* a line "tick K STATUS" then each value's IEEE bit pattern in hex, exact on any libc */
void ticks_write_tick(long tick, int status);
void ticks_write_bits(double value);
void ticks_write_end_of_line(void);
void ticks_write_count(const char* label, unsigned long count);

#endif /* DYADFMU_TICKS_PORT_H */
