/* Cortex-M0+ start-up: vector table (entered by boot2 at 0x10000100), .data
 * copy, .bss clear, clocks, and the memset/memcpy the compiler may emit
 * (there is no libc in this image).  No interrupt is enabled: the USB stack
 * and the link are polled from the main loop. */
#include <stddef.h>
#include <stdint.h>

#include "port.h"

extern uint32_t __data_load, __data_start, __data_end, __bss_start, __bss_end, __stack_top;
int main(void);

void *memset(void *d, int c, size_t n) {
    uint8_t *p = d;
    while (n--) *p++ = (uint8_t)c;
    return d;
}
void *memcpy(void *d, const void *s, size_t n) {
    uint8_t *p = d;
    const uint8_t *q = s;
    while (n--) *p++ = *q++;
    return d;
}

void Reset_Handler(void) {
    /* the linker's symbols are separate objects to C: compare addresses as integers */
    const uint32_t *s = &__data_load;
    for (uintptr_t d = (uintptr_t)&__data_start; d < (uintptr_t)&__data_end; d += 4) *(uint32_t *)d = *s++;
    for (uintptr_t d = (uintptr_t)&__bss_start; d < (uintptr_t)&__bss_end; d += 4) *(uint32_t *)d = 0;
    board_clocks_init();
    main();
    for (;;) {}
}

static void Default_Handler(void) {
    for (;;) {}
}

/* 16 system exceptions + 26 RP2040 interrupts (48 words, VTOR needs 256-byte
 * alignment: 0x10000100 has it); only the first two are used. */
#define D2 Default_Handler, Default_Handler
#define D8 D2, D2, D2, D2
__attribute__((section(".vectors"), used)) static void (*const vectors[16 + 26])(void) = {
    (void (*)(void))(uintptr_t)&__stack_top, Reset_Handler, D8, D8, D8, D8, D8,
};
