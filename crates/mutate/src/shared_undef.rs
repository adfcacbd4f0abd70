//! Undefined values shared by the two copies of the per-module formal check
//! ([`crate::reset_proof`]). A module that leaves a value undefined (`x`:
//! a register read mux's unused address, a write mux's "no write" data)
//! differs from itself when each copy picks that value freely, so the
//! check's control run fails and no mutant of it gets a verdict. Here every
//! `x` of the module becomes one input port (`cosim_undef_N`), made before
//! the module is copied, so the wrapper drives the original and the mutant
//! with the same free value, every clock.
//!
//! What a verdict then means: for every resolution of the module's
//! undefined values (any value, any clock), the same in both copies, the
//! mutant's outputs equal the original's. A mutant that pins an `x` (its
//! mutated bit was one) differs whenever that `x` reaches an output: it is
//! refuted, never proved. Undefined values made later (by `memory` from a
//! memory's out-of-range read, or inside a submodule) stay independent per
//! copy; the control run (the unmutated module against itself, with the same
//! sharing) still decides whether a verdict means anything.

/// Prefix of the input ports that carry the module's undefined values.
pub const PREFIX: &str = "cosim_undef_";

/// Yosys commands, run on `module` after `prep` and before it is copied:
/// each `x` constant of the module (not of its submodules) becomes a
/// `$anyseq` driver (`setundef -anyseq`), whose wire is named
/// `cosim_undef_N` and turned into an input port (`expose -input`; it only
/// takes public names, hence the rename), the drivers removed.
pub fn expose_commands(module: &str) -> String {
    format!(
        "setundef -anyseq {module}\n\
         select -set cosim_undef {module}/t:$anyseq %co:+[Y] {module}/w:* %i\n\
         rename -enumerate -pattern {PREFIX}% @cosim_undef\n\
         expose -input {module}/w:{PREFIX}*\n\
         delete {module}/t:$anyseq\n"
    )
}

/// Whether a port of the module carries one of its undefined values.
pub fn is_undef_port(name: &str) -> bool {
    name.strip_prefix(PREFIX).is_some_and(|n| !n.is_empty() && n.chars().all(|c| c.is_ascii_digit()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_exposed_names_are_undefined_value_ports() {
        assert!(is_undef_port("cosim_undef_0"));
        assert!(is_undef_port("cosim_undef_82"));
        assert!(!is_undef_port("cosim_undef_"));
        assert!(!is_undef_port("cosim_undef_x1"));
        assert!(!is_undef_port("acc_adr"));
    }

    #[test]
    fn the_commands_touch_only_the_module_checked() {
        let s = expose_commands("can_regs");
        for l in s.lines().filter(|l| !l.starts_with("rename")) {
            // (rename acts on the named selection, itself inside can_regs)
            assert!(l.contains("can_regs/") || l.ends_with(" can_regs"), "a command without the module's selection would reach its submodules too: {l}");
        }
        assert!(s.contains("@cosim_undef"), "{s}");
    }
}
