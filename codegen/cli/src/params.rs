//! Parameter overrides: `--param name=value`, parsed once and checked against the declared
//! parameters of a serial robot or a closed mechanism alike.

use crate::output::CliError;

/// Parses one `--param name=value` (the value obeying [`trocar_model::validity`]).
pub(crate) fn parse(s: &str) -> Result<(String, f64), String> {
    let (name, value) = s
        .split_once('=')
        .ok_or_else(|| format!("`{s}`: expected name=value"))?;
    let value: f64 = value
        .trim()
        .parse()
        .map_err(|_| format!("`{s}`: `{value}` is not a number"))?;
    if let Err(problem) = trocar_model::validity::check(value) {
        return Err(format!("`{s}`: {value:e} {problem}"));
    }
    Ok((name.trim().to_string(), value))
}

/// The parameter values, in declaration order, of `declared` (`(name, nominal value)`) with
/// `overrides` applied; an override of an undeclared name is an error naming what `owner`
/// (`"description"` or `"mechanism"`) declares.
pub(crate) fn resolve<'a>(
    declared: impl IntoIterator<Item = (&'a str, f64)>,
    overrides: &[(String, f64)],
    owner: &str,
) -> Result<Vec<f64>, CliError> {
    let (names, mut values): (Vec<&str>, Vec<f64>) = declared.into_iter().unzip();
    for (name, value) in overrides {
        let k = names.iter().position(|n| n == name).ok_or_else(|| {
            CliError(format!(
                "unknown parameter `{name}` (the {owner} declares: {})",
                names.join(", ")
            ))
        })?;
        values[k] = *value;
    }
    Ok(values)
}
