/*
 * test_pio.c: includes the generated can_sja_pio.h with PIO bases in the
 * stand-in memory and checks the control words and the ack timeout.
 * With the plain memory stand-in nothing answers unless the test sets the
 * ack register first, which is how both paths are exercised.
 */
#include <stdio.h>
#include <string.h>

#define CAN_SJA_PIO_ADDR_BASE 0x3030u
#define CAN_SJA_PIO_DOUT_BASE 0x3010u
#define CAN_SJA_PIO_CTRL_BASE 0x3040u
#define CAN_SJA_PIO_ACK_BASE 0x3020u
#define CAN_SJA_PIO_DIN_BASE 0x3000u
#define CAN_SJA_PIO_TIMEOUT 50UL

#include "can_sja_pio.h"
#include "host_io_mem.h"

static int failures;

#define CHECK(cond)                                                         \
    do {                                                                    \
        if (!(cond)) {                                                      \
            printf("FAIL %s:%d: %s\n", __FILE__, __LINE__, #cond);          \
            failures++;                                                     \
        }                                                                   \
    } while (0)

int main(void)
{
    unsigned char v = 0;
    unsigned long before;

    CHECK(CAN_SJA_PIO_CTRL_WRITE == 0x07);
    CHECK(CAN_SJA_PIO_CTRL_READ == 0x06);
    CHECK(CAN_SJA_PIO_CTRL_RESET == 0x08);

    /* No ack: the write gives up after the timeout and drops the cycle. */
    memset(host_io_mem, 0, sizeof host_io_mem);
    before = host_io_reads;
    CHECK(can_sja_pio_write_reg(CAN_SJA_PELI_BTR0_REG, 0x41) == -1);
    CHECK(host_io_reads - before == CAN_SJA_PIO_TIMEOUT);
    CHECK(host_io_mem[CAN_SJA_PIO_CTRL_BASE] == 0x00);
    CHECK(host_io_mem[CAN_SJA_PIO_ADDR_BASE] == 6);
    CHECK(host_io_mem[CAN_SJA_PIO_DOUT_BASE] == 0x41);

    /* Ack present: write succeeds, read returns the data-in PIO. */
    host_io_mem[CAN_SJA_PIO_ACK_BASE] = 1;
    CHECK(can_sja_pio_write_reg(CAN_SJA_PELI_MOD_REG, 0x01) == 0);
    host_io_mem[CAN_SJA_PIO_DIN_BASE] = 0xA5;
    CHECK(can_sja_pio_read_reg(CAN_SJA_PELI_CDR_REG, &v) == 0);
    CHECK(v == 0xA5);
    CHECK(host_io_mem[CAN_SJA_PIO_ADDR_BASE] == 31);
    CHECK(host_io_mem[CAN_SJA_PIO_CTRL_BASE] == 0x00);

    can_sja_pio_reset(10);
    CHECK(host_io_mem[CAN_SJA_PIO_CTRL_BASE] == 0x00);

    if (failures == 0)
        printf("test_pio: all checks passed\n");
    return failures == 0 ? 0 : 1;
}
