//! Validation of descriptions: every rule with the field it names.
