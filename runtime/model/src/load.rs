//! Which reader a description goes to: the one place that tells serial robots from closed
//! mechanisms.

use crate::closed_chain::{self, MechanismModel};
use crate::description::{preset_names, DescriptionError, RobotDescription};
use std::path::Path;

/// A description read by [`Description::load`]: a serial robot or a closed mechanism.
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)]
pub enum Description {
    /// A serial robot (TOML description or preset).
    Serial(RobotDescription),
    /// A closed planar mechanism (a TOML file with `[[chains]]`, or a shipped mechanism).
    Mechanism(MechanismModel),
}

impl Description {
    /// Loads `name_or_path`: an existing file is a closed mechanism when it is TOML with a
    /// top-level `chains` array (`[[chains]]`), a serial robot otherwise; a name that is not a
    /// file (nothing of that name, or a directory) is a shipped mechanism (`four-bar`, `planar-stewart`, `cooperative-arms`) or a serial
    /// preset (`bidirectional-zy`, …). Errors name the file, line and field.
    pub fn load(name_or_path: &str) -> Result<Self, DescriptionError> {
        let path = Path::new(name_or_path);
        let shipped = closed_chain::shipped_text(name_or_path).is_some()
            || preset_names().any(|n| n == name_or_path);
        // A directory of a shipped name's name (a checkout's `four-bar/`) does not hide it.
        if !path.exists() || (shipped && path.is_dir()) {
            if closed_chain::shipped_text(name_or_path).is_some() {
                return MechanismModel::shipped(name_or_path).map(Description::Mechanism);
            }
            if preset_names().any(|n| n == name_or_path) {
                return RobotDescription::preset(name_or_path).map(Description::Serial);
            }
            return RobotDescription::from_toml_file(path).map(Description::Serial);
        }
        let text = DescriptionError::read_file(path)?;
        if crate::scene::SceneDescription::is_scene_text(&text) {
            return Err(DescriptionError {
                file: Some(path.to_path_buf()),
                line: Some(1),
                column: None,
                field: "scene".into(),
                message: "this is a scene of several arms, not one robot: `trocar generate` \
                          and the builder's `scene` take it (or name one of its arms' \
                          descriptions)"
                    .into(),
            });
        }
        match closed_chain::parse_table(&text) {
            Ok(table) if table.contains_key("chains") => {
                MechanismModel::from_table(&table, &text, Some(path)).map(Description::Mechanism)
            }
            _ => RobotDescription::from_toml_str(&text, Some(path)).map(Description::Serial),
        }
    }

    /// The mechanism, if this is one.
    pub fn as_mechanism(&self) -> Option<&MechanismModel> {
        match self {
            Description::Mechanism(m) => Some(m),
            Description::Serial(_) => None,
        }
    }

    /// The serial robot, if this is one.
    pub fn as_serial(&self) -> Option<&RobotDescription> {
        match self {
            Description::Serial(d) => Some(d),
            Description::Mechanism(_) => None,
        }
    }
}
