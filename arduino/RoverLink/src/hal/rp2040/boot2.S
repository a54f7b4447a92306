/* The RP2040's second-stage boot block (datasheet 2.8.1): the boot ROM copies the first 256 bytes
   of flash to SRAM at 0x20041f00, checks their CRC-32 (the last 4 bytes, which the build appends)
   and runs them. This one sets the flash interface (SSI) up for execute-in-place with the standard
   03h read command, which every SPI flash answers (no quad mode: slower, and independent of the
   chip on the board), at clk_sys / 4 (31 MHz once the firmware runs clk_sys at 125 MHz, within
   the 50 MHz such chips allow for 03h), then starts the image through its vector table. */
#if defined(ROVERLINK_ARCH_RP2040)  /* the Arduino IDE assembles every .S of a library */
    .syntax unified
    .cpu cortex-m0plus
    .thumb

    .equ XIP_SSI, 0x18000000
    .equ SSI_CTRLR0, 0x00
    .equ SSI_CTRLR1, 0x04
    .equ SSI_SSIENR, 0x08
    .equ SSI_BAUDR, 0x14
    .equ SSI_SPI_CTRLR0, 0xf4
    .equ VECTORS, 0x10000100
    .equ SCB_VTOR, 0xe000ed08

    .section .text.boot2, "ax"
    .global boot2_entry
    .type boot2_entry, %function
    .thumb_func
boot2_entry:
    push {lr}
    ldr r3, =XIP_SSI
    movs r1, #0
    str r1, [r3, #SSI_SSIENR]       /* off while it is configured */
    movs r1, #4
    str r1, [r3, #SSI_BAUDR]        /* clk_sys / 4 */
    ldr r1, =((31 << 16) | (3 << 8))
    str r1, [r3, #SSI_CTRLR0]       /* 32-bit frames, EEPROM-read transfers, standard SPI */
    movs r1, #0
    str r1, [r3, #SSI_CTRLR1]       /* one frame per transfer */
    ldr r1, =((0x03 << 24) | (2 << 8) | (6 << 2))
    ldr r0, =SSI_SPI_CTRLR0
    str r1, [r3, r0]                /* XIP command 03h, 8-bit instruction, 24-bit address */
    movs r1, #1
    str r1, [r3, #SSI_SSIENR]
    pop {r0}
    cmp r0, #0
    beq 1f
    bx r0                           /* called by code (lr set): return to it */
1:  ldr r0, =VECTORS                /* from the boot ROM (lr 0): start the image */
    ldr r1, =SCB_VTOR
    str r0, [r1]
    ldmia r0, {r0, r1}
    msr msp, r0
    bx r1
    .ltorg
#endif
