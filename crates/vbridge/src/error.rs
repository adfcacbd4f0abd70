//! What can go wrong in the bridge: building, loading or binding a model
//! ([`BridgeError`]), and the GHDL step of a core with VHDL sources
//! ([`VhdlError`], one of its causes).

/// What can go wrong building, loading or binding a model. Each variant
/// prints as one paragraph, including Verilator's or the compiler's own words.
#[derive(Debug, thiserror::Error)]
pub enum BridgeError {
    /// The top is not in the table of linked-in tops.
    #[error("no bundled top `{name}`; this build has: {available}")]
    UnknownTop {
        /// Requested top.
        name: String,
        /// Tops that exist.
        available: String,
    },
    /// The core's directory cannot hold the core ([`crate::ExternalCore::check`]).
    #[error("external core {dir}: {problem}")]
    BadSources {
        /// Source directory.
        dir: String,
        /// What is wrong, in one line.
        problem: String,
    },
    /// Verilator rejected the sources.
    #[error("Verilator could not build top `{top}` from {dir}; Verilator said:\n{message}")]
    Verilate {
        /// Top module.
        top: String,
        /// Source directory.
        dir: String,
        /// Verilator's output.
        message: String,
    },
    /// The C++ compiler or linker failed on the Verilated model.
    #[error("compiling the Verilated model of `{top}` failed ({step}):\n{message}")]
    Compile {
        /// Top module.
        top: String,
        /// Which step.
        step: String,
        /// Compiler output.
        message: String,
    },
    /// A port the caller needs is absent.
    #[error(
        "top `{top}` has no port `{port}` (it has: {available}){}",
        wanted_by(.kind)
    )]
    MissingPort {
        /// Top module.
        top: String,
        /// Missing port.
        port: String,
        /// Ports it has.
        available: String,
        /// Which port list was expected (the caller's words).
        kind: String,
    },
    /// A port has an unexpected width or direction.
    #[error("port `{port}` of top `{top}` is {got}; expected {want}")]
    PortShape {
        /// Top module.
        top: String,
        /// Port.
        port: String,
        /// What it is.
        got: String,
        /// What it should be.
        want: String,
    },
    /// The shared library could not be loaded.
    #[error("could not load {path}: {message}")]
    Load {
        /// Library path.
        path: String,
        /// Loader message.
        message: String,
    },
    /// Tracing could not start.
    #[error("could not open VCD trace {path}: {reason}")]
    Trace {
        /// VCD path.
        path: String,
        /// Why.
        reason: String,
    },
    /// The GHDL step of a core with VHDL sources failed ([`crate::vhdl`]).
    #[error(transparent)]
    Vhdl(#[from] VhdlError),
    /// File-system trouble.
    #[error("{context}: {source}")]
    Io {
        /// What was being done.
        context: String,
        /// The error.
        source: std::io::Error,
    },
}

fn wanted_by(kind: &str) -> String {
    if kind.is_empty() {
        String::new()
    } else {
        format!("; the {kind} port list needs it")
    }
}

/// What went wrong in the GHDL step, in one paragraph.
#[derive(Debug, thiserror::Error)]
pub enum VhdlError {
    /// GHDL is not installed.
    #[error(
        "external core {dir} has VHDL sources, and `ghdl` was not found: install GHDL (scripts/setup.sh, or apt-get install ghdl)"
    )]
    NoGhdl {
        /// Core directory.
        dir: String,
    },
    /// GHDL rejected the sources: its first message (`file:line:col: ...`).
    #[error("GHDL could not {step} ({standard}): {first}{more}")]
    Ghdl {
        /// "analyse x.vhd", "order the VHDL of top", "synthesise top".
        step: String,
        /// The standard used.
        standard: &'static str,
        /// GHDL's first error line, with file and line.
        first: String,
        /// "(and n more lines from GHDL)" or empty.
        more: String,
    },
    /// No VHDL entity to synthesise.
    #[error(
        "external core {dir}: `{top}` is a Verilog module and none of its Verilog files instantiates a VHDL entity ({entities}); give the VHDL top with --top"
    )]
    NoRoot {
        /// Core directory.
        dir: String,
        /// Top.
        top: String,
        /// Entities seen.
        entities: String,
    },
}
