/* host_io_callback.c: see host_io_callback.h. */
#include <io.h>
#include <stdio.h>
#include <stdlib.h>

#include "host_io_callback.h"

static host_io_read8_fn cb_read8;
static host_io_write8_fn cb_write8;
static host_io_read32_fn cb_read32;
static host_io_write32_fn cb_write32;
static void *cb_ctx;

void host_io_set_callbacks(host_io_read8_fn read8, host_io_write8_fn write8,
                           host_io_read32_fn read32, host_io_write32_fn write32,
                           void *ctx)
{
    cb_read8 = read8;
    cb_write8 = write8;
    cb_read32 = read32;
    cb_write32 = write32;
    cb_ctx = ctx;
}

static void need_callbacks(void)
{
    if (cb_read8 == NULL || cb_write8 == NULL) {
        fprintf(stderr, "host_io_callback: IORD/IOWR used before host_io_set_callbacks\n");
        abort();
    }
}

uint8_t host_io_read8(uintptr_t addr)
{
    need_callbacks();
    return cb_read8(cb_ctx, addr);
}

void host_io_write8(uintptr_t addr, uint8_t data)
{
    need_callbacks();
    cb_write8(cb_ctx, addr, data);
}

/* 16-bit accesses (a header generated at a 2-byte stride) as one 8-bit
 * access of the low byte: the simulated hosts have an 8-bit data bus. */
uint16_t host_io_read16(uintptr_t addr)
{
    need_callbacks();
    return cb_read8(cb_ctx, addr);
}

void host_io_write16(uintptr_t addr, uint16_t data)
{
    need_callbacks();
    cb_write8(cb_ctx, addr, (uint8_t)data);
}

uint32_t host_io_read32(uintptr_t addr)
{
    need_callbacks();
    if (cb_read32 != NULL)
        return cb_read32(cb_ctx, addr);
    return cb_read8(cb_ctx, addr);
}

void host_io_write32(uintptr_t addr, uint32_t data)
{
    need_callbacks();
    if (cb_write32 != NULL)
        cb_write32(cb_ctx, addr, data);
    else
        cb_write8(cb_ctx, addr, (uint8_t)data);
}
