/* m4f_start.c: reset, memory and output of the Cortex-M4F firmware the embedded tests run
 * under QEMU (mps2-an386). No C library start-up: the reset handler copies .data, clears
 * .bss, switches the FPU on, paints the stack with a known word (so that the deepest
 * stack the ticks used can be read afterwards) and calls ticks_main. Output goes to the
 * host through semihosting, the debugger's channel QEMU serves; nothing of stdio. */
#include <stdint.h>

#include "ticks_port.h"

extern uint32_t m4f_data_start[], m4f_data_end[], m4f_data_load[];
extern uint32_t m4f_bss_start[], m4f_bss_end[];
extern uint32_t m4f_stack_bottom[], m4f_stack_top[];

#define STACK_PAINT 0x5afec0deu
#define CPACR       (*(volatile uint32_t*)0xE000ED88u)

void m4f_reset(void);
static void m4f_fault(void);

/* The vector table: the initial stack pointer, then the handlers (reset, NMI, the faults).
 * A fault ends the run with a message: a firmware error must not hang the test. */
typedef void (*m4f_handler)(void);
typedef struct m4f_vector_table {
    uint32_t* stack_top;
    m4f_handler handlers[6];
} m4f_vector_table;

__attribute__((section(".vectors"), used)) static const m4f_vector_table m4f_vectors = {
    m4f_stack_top, {m4f_reset, m4f_fault, m4f_fault, m4f_fault, m4f_fault, m4f_fault}};

/* semihosting: r0 the operation, r1 its argument block; bkpt 0xab traps to the host */
static int semihost(int operation, const void* argument)
{
    register int r0 __asm__("r0") = operation;
    register const void* r1 __asm__("r1") = argument;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

#define SYS_WRITE0                   0x04
#define SYS_EXIT                     0x18
#define ADP_STOPPED_APPLICATION_EXIT 0x20026u

void ticks_write(const char* text)
{
    semihost(SYS_WRITE0, text);
}

void ticks_exit(int status)
{
    /* the 32-bit form of SYS_EXIT carries no exit code: a failed run says so first */
    if (status != 0) {
        ticks_write("exit status nonzero\n");
    }
    semihost(SYS_EXIT, (const void*)ADP_STOPPED_APPLICATION_EXIT);
    for (;;) {
    }
}

unsigned long ticks_stack_used(void)
{
    const uint32_t* word = m4f_stack_bottom;
    while (word < m4f_stack_top && *word == STACK_PAINT) {
        ++word;
    }
    return (unsigned long)((const char*)m4f_stack_top - (const char*)word);
}

/* No heap: the C library's allocator gets no memory, so that an allocation on the
 * controller's path fails at once instead of growing into the stack. (The formatted
 * reasons of the scene's refusals link newlib's printf, whose code names malloc; with
 * a caller's buffer it never calls it.) */
void* _sbrk(int increment);
void* _sbrk(int increment)
{
    (void)increment;
    return (void*)-1;
}

static void m4f_fault(void)
{
    ticks_write("fault: the firmware took a hard fault\n");
    ticks_exit(1);
}

void m4f_reset(void)
{
    uint32_t* word;
    const uint32_t* from = m4f_data_load;
    for (word = m4f_data_start; word < m4f_data_end; ++word) {
        *word = *from++;
    }
    for (word = m4f_bss_start; word < m4f_bss_end; ++word) {
        *word = 0;
    }
    CPACR |= 0xFu << 20; /* CP10 and CP11 (the FPU): full access */
    __asm__ volatile("dsb\n\tisb" ::: "memory");
    {
        /* paint from the bottom up to 64 bytes below this frame's stack pointer */
        uint32_t* sp;
        __asm__ volatile("mov %0, sp" : "=r"(sp));
        for (word = m4f_stack_bottom; word < sp - 16; ++word) {
            *word = STACK_PAINT;
        }
    }
    ticks_exit(ticks_main());
}
