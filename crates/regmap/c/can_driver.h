/*
 * can_driver.h: a small driver for the SJA1000-compatible CAN controller,
 * written against the generated can_sja_regs.h only (no address typed by
 * hand). Works in the BasicCAN and the PeliCAN view. Every wait on the
 * hardware is bounded by CAN_DRV_POLLS reads.
 */
#ifndef CAN_DRIVER_H
#define CAN_DRIVER_H

#include <stdint.h>

#ifndef CAN_DRV_POLLS
#define CAN_DRV_POLLS 1000u
#endif

/* Return codes. */
#define CAN_OK 0
#define CAN_ETIMEDOUT (-1) /* the controller did not enter/leave reset mode */
#define CAN_EBUSY (-2)     /* transmit buffer locked (SR.TBS = 0) */
#define CAN_EINVAL (-3)    /* frame not representable in this view */
#define CAN_EBUSOFF (-4)   /* controller is bus-off (SR.BS = 1) */

typedef enum { CAN_VIEW_BASIC = 0, CAN_VIEW_PELI = 1 } can_view_t;

typedef struct {
    uint32_t id;      /* 11-bit or 29-bit identifier */
    uint8_t extended; /* 1 = 29-bit identifier (PeliCAN only) */
    uint8_t rtr;      /* 1 = remote frame */
    uint8_t dlc;      /* 0..15; at most 8 data bytes are carried */
    uint8_t data[8];
} can_frame_t;

typedef struct {
    uint8_t btr0, btr1; /* bus timing */
    uint8_t ocr;        /* output control, e.g. 0xDA normal mode */
    uint8_t cdr;        /* clock divider bits other than CAN mode */
    uint8_t acr[4];     /* BasicCAN uses acr[0] / amr[0] only */
    uint8_t amr[4];     /* 1 = don't care */
    uint8_t single_filter; /* PeliCAN MOD.AFM */
    uint8_t irq_enable; /* PeliCAN IER, or BasicCAN CR enable bits */
} can_config_t;

typedef struct {
    uintptr_t base;
    can_view_t view;
    unsigned long overruns; /* data overruns seen and cleared */
} can_dev_t;

typedef struct {
    uint8_t sr, ir;      /* status, and the interrupt flags consumed by the read */
    uint8_t has_capture; /* 1 in PeliCAN: ecc/alc/counters are valid */
    uint8_t ecc, alc;    /* error code capture, arbitration lost capture */
    uint8_t rxerr, txerr;
    uint8_t bus_off, error_warning;
} can_errors_t;

/* Resets into the requested view, programs timing and filters, and goes
 * to operating mode. */
int can_init(can_dev_t *dev, uintptr_t base, can_view_t view, const can_config_t *cfg);
/* Queues one frame: CAN_OK, CAN_EBUSY, CAN_EINVAL or CAN_EBUSOFF. */
int can_transmit(can_dev_t *dev, const can_frame_t *frame);
/* 1 and *frame filled (buffer released) if a frame was waiting, else 0. */
int can_receive(can_dev_t *dev, can_frame_t *frame);
/* Reads status, interrupt flags, and (PeliCAN) ECC, ALC and the counters. */
int can_read_errors(can_dev_t *dev, can_errors_t *err);
/* Leaves the reset mode that bus-off forced, starting bus-off recovery. */
int can_bus_off_recover(can_dev_t *dev);
/* Name of the ECC error code ("bit", "form", "stuff", "other"). */
const char *can_ecc_kind(uint8_t ecc);

#endif /* CAN_DRIVER_H */
