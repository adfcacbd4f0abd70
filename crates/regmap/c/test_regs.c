/*
 * test_regs.c: includes the generated can_sja_regs.h (either spacing) and
 * checks, through the stand-in io.h, that the macros reach the bytes the
 * data sheet gives. Exit status 0 = pass; each failure prints a line.
 */
#include <stdio.h>
#include <string.h>

#include "can_sja_regs.h"
#include "host_io_mem.h"

#define BASE 0x1000u

static int failures;

#define CHECK(cond)                                                         \
    do {                                                                    \
        if (!(cond)) {                                                      \
            printf("FAIL %s:%d: %s\n", __FILE__, __LINE__, #cond);          \
            failures++;                                                     \
        }                                                                   \
    } while (0)

/* Byte the data of the register with index n occupies on the host bus
 * (stride and byte lane). */
static unsigned at(unsigned n) { return BASE + CAN_SJA_OFFSET(n); }

int main(void)
{
    unsigned i;

    /* Indexes as in the data sheet (Tables 1 and 5). */
    CHECK(CAN_SJA_PELI_MOD_REG == 0);
    CHECK(CAN_SJA_PELI_IER_REG == 4);
    CHECK(CAN_SJA_BASIC_ACR_REG == 4);
    CHECK(CAN_SJA_PELI_ECC_REG == 12);
    CHECK(CAN_SJA_PELI_ACR0_REG == 16 && CAN_SJA_PELI_TXFI_REG == 16 && CAN_SJA_PELI_RXFI_REG == 16);
    CHECK(CAN_SJA_PELI_AMR3_REG == 23);
    CHECK(CAN_SJA_PELI_RXFIFO_REG == 32 && CAN_SJA_PELI_RXFIFO_LEN == 64);
    CHECK(CAN_SJA_BASIC_TXID1_REG == 10 && CAN_SJA_BASIC_RXDATA_REG == 22);
    CHECK(CAN_SJA_BASIC_CDR_REG == 31 && CAN_SJA_PELI_CDR_REG == 31);

    /* Field masks and offsets. */
    CHECK(CAN_SJA_PELI_SR_TBS_MSK == 0x04 && CAN_SJA_PELI_SR_TBS_OFST == 2);
    CHECK(CAN_SJA_PELI_IR_BEI_MSK == 0x80);
    CHECK(CAN_SJA_PELI_BTR0_SJW_MSK == 0xC0 && CAN_SJA_PELI_BTR0_SJW_OFST == 6);
    CHECK(CAN_SJA_PELI_ECC_ERRC_MSK == 0xC0);
    CHECK(CAN_SJA_PELI_CDR_CANMODE_MSK == 0x80);
    CHECK(CAN_SJA_BASIC_CR_RR_MSK == 0x01 && CAN_SJA_BASIC_CMR_GTS_MSK == 0x10);
    CHECK(CAN_SJA_PELI_FRAME_EFF_DATA_OFST == 5 && CAN_SJA_PELI_FRAME_SFF_DATA_OFST == 3);

    /* Writes land on base + index * stride + lane, and nowhere else. */
    memset(host_io_mem, 0, sizeof host_io_mem);
    IOWR_CAN_SJA_PELI_BTR0(BASE, 0x41);
    CHECK(host_io_mem[at(6)] == 0x41);
    for (i = 0; i < 4 * 128; i++)
        CHECK(BASE + i == at(6) || host_io_mem[BASE + i] == 0);
    IOWR_CAN_SJA_BASIC_CR(BASE, CAN_SJA_BASIC_CR_RR_MSK);
    CHECK(host_io_mem[at(0)] == 0x01);
    IOWR_CAN_SJA_PELI_TXB(BASE, 11, 0x5A); /* last TX byte: address 28 */
    CHECK(host_io_mem[at(28)] == 0x5A);
    CAN_SJA_IOWR(BASE, 31, 0x88);
    CHECK(host_io_mem[at(31)] == 0x88);

    /* Reads come from the same place. */
    host_io_mem[at(2)] = 0x3C;
    CHECK(IORD_CAN_SJA_PELI_SR(BASE) == 0x3C);
    CHECK(IORD_CAN_SJA_BASIC_SR(BASE) == 0x3C);
    for (i = 0; i < CAN_SJA_PELI_RXFIFO_LEN; i++)
        host_io_mem[at(32 + i)] = (uint8_t)(i * 3);
    for (i = 0; i < CAN_SJA_PELI_RXFIFO_LEN; i++)
        CHECK(IORD_CAN_SJA_PELI_RXFIFO(BASE, i) == (uint8_t)(i * 3));
    CHECK((uintptr_t)IOADDR_CAN_SJA_PELI_ALC(BASE) == at(11));

    /* A write puts nothing but the register's byte on the bus. */
    memset(host_io_mem, 0, sizeof host_io_mem);
    IOWR_CAN_SJA_PELI_TXERR(BASE, 0x1FF);
    CHECK(host_io_mem[at(15)] == 0xFF);
    for (i = 0; i < 4 * 128; i++)
        CHECK(BASE + i == at(15) || host_io_mem[BASE + i] == 0);
    /* A read returns only the register's byte, whatever the other lanes hold. */
    memset(host_io_mem, 0xA5, sizeof host_io_mem);
    host_io_mem[at(3)] = 0x81;
    CHECK((IORD_CAN_SJA_PELI_IR(BASE) & 0xFF) == 0x81);

    if (failures == 0)
        printf("test_regs: all checks passed (spacing %u, offset of register 1: %u)\n", (unsigned)CAN_SJA_SPACING, (unsigned)CAN_SJA_OFFSET(1));
    return failures == 0 ? 0 : 1;
}
