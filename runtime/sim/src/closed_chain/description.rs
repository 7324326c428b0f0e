//! Mechanism descriptions evaluated at their nominal parameters: the reader is trocar-model's
//! ([`MechanismModel`]), this module only builds the numeric [`Mechanism`].

use super::error::ClosedChainError;
use super::mechanism::Mechanism;
use std::path::Path;
use trocar_model::closed_chain::MechanismModel;
pub use trocar_model::closed_chain::{COOPERATIVE_TOML, FOUR_BAR_TOML, SHIPPED, STEWART_TOML};

/// A shipped mechanism by name (`four-bar`, `planar-stewart`, `cooperative-arms`).
pub fn shipped(name: &str) -> Result<Mechanism, ClosedChainError> {
    if trocar_model::closed_chain::shipped_text(name).is_none() {
        return Err(ClosedChainError::UnknownScenario {
            name: name.into(),
            known: SHIPPED.to_vec(),
        });
    }
    Mechanism::nominal(&MechanismModel::shipped(name)?)
}

/// Reads a mechanism description from a file; errors name the file and the field.
pub fn from_toml_file(path: impl AsRef<Path>) -> Result<Mechanism, ClosedChainError> {
    Mechanism::nominal(&MechanismModel::from_toml_file(path)?)
}

/// Reads a mechanism description from TOML text.
pub fn from_toml_str(src: &str) -> Result<Mechanism, ClosedChainError> {
    Mechanism::nominal(&MechanismModel::from_toml_str(src)?)
}
