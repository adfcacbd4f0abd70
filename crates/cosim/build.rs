//! Verilates the bundled tops (our RTL `can_top` and `can_avalon`, and the
//! test fixtures in `tb/fixtures/`; Verilator `-O3` as the bench's raw C++
//! harness, plus `--trace` for `dut_trace`), generates the `extern "C"` shim of
//! each from its `V<top>.h`, and compiles model + shim as one translation
//! unit per top with `-O3 -fno-semantic-interposition`, plus Verilator's
//! runtime. Source lists come from the generated `V<top>_classes.mk`.

#[path = "../vbridge/src/shimgen.rs"]
#[allow(dead_code)]
mod shimgen;
#[path = "src/batch_shim.rs"]
mod batch_shim;

use std::env;
use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

struct Top {
    name: String,
    sources: Vec<PathBuf>,
    include_dirs: Vec<PathBuf>,
    /// Part of our RTL (may be skipped with COSIM_ALLOW_MISSING_RTL=1).
    rtl: bool,
}

fn fail(msg: &str) -> ! {
    eprintln!("\nerror: {msg}\n");
    std::process::exit(1);
}

fn verilog_files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| matches!(p.extension().and_then(|e| e.to_str()), Some("v" | "sv")))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

fn main() {
    let manifest = PathBuf::from(env::var("CARGO_MANIFEST_DIR").unwrap());
    let root = manifest.join("../..");
    let rtl_dir = root.join("rtl");
    let fixtures_dir = root.join("tb/fixtures");
    let out = PathBuf::from(env::var("OUT_DIR").unwrap());
    println!("cargo:rerun-if-changed={}", rtl_dir.display());
    println!("cargo:rerun-if-changed={}", fixtures_dir.display());
    println!("cargo:rerun-if-changed=../vbridge/src/shimgen.rs");
    println!("cargo:rerun-if-changed=src/batch_shim.rs");
    println!("cargo:rerun-if-env-changed=COSIM_ALLOW_MISSING_RTL");
    let allow_missing = env::var("COSIM_ALLOW_MISSING_RTL")
        .map(|v| v == "1")
        .unwrap_or(false);

    let root_out = match Command::new("verilator")
        .arg("--getenv")
        .arg("VERILATOR_ROOT")
        .output()
    {
        Ok(o) if o.status.success() => PathBuf::from(String::from_utf8_lossy(&o.stdout).trim()),
        _ => fail(
            "`verilator` was not found: install Verilator (apt-get install verilator) or run scripts/setup.sh",
        ),
    };
    let vinc = root_out.join("include");

    let mut tops = Vec::new();
    for f in verilog_files(&fixtures_dir) {
        println!("cargo:rerun-if-changed={}", f.display());
        let name = f.file_stem().unwrap().to_string_lossy().into_owned();
        tops.push(Top {
            name,
            sources: vec![f],
            include_dirs: vec![fixtures_dir.clone()],
            rtl: false,
        });
    }
    let rtl_files = verilog_files(&rtl_dir);
    for f in &rtl_files {
        println!("cargo:rerun-if-changed={}", f.display());
    }
    for name in ["can_top", "can_avalon", "can_top_pio", "can_top_8051", "can_top_mcu", "can_regport", "can_axi4lite", "can_apb"] {
        tops.push(Top {
            name: name.to_string(),
            sources: rtl_files.clone(),
            include_dirs: vec![rtl_dir.clone()],
            rtl: true,
        });
    }

    let mut built: Vec<(String, PathBuf, shimgen::ClassLists, Vec<shimgen::PortDecl>)> = Vec::new();
    for top in &tops {
        let mdir = out.join(format!("V{}", top.name));
        let _ = fs::remove_dir_all(&mdir);
        let result = if top.sources.is_empty() {
            Err(format!(
                "no Verilog sources (*.v, *.sv) in {}",
                rtl_dir.display()
            ))
        } else {
            let mut cmd = Command::new("verilator");
            cmd.args([
                "--cc",
                "-O3",
                "--trace",
                "--no-timing",
                "-Wno-fatal",
                "-Wno-lint",
                "-Wno-style",
                "--top-module",
            ])
            .arg(&top.name)
            .arg("--prefix")
            .arg(format!("V{}", top.name))
            .arg("-Mdir")
            .arg(&mdir);
            for d in &top.include_dirs {
                cmd.arg(format!("-I{}", d.display()));
            }
            cmd.args(&top.sources);
            match cmd.output() {
                Ok(o) if o.status.success() => Ok(()),
                Ok(o) => Err(format!(
                    "{}{}",
                    String::from_utf8_lossy(&o.stdout),
                    String::from_utf8_lossy(&o.stderr)
                )),
                Err(e) => Err(format!("could not run verilator: {e}")),
            }
        };
        if let Err(msg) = result {
            let msg = msg.trim().to_string();
            if top.rtl && allow_missing {
                let first = msg.lines().next().unwrap_or("");
                println!(
                    "cargo:warning=cosim: skipping bundled RTL top `{}` (COSIM_ALLOW_MISSING_RTL=1): {first}",
                    top.name
                );
                continue;
            }
            let hint = if top.rtl {
                " Fix rtl/ (or, while rtl/ is being written, set COSIM_ALLOW_MISSING_RTL=1 to build without the RTL tops)."
            } else {
                ""
            };
            fail(&format!(
                "cosim could not verilate the bundled top `{}` from {:?}; Verilator said:\n{msg}\n{hint}",
                top.name, top.sources
            ));
        }
        let prefix = format!("V{}", top.name);
        let mk =
            fs::read_to_string(mdir.join(format!("{prefix}_classes.mk"))).unwrap_or_else(|e| {
                fail(&format!(
                    "cosim: Verilator produced no {prefix}_classes.mk: {e}"
                ))
            });
        let classes = shimgen::parse_classes_mk(&mk);
        let header = fs::read_to_string(mdir.join(format!("{prefix}.h")))
            .unwrap_or_else(|e| fail(&format!("cosim: Verilator produced no {prefix}.h: {e}")));
        let ports = shimgen::parse_ports(&header);
        built.push((top.name.clone(), mdir, classes, ports));
    }

    // One translation unit per top: model classes + shim.
    let mut build = cc::Build::new();
    build
        .cpp(true)
        .opt_level(3)
        .debug(false)
        .warnings(false)
        .flag("-fno-semantic-interposition")
        .flag_if_supported("-faligned-new")
        .flag_if_supported("-fcf-protection=none")
        .flag("-w")
        .include(&vinc)
        .include(vinc.join("vltstd"));
    let mut globals: Vec<String> = Vec::new();
    let mut switches: Vec<(String, String)> = Vec::new();
    for (name, mdir, classes, ports) in &built {
        let mut unity = String::new();
        for c in &classes.model {
            let _ = writeln!(
                unity,
                "#include \"{}\"",
                mdir.join(format!("{c}.cpp")).display()
            );
        }
        unity.push_str(&shimgen::gen_shim(name, ports, true, Some(batch_shim::batch_loop_cpp())));
        let path = out.join(format!("cosim_unity_{name}.cpp"));
        fs::write(&path, unity).unwrap();
        build.file(&path).include(mdir);
        for g in &classes.global {
            if !globals.contains(g) {
                globals.push(g.clone());
            }
        }
        for s in &classes.switches {
            if s.0.starts_with("VM_") && !switches.iter().any(|x| x.0 == s.0) {
                switches.push(s.clone());
            }
        }
    }
    for (k, v) in &switches {
        build.define(k, Some(v.as_str()));
    }
    build.define("VM_SC", Some("0"));
    for g in &globals {
        build.file(vinc.join(format!("{g}.cpp")));
    }
    build.compile("cosim_bundled");
    println!("cargo:rustc-link-lib=pthread");
    println!("cargo:rustc-link-lib=atomic");

    // The Rust side: one vtable per bundled top.
    let names: Vec<&str> = built.iter().map(|(n, ..)| n.as_str()).collect();
    let rs = shimgen::gen_rust_table("BUNDLED", &names);
    fs::write(out.join("bundled.rs"), rs).unwrap();
}
