//! The description files shipped with trocar (every `robots/*.toml`): the thesis's three wrist
//! presets, the reference arm, a Franka Panda holding a laparoscope (its chain from the shipped
//! `urdf/panda.urdf`) and a KUKA iiwa 14 constrained on its last link (holding an endoscope) and
//! on a middle link (their chain from `urdf/iiwa14.urdf`).

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
    (
        "panda-laparoscope",
        include_str!("../../robots/panda-laparoscope.toml"),
    ),
    (
        "iiwa-endoscope",
        include_str!("../../robots/iiwa-endoscope.toml"),
    ),
    ("iiwa-link6", include_str!("../../robots/iiwa-link6.toml")),
];

/// `(path relative to the shipped descriptions, URDF text)` of every URDF a shipped description
/// takes its chain from (`[robot] urdf = "…"`).
pub const SHIPPED_URDFS: &[(&str, &str)] = &[
    (
        "urdf/panda.urdf",
        include_str!("../../robots/urdf/panda.urdf"),
    ),
    (
        "urdf/iiwa14.urdf",
        include_str!("../../robots/urdf/iiwa14.urdf"),
    ),
];

/// The shipped URDF `rel` when `file` is a shipped description (`<preset NAME>`), else `None`.
pub(crate) fn shipped_urdf(file: Option<&std::path::Path>, rel: &str) -> Option<&'static str> {
    let shipped = file
        .and_then(|f| f.to_str())
        .is_some_and(|f| f.starts_with("<preset ") && f.ends_with('>'));
    if !shipped {
        return None;
    }
    SHIPPED_URDFS
        .iter()
        .find(|(path, _)| *path == rel)
        .map(|(_, text)| *text)
}

/// The TOML text of a shipped description, by name.
pub fn preset(name: &str) -> Option<&'static str> {
    PRESETS.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
}

/// Names of the shipped descriptions.
pub fn preset_names() -> impl Iterator<Item = &'static str> {
    PRESETS.iter().map(|(n, _)| *n)
}
