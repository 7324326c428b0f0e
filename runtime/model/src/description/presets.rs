//! The description files shipped with trocar: the thesis's three wrist presets and the reference arm.

/// `(name, TOML text)` of every shipped description.
pub const PRESETS: &[(&str, &str)] = &[
    (
        "unidirectional",
        include_str!("../../robots/unidirectional.toml"),
    ),
    (
        "bidirectional-zy",
        include_str!("../../robots/bidirectional-zy.toml"),
    ),
    (
        "bidirectional-zx",
        include_str!("../../robots/bidirectional-zx.toml"),
    ),
    (
        "dia10_like_zy",
        include_str!("../../robots/dia10_like_zy.toml"),
    ),
    (
        "dia10_like_zx",
        include_str!("../../robots/dia10_like_zx.toml"),
    ),
];

/// The TOML text of a shipped description, by name.
pub fn preset(name: &str) -> Option<&'static str> {
    PRESETS.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
}

/// Names of the shipped descriptions.
pub fn preset_names() -> impl Iterator<Item = &'static str> {
    PRESETS.iter().map(|(n, _)| *n)
}
