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

/// What an output file holds, for the checks made before any work: `trocar simulate --plot`
/// must name a `.svg` or `.png` file; a CSV or a generated module may have any name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum OutputKind {
    /// A figure (`--plot`): SVG or PNG, by the extension.
    Figure,
    /// Anything else (`--csv`, `generate -o`).
    Data,
}

/// The output files of one command, checked before the command does any work and written
/// atomically after it has succeeded: each is first written under a temporary name in its own
/// directory, then renamed over the requested name once every output has been written, so a
/// failure (or a closed terminal) leaves no half-written or stale-looking file behind.
#[derive(Debug, Default)]
pub(crate) struct Outputs {
    /// `(option, requested path, temporary path)` of each output.
    files: Vec<(&'static str, std::path::PathBuf, std::path::PathBuf)>,
}

impl Outputs {
    /// Checks the outputs up front: every path names a file in a directory that exists, figures
    /// end in `.svg` or `.png`, and no two outputs are the same file. Errors name the option
    /// and the path.
    pub(crate) fn check(
        requested: &[(&'static str, Option<&std::path::Path>, OutputKind)],
    ) -> Result<Outputs, CliError> {
        let mut out = Outputs::default();
        for &(option, path, kind) in requested {
            let Some(path) = path else { continue };
            let shown = path.display();
            let Some(name) = path.file_name() else {
                return Err(CliError(format!("{option} {shown}: not a file name")));
            };
            if kind == OutputKind::Figure {
                let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
                if !ext.eq_ignore_ascii_case("svg") && !ext.eq_ignore_ascii_case("png") {
                    return Err(CliError(format!(
                        "{option} {shown}: a figure is written as SVG or PNG; name the file `….svg` or `….png`"
                    )));
                }
            }
            let dir = directory(path);
            if !dir.is_dir() {
                return Err(CliError(format!(
                    "{option} {shown}: the directory {} does not exist",
                    dir.display()
                )));
            }
            if path.is_dir() {
                return Err(CliError(format!("{option} {shown}: is a directory")));
            }
            // The same file under two names: the directories resolved and the names.
            let same = |p: &std::path::Path| {
                let d = directory(p);
                (
                    d.canonicalize().unwrap_or(d),
                    p.file_name().map(|n| n.to_owned()),
                )
            };
            if let Some((other, p, _)) = out.files.iter().find(|(_, p, _)| same(p) == same(path)) {
                return Err(CliError(format!(
                    "{option} {shown} and {other} {}: the same file for two outputs",
                    p.display()
                )));
            }
            // The temporary keeps the extension: the figure's format follows it.
            let mut temp = std::ffi::OsString::from(".");
            temp.push(name);
            temp.push(format!(".partial-{}", std::process::id()));
            if let Some(ext) = path.extension() {
                temp.push(".");
                temp.push(ext);
            }
            out.files.push((option, path.to_path_buf(), dir.join(temp)));
        }
        Ok(out)
    }

    /// Where to write the output requested as `path` until [`Outputs::commit`].
    pub(crate) fn temporary<'a>(&'a self, path: &'a std::path::Path) -> &'a std::path::Path {
        self.files
            .iter()
            .find(|(_, p, _)| p == path)
            .map_or(path, |(_, _, t)| t.as_path())
    }

    /// `e` with every temporary file name replaced by the name the user gave.
    pub(crate) fn explain(&self, e: CliError) -> CliError {
        let mut text = e.0;
        for (_, path, temp) in &self.files {
            text = text.replace(&temp.display().to_string(), &path.display().to_string());
        }
        CliError(text)
    }

    /// Renames every temporary file over its requested name.
    pub(crate) fn commit(mut self) -> Result<(), CliError> {
        for (option, path, temp) in std::mem::take(&mut self.files) {
            std::fs::rename(&temp, &path).map_err(|e| {
                let _ = std::fs::remove_file(&temp);
                CliError(format!("{option} {}: {e}", path.display()))
            })?;
        }
        Ok(())
    }
}

/// The directory a file `path` goes into (`.` for a bare file name).
fn directory(path: &std::path::Path) -> std::path::PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    }
}

impl Drop for Outputs {
    /// Removes the temporary files of a command that failed.
    fn drop(&mut self) {
        for (_, _, temp) in &self.files {
            let _ = std::fs::remove_file(temp);
        }
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
