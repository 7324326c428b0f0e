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

/// The largest description file (TOML or URDF) that is read: 16 MiB (a URDF chain of 20 000
/// links, `codegen/cli/tests/deep_urdf.rs`, is 4.4 MiB). A larger one, or an endless
/// input such as `/dev/zero`, is an error once that many bytes have been read.
pub const MAX_FILE_BYTES: u64 = 16 << 20;

impl DescriptionError {
    /// Reads a description file as text, at most [`MAX_FILE_BYTES`] of it; an unreadable file
    /// (missing, too large, not UTF-8, ...) is an error naming the file, and for text that is not
    /// UTF-8 the line, column and byte offset of the first invalid byte.
    pub fn read_file(path: &std::path::Path) -> Result<String, DescriptionError> {
        let error = |line, column, message| DescriptionError {
            file: Some(PathBuf::from(path)),
            line,
            column,
            field: "(file)".into(),
            message,
        };
        let mut bytes = Vec::new();
        {
            use std::io::Read;
            std::fs::File::open(path)
                .and_then(|f| f.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes))
                .map_err(|e| error(None, None, format!("cannot read the file: {e}")))?;
        }
        if bytes.len() as u64 > MAX_FILE_BYTES {
            return Err(error(
                None,
                None,
                format!(
                    "the file is larger than {} MiB, the most a description may be",
                    MAX_FILE_BYTES >> 20
                ),
            ));
        }
        String::from_utf8(bytes).map_err(|e| {
            let at = e.utf8_error().valid_up_to();
            let before = &e.as_bytes()[..at];
            let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
            let line_start = before
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |k| k + 1);
            // Columns count characters, as the TOML errors do (the prefix is valid UTF-8).
            let column = String::from_utf8_lossy(&before[line_start..])
                .chars()
                .count()
                + 1;
            error(
                Some(line),
                Some(column),
                format!(
                    "the file is not UTF-8 text: invalid byte 0x{:02x} at byte offset {at}",
                    e.as_bytes()[at]
                ),
            )
        })
    }
}
