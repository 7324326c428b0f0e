//! Everything `trocar` prints: matrices as aligned text or JSON, and errors.

use std::fmt;
use trocar_codegen::evaluate::Evaluated;
use trocar_model::description::DescriptionError;

/// An error of the command line: printed to stderr as `error: …`, exit code 1.
#[derive(Debug)]
pub struct CliError(pub String);

impl CliError {
    /// An error from anything that displays.
    pub(crate) fn from_display(e: impl fmt::Display) -> Self {
        CliError(e.to_string())
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for CliError {}

impl From<DescriptionError> for CliError {
    fn from(e: DescriptionError) -> Self {
        CliError(e.to_string())
    }
}

/// Writes `text` to stdout. A reader that has gone away (`trocar generate … | head`) is not an
/// error: the rest of the output is unwanted, and the command ends normally instead of panicking
/// on the broken pipe. Any other failure to write is an error.
pub(crate) fn write_stdout(text: &str) -> Result<(), CliError> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(CliError(format!("cannot write to stdout: {e}")))
        }
        _ => Ok(()),
    }
}

/// Prints an error to stderr and returns the exit code of a failed command.
pub(crate) fn print_error(e: &CliError) -> i32 {
    eprintln!("error: {e}");
    1
}

/// A matrix in row-major order, as printed by the command line.
#[derive(Clone, Debug, PartialEq)]
pub struct MatrixOut {
    /// Row count.
    pub rows: usize,
    /// Column count.
    pub cols: usize,
    /// Entries, row by row.
    pub data: Vec<Vec<f64>>,
}

impl MatrixOut {
    /// A 1×1 matrix.
    pub fn scalar(value: f64) -> Self {
        MatrixOut {
            rows: 1,
            cols: 1,
            data: vec![vec![value]],
        }
    }

    /// From entries stored column by column (the emitted layout of generated functions).
    pub fn column_major(v: &[f64], rows: usize, cols: usize) -> Self {
        MatrixOut {
            rows,
            cols,
            data: (0..rows)
                .map(|r| (0..cols).map(|c| v[c * rows + r]).collect())
                .collect(),
        }
    }

    /// From a nalgebra matrix.
    pub fn from_nalgebra<R: trocar::nalgebra::Dim, C: trocar::nalgebra::Dim, S>(
        m: &trocar::nalgebra::Matrix<f64, R, C, S>,
    ) -> Self
    where
        S: trocar::nalgebra::RawStorage<f64, R, C>,
    {
        let (rows, cols) = m.shape();
        MatrixOut {
            rows,
            cols,
            data: (0..rows)
                .map(|r| (0..cols).map(|c| m[(r, c)]).collect())
                .collect(),
        }
    }

    /// From a faer matrix (the numeric runtime's answers).
    pub fn from_faer(m: &faer::Mat<f64>) -> Self {
        MatrixOut {
            rows: m.nrows(),
            cols: m.ncols(),
            data: (0..m.nrows())
                .map(|r| (0..m.ncols()).map(|c| m[(r, c)]).collect())
                .collect(),
        }
    }

    /// From a generated function's value (column-major).
    pub fn from_evaluated(m: &Evaluated) -> Self {
        Self::column_major(&m.values, m.rows, m.cols)
    }

    /// Whether every entry is finite.
    pub fn is_finite(&self) -> bool {
        self.data.iter().flatten().all(|v| v.is_finite())
    }

    /// The JSON form `{"rows": R, "cols": C, "data": [[row], ...]}` (keys in this order).
    pub fn to_json(&self) -> String {
        let data =
            serde_json::to_string(&self.data).expect("finite or null numbers always serialise");
        format!(
            r#"{{"rows": {}, "cols": {}, "data": {data}}}"#,
            self.rows, self.cols
        )
    }

    /// Aligned text, one row a line.
    pub fn to_text(&self) -> String {
        let cells: Vec<Vec<String>> = self
            .data
            .iter()
            .map(|r| r.iter().map(|v| format!("{v:.9}")).collect())
            .collect();
        let width = cells.iter().flatten().map(String::len).max().unwrap_or(0);
        cells
            .iter()
            .map(|r| {
                r.iter()
                    .map(|c| format!("{c:>width$}"))
                    .collect::<Vec<_>>()
                    .join("  ")
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// Prints the matrix to stdout, as JSON or aligned text ([`write_stdout`]).
    pub(crate) fn print(&self, json: bool) -> Result<(), CliError> {
        let text = if json { self.to_json() } else { self.to_text() };
        write_stdout(&format!("{text}\n"))
    }
}
