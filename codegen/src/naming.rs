//! Names of generated modules.

use crate::error::Error;

/// The module name for a robot name: lower snake case, a valid identifier.
pub fn module_name(robot: &str) -> String {
    let mut s = String::new();
    let mut prev_lower = false;
    for ch in robot.chars() {
        if ch.is_ascii_alphanumeric() {
            if ch.is_ascii_uppercase() && prev_lower {
                s.push('_');
            }
            prev_lower = ch.is_ascii_lowercase() || ch.is_ascii_digit();
            s.push(ch.to_ascii_lowercase());
        } else {
            if !s.ends_with('_') {
                s.push('_');
            }
            prev_lower = false;
        }
    }
    let s = s.trim_matches('_').to_string();
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        format!("robot_{s}")
    } else if syn::parse_str::<syn::Ident>(&s).is_err() {
        format!("{s}_")
    } else {
        s
    }
}

/// The module name for a robot or mechanism named `robot` ([`module_name`]), or `module` when
/// given; an error when the result is not a Rust identifier.
pub fn checked_module_name(robot: &str, module: Option<&str>) -> Result<String, Error> {
    let name = module
        .map(str::to_string)
        .unwrap_or_else(|| module_name(robot));
    if syn::parse_str::<syn::Ident>(&name).is_err() {
        return Err(Error::BadModuleName(name));
    }
    Ok(name)
}
