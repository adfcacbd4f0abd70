/*
 * host_io_mem.c: the stand-in io.h functions over a flat byte array, for
 * host unit tests. An access outside the array aborts with a message
 * (a wrong address must not pass silently).
 */
#include <io.h>
#include <stdio.h>
#include <stdlib.h>

#include "host_io_mem.h"

uint8_t host_io_mem[HOST_IO_MEM_SIZE];
unsigned long host_io_reads;
unsigned long host_io_writes;

static uintptr_t check(uintptr_t addr, unsigned size)
{
    if (addr + size > HOST_IO_MEM_SIZE) {
        fprintf(stderr, "host_io_mem: access at 0x%lx (size %u) outside 0..0x%x\n",
                (unsigned long)addr, size, HOST_IO_MEM_SIZE);
        abort();
    }
    return addr;
}

uint8_t host_io_read8(uintptr_t addr)
{
    host_io_reads++;
    return host_io_mem[check(addr, 1)];
}

void host_io_write8(uintptr_t addr, uint8_t data)
{
    host_io_writes++;
    host_io_mem[check(addr, 1)] = data;
}

uint16_t host_io_read16(uintptr_t addr)
{
    uintptr_t a = check(addr, 2);
    host_io_reads++;
    return (uint16_t)(host_io_mem[a] | (host_io_mem[a + 1] << 8));
}

void host_io_write16(uintptr_t addr, uint16_t data)
{
    uintptr_t a = check(addr, 2);
    host_io_writes++;
    host_io_mem[a] = (uint8_t)data;
    host_io_mem[a + 1] = (uint8_t)(data >> 8);
}

uint32_t host_io_read32(uintptr_t addr)
{
    uintptr_t a = check(addr, 4);
    host_io_reads++;
    return (uint32_t)host_io_mem[a] | ((uint32_t)host_io_mem[a + 1] << 8) |
           ((uint32_t)host_io_mem[a + 2] << 16) | ((uint32_t)host_io_mem[a + 3] << 24);
}

void host_io_write32(uintptr_t addr, uint32_t data)
{
    uintptr_t a = check(addr, 4);
    host_io_writes++;
    host_io_mem[a] = (uint8_t)data;
    host_io_mem[a + 1] = (uint8_t)(data >> 8);
    host_io_mem[a + 2] = (uint8_t)(data >> 16);
    host_io_mem[a + 3] = (uint8_t)(data >> 24);
}
