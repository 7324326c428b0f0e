//! The thesis's derivation (chapter 3) carried out on symbols.
