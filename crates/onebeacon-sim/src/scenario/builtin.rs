//! Built-in scenarios: the TOML files of `scenarios/`, embedded in the binary.

/// A built-in scenario file.
#[derive(Debug, Clone, Copy)]
pub struct Builtin {
    pub name: &'static str,
    pub toml: &'static str,
}

/// All built-in scenarios.
pub const BUILTINS: &[Builtin] = &[
    Builtin { name: "garin2024", toml: include_str!("../../../../scenarios/garin2024.toml") },
    Builtin { name: "garin2024-sea", toml: include_str!("../../../../scenarios/garin2024-sea.toml") },
    Builtin { name: "sousa", toml: include_str!("../../../../scenarios/sousa.toml") },
    Builtin { name: "sousa-sea", toml: include_str!("../../../../scenarios/sousa-sea.toml") },
    Builtin { name: "sousa-pair", toml: include_str!("../../../../scenarios/sousa-pair.toml") },
    Builtin { name: "hoff2024", toml: include_str!("../../../../scenarios/hoff2024.toml") },
    Builtin { name: "hoff2024-kinematic", toml: include_str!("../../../../scenarios/hoff2024-kinematic.toml") },
    Builtin { name: "hoff2024-current", toml: include_str!("../../../../scenarios/hoff2024-current.toml") },
    Builtin { name: "hoff2024-pair", toml: include_str!("../../../../scenarios/hoff2024-pair.toml") },
    Builtin { name: "hoff2024-consistency", toml: include_str!("../../../../scenarios/hoff2024-consistency.toml") },
    Builtin { name: "hoff2024-literal", toml: include_str!("../../../../scenarios/hoff2024-literal.toml") },
    Builtin { name: "hoff2024-sea", toml: include_str!("../../../../scenarios/hoff2024-sea.toml") },
    Builtin { name: "rypkema-m1", toml: include_str!("../../../../scenarios/rypkema-m1.toml") },
    Builtin { name: "rypkema-m6", toml: include_str!("../../../../scenarios/rypkema-m6.toml") },
    Builtin { name: "rypkema-m1-sea", toml: include_str!("../../../../scenarios/rypkema-m1-sea.toml") },
    Builtin { name: "rypkema-m6-sea", toml: include_str!("../../../../scenarios/rypkema-m6-sea.toml") },
];

/// The built-in scenario called `name`.
pub fn builtin(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_parses_and_is_named_after_its_file() {
        for b in BUILTINS {
            let s = crate::scenario::parse(b.toml, b.name).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(s.name(), b.name);
            assert!(!s.description().is_empty() && !s.description().contains('\n'));
        }
    }
}
