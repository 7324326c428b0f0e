//! Writing descriptions back to TOML.
