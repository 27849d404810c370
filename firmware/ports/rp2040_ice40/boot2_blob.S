/* The checksummed boot2 (256 bytes, made by rp2040_image boot2 from
 * boot2.c) placed at the start of flash by rp2040.ld. */
    .section .boot2, "a"
    .incbin BOOT2_BIN
