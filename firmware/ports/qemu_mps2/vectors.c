/* Vector table for mps2-an385: initial stack, then newlib's _start (rdimon
 * crt0 sets up semihosting, .bss and the heap). */
#include <stdint.h>

extern uint32_t __stack_top;
void _start(void);

static void fault(void) {
    for (;;) {}
}

__attribute__((section(".vectors"), used)) static void (*const vectors[16])(void) = {
    (void (*)(void))(uintptr_t)&__stack_top, _start, fault, fault, fault, fault, fault,
};
