/*
 * test_driver.c: runs can_driver.c against the plain-memory stand-in and
 * checks the bytes it writes and how it parses what it reads. Expected
 * bytes are worked out by hand from the data sheet buffer layouts.
 */
#include <stdio.h>
#include <string.h>

#include "can_driver.h"
#include "host_io_mem.h"

#define BASE 0x2000u
#define M(n) host_io_mem[BASE + (n)]

static int failures;

#define CHECK(cond)                                                         \
    do {                                                                    \
        if (!(cond)) {                                                      \
            printf("FAIL %s:%d: %s\n", __FILE__, __LINE__, #cond);          \
            failures++;                                                     \
        }                                                                   \
    } while (0)

static const can_config_t cfg = {
    0x41, 0x25, 0xDA, 0x07, {0x11, 0x22, 0x33, 0x44}, {0xF1, 0xF2, 0xF3, 0xF4}, 1, 0x05,
};

static void pelican(void)
{
    can_dev_t dev;
    can_frame_t f;
    can_errors_t e;

    memset(host_io_mem, 0, sizeof host_io_mem);
    CHECK(can_init(&dev, BASE, CAN_VIEW_PELI, &cfg) == CAN_OK);
    CHECK(dev.view == CAN_VIEW_PELI);
    CHECK(M(31) == 0x87);                      /* CDR: CAN mode + cfg bits */
    CHECK(M(16) == 0x11 && M(19) == 0x44);     /* ACR0, ACR3 */
    CHECK(M(20) == 0xF1 && M(23) == 0xF4);     /* AMR0, AMR3 */
    CHECK(M(6) == 0x41 && M(7) == 0x25 && M(8) == 0xDA);
    CHECK(M(4) == 0x05);                       /* IER */
    CHECK(M(0) == 0x08);                       /* MOD: AFM, RM cleared */

    /* Transmit buffer locked, then bus-off. */
    memset(&f, 0, sizeof f);
    M(2) = 0x00;
    CHECK(can_transmit(&dev, &f) == CAN_EBUSY);
    M(2) = 0x80 | 0x04;
    CHECK(can_transmit(&dev, &f) == CAN_EBUSOFF);

    /* Extended data frame: ID 0x12345678 << 3 = 0x91A2B3C0. */
    M(2) = 0x0C;
    f.id = 0x12345678u;
    f.extended = 1;
    f.dlc = 3;
    f.data[0] = 0xD1;
    f.data[1] = 0xD2;
    f.data[2] = 0xD3;
    CHECK(can_transmit(&dev, &f) == CAN_OK);
    CHECK(M(16) == 0x83);
    CHECK(M(17) == 0x91 && M(18) == 0xA2 && M(19) == 0xB3 && M(20) == 0xC0);
    CHECK(M(21) == 0xD1 && M(23) == 0xD3 && M(24) == 0x00);
    CHECK(M(1) == 0x01); /* CMR.TR */

    /* Standard frame 0x529: the thesis's ID bytes A5 and 2x. */
    memset(&f, 0, sizeof f);
    f.id = 0x529;
    f.dlc = 1;
    f.data[0] = 0x51;
    CHECK(can_transmit(&dev, &f) == CAN_OK);
    CHECK(M(16) == 0x01 && M(17) == 0xA5 && M(18) == 0x20 && M(19) == 0x51);
    f.id = 0x800;
    CHECK(can_transmit(&dev, &f) == CAN_EINVAL);

    /* Receive a standard frame, then release. */
    M(16) = 0x02;
    M(17) = 0xA5;
    M(18) = 0x20;
    M(19) = 0x11;
    M(20) = 0x22;
    M(2) = 0x0D; /* RBS, TBS, TCS */
    M(1) = 0;
    memset(&f, 0xEE, sizeof f);
    CHECK(can_receive(&dev, &f) == 1);
    CHECK(f.id == 0x529 && !f.extended && !f.rtr && f.dlc == 2);
    CHECK(f.data[0] == 0x11 && f.data[1] == 0x22 && f.data[2] == 0);
    CHECK(M(1) == 0x04); /* CMR.RRB */

    /* Extended remote frame with DLC 15: no data bytes read. */
    M(16) = 0xC0 | 0x0F;
    M(17) = 0x91;
    M(18) = 0xA2;
    M(19) = 0xB3;
    M(20) = 0xC4; /* RTR copy in bit 2 must not leak into the ID */
    CHECK(can_receive(&dev, &f) == 1);
    CHECK(f.id == 0x12345678u && f.extended && f.rtr && f.dlc == 15);

    /* Overrun without message: cleared with CMR.CDO, counted. */
    M(2) = 0x02;
    M(1) = 0;
    CHECK(can_receive(&dev, &f) == 0);
    CHECK(M(1) == 0x08 && dev.overruns == 1);

    /* Error capture. */
    M(2) = 0x40;
    M(3) = 0x84; /* BEI, EI */
    M(12) = 0x48; /* form error, during transmission, segment 8 */
    M(11) = 0xE5;
    M(14) = 7;
    M(15) = 130;
    CHECK(can_read_errors(&dev, &e) == CAN_OK);
    CHECK(e.has_capture && e.ecc == 0x48 && e.alc == 5 && e.rxerr == 7 && e.txerr == 130);
    CHECK(e.error_warning && !e.bus_off && e.ir == 0x84);
    CHECK(strcmp(can_ecc_kind(e.ecc), "form") == 0);
    CHECK(strcmp(can_ecc_kind(0xC0), "other") == 0);

    /* Bus-off recovery leaves reset mode, keeping AFM. */
    M(0) = 0x09;
    CHECK(can_bus_off_recover(&dev) == CAN_OK);
    CHECK(M(0) == 0x08);
}

static void basiccan(void)
{
    can_dev_t dev;
    can_frame_t f;
    can_errors_t e;

    memset(host_io_mem, 0, sizeof host_io_mem);
    M(31) = 0x80; /* starts in PeliCAN: the driver must use MOD to reset */
    CHECK(can_init(&dev, BASE, CAN_VIEW_BASIC, &cfg) == CAN_OK);
    CHECK(dev.view == CAN_VIEW_BASIC);
    CHECK(M(31) == 0x07);
    CHECK(M(4) == 0x11 && M(5) == 0xF1);
    CHECK(M(6) == 0x41 && M(7) == 0x25 && M(8) == 0xDA);
    CHECK(M(0) == 0x04); /* CR: irq_enable 0x05 keeps TIE only (bit 0 is RR) */

    memset(&f, 0, sizeof f);
    M(2) = 0x0C;
    f.id = 0x529;
    f.dlc = 1;
    f.data[0] = 0x51;
    CHECK(can_transmit(&dev, &f) == CAN_OK);
    CHECK(M(10) == 0xA5 && M(11) == 0x21 && M(12) == 0x51);
    CHECK(M(1) == 0x01);
    f.extended = 1;
    CHECK(can_transmit(&dev, &f) == CAN_EINVAL);

    M(20) = 0xA5;
    M(21) = 0x31; /* ID.2..0 = 1, RTR, DLC 1 */
    M(2) = 0x0D;
    CHECK(can_receive(&dev, &f) == 1);
    CHECK(f.id == 0x529 && f.rtr && f.dlc == 1 && !f.extended && f.data[0] == 0);
    CHECK(M(1) == 0x04);

    M(3) = 0xE4;
    CHECK(can_read_errors(&dev, &e) == CAN_OK);
    CHECK(!e.has_capture && e.ir == 0xE4 && e.txerr == 0);
}

int main(void)
{
    pelican();
    basiccan();
    if (failures == 0)
        printf("test_driver: all checks passed\n");
    return failures == 0 ? 0 : 1;
}
