//! Description errors that name file, line and field.

use std::fmt;
use std::path::PathBuf;

/// An invalid or unreadable description: what is wrong and where.
#[derive(Clone, Debug, PartialEq)]
pub struct DescriptionError {
    /// The file, when the description came from one.
    pub file: Option<PathBuf>,
    /// 1-based line, when known.
    pub line: Option<usize>,
    /// 1-based column, when known.
    pub column: Option<usize>,
    /// The field, as a path such as `joints[3].axis` or `constraint.h`.
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for DescriptionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(file) = &self.file {
            write!(f, "{}:", file.display())?;
        }
        if let Some(line) = self.line {
            write!(f, "{line}:")?;
            if let Some(column) = self.column {
                write!(f, "{column}:")?;
            }
        }
        if self.file.is_some() || self.line.is_some() {
            write!(f, " ")?;
        }
        write!(f, "field `{}`: {}", self.field, self.message)
    }
}

impl std::error::Error for DescriptionError {}

impl DescriptionError {
    /// Reads a description file as text; an unreadable file (missing, not UTF-8, ...) is an error
    /// naming the file.
    pub fn read_file(path: &std::path::Path) -> Result<String, DescriptionError> {
        std::fs::read_to_string(path).map_err(|e| DescriptionError {
            file: Some(PathBuf::from(path)),
            line: None,
            column: None,
            field: "(file)".into(),
            message: format!("cannot read the file: {e}"),
        })
    }
}
