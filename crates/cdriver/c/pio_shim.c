/*
 * pio_shim.c: the thesis-style PIO wiring (seed 000 annexe 4) as 8-bit
 * host_io callbacks. Each register access of the C driver becomes one
 * Wishbone cycle bit-banged by the generated can_sja_pio.h accessors,
 * whose IORD/IOWR on the five PIO cores reach the simulator through the
 * 32-bit callbacks. The ack PIO uses rising-edge capture because the
 * core's wb_ack_o is a one-clock pulse (see can_sja_pio.h).
 */
#include <stdint.h>

/* PIO core bases, 16 bytes apart (four word-spaced registers each). */
#define CAN_SJA_PIO_ADDR_BASE 0x1000u
#define CAN_SJA_PIO_DOUT_BASE 0x1010u
#define CAN_SJA_PIO_CTRL_BASE 0x1020u
#define CAN_SJA_PIO_ACK_BASE 0x1030u
#define CAN_SJA_PIO_DIN_BASE 0x1040u
#define CAN_SJA_PIO_ACK_EDGE_CAPTURE 1
#ifndef CAN_SJA_PIO_TIMEOUT
#define CAN_SJA_PIO_TIMEOUT 2000UL
#endif

#include "can_sja_pio.h"

/* Base of the CAN register window the driver was given (can_init). */
static uintptr_t pio_can_base;
/* Accesses whose ack never came (the accessor returned -1). */
static unsigned long pio_timeouts;

void cdriver_pio_set_base(uintptr_t base)
{
    pio_can_base = base;
}

unsigned long cdriver_pio_take_timeouts(void)
{
    unsigned long n = pio_timeouts;
    pio_timeouts = 0;
    return n;
}

/* The five PIO bases, in the order address, data out, control, ack, data in. */
void cdriver_pio_bases(uintptr_t out[5])
{
    out[0] = CAN_SJA_PIO_ADDR_BASE;
    out[1] = CAN_SJA_PIO_DOUT_BASE;
    out[2] = CAN_SJA_PIO_CTRL_BASE;
    out[3] = CAN_SJA_PIO_ACK_BASE;
    out[4] = CAN_SJA_PIO_DIN_BASE;
}

unsigned long cdriver_pio_timeout_polls(void)
{
    return CAN_SJA_PIO_TIMEOUT;
}

/* After an access timed out, the rest of the driver call fails fast
 * instead of waiting out every timeout of its bounded loops again. */
uint8_t cdriver_pio_read8(void *ctx, uintptr_t addr)
{
    unsigned char v = 0xFF;
    (void)ctx;
    if (pio_timeouts != 0)
        return 0xFF;
    if (can_sja_pio_read_reg((unsigned char)(addr - pio_can_base), &v) != 0) {
        pio_timeouts++;
        return 0xFF;
    }
    return v;
}

void cdriver_pio_write8(void *ctx, uintptr_t addr, uint8_t data)
{
    (void)ctx;
    if (pio_timeouts != 0)
        return;
    if (can_sja_pio_write_reg((unsigned char)(addr - pio_can_base), data) != 0)
        pio_timeouts++;
}

/* Holds the core's reset input for `hold` polling loops through the control PIO. */
void cdriver_pio_reset(unsigned long hold)
{
    can_sja_pio_reset(hold);
}
