/*
 * can_driver.c: see can_driver.h. Uses only names from the generated
 * can_sja_regs.h; the access rules it follows (configuration writes in
 * reset mode, TX buffer writes while SR.TBS = 1, RX buffer release with
 * CMR.RRB) are the SJA1000 data sheet's.
 */
#include "can_driver.h"
#include "can_sja_regs.h"

#define RD(dev, idx) ((uint8_t)CAN_SJA_IORD((dev)->base, (idx)))
#define WR(dev, idx, v) CAN_SJA_IOWR((dev)->base, (idx), (uint8_t)(v))
#define IS_PELI(dev) ((dev)->view == CAN_VIEW_PELI)
/* A register or mask that exists in both views, under the view's own name. */
#define REG(dev, r) (IS_PELI(dev) ? CAN_SJA_PELI_##r##_REG : CAN_SJA_BASIC_##r##_REG)
#define MSK(dev, r, f) (IS_PELI(dev) ? CAN_SJA_PELI_##r##_##f##_MSK : CAN_SJA_BASIC_##r##_##f##_MSK)

/* Address 0 bit 0 is MOD.RM in PeliCAN and CR.RR in BasicCAN. */
static int set_reset_mode(can_dev_t *dev, int on, uint8_t mode_bits)
{
    unsigned n;
    for (n = 0; n < CAN_DRV_POLLS; n++) {
        uint8_t v;
        if (dev->view == CAN_VIEW_PELI) {
            WR(dev, CAN_SJA_PELI_MOD_REG, mode_bits | (on ? CAN_SJA_PELI_MOD_RM_MSK : 0));
            v = RD(dev, CAN_SJA_PELI_MOD_REG) & CAN_SJA_PELI_MOD_RM_MSK;
        } else {
            WR(dev, CAN_SJA_BASIC_CR_REG, mode_bits | (on ? CAN_SJA_BASIC_CR_RR_MSK : 0));
            v = RD(dev, CAN_SJA_BASIC_CR_REG) & CAN_SJA_BASIC_CR_RR_MSK;
        }
        if ((v != 0) == (on != 0))
            return CAN_OK;
    }
    return CAN_ETIMEDOUT;
}

int can_init(can_dev_t *dev, uintptr_t base, can_view_t view, const can_config_t *cfg)
{
    uint8_t cdr;
    int rc;

    dev->base = base;
    dev->overruns = 0;
    /* The view in force now decides which reset bit to use; CDR has the
     * same address and layout in both views. */
    dev->view = (RD(dev, CAN_SJA_BASIC_CDR_REG) & CAN_SJA_BASIC_CDR_CANMODE_MSK) ? CAN_VIEW_PELI : CAN_VIEW_BASIC;
    rc = set_reset_mode(dev, 1, 0);
    if (rc != CAN_OK)
        return rc;

    /* Select the view (CDR.CANMODE is writable in reset mode only). */
    cdr = (uint8_t)(cfg->cdr & (uint8_t)~CAN_SJA_BASIC_CDR_CANMODE_MSK);
    if (view == CAN_VIEW_PELI)
        cdr |= CAN_SJA_BASIC_CDR_CANMODE_MSK;
    WR(dev, REG(dev, CDR), cdr);
    dev->view = view;

    if (view == CAN_VIEW_PELI) {
        uint8_t mod = cfg->single_filter ? CAN_SJA_PELI_MOD_AFM_MSK : 0;
        WR(dev, CAN_SJA_PELI_MOD_REG, mod | CAN_SJA_PELI_MOD_RM_MSK);
        WR(dev, CAN_SJA_PELI_IER_REG, 0);
        WR(dev, CAN_SJA_PELI_ACR0_REG, cfg->acr[0]);
        WR(dev, CAN_SJA_PELI_ACR1_REG, cfg->acr[1]);
        WR(dev, CAN_SJA_PELI_ACR2_REG, cfg->acr[2]);
        WR(dev, CAN_SJA_PELI_ACR3_REG, cfg->acr[3]);
        WR(dev, CAN_SJA_PELI_AMR0_REG, cfg->amr[0]);
        WR(dev, CAN_SJA_PELI_AMR1_REG, cfg->amr[1]);
        WR(dev, CAN_SJA_PELI_AMR2_REG, cfg->amr[2]);
        WR(dev, CAN_SJA_PELI_AMR3_REG, cfg->amr[3]);
        WR(dev, CAN_SJA_PELI_BTR0_REG, cfg->btr0);
        WR(dev, CAN_SJA_PELI_BTR1_REG, cfg->btr1);
        WR(dev, CAN_SJA_PELI_OCR_REG, cfg->ocr);
        WR(dev, CAN_SJA_PELI_IER_REG, cfg->irq_enable);
        return set_reset_mode(dev, 0, mod);
    }
    WR(dev, CAN_SJA_BASIC_ACR_REG, cfg->acr[0]);
    WR(dev, CAN_SJA_BASIC_AMR_REG, cfg->amr[0]);
    WR(dev, CAN_SJA_BASIC_BTR0_REG, cfg->btr0);
    WR(dev, CAN_SJA_BASIC_BTR1_REG, cfg->btr1);
    WR(dev, CAN_SJA_BASIC_OCR_REG, cfg->ocr);
    return set_reset_mode(dev, 0,
                          cfg->irq_enable & (CAN_SJA_BASIC_CR_RIE_MSK | CAN_SJA_BASIC_CR_TIE_MSK |
                                             CAN_SJA_BASIC_CR_EIE_MSK | CAN_SJA_BASIC_CR_OIE_MSK));
}

static uint8_t data_len(const can_frame_t *f)
{
    if (f->rtr)
        return 0;
    return f->dlc > 8 ? 8 : f->dlc;
}

int can_transmit(can_dev_t *dev, const can_frame_t *f)
{
    uint8_t i, n = data_len(f);
    uint8_t sr = RD(dev, REG(dev, SR));

    if (sr & MSK(dev, SR, BS))
        return CAN_EBUSOFF;
    if (!(sr & MSK(dev, SR, TBS)))
        return CAN_EBUSY;

    if (dev->view == CAN_VIEW_PELI) {
        const unsigned fi = CAN_SJA_PELI_TXFI_REG;
        uint8_t info = (uint8_t)((f->dlc & CAN_SJA_PELI_TXFI_DLC_MSK) |
                                 (f->rtr ? CAN_SJA_PELI_TXFI_RTR_MSK : 0) |
                                 (f->extended ? CAN_SJA_PELI_TXFI_FF_MSK : 0));
        unsigned d;
        WR(dev, fi + CAN_SJA_PELI_FRAME_FI_OFST, info);
        if (f->extended) {
            uint32_t v = (f->id & 0x1FFFFFFFu) << 3;
            WR(dev, fi + CAN_SJA_PELI_FRAME_ID1_OFST, v >> 24);
            WR(dev, fi + CAN_SJA_PELI_FRAME_ID2_OFST, v >> 16);
            WR(dev, fi + CAN_SJA_PELI_FRAME_EFF_ID3_OFST, v >> 8);
            WR(dev, fi + CAN_SJA_PELI_FRAME_EFF_ID4_OFST, v & 0xF8u);
            d = fi + CAN_SJA_PELI_FRAME_EFF_DATA_OFST;
        } else {
            if (f->id > 0x7FFu)
                return CAN_EINVAL;
            WR(dev, fi + CAN_SJA_PELI_FRAME_ID1_OFST, f->id >> 3);
            WR(dev, fi + CAN_SJA_PELI_FRAME_ID2_OFST, (f->id & 7u) << 5);
            d = fi + CAN_SJA_PELI_FRAME_SFF_DATA_OFST;
        }
        for (i = 0; i < n; i++)
            WR(dev, d + i, f->data[i]);
        WR(dev, CAN_SJA_PELI_CMR_REG, CAN_SJA_PELI_CMR_TR_MSK);
        return CAN_OK;
    }

    if (f->extended || f->id > 0x7FFu)
        return CAN_EINVAL;
    IOWR_CAN_SJA_BASIC_TXID1(dev->base, f->id >> 3);
    IOWR_CAN_SJA_BASIC_TXID2(dev->base,
                             ((f->id & 7u) << CAN_SJA_BASIC_TXID2_ID_OFST) |
                             (f->rtr ? CAN_SJA_BASIC_TXID2_RTR_MSK : 0) |
                             (f->dlc & CAN_SJA_BASIC_TXID2_DLC_MSK));
    for (i = 0; i < n; i++)
        IOWR_CAN_SJA_BASIC_TXDATA(dev->base, i, f->data[i]);
    IOWR_CAN_SJA_BASIC_CMR(dev->base, CAN_SJA_BASIC_CMR_TR_MSK);
    return CAN_OK;
}

int can_receive(can_dev_t *dev, can_frame_t *f)
{
    uint8_t i, n, sr = RD(dev, REG(dev, SR));
    uint8_t release = MSK(dev, CMR, RRB);

    if (sr & MSK(dev, SR, DOS)) {
        dev->overruns++;
        release |= MSK(dev, CMR, CDO);
    }
    if (!(sr & MSK(dev, SR, RBS))) {
        if (sr & MSK(dev, SR, DOS))
            WR(dev, REG(dev, CMR), MSK(dev, CMR, CDO));
        return 0;
    }

    if (dev->view == CAN_VIEW_PELI) {
        const unsigned fi = CAN_SJA_PELI_RXFI_REG;
        uint8_t info = RD(dev, fi + CAN_SJA_PELI_FRAME_FI_OFST);
        unsigned d;
        f->extended = (info & CAN_SJA_PELI_RXFI_FF_MSK) ? 1 : 0;
        f->rtr = (info & CAN_SJA_PELI_RXFI_RTR_MSK) ? 1 : 0;
        f->dlc = (uint8_t)(info & CAN_SJA_PELI_RXFI_DLC_MSK);
        if (f->extended) {
            f->id = (((uint32_t)RD(dev, fi + CAN_SJA_PELI_FRAME_ID1_OFST) << 24) |
                     ((uint32_t)RD(dev, fi + CAN_SJA_PELI_FRAME_ID2_OFST) << 16) |
                     ((uint32_t)RD(dev, fi + CAN_SJA_PELI_FRAME_EFF_ID3_OFST) << 8) |
                     (uint32_t)RD(dev, fi + CAN_SJA_PELI_FRAME_EFF_ID4_OFST)) >> 3;
            d = fi + CAN_SJA_PELI_FRAME_EFF_DATA_OFST;
        } else {
            f->id = ((uint32_t)RD(dev, fi + CAN_SJA_PELI_FRAME_ID1_OFST) << 3) |
                    ((uint32_t)RD(dev, fi + CAN_SJA_PELI_FRAME_ID2_OFST) >> 5);
            d = fi + CAN_SJA_PELI_FRAME_SFF_DATA_OFST;
        }
        n = data_len(f);
        for (i = 0; i < n; i++)
            f->data[i] = RD(dev, d + i);
    } else {
        uint8_t id2 = (uint8_t)IORD_CAN_SJA_BASIC_RXID2(dev->base);
        f->extended = 0;
        f->id = ((uint32_t)(uint8_t)IORD_CAN_SJA_BASIC_RXID1(dev->base) << 3) |
                ((id2 & CAN_SJA_BASIC_RXID2_ID_MSK) >> CAN_SJA_BASIC_RXID2_ID_OFST);
        f->rtr = (id2 & CAN_SJA_BASIC_RXID2_RTR_MSK) ? 1 : 0;
        f->dlc = (uint8_t)(id2 & CAN_SJA_BASIC_RXID2_DLC_MSK);
        n = data_len(f);
        for (i = 0; i < n; i++)
            f->data[i] = (uint8_t)IORD_CAN_SJA_BASIC_RXDATA(dev->base, i);
    }
    for (i = n; i < 8; i++)
        f->data[i] = 0;
    WR(dev, REG(dev, CMR), release);
    return 1;
}

int can_read_errors(can_dev_t *dev, can_errors_t *e)
{
    e->sr = RD(dev, REG(dev, SR));
    e->ir = RD(dev, REG(dev, IR)); /* reading IR consumes the flags */
    e->bus_off = (e->sr & MSK(dev, SR, BS)) ? 1 : 0;
    e->error_warning = (e->sr & MSK(dev, SR, ES)) ? 1 : 0;
    if (dev->view == CAN_VIEW_PELI) {
        e->has_capture = 1;
        e->ecc = (uint8_t)IORD_CAN_SJA_PELI_ECC(dev->base); /* re-arms the capture */
        e->alc = (uint8_t)(IORD_CAN_SJA_PELI_ALC(dev->base) & CAN_SJA_PELI_ALC_BITNO_MSK);
        e->rxerr = (uint8_t)IORD_CAN_SJA_PELI_RXERR(dev->base);
        e->txerr = (uint8_t)IORD_CAN_SJA_PELI_TXERR(dev->base);
    } else {
        /* BasicCAN has no capture registers and no readable counters. */
        e->has_capture = 0;
        e->ecc = e->alc = e->rxerr = e->txerr = 0;
    }
    return CAN_OK;
}

int can_bus_off_recover(can_dev_t *dev)
{
    uint8_t keep = 0;
    if (dev->view == CAN_VIEW_PELI)
        keep = (uint8_t)(RD(dev, CAN_SJA_PELI_MOD_REG) & CAN_SJA_PELI_MOD_AFM_MSK);
    else
        keep = (uint8_t)(RD(dev, CAN_SJA_BASIC_CR_REG) &
                         (CAN_SJA_BASIC_CR_RIE_MSK | CAN_SJA_BASIC_CR_TIE_MSK |
                          CAN_SJA_BASIC_CR_EIE_MSK | CAN_SJA_BASIC_CR_OIE_MSK));
    return set_reset_mode(dev, 0, keep);
}

const char *can_ecc_kind(uint8_t ecc)
{
    switch ((ecc & CAN_SJA_PELI_ECC_ERRC_MSK) >> CAN_SJA_PELI_ECC_ERRC_OFST) {
    case 0:
        return "bit";
    case 1:
        return "form";
    case 2:
        return "stuff";
    default:
        return "other";
    }
}
