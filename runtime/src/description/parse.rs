//! Reading descriptions from TOML with locations for every field.
