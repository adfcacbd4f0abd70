//! The generated 8051 header (`can_sja_8051.h`) compiled with SDCC for the
//! MCS-51 (Debian's `sdcc`, installed by scripts/setup.sh): every register
//! access becomes a MOVX at base + index; and with gcc on the host, where
//! the same macros index a plain array, run to check every register's
//! offset and every window's indexing against the register map.

use regmap::generate::{self, GenOptions};
use regmap::{registers, Mode};
use std::path::{Path, PathBuf};
use std::process::Command;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("regmap-8051-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run(cmd: &mut Command) -> String {
    let out = cmd.output().unwrap_or_else(|e| {
        panic!("cannot run {cmd:?}: {e} (install it: scripts/setup.sh installs Debian's sdcc and gcc)")
    });
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{cmd:?} failed ({}):\n{text}", out.status);
    text
}

fn generate_into(dir: &Path) {
    generate::write_all(dir, &GenOptions::default()).unwrap();
}

#[test]
fn sdcc_compiles_the_header_to_movx_at_base_plus_index() {
    let dir = tmp("sdcc");
    generate_into(&dir);
    std::fs::write(
        dir.join("probe.c"),
        r#"#define CAN_SJA_BASE 0x7F00
#include "can_sja_8051.h"

unsigned char probe(void)
{
    unsigned char i, sum = 0;
    WR_CAN_SJA_PELI_MOD(CAN_SJA_PELI_MOD_RM_MSK);
    WR_CAN_SJA_PELI_BTR0(0x41);
    for (i = 0; i < CAN_SJA_PELI_TXB_LEN; i++)
        WR_CAN_SJA_PELI_TXB(i, i);
    for (i = 0; i < CAN_SJA_PELI_RXB_LEN; i++)
        sum += RD_CAN_SJA_PELI_RXB(i);
    WR_CAN_SJA_BASIC_CMR(0x04);
    return (RD_CAN_SJA_PELI_SR() & CAN_SJA_PELI_SR_TBS_MSK) ? sum : 0;
}

void main(void)
{
    (void)probe();
}
"#,
    )
    .unwrap();
    let out = run(Command::new("sdcc")
        .current_dir(&dir)
        .args(["-mmcs51", "--std-c99", "-S", "probe.c", "-o", "probe.asm"]));
    assert!(!out.contains("warning"), "SDCC warned:\n{out}");
    let asm = std::fs::read_to_string(dir.join("probe.asm")).unwrap().to_lowercase();
    let movx = asm.matches("movx").count();
    assert!(movx >= 6, "expected MOVX accesses, found {movx}:\n{asm}");
    // MOD (0), BTR0 (6), SR (2) at their XDATA addresses; the windows from 17.
    for addr in ["#0x7f00", "#0x7f06", "#0x7f02", "#0x7f01"] {
        assert!(asm.contains(addr), "no access to {addr}:\n{asm}");
    }
    assert!(asm.contains("#0x11") || asm.contains("#0x7f11"), "TX/RX window base 17 not used:\n{asm}");
    // Without a base the header says what to define.
    std::fs::write(dir.join("nobase.c"), "#include \"can_sja_8051.h\"\nvoid main(void) {}\n").unwrap();
    let o = Command::new("sdcc").current_dir(&dir).args(["-mmcs51", "-c", "nobase.c"]).output().unwrap();
    assert!(!o.status.success());
    let msg = String::from_utf8_lossy(&o.stderr);
    assert!(msg.contains("define CAN_SJA_BASE"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// On the host (gcc, no __xdata) the macros index a byte array: each
/// register's RD_/WR_ macro and each window element lands at the map's
/// address.
#[test]
fn every_register_macro_hits_its_address() {
    let dir = tmp("host");
    generate_into(&dir);
    let header = std::fs::read_to_string(dir.join("can_sja_8051.h")).unwrap();
    let (mut n_wr, mut n_rd) = (0, 0);
    let mut body = String::new();
    for mode in [Mode::PeliCan, Mode::BasicCan] {
        for r in registers(mode) {
            let root = format!("CAN_SJA_{}_{}", mode.tag(), r.name);
            let writable = header.contains(&format!("#define WR_{root}("));
            let readable = header.contains(&format!("#define RD_{root}("));
            assert!(writable || readable, "{root}: neither RD_ nor WR_ in the header");
            for i in 0..r.len {
                let (wr, rd) = if r.len > 1 {
                    (format!("WR_{root}({i}, 0xA5)"), format!("RD_{root}({i})"))
                } else {
                    (format!("WR_{root}(0xA5)"), format!("RD_{root}()"))
                };
                let a = r.addr as u16 + i as u16;
                if writable {
                    n_wr += 1;
                    body.push_str(&format!(
                        "    memset(regs, 0, sizeof regs); {wr}; check(\"{wr}\", {a});\n"
                    ));
                }
                if readable {
                    n_rd += 1;
                    body.push_str(&format!(
                        "    memset(regs, 0, sizeof regs); regs[{a}] = 0x5A; if ({rd} != 0x5A) {{ printf(\"{rd} missed %d\\n\", {a}); fails++; }}\n"
                    ));
                }
            }
        }
    }
    // Both views, windows included: dozens of each.
    assert!(n_wr > 40 && n_rd > 40, "{n_wr} writes, {n_rd} reads");
    let prog = format!(
        r#"#include <stdio.h>
#include <string.h>
static unsigned char regs[256];
#define CAN_SJA_BASE (regs)
#include "can_sja_8051.h"
static int fails;
static void check(const char *what, int addr)
{{
    int k;
    for (k = 0; k < 256; k++)
        if ((k == addr) != (regs[k] == 0xA5)) {{ printf("%s: byte %d\n", what, k); fails++; return; }}
}}
int main(void)
{{
{body}    printf("fails %d\n", fails);
    return fails != 0;
}}
"#
    );
    std::fs::write(dir.join("host.c"), prog).unwrap();
    run(Command::new("gcc")
        .current_dir(&dir)
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-I."])
        .args(["host.c", "-o", "host"]));
    let out = run(&mut Command::new(dir.join("host")));
    assert!(out.contains("fails 0"), "{out}");
    let _ = std::fs::remove_dir_all(&dir);
}
