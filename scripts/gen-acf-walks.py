#!/usr/bin/env python3
"""Writes tb/mutation-holes/acf-walk-*.toml: acceptance-filter bit walks.

For every filter mode of the SJA1000 (datasheet 6.3.9 / 6.4.15: BasicCAN
ACR/AMR; PeliCAN single filter, standard and extended frames; dual filter,
standard and extended frames) and every bit position a filter compares
(identifier, RTR, the data-byte bits of the standard-frame filters), a frame
that differs from the acceptance code in exactly that one bit is sent twice:
once under a mask that compares the bit (AMR bit 0: the frame must be
rejected) and once under a mask that ignores it (AMR bit 1: accepted). The
two configurations of a scenario have complementary masks, so every mask bit
is 0 in one and 1 in the other; "mask bit i wrong while mask bit j is v" is
reached for every j too. The dual filters are walked together: the two codes
of a configuration differ in all eight ID.28..21 / ID.10..3 bits and each
filter compares four of them, so a frame one bit away from one filter's code
is always rejected by the other.

Expected results come from the construction (one bit away, that bit's mask),
not from a filter model (crates/scenario/tests/suite/acf_walk.rs checks them with
the golden model's filter). The host drains the FIFO as the frames arrive
(receive interrupt, then the frame information, identifier and data of the
head message, release, IR = 00), so a frame wrongly accepted or wrongly
rejected shows at the next check; RMC (BasicCAN: SR.RBS) must be 0 after each
configuration's last (marker) frame.

Run from the repository root: python3 scripts/gen-acf-walks.py
Regenerate rather than hand-edit the scenarios.
"""

from pathlib import Path

OUT = Path(__file__).resolve().parent.parent / "tb" / "mutation-holes"
BTR0, BTR1 = 0x00, 0x27  # BRP 0, 12 tq of 2 clocks: 1 Mbit/s at 24 MHz
SLOT = {False: 80, True: 90}  # bit times per frame slot (std up to DLC 2 / ext DLC 0, worst-case stuffing)
GAP = 40  # bit times after the last slot of a configuration (whose own slack is about 30): drain, reset mode, 10 writes, bus integration (PIO needs about 25 in all)
FIRST = 100  # first frame: after the set-up (about 16 accesses) and the 11-bit bus integration
EXT_LOW13 = 0x0A5A  # ID.12..0 of the dual-filter extended frames (not filtered there)


def hx(v):
    return f"0x{v:02X}"


class Frame:
    def __init__(self, ext, ident, rtr=False, data=(), note=""):
        self.ext, self.id, self.rtr, self.data, self.note = ext, ident, rtr, list(data), note
        # RXB+3 (ID.4..0, RTR) not read: the walk changed no bit there and
        # RXFI already shows the RTR bit (on the opencores core a remote
        # extended frame's RXB+3 lacks its RTR bit, D7, waived at most 4 times)
        self.skip_id4 = False

    def dlc(self):
        return 0 if self.rtr else len(self.data)

    def toml(self, at):
        s = f"{{ id = 0x{self.id:X}"
        if self.ext:
            s += ", extended = true"
        if self.rtr:
            s += ", rtr = true, dlc = 0"
        elif self.data:
            s += ", data = [" + ", ".join(hx(d) for d in self.data) + "]"
        return s + f", at_bit = {at} }},"

    def text(self):
        s = ("ext" if self.ext else "std") + f" 0x{self.id:0{8 if self.ext else 3}X}"
        if self.rtr:
            s += " RTR"
        elif self.data:
            s += " [" + " ".join(f"{d:02X}" for d in self.data) + "]"
        else:
            s += " DLC 0"
        return s


def flip(f, what, bit, dlc_data=None):
    """The frame f with one bit changed: what = 'id' (bit = ID bit number),
    'rtr', or 'data' (bit = 8 * byte + bit); dlc_data = the data bytes the
    frame carries (the code's)."""
    g = Frame(f.ext, f.id, f.rtr, f.data if dlc_data is None else dlc_data)
    if what == "id":
        g.id ^= 1 << bit
    elif what == "rtr":
        g.rtr = not g.rtr
        g.data = []
    else:
        g.data[bit // 8] ^= 1 << (bit % 8)
    return g


def reads_peli(f):
    """Reads of the FIFO head in PeliCAN: frame information, identifier, data."""
    info = (0x80 if f.ext else 0) | (0x40 if f.rtr else 0) | f.dlc()
    r = [("RXFI", info, None)]
    if f.ext:
        r += [("RXB", f.id >> 21, None), ("RXB+1", (f.id >> 13) & 0xFF, None), ("RXB+2", (f.id >> 5) & 0xFF, None)]
        if not f.skip_id4:
            r.append(("RXB+3", ((f.id & 0x1F) << 3) | (4 if f.rtr else 0), 0xFC))
        base = 4
    else:
        r += [("RXB", f.id >> 3, None), ("RXB+1", ((f.id & 7) << 5) | (0x10 if f.rtr else 0), 0xF0)]
        base = 2
    for i, d in enumerate(f.data if not f.rtr else []):
        r.append((f"RXB+{base + i}", d, None))
    return r


def reads_basic(f):
    r = [("RXID1", f.id >> 3, None), ("RXID2", ((f.id & 7) << 5) | (0x10 if f.rtr else 0) | f.dlc(), None)]
    for i, d in enumerate(f.data if not f.rtr else []):
        r.append(("RXDATA" if i == 0 else f"RXDATA+{i}", d, None))
    return r


# ---- the walks: (label, acr register, acr bit, frame builder) per filter mode ----

def walk_basic(acr, amr):
    code = Frame(False, (acr[0] << 3) | 0b101)
    items = []
    for b in range(7, -1, -1):
        items.append((f"ID.{3 + b}", 0, b, flip(code, "id", 3 + b)))
    marker = Frame(False, (acr[0] << 3) | 0b010, rtr=True, note="ID.2..0 and RTR are not filtered")
    return items, [marker]


def walk_single_std(acr, amr):
    assert not acr[1] & 0x10, "the code's RTR must be 0 so that data frames match it"
    code = Frame(False, (acr[0] << 3) | (acr[1] >> 5))
    d = [acr[2], acr[3]]
    items = []
    for b in range(7, -1, -1):
        items.append((f"ID.{3 + b}", 0, b, flip(code, "id", 3 + b)))
    for b in range(7, 4, -1):
        items.append((f"ID.{b - 5}", 1, b, flip(code, "id", b - 5)))
    items.append(("RTR", 1, 4, flip(code, "rtr", 0)))
    for b in range(7, -1, -1):
        items.append((f"data 1 bit {b}", 2, b, flip(code, "data", b, d[:1])))
    for b in range(7, -1, -1):
        items.append((f"data 2 bit {b}", 3, b, flip(code, "data", 8 + b, d)))
    return items, [Frame(False, code.id, data=d)]


def walk_single_ext(acr, amr):
    ident = (acr[0] << 21) | (acr[1] << 13) | (acr[2] << 5) | (acr[3] >> 3)
    code = Frame(True, ident, rtr=bool(acr[3] & 4))
    items = []
    for r, top in ((0, 28), (1, 20), (2, 12)):
        for b in range(7, -1, -1):
            items.append((f"ID.{top - 7 + b}", r, b, flip(code, "id", top - 7 + b)))
    for b in range(7, 2, -1):
        items.append((f"ID.{b - 3}", 3, b, flip(code, "id", b - 3)))
    items.append(("RTR", 3, 2, flip(code, "rtr", 0)))
    for (lab, r, _, f) in items:
        f.skip_id4 = f.rtr and (r < 3 or lab == "RTR")  # remote, ID.4..0 as the code's
    return items, [code]


def walk_dual_std(acr, amr):
    assert acr[2] == acr[0] ^ 0xFF, "the two filters' ID.10..3 codes differ in every bit"
    assert not acr[1] & 0x10, "filter 1's RTR code must be 0 so that data frames match it"
    c1 = Frame(False, (acr[0] << 3) | (acr[1] >> 5))
    d1 = [((acr[1] & 0xF) << 4) | (acr[3] & 0xF)]
    c2 = Frame(False, (acr[2] << 3) | (acr[3] >> 5), rtr=bool(acr[3] & 0x10))
    items = []
    for b in range(7, -1, -1):
        items.append((f"filter 1 ID.{3 + b}", 0, b, flip(c1, "id", 3 + b)))
    for b in range(7, 4, -1):
        items.append((f"filter 1 ID.{b - 5}", 1, b, flip(c1, "id", b - 5)))
    items.append(("filter 1 RTR", 1, 4, flip(c1, "rtr", 0)))
    for b in range(3, -1, -1):
        items.append((f"filter 1 data 1 bit {4 + b}", 1, b, flip(c1, "data", 4 + b, d1)))
    for b in range(3, -1, -1):
        items.append((f"filter 1 data 1 bit {b}", 3, b, flip(c1, "data", b, d1)))
    for b in range(7, -1, -1):
        items.append((f"filter 2 ID.{3 + b}", 2, b, flip(c2, "id", 3 + b)))
    for b in range(7, 4, -1):
        items.append((f"filter 2 ID.{b - 5}", 3, b, flip(c2, "id", b - 5)))
    items.append(("filter 2 RTR", 3, 4, flip(c2, "rtr", 0)))
    m2 = Frame(False, c2.id, c2.rtr, [] if c2.rtr else [d1[0] ^ 0xFF], note="filter 2 does not compare data")
    return items, [Frame(False, c1.id, data=d1), m2]


def walk_dual_ext(acr, amr):
    assert acr[2] == acr[0] ^ 0xFF, "the two filters' ID.28..21 codes differ in every bit"
    c1 = Frame(True, (acr[0] << 21) | (acr[1] << 13) | EXT_LOW13)
    c2 = Frame(True, (acr[2] << 21) | (acr[3] << 13) | EXT_LOW13)
    items = []
    for f, (r0, r1), c in ((1, (0, 1), c1), (2, (2, 3), c2)):
        for r, top in ((r0, 28), (r1, 20)):
            for b in range(7, -1, -1):
                items.append((f"filter {f} ID.{top - 7 + b}", r, b, flip(c, "id", top - 7 + b)))
    return items, [c1, Frame(True, c2.id, rtr=True, note="ID.12..0 and RTR are not filtered")]


MODES = {
    "basic": dict(
        short="BasicCAN",
        walk=walk_basic, peli=False, afm=None, ext=False,
        title="BasicCAN: ACR/AMR against ID.10..3",
        configs=[([0xB4], [0x5A]), ([0x4B], [0xA5])],
        unused="ID.2..0 and RTR are not filtered (the markers vary them)",
    ),
    "single-std": dict(
        short="single filter, standard frames",
        walk=walk_single_std, peli=True, afm=1, ext=False,
        title="PeliCAN single filter, standard frames: ID.10..0, RTR, data bytes 1 and 2",
        configs=[([0xB4, 0x6A, 0x3A, 0xC5], [0x5A, 0xA5, 0x96, 0x3C]),
                 ([0x4B, 0x85, 0xC5, 0x3A], [0xA5, 0x5A, 0x69, 0xC3])],
        unused="ACR1.3..0 / AMR1.3..0 are not used",
    ),
    "single-ext": dict(
        short="single filter, extended frames",
        walk=walk_single_ext, peli=True, afm=1, ext=True,
        title="PeliCAN single filter, extended frames: ID.28..0 and RTR",
        configs=[([0xB4, 0x6A, 0x3A, 0xC1], [0x5A, 0xA5, 0x96, 0x3C]),
                 ([0x4B, 0x95, 0xC5, 0x3E], [0xA5, 0x5A, 0x69, 0xC3])],
        unused="ACR3.1..0 / AMR3.1..0 are not used; the code's RTR is 0 in A (data frames), 1 in B (remote frames)",
    ),
    "dual-std": dict(
        short="dual filter, standard frames",
        walk=walk_dual_std, peli=True, afm=0, ext=False,
        title="PeliCAN dual filter, standard frames: filter 1 ID.10..0, RTR, data byte 1; filter 2 ID.10..0, RTR",
        configs=[([0xB4, 0x6A, 0x4B, 0xC5], [0x5A, 0xA5, 0x96, 0x3C]),
                 ([0x4B, 0x85, 0xB4, 0x3A], [0xA5, 0x5A, 0x69, 0xC3])],
        unused="every ACR/AMR bit is used",
    ),
    "dual-ext": dict(
        short="dual filter, extended frames",
        walk=walk_dual_ext, peli=True, afm=0, ext=True,
        title="PeliCAN dual filter, extended frames: filter 1 and filter 2 ID.28..13",
        configs=[([0xB4, 0x6A, 0x4B, 0xC5], [0x5A, 0xA5, 0x96, 0x3C]),
                 ([0x4B, 0x95, 0xB4, 0x3A], [0xA5, 0x5A, 0x69, 0xC3])],
        unused="every ACR/AMR bit is used; ID.12..0 and RTR are not filtered",
    ),
}


def step(s):
    return "    " + s


def generate(name, m):
    peli, ext = m["peli"], m["ext"]
    slot = SLOT[ext]
    reads = reads_peli if peli else reads_basic
    steps, sends, seq = [], [], []
    nrej = nacc = 0
    t = FIRST
    # the set-up
    if peli:
        steps += [step('{ write = "CR", value = 0x01, note = "reset mode (the BasicCAN view is in force after reset)" },'),
                  step('{ write = "CDR", value = 0x80, note = "CDR.7: PeliCAN" },'),
                  step('{ write = "IER", value = 0x01, note = "RIE: the pin tells the host a message is stored" },')]
    else:
        steps += [step('{ write = "CR", value = 0x03, note = "reset mode, RIE" },'),
                  step('{ write = "CDR", value = 0x00, note = "BasicCAN (CDR.7 = 0)" },')]
    prev = 0
    for ci, (acr, amr) in enumerate(m["configs"]):
        label = "AB"[ci]
        if ci > 0:
            steps.append(step(f'{{ write = "{"MOD" if peli else "CR"}", value = {hx(0x01 | (m["afm"] << 3) if peli else 0x03)}, '
                              f'note = "reset mode: configuration {label}" }},'))
        if peli:
            for r in range(4):
                steps.append(step(f'{{ write = "ACR{r}", value = {hx(acr[r])} }},'))
            for r in range(4):
                steps.append(step(f'{{ write = "AMR{r}", value = {hx(amr[r])}'
                                  + (', note = "AMR: 1 = don\'t care; the next configuration has the complement" }' if r == 0 else " }") + ","))
        else:
            steps.append(step(f'{{ write = "ACR", value = {hx(acr[0])}, note = "ID.10..3 code" }},'))
            steps.append(step(f'{{ write = "AMR", value = {hx(amr[0])}, note = "1 = don\'t care; the next configuration has the complement" }},'))
        if ci == 0:
            steps += [step(f'{{ write = "BTR0", value = {hx(BTR0)}, note = "BRP = 0, SJW = 1" }},'),
                      step(f'{{ write = "BTR1", value = {hx(BTR1)}, note = "TSEG1 = 8, TSEG2 = 3: 12 tq, 1 Mbit/s at 24 MHz" }},'),
                      step('{ write = "OCR", value = 0xDA },')]
        if peli:
            mod = m["afm"] << 3
            steps.append(step(f'{{ write = "MOD", value = {hx(mod)}, note = "operating mode, AFM = {m["afm"]} ({"single" if m["afm"] else "dual"} filter)" }},'))
        else:
            steps.append(step('{ write = "CR", value = 0x02, note = "operating mode, RIE" },'))
        items, markers = m["walk"](acr, amr)
        frames = []
        for (lab, r, b, f) in items:
            masked = bool(amr[r] >> b & 1)
            f.note = f"{lab} flipped, {'AMR' if not peli else 'AMR' + str(r)}.{b} = {int(masked)}: " + ("accepted" if masked else "rejected")
            frames.append((f, masked))
            if masked:
                nacc += 1
            else:
                nrej += 1
        frames += [(mk, True) for mk in markers]
        seq.append(f"Configuration {label}: ACR = {' '.join(f'{a:02X}' for a in acr)}, AMR = {' '.join(f'{a:02X}' for a in amr)}; "
                   f"{len(items)} frames one bit away from the code ({sum(1 for _, ok in frames[:len(items)] if ok)} accepted), then {len(markers)} marker frame(s)")
        for i, (f, ok) in enumerate(frames):
            at = t + i * slot
            sends.append("    " + f.toml(at) + f"  # {label}: {f.note or 'marker'}")
            if ok:
                steps.append(step(f'{{ wait_irq = true, timeout_bits = {at + 2 * slot - prev + GAP}, note = "{label}: {f.text()}: {f.note or "marker: the code itself"}" }},'))
                for (reg, v, mask) in reads(f):
                    steps.append(step(f'{{ read = "{reg}", expect = {hx(v)}' + (f", mask = {hx(mask)}" if mask else "") + " },"))
                steps.append(step('{ write = "CMR", value = 0x04, note = "release receive buffer" },'))
                steps.append(step('{ read = "IR", expect = 0x00' + ('' if peli else ', mask = 0x1F') + ', note = "no RI: the FIFO is empty again" },'))
                prev = at
        if peli:
            steps.append(step(f'{{ read = "RMC", expect = 0x00, note = "{label}: every rejected frame stayed out of the FIFO" }},'))
        else:
            steps.append(step(f'{{ read = "SR", expect = 0x00, mask = 0x03, note = "{label}: RBS = 0, DOS = 0: every rejected frame stayed out" }},'))
        t += len(frames) * slot + GAP
    steps.append(step('{ read = "SR", expect = 0x00, mask = 0x03, note = "RBS = 0, DOS = 0" },'))
    if peli:
        steps.append(step('{ read = "RXERR", expect = 0x00 },'))
    total = len(sends)
    verifies = [
        f"Each bit position the filter compares ({m['title'].split(': ', 1)[1]}), in a frame otherwise equal to the code: rejected when its AMR bit is 0 ({nrej} frames)",
        f"The same bit position with its AMR bit 1: accepted, stored in order with its identifier, frame information and data ({nacc} frames)",
        "Two configurations with complementary masks: every mask bit compared once and ignored once, each with the other mask bits mixed",
        "The code itself is accepted at the end of each configuration; " + m["unused"],
        "RMC (BasicCAN: RBS) is 0 after each configuration's last frame: no rejected frame entered the FIFO",
    ]
    head = f"""# Acceptance-filter bit walk (mutants 47, 116, 178 of rtl/'s seed-1 sample,
# seed 1, all in can_acf.v's match function), written from the SJA1000
# datasheet (6.3.9 and 6.4.15: ACR bits must equal the received bits where
# the AMR bit is 0, AMR = 1 is "don't care"), here: {m['title'].split(':')[0]}.
# Generated by scripts/gen-acf-walks.py (regenerate, do not hand-edit): each
# frame differs from the code in exactly one filtered bit; its expected fate
# follows from that bit's mask bit alone. The host drains the FIFO as frames
# arrive: it waits for the receive interrupt, reads the whole message,
# releases it and reads IR = 00, so a wrongly accepted frame shows as an RI
# or the wrong message, a wrongly rejected one as a missing message.
# 1 Mbit/s, frames in fixed slots. On the opencores core the host waits on
# the pin rather than polling SR (each poll in a frame is a D1/D2 waiver hit).
name = "acceptance filter bit walk: {m['short']}"
purpose = "Bit walk of the acceptance filter ({m['title']}): one frame per filtered bit, rejected when its mask bit is 0, accepted when it is 1"
verifies = [
""" + "".join(f'    "{v}",\n' for v in verifies) + "]\nsequence = [\n" + "".join(f'    "{s}",\n' for s in seq) + \
        '    "After each frame that must be accepted: wait for the receive interrupt, read the whole message, release it, IR must read 00; RMC (BasicCAN: SR) at the end of each configuration",\n]\n'
    body = "step = [\n" + "\n".join(steps) + "\n]\n"
    end = t
    tail = f"""
[clocks]
host_mhz = 50.0
can_mhz = 24.0
bit_rate = 1000000

[host]
bfm = "wishbone"

[dut]
kind = "rtl"

[run]
max_bits = {end + 200}

[[node]]
name = "sender"
btr0 = {hx(BTR0)}
btr1 = {hx(BTR1)}
mode = "peli"
send = [
""" + "\n".join(sends) + f"""
]

[expect]
# No monitor node: a model node's FIFO would overrun on this many frames. The
# sender sends its frames in order, so the last marker read proves the whole
# sequence went over the bus (acknowledged by the DUT).
category = "Pass"
"""
    (OUT / f"acf-walk-{name}.toml").write_text(head + body + tail)
    return total, end


if __name__ == "__main__":
    for n, m in MODES.items():
        total, end = generate(n, m)
        print(f"acf-walk-{n}.toml: {total} frames, {end} bit times")
