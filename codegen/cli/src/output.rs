//! Everything `trocar` prints: matrices as aligned text or JSON, and errors.

use trocar_api::{Error, Evaluation};

/// An error of the command line: printed to stderr as `error: …`, exit code 1.
pub(crate) type CliError = Error;

/// Writes `text` to stdout. A reader that has gone away (`trocar generate … | head`) is not an
/// error: the rest of the output is unwanted, and the command ends normally instead of panicking
/// on the broken pipe. Any other failure to write is an error.
pub(crate) fn write_stdout(text: &str) -> Result<(), CliError> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(Error::Output(format!("cannot write to stdout: {e}")))
        }
        _ => Ok(()),
    }
}

/// What an output file holds, for the checks made before any work: `trocar simulate --plot`
/// and `--snapshot` must name a `.svg` or `.png` file, `--animate` a `.gif`; a CSV or a
/// generated module may have any name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum OutputKind {
    /// A figure (`--plot`, `--snapshot`): SVG or PNG, by the extension.
    Figure,
    /// An animation (`--animate`): GIF.
    Animation,
    /// Anything else (`--csv`, `generate -o`).
    Data,
}

/// The output files of one command, checked before the command does any work and written
/// atomically after it has succeeded: each is first written under a temporary name in its own
/// directory, then renamed over the requested name once every output has been written, so a
/// failure (or a closed terminal) leaves no half-written or stale-looking file behind.
///
/// Only regular files are replaced that way. A path that already exists as something else — a
/// device such as `/dev/null`, a FIFO, a socket — is written in place (renaming over it would
/// replace the device node with a plain file), and a symbolic link is followed: its target is
/// replaced and the link kept.
#[derive(Debug, Default)]
pub(crate) struct Outputs {
    files: Vec<OutputFile>,
}

/// One output of a command.
#[derive(Debug)]
struct OutputFile {
    /// The option that named it (`--csv`, `-o` …), for errors.
    option: &'static str,
    /// The path as the user gave it.
    requested: std::path::PathBuf,
    /// The regular file that [`Outputs::commit`] replaces (the requested path with any symbolic
    /// link resolved).
    target: std::path::PathBuf,
    /// Where the output is written until the commit; `None` when it is written in place.
    temp: Option<std::path::PathBuf>,
}

impl Outputs {
    /// Checks the outputs up front: every path names a file in a directory that exists, figures
    /// end in `.svg` or `.png`, animations in `.gif`, and no two outputs are the same file. Errors name the option
    /// and the path.
    pub(crate) fn check(
        requested: &[(&'static str, Option<&std::path::Path>, OutputKind)],
    ) -> Result<Outputs, CliError> {
        let mut out = Outputs::default();
        for &(option, path, kind) in requested {
            let Some(path) = path else { continue };
            let shown = path.display();
            if path.file_name().is_none() {
                return Err(Error::Input(format!("{option} {shown}: not a file name")));
            }
            let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
            if kind == OutputKind::Figure && trocar_sim::plot::ImageFormat::of(path).is_none() {
                return Err(Error::Input(format!(
                    "{option} {shown}: a figure is written as SVG or PNG; name the file `….svg` or `….png`"
                )));
            }
            if kind == OutputKind::Animation && !ext.eq_ignore_ascii_case("gif") {
                return Err(Error::Input(format!(
                    "{option} {shown}: an animation is written as GIF; name the file `….gif`"
                )));
            }
            let dir = directory(path);
            if !dir.is_dir() {
                return Err(Error::Input(format!(
                    "{option} {shown}: the directory {} does not exist",
                    dir.display()
                )));
            }
            if path.is_dir() {
                return Err(Error::Input(format!("{option} {shown}: is a directory")));
            }
            // What exists at the path, symbolic links followed: a regular file (or nothing) is
            // replaced through a temporary; anything else is written in place.
            let (target, in_place) = match std::fs::metadata(path) {
                Ok(m) if !m.is_file() => (path.to_path_buf(), true),
                Ok(_) => (
                    path.canonicalize().unwrap_or_else(|_| path.to_path_buf()),
                    false,
                ),
                // A dangling symbolic link: written through, like any write to it would.
                Err(_) if path.is_symlink() => (path.to_path_buf(), true),
                Err(_) => (path.to_path_buf(), false),
            };
            // The same file under two names: the directories resolved and the names.
            let same = |p: &std::path::Path| {
                let d = directory(p);
                (
                    d.canonicalize().unwrap_or(d),
                    p.file_name().map(|n| n.to_owned()),
                )
            };
            if let Some(other) = out.files.iter().find(|f| same(&f.target) == same(&target)) {
                return Err(Error::Input(format!(
                    "{option} {shown} and {} {}: the same file for two outputs",
                    other.option,
                    other.requested.display()
                )));
            }
            let temp = (!in_place).then(|| {
                // The temporary keeps the extension: the figure's format follows it.
                let name = target.file_name().unwrap_or(path.as_os_str());
                let mut temp = std::ffi::OsString::from(".");
                temp.push(name);
                temp.push(format!(".partial-{}", std::process::id()));
                if let Some(ext) = target.extension() {
                    temp.push(".");
                    temp.push(ext);
                }
                directory(&target).join(temp)
            });
            out.files.push(OutputFile {
                option,
                requested: path.to_path_buf(),
                target,
                temp,
            });
        }
        Ok(out)
    }

    /// Where to write the output requested as `path` until [`Outputs::commit`].
    pub(crate) fn temporary<'a>(&'a self, path: &'a std::path::Path) -> &'a std::path::Path {
        self.files
            .iter()
            .find(|f| f.requested == path)
            .map_or(path, |f| f.temp.as_deref().unwrap_or(&f.target))
    }

    /// `e` with every temporary file name replaced by the name the user gave.
    pub(crate) fn explain(&self, e: String) -> CliError {
        let mut text = e;
        for f in &self.files {
            let written = f.temp.as_deref().unwrap_or(&f.target);
            text = text.replace(
                &written.display().to_string(),
                &f.requested.display().to_string(),
            );
        }
        Error::Output(text)
    }

    /// Renames every temporary file over its requested name.
    pub(crate) fn commit(mut self) -> Result<(), CliError> {
        for f in std::mem::take(&mut self.files) {
            let Some(temp) = &f.temp else { continue };
            std::fs::rename(temp, &f.target).map_err(|e| {
                let _ = std::fs::remove_file(temp);
                Error::Input(format!("{} {}: {e}", f.option, f.requested.display()))
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
        for temp in self.files.iter().filter_map(|f| f.temp.as_ref()) {
            let _ = std::fs::remove_file(temp);
        }
    }
}

/// One entry of a text matrix: nine decimals, or scientific notation from `1e9` on (a value such
/// as `1.5e298` would otherwise print as 300 digits).
fn cell(v: f64) -> String {
    if v.abs() >= 1e9 {
        format!("{v:.9e}")
    } else {
        format!("{v:.9}")
    }
}

/// Prints an error to stderr and returns the exit code of a failed command.
pub(crate) fn print_error(e: &CliError) -> i32 {
    eprintln!("error: {e}");
    1
}

/// The JSON form `{"rows": R, "cols": C, "data": [[row], ...]}` (keys in this order).
pub(crate) fn to_json(m: &Evaluation) -> String {
    let data =
        serde_json::to_string(&m.to_rows()).expect("finite or null numbers always serialise");
    format!(
        r#"{{"rows": {}, "cols": {}, "data": {data}}}"#,
        m.rows, m.cols
    )
}

/// Aligned text, one row a line.
pub(crate) fn to_text(m: &Evaluation) -> String {
    let cells: Vec<Vec<String>> = m
        .to_rows()
        .iter()
        .map(|r| r.iter().map(|v| cell(*v)).collect())
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

/// Aligned text with a header of column labels and each row's label in front (labels of the
/// wrong count are ignored: the plain [`to_text`] is returned). Whitespace inside a label becomes
/// `_`, so each line is still one label and numbers.
pub(crate) fn to_labelled_text(
    m: &Evaluation,
    row_labels: &[String],
    col_labels: &[String],
) -> String {
    if row_labels.len() != m.rows || col_labels.len() != m.cols || m.cols == 0 {
        return to_text(m);
    }
    let clean = |l: &String| l.split_whitespace().collect::<Vec<_>>().join("_");
    let rows: Vec<String> = row_labels.iter().map(clean).collect();
    let cols: Vec<String> = col_labels.iter().map(clean).collect();
    let cells: Vec<Vec<String>> = m
        .to_rows()
        .iter()
        .map(|r| r.iter().map(|v| cell(*v)).collect())
        .collect();
    let width = cells
        .iter()
        .flatten()
        .chain(&cols)
        .map(|c| c.chars().count())
        .max()
        .unwrap_or(0);
    let first = rows.iter().map(|r| r.chars().count()).max().unwrap_or(0);
    let mut lines = vec![format!(
        "{:first$}  {}",
        "",
        cols.iter()
            .map(|c| format!("{c:>width$}"))
            .collect::<Vec<_>>()
            .join("  ")
    )];
    for (label, r) in rows.iter().zip(&cells) {
        lines.push(format!(
            "{label:<first$}  {}",
            r.iter()
                .map(|c| format!("{c:>width$}"))
                .collect::<Vec<_>>()
                .join("  ")
        ));
    }
    lines.join("\n")
}

/// Prints the matrix to stdout, as JSON or aligned text ([`write_stdout`]); the text has row and
/// column labels when `labels` are given.
pub(crate) fn print_matrix(
    m: &Evaluation,
    json: bool,
    labels: Option<(Vec<String>, Vec<String>)>,
) -> Result<(), CliError> {
    let text = match (json, labels) {
        (true, _) => to_json(m),
        (false, Some((rows, cols))) => to_labelled_text(m, &rows, &cols),
        (false, None) => to_text(m),
    };
    write_stdout(&format!("{text}\n"))
}
